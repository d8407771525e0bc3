// tests/test_eim.cpp: the Empirical Interpolation Method (src/reduction/eim.cpp, docs/eim.md), serial.
//   1. the classical example f(x; mu) = 1/sqrt((x - mu)^2 + 0.01), 200 x in [0,1], 60 mu in [-1,-0.01]:
//      reaches 1e-8 (absolute) with M <= 30, exponential decay, history[k] = max_j ||s_j - I_k s_j||_inf
//      recomputed with EIMInterpolate, ||q_k||_inf = 1, hierarchy (a maxM = 5 run is the same prefix);
//   2. interpolation property (I_M s = s at the points, every snapshot), B unit lower triangular;
//   3. snapshots in the span of 5 vectors: M = 5, exhausted, a new combination reproduced; ties;
//   4. EIMInterpolate against a dense LAPACK gesv solve of Q(points, :) phi = f(points);
//   5. bad input (NaN, Inf, empty, size) and EIMOptionsFromOptions (prefixed/shared options, range checks).
#include "rbcontact/eim.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

using namespace rbc;

static int failures = 0;
static void Check(bool ok, const char *what, double v, double bound)
{
  PetscCallVoid(PetscPrintf(PETSC_COMM_WORLD, "  %-6s %-72s %.3e (bound %.1e)\n", ok ? "ok" : "FAIL", what, v, bound));
  if (!ok) ++failures;
}

static double InfNorm(const PetscReal *v, PetscInt n)
{
  double s = 0;
  for (PetscInt i = 0; i < n; ++i) s = std::max(s, (double)std::abs(v[i]));
  return s;
}

// 1/sqrt((x - mu)^2 + 0.01) on x_i = i/(n-1), mu_j = -1 + 0.99 j/(m-1)
static std::vector<PetscReal> Classic(PetscInt n, PetscInt m)
{
  std::vector<PetscReal> S((size_t)n * m);
  for (PetscInt j = 0; j < m; ++j) {
    const double mu = -1 + 0.99 * j / (m - 1);
    for (PetscInt i = 0; i < n; ++i) {
      const double x         = (double)i / (n - 1);
      S[i + (size_t)j * n]   = 1 / std::sqrt((x - mu) * (x - mu) + 0.01);
    }
  }
  return S;
}

