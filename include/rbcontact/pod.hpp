// rbcontact/pod.hpp: the primal basis by POD of displacement snapshots with SLEPc, in the energy
// inner product (x^T A y, A the reference stiffness), H1 or l2 (-pod_inner energy|h1|l2).
// The weighted problem is formed with BV: BVSetMatrix(X, M), the correlation matrix C = X^T M X by
// BVDot, its dense symmetric eigendecomposition (LAPACK), and the modes X V S^{-1} by BVMultInPlace;
// correct in parallel. -pod_inner l2 may instead use SVDSetOperators directly (-pod_method svd,
// -pod_svd_type ...). Size: -pod_tol (relative energy left out, default 1e-8) or -pod_n (count).
#pragma once
#include <petscmat.h>
#include <slepcbv.h>
#include <vector>

namespace rbc {

struct PODResult {
  BV                     modes = nullptr;   // N orthonormal columns (in the inner product M)
  std::vector<PetscReal> singularValues;    // all of them (sqrt of the correlation eigenvalues), decreasing
  PetscInt               N = 0;
  PetscReal              energyCaptured = 0; // sum_{i<N} s_i^2 / sum s_i^2
  PetscReal              orthonormalityError = 0; // max |V^T M V - I|
  ~PODResult();
};

// snapshots: columns = snapshot vectors (same layout as M's rows, e.g. DMCreateGlobalVector), M the
// inner-product matrix (nullptr: l2). Options prefix pod_.
PetscErrorCode ComputePOD(const std::vector<Vec> &snapshots, Mat M, PODResult *res);

} // namespace rbc
