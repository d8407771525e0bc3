// src/reduction/empirical_cubature.cpp: the Gram matrix of the cubature fit and the sparse NNLS
// (Lawson-Hanson in Gram form, stopped at the tolerance) that picks the points and their weights.
// See include/rbcontact/empirical_cubature.hpp and docs/hyper_reduction.md.
#include "rbcontact/empirical_cubature.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <functional>
#include <cmath>

namespace rbc {

static PetscLogEvent CUB_Gram = 0, CUB_Fit = 0; // -log_view: the cubature's Gram systems and its fits

PetscErrorCode CubatureOptionsFromOptions(MPI_Comm comm, const char *pre, CubatureOptions *opt)
{
  PetscBool flg = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, pre, "Empirical cubature of the reduced contact terms", "rbcontact");
  {
    const char *fits[] = {"terms", "action", "lambda"};
    PetscInt    f      = (PetscInt)opt->fit;
    PetscCall(PetscOptionsEList("-fit", "what the fit measures: K^' lambda and K^ v - g^ at the training solutions (action), the same with K^ v - g^ by the multiplier error it causes (lambda), or every entry of K^, g^ (terms)", "", fits, 3, fits[f], &f, NULL));
    opt->fit = (CubatureFit)f;
  }
  flg = opt->fitForce ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscOptionsBool("-fit_force", "with -fit action or lambda: fit the resultant contact force too (the online stage's output of interest)", "", flg, &flg, NULL));
  opt->fitForce = flg;
  flg = opt->lambdaForce ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscOptionsBool("-fit_lambda_force", "with -fit lambda: also the multiplier error caused by the contact forces' error through the displacement", "", flg, &flg, NULL));
  opt->lambdaForce = flg;
  PetscCall(PetscOptionsReal("-tol", "relative residual of the fitted reduced terms", "", opt->tol, &opt->tol, NULL));
  PetscCall(PetscOptionsInt("-max_points", "largest number of cubature points", "", opt->maxPoints, &opt->maxPoints, NULL));
  PetscCall(PetscOptionsInt("-group_points", "more quadrature points than this: fit groups of at most this many points, then their union against every point's terms (0: one Gram matrix of every point)", "", opt->groupPoints, &opt->groupPoints, NULL));
  flg = opt->monitor ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscOptionsBool("-monitor", "print the residual per added point", "", flg, &flg, NULL));
  opt->monitor = flg;
  flg = opt->shareGroups ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscOptionsBool("-share_groups", "with groups (-group_points): each group fitted by one rank, in turn, its points broadcast (false: every rank fits every group; the same result)", "", flg, &flg, NULL));
  opt->shareGroups = flg;
  flg = opt->eliminate ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscOptionsBool("-eliminate", "after the fit, remove points one at a time while the others, refitted, still reach -tol (fewer points online)", "", flg, &flg, NULL));
  opt->eliminate = flg;
  PetscCall(PetscOptionsReal("-eliminate_from", "with -eliminate: the fit goes on to this fraction of -tol, then the elimination thins it back to -tol", "", opt->eliminateFrom, &opt->eliminateFrom, NULL));
  PetscOptionsEnd();
  PetscCheck(opt->eliminateFrom > 0 && opt->eliminateFrom <= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%seliminate_from %g must lie in (0, 1]", pre, (double)opt->eliminateFrom);
  PetscCheck(opt->tol > 0 && opt->tol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%stol %g must lie in (0, 1)", pre, (double)opt->tol);
  PetscCheck(opt->maxPoints >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%smax_points %" PetscInt_FMT " must be >= 1", pre, opt->maxPoints);
  PetscCheck(opt->groupPoints == 0 || opt->groupPoints >= 100, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%sgroup_points %" PetscInt_FMT " must be 0 (one group) or >= 100", pre, opt->groupPoints);
  PetscFunctionReturn(0);
}

// Cholesky factor (lower, in place, n x n column-major) of a symmetric positive semidefinite matrix, regularized by a
// ridge of 1e-12, then 1e-9, of its largest diagonal entry when rounding makes it indefinite; false if even that fails.
static bool FactorRegularized(PetscInt n, std::vector<PetscReal> *A)
{
  if (n == 0) return true;
  const std::vector<PetscReal> A0 = *A;
  PetscReal                    dmax = 0;
  for (PetscInt i = 0; i < n; ++i) dmax = std::max(dmax, A0[i + (size_t)n * i]);
  const PetscBLASInt m = (PetscBLASInt)n;
  for (PetscReal ridge : {0.0, 1e-12, 1e-9}) {
    *A = A0;
    for (PetscInt i = 0; i < n; ++i) (*A)[i + (size_t)n * i] += ridge * dmax;
    PetscBLASInt info = 0;
    LAPACKpotrf_("L", &m, A->data(), &m, &info);
    if (info == 0) return true;
  }
  return false;
}

PetscInt CubatureLambdaWeights(PetscInt R, PetscInt N, const PetscReal *A, const PetscReal *K, const PetscReal *lam, const std::vector<PetscReal> &M, std::vector<PetscReal> *T, std::vector<PetscReal> *C)
{
  std::vector<PetscInt> F;
  for (PetscInt r = 0; r < R; ++r)
    if (lam[r] > 0) F.push_back(r);
  const PetscInt k = (PetscInt)F.size();
  T->assign((size_t)k * R, 0.0);
  if (C) C->clear();
  if (k == 0) return 0;
  // Y = A^{-1} K_F' (N x k), S = K_F Y
  std::vector<PetscReal> LA(A, A + (size_t)N * N), Y((size_t)N * k), S((size_t)k * k, 0.0), LM((size_t)k * k), Z((size_t)k * k, 0.0);
  if (!FactorRegularized(N, &LA)) {
    T->clear();
    return 0;
  }
  for (PetscInt c = 0; c < k; ++c)
    for (PetscInt n = 0; n < N; ++n) Y[n + (size_t)N * c] = K[F[c] + (size_t)R * n];
  const PetscBLASInt nn = (PetscBLASInt)N, kk = (PetscBLASInt)k;
  PetscBLASInt       info = 0;
  LAPACKpotrs_("L", &nn, &kk, LA.data(), &nn, Y.data(), &nn, &info);
  for (PetscInt b = 0; b < k; ++b)
    for (PetscInt a = 0; a < k; ++a)
      for (PetscInt n = 0; n < N; ++n) S[a + (size_t)k * b] += K[F[a] + (size_t)R * n] * Y[n + (size_t)N * b];
  for (PetscInt b = 0; b < k; ++b)
    for (PetscInt a = 0; a < k; ++a) LM[a + (size_t)k * b] = M[(size_t)F[a] * R + F[b]];
  if (!FactorRegularized(k, &S) || !FactorRegularized(k, &LM)) {
    T->clear();
    return 0;
  }
  for (PetscInt i = 0; i < k; ++i) Z[i + (size_t)k * i] = 1;
  LAPACKpotrs_("L", &kk, &kk, S.data(), &kk, Z.data(), &kk, &info); // Z = S^{-1}
  for (PetscInt i = 0; i < k; ++i) // T_F = L_M' Z, rows i, columns F
    for (PetscInt c = 0; c < k; ++c) {
      PetscReal t = 0;
      for (PetscInt l = i; l < k; ++l) t += LM[l + (size_t)k * i] * Z[l + (size_t)k * c];
      (*T)[(size_t)i * R + F[c]] = t;
    }
  if (C) { // C = T_F Y' = L_M' S^{-1} K_F A^{-1}
    C->assign((size_t)k * N, 0.0);
    for (PetscInt i = 0; i < k; ++i)
      for (PetscInt c = 0; c < k; ++c) {
        const PetscReal t = (*T)[(size_t)i * R + F[c]];
        for (PetscInt n = 0; n < N; ++n) (*C)[(size_t)i * N + n] += t * Y[n + (size_t)N * c];
      }
  }
  return k;
}

PetscInt CubatureLambdaForceFactor(PetscInt N, const std::vector<std::vector<PetscReal>> &C, std::vector<PetscReal> *Fg)
{
  std::vector<PetscReal> G((size_t)N * N, 0.0);
  PetscInt               cnt = 0;
  for (const auto &Cj : C) {
    const size_t k = Cj.size() / std::max<PetscInt>(N, 1);
    if (k == 0) continue;
    ++cnt;
    for (size_t i = 0; i < k; ++i)
      for (PetscInt a = 0; a < N; ++a) {
        const PetscReal ca = Cj[i * N + a];
        if (ca == 0.0) continue;
        for (PetscInt b = 0; b < N; ++b) G[a + (size_t)N * b] += ca * Cj[i * N + b];
      }
  }
  Fg->clear();
  if (cnt == 0 || N == 0) return 0;
  for (auto &x : G) x /= cnt;
  std::vector<PetscReal> ev(N), work(1);
  const PetscBLASInt     nn = (PetscBLASInt)N;
  PetscBLASInt           lwork = -1, info = 0;
  LAPACKsyev_("V", "U", &nn, G.data(), &nn, ev.data(), work.data(), &lwork, &info);
  lwork = (PetscBLASInt)work[0];
  work.resize((size_t)std::max<PetscBLASInt>(lwork, 1));
  LAPACKsyev_("V", "U", &nn, G.data(), &nn, ev.data(), work.data(), &lwork, &info);
  if (info != 0 || !(ev[N - 1] > 0)) return 0;
  std::vector<PetscInt> keep;
  for (PetscInt i = N - 1; i >= 0 && ev[i] > 1e-8 * ev[N - 1]; --i) keep.push_back(i);
  const PetscInt r = (PetscInt)keep.size();
  Fg->assign((size_t)N * r, 0.0);
  for (PetscInt c = 0; c < r; ++c) {
    const PetscReal sq = std::sqrt(ev[keep[c]]);
    for (PetscInt n = 0; n < N; ++n) (*Fg)[(size_t)n * r + c] = sq * G[n + (size_t)N * keep[c]];
  }
  return r;
}

namespace {
// The reduced terms of one state, K (R x N, row-major) = sum_p xi_p P(:, p) kappa(p, :) and g likewise,
// over the points pts with weights xi (pts empty: every point, xi = 1).
void ReducedTerms(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const PetscReal *kap, const PetscReal *gam, const std::vector<PetscInt> &pts, const std::vector<PetscReal> &xi, std::vector<PetscReal> *K, std::vector<PetscReal> *g)
{
  K->assign((size_t)R * N, 0.0);
  g->assign(R, 0.0);
  const PetscInt M = pts.empty() ? Q : (PetscInt)pts.size();
  for (PetscInt r = 0; r < R; ++r)
    for (PetscInt j = 0; j < M; ++j) {
      const PetscInt  p  = pts.empty() ? j : pts[j];
      const PetscReal pr = (pts.empty() ? 1.0 : xi[j]) * P[(size_t)r * Q + p];
      if (pr == 0.0) continue;
      (*g)[r] += pr * gam[p];
      for (PetscInt n = 0; n < N; ++n) (*K)[(size_t)r * N + n] += pr * kap[(size_t)p * N + n];
    }
}

PetscReal SumSquares(const std::vector<PetscReal> &v)
{
  PetscReal s = 0;
  for (PetscReal x : v) s += x * x;
  return s;
}

// States per block: the block's columns within about 64 MB (at least one state), or all when block > 0 says so.
PetscInt StatesPerBlock(PetscInt Q, PetscInt per, PetscInt ms, PetscInt block)
{
  if (block > 0) return std::min(block, std::max<PetscInt>(ms, 1));
  const size_t bytes = (size_t)Q * std::max<PetscInt>(per, 1) * sizeof(PetscReal);
  return std::max<PetscInt>(1, std::min<PetscInt>(std::max<PetscInt>(ms, 1), (PetscInt)((64u << 20) / std::max<size_t>(bytes, 1))));
}

PetscInt gramColumnBlock = 0; // SetCubatureGramColumnBlock (tests); 0: by memory

// H (n x n, column-major) += GA o (X X') for X (n x k, leading dimension n), X X' formed a block of columns at a time
// (n / 8 of them, at least 64; W the block's scratch): no second n x n matrix beside GA and H, so that the Gram system
// of n points takes about 2.25 n^2 doubles, not 3 (the finest 3D level's final fit: docs/hyper_reduction.md "Memory").
static void AddHadamardProductColumns(PetscInt n, PetscInt k, const PetscReal *X, const PetscReal *GA, PetscReal *H, std::vector<PetscReal> *W)
{
  if (n <= 0 || k <= 0) return;
  const PetscInt jb = gramColumnBlock > 0 ? std::min(gramColumnBlock, n) : std::min<PetscInt>(n, std::max<PetscInt>(64, n / 8)); // W: n^2 / 8
  W->resize((size_t)n * jb);
  const PetscBLASInt m = (PetscBLASInt)n, kk = (PetscBLASInt)k;
  const PetscReal    one = 1, zero = 0;
  for (PetscInt j0 = 0; j0 < n; j0 += jb) {
    const PetscBLASInt nj = (PetscBLASInt)std::min(jb, n - j0);
    BLASgemm_("N", "T", &m, &nj, &kk, &one, X, &m, X + j0, &m, &zero, W->data(), &m);
    for (PetscInt j = 0; j < nj; ++j) {
      const PetscReal *ga = GA + (size_t)n * (j0 + j), *w = W->data() + (size_t)n * j;
      PetscReal       *h  = H + (size_t)n * (j0 + j);
      for (PetscInt i = 0; i < n; ++i) h[i] += ga[i] * w[i];
    }
  }
}

// H += (A A') o (B B') for A (Q x ka) and B (Q x kb), column-major: the Gram matrix of the fitting rows
// whose coefficient of point p is A(p, a) B(p, b) (a Hadamard product of two Gram matrices, two GEMMs).
void AddHadamardGramBlocks(PetscInt Q, const PetscReal *A, PetscInt ka, PetscInt ms, PetscInt per, PetscInt block, const std::function<void(PetscInt, PetscInt, PetscReal *)> &fill, std::vector<PetscReal> *H, CubatureCandidates *cand);

void AddHadamardGram(PetscInt Q, const PetscReal *A, PetscInt ka, const PetscReal *B, PetscInt kb, std::vector<PetscReal> *H, CubatureCandidates *cand)
{
  if (ka <= 0 || kb <= 0) return;
  if (cand && !cand->points.empty()) { // one block holding every column
    AddHadamardGramBlocks(Q, A, ka, kb, 1, StatesPerBlock(Q, 1, kb, 0), [&](PetscInt c0, PetscInt cnt, PetscReal *Bb) { std::copy(B + (size_t)Q * c0, B + (size_t)Q * (c0 + cnt), Bb); }, H, cand);
    return;
  }
  std::vector<PetscReal> GA((size_t)Q * Q), W;
  const PetscBLASInt     q = (PetscBLASInt)Q, a = (PetscBLASInt)ka;
  const PetscReal        one = 1, zero = 0;
  BLASgemm_("N", "T", &q, &q, &a, &one, A, &q, A, &q, &zero, GA.data(), &q);
  AddHadamardProductColumns(Q, kb, B, GA.data(), H->data(), &W);
}

// H += (A A') o (sum_b B_b B_b'), the columns B_b produced a block at a time by fill(first, count, B_b) (column-major
// Q x (count * per)): the same Gram matrix as AddHadamardGram on all the columns at once (to rounding) without
// holding them: the states' columns are the offline stage's largest objects in 3D (docs/rom3d.md).
// On candidate points C (cand->points): H_CC += (A_C A_C') o (sum_b B_b,C B_b,C'), and over every point the
// target's pieces b_C += ((A A') o (sum_b B_b B_b')) 1 restricted to C (= rows C of A o (B T), T = B'A) and
// c += 1'((A A') o (B_b B_b'))1 = ||B_b'A||_F^2: memory |C|^2, not Q^2.
static void AddHadamardGramCandidates(PetscInt Q, const PetscReal *A, PetscInt ka, PetscInt ms, PetscInt per, PetscInt block, const std::function<void(PetscInt, PetscInt, PetscReal *)> &fill, std::vector<PetscReal> *H, CubatureCandidates *cand)
{
  const std::vector<PetscInt> &C  = cand->points;
  const PetscInt               nc = (PetscInt)C.size();
  const bool                   gramToo = !cand->targetOnly;
  std::vector<PetscReal>       AC((size_t)nc * ka), GA, W, B, BC, T, U, Pend;
  for (PetscInt a = 0; a < ka; ++a)
    for (PetscInt i = 0; i < nc; ++i) AC[i + (size_t)nc * a] = A[C[i] + (size_t)Q * a];
  const PetscBLASInt q = (PetscBLASInt)Q, n = (PetscBLASInt)nc, a = (PetscBLASInt)ka;
  const PetscReal    one = 1, zero = 0;
  if (gramToo) {
    GA.resize((size_t)nc * nc);
    BLASgemm_("N", "T", &n, &n, &a, &one, AC.data(), &n, AC.data(), &n, &zero, GA.data(), &n);
    cand->b.resize(nc, 0.0);
  }
  for (PetscInt s0 = 0; s0 < ms; s0 += block) {
    const PetscInt cnt = std::min(block, ms - s0), kb = cnt * per;
    B.assign((size_t)Q * kb, 0.0);
    fill(s0, cnt, B.data());
    BC.resize((size_t)nc * kb);
    for (PetscInt c = 0; c < kb; ++c)
      for (PetscInt i = 0; i < nc; ++i) BC[i + (size_t)nc * c] = B[C[i] + (size_t)Q * c];
    const PetscBLASInt b = (PetscBLASInt)kb;
    T.resize((size_t)kb * ka); // B'A
    BLASgemm_("T", "N", &b, &a, &q, &one, B.data(), &q, A, &q, &zero, T.data(), &b);
    for (PetscReal t : T) cand->c += t * t;
    if (!gramToo) { // the candidates' own target: ||B_C'A_C||^2 = 1_C'((A_C A_C') o (B_C B_C'))1_C
      BLASgemm_("T", "N", &b, &a, &n, &one, BC.data(), &n, AC.data(), &n, &zero, T.data(), &b);
      for (PetscReal t : T) cand->cOwn += t * t;
      continue;
    }
    // H_CC += GA o (B_C B_C'), the blocks' B_C gathered up to n^2 / 8 entries first: each product's pass over H and
    // GA then serves several states (one pass a state would move 2.5x the memory of the gemm's own updates)
    const size_t cap = gramColumnBlock > 0 ? (size_t)gramColumnBlock * nc : (size_t)nc * nc / 8; // (tests: flush often)
    if (Pend.empty() && BC.size() >= cap) AddHadamardProductColumns(nc, kb, BC.data(), GA.data(), H->data(), &W); // large enough alone: no copy
    else {
      Pend.insert(Pend.end(), BC.begin(), BC.end());
      if (s0 + block >= ms || Pend.size() + BC.size() > cap) {
        AddHadamardProductColumns(nc, (PetscInt)(Pend.size() / std::max<PetscInt>(nc, 1)), Pend.data(), GA.data(), H->data(), &W);
        Pend.clear();
      }
    }
    U.resize((size_t)nc * ka); // B_C T
    BLASgemm_("N", "N", &n, &a, &b, &one, BC.data(), &n, T.data(), &b, &zero, U.data(), &n);
    for (PetscInt k = 0; k < ka; ++k)
      for (PetscInt i = 0; i < nc; ++i) cand->b[i] += AC[i + (size_t)nc * k] * U[i + (size_t)nc * k];
  }
}

void AddHadamardGramBlocks(PetscInt Q, const PetscReal *A, PetscInt ka, PetscInt ms, PetscInt per, PetscInt block, const std::function<void(PetscInt, PetscInt, PetscReal *)> &fill, std::vector<PetscReal> *H, CubatureCandidates *cand)
{
  if (ka <= 0 || per <= 0 || ms <= 0) return;
  if (cand && !cand->points.empty()) return AddHadamardGramCandidates(Q, A, ka, ms, per, block, fill, H, cand);
  std::vector<PetscReal> GA((size_t)Q * Q), B, W;
  const PetscBLASInt     q = (PetscBLASInt)Q, a = (PetscBLASInt)ka;
  const PetscReal        one = 1, zero = 0;
  BLASgemm_("N", "T", &q, &q, &a, &one, A, &q, A, &q, &zero, GA.data(), &q);
  for (PetscInt s0 = 0; s0 < ms; s0 += block) {
    const PetscInt cnt = std::min(block, ms - s0);
    B.assign((size_t)Q * cnt * per, 0.0);
    fill(s0, cnt, B.data());
    AddHadamardProductColumns(Q, cnt * per, B.data(), GA.data(), H->data(), &W); // H += GA o (B_b B_b')
  }
}

// H zeroed at its size (Q x Q, or the candidates' |C| x |C| with their target pieces b, c zeroed too; empty with
// cand->targetOnly).
void ResetGram(PetscInt Q, std::vector<PetscReal> *H, CubatureCandidates *cand)
{
  const bool   onC = cand && !cand->points.empty();
  const size_t n   = onC ? cand->points.size() : (size_t)Q;
  if (onC && cand->targetOnly) H->clear();
  else H->assign(n * n, 0.0);
  if (cand) {
    cand->b.assign(onC && cand->targetOnly ? 0 : cand->points.size(), 0.0);
    cand->c    = 0;
    cand->cOwn = 0;
  }
}
} // namespace

void SetCubatureGramColumnBlock(PetscInt columns) { gramColumnBlock = std::max<PetscInt>(columns, 0); }

static PetscInt eliminationRefresh = 0; // SetCubatureEliminationRefresh (tests); 0: max(64, k / 8)
void SetCubatureEliminationRefresh(PetscInt removals) { eliminationRefresh = std::max<PetscInt>(removals, 0); }

void CubatureStateErrors(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const KappaBlocks &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const CubatureResult &res, std::vector<PetscReal> *errK, std::vector<PetscReal> *errG)
{
  std::vector<PetscReal> Ke, ge, Kc, gc;
  errK->clear();
  errG->clear();
  for (PetscInt s = 0; s < ms; ++s) {
    const PetscReal *kap = Sk(s), *gam = &Sg[(size_t)s * Q];
    ReducedTerms(P, R, Q, N, kap, gam, {}, {}, &Ke, &ge);
    ReducedTerms(P, R, Q, N, kap, gam, res.points, res.weights, &Kc, &gc);
    for (size_t i = 0; i < Kc.size(); ++i) Kc[i] -= Ke[i];
    for (size_t i = 0; i < gc.size(); ++i) gc[i] -= ge[i];
    const PetscReal nk = SumSquares(Ke), ng = SumSquares(ge);
    errK->push_back(std::sqrt(nk > 0 ? SumSquares(Kc) / nk : SumSquares(Kc)));
    errG->push_back(std::sqrt(ng > 0 ? SumSquares(gc) / ng : SumSquares(gc)));
  }
}

void CubatureGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const KappaBlocks &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, std::vector<PetscReal> *H, CubatureCandidates *cand)
{
  const PetscInt         nc = N + 1;
  std::vector<PetscReal> Z((size_t)Q * ms * nc, 0.0), Kh, gh;
  for (PetscInt s = 0; s < ms; ++s) {
    const PetscReal *kap = Sk(s), *gam = &Sg[(size_t)s * Q];
    ReducedTerms(P, R, Q, N, kap, gam, {}, {}, &Kh, &gh); // exact reduced terms of this state, for its scaling
    const PetscReal nk = SumSquares(Kh), ng = SumSquares(gh);
    const PetscReal sk = nk > 0 ? 1 / std::sqrt(nk) : 0, sg = ng > 0 ? 1 / std::sqrt(ng) : 0;
    for (PetscInt n = 0; n < N; ++n) {
      PetscReal *z = &Z[(size_t)(s * nc + n) * Q];
      for (PetscInt p = 0; p < Q; ++p) z[p] = sk * kap[(size_t)p * N + n];
    }
    PetscReal *z = &Z[(size_t)(s * nc + N) * Q];
    for (PetscInt p = 0; p < Q; ++p) z[p] = sg * gam[p];
  }
  // H = (P'P) o (Z Z') (P row-major R x Q = column-major Q x R)
  ResetGram(Q, H, cand);
  AddHadamardGram(Q, P.data(), R, Z.data(), ms * nc, H, cand);
}

void CubatureActionGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const KappaBlocks &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const std::vector<PetscReal> &Lam, const std::vector<PetscReal> &Vs, PetscInt nt, std::vector<PetscReal> *H, const std::vector<PetscReal> &Sw, PetscInt dim, PetscInt block, CubatureCandidates *cand, CubatureScalings *scalings, const CubatureLambdaMetric *metric)
{
  // Lam P (nt x Q): the points' rows seen through the training multipliers
  std::vector<PetscReal> LP((size_t)nt * Q, 0.0), s1(ms), s2(ms), Kh, gh, Kv;
  for (PetscInt j = 0; j < nt; ++j)
    for (PetscInt r = 0; r < R; ++r) {
      const PetscReal l = Lam[(size_t)j * R + r];
      if (l == 0.0) continue;
      for (PetscInt p = 0; p < Q; ++p) LP[(size_t)j * Q + p] += l * P[(size_t)r * Q + p];
    }
  // each state's scalings: its terms to unit norm over the training solutions (or those of an earlier call)
  const bool known = scalings && scalings->s1.size() == (size_t)ms && scalings->s2.size() == (size_t)ms;
  if (known) {
    s1 = scalings->s1;
    s2 = scalings->s2;
  }
  for (PetscInt s = 0; s < ms && !known; ++s) {
    const PetscReal *kap = Sk(s), *gam = &Sg[(size_t)s * Q];
    ReducedTerms(P, R, Q, N, kap, gam, {}, {}, &Kh, &gh);
    PetscReal n1 = 0, n2 = 0, gg = SumSquares(gh);
    for (PetscInt j = 0; j < nt; ++j) {
      for (PetscInt n = 0; n < N; ++n) { // (K^' lam_j)_n
        PetscReal t = 0;
        for (PetscInt r = 0; r < R; ++r) t += Kh[(size_t)r * N + n] * Lam[(size_t)j * R + r];
        n1 += t * t;
      }
      Kv.assign(R, 0.0);
      for (PetscInt r = 0; r < R; ++r) // (K^ v_j)_r
        for (PetscInt n = 0; n < N; ++n) Kv[r] += Kh[(size_t)r * N + n] * Vs[(size_t)j * N + n];
      if (metric) { // ||T_j K^ v_j||^2 + ||T_j g^||^2
        const std::vector<PetscReal> &T = metric->T[j];
        for (size_t i = 0; i < T.size() / std::max<PetscInt>(R, 1); ++i) {
          PetscReal a = 0, b = 0;
          for (PetscInt r = 0; r < R; ++r) {
            a += T[i * R + r] * Kv[r];
            b += T[i * R + r] * gh[r];
          }
          n2 += a * a + b * b;
        }
      } else n2 += SumSquares(Kv) + gg;
    }
    s1[s] = n1 > 0 ? 1 / std::sqrt(n1) : 0;
    s2[s] = n2 > 0 ? 1 / std::sqrt(n2) : 0;
  }
  if (scalings && !known) {
    scalings->s1 = s1;
    scalings->s2 = s2;
  }
  // (Lam P)'(Lam P) o Zk Zk' + P'P o Y Y', Zk (the scaled kappa columns) and Y(p, (s, j)) = s2 (kappa_s(p, :) v_j -
  // gamma_s(p)) formed a block of states at a time
  // with the lambda metric's force factor, each state's N columns are followed by its rg columns s2 kappa_s Fg
  const PetscInt   rg  = metric ? metric->forceRank : 0;
  const PetscInt   per = N + rg;
  const PetscReal *Fg  = rg > 0 ? metric->forceFactor.data() : nullptr;
  ResetGram(Q, H, cand);
  AddHadamardGramBlocks(Q, LP.data(), nt, ms, per, StatesPerBlock(Q, per, ms, block), [&](PetscInt s0, PetscInt cnt, PetscReal *Z) {
    for (PetscInt s = s0; s < s0 + cnt; ++s) {
      const PetscReal *kap = Sk(s);
      for (PetscInt n = 0; n < N; ++n) {
        PetscReal *z = &Z[(size_t)((s - s0) * per + n) * Q];
        for (PetscInt p = 0; p < Q; ++p) z[p] = s1[s] * kap[(size_t)p * N + n];
      }
      if (rg == 0) continue;
      // zg (Q x rg, column-major) = s2 kappa_s Fg, kappa_s and Fg row-major: the transposes of column-major arrays
      const PetscBLASInt bq = (PetscBLASInt)Q, br = (PetscBLASInt)rg, bn = (PetscBLASInt)N;
      const PetscReal    zero = 0;
      BLASgemm_("T", "T", &bq, &br, &bn, &s2[s], kap, &bn, Fg, &br, &zero, &Z[(size_t)((s - s0) * per + N) * Q], &bq);
    }
  }, H, cand);
  if (metric) // sum_j ((T_j P)'(T_j P)) o (Y_j Y_j'), one training solution at a time
    for (PetscInt j = 0; j < nt; ++j) {
      const std::vector<PetscReal> &T = metric->T[j];
      const PetscInt                k = (PetscInt)(T.size() / std::max<PetscInt>(R, 1));
      if (k == 0) continue;
      std::vector<PetscReal> TP((size_t)k * Q, 0.0);
      for (PetscInt i = 0; i < k; ++i)
        for (PetscInt r = 0; r < R; ++r) {
          const PetscReal t = T[(size_t)i * R + r];
          if (t == 0.0) continue;
          for (PetscInt p = 0; p < Q; ++p) TP[(size_t)i * Q + p] += t * P[(size_t)r * Q + p];
        }
      AddHadamardGramBlocks(Q, TP.data(), k, ms, 1, StatesPerBlock(Q, 1, ms, block), [&](PetscInt s0, PetscInt cnt, PetscReal *Y) {
        for (PetscInt s = s0; s < s0 + cnt; ++s) {
          const PetscReal *gam = &Sg[(size_t)s * Q];
          PetscReal       *y   = &Y[(size_t)(s - s0) * Q];
          if (metric->kappaTimes) metric->kappaTimes(s, j, y);
          else {
            const PetscReal *kap = Sk(s);
            for (PetscInt p = 0; p < Q; ++p) {
              PetscReal t = 0;
              for (PetscInt n = 0; n < N; ++n) t += kap[(size_t)p * N + n] * Vs[(size_t)j * N + n];
              y[p] = t;
            }
          }
          for (PetscInt p = 0; p < Q; ++p) y[p] = s2[s] * (y[p] - gam[p]);
        }
      }, H, cand);
    }
  else AddHadamardGramBlocks(Q, P.data(), R, ms, nt, StatesPerBlock(Q, nt, ms, block), [&](PetscInt s0, PetscInt cnt, PetscReal *Y) {
    for (PetscInt s = s0; s < s0 + cnt; ++s) {
      const PetscReal *kap = Sk(s), *gam = &Sg[(size_t)s * Q];
      for (PetscInt j = 0; j < nt; ++j) {
        PetscReal *y = &Y[(size_t)((s - s0) * nt + j) * Q];
        for (PetscInt p = 0; p < Q; ++p) {
          PetscReal t = -gam[p];
          for (PetscInt n = 0; n < N; ++n) t += kap[(size_t)p * N + n] * Vs[(size_t)j * N + n];
          y[p] = s2[s] * t;
        }
      }
    }
  }, H, cand);
  // the resultant force: F_s(lam_j)_d = sum_p LP(j, p) Sw_s(p, d), scaled to unit norm per state
  if (dim > 0 && Sw.size() == (size_t)ms * Q * dim) {
    std::vector<PetscReal> Zf((size_t)Q * ms * dim, 0.0);
    for (PetscInt s = 0; s < ms; ++s) {
      const PetscReal *wn = &Sw[(size_t)s * Q * dim];
      PetscReal        n3 = 0;
      for (PetscInt j = 0; j < nt; ++j)
        for (PetscInt d = 0; d < dim; ++d) {
          PetscReal t = 0;
          for (PetscInt p = 0; p < Q; ++p) t += LP[(size_t)j * Q + p] * wn[(size_t)p * dim + d];
          n3 += t * t;
        }
      const PetscReal s3 = n3 > 0 ? 1 / std::sqrt(n3) : 0;
      for (PetscInt d = 0; d < dim; ++d) {
        PetscReal *z = &Zf[(size_t)(s * dim + d) * Q];
        for (PetscInt p = 0; p < Q; ++p) z[p] = s3 * wn[(size_t)p * dim + d];
      }
    }
    AddHadamardGram(Q, LP.data(), nt, Zf.data(), ms * dim, H, cand);
  }
}

// The ms blocks of a contiguous array.
static KappaBlocks Blocks(const std::vector<PetscReal> &Sk, PetscInt Q, PetscInt N)
{
  return [&Sk, Q, N](PetscInt s) { return &Sk[(size_t)s * Q * N]; };
}

void CubatureStateErrors(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const CubatureResult &res, std::vector<PetscReal> *errK, std::vector<PetscReal> *errG)
{
  CubatureStateErrors(P, R, Q, N, Blocks(Sk, Q, N), Sg, ms, res, errK, errG);
}

void CubatureGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, std::vector<PetscReal> *H, CubatureCandidates *cand)
{
  CubatureGram(P, R, Q, N, Blocks(Sk, Q, N), Sg, ms, H, cand);
}

void CubatureActionGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const std::vector<PetscReal> &Lam, const std::vector<PetscReal> &Vs, PetscInt nt, std::vector<PetscReal> *H, const std::vector<PetscReal> &Sw, PetscInt dim, PetscInt block, CubatureCandidates *cand, CubatureScalings *scalings, const CubatureLambdaMetric *metric)
{
  CubatureActionGram(P, R, Q, N, Blocks(Sk, Q, N), Sg, ms, Lam, Vs, nt, H, Sw, dim, block, cand, scalings, metric);
}

namespace {
// H(S, S) (k x k, column-major) gathered from H (Q x Q, row-major)
void GatherSupport(const std::vector<PetscReal> &H, PetscInt Q, const std::vector<PetscInt> &S, std::vector<PetscReal> *A)
{
  const PetscInt k = (PetscInt)S.size();
  A->resize((size_t)k * k);
  for (PetscInt j = 0; j < k; ++j)
    for (PetscInt i = 0; i < k; ++i) (*A)[i + (size_t)k * j] = H[(size_t)S[i] * Q + S[j]];
}
// Cholesky solve of H(S, S) z = b(S); false if H(S, S) is not (numerically) positive definite.
bool SolveOnSupport(const std::vector<PetscReal> &H, PetscInt Q, const std::vector<PetscInt> &S, const std::vector<PetscReal> &b, std::vector<PetscReal> *z)
{
  const PetscInt         k = (PetscInt)S.size();
  std::vector<PetscReal> A;
  PetscReal              dmax = 0;
  GatherSupport(H, Q, S, &A);
  for (PetscInt i = 0; i < k; ++i) dmax = std::max(dmax, A[i + (size_t)k * i]);
  z->resize(k);
  for (PetscInt i = 0; i < k; ++i) (*z)[i] = b[S[i]];
  PetscBLASInt n = (PetscBLASInt)k, one = 1, info = 0;
  LAPACKpotrf_("L", &n, A.data(), &n, &info);
  if (info != 0) return false;
  // a pivot far below the largest diagonal entry: the new point is (numerically) a combination of the others
  for (PetscInt i = 0; i < k; ++i)
    if (!(A[i + (size_t)k * i] * A[i + (size_t)k * i] > 1e-13 * dmax)) return false;
  LAPACKpotrs_("L", &n, &one, A.data(), &n, z->data(), &n, &info);
  return info == 0;
}
// The Cholesky factor of H(S, S) kept along Lawson-Hanson's steps: a point appended to S adds a row (O(k^2):
// L l = H(S, j), d^2 = H(j, j) - l'l), a point leaving S deletes its row and column (the rows below it lose that column
// and their trailing block takes the rank-one update by it: O((k - i)^2) Givens steps, i the point's place). The same
// pivot test as SolveOnSupport on an appended pivot (d^2 > 1e-13 max diag H(S, S)). O(k^2) a step instead of O(k^3):
// the groups of the hierarchical fit select thousands of points (CubatureOptions::incremental).
class SupportCholesky {
public:
  // Factor of H(S, S) for the current S: the factored set's points missing from S deleted, S's points after them
  // appended; false: an appended pivot not (numerically) positive, the factor left at the points before it.
  bool Update(const std::vector<PetscReal> &H, PetscInt Q, const std::vector<PetscInt> &S)
  {
    if (S == S_) return true;
    std::vector<size_t> gone; // places in S_ of the points S no longer holds (S_ minus these = S[0, m))
    size_t              m = 0;
    for (size_t i = 0; i < S_.size(); ++i) {
      if (m < S.size() && S_[i] == S[m]) ++m;
      else gone.push_back(i);
    }
    for (size_t g = gone.size(); g-- > 0;) Delete(gone[g]);
    if (!gone.empty()) {
      dmax_ = 0;
      for (PetscInt p : S_) dmax_ = std::max(dmax_, H[(size_t)p * Q + p]);
    }
    for (size_t i = m; i < S.size(); ++i)
      if (!Append(H, Q, S[i])) return false;
    return true;
  }
  // z = H(S, S)^{-1} b(S) (forward and back substitution)
  void Solve(const std::vector<PetscReal> &b, std::vector<PetscReal> *z) const
  {
    const size_t k = S_.size();
    z->resize(k);
    for (size_t i = 0; i < k; ++i) {
      PetscReal t = b[S_[i]];
      for (size_t m = 0; m < i; ++m) t -= L_[Row(i) + m] * (*z)[m];
      (*z)[i] = t / L_[Row(i) + i];
    }
    for (size_t i = k; i-- > 0;) {
      PetscReal t = (*z)[i];
      for (size_t m = i + 1; m < k; ++m) t -= L_[Row(m) + i] * (*z)[m];
      (*z)[i] = t / L_[Row(i) + i];
    }
  }

private:
  static size_t Row(size_t i) { return i * (i + 1) / 2; } // packed lower triangle by rows
  bool Append(const std::vector<PetscReal> &H, PetscInt Q, PetscInt j)
  {
    const size_t k = S_.size();
    std::vector<PetscReal> l(k);
    PetscReal              ll = 0;
    for (size_t i = 0; i < k; ++i) {
      PetscReal t = H[(size_t)S_[i] * Q + j];
      for (size_t m = 0; m < i; ++m) t -= L_[Row(i) + m] * l[m];
      l[i] = t / L_[Row(i) + i];
      ll += l[i] * l[i];
    }
    const PetscReal hjj = H[(size_t)j * Q + j], dmax = std::max(dmax_, hjj), d2 = hjj - ll;
    if (!(d2 > 1e-13 * dmax)) return false;
    L_.insert(L_.end(), l.begin(), l.end());
    L_.push_back(std::sqrt(d2));
    S_.push_back(j);
    dmax_ = dmax;
    return true;
  }
  // delete the point at place i: rows below i without column i, L33 L33' + v v' refactored by Givens rotations
  // (v the deleted column below the diagonal); a rank-one update, no cancellation
  void Delete(size_t i)
  {
    const size_t           k = S_.size(), t = k - i - 1;
    std::vector<PetscReal> v(t);
    auto                   L = L_.begin();
    for (size_t r = i + 1; r < k; ++r) { // old row r -> new row r - 1, column i left out, in place (every piece moves to lower places)
      v[r - i - 1] = L_[Row(r) + i];
      std::copy(L + Row(r), L + Row(r) + i, L + Row(r - 1));
      std::copy(L + Row(r) + i + 1, L + Row(r) + r + 1, L + Row(r - 1) + i);
    }
    L_.resize(Row(k - 1));
    for (size_t j = 0; j < t; ++j) {
      const size_t    c = i + j;
      const PetscReal d = L_[Row(c) + c], r = std::hypot(d, v[j]), cs = r / d, sn = v[j] / d;
      L_[Row(c) + c] = r;
      for (size_t q = j + 1; q < t; ++q) {
        PetscReal &e = L_[Row(i + q) + c];
        e            = (e + sn * v[q]) / cs;
        v[q]         = cs * v[q] - sn * e;
      }
    }
    S_.erase(S_.begin() + i);
  }
  std::vector<PetscInt>  S_;
  std::vector<PetscReal> L_;
  PetscReal              dmax_ = 0;
};

// (z - 1)' H (z - 1) / c for weights z on a support whose Gram matrix Hs = H(S, S) (k x k, column-major) and target bs =
// b(S) are given, leaving out its place `skip` (-1: none; z then has k - 1 entries), evaluated as z'Hs z - 2 bs'z + c: an
// error in z enters at second order (the least-squares residual's form c - bs'z loses it to cancellation)
PetscReal RelResidual2(PetscInt k, const std::vector<PetscReal> &Hs, const std::vector<PetscReal> &bs, PetscInt skip, const std::vector<PetscReal> &z, PetscReal c)
{
  PetscReal xHx = 0, bx = 0;
  for (PetscInt j = 0, jz = 0; j < k; ++j) {
    if (j == skip) continue;
    const PetscReal *col = &Hs[(size_t)k * j];
    PetscReal        t   = 0;
    for (PetscInt i = 0, iz = 0; i < k; ++i) {
      if (i == skip) continue;
      t += col[i] * z[iz++];
    }
    xHx += z[jz] * t;
    bx += bs[j] * z[jz];
    ++jz;
  }
  return std::max<PetscReal>(xHx - 2 * bx + c, 0) / c;
}

// a k x k column-major matrix without row and column j, in place (k - 1 x k - 1)
void DropRowColumn(PetscInt k, PetscInt j, std::vector<PetscReal> *A)
{
  size_t w = 0;
  for (PetscInt q = 0; q < k; ++q)
    if (q != j)
      for (PetscInt i = 0; i < k; ++i)
        if (i != j) (*A)[w++] = (*A)[i + (size_t)k * q]; // w never passes i + k q: nothing unread is overwritten
  A->resize(w);
}
} // namespace

