// bench/bench_reduced_qp.cpp: micro benchmark of the online reduced QP (rbc::ReducedQP, docs/reduced_qp.md).
// For random problems (A SPD, D random, about half of the constraints active) it prints, per (N, R), the
// median time of 1000 solves:
//   cold       lambda = 0 in, nothing reused (Cholesky of A, S = D A^{-1} D', active set from empty)
//   warm       lambda of the previous solve in, nothing reused (A or D changed: the general Kacanov step)
//   warm_newD  lambda of the previous solve in, A the same (cached Cholesky factor), D changed (by one ulp
//              in one entry, alternating: S is rebuilt; the reduced Kacanov case with a constant stiffness)
//   warm_same  lambda of the previous solve in, A and D the same as before (cached factor and S)
//   tao        the TAO BQPIP cross-check (-qp_type tao), median of 50 solves
// and the active-set iterations (Cholesky solves on the free set) of the cold and warm solves.
// Each median is measured -rounds times (default 3) and the smallest is printed (the VM's timing noise).
// Measures only; exits 0. Usage: build/bin/rbc_bench_reduced_qp [-reps 1000] [-tao_reps 50] [-rounds 3]
#include "rbcontact/reduced_qp.hpp"
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

using namespace rbc;
using Vecd = std::vector<PetscReal>;

struct Problem {
  PetscInt N, R;
  Vecd     A, f, D, c;
};

static Problem MakeProblem(PetscInt N, PetscInt R, unsigned seed)
{
  std::mt19937                     gen(seed);
  std::normal_distribution<double> G(0, 1);
  Problem                          p{N, R, Vecd(N * N, 0.0), Vecd(N), Vecd(R * N), Vecd(R)};
  Vecd                             M(N * N);
  for (auto &x : M) x = G(gen);
  for (PetscInt i = 0; i < N; ++i)
    for (PetscInt j = 0; j < N; ++j) {
      for (PetscInt k = 0; k < N; ++k) p.A[i + j * N] += M[k + i * N] * M[k + j * N] / N;
      if (i == j) p.A[i + j * N] += 0.1;
    }
  for (auto &x : p.f) x = G(gen);
  for (auto &x : p.D) x = G(gen);
  // unconstrained solution by Gaussian elimination, then gaps of both signs
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
  for (PetscInt i = 0; i < R; ++i) {
    double dv = 0, rn = 0;
    for (PetscInt j = 0; j < N; ++j) { dv += p.D[i + j * R] * v0[j]; rn += std::abs(p.D[i + j * R]); }
    p.c[i] = dv + rn * 0.5 * G(gen);
  }
  return p;
}

static double Median(std::vector<double> t)
{
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return t[t.size() / 2];
}

static PetscInt gRounds = 3;

