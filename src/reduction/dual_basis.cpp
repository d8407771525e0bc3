// src/reduction/dual_basis.cpp: the nonnegative dual bases (nmf, angle, cpg, mcpg) built from the
// multiplier snapshots, the cone projection errors, mcpg's constrained projection (LSI -> LDP -> NNLS),
// cond(W^T W), the dual_ options and the RBCDualBasis log event. All dense, on PETSC_COMM_SELF data:
// every rank computes the same basis bit for bit (no rank-dependent data, seeded splitmix64 for NMF).
#include "rbcontact/dual_basis.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace rbc {

static PetscLogEvent DUAL_Build = 0;

namespace {

// splitmix64 (Steele, Lea, Flood 2014): the same stream on every platform and compiler.
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t Next()
  {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z               = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z               = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  double Uniform() { return (double)(Next() >> 11) * 0x1.0p-53; } // [0, 1)
};

PetscReal VecNormOf(const PetscReal *v, PetscInt n, bool linf)
{
  PetscReal s = 0;
  for (PetscInt i = 0; i < n; ++i) s = linf ? std::max(s, std::abs(v[i])) : s + v[i] * v[i];
  return linf ? s : std::sqrt(s);
}

void AppendColumn(DenseMatrix *W, const std::vector<PetscReal> &v)
{
  W->a.insert(W->a.end(), v.begin(), v.end());
  W->cols += 1;
}

// C (m x n) = op(A) op(B), column-major, reference BLAS (deterministic).
void Gemm(const char *ta, const char *tb, PetscInt m, PetscInt n, PetscInt k, const PetscReal *A, PetscInt lda, const PetscReal *B, PetscInt ldb, PetscReal *C)
{
  PetscBLASInt    M = (PetscBLASInt)m, N = (PetscBLASInt)n, K = (PetscBLASInt)k, LDA = (PetscBLASInt)lda, LDB = (PetscBLASInt)ldb, LDC = (PetscBLASInt)m;
  const PetscReal one = 1, zero = 0;
  if (!m || !n) return;
  if (!k) { std::fill(C, C + (size_t)m * n, 0.0); return; }
  BLASgemm_(ta, tb, &M, &N, &K, &one, A, &LDA, B, &LDB, &zero, C, &LDC);
}

// Least-squares residuals of every column of L from the span of W (Householder QR of W).
PetscErrorCode SpanProjectionErrors(const DenseMatrix &W, const DenseMatrix &L, bool linf, std::vector<PetscReal> *err)
{
  const PetscInt R = L.rows, m = L.cols, n = W.cols;

  PetscFunctionBeginUser;
  err->assign(m, 0.0);
  std::vector<PetscReal> Res(L.a);
  if (n > 0 && n <= R) {
    std::vector<PetscReal> A(W.a), tau(n), work(64 * (size_t)(n + m + 1));
    PetscBLASInt           RR = (PetscBLASInt)R, nn = (PetscBLASInt)n, mm = (PetscBLASInt)m, lw = (PetscBLASInt)work.size(), info = 0;
    LAPACKgeqrf_(&RR, &nn, A.data(), &RR, tau.data(), work.data(), &lw, &info);
    PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_LIB, "LAPACK geqrf failed (info %d)", (int)info);
    LAPACKormqr_("L", "T", &RR, &mm, &nn, A.data(), &RR, tau.data(), Res.data(), &RR, work.data(), &lw, &info);
    PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_LIB, "LAPACK ormqr failed (info %d)", (int)info);
    for (PetscInt j = 0; j < m; ++j)
      for (PetscInt i = 0; i < n; ++i) Res[i + (size_t)j * R] = 0;
    LAPACKormqr_("L", "N", &RR, &mm, &nn, A.data(), &RR, tau.data(), Res.data(), &RR, work.data(), &lw, &info);
    PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_LIB, "LAPACK ormqr failed (info %d)", (int)info);
  } else if (n > R) {
    std::fill(Res.begin(), Res.end(), 0.0); // more columns than rows: the greedy never gets here with independent picks
  }
  for (PetscInt j = 0; j < m; ++j) (*err)[j] = VecNormOf(&Res[(size_t)j * R], R, linf);
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode GramConditionNumber(const DenseMatrix &W, PetscReal *cond)
{
  const PetscInt R = W.rows, n = W.cols;

  PetscFunctionBeginUser;
  *cond = n ? 0 : 1;
  if (!n) PetscFunctionReturn(0);
  std::vector<PetscReal> G((size_t)n * n), ev(n), work(64 * (size_t)n);
  Gemm("T", "N", n, n, R, W.a.data(), R, W.a.data(), R, G.data());
  PetscBLASInt nn = (PetscBLASInt)n, lw = (PetscBLASInt)work.size(), info = 0;
  LAPACKsyev_("N", "U", &nn, G.data(), &nn, ev.data(), work.data(), &lw, &info);
  PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_LIB, "LAPACK syev on the Gram matrix failed (info %d)", (int)info);
  // numerically singular Gram matrix (lambda_min at the rounding level of lambda_max): inf
  *cond = ev[0] > (PetscReal)n * PETSC_MACHINE_EPSILON * ev[n - 1] ? ev[n - 1] / ev[0] : PETSC_INFINITY;
  PetscFunctionReturn(0);
}

