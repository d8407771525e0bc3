// src/reduction/pod.cpp: proper orthogonal decomposition of snapshots (rbcontact/pod.hpp).
// Owns the pod_ options, the method of snapshots with SLEPc BV in the inner product of a matrix M
// (C = X^T M X by BVDot, LAPACK dsyev on every rank on rank 0's copy of C, modes X V S^{-1} by
// BVMult), the alternative SLEPc SVD of the dense snapshot matrix (l2 only), the choice of N, the
// sign convention (largest-magnitude entry of each right singular vector positive), the
// orthonormality measurement with one BVOrthogonalize pass if needed, and the M-norm projection
// errors of snapshots. See docs/pod.md.
#include "rbcontact/pod.hpp"

#include <petscblaslapack.h>
#include <slepcsvd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <utility>

namespace rbc {

namespace {

PetscLogEvent POD_Event = 0;

// Modes whose M-Gram matrix differs from I by more than this (max entry) are re-orthonormalized.
constexpr PetscReal kOrthoTol = 1e-10;

const char *const kMethods[] = {"bv", "svd"};
const char *const kInners[]  = {"energy", "h1", "l2"};

struct PODOptions {
  PetscInt  method = 0; // 0 bv, 1 svd
  PetscInt  inner  = 0; // index in kInners
  PetscBool innerSet = PETSC_FALSE;
  PetscInt  n        = -1;
  PetscBool nSet     = PETSC_FALSE;
  PetscInt  svdNsv   = -1; // singular triplets requested from SLEPc (-pod_svd_nsv, default m)
  PetscReal tol      = kPODDefaultTol;
  PetscReal rankTol  = 0;
  PetscBool view     = PETSC_FALSE;
  char      svOut[PETSC_MAX_PATH_LEN] = "";
};

PetscErrorCode ReadOptions(MPI_Comm comm, PetscInt m, Mat M, PODOptions *o)
{
  PetscBool set;

  PetscFunctionBeginUser;
  // Relative noise level of the correlation eigenvalues is ~ m eps (lambda_i = s_i^2), so singular
  // values below ~ sqrt(m eps) s_0 are not resolved by the method of snapshots; 10x margin.
  o->rankTol = 10 * PetscSqrtReal((PetscReal)std::max<PetscInt>(m, 1) * PETSC_MACHINE_EPSILON);
  PetscOptionsBegin(comm, "pod_", "Proper orthogonal decomposition", "ComputePOD");
  PetscCall(PetscOptionsEList("-method", "bv: method of snapshots with BV (any inner product); svd: SLEPc SVD of the snapshot matrix (l2 only)", "ComputePOD", kMethods, 2, kMethods[o->method], &o->method, NULL));
  PetscCall(PetscOptionsEList("-inner", "Inner product of the POD (the caller builds M accordingly)", "PODInnerFromOptions", kInners, 3, kInners[o->inner], &o->inner, &o->innerSet));
  PetscCall(PetscOptionsInt("-n", "Number of modes (takes precedence over -pod_tol)", "ComputePOD", o->n, &o->n, &o->nSet));
  PetscCall(PetscOptionsReal("-tol", "Relative energy left out: smallest N with sum_{i>=N} s_i^2 <= tol sum s_i^2", "ComputePOD", o->tol, &o->tol, NULL));
  PetscCall(PetscOptionsReal("-rank_tol", "Singular values s_i <= rank_tol * s_0 count as zero", "ComputePOD", o->rankTol, &o->rankTol, NULL));
  PetscCall(PetscOptionsString("-sv_out", "Rank 0 writes all singular values to this file", "ComputePOD", o->svOut, o->svOut, sizeof o->svOut, &set));
  o->svdNsv = m;
  PetscCall(PetscOptionsInt("-svd_nsv", "-pod_method svd: number of singular triplets requested (default: all m)", "ComputePOD", o->svdNsv, &o->svdNsv, NULL));
  PetscCall(PetscOptionsBool("-view", "Print a summary of the POD", "ComputePOD", o->view, &o->view, NULL));
  PetscOptionsEnd();

  PetscCheck(o->tol >= 0 && o->tol < 1, comm, PETSC_ERR_USER_INPUT, "-pod_tol %g must lie in [0, 1)", (double)o->tol);
  PetscCheck(o->rankTol > 0 && o->rankTol < 1, comm, PETSC_ERR_USER_INPUT, "-pod_rank_tol %g must lie in (0, 1)", (double)o->rankTol);
  if (m < 0) { // before the snapshots (PODCheckOptions): what does not depend on them
    PetscCheck(!o->nSet || o->n >= 1, comm, PETSC_ERR_USER_INPUT, "-pod_n %" PetscInt_FMT " must be >= 1", o->n);
    PetscCheck(!(o->method == 1 && o->inner != 2), comm, PETSC_ERR_USER_INPUT, "-pod_method svd computes the l2 POD only (-pod_inner l2), not -pod_inner %s", kInners[o->inner]);
    PetscFunctionReturn(0);
  }
  if (o->nSet) PetscCheck(o->n >= 1 && o->n <= m, comm, PETSC_ERR_USER_INPUT, "-pod_n %" PetscInt_FMT " must lie in [1, %" PetscInt_FMT "] (the number of snapshots)", o->n, m);
  PetscCheck(o->svdNsv >= 1 && o->svdNsv <= m, comm, PETSC_ERR_USER_INPUT, "-pod_svd_nsv %" PetscInt_FMT " must lie in [1, %" PetscInt_FMT "] (the number of snapshots)", o->svdNsv, m);
  PetscCheck(!(o->method == 1 && M), comm, PETSC_ERR_USER_INPUT, "-pod_method svd computes the l2 POD only (-pod_inner l2), but an inner-product matrix M was given (-pod_inner %s)", kInners[o->inner]);
  if (o->innerSet) {
    PetscCheck(!(o->inner == 2 && M), comm, PETSC_ERR_USER_INPUT, "-pod_inner l2 but an inner-product matrix M was given to ComputePOD");
    PetscCheck(!(o->inner != 2 && !M), comm, PETSC_ERR_USER_INPUT, "-pod_inner %s needs its inner-product matrix M (got none)", kInners[o->inner]);
  }
  PetscFunctionReturn(0);
}

// Sign convention: the largest-magnitude entry of v (first one on ties) is made positive; returns
// the factor (+1 or -1) to apply to v (and to the mode).
PetscReal SignOf(const PetscScalar *v, PetscInt m)
{
  PetscInt  imax = 0;
  PetscReal amax = -1;
  for (PetscInt i = 0; i < m; ++i)
    if (PetscAbsScalar(v[i]) > amax) {
      amax = PetscAbsScalar(v[i]);
      imax = i;
    }
  return PetscRealPart(v[imax]) < 0 ? -1.0 : 1.0;
}

// Rank and N from the singular values (decreasing, s_0 > 0). `missing`: energy not represented by
// singularValues (-pod_method svd with fewer converged triplets than snapshots), part of every tail.
// Suffix sums (accurate tails) left[i] = sum_{k>=i} s_k^2 + missing, and the smallest N with left[N] <= tol left[0]
// (m when none).
PetscInt TailSize(const std::vector<PetscReal> &s, PetscReal missing, PetscReal tol, std::vector<PetscReal> *left)
{
  const PetscInt m = (PetscInt)s.size();
  left->assign(m + 1, missing);
  for (PetscInt i = m - 1; i >= 0; --i) (*left)[i] = (*left)[i + 1] + s[i] * s[i];
  for (PetscInt i = 0; i <= m; ++i)
    if ((*left)[i] <= tol * (*left)[0]) return i;
  return m;
}

void SelectSize(const PODOptions &o, PetscReal missing, PODResult *res)
{
  const std::vector<PetscReal> &s = res->singularValues;
  const PetscInt                m = (PetscInt)s.size();
  res->rank = 0;
  for (PetscInt i = 0; i < m; ++i)
    if (s[i] > o.rankTol * s[0]) res->rank = i + 1;
  std::vector<PetscReal> left;
  const PetscInt         byTol = TailSize(s, missing, o.tol, &left);
  const PetscInt         N     = o.nSet ? o.n : byTol;
  res->N              = std::max<PetscInt>(1, std::min(N, res->rank));
  res->energyCaptured = 1.0 - left[res->N] / left[0];
}

// max |V^T M V - I| (the BV's matrix, if any).
PetscErrorCode OrthonormalityError(BV V, PetscReal *err)
{
  PetscInt           N;
  Mat                G;
  const PetscScalar *g;

  PetscFunctionBeginUser;
  PetscCall(BVGetSizes(V, NULL, NULL, &N));
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, N, N, NULL, &G));
  PetscCall(BVDot(V, V, G));
  PetscCall(MatDenseGetArrayRead(G, &g));
  *err = 0;
  for (PetscInt j = 0; j < N; ++j)
    for (PetscInt i = 0; i < N; ++i) *err = std::max(*err, PetscAbsScalar(g[i + j * N] - (i == j ? 1.0 : 0.0)));
  PetscCall(MatDenseRestoreArrayRead(G, &g));
  PetscCall(MatDestroy(&G));
  PetscFunctionReturn(0);
}

