// src/rom/reduced_qp.cpp: the online reduced saddle-point QP (ReducedQP): set-up of the equilibrated
// dual (Cholesky of A, S = D A^{-1} D', b), the Lawson-Hanson-type active-set method on S with
// incremental Cholesky factors of S on the free set (dependent constraints handled by null-space ray
// steps, unboundedness = primal infeasibility), the TAO BQPIP cross-check, v = A^{-1}(f - D'lambda) and
// the scaled KKT residuals; for an A that does not change between solves, its factor kept (FactorA) and the set-up
// from D L^{-T} formed by the caller (SolveFactored). See docs/reduced_qp.md.
#include "rbcontact/tao_recipe.hpp"
#include "rbcontact/reduced_qp.hpp"
#include "dense_kernels.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace rbc {

namespace {
// ||M||_inf of an m x n column-major matrix (rows: work space of m); false if an entry or a row sum
// is not finite.
bool MaxRowSum(PetscInt m, PetscInt n, const PetscReal *M, PetscReal *rows, PetscReal *norm)
{
  bool finite = true;
  *norm       = 0;
  for (PetscInt i = 0; i < m; ++i) rows[i] = 0;
  for (PetscInt j = 0; j < n; ++j)
    for (PetscInt i = 0; i < m; ++i) rows[i] += std::abs(M[i + j * m]);
  for (PetscInt i = 0; i < m; ++i) {
    finite = finite && std::isfinite(rows[i]);
    *norm  = std::max(*norm, rows[i]);
  }
  return finite;
}

// Free-set pivot test on the unit-diagonal S: a constraint whose column makes S_PP's new Cholesky
// pivot^2 (= sin^2 of its angle to the span of the free ones, in the A^{-1} inner product) smaller
// than this is treated as linearly dependent on the free set.
constexpr PetscReal kPivotTol = 1e-12;
// A is "not SPD" when a Cholesky pivot^2 is below this times its largest diagonal entry.
constexpr PetscReal kSPDTol = 64 * PETSC_MACHINE_EPSILON;
// TAO: iteration limit reached counts as converged when every scaled KKT residual is below this.
constexpr PetscReal kTaoAcceptKKT = 1e-6;
constexpr PetscReal kTiny         = std::numeric_limits<PetscReal>::min();

const char *const kTypeNames[] = {"activeset", "tao"};

inline PetscBLASInt B(PetscInt i) { return (PetscBLASInt)i; }

// x <- L^{-1} x and x <- L^{-T} x for one vector, L lower (n x n, leading dimension n): plain loops,
// 2-3x faster than the reference BLAS trsm call for n <= 60.
inline void ForwardSolve(PetscInt n, const PetscReal *L, PetscReal *x)
{
  for (PetscInt k = 0; k < n; ++k) {
    const PetscReal *col = &L[(size_t)k * n], xk = x[k] / col[k];
    x[k]                 = xk;
    for (PetscInt i = k + 1; i < n; ++i) x[i] -= col[i] * xk;
  }
}
inline void BackwardSolveT(PetscInt n, const PetscReal *L, PetscReal *x)
{
  for (PetscInt k = n - 1; k >= 0; --k) {
    const PetscReal *col = &L[(size_t)k * n];
    PetscReal        t   = x[k];
    for (PetscInt i = k + 1; i < n; ++i) t -= col[i] * x[i];
    x[k] = t / col[k];
  }
}

} // namespace

const char *ReducedQPStatusName(ReducedQPStatus s)
{
  switch (s) {
  case ReducedQPStatus::Ok: return "ok";
  case ReducedQPStatus::NotSPD: return "not_spd";
  case ReducedQPStatus::Infeasible: return "infeasible";
  case ReducedQPStatus::Singular: return "singular";
  case ReducedQPStatus::MaxIt: return "max_it";
  case ReducedQPStatus::TaoFailed: return "tao_failed";
  }
  return "unknown";
}

ReducedQP::~ReducedQP() { (void)Reset(); }

PetscErrorCode ReducedQP::Reset()
{
  PetscFunctionBeginUser;
  PetscCall(TaoDestroy(&tao_));
  PetscCall(MatDestroy(&H_));
  PetscCall(VecDestroy(&x_));
  PetscCall(VecDestroy(&cv_));
  PetscCall(VecDestroy(&lo_));
  PetscCall(VecDestroy(&hi_));
  taoR_   = -1;
  cachedA_ = cachedD_ = factored_ = unit_ = false;
  PetscFunctionReturn(0);
}