PetscErrorCode ConeProjectionErrors(const DenseMatrix &W, const DenseMatrix &L, bool linf, std::vector<PetscReal> *err, NNLSStats *stats, NNLSSolver *solver, std::vector<std::vector<PetscReal>> *warm)
{
  const PetscInt         R = L.rows, m = L.cols;
  NNLSSolver             local;
  NNLSSolver            *s = solver;
  std::vector<PetscReal> b(R), x, r(R);

  PetscFunctionBeginUser;
  PetscCheck(W.rows == R || W.cols == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "Cone projection: W has %" PetscInt_FMT " rows, the snapshots %" PetscInt_FMT, W.rows, R);
  if (!s) {
    PetscCall(local.SetFromOptions());
    s = &local;
  }
  err->assign(m, 0.0);
  for (PetscInt j = 0; j < m; ++j) {
    std::copy(&L.a[(size_t)j * R], &L.a[(size_t)j * R] + R, b.begin());
    if (W.cols == 0) { (*err)[j] = VecNormOf(b.data(), R, linf); continue; }
    if (warm) {
      if ((PetscInt)warm->size() != m) warm->assign(m, {});
      (*warm)[j].resize(W.cols, 0.0); // columns added since the last projection start at 0
      PetscCall(s->Solve(W, b, &x, stats, nullptr, &(*warm)[j]));
      (*warm)[j] = x;
    } else PetscCall(s->Solve(W, b, &x, stats));
    r = b;
    for (PetscInt k = 0; k < W.cols; ++k)
      if (x[k] != 0)
        for (PetscInt i = 0; i < R; ++i) r[i] -= W(i, k) * x[k];
    (*err)[j] = VecNormOf(r.data(), R, linf);
  }
  PetscCall(local.Reset());
  PetscFunctionReturn(0);
}

