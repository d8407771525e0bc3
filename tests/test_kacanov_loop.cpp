// tests/test_kacanov_loop.cpp: KacanovLoop (src/contact/kacanov_loop.cpp), the loop shared by the FOM and
// the ROM, on a linear contraction x = M x + b (n = 12, spectral radius 0.8) driven exactly as the backends
// drive it (Begin, Relax, Record, Next), serial:
//   1. the fixed point against an independent LAPACK solve of (I - M) x = b, with Anderson depth 0 and 3
//      (fewer iterations with mixing), and with relaxation 0.5;
//   2. the primal change Relax returns = |g - x| / |x| computed here; the history holds every iterate;
//   3. max_it 1 is the linearized model (converged after one iterate); a loop that runs out of iterations
//      reports it with the option names and the history;
//   4. the options: -t_kacanov_max_it, _anderson, _relaxation read with the prefix; out-of-range values refused;
//   5. Cycle: the period and start of a cycle the history ends in, and the message naming it; a stall named too.
#include "rbcontact/kacanov_loop.hpp"
#include <petscblaslapack.h>
#include <cmath>
#include <random>

using namespace rbc;

static int failures = 0;
static void Check(bool ok, const char *what, double v, double bound)
{
  PetscCallVoid(PetscPrintf(PETSC_COMM_WORLD, "  %-6s %-78s %.3e (bound %.1e)\n", ok ? "ok" : "FAIL", what, v, bound));
  if (!ok) ++failures;
}

struct Problem {
  PetscInt            n = 12;
  std::vector<double> M, b, xstar;
};

static Problem MakeProblem()
{
  Problem      p;
  const int    n = (int)p.n;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  p.M.assign(n * n, 0.0);
  p.b.resize(n);
  for (auto &v : p.M) v = u(rng);
  double rowmax = 0;
  for (int i = 0; i < n; ++i) {
    double s = 0;
    for (int j = 0; j < n; ++j) s += std::abs(p.M[i + j * n]);
    rowmax = std::max(rowmax, s);
  }
  for (auto &v : p.M) v *= 0.8 / rowmax; // ||M||_inf = 0.8: a contraction
  for (auto &v : p.b) v = u(rng);
  // (I - M) x = b by LAPACK
  std::vector<double> A(n * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) A[i + j * n] = (i == j) - p.M[i + j * n];
  p.xstar = p.b;
  std::vector<PetscBLASInt> piv(n);
  PetscBLASInt              nn = n, one = 1, info = 0;
  LAPACKgesv_(&nn, &one, A.data(), &nn, piv.data(), p.xstar.data(), &nn, &info);
  return p;
}