PetscErrorCode ReducedQP::SetFromOptions(const std::string &prefix)
{
  PetscInt t = (PetscInt)type;

  PetscFunctionBeginUser;
  PetscOptionsBegin(PETSC_COMM_SELF, prefix.c_str(), "Reduced (online) contact QP", "ReducedQP");
  PetscCall(PetscOptionsEList("-qp_type", "Reduced QP solver: activeset (exact, fast) or tao (BQPIP cross-check)", "ReducedQP", kTypeNames, 2, kTypeNames[t], &t, NULL));
  PetscCall(PetscOptionsInt("-qp_max_it", "Maximum active-set iterations (Cholesky solves on the free set)", "ReducedQP", maxIt, &maxIt, NULL));
  PetscOptionsEnd();
  PetscCheck(maxIt >= 1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-%sqp_max_it %" PetscInt_FMT " must be >= 1", prefix.c_str(), maxIt);
  type = (ReducedQPType)t;
  // the Tao reads its options (-<prefix>qp_tao_*) when it is created: start afresh
  PetscCall(TaoDestroy(&tao_));
  taoR_   = -1;
  prefix_ = prefix;
  PetscFunctionReturn(0);
}

void ReducedQP::Reserve(PetscInt N, PetscInt R)
{
  N     = std::max<PetscInt>(N, 1);
  R     = std::max<PetscInt>(R, 1);
  nCap_ = std::max(nCap_, N);
  rCap_ = std::max(rCap_, R);
  const size_t n = nCap_, r = rCap_;
  Ac_.resize(n * n);
  Dc_.resize(r * n);
  L_.resize(n * n);
  G_.resize(r * n);
  S_.resize(r * r);
  Lf_.resize(r * r);
  for (auto *vec : {&s_, &b_, &l_, &z_, &w_, &t_, &tR_}) vec->resize(r);
  for (auto *vec : {&y_, &tN_}) vec->resize(n);
  P_.resize(r);
  inP_.resize(r);
  blocked_.resize(r);
}

// A = L L' into L_ and ||A||_inf into normA_ (A finite: checked here); info NotSPD when a pivot breaks down or is
// negligible.
PetscErrorCode ReducedQP::FactorInto(PetscInt N, const PetscReal *A, ReducedQPInfo *info)
{
  const PetscBLASInt n = B(N), ldn = B(std::max<PetscInt>(N, 1));

  PetscFunctionBeginUser;
  factored_ = unit_ = false;
  PetscCheck(MaxRowSum(N, N, A, tN_.data(), &normA_), PETSC_COMM_SELF, PETSC_ERR_FP, "ReducedQP: non-finite entry in A (or a row sum overflows)");
  PetscReal amax = 0;
  std::copy_n(A, N * N, L_.data());
  for (PetscInt i = 0; i < N; ++i) amax = std::max(amax, A[i + i * N]);
  PetscBLASInt linfo = 0;
  if (N) LAPACKpotrf_("L", &n, L_.data(), &ldn, &linfo);
  PetscInt  bad   = linfo > 0 ? (PetscInt)linfo - 1 : -1;
  PetscReal pivot = linfo > 0 ? L_[bad + bad * N] : 0;
  for (PetscInt i = 0; bad < 0 && i < N; ++i)
    if (L_[i + i * N] * L_[i + i * N] <= kSPDTol * amax) { bad = i; pivot = L_[i + i * N] * L_[i + i * N]; }
  if (bad >= 0 || (amax <= 0 && N > 0)) {
    char buf[320];
    std::snprintf(buf, sizeof buf, "reduced matrix A is not symmetric positive definite (Cholesky breaks down at row %" PetscInt_FMT ": squared pivot %g, largest diagonal entry %g): the primal reduced basis is not linearly independent or the reduced operator is wrong", bad, (double)pivot, (double)amax);
    info->message = buf;
    info->status  = ReducedQPStatus::NotSPD;
  }
  PetscFunctionReturn(0);
}

// From GT = D L^{-T} in G_ (R x N): the lower triangle of S = GT GT', the equilibration s (unit diagonal; 1 for a zero
// row of D), S made full, the rows of GT scaled by s.
void ReducedQP::DualHessian(PetscInt N, PetscInt R)
{
  LowerGram(R, N, G_.data(), S_.data());
  for (PetscInt i = 0; i < R; ++i) s_[i] = S_[i + i * R] > 0 ? 1.0 / std::sqrt(S_[i + i * R]) : 1.0;
  for (PetscInt j = 0; j < R; ++j) {
    for (PetscInt i = j + 1; i < R; ++i) {
      const PetscReal sij = S_[i + j * R] * s_[i] * s_[j];
      S_[i + j * R]       = sij;
      S_[j + i * R]       = sij;
    }
    S_[j + j * R] = S_[j + j * R] > 0 ? 1.0 : 0.0;
  }
  for (PetscInt k = 0; k < N; ++k)
    for (PetscInt i = 0; i < R; ++i) G_[i + k * R] *= s_[i];
}

// y = L^{-1} f, b = GT y - diag(s) c (f, c finite: checked by the caller)
void ReducedQP::RightHandSide(PetscInt N, PetscInt R, const PetscReal *f, const PetscReal *c)
{
  std::copy_n(f, N, y_.data());
  if (!unit_) ForwardSolve(N, L_.data(), y_.data());
  for (PetscInt i = 0; i < R; ++i) b_[i] = -s_[i] * c[i];
  for (PetscInt k = 0; k < N; ++k) {
    const PetscReal yk = y_[k], *g = &G_[(size_t)k * R];
    for (PetscInt i = 0; i < R; ++i) b_[i] += yk * g[i];
  }
}

// Factorization of A, S = diag(s) D A^{-1} D' diag(s) (unit diagonal) and b = diag(s)(D A^{-1} f - c).
// The Cholesky factor of A is kept while A stays bitwise the same, GT and S while A and D do.
PetscErrorCode ReducedQP::Setup(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *D, const PetscReal *c, ReducedQPInfo *info)
{
  PetscFunctionBeginUser;
  bool finite = true;
  for (PetscInt i = 0; i < N; ++i) finite = finite && std::isfinite(f[i]);
  for (PetscInt i = 0; i < R; ++i) finite = finite && std::isfinite(c[i]);
  PetscCheck(finite, PETSC_COMM_SELF, PETSC_ERR_FP, "ReducedQP: non-finite entry in f or c");
  const bool hitA = reuseFactorization && cachedA_ && cN_ == N && std::equal(A, A + (size_t)N * N, Ac_.data());
  const bool hitD = hitA && cachedD_ && cR_ == R && std::equal(D, D + (size_t)R * N, Dc_.data());
  if (!hitA) {
    cachedA_ = cachedD_ = false;
    PetscCall(FactorInto(N, A, info));
    if (info->status == ReducedQPStatus::NotSPD) PetscFunctionReturn(0);
    if (reuseFactorization) {
      std::copy_n(A, N * N, Ac_.data());
      cachedA_ = true;
      cN_      = N;
    }
  }
  if (!hitD) {
    cachedD_ = false;
    finite   = MaxRowSum(R, N, D, tR_.data(), &normD_) && finite;
    PetscCheck(finite, PETSC_COMM_SELF, PETSC_ERR_FP, "ReducedQP: non-finite entry in D (or a row sum overflows)");
    // GT = D L^{-T} (R x N; GT' = L^{-1} D'), then S and the equilibration
    RightSolveT(R, N, L_.data(), D, G_.data());
    DualHessian(N, R);
    if (reuseFactorization) {
      std::copy_n(D, R * N, Dc_.data());
      cachedD_ = true;
      cR_      = R;
    }
  }
  RightHandSide(N, R, f, c);
  PetscFunctionReturn(0);
}

PetscErrorCode ReducedQP::FactorA(PetscInt N, const PetscReal *A, ReducedQPInfo *info)
{
  PetscFunctionBeginUser;
  PetscCheck(N >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "ReducedQP: size N = %" PetscInt_FMT " must be >= 0", N);
  info->status = ReducedQPStatus::Ok;
  info->message.clear();
  if (N > nCap_ || !nCap_) Reserve(N, std::max<PetscInt>(rCap_, 1));
  cachedA_ = cachedD_ = false;
  PetscCall(FactorInto(N, A, info));
  if (info->status != ReducedQPStatus::Ok) PetscFunctionReturn(0);
  std::copy_n(A, N * N, Ac_.data()); // Solve with this A reuses the factor (and SolveFactored's residuals read it)
  cachedA_  = reuseFactorization;
  cN_       = N;
  factored_ = true;
  PetscFunctionReturn(0);
}

void ReducedQP::SetIdentityA(PetscInt N)
{
  if (HasIdentity(N)) return;
  N = std::max<PetscInt>(N, 0);
  if (N > nCap_ || !nCap_) Reserve(N, std::max<PetscInt>(rCap_, 1));
  std::fill(Ac_.begin(), Ac_.begin() + (size_t)N * N, 0.0);
  std::fill(L_.begin(), L_.begin() + (size_t)N * N, 0.0);
  for (PetscInt i = 0; i < N; ++i) Ac_[i + (size_t)i * N] = L_[i + (size_t)i * N] = 1;
  normA_    = N > 0 ? 1 : 0;
  cachedA_  = reuseFactorization;
  cachedD_  = false;
  cN_       = N;
  factored_ = unit_ = true;
}

// Appends constraint j as row k of the Cholesky factor Lf_ of S_PP (P = P_[0..k-1]). Returns false
// (factor unchanged, t_ = L_P^{-1} S_Pj) when the new pivot^2 is below kPivotTol (j depends on P).
bool ReducedQP::AppendFree(PetscInt R, PetscInt k, PetscInt j, PetscReal *pivot2)
{
  const PetscBLASInt kk = B(k), ldr = B(R), one = 1;
  PetscBLASInt       info = 0;
  PetscReal          p2   = S_[j + j * R];

  for (PetscInt q = 0; q < k; ++q) t_[q] = S_[P_[q] + j * R];
  if (k) LAPACKtrtrs_("L", "N", "N", &kk, &one, Lf_.data(), &ldr, t_.data(), &kk, &info);
  for (PetscInt q = 0; q < k; ++q) p2 -= t_[q] * t_[q];
  *pivot2 = p2;
  if (info || !(p2 > kPivotTol * S_[j + j * R])) return false;
  for (PetscInt q = 0; q < k; ++q) Lf_[k + q * R] = t_[q];
  Lf_[k + k * R] = std::sqrt(p2);
  return true;
}

// Cholesky factor of S_PP from scratch (P = P_[0..k-1]); false if not numerically positive definite.
bool ReducedQP::Refactor(PetscInt R, PetscInt k)
{
  const PetscBLASInt kk = B(k), ldr = B(R);
  PetscBLASInt       info = 0;

  if (!k) return true;
  for (PetscInt q = 0; q < k; ++q)
    for (PetscInt p = q; p < k; ++p) Lf_[p + q * R] = S_[P_[p] + P_[q] * R];
  LAPACKpotrf_("L", &kk, Lf_.data(), &ldr, &info);
  if (info) return false;
  for (PetscInt q = 0; q < k; ++q)
    if (!(Lf_[q + q * R] * Lf_[q + q * R] > 1e-2 * kPivotTol)) return false;
  return true;
}

// Lawson-Hanson active-set method for min 1/2 l'Sl - b'l, l >= 0 (S = S_, b = b_, unit diagonal),
// l in/out (scaled multipliers; positive entries = warm start). The free set P is kept linearly
// independent: a constraint whose column depends on P is entered by a ray step along the null
// direction d = e_j - S_PP^{-1} S_Pj (S d = 0), which ends when a free multiplier reaches zero; if d >= 0
// with b'd > 0 the dual is unbounded (the primal infeasible).
void ReducedQP::ActiveSet(PetscInt R, PetscReal *l, ReducedQPInfo *info)
{
  const PetscBLASInt ldr = B(R), one = 1;
  PetscInt           k = 0, its = 0, justAdded = -1;
  PetscReal          bmax = 0;
  char               buf[400];

  for (PetscInt i = 0; i < R; ++i) {
    bmax        = std::max(bmax, std::abs(b_[i]));
    inP_[i]     = 0;
    blocked_[i] = 0;
    if (l[i] > 0) { P_[k++] = i; inP_[i] = 1; }
    else l[i] = 0;
  }
  if (k && !Refactor(R, k)) { // warm start with dependent constraints: keep an independent subset
    PetscInt  m = 0;
    PetscReal p2;
    for (PetscInt q = 0; q < k; ++q) {
      const PetscInt j = P_[q];
      if (AppendFree(R, m, j, &p2)) P_[m++] = j;
      else { l[j] = 0; inP_[j] = 0; }
    }
    k = m;
  }
  bool needSolve = k > 0;
  for (;;) {
    // Inner loop: from feasible l (l_P > 0 except a just-added entry, 0) towards the minimizer on P.
    while (needSolve && k > 0) {
      if (its >= maxIt) goto maxit;
      ++its;
      const PetscBLASInt kk = B(k);
      PetscBLASInt       linfo = 0;
      for (PetscInt q = 0; q < k; ++q) z_[q] = b_[P_[q]];
      LAPACKpotrs_("L", &kk, &one, Lf_.data(), &ldr, z_.data(), &kk, &linfo);
      bool feasible = true;
      for (PetscInt q = 0; q < k; ++q) feasible = feasible && z_[q] > 0;
      if (feasible) {
        for (PetscInt q = 0; q < k; ++q) l[P_[q]] = z_[q];
        justAdded = -1;
        break;
      }
      if (justAdded >= 0 && !(z_[k - 1] > 0)) {
        // Lawson-Hanson's safeguard: the entering multiplier (in theory w_j / pivot^2 > 0) is not positive
        // in floating point; keep it out until the next step (its row is the factor's last: drop it)
        inP_[justAdded] = 0;
        blocked_[justAdded] = 1;
        --k;
        justAdded = -1;
        break;
      }
      justAdded          = -1;
      PetscReal alpha = 1;
      PetscInt  qmin  = -1;
      for (PetscInt q = 0; q < k; ++q)
        if (!(z_[q] > 0)) {
          const PetscReal lq = l[P_[q]], a = lq / (lq - z_[q]);
          if (qmin < 0 || a < alpha) { alpha = a; qmin = q; }
        }
      for (PetscInt q = 0; q < k; ++q) l[P_[q]] += alpha * (z_[q] - l[P_[q]]);
      l[P_[qmin]] = 0;
      PetscInt m = 0;
      for (PetscInt q = 0; q < k; ++q) {
        const PetscInt i = P_[q];
        if (l[i] > 0) P_[m++] = i;
        else { l[i] = 0; inP_[i] = 0; }
      }
      k = m;
      if (!Refactor(R, k)) goto singular;
    }
    needSolve = true;
    // w = b - S l (the scaled primal residual c - D v), largest on the zero set
    PetscReal l1 = 0;
    for (PetscInt i = 0; i < R; ++i) w_[i] = b_[i];
    for (PetscInt q = 0; q < k; ++q) {
      const PetscInt   p  = P_[q];
      const PetscReal  lp = l[p], *col = &S_[(size_t)p * R];
      l1 += lp;
      for (PetscInt i = 0; i < R; ++i) w_[i] -= col[i] * lp;
    }
    const PetscReal tol = 64 * PETSC_MACHINE_EPSILON * (bmax + l1);
    for (;;) {
      PetscInt  j    = -1;
      PetscReal best = tol;
      for (PetscInt i = 0; i < R; ++i)
        if (!inP_[i] && !blocked_[i] && w_[i] > best) { best = w_[i]; j = i; }
      if (j < 0) goto done;
      PetscReal p2;
      if (AppendFree(R, k, j, &p2)) {
        P_[k++]   = j;
        inP_[j]   = 1;
        l[j]      = 0;
        justAdded = j;
        std::fill(blocked_.begin(), blocked_.begin() + R, 0);
        break;
      }
      // j depends on the free set: a = S_PP^{-1} S_Pj, d = e_j - a, S d = 0 (up to the pivot test)
      PetscBLASInt linfo = 0;
      const PetscBLASInt kk = B(k);
      if (k) LAPACKtrtrs_("L", "T", "N", &kk, &one, Lf_.data(), &ldr, t_.data(), &kk, &linfo);
      PetscReal bd = b_[j], amax = 0;
      for (PetscInt q = 0; q < k; ++q) { bd -= t_[q] * b_[P_[q]]; amax = std::max(amax, std::abs(t_[q])); }
      if (!(bd > tol)) { blocked_[j] = 1; continue; } // no descent along d: j's constraint is redundant here
      const PetscReal atol = 1e-12 * amax;
      PetscReal       step = 0;
      PetscInt        qmin = -1;
      for (PetscInt q = 0; q < k; ++q)
        if (t_[q] > atol) {
          const PetscReal sq = l[P_[q]] / t_[q];
          if (qmin < 0 || sq < step) { step = sq; qmin = q; }
        }
      if (qmin < 0) { // d >= 0, S d = 0, b'd > 0: the dual is unbounded, the primal infeasible
        PetscInt nd = 1;
        for (PetscInt q = 0; q < k; ++q) nd += t_[q] < -atol;
        std::snprintf(buf, sizeof buf,
                      "reduced constraints D v <= c are infeasible (the dual is unbounded along d >= 0 with S d = 0, b'd > 0, on %" PetscInt_FMT " constraints, e.g. %" PetscInt_FMT "): "
                      "the reduced constraints are inconsistent, the dual basis is too rich for the primal one; add -pod_supremizers or reduce R",
                      nd, j);
        info->status  = ReducedQPStatus::Infeasible;
        info->message = buf;
        goto finish;
      }
      // Along d the objective changes by -step b'd + step^2 p2 / 2 (p2 = d'Sd >= 0, below the pivot
      // tolerance): no decrease means S_PP+j is too ill-conditioned to tell j from the free set.
      if (!(step * p2 < 2 * bd)) goto singular;
      if (its >= maxIt) goto maxit;
      ++its;
      for (PetscInt q = 0; q < k; ++q) l[P_[q]] -= step * t_[q];
      l[P_[qmin]] = 0;
      l[j]        = step;
      PetscInt m  = 0;
      for (PetscInt q = 0; q < k; ++q) {
        const PetscInt i = P_[q];
        if (l[i] > 0) P_[m++] = i;
        else { l[i] = 0; inP_[i] = 0; }
      }
      k       = m;
      P_[k++] = j;
      inP_[j] = 1;
      std::fill(blocked_.begin(), blocked_.begin() + R, 0);
      justAdded = -1;
      if (!Refactor(R, k)) goto singular;
      break;
    }
  }
maxit:
  std::snprintf(buf, sizeof buf, "active-set method stopped at the iteration limit (%" PetscInt_FMT ", -%sqp_max_it) without meeting the KKT conditions (cycling on nearly degenerate constraints?): increase -%sqp_max_it", maxIt, prefix_.c_str(), prefix_.c_str());
  info->status  = ReducedQPStatus::MaxIt;
  info->message = buf;
  goto finish;
singular:
  info->status  = ReducedQPStatus::Singular;
  info->message = "reduced dual Hessian S is singular on the active set (rank-deficient reduced constraints): the dual basis is too rich for the primal one; add -pod_supremizers or reduce R";
  for (PetscInt i = 0; i < R; ++i) if (!inP_[i]) l[i] = 0;
  goto finish;
done:
finish:
  info->iterations = its;
}

// v = A^{-1}(f - D' lambda) = L^{-T}(y - GT' l), l the scaled multipliers.
void ReducedQP::Recover(PetscInt N, PetscInt R, const PetscReal *l, PetscReal *v)
{
  if (!N) return;
  std::copy_n(y_.data(), N, v);
  for (PetscInt i = 0; i < R; ++i) // only the positive multipliers contribute
    if (l[i] != 0) {
      const PetscReal li = l[i], *g = &G_[i];
      for (PetscInt k = 0; k < N; ++k) v[k] -= g[(size_t)k * R] * li;
    }
  if (!unit_) BackwardSolveT(N, L_.data(), v);
}

// Scaled KKT residuals of (v, lambda) with the caller's A, f, D, c (one pass over A and one over D).
void ReducedQP::KKT(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *D, const PetscReal *c, const PetscReal *v, const PetscReal *lambda, ReducedQPInfo *info)
{
  PetscReal cn = 0, fn = 0, vn = 0, ln = 0, rmax = 0, neg = 0, lr = 0, st = 0;

  for (PetscInt i = 0; i < N; ++i) { fn = std::max(fn, std::abs(f[i])); vn = std::max(vn, std::abs(v[i])); }
  for (PetscInt i = 0; i < R; ++i) {
    cn     = std::max(cn, std::abs(c[i]));
    ln     = std::max(ln, std::abs(lambda[i]));
    neg    = std::max(neg, -lambda[i]);
    tR_[i] = -c[i];
  }
  // tR = D v - c and tN = A v - f + D'lambda, column by column (contiguous, vectorizable updates)
  for (PetscInt i = 0; i < N; ++i) tN_[i] = -f[i];
  for (PetscInt k = 0; k < N; ++k) {
    const PetscReal *d = &D[(size_t)k * R], *a = &A[(size_t)k * N], vk = v[k];
    for (PetscInt i = 0; i < R; ++i) tR_[i] += vk * d[i];
    for (PetscInt i = 0; i < N; ++i) tN_[i] += vk * a[i];
  }
  for (PetscInt i = 0; i < R; ++i)
    if (lambda[i] != 0) {
      const PetscReal li = lambda[i], *d = &D[i];
      for (PetscInt k = 0; k < N; ++k) tN_[k] += d[(size_t)k * R] * li;
    }
  for (PetscInt i = 0; i < N; ++i) st = std::max(st, std::abs(tN_[i]));
  for (PetscInt i = 0; i < R; ++i) { rmax = std::max(rmax, tR_[i]); lr += lambda[i] * tR_[i]; }
  const PetscReal sc    = cn + normD_ * vn;
  info->primal          = rmax / (sc + kTiny);
  info->dual            = neg / (ln + kTiny);
  info->complementarity = std::abs(lr) / (ln * sc + kTiny);
  info->stationarity    = st / (fn + normA_ * vn + kTiny);
}

PetscErrorCode ReducedQP::SetupTao(PetscInt R)
{
  PetscFunctionBeginUser;
  if (tao_ && taoR_ == R) PetscFunctionReturn(0);
  PetscCall(TaoDestroy(&tao_));
  PetscCall(MatDestroy(&H_));
  PetscCall(VecDestroy(&x_));
  PetscCall(VecDestroy(&cv_));
  PetscCall(VecDestroy(&lo_));
  PetscCall(VecDestroy(&hi_));
  taoR_ = R;
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, R, R, NULL, &H_));
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, R, &x_));
  PetscCall(VecDuplicate(x_, &cv_));
  PetscCall(VecDuplicate(x_, &lo_));
  PetscCall(VecDuplicate(x_, &hi_));
  PetscCall(VecSet(lo_, 0.0));
  PetscCall(VecSet(hi_, PETSC_INFINITY));
  PetscCall(TaoCreate(PETSC_COMM_SELF, &tao_));
  PetscCall(TaoSetOptionsPrefix(tao_, (prefix_ + "qp_").c_str()));
  PetscCall(TaoSetSolution(tao_, x_));
  quad_.H = H_;
  quad_.c = cv_;
  PetscCall(TaoSetQuadratic(tao_, &quad_));
  PetscCall(TaoSetVariableBounds(tao_, lo_, hi_));
  // shared/notes/nnls-with-bqpip.md: absolute test only (the relative one fires spuriously), gatol 1e-7
  // (BQPIP's measure stalls near 3e-8), at most 200 iterations, inner Cholesky. Equilibration is done
  // by the caller (unit diagonal S, ||b|| = 1). No finite upper bound is provable here: [0, inf].
  PetscCall(TaoBQPIPRecipe(tao_));
  PetscCall(TaoSetFromOptions(tao_));
  PetscFunctionReturn(0);
}