// min ||W y - theta|| s.t. y >= 0, W y <= theta, by Lawson & Hanson (Solving Least Squares Problems,
// ch. 23): LSI -> LDP -> NNLS. With W = Q1 R1 (QR), z = R1 y - Q1^T theta turns it into the least-distance
// problem min ||z|| s.t. G R1^{-1} z >= h - G y_ls (G = [I; -W], h = [0; -theta], y_ls = R1^{-1} Q1^T theta),
// solved by one NNLS: u = argmin_{u >= 0} ||[A^T; c^T] u - e_{n+1}||, z = -r_{1..n} / r_{n+1}.
// A rank-deficient W is regularized as [W; 1e-8 I] (changes the objective by <= 1e-16 ||theta||^2, since
// ||y|| <= ||W y|| <= ||theta|| for nonnegative unit columns).
static PetscErrorCode LowerProjectionLDP(const DenseMatrix &W, const std::vector<PetscReal> &theta, std::vector<PetscReal> *upsilon, PetscReal *remainderMin)
{
  const PetscInt R = W.rows, n = W.cols;
  PetscReal      tn = 0;

  PetscFunctionBeginUser;
  PetscCheck((PetscInt)theta.size() == R || n == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "mcpg: theta has %zu entries, W has %" PetscInt_FMT " rows", theta.size(), R);
  upsilon->assign(theta.size(), 0.0);
  for (PetscReal v : theta) tn += v * v;
  tn = std::sqrt(tn);
  if (remainderMin) *remainderMin = 0;
  if (tn == 0 || n == 0) {
    if (remainderMin && tn > 0) {
      PetscReal mn = 0;
      for (PetscReal v : theta) mn = std::min(mn, v / tn);
      *remainderMin = mn;
    }
    PetscFunctionReturn(0);
  }
  std::vector<PetscReal> t(R);
  for (PetscInt i = 0; i < R; ++i) t[i] = theta[i] / tn;

  // QR of E = W (or [W; delta I] if W is numerically rank deficient)
  PetscInt               Me = R;
  std::vector<PetscReal> E(W.a), tau(n), work(64 * (size_t)(n + 1));
  PetscBLASInt           nn = (PetscBLASInt)n, one = 1, lw = (PetscBLASInt)work.size(), info = 0;
  auto                   factor = [&](bool *fullRank) {
    PetscBLASInt MM = (PetscBLASInt)Me;
    LAPACKgeqrf_(&MM, &nn, E.data(), &MM, tau.data(), work.data(), &lw, &info);
    PetscReal dmax = 0, dmin = PETSC_MAX_REAL;
    for (PetscInt k = 0; k < n; ++k) { dmax = std::max(dmax, std::abs(E[k + (size_t)k * Me])); dmin = std::min(dmin, std::abs(E[k + (size_t)k * Me])); }
    *fullRank = info == 0 && dmin > 1e-10 * dmax;
  };
  bool fullRank = false;
  if (n <= R) factor(&fullRank);
  if (!fullRank) {
    const PetscReal delta = 1e-8;
    Me                    = R + n;
    E.assign((size_t)Me * n, 0.0);
    for (PetscInt k = 0; k < n; ++k) {
      for (PetscInt i = 0; i < R; ++i) E[i + (size_t)k * Me] = W(i, k);
      E[R + k + (size_t)k * Me] = delta;
    }
    factor(&fullRank);
    PetscCheck(info == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "mcpg: LAPACK geqrf failed (info %d)", (int)info);
  }
  // f1 = Q1^T f, f = [t; 0]
  std::vector<PetscReal> f(Me, 0.0);
  std::copy(t.begin(), t.end(), f.begin());
  {
    PetscBLASInt MM = (PetscBLASInt)Me;
    LAPACKormqr_("L", "T", &MM, &one, &nn, E.data(), &MM, tau.data(), f.data(), &MM, work.data(), &lw, &info);
    PetscCheck(info == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "mcpg: LAPACK ormqr failed (info %d)", (int)info);
  }
  std::vector<PetscReal> f1(f.begin(), f.begin() + n);
  // Rinv = R1^{-1} (n x n)
  std::vector<PetscReal> Rinv((size_t)n * n, 0.0);
  for (PetscInt k = 0; k < n; ++k) Rinv[k + (size_t)k * n] = 1;
  {
    PetscBLASInt MM = (PetscBLASInt)Me;
    LAPACKtrtrs_("U", "N", "N", &nn, &nn, E.data(), &MM, Rinv.data(), &nn, &info);
    PetscCheck(info == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "mcpg: LAPACK trtrs failed (info %d)", (int)info);
  }
  std::vector<PetscReal> yls(n, 0.0), WRinv((size_t)R * n), Wyls(R);
  Gemm("N", "N", n, 1, n, Rinv.data(), n, f1.data(), n, yls.data());
  Gemm("N", "N", R, n, n, W.a.data(), R, Rinv.data(), n, WRinv.data());
  Gemm("N", "N", R, 1, n, W.a.data(), R, yls.data(), n, Wyls.data());
  // LDP: A z >= c, A = [Rinv; -W Rinv] ((n+R) x n), c = [-y_ls; W y_ls - t]; NNLS matrix [A^T; c^T]
  const PetscInt mc = n + R;
  DenseMatrix    Ep;
  Ep.Resize(n + 1, mc);
  for (PetscInt i = 0; i < n; ++i) { // constraint y_i >= 0
    for (PetscInt k = 0; k < n; ++k) Ep(k, i) = Rinv[i + (size_t)k * n];
    Ep(n, i) = -yls[i];
  }
  for (PetscInt i = 0; i < R; ++i) { // constraint (W y)_i <= t_i
    for (PetscInt k = 0; k < n; ++k) Ep(k, n + i) = -WRinv[i + (size_t)k * R];
    Ep(n, n + i) = Wyls[i] - t[i];
  }
  std::vector<PetscReal> fp(n + 1, 0.0), u(mc, 0.0);
  fp[n] = 1;
  PetscInt its;
  PetscCall(NNLSLawsonHanson(Ep, fp, &u, 5 * mc + 50, &its));
  std::vector<PetscReal> rp(fp);
  for (PetscReal &v : rp) v = -v;
  for (PetscInt j = 0; j < mc; ++j)
    if (u[j] != 0)
      for (PetscInt k = 0; k <= n; ++k) rp[k] += Ep(k, j) * u[j];
  PetscCheck(std::abs(rp[n]) > 1e-14, PETSC_COMM_SELF, PETSC_ERR_NOT_CONVERGED, "mcpg: the least-distance problem reports incompatible constraints (|r_n+1| = %g), but y = 0 is feasible", (double)std::abs(rp[n]));
  std::vector<PetscReal> zf(n), y(n);
  for (PetscInt k = 0; k < n; ++k) zf[k] = -rp[k] / rp[n] + f1[k];
  Gemm("N", "N", n, 1, n, Rinv.data(), n, zf.data(), n, y.data());
  for (PetscReal &v : y) v = std::max((PetscReal)0, v); // y >= 0 up to rounding: keep Upsilon in the cone
  std::vector<PetscReal> Wy(R);
  Gemm("N", "N", R, 1, n, W.a.data(), R, y.data(), n, Wy.data());
  PetscReal mn = PETSC_MAX_REAL;
  for (PetscInt i = 0; i < R; ++i) {
    (*upsilon)[i] = tn * Wy[i];
    mn            = std::min(mn, t[i] - Wy[i]);
  }
  if (remainderMin) *remainderMin = mn;
  PetscFunctionReturn(0);
}