// Method of snapshots: C = X^T M X, C = V Lambda V^T, modes X V_N S_N^{-1}.
PetscErrorCode PODSnapshots(MPI_Comm comm, const std::vector<Vec> &snapshots, Mat M, const PODOptions &o, PODResult *res)
{
  const PetscInt m = (PetscInt)snapshots.size();
  BV             X;
  Mat            C, Q;

  PetscFunctionBeginUser;
  PetscCall(BVCreate(comm, &X));
  PetscCall(BVSetSizesFromVec(X, snapshots[0], m));
  PetscCall(BVSetOptionsPrefix(X, "pod_"));
  PetscCall(BVSetFromOptions(X));
  for (PetscInt j = 0; j < m; ++j) PetscCall(BVInsertVec(X, j, snapshots[j]));
  if (M) PetscCall(BVSetMatrix(X, M, PETSC_FALSE));

  // C = X^T M X (replicated); symmetrized; rank 0's copy broadcast so that every rank decomposes
  // bitwise the same matrix (same eigenvectors, same signs).
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, m, m, NULL, &C));
  PetscCall(BVDot(X, X, C));
  std::vector<PetscScalar> c(m * m);
  {
    const PetscScalar *a;
    PetscCall(MatDenseGetArrayRead(C, &a));
    for (PetscInt j = 0; j < m; ++j)
      for (PetscInt i = 0; i < m; ++i) c[i + j * m] = 0.5 * (a[i + j * m] + a[j + i * m]);
    PetscCall(MatDenseRestoreArrayRead(C, &a));
  }
  PetscCall(MatDestroy(&C));
  PetscCallMPI(MPI_Bcast(c.data(), (int)(m * m), MPIU_SCALAR, 0, comm));

  PetscBLASInt             bm, info, lwork;
  std::vector<PetscReal>   w(m);
  PetscCall(PetscBLASIntCast(m, &bm));
  PetscCall(PetscBLASIntCast(std::max<PetscInt>(1, 34 * m), &lwork));
  std::vector<PetscScalar> work(lwork);
  PetscCall(PetscFPTrapPush(PETSC_FP_TRAP_OFF));
  PetscCallBLAS("LAPACKsyev", LAPACKsyev_("V", "U", &bm, c.data(), &bm, w.data(), work.data(), &lwork, &info));
  PetscCall(PetscFPTrapPop());
  PetscCheck(info == 0, comm, PETSC_ERR_LIB, "LAPACK dsyev of the %" PetscInt_FMT " x %" PetscInt_FMT " correlation matrix failed (info %d)", m, m, (int)info);

  // Decreasing order; checks; clamp rounding negatives; sign convention.
  std::vector<PetscReal>   lam(m);
  std::vector<PetscScalar> V(m * m);
  for (PetscInt i = 0; i < m; ++i) {
    lam[i] = w[m - 1 - i];
    std::copy(c.begin() + (m - 1 - i) * m, c.begin() + (m - i) * m, V.begin() + i * m);
  }
  PetscCheck(lam[0] > 0 && std::isfinite(lam[0]), comm, PETSC_ERR_USER_INPUT, "POD: the snapshots are all zero in the inner product (largest correlation eigenvalue %g)", (double)lam[0]);
  PetscCheck(lam[m - 1] >= -PetscSqrtReal(PETSC_MACHINE_EPSILON) * lam[0], comm, PETSC_ERR_USER_INPUT, "POD: the correlation matrix X^T M X has the eigenvalue %g (largest %g): the inner-product matrix M (-pod_inner %s) is not positive semi-definite", (double)lam[m - 1], (double)lam[0], kInners[o.inner]);
  res->singularValues.resize(m);
  for (PetscInt i = 0; i < m; ++i) {
    res->singularValues[i] = PetscSqrtReal(std::max<PetscReal>(lam[i], 0.0));
    const PetscReal sg     = SignOf(&V[i * m], m);
    for (PetscInt k = 0; k < m; ++k) V[k + i * m] *= sg;
  }
  SelectSize(o, 0.0, res);

  // modes = X V_N S_N^{-1}
  const PetscInt N = res->N;
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, m, N, NULL, &Q));
  {
    PetscScalar *q;
    PetscCall(MatDenseGetArrayWrite(Q, &q));
    for (PetscInt i = 0; i < N; ++i)
      for (PetscInt k = 0; k < m; ++k) q[k + i * m] = V[k + i * m] / res->singularValues[i];
    PetscCall(MatDenseRestoreArrayWrite(Q, &q));
  }
  PetscCall(BVDuplicateResize(X, N, &res->modes));
  PetscCall(BVMult(res->modes, 1.0, 0.0, X, Q));
  PetscCall(MatDestroy(&Q));
  PetscCall(BVDestroy(&X));
  PetscFunctionReturn(0);
}

