// rbcontact/elasticity.hpp: linear elasticity (Hooke's law, plane strain in 2D, 3D) of one or several
// bodies on one DMPlex with PetscFE. Owns the discretization (vector Lagrange P1/P2), the per-cell
// material field (Lamé coefficients as a P0 auxiliary field set from the body labels), essential and
// natural boundary conditions, and the assembly of A (free dofs only) and f (loads + Dirichlet lifting).
#pragma once
#include <petscdmplex.h>
#include <petscsnes.h>
#include <petscds.h>
#include <deque>
#include "rbcontact/scene.hpp"

namespace rbc {

// Pointwise signatures of PetscDS (volume and boundary residual terms).
using PointwiseF = void (*)(PetscInt, PetscInt, PetscInt, const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], PetscReal, const PetscReal[], PetscInt, const PetscScalar[], PetscScalar[]);

class Elasticity {
public:
  Elasticity() = default;
  Elasticity(const Elasticity &) = delete;
  Elasticity &operator=(const Elasticity &) = delete;
  ~Elasticity();

  // Takes a reference to dm (which must carry the scene's labels), creates the FE space and the DS.
  PetscErrorCode Setup(DM dm, const SceneSpec &scene);
  // A (SPD, free dofs) and f = loads - A_{free,constrained} u_D. Creates A, f on the first call.
  PetscErrorCode Assemble(Mat *A, Vec *f);
  // Full local field (constrained dofs set to their Dirichlet values) from a global (free-dof) vector.
  PetscErrorCode GlobalToLocalWithBC(Vec u, Vec uloc) const;
  // Elastic energy 0.5 a(u, u) of the full field (Dirichlet values included).
  PetscErrorCode Energy(Vec u, PetscReal *energy) const;
  // Cell von Mises stress (mean over each cell; plane strain sigma_zz = L tr(eps) in 2D).
  PetscErrorCode VonMises(Vec u, Vec *vm) const;
  // Rigid-body near-null space for GAMG.
  PetscErrorCode NearNullSpace(MatNullSpace *nsp) const;
  // Body index of each local cell (cStart..cEnd-1), -1 where no body label matched.
  const std::vector<PetscInt> &CellBody() const { return cellBody_; }

  DM       dm     = nullptr; // the solution DM (a reference is held)
  DM       dmCell = nullptr; // P0 scalar DM (cell fields: von Mises)
  PetscInt dim    = 0;
  PetscInt degree = 1;

private:
  PetscErrorCode SetupMaterials(const SceneSpec &scene);
  SNES                      snes_ = nullptr; // carries the DM's FEM callbacks; never solved
  Vec                       aux_  = nullptr; // (L, G) per cell
  DM                        dmAux_ = nullptr;
  std::deque<DirichletSpec> bcs_;            // stable storage for boundary-condition contexts
  std::vector<PetscInt>     cellBody_;
};

} // namespace rbc