// TAO cross-check on the equilibrated dual (S_, b_ / ||b_||); l out (scaled multipliers).
PetscErrorCode ReducedQP::SolveTao(PetscInt R, PetscReal *l, ReducedQPInfo *info)
{
  PetscScalar       *h, *a;
  const PetscScalar *xa;
  PetscReal          bn = 0, bmax = 0;
  TaoConvergedReason reason;
  PetscInt           its;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < R; ++i) { l[i] = 0; bn += b_[i] * b_[i]; bmax = std::max(bmax, b_[i]); }
  if (!(bmax > 0)) PetscFunctionReturn(0); // -b >= 0 is the gradient at 0: lambda = 0 is optimal, exactly
  bn = std::sqrt(bn);
  PetscCall(SetupTao(R));
  PetscCall(MatDenseGetArrayWrite(H_, &h));
  for (PetscInt k = 0; k < R * R; ++k) h[k] = S_[k];
  PetscCall(MatDenseRestoreArrayWrite(H_, &h));
  PetscCall(MatAssemblyBegin(H_, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(H_, MAT_FINAL_ASSEMBLY));
  PetscCall(VecGetArrayWrite(cv_, &a));
  for (PetscInt i = 0; i < R; ++i) a[i] = b_[i] / bn;
  PetscCall(VecRestoreArrayWrite(cv_, &a));
  PetscCall(VecSet(x_, 0.0));
  {
    // A failure inside BQPIP (e.g. a zero pivot of its inner Cholesky when S is singular or the dual
    // unbounded) is a numerical failure of the cross-check, reported in the status, not a PETSc error.
    PetscErrorCode ierr;
    TaoType        tt;
    PetscCall(TaoGetType(tao_, &tt));
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    ierr = TaoSolve(tao_);
    PetscCall(PetscPopErrorHandler());
    if (ierr) {
      char buf[400];
      std::snprintf(buf, sizeof buf, "TAO %s failed with PETSc error %d inside TaoSolve (typically a zero pivot of its inner Cholesky: S singular or the dual unbounded): use -%sqp_type activeset (exact; it also diagnoses singular or infeasible reduced constraints)", tt, (int)ierr,
                    prefix_.c_str());
      info->status  = ReducedQPStatus::TaoFailed;
      info->message = buf;
      PetscCall(TaoDestroy(&tao_)); // its state is unknown: a new Tao next time
      taoR_ = -1;
      PetscFunctionReturn(0);
    }
  }
  PetscCall(TaoGetConvergedReason(tao_, &reason));
  PetscCall(TaoGetIterationNumber(tao_, &its));
  PetscCall(VecGetArrayRead(x_, &xa));
  bool finite = true;
  for (PetscInt i = 0; i < R; ++i) {
    const PetscReal xi = PetscRealPart(xa[i]);
    finite             = finite && std::isfinite(xi);
    l[i]               = std::isfinite(xi) ? std::max<PetscReal>(xi, 0) * bn : 0;
  }
  PetscCall(VecRestoreArrayRead(x_, &xa));
  info->iterations = its;
  if (!finite || (reason < 0 && reason != TAO_DIVERGED_MAXITS)) {
    char      buf[400];
    TaoType   tt;
    PetscCall(TaoGetType(tao_, &tt));
    std::snprintf(buf, sizeof buf, "TAO %s failed (%s after %" PetscInt_FMT " iterations%s): use -%sqp_type activeset (exact; it also diagnoses singular or infeasible reduced constraints)", tt, TaoConvergedReasons[reason], its,
                  finite ? "" : ", non-finite iterate", prefix_.c_str());
    info->status  = ReducedQPStatus::TaoFailed;
    info->message = buf;
    if (!finite) std::fill(l, l + R, 0.0);
  } else if (reason == TAO_DIVERGED_MAXITS) info->status = ReducedQPStatus::MaxIt; // provisional: Solve checks the KKT residuals
  PetscFunctionReturn(0);
}

