// rbcontact/supremizers.hpp: the primal basis enrichment that keeps the reduced saddle point inf-sup
// stable, compressed. Given the POD modes V (M-orthonormal) and one supremizer s_k = A^{-1} K_k^T xi_k
// per dual basis vector xi_k, the supremizers' M-orthogonal complement to span V is compressed by POD
// (its M-Gram matrix's eigenvectors, largest first) and only as many compressed directions are kept
// as the reduced inf-sup constant needs:
//   beta(k) = min over the training snapshots j of sigma_min( L^{-1} W^T K_j [V Z_1..k] ),  L L^T = W^T W,
// the smallest k with beta(k) >= ratio * beta(all) (-pod_supremizers_infsup ratio; 1 keeps every
// direction, the uncompressed enrichment). Norms: the POD inner product M for the primal coefficients,
// the Euclidean norm of the nodal multiplier field W lambda^ for the dual ones. Why and the measured
// effect: docs/hyper_reduction.md, "Compressed supremizers".
#pragma once
#include <petscvec.h>
#include <slepcbv.h>
#include <vector>
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/snapshot_contact.hpp"

namespace rbc {

struct SupremizerEnrichment {
  PetscInt               candidates = 0; // supremizers computed (one per dual vector)
  PetscInt               rank       = 0; // their numerical rank off span V
  PetscInt               kept       = 0; // compressed directions added to the basis
  PetscReal              ratio      = 1; // the inf-sup fraction asked for
  std::vector<PetscReal> beta;           // beta(k), k = 0..rank (min over the training snapshots)
  std::vector<PetscReal> sigma;          // M-norms of the compressed directions before normalization
};

// -pod_supremizers_infsup (default 1), checked to lie in (0, 1].
PetscErrorCode SupremizerRatioFromOptions(MPI_Comm comm, PetscReal *ratio);

// pod: the POD modes (Np M-orthonormal columns, active columns 0..Np); sup: the supremizers (same
// layout); K: the training snapshots' contact matrices on the contact dofs (snapshot_contact.hpp; beta's
// minimum runs over them); W: the dual basis (R x r); canonical[g]: the canonical index of global dof g
// (CanonicalOrder::CanonicalDof). *out: a new BV [V, Z_1..kept], M-orthonormal (the caller destroys it). Collective.
PetscErrorCode EnrichWithSupremizers(BV pod, const std::vector<Vec> &sup, const SnapshotContactMatrices &K, const DenseMatrix &W, const std::vector<PetscInt> &canonical, PetscReal ratio, BV *out, SupremizerEnrichment *info);

} // namespace rbc