PetscInt EliminateCubaturePoints(const std::vector<PetscReal> &H, PetscInt Q, const std::vector<PetscReal> &b, PetscReal c, PetscReal tol, std::vector<PetscInt> *S, std::vector<PetscReal> *x, PetscReal *rel)
{
  if (S->size() < 2 || !(c > 0)) return 0;
  std::vector<PetscInt>  cur = *S, S2, order;
  std::vector<PetscReal> Hs, bs, z, z2, G, delta, gj;
  SupportCholesky        chol, trial;
  if (!chol.Update(H, Q, cur)) return 0;
  chol.Solve(b, &z);
  PetscInt k = (PetscInt)cur.size();
  GatherSupport(H, Q, cur, &Hs); // H(S, S) and b(S), kept compact as points leave
  for (PetscInt i = 0; i < k; ++i) bs.push_back(b[cur[i]]);
  const PetscReal budget = tol * tol;
  PetscReal       obj    = RelResidual2(k, Hs, bs, -1, z, c);
  PetscInt        removed = 0, sinceInverse = 0;
  // G = H(S, S)^{-1}: the predictions that order and screen the trials. Formed afresh after every max(64, k / 8)
  // removals, and before stopping when an updated one found no removal; updated by rank one in between. Its rounding
  // grows with H(S, S)'s condition, which only changes the predictions: every removal taken is solved (the Cholesky
  // factor updated by the deletion) and checked exactly.
  auto inverse = [&]() {
    G = Hs;
    PetscBLASInt n = (PetscBLASInt)k, info = 0;
    LAPACKpotrf_("L", &n, G.data(), &n, &info);
    if (info == 0) LAPACKpotri_("L", &n, G.data(), &n, &info);
    for (PetscInt j = 0; j < k; ++j)
      for (PetscInt i = 0; i < j; ++i) G[i + (size_t)k * j] = G[j + (size_t)k * i];
    sinceInverse = 0;
    return info == 0;
  };
  if (!inverse()) return 0;
  while (k >= 2) {
    // predicted: the squared residual's rise without point j, z_j^2 / G_jj, and the others' weights z - (z_j / G_jj) G(:, j)
    delta.resize(k);
    order.clear();
    for (PetscInt j = 0; j < k; ++j) {
      delta[j] = z[j] * z[j] / G[j + (size_t)k * j] / c;
      if (obj + delta[j] <= budget) order.push_back(j);
    }
    std::sort(order.begin(), order.end(), [&](PetscInt a, PetscInt q) { return delta[a] < delta[q] || (delta[a] == delta[q] && a < q); });
    PetscInt pick = -1, exact = 0;
    for (size_t t = 0; t < order.size() && pick < 0 && exact < 8; ++t) {
      const PetscInt  j  = order[t];
      const PetscReal f  = z[j] / G[j + (size_t)k * j];
      bool            ok = true;
      for (PetscInt i = 0; i < k && ok; ++i)
        if (i != j) ok = z[i] - f * G[i + (size_t)k * j] > 0;
      if (!ok) continue; // predicted to make a weight negative (in exact arithmetic never the cheapest: docs)
      ++exact;
      S2 = cur;
      S2.erase(S2.begin() + j);
      trial = chol;
      if (!trial.Update(H, Q, S2)) continue;
      trial.Solve(b, &z2);
      bool pos = true;
      for (PetscReal v : z2) pos = pos && v > 0;
      if (!pos) continue;
      const PetscReal obj2 = RelResidual2(k, Hs, bs, j, z2, c);
      if (obj2 <= budget) {
        pick = j;
        obj  = obj2;
      }
    }
    if (pick < 0 && sinceInverse > 0) { // the updated inverse's predictions may have screened out a feasible removal:
      if (!inverse()) break;             // once more with a fresh one before stopping
      continue;
    }
    if (pick < 0) break;
    // accepted: the support, its factor, weights, H(S, S), b(S); G without row and column pick (rank one, then compacted)
    const PetscInt j = pick;
    cur.swap(S2);
    std::swap(chol, trial);
    z.swap(z2);
    DropRowColumn(k, j, &Hs);
    bs.erase(bs.begin() + j);
    ++removed;
    if (++sinceInverse >= (eliminationRefresh > 0 ? eliminationRefresh : std::max<PetscInt>(64, k / 8))) {
      --k;
      if (!inverse()) break;
      continue;
    }
    const PetscReal gjj = G[j + (size_t)k * j];
    gj.assign(G.begin() + (size_t)k * j, G.begin() + (size_t)k * (j + 1));
    size_t w = 0; // the rank-one update and the compaction in one pass over G (the elimination's largest cost at k ~ 5000)
    for (PetscInt q = 0; q < k; ++q)
      if (q != j)
        for (PetscInt i = 0; i < k; ++i)
          if (i != j) G[w++] = G[i + (size_t)k * q] - gj[i] * gj[q] / gjj; // in place: w never passes i + k q
    G.resize(w);
    --k;
  }
  if (!removed) return 0;
  for (PetscInt p : *S) (*x)[p] = 0;
  for (size_t i = 0; i < cur.size(); ++i) (*x)[cur[i]] = z[i];
  *S   = cur;
  *rel = std::sqrt(obj);
  return removed;
}