PetscErrorCode ConeLowerProjection(const DenseMatrix &W, const std::vector<PetscReal> &theta, std::vector<PetscReal> *upsilon, PetscReal *remainderMin, PetscReal *ldpViolation)
{
  const PetscInt R = W.rows, n = W.cols;

  PetscFunctionBeginUser;
  PetscCheck((PetscInt)theta.size() == R || n == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "mcpg: theta has %zu entries, W has %" PetscInt_FMT " rows", theta.size(), R);
  // Exact reduction: where theta_i = 0, sum_j W_ij y_j <= 0 with W, y >= 0 forces y_j = 0 for every
  // column with W_ij > 0. Drop those columns, then the rows where no column is left nonzero (their
  // constraint 0 <= theta_i and residual theta_i are fixed). This keeps Upsilon exactly 0 outside the
  // support of theta instead of at the rounding level of the LDP solution.
  std::vector<char> dropCol(n, 0), keepRow(R, 0);
  for (PetscInt i = 0; i < R; ++i)
    if (theta[i] <= 0)
      for (PetscInt j = 0; j < n; ++j)
        if (W(i, j) > 0) dropCol[j] = 1;
  std::vector<PetscInt> cols, rows;
  for (PetscInt j = 0; j < n; ++j) if (!dropCol[j]) cols.push_back(j);
  for (PetscInt i = 0; i < R; ++i)
    for (PetscInt j : cols)
      if (W(i, j) > 0) { keepRow[i] = 1; break; }
  for (PetscInt i = 0; i < R; ++i) if (keepRow[i]) rows.push_back(i);
  DenseMatrix Wr;
  Wr.Resize((PetscInt)rows.size(), (PetscInt)cols.size());
  std::vector<PetscReal> tr(rows.size()), ur;
  for (size_t k = 0; k < cols.size(); ++k)
    for (size_t l = 0; l < rows.size(); ++l) Wr((PetscInt)l, (PetscInt)k) = W(rows[l], cols[k]);
  for (size_t l = 0; l < rows.size(); ++l) tr[l] = theta[rows[l]];
  PetscCall(LowerProjectionLDP(Wr, tr, &ur, NULL));
  upsilon->assign(R, 0.0);
  for (size_t l = 0; l < rows.size(); ++l) (*upsilon)[rows[l]] = ur[l];
  // Feasibility restoration: the LDP solution violates Upsilon <= theta at the rounding level amplified
  // by cond(W) (measured 2e-10 ||theta|| at cond(W^T W) ~ 5e16). Upsilon is scaled by
  // s = min(1, min_i theta_i / Upsilon_i) <= 1: still in the cone, now below theta (Upsilon_i = 0
  // wherever theta_i <= 0 thanks to the reduction above, so s is close to 1 when the violation is small).
  PetscReal tn = 0, viol = 0, sc = 1;
  for (PetscReal v : theta) tn += v * v;
  tn = std::sqrt(tn);
  for (PetscInt i = 0; i < R; ++i)
    if ((*upsilon)[i] > theta[i]) {
      viol = std::max(viol, (*upsilon)[i] - theta[i]);
      sc   = std::min(sc, theta[i] > 0 ? theta[i] / (*upsilon)[i] : 0.0);
    }
  if (sc < 1)
    for (PetscReal &v : *upsilon) v *= sc;
  if (ldpViolation) *ldpViolation = tn > 0 ? viol / tn : 0;
  if (remainderMin) {
    PetscReal mn = 0;
    for (PetscInt i = 0; i < R; ++i) mn = std::min(mn, theta[i] - (*upsilon)[i]);
    *remainderMin = tn > 0 ? mn / tn : 0;
  }
  PetscFunctionReturn(0);
}