// l2 POD by SLEPc SVD of the dense n x m snapshot matrix (left singular vectors = modes).
PetscErrorCode PODSvd(MPI_Comm comm, const std::vector<Vec> &snapshots, const PODOptions &o, PODResult *res)
{
  const PetscInt m = (PetscInt)snapshots.size();
  PetscInt       nloc, nglob, nconv;
  Mat            A;
  SVD            svd;
  Vec            v, vall;
  VecScatter     toall;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(snapshots[0], &nloc));
  PetscCall(VecGetSize(snapshots[0], &nglob));
  PetscCall(MatCreateDense(comm, nloc, PETSC_DECIDE, nglob, m, NULL, &A));
  for (PetscInt j = 0; j < m; ++j) {
    Vec col;
    PetscCall(MatDenseGetColumnVecWrite(A, j, &col));
    PetscCall(VecCopy(snapshots[j], col));
    PetscCall(MatDenseRestoreColumnVecWrite(A, j, &col));
  }
  PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));

  PetscCall(SVDCreate(comm, &svd));
  PetscCall(SVDSetOperators(svd, A, NULL));
  PetscCall(SVDSetOptionsPrefix(svd, "pod_"));
  PetscCall(SVDSetWhichSingularTriplets(svd, SVD_LARGEST));
  PetscCall(SVDSetDimensions(svd, o.svdNsv, PETSC_DEFAULT, PETSC_DEFAULT));
  // Default thick-restart Lanczos (SLEPc's default, cross, fails on the zero singular values of
  // rank-deficient snapshots: A^T A has tiny negative eigenvalues); -pod_svd_type overrides.
  PetscCall(SVDSetType(svd, SVDTRLANCZOS));
  PetscCall(SVDSetFromOptions(svd));
  PetscCall(SVDSolve(svd));
  PetscCall(SVDGetConverged(svd, &nconv));
  PetscCheck(nconv >= 1, comm, PETSC_ERR_NOT_CONVERGED, "-pod_method svd: no singular triplet converged (try another -pod_svd_type)");
  nconv = std::min(nconv, m);
  // Singular values not computed (-pod_svd_nsv < m, or not converged) are reported as 0; their
  // energy ||X||_F^2 - sum_{i<nconv} s_i^2 counts in every tail (the choice of N).
  PetscReal frob2 = 0, known = 0;
  for (const Vec &x : snapshots) {
    PetscReal nrm;
    PetscCall(VecNorm(x, NORM_2, &nrm));
    frob2 += nrm * nrm;
  }
  res->singularValues.assign(m, 0.0);
  for (PetscInt i = 0; i < nconv; ++i) {
    PetscCall(SVDGetSingularTriplet(svd, i, &res->singularValues[i], NULL, NULL));
    known += res->singularValues[i] * res->singularValues[i];
  }
  PetscCheck(res->singularValues[0] > 0, comm, PETSC_ERR_USER_INPUT, "POD: the snapshots are all zero");
  SelectSize(o, nconv < m ? std::max<PetscReal>(0.0, frob2 - known) : 0.0, res);
  res->N = std::min(res->N, nconv);

  const PetscInt N = res->N;
  PetscCall(BVCreate(comm, &res->modes));
  PetscCall(BVSetSizesFromVec(res->modes, snapshots[0], N));
  PetscCall(BVSetOptionsPrefix(res->modes, "pod_"));
  PetscCall(BVSetFromOptions(res->modes));
  PetscCall(MatCreateVecs(A, &v, NULL));
  PetscCall(VecScatterCreateToAll(v, &toall, &vall));
  for (PetscInt i = 0; i < N; ++i) {
    Vec                u;
    PetscReal          sigma;
    const PetscScalar *va;
    PetscCall(BVGetColumn(res->modes, i, &u));
    PetscCall(SVDGetSingularTriplet(svd, i, &sigma, u, v));
    PetscCall(VecScatterBegin(toall, v, vall, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(toall, v, vall, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecGetArrayRead(vall, &va));
    const PetscReal sg = SignOf(va, m);
    PetscCall(VecRestoreArrayRead(vall, &va));
    if (sg < 0) PetscCall(VecScale(u, -1.0));
    PetscCall(BVRestoreColumn(res->modes, i, &u));
  }
  PetscCall(VecScatterDestroy(&toall));
  PetscCall(VecDestroy(&vall));
  PetscCall(VecDestroy(&v));
  PetscCall(SVDDestroy(&svd));
  PetscCall(MatDestroy(&A));
  PetscFunctionReturn(0);
}

} // namespace