PetscErrorCode EmpiricalCubature(const std::vector<PetscReal> &H, PetscInt Qall, const CubatureOptions &opt, CubatureResult *res, const CubatureCandidates *cand)
{
  PetscFunctionBeginUser;
  const bool     sub = cand && !cand->points.empty();
  const PetscInt Q   = sub ? (PetscInt)cand->points.size() : Qall; // the points the fit may select
  PetscCheck(Q >= 1 && H.size() == (size_t)Q * Q, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "EmpiricalCubature: Gram matrix of %zu entries for Q = %" PetscInt_FMT " points", H.size(), Q);
  PetscCheck(!sub || (cand->b.size() == (size_t)Q && std::isfinite(cand->c)), PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "EmpiricalCubature: %zu target entries for %" PetscInt_FMT " candidates", cand ? cand->b.size() : (size_t)0, Q);
  for (PetscReal v : H) PetscCheck(std::isfinite(v), PETSC_COMM_SELF, PETSC_ERR_FP, "EmpiricalCubature: the Gram matrix of the contact terms holds a non-finite value");
  *res = CubatureResult();
  // target b = H 1, c = 1' H 1 (= ||G 1||^2); on candidates, given (the sums over every point)
  std::vector<PetscReal> b(Q, 0.0), x(Q, 0.0), grad, z, Hx(Q, 0.0);
  PetscReal              c = 0;
  if (sub) {
    b = cand->b;
    c = cand->c;
  } else
    for (PetscInt p = 0; p < Q; ++p) {
      for (PetscInt q = 0; q < Q; ++q) b[p] += H[(size_t)p * Q + q];
      c += b[p];
    }
  if (!(c > 0)) { // nothing to fit: no contact term at any state
    res->residual = 0;
    res->history  = {0};
    PetscFunctionReturn(0);
  }
  std::vector<PetscInt> S;
  std::vector<char>     in(Q, 0), banned(Q, 0);
  SupportCholesky       chol; // opt.incremental
  grad                   = b;
  PetscReal        rel   = 1;
  const PetscReal  gtiny = 1e-14 * *std::max_element(b.begin(), b.end());
  res->history.push_back(1);
  auto residual = [&]() { // sqrt((x - 1)' H (x - 1) / c) from x' H x - 2 b' x + c
    PetscReal xHx = 0, bx = 0;
    for (PetscInt p : S) {
      xHx += x[p] * Hx[p];
      bx += b[p] * x[p];
    }
    return std::sqrt(std::max<PetscReal>(xHx - 2 * bx + c, 0) / c);
  };
  // with opt.eliminate the fit goes on to eliminateFrom x tol, then EliminateCubaturePoints thins it back to tol; the fit
  // as it stood on first reaching tol (the plain fit's result) is kept, and returned if the elimination does not end
  // with fewer points
  const PetscReal        tolFit = opt.eliminate ? opt.tol * opt.eliminateFrom : opt.tol;
  std::vector<PetscInt>  plainS;
  std::vector<PetscReal> plainX;
  PetscReal              plainRel = -1;
  size_t                 plainHistory = 0;
  PetscLogDouble         t0, tPlain = 0, t1, t2;
  PetscCall(PetscTime(&t0));
  // (the longer fit stops at twice the plain fit's points: in the hierarchical fit's union f x tol may be out of reach,
  // and Lawson-Hanson would otherwise run on to the gradient's end or maxPoints)
  while (rel > tolFit && (PetscInt)S.size() < opt.maxPoints && !(plainRel >= 0 && S.size() >= 2 * plainS.size())) {
    PetscInt  j = -1;
    PetscReal gmax = gtiny;
    for (PetscInt p = 0; p < Q; ++p)
      if (!in[p] && !banned[p] && grad[p] > gmax) {
        gmax = grad[p];
        j    = p;
      }
    if (j < 0) break; // KKT point of the NNLS: no point improves the fit
    S.push_back(j);
    in[j] = 1;
    for (;;) {
      ++res->iterations;
      // past the plain fit's result (recorded below) the factor is updated, not refactored: the longer fit only feeds
      // the elimination, which solves every removal exactly, and the plain fit's points and weights stay as before
      const bool inc = opt.incremental || plainRel >= 0;
      const bool ok  = inc ? chol.Update(H, Q, S) : SolveOnSupport(H, Q, S, b, &z);
      if (ok && inc) chol.Solve(b, &z);
      if (!ok) { // j adds nothing independent: drop it for good
        S.erase(std::find(S.begin(), S.end(), j));
        in[j] = 0;
        banned[j] = 1;
        break;
      }
      PetscReal alpha = 1;
      PetscInt  hit   = -1;
      for (size_t i = 0; i < S.size(); ++i)
        if (z[i] <= 0) {
          const PetscReal a = x[S[i]] / (x[S[i]] - z[i]);
          if (a < alpha) { alpha = a; hit = (PetscInt)i; }
        }
      if (hit < 0) {
        for (size_t i = 0; i < S.size(); ++i) x[S[i]] = z[i];
        break;
      }
      for (size_t i = 0; i < S.size(); ++i) x[S[i]] += alpha * (z[i] - x[S[i]]);
      x[S[hit]] = 0;
      std::vector<PetscInt> keep;
      for (PetscInt p : S) {
        if (x[p] > 0) keep.push_back(p);
        else {
          x[p]  = 0;
          in[p] = 0;
        }
      }
      S = keep;
      if (S.empty()) break;
    }
    // gradient b - H x, and H x on the support for the residual; H symmetric: summed by its rows q in S (contiguous),
    // each Hx[p] over q in the order of S as a dot product of row p would
    std::fill(Hx.begin(), Hx.end(), 0.0);
    for (PetscInt q : S) {
      const PetscReal *Hq = H.data() + (size_t)q * Q, xq = x[q];
      for (PetscInt p = 0; p < Q; ++p) Hx[p] += Hq[p] * xq;
    }
    grad.assign(Q, 0.0);
    for (PetscInt p = 0; p < Q; ++p) grad[p] = b[p] - Hx[p];
    rel = residual();
    res->history.push_back(rel);
    if (opt.monitor) PetscCall(PetscPrintf(PETSC_COMM_SELF, "  cubature M = %3zu  rel residual = %.3e\n", S.size(), (double)rel));
    if (opt.eliminate && plainRel < 0 && rel <= opt.tol) {
      plainS   = S;
      plainRel = rel;
      plainHistory = res->history.size();
      for (PetscInt p : S) plainX.push_back(x[p]);
      PetscCall(PetscTime(&tPlain));
    }
  }
  PetscCall(PetscTime(&t1));
  res->timeFit     = (plainRel >= 0 ? tPlain : t1) - t0;
  res->timeLonger  = plainRel >= 0 ? t1 - tPlain : 0;
  res->plainPoints = (PetscInt)(plainRel < 0 ? S.size() : plainS.size());
  if (plainRel >= 0) {
    const size_t longer = S.size();
    res->eliminated     = EliminateCubaturePoints(H, Q, b, c, opt.tol, &S, &x, &rel);
    PetscCall(PetscTime(&t2));
    res->timeEliminate = t2 - t1;
    if (S.size() >= plainS.size()) { // no fewer points than the plain fit: its result
      std::fill(x.begin(), x.end(), 0.0);
      for (size_t i = 0; i < plainS.size(); ++i) x[plainS[i]] = plainX[i];
      S   = plainS;
      rel = plainRel;
      res->history.resize(plainHistory);
      res->eliminated = 0;
    } else if (res->eliminated > 0)
      res->history.push_back(rel); // the last entry: after the elimination
    if (opt.monitor) PetscCall(PetscPrintf(PETSC_COMM_SELF, "  cubature: %zu points at %g x tol, %" PetscInt_FMT " eliminated: M = %zu (the fit stopped at tol: %" PetscInt_FMT "), rel residual = %.3e; %.2f s fit, %.2f s longer fit, %.2f s elimination\n", longer, (double)opt.eliminateFrom, res->eliminated, S.size(), res->plainPoints, (double)rel, res->timeFit, res->timeLonger, res->timeEliminate));
  }
  res->residual = rel;
  res->points   = S;
  if (sub)
    for (auto &p : res->points) p = cand->points[p];
  res->weights.clear();
  for (PetscInt p : S) res->weights.push_back(x[p]);
  PetscFunctionReturn(0);
}

