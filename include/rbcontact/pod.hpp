// rbcontact/pod.hpp: the primal basis by POD of displacement snapshots with SLEPc, in the energy
// inner product (x^T A y, A the reference stiffness), H1 or l2 (-pod_inner energy|h1|l2).
// The weighted problem is formed with BV: BVSetMatrix(X, M), the correlation matrix C = X^T M X by
// BVDot, its dense symmetric eigendecomposition (LAPACK), and the modes X V S^{-1} by BVMult;
// correct in parallel. -pod_inner l2 may instead use SVDSetOperators directly (-pod_method svd,
// -pod_svd_type ...). Size: -pod_tol (relative energy left out, default 1e-8) or -pod_n (count).
// Details, options, the sign convention and measured accuracy: docs/pod.md.
#pragma once
#include <petscmat.h>
#include <slepcbv.h>
#include <string>
#include <vector>

namespace rbc {

struct PODResult {
  BV                     modes = nullptr;   // N orthonormal columns (in the inner product M)
  std::vector<PetscReal> singularValues;    // all of them (sqrt of the correlation eigenvalues), decreasing
  PetscInt               N = 0;
  PetscReal              energyCaptured = 0; // sum_{i<N} s_i^2 / sum s_i^2
  PetscReal              orthonormalityError = 0; // max |V^T M V - I|
  // Additions (pod.cpp):
  PetscInt               rank = 0;          // numerical rank: #{i : s_i > rankTol * s_0} (N <= rank)
  PetscReal              rankTol = 0;       // the relative threshold used (-pod_rank_tol)
  PetscReal              orthonormalityErrorInitial = 0; // max |V^T M V - I| of X V S^{-1} before any re-orthonormalization
  PetscBool              reorthonormalized = PETSC_FALSE; // BVOrthogonalize was applied (initial error > 1e-10)
  std::string            method = "bv";     // "bv" (method of snapshots) or "svd" (SLEPc SVD, l2 only)
  PODResult() = default;
  PODResult(const PODResult &) = delete;
  PODResult &operator=(const PODResult &) = delete;
  PODResult(PODResult &&o) noexcept;
  PODResult &operator=(PODResult &&o) noexcept;
  ~PODResult();
};

// The inner product selected by -pod_inner energy|h1|l2 (default energy). The caller builds M from it:
// energy -> the reference stiffness A_ref, h1 -> an H1 Gram matrix, l2 -> M = nullptr.
enum class PODInner { Energy, H1, L2 };
PetscErrorCode PODInnerFromOptions(MPI_Comm comm, PODInner *inner);
// The -pod_* options ComputePOD reads, checked where they do not depend on the snapshots (their values, names and
// ranges; -pod_n against the snapshot count is ComputePOD's): the offline stage calls it before the snapshots.
PetscErrorCode PODCheckOptions(MPI_Comm comm);
const char    *PODInnerName(PODInner inner);

// snapshots: columns = snapshot vectors (same layout as M's rows, e.g. DMCreateGlobalVector), M the
// inner-product matrix (nullptr: l2). Options prefix pod_.
//   -pod_method bv|svd        bv (default): method of snapshots with BV; svd: SLEPc SVD of the dense
//                             snapshot matrix (l2 only: M must be nullptr), -pod_svd_type (default
//                             trlanczos), -pod_svd_nsv (triplets requested, default m), -pod_svd_*
//   -pod_n <N> | -pod_tol <t> the size (count, or relative energy left out; -pod_n wins), both capped
//                             by the numerical rank
//   -pod_rank_tol <r>         s_i <= r s_0 counts as zero (default 10 sqrt(m eps))
//   -pod_sv_out <file>        rank 0 writes the singular values (one per line, %.17e) to <file>
//   -pod_view                 prints a summary on the snapshots' communicator
// Collective on the snapshots' communicator. Replaces any previous content of *res.
// tol >= 0: this relative energy instead of -pod_tol (offline -estimate's enriched space; -pod_n still wins).
PetscErrorCode ComputePOD(const std::vector<Vec> &snapshots, Mat M, PODResult *res, PetscReal tol = -1);
// The N that -pod_tol tol would have chosen from res's singular values (smallest N with the energy left out
// <= tol, within [1, rank]): the answer's size inside a POD computed to a smaller tolerance (offline -estimate).
PetscInt PODSizeForTolerance(const PODResult &res, PetscReal tol);
// -pod_tol's default (read by ComputePOD, and by offline -estimate for the answer's size).
constexpr PetscReal kPODDefaultTol = 1e-8;

// M-norm projection error of each snapshot onto span(modes): ||x - V V^T M x||_M, M the modes' BV
// matrix (l2 if none). sum_j err_j^2 = sum_{i >= N} s_i^2 (the left-out energy).
PetscErrorCode PODProjectionErrors(BV modes, const std::vector<Vec> &snapshots, std::vector<PetscReal> *errors);

} // namespace rbc
