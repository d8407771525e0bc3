// tests/test_bound_qp.cpp: the dense bound-constrained QP solvers against each other and against the
// KKT conditions: BoundQPActiveSet (exact active set) vs DualQPSolver (TAO BQPIP + polish) vs TAO
// BQPIP alone, on well-conditioned, ill-conditioned (nearly collinear) and trivial problems.
#include "rbcontact/bound_qp.hpp"
#include <petscblaslapack.h>
#include <cmath>
#include <random>

using namespace rbc;

static int failures = 0;
static void Check(bool ok, const char *what, double v, double bound)
{
  std::printf("  %-6s %-60s %.3e (bound %.1e)\n", ok ? "ok" : "FAIL", what, v, bound);
  if (!ok) ++failures;
}

// H = Q'Q + shift I with Q (m x n) random; collinear: columns of Q nearly parallel.
static void MakeProblem(int n, bool collinear, unsigned seed, std::vector<PetscReal> *H, std::vector<PetscReal> *c)
{
  std::mt19937                     gen(seed);
  std::normal_distribution<double> N(0, 1);
  const int                        m = 3 * n;
  std::vector<double>              Q(m * n), base(m);
  for (auto &b : base) b = N(gen);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < m; ++i) Q[i + j * m] = collinear ? base[i] + 1e-4 * N(gen) : N(gen);
  H->assign(n * n, 0.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < m; ++k) (*H)[i + j * n] += Q[k + i * m] * Q[k + j * m];
  c->resize(n);
  for (auto &x : *c) x = N(gen);
}

static double Objective(int n, const std::vector<PetscReal> &H, const std::vector<PetscReal> &c, const std::vector<PetscReal> &x)
{
  double f = 0;
  for (int i = 0; i < n; ++i) {
    f -= c[i] * x[i];
    for (int j = 0; j < n; ++j) f += 0.5 * x[i] * H[i + j * n] * x[j];
  }
  return f;
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  for (int collinear = 0; collinear < 2; ++collinear)
    for (int n : {5, 20, 60}) {
      std::vector<PetscReal> H, c;
      MakeProblem(n, collinear, 17 + n, &H, &c);
      std::printf("n = %d, %s\n", n, collinear ? "nearly collinear columns" : "random columns");
      // 1. active set
      std::vector<PetscReal> xa(n, 0.0);
      BoundQPInfo            bi;
      PetscCall(BoundQPActiveSet(n, H.data(), c.data(), xa.data(), 1e-14, 10 * n + 100, &bi));
      Check(bi.converged, "active set converged", bi.iterations, 10 * n + 100);
      double xmin = 0;
      for (double v : xa) xmin = std::min(xmin, v);
      Check(xmin >= 0, "active set: x >= 0", -xmin, 0);
      Check(bi.kkt <= 1e-9, "active set: scaled KKT residual", bi.kkt, 1e-9);
      // 2. TAO BQPIP + polish, and TAO alone
      DualQPSolver qp, qpTao;
      PetscCall(PetscOptionsSetValue(NULL, "-t1_qp_polish", "1"));
      PetscCall(PetscOptionsSetValue(NULL, "-t2_qp_polish", "0"));
      PetscCall(qp.Setup("t1_"));
      PetscCall(qpTao.Setup("t2_"));
      std::vector<PetscReal> xt, xo;
      DualQPInfo             ti, oi;
      PetscCall(qp.Solve(n, H, c, &xt, &ti));
      PetscCall(qpTao.Solve(n, H, c, &xo, &oi));
      double dx = 0, xn = 0;
      for (int i = 0; i < n; ++i) { dx = std::max(dx, std::abs(xt[i] - xa[i])); xn = std::max(xn, std::abs(xa[i])); }
      const double fa = Objective(n, H, c, xa), ft = Objective(n, H, c, xt), fo = Objective(n, H, c, xo);
      Check(std::abs(ft - fa) <= 1e-12 * (1 + std::abs(fa)), "BQPIP+polish objective equals active set", std::abs(ft - fa), 1e-12 * (1 + std::abs(fa)));
      if (!collinear) Check(dx <= 1e-8 * (1 + xn), "BQPIP+polish solution equals active set", dx, 1e-8 * (1 + xn));
      Check(fo - fa >= -1e-12 * (1 + std::abs(fa)), "TAO alone never beats the exact optimum", fa - fo, 1e-12 * (1 + std::abs(fa)));
      Check(std::abs(fo - fa) <= 1e-6 * (1 + std::abs(fa)), "TAO BQPIP alone: objective close to the optimum", std::abs(fo - fa), 1e-6 * (1 + std::abs(fa)));
    }
  {
    // c <= 0: x = 0 exactly
    std::vector<PetscReal> H, c;
    MakeProblem(10, false, 3, &H, &c);
    for (auto &v : c) v = -std::abs(v);
    DualQPSolver qp;
    PetscCall(qp.Setup("t1_"));
    std::vector<PetscReal> x;
    DualQPInfo             info;
    PetscCall(qp.Solve(10, H, c, &x, &info));
    double xm = 0;
    for (double v : x) xm = std::max(xm, std::abs(v));
    Check(xm == 0.0, "c <= 0 gives exactly x = 0", xm, 0);
  }
  std::printf("%s (%d failure(s))\n", failures ? "bound_qp test FAILED" : "bound_qp test passed", failures);
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
