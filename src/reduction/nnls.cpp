// src/reduction/nnls.cpp: the NNLS cone projections min ||Q x - b||, x >= 0 (dense, PETSC_COMM_SELF).
// Owns NNLSSolver (TAO BQPIP on the equilibrated normal equations following
// ../shared/notes/nnls-with-bqpip.md, then a Lawson-Hanson polish on Q, KKT check, retries), the
// QR-based Lawson-Hanson active-set method NNLSLawsonHanson, the KKT measure NNLSKKT, the nnls_
// options and the RBCNNLS log event.
#include "rbcontact/tao_recipe.hpp"
#include "rbcontact/dual_basis.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>
#include <cstring>

namespace rbc {

static PetscLogEvent NNLS_Solve = 0;

static PetscErrorCode RegisterNNLSEvent()
{
  PetscFunctionBeginUser;
  if (!NNLS_Solve) PetscCall(PetscLogEventRegister("RBCNNLS", TAO_CLASSID, &NNLS_Solve));
  PetscFunctionReturn(0);
}

// --- Lawson-Hanson with QR least-squares subproblems ------------------------------------------------

namespace {

// min || Q(:, P) z - b || by Householder QR of the passive columns. Returns false when Q(:, P) is
// numerically rank deficient (|R_kk| <= rankTol) or has more columns than rows.
bool PassiveLeastSquares(const DenseMatrix &Q, const std::vector<PetscInt> &P, const std::vector<PetscReal> &b, PetscReal rankTol, std::vector<PetscReal> *z)
{
  const PetscBLASInt m = (PetscBLASInt)Q.rows, p = (PetscBLASInt)P.size(), one = 1;
  z->assign(P.size(), 0.0);
  if (!p) return true;
  if (p > m) return false;
  std::vector<PetscReal> A((size_t)m * p), tau(p), rhs(b), work(64 * (size_t)(p + 1));
  const PetscBLASInt     lwork = (PetscBLASInt)work.size();
  PetscBLASInt           info  = 0;
  for (PetscBLASInt j = 0; j < p; ++j) std::copy(&Q.a[(size_t)P[j] * m], &Q.a[(size_t)P[j] * m] + m, &A[(size_t)j * m]);
  LAPACKgeqrf_(&m, &p, A.data(), &m, tau.data(), work.data(), &lwork, &info);
  if (info) return false;
  for (PetscBLASInt k = 0; k < p; ++k)
    if (!(std::abs(A[k + (size_t)k * m]) > rankTol)) return false;
  PetscBLASInt mm = m, pp = p, oo = one, ld = m, lw = lwork;
  LAPACKormqr_("L", "T", &mm, &oo, &pp, A.data(), &ld, tau.data(), rhs.data(), &ld, work.data(), &lw, &info);
  if (info) return false;
  LAPACKtrtrs_("U", "N", "N", &p, &one, A.data(), &m, rhs.data(), &m, &info);
  if (info) return false;
  for (PetscBLASInt k = 0; k < p; ++k) {
    if (!std::isfinite(rhs[k])) return false;
    (*z)[k] = rhs[k];
  }
  return true;
}

// r = b - Q x
void Residual(const DenseMatrix &Q, const std::vector<PetscReal> &b, const std::vector<PetscReal> &x, std::vector<PetscReal> *r)
{
  *r = b;
  for (PetscInt j = 0; j < Q.cols; ++j)
    if (x[j] != 0)
      for (PetscInt i = 0; i < Q.rows; ++i) (*r)[i] -= Q(i, j) * x[j];
}

} // namespace

PetscErrorCode NNLSLawsonHanson(const DenseMatrix &Q, const std::vector<PetscReal> &b, std::vector<PetscReal> *x, PetscInt maxit, PetscInt *iterations)
{
  const PetscInt         m = Q.rows, n = Q.cols;
  std::vector<char>      inP(n, 0), rejected(n, 0);
  std::vector<PetscReal> z, r, colNorm(n, 0.0);
  std::vector<PetscInt>  P;
  PetscReal              qmax = 0, bnorm = 0;
  PetscInt               its  = 0;

  PetscFunctionBeginUser;
  PetscCheck((PetscInt)b.size() == m, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "NNLS: b has %zu entries, Q has %" PetscInt_FMT " rows", b.size(), m);
  if ((PetscInt)x->size() != n) x->assign(n, 0.0);
  for (PetscInt j = 0; j < n; ++j) {
    for (PetscInt i = 0; i < m; ++i) colNorm[j] += Q(i, j) * Q(i, j);
    colNorm[j] = std::sqrt(colNorm[j]);
    qmax       = std::max(qmax, colNorm[j]);
  }
  for (PetscInt i = 0; i < m; ++i) bnorm += b[i] * b[i];
  bnorm = std::sqrt(bnorm);
  if (iterations) *iterations = 0;
  if (bnorm == 0 || qmax == 0) {
    x->assign(n, 0.0);
    PetscFunctionReturn(0);
  }
  // rank test of the passive set and the entering test (both relative to the problem's scale)
  const PetscReal rankTol = 1e-12 * qmax;
  const PetscReal wTol    = 1e-14 * std::sqrt((PetscReal)std::max(m, n)) * qmax * bnorm;

  // Inner loop of Lawson-Hanson: from a feasible x (x > 0 on P) move towards the least-squares
  // solution on P, dropping blocking indices, until that solution is positive. false: rank deficient.
  auto inner = [&](bool *ok) {
    *ok = true;
    for (PetscInt guard = 0; guard < 3 * n + 10; ++guard) {
      P.clear();
      for (PetscInt j = 0; j < n; ++j) if (inP[j]) P.push_back(j);
      if (!PassiveLeastSquares(Q, P, b, rankTol, &z)) { *ok = false; return; }
      bool feasible = true;
      for (size_t k = 0; k < P.size(); ++k) if (z[k] <= 0) feasible = false;
      if (feasible) {
        for (size_t k = 0; k < P.size(); ++k) (*x)[P[k]] = z[k];
        return;
      }
      PetscReal alpha = 1;
      size_t    kmin  = 0;
      for (size_t k = 0; k < P.size(); ++k)
        if (z[k] <= 0) {
          const PetscReal a = (*x)[P[k]] / ((*x)[P[k]] - z[k]);
          if (a < alpha) { alpha = a; kmin = k; }
        }
      for (size_t k = 0; k < P.size(); ++k) {
        const PetscReal old = (*x)[P[k]];
        (*x)[P[k]] += alpha * (z[k] - old);
        if (k == kmin || (*x)[P[k]] <= 0) { (*x)[P[k]] = 0; inP[P[k]] = 0; }
      }
    }
  };

  // starting support: the positive entries of x
  bool any = false;
  for (PetscInt j = 0; j < n; ++j) {
    if ((*x)[j] > 0 && colNorm[j] > 0) { inP[j] = 1; any = true; }
    else (*x)[j] = 0;
  }
  if (any) {
    bool ok;
    inner(&ok);
    if (!ok) { // a rank-deficient starting support: classic Lawson-Hanson from x = 0
      x->assign(n, 0.0);
      std::fill(inP.begin(), inP.end(), 0);
    }
  }
  while (its < maxit) {
    Residual(Q, b, *x, &r);
    PetscInt  jbest = -1;
    PetscReal wbest = wTol;
    for (PetscInt j = 0; j < n; ++j) {
      if (inP[j] || rejected[j] || colNorm[j] == 0) continue;
      PetscReal w = 0;
      for (PetscInt i = 0; i < m; ++i) w += Q(i, j) * r[i];
      if (w > wbest) { wbest = w; jbest = j; }
    }
    if (jbest < 0) break;
    ++its;
    // Entering column: rejected when it makes the passive set dependent or its coefficient is not
    // positive (possible only through rounding), as in Lawson and Hanson's NNLS.
    inP[jbest] = 1;
    P.clear();
    for (PetscInt j = 0; j < n; ++j) if (inP[j]) P.push_back(j);
    const size_t kj = std::find(P.begin(), P.end(), jbest) - P.begin();
    if (!PassiveLeastSquares(Q, P, b, rankTol, &z) || z[kj] <= 0) {
      inP[jbest]      = 0;
      rejected[jbest] = 1;
      continue;
    }
    std::fill(rejected.begin(), rejected.end(), 0);
    bool ok;
    inner(&ok);
    if (!ok) { // cannot happen after a successful entering test; stay with the last feasible x
      inP[jbest] = 0;
      (*x)[jbest] = 0;
      rejected[jbest] = 1;
    }
  }
  for (PetscInt j = 0; j < n; ++j) if (!inP[j]) (*x)[j] = 0;
  if (iterations) *iterations = its;
  PetscFunctionReturn(0);
}

PetscReal NNLSKKT(const DenseMatrix &Q, const std::vector<PetscReal> &b, const std::vector<PetscReal> &x)
{
  std::vector<PetscReal> r;
  PetscReal              bnorm = 0, worst = 0;
  for (PetscReal v : b) bnorm += v * v;
  bnorm = std::sqrt(bnorm);
  Residual(Q, b, x, &r); // r = b - Qx, g = -Q^T r
  for (PetscInt j = 0; j < Q.cols; ++j) {
    PetscReal qn = 0, g = 0;
    for (PetscInt i = 0; i < Q.rows; ++i) { qn += Q(i, j) * Q(i, j); g -= Q(i, j) * r[i]; }
    qn = std::sqrt(qn);
    if (qn == 0) { worst = std::max(worst, std::abs(x[j])); continue; } // a zero column should carry 0
    if (bnorm == 0) { worst = std::max(worst, std::abs(x[j]) * qn); continue; } // b = 0: x = 0
    const PetscReal y = x[j] * qn / bnorm, gs = g / (qn * bnorm);
    worst = std::max({worst, std::abs(std::min(y, gs)), std::abs(y * gs)});
  }
  return worst;
}

// --- NNLSSolver ------------------------------------------------------------------------------------


NNLSSolver::~NNLSSolver()
{
  PetscBool finalized = PETSC_TRUE;
  if (PetscFinalized(&finalized) == 0 && !finalized) (void)Reset();
}

PetscErrorCode NNLSSolver::Reset()
{
  PetscFunctionBeginUser;
  PetscCall(TaoDestroy(&tao_));
  PetscCall(MatDestroy(&H_));
  PetscCall(VecDestroy(&x_));
  PetscCall(VecDestroy(&c_));
  PetscCall(VecDestroy(&lo_));
  PetscCall(VecDestroy(&hi_));
  n_ = -1;
  lastQ_ = DenseMatrix();
  PetscFunctionReturn(0);
}

PetscErrorCode NNLSSolver::SetFromOptions()
{
  const char *methods[] = {"tao", "activeset"};
  PetscInt    method    = useTao_ ? 0 : 1;

  PetscFunctionBeginUser;
  PetscCall(RegisterNNLSEvent());
  PetscOptionsBegin(PETSC_COMM_WORLD, "nnls_", "NNLS cone projections (dual bases)", "NNLSSolver");
  PetscCall(PetscOptionsEList("-method", "tao: TAO (-nnls_tao_type, BQPIP) + Lawson-Hanson polish; activeset: Lawson-Hanson (QR) alone", "NNLSSolver", methods, 2, methods[method], &method, NULL));
  PetscCall(PetscOptionsBool("-polish", "Lawson-Hanson polish from TAO's support", "NNLSSolver", polish_, &polish_, NULL));
  PetscCall(PetscOptionsReal("-kkt_tol", "Largest scaled KKT residual accepted before retrying", "NNLSSolver", kktTol_, &kktTol_, NULL));
  PetscCall(PetscOptionsReal("-support_tol", "TAO entries below this fraction of the largest start the polish at zero", "NNLSSolver", supportTol_, &supportTol_, NULL));
  PetscOptionsEnd();
  PetscCheck(kktTol_ > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-nnls_kkt_tol %g must be > 0", (double)kktTol_);
  PetscCheck(supportTol_ >= 0 && supportTol_ < 1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-nnls_support_tol %g must lie in [0, 1)", (double)supportTol_);
  useTao_ = method == 0 ? PETSC_TRUE : PETSC_FALSE;
  // a new Tao picks up changed options
  PetscCall(Reset());
  PetscFunctionReturn(0);
}

PetscErrorCode NNLSSolver::SetupTao(PetscInt n)
{
  PetscFunctionBeginUser;
  if (tao_ && n == n_) PetscFunctionReturn(0);
  // A Tao is not reused across sizes (BNLS in 3.18 fails with "Cannot change local size of Amat").
  {
    DenseMatrix keepQ = std::move(lastQ_);
    PetscCall(Reset());
    lastQ_ = std::move(keepQ);
  }
  n_ = n;
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, n, n, NULL, &H_));
  PetscCall(MatSetOption(H_, MAT_SPD, PETSC_TRUE));
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, n, &x_));
  PetscCall(VecDuplicate(x_, &c_));
  PetscCall(VecDuplicate(x_, &lo_));
  PetscCall(VecDuplicate(x_, &hi_));
  PetscCall(TaoCreate(PETSC_COMM_SELF, &tao_));
  PetscCall(TaoSetOptionsPrefix(tao_, "nnls_"));
  PetscCall(TaoSetSolution(tao_, x_));
  quad_.H = H_;
  quad_.c = c_;
  PetscCall(TaoSetQuadratic(tao_, &quad_));
  PetscCall(TaoSetVariableBounds(tao_, lo_, hi_));
  // The notes' recipe: absolute test only (the relative one fires spuriously), gatol 1e-7 (BQPIP's
  // measure stalls near 3e-8), at most 200 iterations, inner Cholesky.
  PetscCall(TaoBQPIPRecipe(tao_));
  PetscCall(TaoSetFromOptions(tao_));
  PetscFunctionReturn(0);
}

