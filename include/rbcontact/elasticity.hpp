// rbcontact/elasticity.hpp: linear elasticity (Hooke's law, plane strain in 2D, 3D) of one or several
// bodies on one DMPlex with PetscFE, on a reference mesh mapped per body by x = G_b(mu) xr + t_b(mu).
// Owns the discretization (vector Lagrange P1/P2), the per-cell auxiliary P0 field (the effective
// elasticity tensor |det G| C(G^-T ., G^-T .), the Lamé coefficients, G^-1, the body-force scale),
// essential and natural boundary conditions, and the assembly of A (free dofs only) and f (loads +
// Dirichlet lifting) in the current state: the physical state at mu (SetMu), or any state the affine
// decomposition sets (SetBodyAux, SetLoadScales).
#pragma once
#include <petscdmplex.h>
#include <petscsnes.h>
#include <petscds.h>
#include <deque>
#include "rbcontact/element_assembly.hpp"
#include "rbcontact/geometry_map.hpp"
#include "rbcontact/scene.hpp"

namespace rbc {

// Pointwise signatures of PetscDS (volume and boundary residual terms).
using PointwiseF = void (*)(PetscInt, PetscInt, PetscInt, const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], PetscReal, const PetscReal[], PetscInt, const PetscScalar[], PetscScalar[]);

// The rigid-body modes of a vector P1/P2 Lagrange field on dm (field 0, dim components), orthonormal on the free
// dofs: the modes evaluated at the nodes (vertices, centroids of the other points' vertices), what
// DMPlexCreateRigidBody projects through every cell. *nsp = nullptr where a point holds more than one node.
PetscErrorCode NodalRigidBodyModes(DM dm, MatNullSpace *nsp);

class Elasticity {
public:
  Elasticity() = default;
  Elasticity(const Elasticity &) = delete;
  Elasticity &operator=(const Elasticity &) = delete;
  ~Elasticity();

  // Takes a reference to dm (which must carry the scene's labels), creates the FE space and the DS.
  // The state is the physical one at the scene's parameter values, with the identity map.
  PetscErrorCode Setup(DM dm, const SceneSpec &scene);
  // The geometric map used by SetMu (not owned; nullptr = identity).
  void SetGeometryMap(const GeometryMap *map) { map_ = map; }
  // Physical state at mu: materials E(mu), nu(mu), map G_b(mu), Dirichlet and traction scales.
  PetscErrorCode SetMu(const std::vector<PetscReal> &mu);
  // Raw state for the affine decomposition: per body, the aux values (AuxSize() each) ...
  PetscErrorCode SetBodyAux(const std::vector<std::vector<PetscReal>> &perBody);
  // ... and the load scales: per Dirichlet boundary, body force, per traction boundary.
  PetscErrorCode SetLoadScales(const std::vector<PetscReal> &dirichlet, PetscReal bodyForce, const std::vector<PetscReal> &traction);
  // Aux layout: L, G, G^-1 (dim x dim), body-force scale, mass coefficient, then the effective
  // tensor T (dim^4). The mass term (zero in the physical state) serves the H1 inner product.
  PetscInt AuxBodyForceIndex() const { return 2 + dim * dim; }
  PetscInt AuxMassIndex() const { return 3 + dim * dim; }
  PetscInt AuxTensorOffset() const { return 4 + dim * dim; }
  PetscInt AuxSize() const { return AuxTensorOffset() + dim * dim * dim * dim; }
  // The H1 inner-product matrix (vector mass + vector Laplacian) on the reference mesh, free dofs.
  PetscErrorCode AssembleH1(Mat *M);
  // The physical aux values of a body with moduli (E, nu) under the map a.
  void PhysicalAux(PetscReal E, PetscReal nu, const Affine &a, std::vector<PetscReal> *aux) const;
  // The material of body b at mu.
  void Material(PetscInt b, const std::vector<PetscReal> &mu, PetscReal *E, PetscReal *nu) const;
  // Assemble only A, or only f = -F(0) (loads + lifting), in the current state.
  PetscErrorCode AssembleMatrix(Mat *A);
  PetscErrorCode AssembleRhs(Vec *f);
  // A (SPD, free dofs) and f = loads - A_{free,constrained} u_D. Creates A, f on the first call.
  PetscErrorCode Assemble(Mat *A, Vec *f);
  // Full local field (constrained dofs set to their Dirichlet values) from a global (free-dof) vector.
  PetscErrorCode GlobalToLocalWithBC(Vec u, Vec uloc) const;
  // Elastic energy 0.5 a(u, u) of the full field (Dirichlet values included).
  PetscErrorCode Energy(Vec u, PetscReal *energy) const;
  // Cell von Mises stress (mean over each cell; plane strain sigma_zz = L tr(eps) in 2D).
  PetscErrorCode VonMises(Vec u, Vec *vm) const;
  // Rigid-body near-null space for GAMG (of the reference coordinates: the same for every parameter), computed
  // once per mesh and shared: *nsp is a new reference (MatNullSpaceDestroy it).
  PetscErrorCode NearNullSpace(MatNullSpace *nsp) const;
  // Body index of each local cell (cStart..cEnd-1), -1 where no body label matched.
  const std::vector<PetscInt> &CellBody() const { return cellBody_; }
  // Body owning each traction boundary of the scene (-1: none found).
  const std::vector<PetscInt> &TractionBody() const { return tractionBody_; }
  const GeometryMap           *Map() const { return map_; }

  DM       dm     = nullptr; // the solution DM (a reference is held)
  DM       dmCell = nullptr; // P0 scalar DM (cell fields: von Mises)
  PetscInt dim    = 0;
  PetscInt degree = 1;

  SceneSpec scene; // a copy (names, materials, loads, parameters)

private:
  PetscErrorCode SetupMaterials();
  // The element-by-element path (default; -fem_assembly petscfe selects PetscFE's residual/Jacobian)
  PetscErrorCode                 EnsureElements() const;
  ElementAssembler::Coefficients ElementCoefficients() const;
  PetscErrorCode                 AssembleLoads(Vec f); // f = body forces + tractions (no lifting)
  PetscErrorCode ApplyConstants(PetscReal bodyForceScale, const std::vector<PetscReal> &tractionScale);
  const GeometryMap        *map_ = nullptr;
  SNES                      snes_ = nullptr; // carries the DM's FEM callbacks; never solved
  Vec                       aux_  = nullptr; // (L, G) per cell
  DM                        dmAux_ = nullptr;
  std::deque<DirichletSpec> bcs_;            // stable storage for boundary-condition contexts
  std::vector<PetscInt>     cellBody_;
  std::vector<PetscInt>     tractionBody_;
  std::vector<std::vector<PetscReal>> bodyAux_; // the state set by SetBodyAux, per body
  bool                      elementAssembly_ = true;
  mutable ElementAssembler  elem_;
  mutable Vec               bcLocal_ = nullptr; // the Dirichlet values of the current state, zero elsewhere
  mutable bool              bcValid_ = false;   // cleared by every change of the load scales
  mutable MatNullSpace      nearNull_ = nullptr; // NearNullSpace's rigid-body modes, once per mesh
  std::vector<PetscInt>     bcValue_;           // label value of each essential boundary (bcs_ order)
  // Constant Dirichlet values straight into the local vector (Lagrange nodes of the closures of the
  // labeled points, in DMAddBoundary's order): what DMPlexInsertBoundaryValues projects, without its cost
  PetscErrorCode InsertConstantBoundaryValues(Vec uloc) const;
};

} // namespace rbc
