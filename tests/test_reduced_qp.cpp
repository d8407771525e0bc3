// tests/test_reduced_qp.cpp: the online reduced QP (rbc::ReducedQP): active set vs TAO BQPIP on random
// problems (also with badly scaled constraint rows), an analytic case, warm starts (iterations, bitwise
// reuse of the cached factorization), dependent constraints (R > N, S singular), infeasible
// constraints, a non-SPD A, the iteration limit, the options, no heap allocation in Solve after Reserve, and A
// factored once (FactorA, SolveFactored) against Solve, and a two-term A diagonalized once (AffineDiagonalization,
// SetIdentityA) against Solve.
#include "rbcontact/affine_diagonalization.hpp"
#include "rbcontact/reduced_qp.hpp"
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <random>

// Counts C++ heap allocations (the active-set path must not allocate after Reserve).
static std::atomic<long> gAllocs{0};
void *operator new(std::size_t n)
{
  ++gAllocs;
  if (void *p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void *p) noexcept { std::free(p); }
void operator delete(void *p, std::size_t) noexcept { std::free(p); }

using namespace rbc;
using Vecd = std::vector<PetscReal>;

static int failures = 0;
static void Check(bool ok, const char *what, double v, double bound)
{
  std::printf("  %-6s %-72s %.3e (bound %.1e)\n", ok ? "ok" : "FAIL", what, v, bound);
  if (!ok) ++failures;
}
static void CheckTrue(bool ok, const char *what)
{
  std::printf("  %-6s %s\n", ok ? "ok" : "FAIL", what);
  if (!ok) ++failures;
}

struct Problem {
  PetscInt N = 0, R = 0;
  Vecd     A, f, D, c;
};

static bool AllFinite(const Vecd &x)
{
  for (double v : x)
    if (!std::isfinite(v)) return false;
  return true;
}

static double NormInf(const Vecd &x)
{
  double m = 0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

// max |a - b| / max |b|
static double RelDiff(const Vecd &a, const Vecd &b)
{
  double d = 0;
  for (size_t i = 0; i < b.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d / NormInf(b);
}

// Independent KKT check (same scaling as ReducedQPInfo), plain loops.
static double WorstKKT(const Problem &p, const Vecd &v, const Vecd &l)
{
  double Dn = 0, An = 0, cn = NormInf(p.c), fn = NormInf(p.f), vn = NormInf(v), ln = NormInf(l);
  double rmax = 0, neg = 0, lr = 0, st = 0;
  for (PetscInt i = 0; i < p.R; ++i) {
    double row = 0, r = -p.c[i];
    for (PetscInt j = 0; j < p.N; ++j) { row += std::abs(p.D[i + j * p.R]); r += p.D[i + j * p.R] * v[j]; }
    Dn   = std::max(Dn, row);
    rmax = std::max(rmax, r);
    lr += l[i] * r;
    neg = std::max(neg, -l[i]);
  }
  for (PetscInt i = 0; i < p.N; ++i) {
    double row = 0, g = -p.f[i];
    for (PetscInt j = 0; j < p.N; ++j) { row += std::abs(p.A[i + j * p.N]); g += p.A[i + j * p.N] * v[j]; }
    for (PetscInt k = 0; k < p.R; ++k) g += p.D[k + i * p.R] * l[k];
    An = std::max(An, row);
    st = std::max(st, std::abs(g));
  }
  const double tiny = 1e-300, sc = cn + Dn * vn;
  return std::max(std::max(rmax / (sc + tiny), neg / (ln + tiny)), std::max(std::abs(lr) / (ln * sc + tiny), st / (fn + An * vn + tiny)));
}

static double InfoWorst(const ReducedQPInfo &in) { return std::max(std::max(in.primal, in.dual), std::max(in.complementarity, in.stationarity)); }

// Random SPD A = M'M/N + 0.1 I, f random; D random R x N (rows scaled by 10^rowScale[i] if asked);
// c = D A^{-1}f - gap with gap of both signs: about half of the constraints are active.
static Problem RandomProblem(PetscInt N, PetscInt R, unsigned seed, bool badRows)
{
  std::mt19937                     gen(seed);
  std::normal_distribution<double> G(0, 1);
  Problem                          p;
  p.N = N;
  p.R = R;
  Vecd M(N * N);
  for (auto &x : M) x = G(gen);
  p.A.assign(N * N, 0.0);
  for (PetscInt i = 0; i < N; ++i)
    for (PetscInt j = 0; j < N; ++j) {
      for (PetscInt k = 0; k < N; ++k) p.A[i + j * N] += M[k + i * N] * M[k + j * N] / N;
      if (i == j) p.A[i + j * N] += 0.1;
    }
  p.f.resize(N);
  for (auto &x : p.f) x = G(gen);
  p.D.resize(R * N);
  for (auto &x : p.D) x = G(gen);
  if (badRows)
    for (PetscInt i = 0; i < R; ++i)
      for (PetscInt j = 0; j < N; ++j) p.D[i + j * R] *= std::pow(10.0, (double)(i % 7) - 3);
  // v0 = A^{-1} f by Gaussian elimination (A SPD, small)
  Vecd a = p.A, v0 = p.f;
  for (PetscInt k = 0; k < N; ++k)
    for (PetscInt i = k + 1; i < N; ++i) {
      const double m = a[i + k * N] / a[k + k * N];
      for (PetscInt j = k; j < N; ++j) a[i + j * N] -= m * a[k + j * N];
      v0[i] -= m * v0[k];
    }
  for (PetscInt i = N - 1; i >= 0; --i) {
    for (PetscInt j = i + 1; j < N; ++j) v0[i] -= a[i + j * N] * v0[j];
    v0[i] /= a[i + i * N];
  }
  p.c.resize(R);
  for (PetscInt i = 0; i < R; ++i) {
    double dv = 0, rn = 0;
    for (PetscInt j = 0; j < N; ++j) { dv += p.D[i + j * R] * v0[j]; rn += std::abs(p.D[i + j * R]); }
    p.c[i] = dv + rn * 0.5 * G(gen);
  }
  return p;
}

static PetscErrorCode Run(ReducedQP &qp, const Problem &p, Vecd *v, Vecd *l, ReducedQPInfo *info)
{
  PetscFunctionBeginUser;
  v->assign(p.N, 0.0);
  l->resize(p.R, 0.0);
  PetscCall(qp.Solve(p.N, p.R, p.A.data(), p.f.data(), p.D.data(), p.c.data(), v->data(), l->data(), info));
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCall(PetscOptionsSetValue(NULL, "-t_qp_type", "tao"));
  PetscCall(PetscOptionsSetValue(NULL, "-o_qp_max_it", "7"));
  ReducedQP     as, tao;
  ReducedQPInfo ia, it;
  Vecd          va, la, vt, lt;
  PetscCall(as.SetFromOptions("x_"));
  PetscCall(tao.SetFromOptions("t_"));
  CheckTrue(as.type == ReducedQPType::ActiveSet && as.maxIt == 200, "defaults: activeset, max_it 200");
  CheckTrue(tao.type == ReducedQPType::Tao, "-t_qp_type tao selects the TAO cross-check");
  {
    ReducedQP o;
    PetscCall(o.SetFromOptions("o_"));
    CheckTrue(o.maxIt == 7, "-o_qp_max_it 7");
  }

  std::printf("1. random problems, R < N: active set vs TAO BQPIP\n");
  struct Size { PetscInt N, R; bool bad; };
  for (Size sz : {Size{8, 5, false}, Size{20, 12, false}, Size{40, 30, false}, Size{60, 50, false}, Size{20, 12, true}, Size{40, 30, true}}) {
    for (unsigned seed : {1u, 2u, 3u}) {
      const Problem p = RandomProblem(sz.N, sz.R, 100 * seed + sz.N + sz.R + sz.bad, sz.bad);
      la.assign(p.R, 0.0);
      lt.assign(p.R, 0.0);
      PetscCall(Run(as, p, &va, &la, &ia));
      PetscCall(Run(tao, p, &vt, &lt, &it));
      double dv = 0;
      for (PetscInt i = 0; i < p.N; ++i) dv = std::max(dv, std::abs(va[i] - vt[i]));
      dv /= NormInf(va);
      char what[160];
      std::printf(" N = %d R = %d%s seed %u: active set %d its, %d active, KKT %.1e; TAO %d its, status %s, KKT %.1e (p %.1e d %.1e c %.1e s %.1e)\n", (int)p.N, (int)p.R, sz.bad ? " (rows scaled 1e-3..1e3)" : "", seed, (int)ia.iterations,
                  (int)ia.nactive, InfoWorst(ia), (int)it.iterations, ReducedQPStatusName(it.status), InfoWorst(it), it.primal, it.dual, it.complementarity, it.stationarity);
      CheckTrue(ia.status == ReducedQPStatus::Ok && ia.message.empty(), "active set: status ok, empty message");
      CheckTrue(it.status == ReducedQPStatus::Ok, "TAO: status ok");
      CheckTrue(ia.nactive > 0 && ia.nactive < p.R, "some but not all constraints active");
      std::snprintf(what, sizeof what, "active set: reported scaled KKT residuals");
      Check(InfoWorst(ia) <= 1e-12, what, InfoWorst(ia), 1e-12);
      Check(WorstKKT(p, va, la) <= 1e-12, "active set: independently computed scaled KKT residuals", WorstKKT(p, va, la), 1e-12);
      Check(std::abs(WorstKKT(p, vt, lt) - InfoWorst(it)) <= 1e-3 * InfoWorst(it) + 1e-15, "TAO: reported KKT equals the independent one", std::abs(WorstKKT(p, vt, lt) - InfoWorst(it)), 1e-3 * InfoWorst(it) + 1e-15);
      Check(dv <= 1e-6, "v: active set vs TAO (relative, inf norm)", dv, 1e-6);
      CheckTrue(AllFinite(va) && AllFinite(la) && AllFinite(vt) && AllFinite(lt), "no NaN/Inf");
      double lmin = 0;
      for (double x : la) lmin = std::min(lmin, x);
      Check(lmin >= 0, "active set: lambda >= 0 exactly", -lmin, 0);

      // 3. warm start: the same problem from the previous multipliers, then with a perturbed gap
      Vecd          lw = la, vw;
      ReducedQPInfo iw;
      PetscCall(Run(as, p, &vw, &lw, &iw));
      Check(iw.iterations == 1 && iw.status == ReducedQPStatus::Ok, "warm start, same problem: iterations", iw.iterations, 1);
      double dl = 0;
      for (PetscInt i = 0; i < p.R; ++i) dl = std::max(dl, std::abs(lw[i] - la[i]));
      Check(dl <= 1e-13 * NormInf(la), "warm start, same problem: same multipliers", dl, 1e-13 * NormInf(la));
      Problem q = p;
      for (PetscInt i = 0; i < p.R; ++i) q.c[i] *= 1 + 1e-9;
      lw = la;
      PetscCall(Run(as, q, &vw, &lw, &iw));
      Check(iw.iterations <= 2 && iw.status == ReducedQPStatus::Ok, "warm start, gap perturbed by 1e-9: iterations", iw.iterations, 2);
      Check(WorstKKT(q, vw, lw) <= 1e-12, "warm start, gap perturbed: KKT", WorstKKT(q, vw, lw), 1e-12);
      // residuals = false (the reduced Kacanov loop): Solve leaves them at 0, Residuals() afterwards gives
      // the same numbers as the default path (same solution bits)
      {
        ReducedQP     lazy;
        Vecd          vz, lz(p.R, 0.0);
        ReducedQPInfo iz;
        lazy.residuals = false;
        PetscCall(Run(lazy, p, &vz, &lz, &iz));
        CheckTrue(iz.primal == 0 && iz.dual == 0 && iz.complementarity == 0 && iz.stationarity == 0, "residuals = false: Solve leaves the KKT residuals at 0");
        lazy.Residuals(p.N, p.R, p.A.data(), p.f.data(), p.D.data(), p.c.data(), vz.data(), lz.data(), &iz);
        const double dk = std::max(std::max(std::abs(iz.primal - ia.primal), std::abs(iz.dual - ia.dual)), std::max(std::abs(iz.complementarity - ia.complementarity), std::abs(iz.stationarity - ia.stationarity)));
        Check(dk == 0, "Residuals() after a lazy Solve equals the residuals of the default Solve", dk, 0);
      }
      // the cached factorization gives the same bits as a fresh one
      ReducedQP fresh;
      fresh.reuseFactorization = false;
      Vecd          vf, lf(p.R, 0.0);
      ReducedQPInfo inf;
      PetscCall(Run(fresh, p, &vf, &lf, &inf));
      CheckTrue(vf == va && lf == la, "no reuse of the factorization: bitwise the same solution");
    }
  }

  std::printf("2. analytic: A = diag(a), D = I: v = min(f/a, c), lambda = max(f - a c, 0)\n");
  {
    Problem p;
    p.N = p.R = 4;
    const double a[4] = {1.0, 2.0, 0.5, 3.0};
    p.A.assign(16, 0.0);
    p.D.assign(16, 0.0);
    for (int i = 0; i < 4; ++i) { p.A[i + 4 * i] = a[i]; p.D[i + 4 * i] = 1.0; }
    p.f = {1.0, -2.0, 3.0, 0.5};
    p.c = {0.25, 5.0, 1.0, 0.1};
    la.assign(4, 0.0);
    PetscCall(Run(as, p, &va, &la, &ia));
    double ev = 0, el = 0;
    for (int i = 0; i < 4; ++i) {
      ev = std::max(ev, std::abs(va[i] - std::min(p.f[i] / a[i], p.c[i])));
      el = std::max(el, std::abs(la[i] - std::max(p.f[i] - a[i] * p.c[i], 0.0)));
    }
    CheckTrue(ia.status == ReducedQPStatus::Ok && ia.nactive == 3, "status ok, 3 active");
    Check(ev <= 1e-14, "v = min(f/a, c)", ev, 1e-14);
    Check(el <= 1e-14, "lambda = max(f - a c, 0)", el, 1e-14);
    // the TAO cross-check on the same case: close, not exact
    lt.assign(4, 0.0);
    PetscCall(Run(tao, p, &vt, &lt, &it));
    ev = 0;
    for (int i = 0; i < 4; ++i) ev = std::max(ev, std::abs(vt[i] - std::min(p.f[i] / a[i], p.c[i])));
    Check(ev <= 1e-6, "TAO: v close to min(f/a, c)", ev, 1e-6);
    // R = 0: the unconstrained solution
    Vecd          v0(4);
    ReducedQPInfo i0;
    PetscCall(as.Solve(4, 0, p.A.data(), p.f.data(), NULL, NULL, v0.data(), NULL, &i0));
    double e0 = 0;
    for (int i = 0; i < 4; ++i) e0 = std::max(e0, std::abs(v0[i] - p.f[i] / a[i]));
    Check(e0 <= 1e-15 && i0.status == ReducedQPStatus::Ok, "R = 0: v = A^{-1} f", e0, 1e-15);
  }

  std::printf("4. R > N, dependent active constraints (S singular on the active set), unique v\n");
  for (unsigned seed : {7u, 8u, 9u}) {
    std::mt19937                     gen(seed);
    std::normal_distribution<double> G(0, 1);
    Problem                          p = RandomProblem(6, 15, seed, false);
    // v* given; 10 > N constraints active at v* with positive multipliers (+ a duplicated active row)
    Vecd vs(6), ls(15, 0.0);
    for (auto &x : vs) x = G(gen);
    for (PetscInt j = 0; j < 6; ++j) p.D[14 + j * 15] = p.D[0 + j * 15]; // row 14 duplicates row 0
    for (PetscInt i = 0; i < 15; ++i) {
      double dv = 0;
      for (PetscInt j = 0; j < 6; ++j) dv += p.D[i + j * 15] * vs[j];
      const bool active = i < 10 || i == 14;
      p.c[i]            = active ? dv : dv + 0.5 + std::abs(G(gen));
      if (active) ls[i] = 0.5 + std::abs(G(gen));
    }
    for (PetscInt i = 0; i < 6; ++i) {
      double g = 0;
      for (PetscInt j = 0; j < 6; ++j) g += p.A[i + j * 6] * vs[j];
      for (PetscInt k = 0; k < 15; ++k) g += p.D[k + i * 15] * ls[k];
      p.f[i] = g;
    }
    for (int warm = 0; warm < 3; ++warm) {
      // cold; warm from the (dependent) generating multipliers; warm from all-positive multipliers
      if (warm == 0) la.assign(15, 0.0);
      else if (warm == 1) la = ls;
      else la.assign(15, 1.0);
      PetscCall(Run(as, p, &va, &la, &ia));
      double dv = 0;
      for (PetscInt i = 0; i < 6; ++i) dv = std::max(dv, std::abs(va[i] - vs[i]));
      std::printf(" seed %u, %s: status %s, %d its, %d active\n", seed, warm == 0 ? "cold" : warm == 1 ? "warm (generating lambda)" : "warm (all positive)", ReducedQPStatusName(ia.status), (int)ia.iterations, (int)ia.nactive);
      CheckTrue(ia.status == ReducedQPStatus::Ok, "solved (the free set is kept linearly independent)");
      CheckTrue(ia.nactive <= 6, "at most N positive multipliers (independent free set)");
      Check(dv <= 1e-10 * NormInf(vs), "v equals the unique v*", dv, 1e-10 * NormInf(vs));
      Check(WorstKKT(p, va, la) <= 1e-12, "scaled KKT residuals", WorstKKT(p, va, la), 1e-12);
      CheckTrue(AllFinite(va) && AllFinite(la), "no NaN/Inf");
    }
    lt.assign(15, 0.0);
    PetscCall(Run(tao, p, &vt, &lt, &it));
    double dv = 0;
    for (PetscInt i = 0; i < 6; ++i) dv = std::max(dv, std::abs(vt[i] - vs[i]));
    std::printf(" seed %u, TAO: status %s, %d its, |v - v*| = %.2e %s\n", seed, ReducedQPStatusName(it.status), (int)it.iterations, dv, it.message.c_str());
    CheckTrue(AllFinite(vt) && AllFinite(lt), "TAO: no NaN/Inf");
    CheckTrue(it.status != ReducedQPStatus::Ok || dv <= 1e-5 * NormInf(vs), "TAO: if ok, then v close to v*");
  }

  std::printf("4b. nearly parallel constraints (angle 1e-7: numerically dependent), the second one binding\n");
  {
    Problem p; // A = I, f = (10, 0): v1 <= 1 and v1 + 1e-7 v2 <= 1 - 1e-9 -> only the second active
    p.N = 2;
    p.R = 2;
    p.A = {1.0, 0.0, 0.0, 1.0};
    p.f = {10.0, 0.0};
    p.D = {1.0, 1.0, 0.0, 1e-7};
    p.c = {1.0, 1.0 - 1e-9};
    for (int warm = 0; warm < 2; ++warm) {
      la = warm ? Vecd{1.0, 0.0} : Vecd{0.0, 0.0};
      PetscCall(Run(as, p, &va, &la, &ia));
      // exact: lambda_2 = 9 (1 + 1e-9/9) / (1 + 1e-14), v = f - lambda_2 (1, 1e-7)
      const double l2 = (9.0 + 1e-9) / (1.0 + 1e-14), e = std::max(std::abs(la[0]), std::abs(la[1] - l2) / l2);
      std::printf(" %s: status %s, %d its, lambda = (%.3e, %.12g)\n", warm ? "warm from the first" : "cold", ReducedQPStatusName(ia.status), (int)ia.iterations, la[0], la[1]);
      CheckTrue(ia.status == ReducedQPStatus::Ok, "status ok");
      Check(e <= 1e-8, "lambda = (0, 9 + 1e-9) (relative)", e, 1e-8);
      Check(WorstKKT(p, va, la) <= 1e-12, "scaled KKT residuals", WorstKKT(p, va, la), 1e-12);
    }
  }

  std::printf("5. infeasible constraints\n");
  {
    Problem p; // v <= -1 and -v <= -1 (v >= 1)
    p.N = 1;
    p.R = 2;
    p.A = {2.0};
    p.f = {0.5};
    p.D = {1.0, -1.0};
    p.c = {-1.0, -1.0};
    for (int warm = 0; warm < 2; ++warm) {
      la.assign(2, warm ? 1.0 : 0.0);
      PetscCall(Run(as, p, &va, &la, &ia));
      std::printf(" 1D, %s: %s: %s\n", warm ? "warm" : "cold", ReducedQPStatusName(ia.status), ia.message.c_str());
      CheckTrue(ia.status == ReducedQPStatus::Infeasible, "status Infeasible");
      CheckTrue(ia.message.find("infeasible") != std::string::npos && ia.message.find("supremizers") != std::string::npos, "message says infeasible, with the supremizer hint");
      CheckTrue(AllFinite(va) && AllFinite(la), "v, lambda finite");
    }
    Problem z; // a zero constraint row with a negative bound: 0 <= -1
    z.N = 2;
    z.R = 2;
    z.A = {1.0, 0.0, 0.0, 1.0};
    z.f = {1.0, 1.0};
    z.D = {1.0, 0.0, 0.0, 0.0};
    z.c = {0.5, -1.0};
    la.assign(2, 0.0);
    PetscCall(Run(as, z, &va, &la, &ia));
    CheckTrue(ia.status == ReducedQPStatus::Infeasible && AllFinite(va) && AllFinite(la), "0 v <= -1: Infeasible, finite output");
    Problem q = RandomProblem(10, 8, 5, false); // random + a contradictory pair
    for (PetscInt j = 0; j < 10; ++j) q.D[7 + j * 8] = -q.D[6 + j * 8];
    q.c[6] = -1.0;
    q.c[7] = -1.0;
    la.assign(8, 0.0);
    PetscCall(Run(as, q, &va, &la, &ia));
    CheckTrue(ia.status == ReducedQPStatus::Infeasible && AllFinite(va) && AllFinite(la), "random N = 10 with d'v <= -1, -d'v <= -1: Infeasible, finite output");
    lt.assign(8, 0.0);
    PetscCall(Run(tao, q, &vt, &lt, &it));
    std::printf(" TAO on it: %s (%s)\n", ReducedQPStatusName(it.status), it.message.c_str());
    CheckTrue(AllFinite(vt) && AllFinite(lt), "TAO on an infeasible problem: finite output");
    CheckTrue(it.status != ReducedQPStatus::Ok || InfoWorst(it) > 1e-6, "TAO on an infeasible problem: not a clean Ok");
  }

  std::printf("6. A not SPD\n");
  {
    Problem p = RandomProblem(5, 3, 11, false);
    for (int kind = 0; kind < 2; ++kind) {
      Problem q = p;
      if (kind == 0) q.A[2 + 2 * 5] = -1.0; // indefinite
      else { // singular PSD: A = u u' + v v'
        for (PetscInt i = 0; i < 5; ++i)
          for (PetscInt j = 0; j < 5; ++j) q.A[i + j * 5] = (i + 1.0) * (j + 1.0) + 1.0;
      }
      for (auto *s : {&as, &tao}) {
        la.assign(3, 1.0);
        PetscCall(Run(*s, q, &va, &la, &ia));
        std::printf(" %s, %s: %s: %s\n", kind ? "singular" : "indefinite", s == &as ? "activeset" : "tao", ReducedQPStatusName(ia.status), ia.message.c_str());
        CheckTrue(ia.status == ReducedQPStatus::NotSPD && !ia.message.empty(), "status NotSPD with a message");
        CheckTrue(AllFinite(va) && AllFinite(la), "v, lambda finite");
      }
    }
    // and the next call with a good A works again
    la.assign(3, 0.0);
    PetscCall(Run(as, p, &va, &la, &ia));
    CheckTrue(ia.status == ReducedQPStatus::Ok, "a good A afterwards: ok");
  }

  std::printf("7. iteration limit, non-finite input, allocations\n");
  {
    PetscCall(PetscOptionsSetValue(NULL, "-u_qp_type", "tao"));
    PetscCall(PetscOptionsSetValue(NULL, "-u_qp_tao_max_it", "3"));
    ReducedQP     tao3;
    const Problem p3 = RandomProblem(20, 12, 31, false);
    PetscCall(tao3.SetFromOptions("u_"));
    lt.assign(p3.R, 0.0);
    PetscCall(Run(tao3, p3, &vt, &lt, &it));
    std::printf(" TAO, -u_qp_tao_max_it 3: %s, %d its: %s\n", ReducedQPStatusName(it.status), (int)it.iterations, it.message.c_str());
    CheckTrue(it.status == ReducedQPStatus::MaxIt && it.iterations == 3 && it.message.find("u_qp_tao_max_it") != std::string::npos, "TAO options prefix u_qp_: iteration limit 3 -> MaxIt with a hint");
    PetscCall(tao3.Reset());

    const Problem p = RandomProblem(30, 25, 21, false);
    ReducedQP     small;
    small.maxIt = 2;
    la.assign(p.R, 0.0);
    PetscCall(Run(small, p, &va, &la, &ia));
    CheckTrue(ia.status == ReducedQPStatus::MaxIt && ia.message.find("qp_max_it") != std::string::npos && AllFinite(va) && AllFinite(la), "max_it 2, cold: MaxIt with a hint, finite output");
    double lmin = 0;
    for (double x : la) lmin = std::min(lmin, x);
    CheckTrue(lmin >= 0, "MaxIt: lambda still >= 0");

    Problem bad = p;
    bad.c[3]    = NAN;
    la.assign(p.R, 0.0);
    va.assign(p.N, 0.0);
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    PetscErrorCode ierr = as.Solve(bad.N, bad.R, bad.A.data(), bad.f.data(), bad.D.data(), bad.c.data(), va.data(), la.data(), &ia);
    PetscCall(PetscPopErrorHandler());
    CheckTrue(ierr == PETSC_ERR_FP && AllFinite(va) && AllFinite(la), "NaN in c: PETSC_ERR_FP, finite output");

    const Problem p2 = RandomProblem(10, 8, 22, false);
    ReducedQP     qp;
    qp.Reserve(p.N, p.R);
    Vecd v(p.N), l(p.R, 0.0);
    Problem q = p;
    long    before = gAllocs;
    PetscCall(qp.Solve(p.N, p.R, p.A.data(), p.f.data(), p.D.data(), p.c.data(), v.data(), l.data(), &ia)); // cold
    PetscCall(qp.Solve(p.N, p.R, p.A.data(), p.f.data(), p.D.data(), p.c.data(), v.data(), l.data(), &ia)); // warm, cached
    q.A[0] *= 1 + 1e-12;
    PetscCall(qp.Solve(q.N, q.R, q.A.data(), q.f.data(), q.D.data(), q.c.data(), v.data(), l.data(), &ia)); // warm, new A
    PetscCall(qp.Solve(p2.N, p2.R, p2.A.data(), p2.f.data(), p2.D.data(), p2.c.data(), v.data(), l.data(), &ia)); // smaller sizes
    Check(gAllocs - before == 0, "heap allocations in 4 Solve calls after Reserve", (double)(gAllocs - before), 0);
  }

  std::printf("8. A factored once (FactorA, SolveFactored with D L^{-T} formed by the caller) against Solve\n");
  for (Size sz : {Size{8, 5, false}, Size{60, 12, false}, Size{40, 30, true}}) {
    const Problem p = RandomProblem(sz.N, sz.R, 700 + sz.N + sz.R, sz.bad);
    const PetscInt N = p.N, R = p.R;
    ReducedQP      fq, ft, ref;
    PetscCall(ft.SetFromOptions("t_")); // TAO through the factored path too
    ReducedQPInfo  fi;
    PetscCall(fq.FactorA(N, p.A.data(), &fi));
    CheckTrue(fi.status == ReducedQPStatus::Ok && fq.HasFactor(N) && !fq.HasFactor(N - 1), "FactorA: ok, HasFactor(N) only");
    // the factor against A (L L' = A), and GT = D L^{-T} by plain forward substitution in the test
    const PetscReal *L = fq.FactorL();
    double           dA = 0;
    for (PetscInt i = 0; i < N; ++i)
      for (PetscInt j = 0; j <= i; ++j) {
        double a = 0;
        for (PetscInt k = 0; k <= j; ++k) a += L[i + k * N] * L[j + k * N];
        dA = std::max(dA, std::abs(a - p.A[i + j * N]));
      }
    Vecd GT(R * N);
    for (PetscInt k = 0; k < N; ++k)
      for (PetscInt i = 0; i < R; ++i) {
        double x = p.D[i + k * R];
        for (PetscInt m = 0; m < k; ++m) x -= L[k + m * N] * GT[i + m * R];
        GT[i + k * R] = x / L[k + k * N];
      }
    Vecd vf(N), lf(R, 0.0), vr, lr(R, 0.0);
    PetscCall(fq.SolveFactored(N, R, p.f.data(), GT.data(), p.c.data(), vf.data(), lf.data(), &fi));
    PetscCall(Run(ref, p, &vr, &lr, &ia));
    const double dv = RelDiff(vf, vr), dl = RelDiff(lf, lr);
    std::printf(" N = %d R = %d%s: ||L L' - A|| %.1e, factored %d its, %d active; v rel diff %.1e, lambda %.1e\n", (int)N, (int)R, sz.bad ? " (rows scaled)" : "", dA, (int)fi.iterations, (int)fi.nactive, dv, dl);
    Check(dA <= 1e-13 * NormInf(p.A), "FactorL(): L L' = A", dA, 1e-13 * NormInf(p.A));
    CheckTrue(fi.status == ReducedQPStatus::Ok && fi.nactive == ia.nactive, "SolveFactored: ok, the same active count as Solve");
    Check(dv <= 1e-10, "v: SolveFactored vs Solve (relative, inf norm)", dv, 1e-10);
    Check(dl <= 1e-9, "lambda: SolveFactored vs Solve (relative, inf norm)", dl, 1e-9);
    Check(WorstKKT(p, vf, lf) <= 1e-12, "SolveFactored: independently computed scaled KKT residuals (A, D)", WorstKKT(p, vf, lf), 1e-12);
    Check(std::abs(WorstKKT(p, vf, lf) - InfoWorst(fi)) <= 1e-3 * WorstKKT(p, vf, lf) + 1e-15, "SolveFactored: reported KKT (D = GT L') equals the independent one", std::abs(WorstKKT(p, vf, lf) - InfoWorst(fi)), 1e-3 * WorstKKT(p, vf, lf) + 1e-15);
    // TAO on the factored set-up
    PetscCall(ft.FactorA(N, p.A.data(), &fi));
    Vecd vt2(N), lt2(R, 0.0);
    PetscCall(ft.SolveFactored(N, R, p.f.data(), GT.data(), p.c.data(), vt2.data(), lt2.data(), &fi));
    double dvt = 0;
    for (PetscInt i = 0; i < N; ++i) dvt = std::max(dvt, std::abs(vt2[i] - vr[i]));
    Check(fi.status == ReducedQPStatus::Ok && dvt <= 1e-6 * NormInf(vr), "TAO through SolveFactored: ok, v vs the active set (relative)", dvt / NormInf(vr), 1e-6);
    PetscCall(ft.Reset());
    // warm start from the multipliers: one iteration, no allocation
    fq.Reserve(N, R);
    long before = gAllocs;
    PetscCall(fq.SolveFactored(N, R, p.f.data(), GT.data(), p.c.data(), vf.data(), lf.data(), &fi));
    PetscCall(fq.SolveFactored(N, R, p.f.data(), GT.data(), p.c.data(), vf.data(), lf.data(), &fi));
    Check(fi.iterations == 1, "SolveFactored, warm start: iterations", (double)fi.iterations, 1);
    Check(gAllocs - before == 0, "heap allocations in 2 SolveFactored calls after Reserve", (double)(gAllocs - before), 0);
    // a Solve with another A replaces the factor: SolveFactored refuses
    Problem q = p;
    q.A[0] *= 1 + 1e-12;
    PetscCall(fq.Solve(N, R, q.A.data(), q.f.data(), q.D.data(), q.c.data(), vf.data(), lf.data(), &fi));
    CheckTrue(!fq.HasFactor(N), "Solve with another A: HasFactor false");
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    PetscErrorCode ierr = fq.SolveFactored(N, R, p.f.data(), GT.data(), p.c.data(), vf.data(), lf.data(), &fi);
    PetscCall(PetscPopErrorHandler());
    CheckTrue(ierr == PETSC_ERR_ORDER, "SolveFactored without a factor: PETSC_ERR_ORDER");
    // a non-SPD A: FactorA reports it, no factor
    Problem ns = p;
    ns.A[0] = -1;
    PetscCall(fq.FactorA(N, ns.A.data(), &fi));
    CheckTrue(fi.status == ReducedQPStatus::NotSPD && !fq.HasFactor(N) && !fi.message.empty(), "FactorA on a non-SPD A: NotSPD with a message, no factor");
    // a NaN in GT: PETSC_ERR_FP, finite output
    PetscCall(fq.FactorA(N, p.A.data(), &fi));
    Vecd GTn = GT;
    GTn[1]   = NAN;
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    ierr = fq.SolveFactored(N, R, p.f.data(), GTn.data(), p.c.data(), vf.data(), lf.data(), &fi);
    PetscCall(PetscPopErrorHandler());
    CheckTrue(ierr == PETSC_ERR_FP && AllFinite(vf) && AllFinite(lf), "NaN in D L^{-T}: PETSC_ERR_FP, finite output");
  }

  std::printf("9. A with two affine terms diagonalized once (AffineDiagonalization; SetIdentityA, SolveFactored in z) against Solve\n");
  for (Size sz : {Size{8, 5, false}, Size{44, 30, false}, Size{40, 30, true}}) {
    // A(theta) = theta_0 A_0 + theta_1 A_1: A_0 the random SPD matrix, A_1 = M'M/N (positive semidefinite, rank N/2)
    const Problem  p = RandomProblem(sz.N, sz.R, 900 + sz.N + sz.R, sz.bad);
    const PetscInt N = p.N, R = p.R;
    std::mt19937   gen(17 + N);
    std::normal_distribution<double> G(0, 1);
    Vecd Aq(2 * N * N, 0.0), M((N / 2) * N);
    for (auto &x : M) x = G(gen);
    for (PetscInt i = 0; i < N * N; ++i) Aq[i] = p.A[i];
    for (PetscInt i = 0; i < N; ++i)
      for (PetscInt j = 0; j < N; ++j)
        for (PetscInt k = 0; k < N / 2; ++k) Aq[N * N + i + j * N] += M[k + i * (N / 2)] * M[k + j * (N / 2)] / N;
    auto AofTheta = [&](const Vecd &th) {
      Vecd A(N * N);
      for (PetscInt e = 0; e < N * N; ++e) A[e] = th[0] * Aq[e] + th[1] * Aq[N * N + e];
      return A;
    };
    const Vecd            th0 = {1.0, 0.7};
    AffineDiagonalization ad;
    bool                  ok = false;
    PetscCall(ad.Set(N, th0, Aq.data(), &ok));
    CheckTrue(ok && ad.N() == N, "AffineDiagonalization::Set: ok");
    // V' A(theta) V = diag(d(theta)) at theta0 and at other coefficients (plain triple loops)
    double dd = 0;
    for (const Vecd &th : {th0, Vecd{2.5, 0.1}, Vecd{0.3, 3.0}, Vecd{1.0, 0.0}}) {
      const Vecd A = AofTheta(th), &V = ad.V();
      Vecd       d(N), AV(N * N, 0.0);
      ad.Diagonal(th, d.data());
      for (PetscInt i = 0; i < N; ++i)
        for (PetscInt j = 0; j < N; ++j)
          for (PetscInt k = 0; k < N; ++k) AV[i + j * N] += A[i + k * N] * V[k + j * N];
      double dmax = NormInf(d);
      for (PetscInt i = 0; i < N; ++i)
        for (PetscInt j = 0; j < N; ++j) {
          double x = 0;
          for (PetscInt k = 0; k < N; ++k) x += V[k + i * N] * AV[k + j * N];
          dd = std::max(dd, std::abs(x - (i == j ? d[i] : 0.0)) / dmax);
        }
    }
    Check(dd <= 1e-11, "V' A(theta) V = diag(d(theta)) at 4 coefficient pairs (relative to max d)", dd, 1e-11);
    // the QP in z = diag(d)^{1/2} V^{-1} v (A = I): GT = D V diag(d)^{-1/2}, f_z = diag(d)^{-1/2} V' f, v = V diag(d)^{-1/2} z
    ReducedQP fq, ref;
    for (const Vecd &th : {Vecd{2.5, 0.1}, Vecd{0.3, 3.0}}) {
      Problem q = p;
      q.A       = AofTheta(th);
      const Vecd &V = ad.V();
      Vecd        d(N), sd(N), GT(R * N, 0.0), fz(N, 0.0), z(N), vz(N, 0.0), lz(R, 0.0), vr, lr(R, 0.0);
      ad.Diagonal(th, d.data());
      for (PetscInt i = 0; i < N; ++i) sd[i] = 1 / std::sqrt(d[i]);
      for (PetscInt c = 0; c < N; ++c) {
        for (PetscInt k = 0; k < N; ++k) {
          fz[c] += V[k + c * N] * q.f[k];
          for (PetscInt i = 0; i < R; ++i) GT[i + c * R] += q.D[i + k * R] * V[k + c * N];
        }
        fz[c] *= sd[c];
        for (PetscInt i = 0; i < R; ++i) GT[i + c * R] *= sd[c];
      }
      fq.SetIdentityA(N);
      CheckTrue(fq.HasIdentity(N) && fq.HasFactor(N), "SetIdentityA: HasIdentity(N), HasFactor(N)");
      ReducedQPInfo zi;
      PetscCall(fq.SolveFactored(N, R, fz.data(), GT.data(), q.c.data(), z.data(), lz.data(), &zi));
      for (PetscInt i = 0; i < N; ++i)
        for (PetscInt k = 0; k < N; ++k) vz[i] += V[i + k * N] * sd[k] * z[k];
      PetscCall(Run(ref, q, &vr, &lr, &ia));
      const double dv = RelDiff(vz, vr), dl = RelDiff(lz, lr);
      std::printf(" N = %d R = %d%s, theta (%.1f, %.1f): %d active; v rel diff %.1e, lambda %.1e\n", (int)N, (int)R, sz.bad ? " (rows scaled)" : "", th[0], th[1], (int)zi.nactive, dv, dl);
      CheckTrue(zi.status == ReducedQPStatus::Ok && zi.nactive == ia.nactive, "SolveFactored in z: ok, the same active count as Solve");
      Check(dv <= 1e-10, "v = V diag(d)^{-1/2} z vs Solve with A(theta) (relative, inf norm)", dv, 1e-10);
      Check(dl <= 1e-9, "lambda: in z vs Solve (relative, inf norm)", dl, 1e-9);
      Check(WorstKKT(q, vz, lz) <= 1e-12, "in z: independently computed scaled KKT residuals of (v, lambda) with A(theta), D", WorstKKT(q, vz, lz), 1e-12);
      fq.ResidualsFactored(N, R, nullptr, fz.data(), GT.data(), q.c.data(), z.data(), lz.data(), &zi);
      Problem qz = q; // the same problem in z: A = I, f_z, D_z = GT
      qz.A.assign(N * N, 0.0);
      for (PetscInt i = 0; i < N; ++i) qz.A[i + i * N] = 1;
      qz.f = fz;
      qz.D = GT;
      Check(std::abs(WorstKKT(qz, z, lz) - InfoWorst(zi)) <= 1e-3 * WorstKKT(qz, z, lz) + 1e-15, "ResidualsFactored(nullptr): the KKT residuals of the problem in z", std::abs(WorstKKT(qz, z, lz) - InfoWorst(zi)), 1e-3 * WorstKKT(qz, z, lz) + 1e-15);
    }
    // FactorA after SetIdentityA: the factor is A's again (no identity left behind), and SolveFactored agrees with Solve
    ReducedQPInfo fi;
    PetscCall(fq.FactorA(N, p.A.data(), &fi));
    CheckTrue(fi.status == ReducedQPStatus::Ok && fq.HasFactor(N) && !fq.HasIdentity(N), "FactorA after SetIdentityA: HasFactor, not HasIdentity");
    Vecd GT(R * N), vf(N), lf(R, 0.0), vr, lr(R, 0.0);
    const PetscReal *L = fq.FactorL();
    for (PetscInt k = 0; k < N; ++k)
      for (PetscInt i = 0; i < R; ++i) {
        double x = p.D[i + k * R];
        for (PetscInt m = 0; m < k; ++m) x -= L[k + m * N] * GT[i + m * R];
        GT[i + k * R] = x / L[k + k * N];
      }
    PetscCall(fq.SolveFactored(N, R, p.f.data(), GT.data(), p.c.data(), vf.data(), lf.data(), &fi));
    PetscCall(Run(ref, p, &vr, &lr, &ia));
    double dv = 0;
    for (PetscInt i = 0; i < N; ++i) dv = std::max(dv, std::abs(vf[i] - vr[i]));
    Check(dv <= 1e-10 * NormInf(vr), "... SolveFactored vs Solve (relative)", dv / NormInf(vr), 1e-10);
    fq.SetIdentityA(N);
    Problem q2 = p;
    PetscCall(fq.Solve(N, R, q2.A.data(), q2.f.data(), q2.D.data(), q2.c.data(), vf.data(), lf.data(), &fi));
    dv = 0;
    for (PetscInt i = 0; i < N; ++i) dv = std::max(dv, std::abs(vf[i] - vr[i]));
    CheckTrue(!fq.HasIdentity(N) && dv <= 1e-10 * NormInf(vr), "Solve with another A after SetIdentityA: not HasIdentity, the Solve answer");
    // one term (theta_1 absent): lambda = 0, V' A_0 V = I; B not positive definite, three terms: not ok
    PetscCall(ad.Set(N, {2.0}, Aq.data(), &ok));
    double l1 = ok ? NormInf(ad.Lambda()) : 1;
    Vecd   d1(N);
    if (ok) ad.Diagonal({3.0}, d1.data());
    CheckTrue(ok && l1 == 0 && std::abs(d1[0] - 1.5) <= 1e-15 && std::abs(d1[N - 1] - 1.5) <= 1e-15, "one term: ok, lambda = 0, d(theta) = theta / theta0");
    Vecd Ab = Aq;
    Ab[0]   = -10 * NormInf(p.A);
    PetscCall(ad.Set(N, th0, Ab.data(), &ok));
    CheckTrue(!ok && ad.Empty(), "A(theta0) not positive definite: not ok, empty");
    PetscCall(ad.Set(N, {1.0, 0.5, 0.2}, Aq.data(), &ok));
    CheckTrue(!ok && ad.Empty(), "three terms: not ok, empty");
  }

  PetscCall(as.Reset());
  PetscCall(tao.Reset());
  std::printf("%s: %d failure(s)\n", failures ? "FAILED" : "PASSED", failures);
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