PODResult::PODResult(PODResult &&o) noexcept { *this = std::move(o); }

PODResult &PODResult::operator=(PODResult &&o) noexcept
{
  if (this != &o) {
    if (modes) (void)BVDestroy(&modes);
    modes                      = o.modes;
    o.modes                    = nullptr;
    singularValues             = std::move(o.singularValues);
    N                          = o.N;
    energyCaptured             = o.energyCaptured;
    orthonormalityError        = o.orthonormalityError;
    rank                       = o.rank;
    rankTol                    = o.rankTol;
    orthonormalityErrorInitial = o.orthonormalityErrorInitial;
    reorthonormalized          = o.reorthonormalized;
    method                     = std::move(o.method);
  }
  return *this;
}

PODResult::~PODResult()
{
  if (modes) (void)BVDestroy(&modes);
}

const char *PODInnerName(PODInner inner)
{
  return kInners[(int)inner];
}

PetscErrorCode PODCheckOptions(MPI_Comm comm)
{
  PODOptions o;

  PetscFunctionBeginUser;
  PetscCall(ReadOptions(comm, -1, nullptr, &o));
  PetscFunctionReturn(0);
}

PetscErrorCode PODInnerFromOptions(MPI_Comm comm, PODInner *inner)
{
  PetscInt i = 0;

  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, "pod_", "Proper orthogonal decomposition", "PODInnerFromOptions");
  PetscCall(PetscOptionsEList("-inner", "Inner product of the POD", "PODInnerFromOptions", kInners, 3, kInners[0], &i, NULL));
  PetscOptionsEnd();
  *inner = (PODInner)i;
  PetscFunctionReturn(0);
}