PetscErrorCode HierarchicalCubature(MPI_Comm comm, PetscInt Q, const CubatureOptions &opt, const CubatureGramFunction &gram, CubatureResult *res, CubatureHierarchy *info, bool collectiveGram)
{
  std::vector<PetscReal> H;
  CubatureHierarchy      hi;
  PetscMPIInt            rank, size;

  PetscFunctionBeginUser;
  if (!CUB_Gram) {
    PetscCall(PetscLogEventRegister("RBCCubatureGram", PETSC_SMALLEST_CLASSID, &CUB_Gram));
    PetscCall(PetscLogEventRegister("RBCCubatureFit", PETSC_SMALLEST_CLASSID, &CUB_Fit));
  }
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  auto formGram = [&](CubatureCandidates *c) -> PetscErrorCode {
    PetscFunctionBeginUser;
    PetscCall(PetscLogEventBegin(CUB_Gram, 0, 0, 0, 0));
    gram(c, &H);
    PetscCall(PetscLogEventEnd(CUB_Gram, 0, 0, 0, 0));
    PetscFunctionReturn(0);
  };
  if (opt.groupPoints <= 0 || Q <= opt.groupPoints) { // one Gram matrix of every point
    PetscCall(formGram(nullptr));
    PetscCall(PetscLogEventBegin(CUB_Fit, 0, 0, 0, 0));
    PetscCall(EmpiricalCubature(H, Q, opt, res));
    PetscCall(PetscLogEventEnd(CUB_Fit, 0, 0, 0, 0));
    hi.groups = 1;
    hi.candidates = Q;
    if (info) *info = hi;
    PetscFunctionReturn(0);
  }
  const PetscInt K = (Q + opt.groupPoints - 1) / opt.groupPoints;
  auto group = [&](PetscInt g, CubatureCandidates *c) {
    c->points.clear();
    for (PetscInt p = (PetscInt)(((long long)g * Q) / K); p < (PetscInt)(((long long)(g + 1) * Q) / K); ++p) c->points.push_back(p);
  };
  // pass 1: each group's own target |G_g 1|^2 and the whole one |G 1|^2, without the Gram matrices (targetOnly)
  CubatureCandidates c;
  PetscReal          sumRoot = 0, cAll = 0;
  c.targetOnly = true;
  for (PetscInt g = 0; g < K; ++g) {
    group(g, &c);
    PetscCall(formGram(&c));
    sumRoot += std::sqrt(std::max<PetscReal>(c.cOwn, 0));
    cAll = c.c;
  }
  c.targetOnly = false;
  // the groups' tolerance: their weights together then fit the whole terms within opt.tol (triangle inequality)
  CubatureOptions og = opt;
  og.tol             = sumRoot > 0 ? opt.tol * std::sqrt(cAll) / sumRoot : opt.tol;
  og.monitor         = false;
  og.groupPoints     = 0;
  og.incremental     = true; // thousands of points per group: O(k^2) steps
  og.eliminate       = false; // the union's fit below thins the result
  PetscCheck(og.tol > 0, comm, PETSC_ERR_PLIB, "HierarchicalCubature: group tolerance %g", (double)og.tol);
  // the groups in batches of `share` (the ranks, or 1): every rank forms each group's Gram matrix when gram is
  // collective (else only its own), group b + j is fitted by rank j, which keeps that matrix; then the batch's points
  // are broadcast
  const PetscMPIInt      share = opt.shareGroups ? size : 1;
  std::vector<PetscInt>  U;
  std::vector<PetscReal> Hmine;
  hi.groupResiduals.assign(K, 0);
  for (PetscInt b = 0; b < K; b += share) {
    const PetscInt nb = std::min<PetscInt>(share, K - b);
    PetscInt       mine = -1; // this rank's group of the batch
    for (PetscInt j = 0; j < nb; ++j) {
      if (!collectiveGram && share > 1 && j != rank) continue; // a local gram: only this rank's group is formed here
      group(b + j, &c);
      PetscCall(formGram(&c));
      if (share == 1 || j == rank) {
        mine = b + j;
        Hmine.swap(H);
      }
    }
    H.clear();
    H.shrink_to_fit();
    CubatureResult rg;
    PetscInt       failed = -1; // the group whose fit failed (its error printed by its rank), else -1
    if (mine >= 0) { // the fit on this rank's own group; an error here is made collective below (no rank left waiting)
      group(mine, &c);
      PetscCall(PetscLogEventBegin(CUB_Fit, 0, 0, 0, 0));
      if (EmpiricalCubature(Hmine, (PetscInt)c.points.size(), og, &rg)) failed = mine; // the group's own terms
      PetscCall(PetscLogEventEnd(CUB_Fit, 0, 0, 0, 0));
      for (auto &p : rg.points) p = c.points[p];
    }
    Hmine.clear();
    Hmine.shrink_to_fit();
    if (share > 1) PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &failed, 1, MPIU_INT, MPI_MAX, comm));
    PetscCheck(failed < 0, comm, PETSC_ERR_LIB, "empirical cubature: the fit of group %" PetscInt_FMT " of %" PetscInt_FMT " failed (its error above, from rank %" PetscInt_FMT ")", failed, K, failed % share);
    for (PetscInt j = 0; j < nb; ++j) { // group b + j's points and residual, from the rank that fitted it
      const PetscInt         g = b + j;
      std::vector<PetscInt>  pts;
      PetscReal              resid = 0;
      if (g == mine) {
        pts   = rg.points;
        resid = rg.residual;
      }
      if (share > 1) {
        PetscInt n = (PetscInt)pts.size();
        PetscCallMPI(MPI_Bcast(&n, 1, MPIU_INT, (PetscMPIInt)j, comm));
        pts.resize(n);
        if (n) PetscCallMPI(MPI_Bcast(pts.data(), (PetscMPIInt)n, MPIU_INT, (PetscMPIInt)j, comm));
        PetscCallMPI(MPI_Bcast(&resid, 1, MPIU_REAL, (PetscMPIInt)j, comm));
      }
      PetscCheck(resid <= og.tol, comm, PETSC_ERR_NOT_CONVERGED, "empirical cubature: group %" PetscInt_FMT " of %" PetscInt_FMT " reaches %g > its tolerance %g with %zu points (-ecsw_max_points %" PetscInt_FMT "; larger -ecsw_group_points: fewer groups)", g, K, (double)resid, (double)og.tol, pts.size(), opt.maxPoints);
      U.insert(U.end(), pts.begin(), pts.end());
      hi.groupResiduals[g] = resid;
    }
  }
  // final fit: the union of the groups' points, against every point's terms
  std::sort(U.begin(), U.end());
  c.points = U;
  PetscCall(formGram(&c));
  CubatureOptions of = opt;
  of.incremental     = true;
  PetscCall(PetscLogEventBegin(CUB_Fit, 0, 0, 0, 0));
  PetscCall(EmpiricalCubature(H, Q, of, res, &c));
  PetscCall(PetscLogEventEnd(CUB_Fit, 0, 0, 0, 0));
  hi.groups     = K;
  hi.candidates = (PetscInt)U.size();
  hi.groupTol   = og.tol;
  if (info) *info = hi;
  PetscFunctionReturn(0);
}

} // namespace rbc
