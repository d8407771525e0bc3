// tests/test_pod.cpp -- owns the tests of rbc::ComputePOD (src/reduction/pod.cpp):
//  a) synthetic: M = 5-point Laplacian + variable diagonal (MATAIJ, n = 2000, rows in natural
//     order, contiguous blocks per rank), m = 20 snapshots of rank 10 with weights 0.3^k. Asserts:
//     modes M-orthonormal to 1e-10; singular values == a dense serial reference on rank 0
//     (Cholesky M = U^T U, LAPACK dgesvd of U X) with |s_i^2 - r_i^2| <= 1e-10 s_0^2 for all i and
//     |s_i - r_i| <= 1e-10 s_i where s_i >= 1e-2 s_0; the numerical rank is 10; N from -pod_tol
//     (1e-3, 1e-8) and -pod_n is the one of the definition applied to the reference values;
//     sum_j ||x_j - V V^T M x_j||_M^2 == sum_{i>=N} s_i^2 (relative 1e-10 for -pod_tol 1e-3 and
//     -pod_n 4; 1e-10 s_0^2 absolute for the default 1e-8, whose tail is at the rounding level).
//  b) the FOM of the scene in the options (ring_on_block, -contact 0): M = A, snapshots = the elastic
//     solution and A^{-1} g_k for smooth nodal loads g_k(x) (partition independent), then (one-
//     parameter scenes) 12 elastic solutions u(mu) on a uniform grid of the box with M = A(mu_ref);
//     asserts energy orthonormality <= 1e-10 and the projection identity (1e-10 s_0^2 absolute).
//  c) -pod_inner l2: -pod_method svd (trlanczos, lapack; cross on a full-rank variant with 1e-3
//     noise) vs the BV path on the synthetic snapshots: same singular values (relative 1e-10 for s_i >= 1e-2 s_0, squares 1e-10 s_0^2 for
//     the rest of the numerical rank), same modes with the same signs (|1 - <v_bv, v_svd>| <= 1e-8).
//  d) partition independence: prints checksums (singular values, sum_k w_k v_i[k] of the synthetic
//     modes, sum of entries + sqrt(n) x 2-norm, and 2-norm of the FOM modes) and writes them with -test_out <file>;
//     -test_sv_out <file> sets -pod_sv_out for the FOM load POD (all singular values); the -test_out file
//     holds the modes and singular values with s_i >= 1e-2 s_0 only (the well-conditioned ones). `-compare a,b -compare_mode sv|rel
//     -compare_tol t` compares two such files (sv: |a_i^2 - b_i^2| <= t a_0^2; rel: relative t).
// Options: the scene options, -test_parts abc (subset), -test_out, -test_sv_out, -compare ...
#include "rbcontact/fom.hpp"
#include "rbcontact/pod.hpp"

#include <petscblaslapack.h>
#include <slepcsys.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace {

constexpr PetscInt  kNx = 50, kNy = 40, kN = kNx * kNy; // synthetic problem size
constexpr PetscInt  kM = 20, kK = 10;                     // snapshots, rank
constexpr PetscReal kOrtho = 1e-10;

bool g_ok = true;

PetscErrorCode Expect(MPI_Comm comm, bool cond, const char *what, double value, double tol)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(comm, "  %-62s %.3e (tol %.1e) %s\n", what, value, tol, cond ? "ok" : "FAILED"));
  if (!cond) g_ok = false;
  PetscFunctionReturn(0);
}

// Deterministic pseudo-random number in [-1, 1] from two integers (splitmix64 finalizer).
double Hash(std::uint64_t a, std::uint64_t b)
{
  std::uint64_t z = a * 0x9E3779B97F4A7C15ULL + b * 0xBF58476D1CE4E5B9ULL + 0x94D049BB133111EBULL;
  z               = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z               = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return 2.0 * (double)(z >> 11) * 0x1.0p-53 - 1.0;
}

// Row i of the synthetic SPD matrix: -Laplacian (Dirichlet 5-point, h = 1) + (1 + 0.5 sin i) I.
void MRow(PetscInt i, std::vector<PetscInt> *cols, std::vector<PetscScalar> *vals)
{
  const PetscInt ix = i % kNx, iy = i / kNx;
  cols->assign(1, i);
  vals->assign(1, 4.0 + 1.0 + 0.5 * std::sin((double)i));
  if (ix > 0) cols->push_back(i - 1), vals->push_back(-1.0);
  if (ix < kNx - 1) cols->push_back(i + 1), vals->push_back(-1.0);
  if (iy > 0) cols->push_back(i - kNx), vals->push_back(-1.0);
  if (iy < kNy - 1) cols->push_back(i + kNx), vals->push_back(-1.0);
}