// drives the loop like the backends; returns the iterations, x the last (relaxed) image
static PetscErrorCode Drive(KacanovLoop &loop, const Problem &p, std::vector<double> *x, PetscInt *its, bool *conv, double *relaxErr)
{
  const PetscInt      n = p.n;
  std::vector<double> in(n, 0.0), g(n), next(n);
  PetscFunctionBeginUser;
  *conv     = false;
  *relaxErr = 0;
  loop.Begin(n);
  for (PetscInt k = 1; k <= loop.maxIt; ++k) {
    for (PetscInt i = 0; i < n; ++i) {
      g[i] = p.b[i];
      for (PetscInt j = 0; j < n; ++j) g[i] += p.M[i + j * n] * in[j];
    }
    // the change by hand: the image (before the relaxation) minus the input, relative to the input
    double nd = 0, nx = 0;
    for (PetscInt i = 0; i < n; ++i) {
      nd += (g[i] - in[i]) * (g[i] - in[i]);
      nx += in[i] * in[i];
    }
    const double expect = nx > 0 ? std::sqrt(nd / nx) : std::numeric_limits<double>::infinity();
    const double du     = loop.Relax(in.data(), g.data());
    if (std::isfinite(expect)) *relaxErr = std::max(*relaxErr, std::abs(du - expect) / expect);
    else if (std::isfinite(du)) *relaxErr = 1;
    bool done = false;
    PetscCall(loop.Record(PETSC_COMM_SELF, k, du, du, 0, 0, nullptr, &done)); // dl: the same change (a stand-in)
    *its = k;
    if (done) {
      *conv = true;
      *x    = g;
      break;
    }
    loop.Next(in.data(), g.data(), next.data());
    in = next;
    *x = g;
  }
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  const Problem p = MakeProblem();
  double        xs = 0;
  for (double v : p.xstar) xs = std::max(xs, std::abs(v));
  PetscInt its[2] = {0, 0};
  for (PetscInt depth : {0, 3}) {
    KacanovLoop loop(1e-12, 1e-12, "test");
    loop.anderson = depth;
    loop.maxIt    = 500;
    std::vector<double> x;
    PetscInt            it = 0;
    bool                conv = false;
    double              rerr = 0;
    PetscCall(Drive(loop, p, &x, &it, &conv, &rerr));
    double e = 0;
    for (PetscInt i = 0; i < p.n; ++i) e = std::max(e, std::abs(x[i] - p.xstar[i]));
    char what[160];
    std::snprintf(what, sizeof what, "Anderson depth %d: converged in %d iterations, fixed point = LAPACK solve (rel)", (int)depth, (int)it);
    Check(conv && e <= 1e-10 * xs, what, e / xs, 1e-10);
    Check(rerr <= 1e-12, "Relax: |g - x| / |x| as computed by hand (rel)", rerr, 1e-12);
    Check((PetscInt)loop.history.du.size() == it && (PetscInt)loop.history.nactive.size() == it, "history: one entry per iterate", (double)loop.history.du.size(), (double)it);
    its[depth ? 1 : 0] = it;
  }
  Check(its[1] < its[0], "Anderson mixing (depth 3) needs fewer iterations than the plain loop", (double)its[1], (double)its[0]);
  {
    KacanovLoop loop(1e-12, 1e-12, "test");
    loop.anderson   = 0;
    loop.relaxation = 0.5;
    loop.maxIt      = 1000;
    std::vector<double> x;
    PetscInt            it = 0;
    bool                conv = false;
    double              rerr = 0, e = 0;
    PetscCall(Drive(loop, p, &x, &it, &conv, &rerr));
    for (PetscInt i = 0; i < p.n; ++i) e = std::max(e, std::abs(x[i] - p.xstar[i]));
    Check(conv && e <= 1e-10 * xs && rerr <= 1e-12, "relaxation 0.5: same fixed point, change of the image before the relaxation", e / xs, 1e-10);
  }
  {
    KacanovLoop loop(1e-12, 1e-12, "test");
    loop.maxIt = 1;
    std::vector<double> x;
    PetscInt            it = 0;
    bool                conv = false;
    double              rerr = 0;
    PetscCall(Drive(loop, p, &x, &it, &conv, &rerr));
    Check(conv && it == 1, "max_it 1: the linearized model, converged after one iterate", (double)it, 1);
    loop.maxIt = 3;
    PetscCall(Drive(loop, p, &x, &it, &conv, &rerr));
    const std::string msg = loop.NotConverged(true);
    Check(!conv && it == 3 && msg.find("did not converge in 3") != std::string::npos && msg.find("-kacanov_max_it") != std::string::npos && msg.find("it 3: du") != std::string::npos,
          "max_it 3, tolerance 1e-12: not converged, message names the option and the history", (double)it, 3);
  }
  {
    // a tiny relaxation from a start 1e-3 off the fixed point: the residual, not the relaxed step, is tested (the
    // relaxed step, 1e-4 x 1e-3, met 1e-5 at the first iterate: the warm start returned as converged until 2026-12-01)
    KacanovLoop loop(1e-5, 1e-5, "test");
    loop.anderson   = 0;
    loop.relaxation = 1e-4;
    loop.maxIt      = 5;
    loop.Begin(p.n);
    std::vector<double> in(p.xstar), g(p.n);
    for (auto &v : in) v *= 1 + 1e-3;
    bool conv = false;
    for (PetscInt k = 1; k <= loop.maxIt && !conv; ++k) {
      for (PetscInt i = 0; i < p.n; ++i) {
        g[i] = p.b[i];
        for (PetscInt j = 0; j < p.n; ++j) g[i] += p.M[i + j * p.n] * in[j];
      }
      const double du = loop.Relax(in.data(), g.data());
      PetscCall(loop.Record(PETSC_COMM_SELF, k, du, du, 0, 0, nullptr, &conv));
      in = g;
    }
    Check(!conv && loop.history.du[0] > 1e-4, "relaxation 1e-4, start 1e-3 off: the residual measured (not the relaxed step), not converged in 5", loop.history.du[0], 1e-4);
  }
  {
    // Cycle: a history that ends in a cycle (the reduced model of a 2 x 5 half_disks grid at one test parameter,
    // docs/greedy_training.md: period 3 after a transient) is named with its period and start; a converging one, a
    // period broken by a change of 1e-3 or by another active count, and fewer than three periods are not
    auto record = [](KacanovLoop &l, const std::vector<double> &du, const std::vector<double> &dl, const std::vector<PetscInt> &na) -> PetscErrorCode {
      bool c;
      PetscFunctionBeginUser;
      l.Begin(1);
      for (size_t i = 0; i < du.size(); ++i) PetscCall(l.Record(PETSC_COMM_SELF, (PetscInt)i + 1, du[i], dl[i], na[i], 13, nullptr, &c));
      PetscFunctionReturn(0);
    };
    KacanovLoop              loop(1e-5, 1e-4, "test");
    std::vector<double>      du{2.5e-3, 9.8e-4, 5.9e-4, 5.1e-4}, dl{1e-1, 6.3e-2, 1.6e-2, 3.4e-2};
    std::vector<PetscInt>    na{7, 7, 7, 8};
    const double             cu[3] = {4.386e-4, 4.825e-4, 2.752e-4}, cl[3] = {2.534e-2, 2.510e-2, 2.113e-2};
    for (int k = 0; k < 12; ++k) {
      du.push_back(cu[k % 3] * (1 + 1e-9 * (k % 2))); // equal to rounding
      dl.push_back(cl[k % 3]);
      na.push_back(7);
    }
    PetscCall(record(loop, du, dl, na));
    PetscInt from = 0;
    const PetscInt per = loop.Cycle(&from);
    const std::string msg = loop.NotConverged(false);
    Check(per == 3 && from == 5 && msg.find("repeat with period 3 from iterate 5") != std::string::npos, "a history ending in a period-3 cycle after 4 transient iterates: period 3 from iterate 5, in the message", (double)per, 3);
    std::vector<double> dc(16), lc(16);
    for (int k = 0; k < 16; ++k) {
      dc[k] = 1e-2 * std::pow(0.5, k);
      lc[k] = 1e-1 * std::pow(0.5, k);
    }
    PetscCall(record(loop, dc, lc, std::vector<PetscInt>(16, 7)));
    Check(loop.Cycle() == 0 && loop.NotConverged(false).find("repeat") == std::string::npos, "a converging history: no cycle, none in the message", (double)loop.Cycle(), 0);
    std::vector<double> db = du;
    db[du.size() - 2] *= 1 + 1e-3;
    PetscCall(record(loop, db, dl, na));
    Check(loop.Cycle() == 0, "the same history with one change off by 1e-3 among the last 6: no cycle", (double)loop.Cycle(), 0);
    std::vector<PetscInt> nb = na;
    nb.back() = 8;
    PetscCall(record(loop, du, dl, nb));
    Check(loop.Cycle() == 0, "the same history with another active count at the last iterate: no cycle", (double)loop.Cycle(), 0);
    PetscCall(record(loop, std::vector<double>(du.end() - 8, du.end()), std::vector<double>(dl.end() - 8, dl.end()), std::vector<PetscInt>(8, 7)));
    Check(loop.Cycle() == 0, "8 iterates of a period-3 cycle (fewer than three periods): not called one", (double)loop.Cycle(), 0);
    // a stall that is not periodic to 1e-6 (half_disks's ROM of 6 training points at one parameter: du 5.7e-5 for 20
    // iterates, broken once; no word before 2026-12-02), named; a linear approach at rate 0.8 is not
    std::vector<double> ds, ls;
    for (int k = 0; k < 30; ++k) {
      ds.push_back(k == 24 || k == 25 ? 2.772e-5 : 5.675e-5 * (1 + 1e-4 * (k % 2)));
      ls.push_back(4.94e-4);
    }
    PetscCall(record(loop, ds, ls, std::vector<PetscInt>(30, 3)));
    Check(loop.Cycle() == 0 && loop.NotConverged(false).find("the primal change stalls between") != std::string::npos, "a stall without a period: named as a stall", 0, 0);
    std::vector<double> dr(30);
    for (int k = 0; k < 30; ++k) dr[k] = 1e-2 * std::pow(0.8, k);
    PetscCall(record(loop, dr, std::vector<double>(30, 1e-3), std::vector<PetscInt>(30, 3)));
    Check(loop.NotConverged(false).find("stalls") == std::string::npos, "a linear approach at rate 0.8: not called a stall", 0, 0);
  }
  {
    // the dual change against multipliers the loop did not compute (a warm start's): recorded, not tested
    KacanovLoop loop(1e-5, 1e-4, "test");
    bool        tested = true, untested = false, primalMissed = true;
    loop.Begin(1);
    PetscCall(loop.Record(PETSC_COMM_SELF, 1, 1e-6, 0.5, 0, 0, nullptr, &tested));
    PetscCall(loop.Record(PETSC_COMM_SELF, 1, 1e-6, 0.5, 0, 0, nullptr, &untested, false));
    PetscCall(loop.Record(PETSC_COMM_SELF, 1, 2e-5, 0.0, 0, 0, nullptr, &primalMissed, false));
    Check(!tested && untested && !primalMissed && loop.history.dl.size() == 3 && loop.history.dl[1] == 0.5,
          "Record: dl 0.5 > rtol_dual stops the loop only when it is a change of the iteration; du > rtol_primal never; dl recorded", (double)untested, 1);
  }
  {
    KacanovLoop loop;
    PetscCall(PetscOptionsSetValue(NULL, "-t_kacanov_max_it", "7"));
    PetscCall(PetscOptionsSetValue(NULL, "-t_kacanov_anderson", "5"));
    PetscCall(PetscOptionsSetValue(NULL, "-t_kacanov_relaxation", "0.25"));
    PetscCall(loop.SetFromOptions(PETSC_COMM_SELF, "t_"));
    Check(loop.maxIt == 7 && loop.anderson == 5 && loop.relaxation == 0.25, "-t_kacanov_max_it 7, _anderson 5, _relaxation 0.25 read with the prefix", (double)loop.maxIt, 7);
    PetscCall(PetscOptionsSetValue(NULL, "-t_kacanov_relaxation", "1.5"));
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    PetscErrorCode ierr = loop.SetFromOptions(PETSC_COMM_SELF, "t_");
    PetscCall(PetscPopErrorHandler());
    Check(ierr == PETSC_ERR_ARG_OUTOFRANGE, "-t_kacanov_relaxation 1.5 refused (PETSC_ERR_ARG_OUTOFRANGE)", (double)ierr, PETSC_ERR_ARG_OUTOFRANGE);
    PetscCall(PetscOptionsClearValue(NULL, "-t_kacanov_relaxation"));
    PetscCall(PetscOptionsSetValue(NULL, "-t_kacanov_anderson", "11"));
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    ierr = loop.SetFromOptions(PETSC_COMM_SELF, "t_");
    PetscCall(PetscPopErrorHandler());
    Check(ierr == PETSC_ERR_ARG_OUTOFRANGE, "-t_kacanov_anderson 11 refused", (double)ierr, PETSC_ERR_ARG_OUTOFRANGE);
    PetscCall(PetscOptionsClearValue(NULL, "-t_kacanov_anderson"));
    PetscCall(PetscOptionsClearValue(NULL, "-t_kacanov_max_it"));
  }
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_kacanov_loop: %d failure(s)\n", failures));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