// EIMGreedy with errors returned (not printed); the message goes to *msg.
static PetscErrorCode TryGreedy(const std::vector<PetscReal> &S, PetscInt n, PetscInt m, PetscErrorCode *code, std::string *msg)
{
  EIMOptions opt;
  EIMResult  res;

  PetscFunctionBeginUser;
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  *code = EIMGreedy(S, n, m, opt, &res);
  PetscCall(PetscPopErrorHandler());
  msg->clear();
  if (*code) {
    char *specific = NULL;
    PetscCall(PetscErrorMessage(*code, NULL, &specific));
    if (specific) *msg = specific;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode TryOptions(const char *prefix, EIMOptions *opt, PetscErrorCode *code, std::string *msg)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  *code = EIMOptionsFromOptions(PETSC_COMM_WORLD, prefix, opt);
  PetscCall(PetscPopErrorHandler());
  msg->clear();
  if (*code) {
    char *specific = NULL;
    PetscCall(PetscErrorMessage(*code, NULL, &specific));
    if (specific) *msg = specific;
  }
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));

  // --- 1 + 2: the classical example -----------------------------------------------------------------
  {
    const PetscInt n = 200, m = 60;
    const auto     S = Classic(n, m);
    EIMOptions     opt;
    EIMResult      res;
    opt.tol      = 1e-8;
    opt.relative = false;
    opt.name     = "classic";
    PetscCall(EIMGreedy(S, n, m, opt, &res));
    const PetscInt M = res.M;
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "1. classical example 1/sqrt((x-mu)^2+0.01), n = %d, m = %d, tol 1e-8 absolute: M = %d, scale %.6g, exhausted %d\n   history:", (int)n, (int)m, (int)M, (double)res.scale, (int)res.exhausted));
    for (PetscInt k = 0; k <= M; ++k) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s %.2e", k % 10 ? "" : "\n  ", (double)res.history[k]));
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "\n"));
    Check(res.n == n && (PetscInt)res.points.size() == M && (PetscInt)res.selected.size() == M && res.Q.size() == (size_t)n * M && res.B.size() == (size_t)M * M && (PetscInt)res.history.size() == M + 1, "sizes of points, selected, Q, B, history", 0, 0);
    Check(res.history[M] <= 1e-8, "history[M] <= tol (absolute 1e-8)", res.history[M], 1e-8);
    Check(M <= 30 && !res.exhausted, "reaches 1e-8 with M <= 30 (not by exhaustion)", M, 30);
    Check(std::abs(res.history[0] - res.scale) == 0 && std::abs(res.scale - 1 / std::sqrt(0.0101)) < 1e-12 * res.scale, "history[0] = scale = max |s| = 1/sqrt(0.01^2 + 0.01)", res.scale, 1 / std::sqrt(0.0101));
    // exponential decay: every 10 functions gain at least 5 decades (measured: ~7)
    double worstRate = 0;
    for (PetscInt k = 0; k + 10 <= M; ++k) worstRate = std::max(worstRate, (double)(res.history[k + 10] / res.history[k]));
    Check(M >= 10 && worstRate <= 1e-5, "exponential decay: max_k history[k+10] / history[k]", worstRate, 1e-5);
    // history[k] recomputed independently from the interpolant of every snapshot with k functions
    double                 histErr = 0;
    std::vector<PetscReal> out(n);
    for (PetscInt k = 0; k <= M; ++k) {
      double mx = 0;
      for (PetscInt j = 0; j < m; ++j) {
        const PetscReal *s = &S[(size_t)j * n];
        EIMInterpolate(res, k, s, out.data());
        for (PetscInt i = 0; i < n; ++i) mx = std::max(mx, (double)std::abs(s[i] - out[i]));
      }
      histErr = std::max(histErr, std::abs(mx - res.history[k]) / res.scale);
    }
    Check(histErr <= 1e-12, "history[k] = max_j ||s_j - I_k s_j||_inf (EIMInterpolate), / scale", histErr, 1e-12);
    // ||q_k||_inf = 1 (the point is the largest entry of the residual), so |B| <= 1
    double qinf = 0;
    for (PetscInt k = 0; k < M; ++k) qinf = std::max(qinf, std::abs(InfNorm(&res.Q[(size_t)k * n], n) - 1));
    Check(qinf == 0, "||q_k||_inf = 1 for every k", qinf, 0);
    // distinct points
    std::vector<PetscInt> pts(res.points);
    std::sort(pts.begin(), pts.end());
    Check(std::unique(pts.begin(), pts.end()) == pts.end() && pts.front() >= 0 && pts.back() < n, "distinct points in [0, n)", 0, 0);
    // hierarchy / determinism: maxM = 5 gives the same first 5 functions, points and errors (bitwise)
    {
      EIMOptions o5 = opt;
      EIMResult  r5;
      o5.maxM = 5;
      PetscCall(EIMGreedy(S, n, m, o5, &r5));
      bool same = r5.M == 5 && r5.history.size() == 6 && !r5.exhausted;
      for (PetscInt k = 0; same && k < 5; ++k) same = r5.points[k] == res.points[k] && r5.selected[k] == res.selected[k];
      for (PetscInt k = 0; same && k <= 5; ++k) same = r5.history[k] == res.history[k];
      same = same && std::equal(r5.Q.begin(), r5.Q.end(), res.Q.begin());
      Check(same, "maxM = 5: M = 5, the same points/snapshots/Q/history prefix (bitwise)", r5.M, 5);
      // relative tolerance: tolAbs = tol * scale
      EIMOptions orel = opt;
      EIMResult  rrel;
      orel.relative = true;
      orel.tol      = 1e-6;
      PetscCall(EIMGreedy(S, n, m, orel, &rrel));
      Check(rrel.history[rrel.M] <= 1e-6 * rrel.scale && rrel.history[rrel.M - 1] > 1e-6 * rrel.scale && rrel.M < M, "relative tol 1e-6: first k with history[k] <= 1e-6 scale", rrel.M, M);
    }

    // 2. interpolation property: I_M s_j = s_j at the points, for every snapshot
    double interpErr = 0;
    for (PetscInt j = 0; j < m; ++j) {
      const PetscReal *s = &S[(size_t)j * n];
      EIMInterpolate(res, M, s, out.data());
      for (PetscInt k = 0; k < M; ++k) interpErr = std::max(interpErr, (double)std::abs(out[res.points[k]] - s[res.points[k]]));
    }
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "2. interpolation property and B\n"));
    Check(interpErr <= 1e-12, "max_j max_k |I_M s_j (x_k) - s_j(x_k)| (absolute, scale ~ 10)", interpErr, 1e-12);
    double upper = 0, diag = 0, lower = 0;
    bool   fromQ = true;
    for (PetscInt j = 0; j < M; ++j)
      for (PetscInt i = 0; i < M; ++i) {
        const double b = res.B[i + (size_t)j * M];
        if (i == j) diag = std::max(diag, std::abs(b - 1));
        else if (i < j) upper = std::max(upper, std::abs(b));
        else lower = std::max(lower, std::abs(b));
        fromQ = fromQ && b == res.Q[res.points[i] + (size_t)j * n];
      }
    Check(diag <= 1e-14 && upper <= 1e-14, "B unit lower triangular: max(|B_ii - 1|, |B_ij| (i < j))", std::max(diag, upper), 1e-14);
    Check(lower <= 1, "|B_ij| <= 1 below the diagonal", lower, 1);
    Check(fromQ, "B(i,j) = q_j[points[i]]", 0, 0);
  }

  // --- 3: snapshots in the span of 5 vectors -------------------------------------------------------
  {
    const PetscInt                         n = 150, m = 40, r = 5;
    std::mt19937_64                        gen(12345);
    std::uniform_real_distribution<double> U(-1, 1);
    std::vector<PetscReal>                 V((size_t)n * r), S((size_t)n * m, 0.0), f(n, 0.0), out(n);
    for (auto &v : V) v = U(gen);
    for (PetscInt j = 0; j < m; ++j)
      for (PetscInt l = 0; l < r; ++l) {
        const double c = U(gen);
        for (PetscInt i = 0; i < n; ++i) S[i + (size_t)j * n] += c * V[i + (size_t)l * n];
      }
    for (PetscInt l = 0; l < r; ++l) {
      const double c = U(gen);
      for (PetscInt i = 0; i < n; ++i) f[i] += c * V[i + (size_t)l * n];
    }
    EIMOptions opt;
    EIMResult  res;
    opt.tol     = 1e-20; // below the exhaustion level 1e-14 scale
    opt.monitor = true;
    opt.name    = "span5";
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "3. snapshots in the span of %d random vectors (n = %d, m = %d, tol 1e-20 relative), monitor:\n", (int)r, (int)n, (int)m));
    PetscCall(EIMGreedy(S, n, m, opt, &res));
    Check(res.M == r && res.exhausted, "M = 5 and exhausted", res.M, r);
    EIMResult rd;
    PetscCall(EIMGreedy(S, n, m, EIMOptions(), &rd));
    Check(rd.M == r && !rd.exhausted && rd.points == res.points, "default tol 1e-6: M = 5 too, stopped by the tolerance, same points", rd.M, r);
    Check(res.history[res.M] <= 1e-14 * res.scale, "history[M] / scale", res.history[res.M] / res.scale, 1e-14);
    EIMInterpolate(res, res.M, f.data(), out.data());
    double e = 0;
    for (PetscInt i = 0; i < n; ++i) e = std::max(e, (double)std::abs(out[i] - f[i]));
    Check(e <= 1e-10 * InfNorm(f.data(), n), "a new combination is reproduced: ||I f - f||_inf / ||f||_inf", e / InfNorm(f.data(), n), 1e-10);
    // in place (out aliases f)
    std::vector<PetscReal> g(f);
    EIMInterpolate(res, res.M, g.data(), g.data());
    Check(std::equal(g.begin(), g.end(), out.begin()), "EIMInterpolate in place (out = f) gives the same result", 0, 0);

    // ties: |S| = 1 at (1,0), (2,0), (0,1): snapshot 0, point 1; then an all-zero matrix is exhausted at M = 0
    const std::vector<PetscReal> T = {0.5, 1, -1, -1, 0.2, 0.3};
    EIMResult                    rt;
    EIMOptions                   ot;
    ot.maxM = 1;
    PetscCall(EIMGreedy(T, 3, 2, ot, &rt));
    Check(rt.M == 1 && rt.selected[0] == 0 && rt.points[0] == 1, "ties: smallest snapshot, then smallest entry", rt.points[0], 1);
    EIMResult rz;
    PetscCall(EIMGreedy(std::vector<PetscReal>(6, 0.0), 3, 2, EIMOptions(), &rz));
    Check(rz.M == 0 && rz.history.size() == 1 && rz.history[0] == 0, "zero snapshots: M = 0", rz.M, 0);
  }

  // --- 4: against a dense LAPACK solve of the interpolation system ---------------------------------
  {
    const PetscInt         n = 40, m = 15;
    std::vector<PetscReal> S((size_t)n * m);
    auto                   fun = [](double x, double mu) { return std::exp(-mu * x) * std::cos(3 * mu * x) + 1 / (1 + mu * x * x); };
    for (PetscInt j = 0; j < m; ++j)
      for (PetscInt i = 0; i < n; ++i) S[i + (size_t)j * n] = fun((double)i / (n - 1), 0.5 + 4.5 * j / (m - 1));
    EIMOptions opt;
    EIMResult  res;
    opt.tol  = 1e-12;
    opt.maxM = 8;
    PetscCall(EIMGreedy(S, n, m, opt, &res));
    const PetscInt M = res.M;
    double         worst = 0, worstPhi = 0;
    for (double mu : {0.77, 2.2, 4.9}) {
      std::vector<PetscReal> f(n), out(n), ref(n, 0.0), A((size_t)M * M), rhs(M), phi(M);
      std::vector<PetscBLASInt> ipiv(M);
      for (PetscInt i = 0; i < n; ++i) f[i] = fun((double)i / (n - 1), mu);
      for (PetscInt i = 0; i < M; ++i) {
        rhs[i] = f[res.points[i]];
        for (PetscInt k = 0; k < M; ++k) A[i + (size_t)k * M] = res.Q[res.points[i] + (size_t)k * n];
      }
      PetscBLASInt nn = (PetscBLASInt)M, one = 1, info = 0;
      LAPACKgesv_(&nn, &one, A.data(), &nn, ipiv.data(), rhs.data(), &nn, &info);
      PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_LIB, "LAPACK gesv failed (info %d)", (int)info);
      for (PetscInt k = 0; k < M; ++k)
        for (PetscInt i = 0; i < n; ++i) ref[i] += rhs[k] * res.Q[i + (size_t)k * n];
      EIMInterpolate(res, M, f.data(), out.data());
      std::vector<PetscReal> vals(M);
      for (PetscInt i = 0; i < M; ++i) vals[i] = f[res.points[i]];
      EIMCoefficients(res, M, vals.data(), phi.data());
      for (PetscInt i = 0; i < n; ++i) worst = std::max(worst, std::abs(out[i] - ref[i]) / InfNorm(f.data(), n));
      for (PetscInt k = 0; k < M; ++k) worstPhi = std::max(worstPhi, std::abs(phi[k] - rhs[k]) / InfNorm(rhs.data(), M));
    }
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "4. against LAPACK gesv on Q(points, :) (n = %d, m = %d, M = %d, 3 out-of-sample mu)\n", (int)n, (int)m, (int)M));
    Check(M == 8, "M = maxM = 8", M, 8);
    Check(worst <= 1e-12, "max |EIMInterpolate - gesv interpolant| / ||f||_inf", worst, 1e-12);
    Check(worstPhi <= 1e-12, "max |EIMCoefficients - gesv coefficients| / ||phi||_inf", worstPhi, 1e-12);
  }

  // --- 5: bad input and options --------------------------------------------------------------------
  {
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "5. bad input and EIMOptionsFromOptions\n"));
    PetscErrorCode         code;
    std::string            msg;
    std::vector<PetscReal> S = Classic(10, 4);
    S[13]                    = std::numeric_limits<PetscReal>::quiet_NaN();
    PetscCall(TryGreedy(S, 10, 4, &code, &msg));
    Check(code != 0 && msg.find("non-finite") != std::string::npos, "NaN in S: error naming the non-finite entry", code, 0);
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "         message: %s\n", msg.c_str()));
    S[13] = std::numeric_limits<PetscReal>::infinity();
    PetscCall(TryGreedy(S, 10, 4, &code, &msg));
    Check(code != 0 && msg.find("non-finite") != std::string::npos, "Inf in S: error", code, 0);
    PetscCall(TryGreedy(std::vector<PetscReal>(), 0, 4, &code, &msg));
    Check(code == PETSC_ERR_ARG_SIZ, "n = 0: PETSC_ERR_ARG_SIZ", code, PETSC_ERR_ARG_SIZ);
    PetscCall(TryGreedy(std::vector<PetscReal>(), 10, 0, &code, &msg));
    Check(code == PETSC_ERR_ARG_SIZ, "m = 0: PETSC_ERR_ARG_SIZ", code, PETSC_ERR_ARG_SIZ);
    PetscCall(TryGreedy(Classic(10, 4), 10, 5, &code, &msg));
    Check(code == PETSC_ERR_ARG_SIZ, "S.size() != n m: PETSC_ERR_ARG_SIZ", code, PETSC_ERR_ARG_SIZ);

    EIMOptions o;
    PetscCall(PetscOptionsSetValue(NULL, "-eim_max", "7"));
    PetscCall(PetscOptionsSetValue(NULL, "-eim_monitor", NULL));
    PetscCall(TryOptions("eim_t_", &o, &code, &msg));
    Check(!code && o.maxM == 7 && o.monitor && o.relative && o.tol == 1e-6, "shared -eim_max 7 -eim_monitor are the defaults", o.maxM, 7);
    PetscCall(PetscOptionsSetValue(NULL, "-eim_t_max", "3"));
    PetscCall(PetscOptionsSetValue(NULL, "-eim_t_monitor", "0"));
    PetscCall(PetscOptionsSetValue(NULL, "-eim_t_relative", "false"));
    PetscCall(PetscOptionsSetValue(NULL, "-eim_t_tol", "2.5e-9"));
    o = EIMOptions();
    PetscCall(TryOptions("eim_t_", &o, &code, &msg));
    Check(!code && o.maxM == 3 && !o.monitor && !o.relative && o.tol == 2.5e-9, "prefixed -eim_t_max/monitor/relative/tol override", o.maxM, 3);
    PetscCall(PetscOptionsSetValue(NULL, "-eim_t_tol", "-1e-3"));
    PetscCall(TryOptions("eim_t_", &o, &code, &msg));
    Check(code != 0 && msg.find("-eim_t_tol -0.001") != std::string::npos, "-eim_t_tol -1e-3: error naming the option and value", code, 0);
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "         message: %s\n", msg.c_str()));
    PetscCall(PetscOptionsSetValue(NULL, "-eim_t_tol", "0"));
    PetscCall(TryOptions("eim_t_", &o, &code, &msg));
    Check(code != 0 && msg.find("-eim_t_tol 0") != std::string::npos, "-eim_t_tol 0: error", code, 0);
    PetscCall(PetscOptionsClearValue(NULL, "-eim_t_tol"));
    PetscCall(PetscOptionsSetValue(NULL, "-eim_t_max", "0"));
    o = EIMOptions();
    PetscCall(TryOptions("eim_t_", &o, &code, &msg));
    Check(code != 0 && msg.find("-eim_t_max 0") != std::string::npos, "-eim_t_max 0: error naming the option", code, 0);
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "         message: %s\n", msg.c_str()));
    PetscCall(PetscOptionsClearValue(NULL, "-eim_t_max"));
    PetscCall(PetscOptionsSetValue(NULL, "-eim_max", "0"));
    o = EIMOptions();
    PetscCall(TryOptions("eim_t_", &o, &code, &msg));
    Check(code != 0 && msg.find("-eim_max 0") != std::string::npos, "shared -eim_max 0: error naming -eim_max", code, 0);
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "         message: %s\n", msg.c_str()));
    for (const char *name : {"-eim_max", "-eim_monitor", "-eim_t_monitor", "-eim_t_relative"}) PetscCall(PetscOptionsClearValue(NULL, name));
  }

  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s: %d failure(s)\n", failures ? "FAILED" : "PASSED", failures));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