PetscErrorCode ReducedQP::Solve(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *D, const PetscReal *c, PetscReal *v, PetscReal *lambda, ReducedQPInfo *info)
{
  PetscFunctionBeginUser;
  PetscCheck(N >= 0 && R >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "ReducedQP: sizes N = %" PetscInt_FMT ", R = %" PetscInt_FMT " must be >= 0", N, R);
  info->status     = ReducedQPStatus::Ok;
  info->iterations = 0;
  info->nactive    = 0;
  info->message.clear();
  if (N > nCap_ || R > rCap_ || !nCap_) Reserve(N, R);
  {
    PetscErrorCode ierr = Setup(N, R, A, f, D, c, info);
    if (ierr) { // leave the outputs finite
      std::fill(v, v + N, 0.0);
      std::fill(lambda, lambda + R, 0.0);
      PetscCall(ierr);
    }
  }
  if (info->status == ReducedQPStatus::NotSPD) {
    std::fill(v, v + N, 0.0);
    std::fill(lambda, lambda + R, 0.0);
    KKT(N, R, A, f, D, c, v, lambda, info);
    PetscFunctionReturn(0);
  }
  PetscCall(Finish(N, R, v, lambda, info));
  if (residuals || type == ReducedQPType::Tao) KKT(N, R, A, f, D, c, v, lambda, info);
  TaoStatus(R, lambda, info);
  PetscFunctionReturn(0);
}

