// tests/test_greedy_indicator.cpp: the greedy training's indicator (GreedyIndicator, greedy_indicator.hpp)
// against the full-order model of the scene given by the options (ctest: runs/ring_on_block.opts):
//   - at the FOM's converged contact solution (default radius, and radius 1.1 where A(mu), f(mu), the
//     geometry and the Dirichlet values all differ from the reference) the residual and the penetration
//     vanish to the Kacanov tolerance (1e-8);
//   - u + e with e random on the dofs away from the contact surfaces (the contact terms do not see it):
//     at the reference parameter A = X, so the residual is ||e||_X / ||u + e||_X, computed here with
//     the FOM's own matrix;
//   - 1.2 u pushes the slave into the master: a penetration far above the converged one;
//   - GreedyPick on a small synthetic pool: decreasing indicator, candidates closer than the separation
//     to an earlier pick skipped, negative entries never picked.
// Runs on 1 and 2 ranks. Prints a table; exits 1 on failure.
#include "rbcontact/greedy_indicator.hpp"
#include "rbcontact/kacanov.hpp"
#include <cmath>
#include <algorithm>
#include <random>

static int failures = 0;

static void Check(bool ok, const char *what, double value, double bound)
{
  if (!ok) ++failures;
  PetscPrintf(PETSC_COMM_WORLD, "  %-6s %-84s %10.3e (bound %.1e)\n", ok ? "ok" : "FAILED", what, value, bound);
}

// The FOM's contact solution at mu, with its multipliers in canonical order on every rank.
static PetscErrorCode SolveFOM(rbc::ElasticFOM &fom, rbc::ContactMap &cmap, rbc::KacanovSolver &kac, rbc::CanonicalOrder &order, const std::vector<PetscReal> &mu, std::vector<PetscReal> *lam)
{
  PetscFunctionBeginUser;
  PetscCall(fom.SetMu(mu));
  PetscCall(fom.AssembleAndFactor());
  cmap.SetGeometry(&fom.map, mu);
  PetscCall(kac.Solve(fom, cmap));
  if (order.NumMultipliers() != cmap.NumMultipliers()) PetscCall(order.BuildMultipliers(kac.sys.coordRef, fom.elas.dim));
  PetscCall(order.MultipliersToCanonical(kac.lambda, lam));
  unsigned long long n = lam->size();
  PetscCallMPI(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, PETSC_COMM_WORLD));
  lam->resize(n);
  PetscCallMPI(MPI_Bcast(lam->data(), (int)n, MPIU_REAL, 0, PETSC_COMM_WORLD));
  PetscFunctionReturn(0);
}