PetscErrorCode ComputePOD(const std::vector<Vec> &snapshots, Mat M, PODResult *res, PetscReal tol)
{
  MPI_Comm   comm;
  PODOptions o;

  PetscFunctionBeginUser;
  PetscCheck(!snapshots.empty(), PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "ComputePOD: no snapshots");
  PetscCall(PetscObjectGetComm((PetscObject)snapshots[0], &comm));
  const PetscInt m = (PetscInt)snapshots.size();
  PetscCall(BVInitializePackage());
  if (!POD_Event) PetscCall(PetscLogEventRegister("RBCPOD", BV_CLASSID, &POD_Event));
  PetscCall(ReadOptions(comm, m, M, &o));
  if (tol >= 0) {
    PetscCheck(tol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "ComputePOD: tolerance %g must lie in [0, 1)", (double)tol);
    o.tol = tol; // the caller's tolerance instead of -pod_tol (offline -estimate's enriched space)
  }
  if (M) {
    PetscInt mr, mc, nv;
    PetscCall(MatGetSize(M, &mr, &mc));
    PetscCall(VecGetSize(snapshots[0], &nv));
    PetscCheck(mr == nv && mc == nv, comm, PETSC_ERR_ARG_SIZ, "ComputePOD: inner-product matrix M is %" PetscInt_FMT " x %" PetscInt_FMT ", snapshots have length %" PetscInt_FMT, mr, mc, nv);
  }

  PetscCall(PetscLogEventBegin(POD_Event, 0, 0, 0, 0));
  *res         = PODResult();
  res->method  = kMethods[o.method];
  res->rankTol = o.rankTol;
  if (o.method == 0) PetscCall(PODSnapshots(comm, snapshots, M, o, res));
  else PetscCall(PODSvd(comm, snapshots, o, res));

  // Orthonormality in M; one re-orthonormalization pass (BVOrthogonalize, same inner product) if
  // X V S^{-1} is not orthonormal to kOrthoTol (rounding in C is amplified by s_0^2 / s_i s_j).
  PetscCall(OrthonormalityError(res->modes, &res->orthonormalityErrorInitial));
  res->orthonormalityError = res->orthonormalityErrorInitial;
  if (res->orthonormalityError > kOrthoTol) {
    PetscCall(BVOrthogonalize(res->modes, NULL));
    PetscCall(OrthonormalityError(res->modes, &res->orthonormalityError));
    res->reorthonormalized = PETSC_TRUE;
  }
  PetscCall(PetscLogEventEnd(POD_Event, 0, 0, 0, 0));

  if (o.svOut[0]) {
    PetscMPIInt rank;
    PetscCallMPI(MPI_Comm_rank(comm, &rank));
    PetscErrorCode ierr = 0;
    if (rank == 0) {
      FILE *fp = std::fopen(o.svOut, "w");
      if (!fp) ierr = 1;
      else {
        for (PetscReal s : res->singularValues) std::fprintf(fp, "%.17e\n", (double)s);
        if (std::fclose(fp)) ierr = 1;
      }
    }
    PetscCallMPI(MPI_Bcast(&ierr, 1, MPI_INT, 0, comm));
    PetscCheck(!ierr, comm, PETSC_ERR_FILE_OPEN, "-pod_sv_out %s: cannot write the file", o.svOut);
  }
  if (o.view) {
    PetscCall(PetscPrintf(comm, "POD (%s, inner %s): %" PetscInt_FMT " snapshots, numerical rank %" PetscInt_FMT " (rank_tol %.2e), N = %" PetscInt_FMT ", energy captured 1 - %.3e\n", res->method.c_str(), M ? (o.innerSet ? kInners[o.inner] : "M") : "l2", m, res->rank, (double)res->rankTol, res->N, (double)(1 - res->energyCaptured)));
    PetscCall(PetscPrintf(comm, "  orthonormality max|V^T M V - I| = %.3e%s\n", (double)res->orthonormalityError, res->reorthonormalized ? " (after BVOrthogonalize)" : ""));
    PetscCall(PetscPrintf(comm, "  singular values:"));
    for (PetscInt i = 0; i < m; ++i) PetscCall(PetscPrintf(comm, " %.6e", (double)res->singularValues[i]));
    PetscCall(PetscPrintf(comm, "\n"));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode PODProjectionErrors(BV modes, const std::vector<Vec> &snapshots, std::vector<PetscReal> *errors)
{
  const PetscInt m = (PetscInt)snapshots.size();
  PetscInt       N;
  BV             R;
  Mat            P;

  PetscFunctionBeginUser;
  PetscCall(BVGetSizes(modes, NULL, NULL, &N));
  PetscCall(BVDuplicateResize(modes, m, &R)); // carries the modes' inner-product matrix
  for (PetscInt j = 0; j < m; ++j) PetscCall(BVInsertVec(R, j, snapshots[j]));
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, N, m, NULL, &P));
  PetscCall(BVDot(R, modes, P));               // P = V^T M X
  PetscCall(BVMult(R, -1.0, 1.0, modes, P));   // R = X - V P
  errors->resize(m);
  for (PetscInt j = 0; j < m; ++j) PetscCall(BVNormColumn(R, j, NORM_2, &(*errors)[j]));
  PetscCall(MatDestroy(&P));
  PetscCall(BVDestroy(&R));
  PetscFunctionReturn(0);
}

PetscInt PODSizeForTolerance(const PODResult &res, PetscReal tol)
{
  std::vector<PetscReal> left;
  return std::max<PetscInt>(1, std::min(TailSize(res.singularValues, 0.0, tol, &left), res.rank));
}

} // namespace rbc