// --- NMF -------------------------------------------------------------------------------------------

static PetscErrorCode BuildNMF(const DenseMatrix &L, PetscInt r, PetscInt seed, PetscReal rtol, PetscInt maxit, PetscBool monitor, DualBasisResult *res)
{
  const PetscInt R = L.rows, m = L.cols;
  PetscReal      smax = 0, mean = 0;

  PetscFunctionBeginUser;
  for (PetscReal v : L.a) { smax = std::max(smax, v); mean += v; }
  PetscCheck(smax > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "-dual_type nmf: the snapshot matrix has no positive entry");
  // work on L / max(L): scale-invariant iterations (SI pressures ~1e8 and epsilon in the denominators)
  std::vector<PetscReal> Ls(L.a);
  for (PetscReal &v : Ls) v /= smax;
  mean /= smax * (PetscReal)R * (PetscReal)m;
  const PetscReal scale = std::sqrt(mean / (PetscReal)r), eps = 1e-15;
  SplitMix64      rng{(std::uint64_t)seed};
  std::vector<PetscReal> W((size_t)R * r), H((size_t)r * m);
  for (PetscReal &v : W) v = scale * rng.Uniform();
  for (PetscReal &v : H) v = scale * rng.Uniform();
  std::vector<PetscReal> WtL((size_t)r * m), WtW((size_t)r * r), WtWH((size_t)r * m), LHt((size_t)R * r), HHt((size_t)r * r), WHHt((size_t)R * r), WH((size_t)R * m);
  PetscReal              fprev = -1;
  res->history.clear();
  for (PetscInt it = 0; it < maxit; ++it) {
    // H <- H .* (W^T L) ./ (W^T W H + eps)
    Gemm("T", "N", r, m, R, W.data(), R, Ls.data(), R, WtL.data());
    Gemm("T", "N", r, r, R, W.data(), R, W.data(), R, WtW.data());
    Gemm("N", "N", r, m, r, WtW.data(), r, H.data(), r, WtWH.data());
    for (size_t k = 0; k < H.size(); ++k) H[k] *= WtL[k] / (WtWH[k] + eps);
    // W <- W .* (L H^T) ./ (W H H^T + eps)
    Gemm("N", "T", R, r, m, Ls.data(), R, H.data(), r, LHt.data());
    Gemm("N", "T", r, r, m, H.data(), r, H.data(), r, HHt.data());
    Gemm("N", "N", R, r, r, W.data(), R, HHt.data(), r, WHHt.data());
    for (size_t k = 0; k < W.size(); ++k) W[k] *= LHt[k] / (WHHt[k] + eps);
    Gemm("N", "N", R, m, r, W.data(), R, H.data(), r, WH.data());
    PetscReal f = 0;
    for (size_t k = 0; k < WH.size(); ++k) f += (Ls[k] - WH[k]) * (Ls[k] - WH[k]);
    f = std::sqrt(f);
    res->history.push_back(f * smax);
    if (monitor && (it % 100 == 0)) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "  nmf %5" PetscInt_FMT "  ||L - W H||_F %.6e (relative %.3e)\n", it, (double)(f * smax), (double)(f / std::max(fprev, f))));
    if (fprev > 0 && std::abs(fprev - f) < rtol * fprev) break;
    if (f == 0) break;
    fprev = f;
  }
  // unit columns of W, H scaled accordingly
  res->W.Resize(R, r);
  for (PetscInt k = 0; k < r; ++k) {
    PetscReal nk = 0;
    for (PetscInt i = 0; i < R; ++i) nk += W[i + (size_t)k * R] * W[i + (size_t)k * R];
    nk = std::sqrt(nk);
    for (PetscInt i = 0; i < R; ++i) res->W(i, k) = nk > 0 ? W[i + (size_t)k * R] / nk : 0;
  }
  if (monitor) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "  nmf done after %zu iterations: ||L - W H||_F %.6e\n", res->history.size(), (double)res->history.back()));
  PetscFunctionReturn(0);
}