static PetscErrorCode Run()
{
  rbc::SceneSpec       scene;
  rbc::ElasticFOM      fom;
  rbc::ContactMap      cmap;
  rbc::KacanovSolver   kac;
  rbc::CanonicalOrder  order;
  rbc::GreedyIndicator ind;
  rbc::GreedyEstimate  e;
  std::vector<PetscReal> lam;

  PetscFunctionBeginUser;
  PetscCall(rbc::SceneSpecFromOptions(PETSC_COMM_WORLD, &scene));
  PetscCheck(scene.contact && scene.params.size() == 1, PETSC_COMM_WORLD, PETSC_ERR_USER_INPUT, "test_greedy_indicator: give a contact scene with one parameter (runs/ring_on_block.opts)");
  PetscCall(fom.Create(PETSC_COMM_WORLD, scene));
  PetscCall(fom.SetupAffine());
  PetscCall(order.BuildDofs(fom.elas));
  PetscCall(kac.SetFromOptions(PETSC_COMM_WORLD));
  PetscCall(cmap.Setup(fom.elas, scene.slave, scene.master));
  PetscCall(kac.ShareFactor(fom, cmap));
  PetscCall(ind.Setup(fom));

  // the converged FOM: at the default parameter and at radius 1.1
  const std::vector<PetscReal> mu0 = rbc::ParamValues(scene), mu1 = {1.1};
  PetscCall(SolveFOM(fom, cmap, kac, order, mu1, &lam));
  PetscCall(ind.Evaluate(fom, cmap, order, mu1, fom.u, lam, &e));
  Check(e.residual <= 1e-8, "radius 1.1, FOM solution: residual ||A u - f + K' lam||_X' / ||u||_X", e.residual, 1e-8);
  Check(e.penetration <= 1e-8, "radius 1.1, FOM solution: relative penetration", e.penetration, 1e-8);
  PetscCall(SolveFOM(fom, cmap, kac, order, mu0, &lam));
  PetscCall(ind.Evaluate(fom, cmap, order, mu0, fom.u, lam, &e));
  Check(e.residual <= 1e-8, "default radius, FOM solution: residual", e.residual, 1e-8);
  Check(e.penetration <= 1e-8, "default radius, FOM solution: relative penetration", e.penetration, 1e-8);
  const PetscReal pen0 = e.penetration;

  // u + e, e off the contact surfaces: residual = ||e||_X / ||u + e||_X (fom.A = A(mu0) = X)
  std::vector<PetscInt> D;
  PetscCall(cmap.SurfaceDofs(PETSC_COMM_WORLD, &D));
  Vec      ue, ev, t;
  PetscInt lo, hi;
  PetscCall(VecDuplicate(fom.u, &ev));
  PetscCall(VecDuplicate(fom.u, &ue));
  PetscCall(VecDuplicate(fom.u, &t));
  PetscCall(VecGetOwnershipRange(ev, &lo, &hi));
  {
    std::mt19937                     gen(7);
    std::uniform_real_distribution<> U(-1, 1);
    PetscScalar                     *a;
    PetscCall(VecGetArray(ev, &a));
    for (PetscInt i = 0; i < hi; ++i) { // the same numbers on any rank count
      const double x = U(gen);
      if (i >= lo) a[i - lo] = std::binary_search(D.begin(), D.end(), i) ? 0.0 : x;
    }
    PetscCall(VecRestoreArray(ev, &a));
  }
  PetscScalar eXe, uXu;
  PetscCall(MatMult(fom.A, ev, t));
  PetscCall(VecDot(ev, t, &eXe));
  PetscCall(MatMult(fom.A, fom.u, t));
  PetscCall(VecDot(fom.u, t, &uXu));
  PetscCall(VecScale(ev, 1e-2 * std::sqrt(PetscRealPart(uXu) / PetscRealPart(eXe)))); // ||e||_X = 1e-2 ||u||_X
  PetscCall(VecWAXPY(ue, 1.0, fom.u, ev));
  PetscScalar wXw;
  PetscCall(MatMult(fom.A, ue, t));
  PetscCall(VecDot(ue, t, &wXw));
  const PetscReal expect = 1e-2 * std::sqrt(PetscRealPart(uXu) / PetscRealPart(wXw));
  PetscCall(ind.Evaluate(fom, cmap, order, mu0, ue, lam, &e));
  Check(std::abs(e.residual - expect) <= 1e-6 * expect, "u + e off the surfaces: |residual - ||e||_X/||u+e||_X| / expected", std::abs(e.residual - expect) / expect, 1e-6);
  Check(std::abs(e.penetration - pen0) <= 1e-12, "u + e off the surfaces: penetration unchanged", std::abs(e.penetration - pen0), 1e-12);

  // 1.2 u: the slave pushed into the master
  PetscCall(VecWAXPY(ue, 0.2, fom.u, fom.u));
  PetscCall(ind.Evaluate(fom, cmap, order, mu0, ue, lam, &e));
  Check(e.penetration >= 1e-3 && e.penetration >= 1e3 * std::max(pen0, 1e-12), "1.2 u: relative penetration far above the converged one", e.penetration, 1e-3);
  Check(e.value == std::max(e.residual, e.penetration), "indicator value = max(residual, penetration)", e.value, 0);
  PetscCall(VecDestroy(&ev));
  PetscCall(VecDestroy(&ue));
  PetscCall(VecDestroy(&t));

  // GreedyPick on a synthetic pool (one parameter in [0, 1])
  std::vector<rbc::ParamSpec> ps(1);
  ps[0].name = "x";
  ps[0].min  = 0;
  ps[0].max  = 1;
  const std::vector<std::vector<PetscReal>> pool = {{0.0}, {0.5}, {0.51}, {0.7}, {1.0}};
  const std::vector<PetscReal>              eta  = {0.1, 0.9, 0.85, -1, 0.5};
  const auto                                p2   = rbc::GreedyPick(eta, pool, ps, 2, 0.1);
  Check(p2 == std::vector<PetscInt>({1, 4}), "GreedyPick(2, separation 0.1): picks 1 then 4 (2 too close to 1)", p2.size(), 2);
  const auto p9 = rbc::GreedyPick(eta, pool, ps, 9, 0.0);
  Check(p9 == std::vector<PetscInt>({1, 2, 4, 0}), "GreedyPick(9, no separation): every candidate by decreasing indicator, 3 (negative) never", p9.size(), 4);
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(SlepcInitialize(&argc, &argv, NULL, NULL));
  PetscCall(Run());
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_greedy_indicator: %s\n", failures ? "FAILED" : "passed"));
  PetscCall(SlepcFinalize());
  return failures ? 1 : 0;
}