// Median time (microseconds) of reps solves, smallest over gRounds rounds; warm: lambda in = the
// solution, else zeros; p2 (if given): alternate between p and p2.
static PetscErrorCode Time(ReducedQP &qp, const Problem &p, bool warm, PetscInt reps, const Vecd &lsol, double *us, PetscInt *its, ReducedQPStatus *status, const Problem *p2 = nullptr)
{
  using clock = std::chrono::steady_clock;
  Vecd                v(p.N), l(p.R);
  std::vector<double> t(reps);
  ReducedQPInfo       info;

  PetscFunctionBeginUser;
  *us = 1e300;
  for (PetscInt round = 0; round < gRounds; ++round) {
    for (PetscInt r = 0; r < reps; ++r) {
      if (warm) std::copy(lsol.begin(), lsol.end(), l.begin());
      else std::fill(l.begin(), l.end(), 0.0);
      const Problem &q  = p2 && r % 2 ? *p2 : p;
      const auto     t0 = clock::now();
      PetscCall(qp.Solve(q.N, q.R, q.A.data(), q.f.data(), q.D.data(), q.c.data(), v.data(), l.data(), &info));
      const auto t1 = clock::now();
      t[r]          = std::chrono::duration<double, std::micro>(t1 - t0).count();
    }
    *us = std::min(*us, Median(t));
  }
  *its    = info.iterations;
  *status = info.status;
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscInt reps = 1000, taoReps = 50;
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-reps", &reps, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-tao_reps", &taoReps, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-rounds", &gRounds, NULL));
  const PetscInt sizes[][2] = {{5, 5}, {10, 10}, {20, 10}, {20, 20}, {20, 40}, {40, 20}, {40, 40}, {60, 30}, {60, 60}};
  { // warm-up, untimed: about half a second of solves (the first rows were slower without it: clock ramp-up)
    const Problem p = MakeProblem(20, 20, 1);
    ReducedQP     qp;
    ReducedQPInfo info;
    Vecd          v(p.N), l(p.R);
    const auto    t0 = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(500)) {
      std::fill(l.begin(), l.end(), 0.0);
      qp.reuseFactorization = false;
      PetscCall(qp.Solve(p.N, p.R, p.A.data(), p.f.data(), p.D.data(), p.c.data(), v.data(), l.data(), &info));
    }
  }
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "ReducedQP (activeset unless noted), median of %" PetscInt_FMT " solves (tao: %" PetscInt_FMT "), smallest of %" PetscInt_FMT " rounds, microseconds\n", reps, taoReps, gRounds));
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "%4s %4s %6s | %9s %5s | %9s %5s | %9s | %9s | %9s %5s | %s\n", "N", "R", "active", "cold", "its", "warm", "its", "warm_newD", "warm_same", "tao", "its", "status"));
  for (const auto &sz : sizes) {
    const Problem p = MakeProblem(sz[0], sz[1], 1000 + sz[0] * 7 + sz[1]);
    ReducedQP     qp, qpTao;
    ReducedQPInfo info;
    Vecd          v(p.N), lsol(p.R, 0.0);
    qp.Reserve(p.N, p.R);
    PetscCall(qp.Solve(p.N, p.R, p.A.data(), p.f.data(), p.D.data(), p.c.data(), v.data(), lsol.data(), &info));
    const PetscInt  nactive = info.nactive;
    double          tCold, tWarm, tNewD, tSame, tTao;
    PetscInt        iCold, iWarm, iNewD, iSame, iTao;
    ReducedQPStatus sCold, sWarm, sNewD, sSame, sTao;
    Problem         p2 = p;
    p2.D[0]            = std::nextafter(p2.D[0], 1e300);
    qp.reuseFactorization = false;
    PetscCall(Time(qp, p, false, reps, lsol, &tCold, &iCold, &sCold));
    PetscCall(Time(qp, p, true, reps, lsol, &tWarm, &iWarm, &sWarm));
    qp.reuseFactorization = true;
    PetscCall(Time(qp, p, true, reps, lsol, &tNewD, &iNewD, &sNewD, &p2));
    PetscCall(Time(qp, p, true, reps, lsol, &tSame, &iSame, &sSame));
    qpTao.type = ReducedQPType::Tao;
    PetscCall(Time(qpTao, p, false, taoReps, lsol, &tTao, &iTao, &sTao));
    const bool ok = sCold == ReducedQPStatus::Ok && sWarm == ReducedQPStatus::Ok && sNewD == ReducedQPStatus::Ok && sSame == ReducedQPStatus::Ok && iNewD <= 2 && iSame == iWarm;
    PetscCall(PetscPrintf(PETSC_COMM_SELF, "%4" PetscInt_FMT " %4" PetscInt_FMT " %6" PetscInt_FMT " | %9.2f %5" PetscInt_FMT " | %9.2f %5" PetscInt_FMT " | %9.2f | %9.2f | %9.1f %5" PetscInt_FMT " | %s%s\n", p.N, p.R, nactive, tCold, iCold, tWarm, iWarm, tNewD, tSame, tTao, iTao,
                          ok ? "ok" : "NOT OK", sTao == ReducedQPStatus::Ok ? "" : " (tao not ok)"));
    PetscCall(qpTao.Reset());
  }
  PetscCall(PetscFinalize());
  return 0;
}
