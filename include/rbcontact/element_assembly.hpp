// rbcontact/element_assembly.hpp: the element-by-element assembly of the elasticity operator on
// affine simplices (P1/P2 triangles and tetrahedra). Owns the per-mesh tables built once: the closure
// indices of every local cell (global, constrained dofs negative; local), the cell Jacobians, the exact
// reference-element integrals of the basis gradients and values (the integrands are polynomials with a
// cell-constant tensor: no quadrature per assembly), and a preallocated matrix pattern reused by every
// assembly on the mesh. Computes A, the Dirichlet lifting -A_{free,constrained} u_D, the energy
// 1/2 a(U, U) and the cell means of the von Mises stress (the output's cell field) with the same basis
// ordering and quadrature as PetscFE (its own tabulation); the PetscFE residual, Jacobian and cellwise
// integral of elasticity.cpp stay the reference (-fem_assembly petscfe, docs/fom_speed.md).
#pragma once
#include <petscdmplex.h>
#include <vector>

namespace rbc {

// out[c al e be] = scale sum_{a,b} T[c a e b] M[al a] M[be b] (dim^4 tensors, M dim x dim row-major): a
// fourth-order tensor's derivative indices pulled back by M (the physical tensor by G^-1, the cell's by J^-1).
void PullBackTensor(PetscInt dim, const PetscReal *T, const PetscReal *M, PetscReal scale, PetscReal *out);

// Von Mises stress of the displacement gradient gr[c][b] = du_c/dxr_b on the reference mesh: the physical gradient
// gr G^-1 (Ginv dim x dim row-major), sigma = L tr(eps) I + 2 G eps (plane strain in 2D: sigma_zz = L tr eps),
// sqrt(J2(sigma)). The one formula of the PetscFE pointwise function and of ElementAssembler::VonMises.
PetscReal VonMisesStress(PetscInt dim, const PetscReal *gr, PetscReal L, PetscReal G, const PetscReal *Ginv);

class ElementAssembler {
public:
  ElementAssembler() = default;
  ElementAssembler(const ElementAssembler &) = delete;
  ElementAssembler &operator=(const ElementAssembler &) = delete;
  ~ElementAssembler();
  // Tables of dm (its field 0 is the vector Lagrange PetscFE; the local and global sections exist).
  PetscErrorCode Setup(DM dm);
  bool           Ready() const { return pattern_ != nullptr; }
  // Per-cell coefficients: the effective tensor T[c][a][e][b] (dim^4) and the mass coefficient of each
  // cell, through its body: tensor(b), mass(b) for body index cellBody[c - cStart].
  struct Coefficients {
    const std::vector<PetscInt>                *cellBody = nullptr;
    std::vector<const PetscReal *>              tensor;  // per body, dim^4 entries
    std::vector<PetscReal>                      mass;    // per body
    std::vector<const PetscReal *>              lame;    // per body: L, G, G^-1 (dim x dim); VonMises only
  };
  // A (created from the cached pattern when *A is null; otherwise zeroed and refilled).
  PetscErrorCode AssembleMatrix(const Coefficients &k, Mat *A) const;
  // f += -A_{free,constrained} U_c, U_c the constrained values held in the local vector uloc (its
  // free entries are ignored).
  PetscErrorCode AddLifting(const Coefficients &k, Vec uloc, Vec f) const;
  // 1/2 a(U, U) of the full local field U (constrained dofs included), summed over the ranks.
  PetscErrorCode Energy(const Coefficients &k, Vec uloc, PetscReal *energy) const;
  // Cell means of the von Mises stress of the local field U: vm[c - cStart] = the quadrature mean over the
  // cell of sqrt(J2(sigma)), sigma = L tr(eps) I + 2 G eps of the physical gradient grad_xr u G^-1 (plane
  // strain in 2D: sigma_zz = L tr eps), PetscFE's quadrature points and weights (what
  // DMPlexComputeCellwiseIntegralFEM divided by the cell volume gives, without its per-cell cost).
  PetscErrorCode VonMises(const Coefficients &k, Vec uloc, std::vector<PetscReal> *vm) const;

private:
  PetscErrorCode CreatePattern();
  void           ElementMatrix(const Coefficients &k, PetscInt cell, PetscReal *Ke) const;

  DM                     dm_ = nullptr;
  Mat                    pattern_ = nullptr; // preallocated, zero values
  PetscInt               dim_ = 0, nb_ = 0, cStart_ = 0, cEnd_ = 0;
  std::vector<PetscInt>  gidx_, lidx_;       // per cell nb_ closure indices (global: constrained < 0)
  std::vector<PetscInt>  liftCells_;         // local cells with a constrained dof in their closure
  std::vector<PetscReal> invJ_, detJ_;       // per cell dim^2 (dxi/dx, PETSc layout) and |det J|
  std::vector<PetscInt>  comp_;              // component of each vector basis function
  std::vector<PetscReal> gradInt_;           // [i][j][alpha][beta] int dphi_i/dxi_alpha dphi_j/dxi_beta
  std::vector<PetscReal> massInt_;           // [i][j] int phi_i phi_j (same component only)
  std::vector<PetscReal> qDer_, qWeight_;     // per quadrature point q: [q][i][alpha] dphi_i/dxi_alpha; weights
};

} // namespace rbc