// --- BuildDualBasis --------------------------------------------------------------------------------

PetscErrorCode DualBasisOptionsFromOptions(MPI_Comm comm, DualBasisOptions *o)
{
  PetscFunctionBeginUser;
  *o = DualBasisOptions();
  PetscOptionsBegin(comm, "dual_", "Dual (multiplier) basis", "BuildDualBasis");
  PetscCall(PetscOptionsEList("-type", "Basis construction", "BuildDualBasis", kDualTypes, 4, kDualTypes[o->type], &o->type, NULL));
  PetscCall(PetscOptionsEList("-norm", "Norm of the projection errors (greedy selection, tolerance, trainMaxErr)", "BuildDualBasis", kDualNorms, 2, kDualNorms[o->norm], &o->norm, NULL));
  PetscCall(PetscOptionsReal("-tol", "Greedy tolerance on the largest projection error", "BuildDualBasis", o->tol, &o->tol, NULL));
  PetscCall(PetscOptionsBool("-tol_relative", "-dual_tol is relative to the largest snapshot norm", "BuildDualBasis", o->tolRelative, &o->tolRelative, NULL));
  PetscCall(PetscOptionsInt("-max_r", "Largest greedy basis size (default: the number of snapshots)", "BuildDualBasis", o->maxR, &o->maxR, NULL));
  PetscCall(PetscOptionsInt("-r", "NMF rank", "BuildDualBasis", o->r, &o->r, NULL));
  PetscCall(PetscOptionsInt("-seed", "NMF initialization seed (splitmix64)", "BuildDualBasis", o->seed, &o->seed, NULL));
  PetscCall(PetscOptionsReal("-nmf_rtol", "NMF: stop when the relative change of ||L - W H||_F is below", "BuildDualBasis", o->nmfRtol, &o->nmfRtol, NULL));
  PetscCall(PetscOptionsInt("-nmf_max_it", "NMF: maximum multiplicative updates", "BuildDualBasis", o->nmfMaxIt, &o->nmfMaxIt, NULL));
  PetscCall(PetscOptionsReal("-mcpg_feas_tol", "mcpg: accepted violation of theta - Upsilon >= 0, relative to ||theta||", "BuildDualBasis", o->feasTol, &o->feasTol, NULL));
  PetscCall(PetscOptionsReal("-max_cond", "Greedy: a pick that would make cond(W^T W) exceed this is skipped (a vector in the span of W but outside its cone)", "BuildDualBasis", o->maxCond, &o->maxCond, NULL));
  PetscCall(PetscOptionsBool("-monitor", "Print step, selected snapshot, largest error, cond(W^T W)", "BuildDualBasis", o->monitor, &o->monitor, NULL));
  PetscOptionsEnd();
  // (-dual_tol 1 with -dual_tol_relative kept no vector, and the error came later from the supremizers: "0 supremizers
  // for 0 dual vectors", naming no option)
  PetscCheck(o->tol >= 0 && std::isfinite(o->tol), comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_tol %g must be a finite number >= 0", (double)o->tol);
  PetscCheck(!o->tolRelative || o->tol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_tol %g with -dual_tol_relative must be < 1 (a fraction of the largest multiplier snapshot's norm: 1 keeps no dual vector)", (double)o->tol);
  PetscCheck(o->maxCond >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_max_cond %g must be >= 1", (double)o->maxCond);
  PetscCheck(o->maxR == -1 || o->maxR >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_max_r %" PetscInt_FMT " must be >= 1", o->maxR);
  PetscCheck(o->r >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_r %" PetscInt_FMT " must be >= 1", o->r);
  PetscCheck(o->nmfRtol >= 0 && o->nmfMaxIt >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_nmf_rtol %g must be >= 0 and -dual_nmf_max_it %" PetscInt_FMT " >= 1", (double)o->nmfRtol, o->nmfMaxIt);
  PetscCheck(o->seed >= 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_seed %" PetscInt_FMT " must be >= 0", o->seed);
  PetscFunctionReturn(0);
}

PetscErrorCode BuildDualBasis(const DenseMatrix &L, DualBasisResult *res, PetscReal tolOverride)
{
  static const char *const *types = kDualTypes, *const *norms = kDualNorms;
  DualBasisOptions          o;
  const PetscInt            R = L.rows, m = L.cols;

  PetscFunctionBeginUser;
  if (!DUAL_Build) PetscCall(PetscLogEventRegister("RBCDualBasis", TAO_CLASSID, &DUAL_Build));
  PetscCall(DualBasisOptionsFromOptions(PETSC_COMM_SELF, &o));
  const PetscInt  type = o.type, norm = o.norm, r = o.r, seed = o.seed, nmfMaxIt = o.nmfMaxIt;
  PetscInt        maxR = o.maxR > 0 ? o.maxR : L.cols;
  PetscReal       tol  = o.tol;
  const PetscReal nmfRtol = o.nmfRtol, feasTol = o.feasTol, maxCond = o.maxCond;
  const PetscBool tolRelative = o.tolRelative, monitor = o.monitor;
  if (tolOverride >= 0) tol = tolOverride; // the caller's tolerance (offline -estimate's enriched space), relative with -dual_tol_relative
  PetscCheck(R > 0 && m > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "Dual basis: empty snapshot matrix (%" PetscInt_FMT " x %" PetscInt_FMT ")", R, m);
  PetscCheck(tol >= 0 && (!tolRelative || tol < 1), PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "dual basis tolerance %g must be >= 0 (and < 1 with -dual_tol_relative)", (double)tol);
  PetscCheck(type != 0 || (r >= 1 && r <= std::min(R, m)), PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-dual_r %" PetscInt_FMT " must lie in [1, min(R, m)] = [1, %" PetscInt_FMT "]", r, std::min(R, m));
  for (PetscReal v : L.a) PetscCheck(v >= 0 && std::isfinite(v), PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "Dual basis: the multiplier snapshots must be finite and >= 0 (found %g)", (double)v);
  maxR = std::min(maxR, m);

  PetscCall(PetscLogEventBegin(DUAL_Build, 0, 0, 0, 0));
  const bool linf = norm == 0;
  *res            = DualBasisResult();
  res->type       = types[type];
  res->norm       = norms[norm];
  NNLSSolver nnls;
  PetscCall(nnls.SetFromOptions());

  std::vector<PetscReal> snapNorm(m), err(m);
  for (PetscInt j = 0; j < m; ++j) snapNorm[j] = VecNormOf(&L.a[(size_t)j * R], R, linf);
  res->initialMaxErr = *std::max_element(snapNorm.begin(), snapNorm.end());
  {
    // (entries whose squares overflow or underflow in the cone projections gave r = 0 with exit 0; snapshots all zero
    // a later error naming no cause)
    const PetscReal big = *std::max_element(L.a.begin(), L.a.end());
    PetscCheck(big > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "Dual basis: every multiplier snapshot is zero (no contact at any training parameter?)");
    PetscCheck(big < 1e150 && big > 1e-150, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "Dual basis: the largest multiplier is %g, outside [1e-150, 1e150] where the cone projections' squares stay finite and nonzero: scale the snapshots", (double)big);
  }
  res->tolAbs        = tolRelative ? tol * res->initialMaxErr : tol;
  res->W.Resize(R, 0);

  if (type == 0) {
    PetscCall(BuildNMF(L, r, seed, nmfRtol, nmfMaxIt, monitor, res));
    PetscReal c;
    PetscCall(GramConditionNumber(res->W, &c));
    res->gramCond.push_back(c);
    PetscCall(ConeProjectionErrors(res->W, L, linf, &err, &res->nnls, &nnls));
  } else {
    // greedy: the empty basis projects every snapshot to 0
    err                      = snapNorm;
    const PetscReal nothing  = 1e-13 * res->initialMaxErr; // "the pick adds nothing"
    std::vector<char> picked(m, 0);
    std::vector<std::vector<PetscReal>> warmX; // per snapshot, its cone projection at the previous step
    res->mcpgMinRemainder = 0;
    if (monitor) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "  dual %s (%s): step 0, largest snapshot norm %.6e, tolerance %.3e\n", types[type], norms[norm], (double)res->initialMaxErr, (double)res->tolAbs));
    while (true) {
      const PetscReal curMax = *std::max_element(err.begin(), err.end());
      if (curMax <= res->tolAbs || res->W.cols >= maxR) break;
      PetscInt j = -1;
      for (PetscInt k = 0; k < m; ++k)
        if (!picked[k] && (j < 0 || err[k] > err[j])) j = k;
      if (j < 0 || err[j] <= nothing) break;
      std::vector<PetscReal> v(&L.a[(size_t)j * R], &L.a[(size_t)j * R] + R);
      if (type == 3) {
        std::vector<PetscReal> ups;
        PetscReal              rmin;
        PetscReal              viol;
        PetscCall(ConeLowerProjection(res->W, v, &ups, &rmin, &viol));
        res->mcpgMaxLDPViolation = std::max(res->mcpgMaxLDPViolation, viol);
        PetscCheck(rmin >= -feasTol, PETSC_COMM_SELF, PETSC_ERR_NOT_CONVERGED, "mcpg step %" PetscInt_FMT ": theta - Upsilon has an entry %g ||theta|| < -dual_mcpg_feas_tol %g", res->W.cols + 1, (double)rmin, (double)feasTol);
        res->mcpgMinRemainder = std::min(res->mcpgMinRemainder, rmin);
        for (PetscInt i = 0; i < R; ++i) v[i] = std::max((PetscReal)0, v[i] - ups[i]);
      }
      PetscReal vn = VecNormOf(v.data(), R, false);
      if (!(vn > 1e-13 * VecNormOf(&L.a[(size_t)j * R], R, false))) break;
      for (PetscReal &x : v) x /= vn;
      AppendColumn(&res->W, v);
      picked[j] = 1;
      PetscReal c;
      PetscCall(GramConditionNumber(res->W, &c));
      if (!(c <= maxCond)) { // (nearly) in the span of W but outside its cone: W^T W would be singular
        res->W.cols -= 1;
        res->W.a.resize((size_t)R * res->W.cols);
        res->skipped.push_back(j);
        if (monitor) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "  dual %s: snapshot %4" PetscInt_FMT " skipped: it would make cond(W^T W) %.3e > -dual_max_cond %.3e\n", types[type], j, (double)c, (double)maxCond));
        continue;
      }
      res->selected.push_back(j);
      if (type == 1) PetscCall(SpanProjectionErrors(res->W, L, linf, &err));
      else PetscCall(ConeProjectionErrors(res->W, L, linf, &err, &res->nnls, &nnls, &warmX)); // warm: the previous step's projections
      res->history.push_back(*std::max_element(err.begin(), err.end()));
      res->gramCond.push_back(c);
      if (monitor) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "  dual %s: step %3" PetscInt_FMT "  snapshot %4" PetscInt_FMT "  largest error %.6e  cond(W^T W) %.3e\n", types[type], res->W.cols, j, (double)res->history.back(), (double)c));
    }
    // angle: the final errors are those of the cone (NNLS), not of the span
    if (type == 1) PetscCall(ConeProjectionErrors(res->W, L, linf, &err, &res->nnls, &nnls));
  }
  res->trainErr    = err;
  res->trainMaxErr = *std::max_element(err.begin(), err.end());
  res->trainMaxRelErr = 0;
  for (PetscInt j = 0; j < m; ++j)
    if (snapNorm[j] > 0) res->trainMaxRelErr = std::max(res->trainMaxRelErr, err[j] / snapNorm[j]);
  if (monitor)
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "  dual %s: R = %" PetscInt_FMT ", cone projection error max %.6e (relative %.3e); NNLS solves %" PetscInt_FMT ", retries %" PetscInt_FMT ", failures %" PetscInt_FMT ", worst KKT %.2e\n", types[type], res->W.cols, (double)res->trainMaxErr,
                          (double)res->trainMaxRelErr, res->nnls.solves, res->nnls.retries, res->nnls.failures, (double)res->nnls.maxKKT));
  PetscCall(nnls.Reset());
  PetscCall(PetscLogEventEnd(DUAL_Build, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

} // namespace rbc