PetscErrorCode NNLSSolver::SolveTao(const std::vector<PetscReal> &H, const std::vector<PetscReal> &c, PetscBool bounded, PetscReal gatolFactor, std::vector<PetscReal> *y, PetscInt *its, TaoConvergedReason *reason)
{
  const PetscInt n = (PetscInt)c.size();
  PetscScalar   *h, *a;
  PetscReal      gatol, grtol, gttol;

  PetscFunctionBeginUser;
  PetscCall(SetupTao(n));
  PetscCall(MatDenseGetArrayWrite(H_, &h));
  for (PetscInt k = 0; k < n * n; ++k) h[k] = H[k];
  PetscCall(MatDenseRestoreArrayWrite(H_, &h));
  PetscCall(MatAssemblyBegin(H_, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(H_, MAT_FINAL_ASSEMBLY));
  PetscCall(VecGetArrayWrite(c_, &a));
  for (PetscInt i = 0; i < n; ++i) a[i] = c[i];
  PetscCall(VecRestoreArrayWrite(c_, &a));
  PetscCall(VecSet(x_, 0.0));
  PetscCall(VecSet(lo_, 0.0));
  // Upper bound 2 (equilibrated): with Q >= 0 and unit columns ||x|| <= ||Q x|| <= ||b|| = 1 at the
  // optimum, so it is never active; it saves BQPIP ~30 iterations over an infinite bound.
  PetscCall(VecSet(hi_, bounded ? 2.0 : PETSC_INFINITY));
  PetscCall(TaoGetTolerances(tao_, &gatol, &grtol, &gttol));
  if (gatolFactor != 1) PetscCall(TaoSetTolerances(tao_, gatol * gatolFactor, grtol, gttol));
  PetscCall(TaoSolve(tao_));
  if (gatolFactor != 1) PetscCall(TaoSetTolerances(tao_, gatol, grtol, gttol));
  PetscCall(TaoGetConvergedReason(tao_, reason));
  PetscCall(TaoGetIterationNumber(tao_, its));
  const PetscScalar *xa;
  y->resize(n);
  PetscCall(VecGetArrayRead(x_, &xa));
  for (PetscInt i = 0; i < n; ++i) {
    const PetscReal v = PetscRealPart(xa[i]);
    (*y)[i]           = std::isfinite(v) ? std::max((PetscReal)0, v) : 0; // clip to >= 0
  }
  PetscCall(VecRestoreArrayRead(x_, &xa));
  PetscFunctionReturn(0);
}

PetscErrorCode NNLSSolver::Solve(const DenseMatrix &Q, const std::vector<PetscReal> &b, std::vector<PetscReal> *x, NNLSStats *stats, NNLSInfo *info, const std::vector<PetscReal> *start)
{
  const PetscInt R = Q.rows, n = Q.cols;
  NNLSInfo       local;
  NNLSInfo      &inf = info ? *info : local;
  PetscReal      bnorm = 0;

  PetscFunctionBeginUser;
  PetscCheck((PetscInt)b.size() == R, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "NNLS: b has %zu entries, Q has %" PetscInt_FMT " rows", b.size(), R);
  PetscCall(RegisterNNLSEvent());
  PetscCall(PetscLogEventBegin(NNLS_Solve, 0, 0, 0, 0));
  inf = NNLSInfo();
  x->assign(n, 0.0);
  if (stats) ++stats->solves;
  for (PetscReal v : b) bnorm += v * v;
  bnorm = std::sqrt(bnorm);

  // Equilibrate Q (unit columns; zero columns are dropped and carry x_j = 0); cached while Q is unchanged.
  if (!(lastQ_.rows == R && lastQ_.cols == n && lastQ_.a == Q.a)) {
    lastQ_ = Q;
    colNorm_.assign(n, 0.0);
    cols_.clear();
    nonnegative_ = true;
    for (PetscInt j = 0; j < n; ++j) {
      for (PetscInt i = 0; i < R; ++i) {
        colNorm_[j] += Q(i, j) * Q(i, j);
        if (Q(i, j) < 0) nonnegative_ = false;
      }
      colNorm_[j] = std::sqrt(colNorm_[j]);
      if (colNorm_[j] > 0) cols_.push_back(j);
    }
    const PetscInt nc = (PetscInt)cols_.size();
    Qs_.Resize(R, nc);
    for (PetscInt k = 0; k < nc; ++k)
      for (PetscInt i = 0; i < R; ++i) Qs_(i, k) = Q(i, cols_[k]) / colNorm_[cols_[k]];
    Hs_.assign((size_t)nc * nc, 0.0);
    for (PetscInt k = 0; k < nc; ++k)
      for (PetscInt l = 0; l <= k; ++l) {
        PetscReal s = 0;
        for (PetscInt i = 0; i < R; ++i) s += Qs_(i, k) * Qs_(i, l);
        Hs_[k + (size_t)l * nc] = Hs_[l + (size_t)k * nc] = s;
      }
  }
  const PetscInt         nc = (PetscInt)cols_.size();
  std::vector<PetscReal> bs(R), cs(nc, 0.0), y, best;
  bool                   trivial = bnorm == 0 || nc == 0;
  if (!trivial) {
    for (PetscInt i = 0; i < R; ++i) bs[i] = b[i] / bnorm;
    PetscReal cmax = 0;
    for (PetscInt k = 0; k < nc; ++k) {
      for (PetscInt i = 0; i < R; ++i) cs[k] += Qs_(i, k) * bs[i];
      cmax = std::max(cmax, cs[k]);
    }
    trivial = !(cmax > 0); // gradient -Q^T b >= 0 at 0: x = 0 is optimal (b = 0, b in the polar cone)
  }
  if (!trivial) {
    // attempts, in order until the KKT check passes: -nnls_method tao: TAO (gatol), TAO (gatol / 10), the
    // active-set method alone; activeset: from the start's support (if given), from zero, then TAO twice
    enum Kind { TaoFull, TaoTight, ActiveWarm, ActiveCold };
    std::vector<Kind> plan;
    if (useTao_) plan = {TaoFull, TaoTight, ActiveCold};
    else {
      if (start && (PetscInt)start->size() == n) plan.push_back(ActiveWarm);
      plan.insert(plan.end(), {ActiveCold, TaoFull, TaoTight});
    }
    PetscReal bestKKT = PETSC_MAX_REAL;
    NNLSInfo  bestInfo;
    for (size_t attempt = 0; attempt < plan.size(); ++attempt) {
      NNLSInfo a;
      a.attempts = (PetscInt)attempt + 1;
      if (plan[attempt] == TaoFull || plan[attempt] == TaoTight) {
        PetscCall(SolveTao(Hs_, cs, nonnegative_ ? PETSC_TRUE : PETSC_FALSE, plan[attempt] == TaoFull ? 1.0 : 0.1, &y, &a.taoIterations, &a.taoReason));
        if (polish_) {
          PetscReal ymax = 0;
          for (PetscReal v : y) ymax = std::max(ymax, v);
          for (PetscReal &v : y) if (v <= supportTol_ * ymax) v = 0; // interior-point "zeros"
          PetscCall(NNLSLawsonHanson(Qs_, bs, &y, 5 * nc + 50, &a.polishIterations));
        }
      } else {
        y.assign(nc, 0.0);
        if (plan[attempt] == ActiveWarm) // y = x ||q_j|| / ||b||: its support starts the method
          for (PetscInt k = 0; k < nc; ++k) y[k] = std::max((PetscReal)0, (*start)[cols_[k]] * colNorm_[cols_[k]] / bnorm);
        PetscCall(NNLSLawsonHanson(Qs_, bs, &y, 5 * nc + 50, &a.polishIterations));
      }
      a.kkt = NNLSKKT(Qs_, bs, y);
      if (stats) {
        stats->taoIterations += a.taoIterations;
        stats->polishIterations += a.polishIterations;
      }
      if (a.kkt < bestKKT) { bestKKT = a.kkt; best = y; bestInfo = a; }
      if (a.kkt <= kktTol_) break;
      if (attempt + 1 < plan.size() && stats) ++stats->retries;
      PetscCall(PetscInfo(NULL, "NNLS attempt %" PetscInt_FMT " (R %" PetscInt_FMT ", n %" PetscInt_FMT "): scaled KKT %g > -nnls_kkt_tol %g, TAO reason %s\n", (PetscInt)attempt + 1, R, n, (double)a.kkt, (double)kktTol_, TaoConvergedReasons[a.taoReason]));
    }
    inf    = bestInfo;
    inf.ok = bestKKT <= kktTol_ ? PETSC_TRUE : PETSC_FALSE;
    if (!inf.ok && stats) ++stats->failures;
    for (PetscInt k = 0; k < nc; ++k) (*x)[cols_[k]] = best[k] * bnorm / colNorm_[cols_[k]];
  }
  if (stats) stats->maxKKT = std::max(stats->maxKKT, inf.kkt);
  // the residual with the original Q and b
  std::vector<PetscReal> r;
  Residual(Q, b, *x, &r);
  PetscReal rn = 0;
  for (PetscReal v : r) rn += v * v;
  inf.residual = std::sqrt(rn);
  PetscCall(PetscLogEventEnd(NNLS_Solve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

} // namespace rbc