PetscErrorCode ReducedQP::SolveFactored(PetscInt N, PetscInt R, const PetscReal *f, const PetscReal *GT, const PetscReal *c, PetscReal *v, PetscReal *lambda, ReducedQPInfo *info)
{
  PetscFunctionBeginUser;
  PetscCheck(R >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "ReducedQP: size R = %" PetscInt_FMT " must be >= 0", R);
  PetscCheck(HasFactor(N), PETSC_COMM_SELF, PETSC_ERR_ORDER, "ReducedQP::SolveFactored: no factor of A with N = %" PetscInt_FMT " (call FactorA first; a Solve with another A replaces it)", N);
  info->status     = ReducedQPStatus::Ok;
  info->iterations = 0;
  info->nactive    = 0;
  info->message.clear();
  if (R > rCap_) Reserve(N, R);
  bool finite = true;
  for (PetscInt i = 0; i < N; ++i) finite = finite && std::isfinite(f[i]);
  for (PetscInt i = 0; i < R; ++i) finite = finite && std::isfinite(c[i]);
  PetscReal gn = 0;
  finite = MaxRowSum(R, N, GT, tR_.data(), &gn) && finite;
  if (!finite) {
    std::fill(v, v + N, 0.0);
    std::fill(lambda, lambda + R, 0.0);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FP, "ReducedQP: non-finite entry in f, c or D L^{-T} (or a row sum overflows)");
  }
  cachedD_ = false; // G_ and S_ are GT's now
  std::copy_n(GT, (size_t)R * N, G_.data());
  DualHessian(N, R);
  RightHandSide(N, R, f, c);
  PetscCall(Finish(N, R, v, lambda, info));
  if (residuals || type == ReducedQPType::Tao) ResidualsFactored(N, R, Ac_.data(), f, GT, c, v, lambda, info);
  TaoStatus(R, lambda, info);
  PetscFunctionReturn(0);
}