// Snapshot j, entry i: sum_k 0.3^k c_jk phi_k(i), phi_k a smooth grid mode plus 10% hash noise.
double SnapshotEntry(PetscInt j, PetscInt i, double noise)
{
  const PetscInt ix = i % kNx, iy = i / kNx;
  double         x  = noise * Hash(5000 + j, i), w = 1;
  for (PetscInt k = 0; k < kK; ++k, w *= 0.3) {
    const double phi = std::sin(PETSC_PI * (1 + k % 4) * (ix + 1) / (kNx + 1)) * std::sin(PETSC_PI * (1 + k / 4) * (iy + 1) / (kNy + 1)) + 0.1 * Hash(1000 + k, i);
    x += w * Hash(j, k) * phi;
  }
  return x;
}

// noise > 0: plus noise * (hash in [-1, 1]) per entry (full rank).
PetscErrorCode BuildSynthetic(MPI_Comm comm, Mat *M, std::vector<Vec> *X, double noise = 0)
{
  PetscInt rs, re;

  PetscFunctionBeginUser;
  PetscCall(MatCreateAIJ(comm, PETSC_DECIDE, PETSC_DECIDE, kN, kN, 5, NULL, 2, NULL, M));
  PetscCall(MatGetOwnershipRange(*M, &rs, &re));
  std::vector<PetscInt>    cols;
  std::vector<PetscScalar> vals;
  for (PetscInt i = rs; i < re; ++i) {
    MRow(i, &cols, &vals);
    PetscCall(MatSetValues(*M, 1, &i, (PetscInt)cols.size(), cols.data(), vals.data(), INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(*M, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*M, MAT_FINAL_ASSEMBLY));
  X->resize(kM);
  for (PetscInt j = 0; j < kM; ++j) {
    PetscScalar *a;
    PetscCall(MatCreateVecs(*M, &(*X)[j], NULL));
    PetscCall(VecGetArray((*X)[j], &a));
    for (PetscInt i = rs; i < re; ++i) a[i - rs] = SnapshotEntry(j, i, noise);
    PetscCall(VecRestoreArray((*X)[j], &a));
  }
  PetscFunctionReturn(0);
}

// Reference singular values on rank 0 (broadcast): gather X, dense M from MRow, M = U^T U (dpotrf),
// singular values of U X (dgesvd). withM = false: of X itself (l2).
PetscErrorCode ReferenceSV(MPI_Comm comm, const std::vector<Vec> &X, bool withM, std::vector<PetscReal> *ref)
{
  PetscMPIInt rank;
  const PetscInt m = (PetscInt)X.size();

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  std::vector<PetscScalar> Xd(kN * m);
  for (PetscInt j = 0; j < m; ++j) {
    VecScatter         sc;
    Vec                v0;
    const PetscScalar *a;
    PetscCall(VecScatterCreateToZero(X[j], &sc, &v0));
    PetscCall(VecScatterBegin(sc, X[j], v0, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(sc, X[j], v0, INSERT_VALUES, SCATTER_FORWARD));
    if (rank == 0) {
      PetscCall(VecGetArrayRead(v0, &a));
      std::copy(a, a + kN, Xd.begin() + j * kN);
      PetscCall(VecRestoreArrayRead(v0, &a));
    }
    PetscCall(VecScatterDestroy(&sc));
    PetscCall(VecDestroy(&v0));
  }
  ref->assign(m, 0.0);
  if (rank == 0) {
    PetscBLASInt n, bm, info, lwork, one = 1;
    PetscCall(PetscBLASIntCast(kN, &n));
    PetscCall(PetscBLASIntCast(m, &bm));
    std::vector<PetscScalar> Y(kN * m);
    if (withM) {
      std::vector<PetscScalar> Md((size_t)kN * kN, 0.0);
      std::vector<PetscInt>    cols;
      std::vector<PetscScalar> vals;
      for (PetscInt i = 0; i < kN; ++i) {
        MRow(i, &cols, &vals);
        for (size_t c = 0; c < cols.size(); ++c) Md[i + (size_t)cols[c] * kN] = vals[c];
      }
      PetscCallBLAS("LAPACKpotrf", LAPACKpotrf_("U", &n, Md.data(), &n, &info));
      PetscCheck(info == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "dpotrf failed: %d", (int)info);
      // Y = U X, U upper triangular (column-major, stored in the upper part of Md).
      for (PetscInt j = 0; j < m; ++j)
        for (PetscInt i = 0; i < kN; ++i) {
          double s = 0;
          for (PetscInt k = i; k < kN; ++k) s += Md[i + (size_t)k * kN] * Xd[k + j * kN];
          Y[i + j * kN] = s;
        }
    } else Y = Xd;
    lwork = 10 * (kN + m);
    std::vector<PetscScalar> work(lwork);
    PetscCall(PetscFPTrapPush(PETSC_FP_TRAP_OFF));
    PetscCallBLAS("LAPACKgesvd", LAPACKgesvd_("N", "N", &n, &bm, Y.data(), &n, ref->data(), NULL, &one, NULL, &one, work.data(), &lwork, &info));
    PetscCall(PetscFPTrapPop());
    PetscCheck(info == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "dgesvd failed: %d", (int)info);
  }
  PetscCallMPI(MPI_Bcast(ref->data(), (int)m, MPIU_REAL, 0, comm));
  PetscFunctionReturn(0);
}

// Smallest N with sum_{i>=N} r_i^2 <= tol sum r_i^2 (the definition), capped by rank.
PetscInt ExpectedN(const std::vector<PetscReal> &r, PetscReal tol, PetscInt rank)
{
  const PetscInt m = (PetscInt)r.size();
  double         total = 0;
  for (PetscReal s : r) total += s * s;
  for (PetscInt N = 0; N <= m; ++N) {
    double tail = 0;
    for (PetscInt i = N; i < m; ++i) tail += r[i] * r[i];
    if (tail <= tol * total) return std::min(N, rank);
  }
  return std::min(m, rank);
}

PetscErrorCode SetOption(const char *name, const char *value)
{
  PetscFunctionBeginUser;
  if (value) PetscCall(PetscOptionsSetValue(NULL, name, value));
  else PetscCall(PetscOptionsClearValue(NULL, name));
  PetscFunctionReturn(0);
}

// Checks that hold for every POD: orthonormality, projection identity.
PetscErrorCode CheckPOD(MPI_Comm comm, const char *tag, const rbc::PODResult &pod, const std::vector<Vec> &X, PetscReal projRelTol)
{
  char                   what[128];
  std::vector<PetscReal> err;

  PetscFunctionBeginUser;
  std::snprintf(what, sizeof what, "%s: max|V^T M V - I| (initial %.1e%s)", tag, (double)pod.orthonormalityErrorInitial, pod.reorthonormalized ? ", reorth." : "");
  PetscCall(Expect(comm, pod.orthonormalityError <= kOrtho, what, pod.orthonormalityError, kOrtho));
  PetscCall(rbc::PODProjectionErrors(pod.modes, X, &err));
  double proj = 0, tail = 0, s0 = pod.singularValues[0];
  for (PetscReal e : err) proj += e * e;
  for (size_t i = pod.N; i < pod.singularValues.size(); ++i) tail += pod.singularValues[i] * pod.singularValues[i];
  if (projRelTol > 0) {
    std::snprintf(what, sizeof what, "%s: N=%d, |sum proj err^2 - tail| / tail", tag, (int)pod.N);
    const double rel = std::abs(proj - tail) / tail;
    PetscCall(Expect(comm, rel <= projRelTol, what, rel, projRelTol));
  } else {
    std::snprintf(what, sizeof what, "%s: N=%d, |sum proj err^2 - tail| / s_0^2 (tail/s0^2 %.1e)", tag, (int)pod.N, tail / (s0 * s0));
    const double rel = std::abs(proj - tail) / (s0 * s0);
    PetscCall(Expect(comm, rel <= 1e-10, what, rel, 1e-10));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode PartSynthetic(MPI_Comm comm, std::vector<double> *checksums)
{
  Mat                    M;
  std::vector<Vec>       X;
  std::vector<PetscReal> ref;
  PetscLogDouble         t0, t1, t2;
  char                   what[128];

  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(comm, "a) synthetic: n = %d, m = %d snapshots of rank %d, M = Laplacian + diag\n", (int)kN, (int)kM, (int)kK));
  PetscCall(BuildSynthetic(comm, &M, &X));
  PetscCall(PetscTime(&t0));
  PetscCall(ReferenceSV(comm, X, true, &ref));
  PetscCall(PetscTime(&t1));
  {
    rbc::PODResult pod;
    PetscCall(SetOption("-pod_inner", "energy"));
    PetscCall(rbc::ComputePOD(X, M, &pod));
    PetscCall(PetscTime(&t2));
    PetscCall(PetscPrintf(comm, "  reference (dense Cholesky + dgesvd on rank 0) %.3f s, ComputePOD %.3f s\n", t1 - t0, t2 - t1));
    PetscCall(PetscPrintf(comm, "  %3s %22s %22s %10s\n", "i", "s_i (POD)", "reference", "rel.diff"));
    double maxSq = 0, maxRel = 0;
    const double s0 = ref[0];
    for (PetscInt i = 0; i < kM; ++i) {
      const double s = pod.singularValues[i], r = ref[i], rel = std::abs(s - r) / r;
      if (i < pod.rank) PetscCall(PetscPrintf(comm, "  %3d %22.15e %22.15e %10.2e\n", (int)i, s, r, rel));
      else PetscCall(PetscPrintf(comm, "  %3d %22.15e %22.15e (below the numerical rank)\n", (int)i, s, r));
      maxSq = std::max(maxSq, std::abs(s * s - r * r) / (s0 * s0));
      if (r >= 1e-2 * s0) maxRel = std::max(maxRel, rel);
    }
    PetscCall(Expect(comm, maxSq <= 1e-10, "a: max_i |s_i^2 - r_i^2| / s_0^2", maxSq, 1e-10));
    PetscCall(Expect(comm, maxRel <= 1e-10, "a: max |s_i - r_i| / r_i over r_i >= 1e-2 s_0", maxRel, 1e-10));
    PetscCall(Expect(comm, pod.rank == kK, "a: numerical rank (expected 10)", (double)pod.rank, 0));
    {
      // the tolerance in effect: the library default 1e-8, or the scene's options file (-pod_tol)
      PetscReal tolEff = 1e-8;
      PetscCall(PetscOptionsGetReal(NULL, NULL, "-pod_tol", &tolEff, NULL));
      char what[96];
      std::snprintf(what, sizeof what, "a: N from -pod_tol %g (in effect) == definition", (double)tolEff);
      PetscCall(Expect(comm, pod.N == ExpectedN(ref, tolEff, kK), what, (double)pod.N, 0));
    }
    PetscCall(CheckPOD(comm, "a tol in effect", pod, X, 0));
    // d) checksums: singular values above the rank; w-weighted sums of the modes (natural order).
    Vec          w;
    PetscScalar *a;
    PetscInt     rs, re;
    PetscCall(VecDuplicate(X[0], &w));
    PetscCall(VecGetOwnershipRange(w, &rs, &re));
    PetscCall(VecGetArray(w, &a));
    for (PetscInt i = rs; i < re; ++i) a[i - rs] = 1 + i % 13;
    PetscCall(VecRestoreArray(w, &a));
    double csS = 0, csV = 0;
    for (PetscInt i = 0; i < pod.rank; ++i) csS += (i + 1) * pod.singularValues[i];
    // The file gets the well-conditioned part only (s_i >= 1e-2 s_0: 1 vs 2 ranks agree to ~1e-12;
    // mode i and s_i carry rounding ~ eps (s_0 / s_i)^2 from C = X^T M X).
    for (PetscInt i = 0; i < pod.N; ++i) {
      Vec         v;
      PetscScalar d;
      PetscCall(BVGetColumn(pod.modes, i, &v));
      PetscCall(VecDot(v, w, &d));
      PetscCall(BVRestoreColumn(pod.modes, i, &v));
      if (pod.singularValues[i] >= 1e-2 * pod.singularValues[0]) checksums->push_back(d), checksums->push_back(pod.singularValues[i]);
      csV += (i + 1) * d;
    }
    PetscCall(VecDestroy(&w));
    PetscCall(PetscPrintf(comm, "  checksum synthetic: sum (i+1) s_i = %.15e, sum (i+1) w.v_i = %.15e\n", csS, csV));
  }
  for (const char *tol : {"1e-3", "1e-8"}) {
    rbc::PODResult pod;
    PetscCall(SetOption("-pod_tol", tol));
    PetscCall(rbc::ComputePOD(X, M, &pod));
    PetscCall(SetOption("-pod_tol", NULL));
    const PetscInt N = ExpectedN(ref, std::atof(tol), kK);
    std::snprintf(what, sizeof what, "a: -pod_tol %s: N == %d (definition on the reference)", tol, (int)N);
    PetscCall(Expect(comm, pod.N == N, what, (double)pod.N, 0));
    std::snprintf(what, sizeof what, "a tol %s", tol);
    PetscCall(CheckPOD(comm, what, pod, X, std::atof(tol) >= 1e-3 ? 1e-10 : 0));
  }
  {
    rbc::PODResult pod;
    PetscCall(SetOption("-pod_n", "4"));
    PetscCall(rbc::ComputePOD(X, M, &pod));
    PetscCall(Expect(comm, pod.N == 4, "a: -pod_n 4: N", (double)pod.N, 0));
    PetscCall(CheckPOD(comm, "a n 4", pod, X, 1e-10));
    PetscCall(SetOption("-pod_n", "15"));
    PetscCall(rbc::ComputePOD(X, M, &pod));
    PetscCall(Expect(comm, pod.N == kK, "a: -pod_n 15 capped by the numerical rank 10", (double)pod.N, 0));
    PetscCall(CheckPOD(comm, "a n 15", pod, X, 0));
    PetscCall(SetOption("-pod_n", NULL));
  }
  PetscCall(SetOption("-pod_inner", NULL));
  for (Vec &v : X) PetscCall(VecDestroy(&v));
  PetscCall(MatDestroy(&M));
  PetscFunctionReturn(0);
}

// One snapshot set: the BV path vs -pod_method svd of each type.
PetscErrorCode SvdCase(MPI_Comm comm, double noise, const std::vector<const char *> &types)
{
  Mat                    M;
  std::vector<Vec>       X;
  std::vector<PetscReal> ref;
  rbc::PODResult         bv;
  char                   what[160], tag[64];

  PetscFunctionBeginUser;
  PetscCall(BuildSynthetic(comm, &M, &X, noise));
  PetscCall(ReferenceSV(comm, X, false, &ref));
  PetscCall(SetOption("-pod_inner", "l2"));
  PetscCall(SetOption("-pod_tol", "1e-12"));
  PetscCall(rbc::ComputePOD(X, nullptr, &bv));
  PetscCall(PetscPrintf(comm, "  snapshots with noise %.0e: numerical rank %d, s_min/s_0 = %.2e, N = %d (-pod_tol 1e-12)\n", noise, (int)bv.rank, bv.singularValues[kM - 1] / bv.singularValues[0], (int)bv.N));
  std::snprintf(tag, sizeof tag, "c noise %.0e bv", noise);
  PetscCall(CheckPOD(comm, tag, bv, X, 0));
  double maxRel = 0;
  for (PetscInt i = 0; i < bv.rank; ++i)
    if (ref[i] >= 1e-2 * ref[0]) maxRel = std::max(maxRel, std::abs(bv.singularValues[i] - ref[i]) / ref[i]);
  PetscCall(Expect(comm, maxRel <= 1e-10, "c: bv vs dgesvd of X: max rel. diff (s_i >= 1e-2 s_0)", maxRel, 1e-10));
  for (const char *type : types) {
    rbc::PODResult sv;
    PetscLogDouble t0, t1;
    PetscCall(SetOption("-pod_method", "svd"));
    PetscCall(SetOption("-pod_svd_type", type));
    PetscCall(PetscTime(&t0));
    PetscCall(rbc::ComputePOD(X, nullptr, &sv));
    PetscCall(PetscTime(&t1));
    PetscCall(SetOption("-pod_method", NULL));
    PetscCall(SetOption("-pod_svd_type", NULL));
    double relBig = 0, sq = 0, relRef = 0, dmax = 0;
    const double s0 = bv.singularValues[0];
    for (PetscInt i = 0; i < bv.rank; ++i) {
      const double a = bv.singularValues[i], b = sv.singularValues[i];
      if (a >= 1e-2 * s0) relBig = std::max(relBig, std::abs(a - b) / a);
      sq     = std::max(sq, std::abs(a * a - b * b) / (s0 * s0));
      relRef = std::max(relRef, std::abs(b - ref[i]) / ref[i]);
    }
    const PetscInt N = std::min(bv.N, sv.N);
    for (PetscInt i = 0; i < N; ++i) {
      Vec         a, b;
      PetscScalar d;
      PetscCall(BVGetColumn(bv.modes, i, &a));
      PetscCall(BVGetColumn(sv.modes, i, &b));
      PetscCall(VecDot(a, b, &d));
      PetscCall(BVRestoreColumn(sv.modes, i, &b));
      PetscCall(BVRestoreColumn(bv.modes, i, &a));
      dmax = std::max(dmax, std::abs(1.0 - (double)d));
    }
    PetscCall(PetscPrintf(comm, "  svd type %-9s: N %d (bv %d), %.3f s; max rel. diff of s_i (i < rank) vs the dgesvd reference %.2e\n", type, (int)sv.N, (int)bv.N, t1 - t0, relRef));
    std::snprintf(what, sizeof what, "c %s: max rel. diff of s_i >= 1e-2 s_0 vs bv", type);
    PetscCall(Expect(comm, relBig <= 1e-10, what, relBig, 1e-10));
    std::snprintf(what, sizeof what, "c %s: max |s_i^2 - s_bv,i^2| / s_0^2, i < rank", type);
    PetscCall(Expect(comm, sq <= 1e-10, what, sq, 1e-10));
    std::snprintf(what, sizeof what, "c %s: modes (same sign): max |1 - <v_bv, v_svd>|", type);
    PetscCall(Expect(comm, dmax <= 1e-8 && sv.N == bv.N, what, dmax, 1e-8));
    std::snprintf(tag, sizeof tag, "c noise %.0e %s", noise, type);
    PetscCall(CheckPOD(comm, tag, sv, X, 0));
  }
  PetscCall(SetOption("-pod_inner", NULL));
  PetscCall(SetOption("-pod_tol", NULL));
  for (Vec &v : X) PetscCall(VecDestroy(&v));
  PetscCall(MatDestroy(&M));
  PetscFunctionReturn(0);
}

PetscErrorCode PartSvd(MPI_Comm comm)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(comm, "c) -pod_inner l2: -pod_method svd vs bv on the synthetic snapshots\n"));
  // Rank 10 of 20: cross (eigenvalues of X^T X) fails on the zero singular values (SLEPc: "negative
  // eigenvalue computed by EPS"), so only on the full-rank set.
  PetscCall(SvdCase(comm, 0.0, {"trlanczos", "lapack"}));
  PetscCall(SvdCase(comm, 1e-3, {"cross", "trlanczos", "lapack"}));
  PetscFunctionReturn(0);
}

struct ParamLike {
  PetscReal lo, hi;
};

// Smooth nodal load k, component c at the position x (partition independent).
double LoadFn(PetscInt k, PetscInt c, const PetscReal x[])
{
  return std::sin((1 + k) * x[0] + 0.7 * c + 0.3 * k) * std::cos((1 + (k + c) % 3) * x[1]);
}

// g(free dof) = LoadFn(k, component, point position), the point position = mean of its closure's
// vertices (P1: the vertex, P2: the edge midpoint). Walks the owned points of the global section.
// (DMProjectFunction was the first choice; on 2 ranks it failed inside PetscFECreateTabulation on
// this DM, PETSc 3.18.5, not investigated.)
PetscErrorCode NodalLoad(const rbc::ElasticFOM &fom, PetscInt k, Vec g)
{
  DM                 dm = fom.dm, cdm;
  PetscSection       gsec, lsec, csec;
  Vec                coords;
  const PetscScalar *xc;
  PetscScalar       *ga;
  PetscInt           pStart, pEnd, rstart, dim = fom.elas.dim;

  PetscFunctionBeginUser;
  PetscCall(DMGetGlobalSection(dm, &gsec));
  PetscCall(DMGetLocalSection(dm, &lsec));
  PetscCall(DMGetCoordinateDM(dm, &cdm));
  PetscCall(DMGetLocalSection(cdm, &csec));
  PetscCall(DMGetCoordinatesLocal(dm, &coords));
  PetscCall(DMPlexGetChart(dm, &pStart, &pEnd));
  PetscCall(VecGetOwnershipRange(g, &rstart, NULL));
  PetscCall(VecGetArrayRead(coords, &xc));
  PetscCall(VecGetArray(g, &ga));
  for (PetscInt p = pStart; p < pEnd; ++p) {
    PetscInt dof, cdof, off;
    PetscCall(PetscSectionGetDof(lsec, p, &dof));
    PetscCall(PetscSectionGetConstraintDof(lsec, p, &cdof));
    PetscCall(PetscSectionGetOffset(gsec, p, &off));
    if (dof <= 0 || off < 0 || dof - cdof <= 0) continue; // no dofs, not owned, or fully constrained
    PetscInt *closure = NULL, ncl, nvert = 0;
    PetscReal x[3] = {0, 0, 0};
    PetscCall(DMPlexGetTransitiveClosure(dm, p, PETSC_TRUE, &ncl, &closure));
    for (PetscInt q = 0; q < ncl; ++q) {
      PetscInt cd, co;
      PetscCall(PetscSectionGetDof(csec, closure[2 * q], &cd));
      if (!cd) continue;
      PetscCall(PetscSectionGetOffset(csec, closure[2 * q], &co));
      for (PetscInt d = 0; d < dim; ++d) x[d] += PetscRealPart(xc[co + d]);
      ++nvert;
    }
    PetscCall(DMPlexRestoreTransitiveClosure(dm, p, PETSC_TRUE, &ncl, &closure));
    for (PetscInt d = 0; d < dim; ++d) x[d] /= nvert;
    const PetscInt *cind = NULL;
    PetscCall(PetscSectionGetConstraintIndices(lsec, p, &cind));
    PetscInt gi = off - rstart;
    for (PetscInt c = 0; c < dof; ++c) {
      bool constrained = false;
      for (PetscInt q = 0; q < cdof; ++q)
        if (cind && cind[q] == c) constrained = true;
      if (!constrained) ga[gi++] = LoadFn(k, c % dim, x);
    }
  }
  PetscCall(VecRestoreArray(g, &ga));
  PetscCall(VecRestoreArrayRead(coords, &xc));
  PetscFunctionReturn(0);
}

PetscErrorCode PartFOM(MPI_Comm comm, const char *svOut, std::vector<double> *checksums)
{
  rbc::SceneSpec   scene;
  rbc::ElasticFOM  fom;
  std::vector<Vec> X;
  const PetscInt   m = 10;
  PetscLogDouble   t0, t1, t2;

  PetscFunctionBeginUser;
  PetscCall(rbc::SceneSpecFromOptions(comm, &scene));
  PetscCheck(!scene.contact, comm, PETSC_ERR_USER_INPUT, "test_pod part b solves the elastic FOM only: pass -contact 0");
  PetscCall(PetscTime(&t0));
  PetscCall(fom.Create(comm, scene));
  PetscCall(fom.AssembleAndFactor());
  PetscCall(fom.SolveElastic());
  X.resize(m);
  PetscCall(VecDuplicate(fom.u, &X[0]));
  PetscCall(VecCopy(fom.u, X[0]));
  for (PetscInt k = 1; k < m; ++k) {
    Vec g;
    PetscCall(VecDuplicate(fom.u, &g));
    PetscCall(NodalLoad(fom, k, g));
    PetscCall(VecDuplicate(fom.u, &X[k]));
    PetscCall(fom.ApplyInverse(g, X[k]));
    PetscCall(VecDestroy(&g));
  }
  PetscCall(PetscTime(&t1));
  {
    rbc::PODResult pod;
    PetscCall(SetOption("-pod_inner", "energy"));
    if (svOut[0]) PetscCall(SetOption("-pod_sv_out", svOut));
    PetscCall(rbc::ComputePOD(X, fom.A, &pod));
    PetscCall(SetOption("-pod_sv_out", NULL));
    PetscCall(SetOption("-pod_inner", NULL));
    PetscCall(PetscTime(&t2));
    PetscCall(PetscPrintf(comm, "b) FOM %s: %d dofs, m = %d snapshots (u and A^-1 g_k), energy inner product\n", scene.name.c_str(), (int)fom.GlobalSize(), (int)m));
    PetscCall(PetscPrintf(comm, "  FOM setup + solves %.3f s, ComputePOD %.3f s; N = %d, rank %d, energy captured 1 - %.2e\n", t1 - t0, t2 - t1, (int)pod.N, (int)pod.rank, 1 - pod.energyCaptured));
    PetscCall(PetscPrintf(comm, "  singular values:"));
    for (PetscReal s : pod.singularValues) PetscCall(PetscPrintf(comm, " %.6e", (double)s));
    PetscCall(PetscPrintf(comm, "\n"));
    PetscCall(CheckPOD(comm, "b FOM energy", pod, X, 0));
    // Partition-independent checksums: sum of entries and 2-norm of each mode.
    double csS = 0, csSum = 0, csNorm = 0;
    for (PetscInt i = 0; i < pod.rank; ++i) csS += (i + 1) * pod.singularValues[i];
    for (PetscInt i = 0; i < pod.N; ++i) {
      Vec         v;
      PetscScalar s;
      PetscReal   nrm;
      PetscCall(BVGetColumn(pod.modes, i, &v));
      PetscCall(VecSum(v, &s));
      PetscCall(VecNorm(v, NORM_2, &nrm));
      PetscInt nent;
      PetscCall(VecGetSize(v, &nent));
      PetscCall(BVRestoreColumn(pod.modes, i, &v));
      // sum(v_i) + sqrt(n) |v_i|_2 >= 0 (Cauchy-Schwarz): the sum alone can cancel to ~1e-4 of its terms
      // (a mode of mixed sign), which turns a round-off difference of the mode into a large relative one
      if (pod.singularValues[i] >= 1e-2 * pod.singularValues[0]) checksums->push_back(PetscRealPart(s) + std::sqrt((double)nent) * nrm), checksums->push_back(nrm);
      csSum += (i + 1) * s;
      csNorm += (i + 1) * nrm;
    }
    PetscCall(PetscPrintf(comm, "  checksum FOM: sum (i+1) s_i = %.15e, sum (i+1) sum(v_i) = %.15e, sum (i+1) |v_i|_2 = %.15e\n", csS, csSum, csNorm));
  }
  for (Vec &v : X) PetscCall(VecDestroy(&v));

  // Parametric snapshots u(mu) (the reference-configuration map: same dofs for every mu) in the
  // energy inner product of A(mu_ref): the POD of the offline stage.
  if (scene.params.size() == 1) {
    const PetscInt mp = 12;
    Mat            Aref;
    PetscCall(MatDuplicate(fom.A, MAT_COPY_VALUES, &Aref));
    X.assign(mp, nullptr);
    PetscCall(PetscTime(&t0));
    for (PetscInt k = 0; k < mp; ++k) {
      const ParamLike p{scene.params[0].min, scene.params[0].max};
      PetscCall(fom.SetMu({p.lo + (p.hi - p.lo) * k / (mp - 1)}));
      PetscCall(fom.AssembleAndFactor());
      PetscCall(fom.SolveElastic());
      PetscCall(VecDuplicate(fom.u, &X[k]));
      PetscCall(VecCopy(fom.u, X[k]));
    }
    PetscCall(PetscTime(&t1));
    rbc::PODResult pod;
    PetscCall(SetOption("-pod_inner", "energy"));
    PetscCall(rbc::ComputePOD(X, Aref, &pod));
    PetscCall(SetOption("-pod_inner", NULL));
    PetscCall(PetscTime(&t2));
    PetscCall(PetscPrintf(comm, "b) FOM %s: m = %d snapshots u(%s) on [%g, %g], energy inner product of A(%s = %g)\n", scene.name.c_str(), (int)mp, scene.params[0].name.c_str(), (double)scene.params[0].min, (double)scene.params[0].max, scene.params[0].name.c_str(), (double)scene.params[0].def));
    PetscCall(PetscPrintf(comm, "  %d assemblies + factorizations + solves %.3f s, ComputePOD %.3f s; N = %d (-pod_tol 1e-8), rank %d, energy captured 1 - %.2e\n", (int)mp, t1 - t0, t2 - t1, (int)pod.N, (int)pod.rank, 1 - pod.energyCaptured));
    PetscCall(PetscPrintf(comm, "  s_i / s_0:"));
    for (PetscReal sv : pod.singularValues) PetscCall(PetscPrintf(comm, " %.2e", (double)(sv / pod.singularValues[0])));
    PetscCall(PetscPrintf(comm, "\n"));
    PetscCall(CheckPOD(comm, "b FOM u(mu)", pod, X, 0));
    for (PetscInt i = 0; i < pod.N; ++i) {
      Vec         v;
      PetscScalar sum;
      PetscReal   nrm;
      PetscCall(BVGetColumn(pod.modes, i, &v));
      PetscCall(VecSum(v, &sum));
      PetscCall(VecNorm(v, NORM_2, &nrm));
      PetscInt nent;
      PetscCall(VecGetSize(v, &nent));
      PetscCall(BVRestoreColumn(pod.modes, i, &v));
      if (pod.singularValues[i] >= 1e-2 * pod.singularValues[0]) checksums->push_back(PetscRealPart(sum) + std::sqrt((double)nent) * nrm), checksums->push_back(nrm);
    }
    for (Vec &v : X) PetscCall(VecDestroy(&v));
    PetscCall(MatDestroy(&Aref));
  }
  PetscFunctionReturn(0);
}

// Compares two files of numbers (one per line).
PetscErrorCode Compare(MPI_Comm comm, const std::string &files, const char *mode, PetscReal tol)
{
  PetscFunctionBeginUser;
  const auto comma = files.find(',');
  PetscCheck(comma != std::string::npos, comm, PETSC_ERR_USER_INPUT, "-compare %s: expected two files a,b", files.c_str());
  std::vector<double> v[2];
  const std::string   name[2] = {files.substr(0, comma), files.substr(comma + 1)};
  for (int f = 0; f < 2; ++f) {
    std::ifstream in(name[f]);
    PetscCheck(in, comm, PETSC_ERR_FILE_OPEN, "-compare: cannot read %s", name[f].c_str());
    double x;
    while (in >> x) v[f].push_back(x);
  }
  PetscCheck(v[0].size() == v[1].size() && !v[0].empty(), comm, PETSC_ERR_USER_INPUT, "-compare: %s has %zu numbers, %s has %zu", name[0].c_str(), v[0].size(), name[1].c_str(), v[1].size());
  const bool sv = std::string(mode) == "sv";
  double     worst = 0;
  for (size_t i = 0; i < v[0].size(); ++i) {
    const double a = v[0][i], b = v[1][i];
    const double d = sv ? std::abs(a * a - b * b) / (v[0][0] * v[0][0]) : std::abs(a - b) / std::max(std::abs(a), 1e-300);
    worst          = std::max(worst, d);
  }
  char what[160];
  std::snprintf(what, sizeof what, "%zu numbers, %s mode: max difference", v[0].size(), mode);
  PetscCall(Expect(comm, worst <= tol, what, worst, tol));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  char      parts[16] = "abc", out[PETSC_MAX_PATH_LEN] = "", svOut[PETSC_MAX_PATH_LEN] = "", cmp[2 * PETSC_MAX_PATH_LEN] = "", mode[8] = "rel";
  PetscBool isCompare;
  PetscReal tol = 1e-9;
  PetscMPIInt size, rank;

  PetscCall(SlepcInitialize(&argc, &argv, NULL, "tests of rbc::ComputePOD\n"));
  MPI_Comm comm = PETSC_COMM_WORLD;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-test_parts", parts, sizeof parts, NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-test_out", out, sizeof out, NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-test_sv_out", svOut, sizeof svOut, NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-compare", cmp, sizeof cmp, &isCompare));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-compare_mode", mode, sizeof mode, NULL));
  PetscCall(PetscOptionsGetReal(NULL, NULL, "-compare_tol", &tol, NULL));
  PetscLogDouble t0, t1;
  PetscCall(PetscTime(&t0));
  if (isCompare) PetscCall(Compare(comm, cmp, mode, tol));
  else {
    std::vector<double> checksums;
    const std::string   p(parts);
    PetscCall(PetscPrintf(comm, "test_pod: %d rank(s)\n", size));
    if (p.find('a') != std::string::npos) PetscCall(PartSynthetic(comm, &checksums));
    if (p.find('b') != std::string::npos) PetscCall(PartFOM(comm, svOut, &checksums));
    if (p.find('c') != std::string::npos) PetscCall(PartSvd(comm));
    if (out[0] && rank == 0) {
      FILE *fp = std::fopen(out, "w");
      PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "-test_out %s: cannot write", out);
      for (double c : checksums) std::fprintf(fp, "%.17e\n", c);
      std::fclose(fp);
    }
  }
  PetscCall(PetscTime(&t1));
  PetscCall(PetscPrintf(comm, "test_pod: %s (%.2f s)\n", g_ok ? "passed" : "FAILED", t1 - t0));
  PetscCall(SlepcFinalize());
  return g_ok ? 0 : 1;
}