void ReducedQP::ResidualsFactored(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *GT, const PetscReal *c, const PetscReal *v, const PetscReal *lambda, ReducedQPInfo *info)
{
  // D = GT L' into the D cache's storage, then the residuals with D
  cachedD_     = false;
  PetscReal *D = Dc_.data();
  if (!A) A = Ac_.data();
  if (unit_) std::copy_n(GT, (size_t)R * N, D);
  else RightMulLT(R, N, L_.data(), GT, D);
  (void)MaxRowSum(R, N, D, tR_.data(), &normD_);
  KKT(N, R, A, f, D, c, v, lambda, info);
}

// The dual's solution from S_, b_ (the multipliers' warm start in lambda), v, lambda and the counts into info.
PetscErrorCode ReducedQP::Finish(PetscInt N, PetscInt R, PetscReal *v, PetscReal *lambda, ReducedQPInfo *info)
{
  PetscFunctionBeginUser;
  PetscReal *l = l_.data();
  if (type == ReducedQPType::ActiveSet) {
    for (PetscInt i = 0; i < R; ++i) l[i] = std::isfinite(lambda[i]) && lambda[i] > 0 ? lambda[i] / s_[i] : 0.0;
    ActiveSet(R, l, info);
  } else PetscCall(SolveTao(R, l, info));
  Recover(N, R, l, v);
  bool finite = true;
  for (PetscInt i = 0; i < R; ++i) {
    lambda[i] = s_[i] * l[i];
    finite    = finite && std::isfinite(lambda[i]);
    info->nactive += lambda[i] > 0;
  }
  for (PetscInt i = 0; i < N; ++i) finite = finite && std::isfinite(v[i]);
  if (!finite) { // overflow on a nearly infeasible problem: never hand out Inf/NaN
    std::fill(lambda, lambda + R, 0.0);
    Recover(N, R, lambda, v);
    info->nactive = 0;
    if (info->status == ReducedQPStatus::Ok) {
      info->status  = ReducedQPStatus::Singular;
      info->message = "reduced dual Hessian S is singular on the active set (rank-deficient reduced constraints; the multipliers overflowed): the dual basis is too rich for the primal one; add -pod_supremizers or reduce R";
    }
  }
  info->primal = info->dual = info->complementarity = info->stationarity = 0;
  PetscFunctionReturn(0);
}

// TAO: its count of active multipliers (> 1e-6 max lambda) and the iteration limit accepted when the KKT residuals are small.
void ReducedQP::TaoStatus(PetscInt R, const PetscReal *lambda, ReducedQPInfo *info)
{
  if (type != ReducedQPType::Tao) return;
  PetscReal lmax = 0;
  PetscInt  nact = 0;
  for (PetscInt i = 0; i < R; ++i) lmax = std::max(lmax, lambda[i]);
  for (PetscInt i = 0; i < R; ++i) nact += lambda[i] > 1e-6 * lmax;
  info->nactive = nact;
  if (info->status == ReducedQPStatus::MaxIt) {
    const PetscReal worst = std::max(std::max(info->primal, info->dual), std::max(info->complementarity, info->stationarity));
    if (worst <= kTaoAcceptKKT) info->status = ReducedQPStatus::Ok;
    else {
      char buf[300];
      std::snprintf(buf, sizeof buf, "TAO reached its iteration limit with scaled KKT residual %g > %g: increase -%sqp_tao_max_it or use -%sqp_type activeset", (double)worst, (double)kTaoAcceptKKT, prefix_.c_str(), prefix_.c_str());
      info->message = buf;
    }
  }
}

} // namespace rbc
