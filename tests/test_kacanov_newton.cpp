// tests/test_kacanov_newton.cpp: the Newton step of the full-order Kacanov loop (-kacanov_type newton,
// src/contact/kacanov_newton.cpp) and the derivative of the contact geometry it uses
// (ContactMap::AssembleTangent, src/contact/contact_tangent.cpp), on the scene of the options:
//   1. the scene solved with -kacanov_type fixed_point (the options' Anderson depth) and with newton on the
//      same factorization: both converge, the contact forces agree to -test_force_rtol (1e-8), Newton needs
//      at most -test_max_its iterations and no more than the fixed point, and at least one Newton step
//      was taken;
//   2. every Newton step refused (-kacanov_newton_max_ratio 1e-6): the plain Kacanov iterates (the same
//      iterations and force as -kacanov_type fixed_point -kacanov_anderson 0);
//   3. the tangent against central finite differences of the assembly at the converged state, in three
//      random directions on the contact dofs: H dx = d(K^T lambda) and Q dx = d(g - K y) (active rows,
//      y = the solution plus a random field): with the scene's rule to -test_fd_rtol (1e-3: the segment-based
//      rule's moving cuts are left out, 5e-7 to 6e-4 measured), with fixed composite points (the pointwise
//      derivative alone) to -test_fd_rtol_fixed (1e-8; 8e-11 to 9e-10 measured).
//   4. GatherRowsOnDofs (the contact matrix's rows on the contact dofs, gathered by rows on every rank: the dense
//      dual path's K_D) against PETSc's MatMult and MatMultTranspose with K itself, in a random direction, to 1e-14.
// Serial and parallel (the tangent is gathered on every rank; the direction is the same on every rank).
#include "rbcontact/fom.hpp"
#include "rbcontact/kacanov.hpp"
#include <algorithm>
#include <cmath>
#include <random>

#include "test_check.hpp"

using namespace rbc;

using rbctest::Check;
using rbctest::failures;

// The values of a global vector at the sorted global indices D, on every rank.
static PetscErrorCode ValuesAt(Vec v, const std::vector<PetscInt> &D, std::vector<PetscReal> *out)
{
  std::vector<PetscReal> all;

  PetscFunctionBeginUser;
  PetscCall(GatherVec(v, &all));
  out->resize(D.size());
  for (size_t j = 0; j < D.size(); ++j) (*out)[j] = all[D[j]];
  PetscFunctionReturn(0);
}

// K(u)^T lambda on D and g(u) - K(u) y (all rows) with u = base + eps dx (dx on D).
static PetscErrorCode Evaluate(ElasticFOM &fom, ContactMap &map, Vec base, const std::vector<PetscInt> &D, const std::vector<PetscReal> &dx, PetscReal eps, Vec lambda, Vec y, std::vector<PetscReal> *ktl, std::vector<PetscReal> *gky)
{
  Vec           u, uloc, w, r;
  ContactSystem sys;
  PetscInt      lo, hi;
  PetscScalar  *a;

  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(base, &u));
  PetscCall(VecCopy(base, u));
  PetscCall(VecGetOwnershipRange(u, &lo, &hi));
  PetscCall(VecGetArray(u, &a));
  for (size_t j = 0; j < D.size(); ++j)
    if (D[j] >= lo && D[j] < hi) a[D[j] - lo] += eps * dx[j];
  PetscCall(VecRestoreArray(u, &a));
  PetscCall(DMCreateLocalVector(fom.dm, &uloc));
  PetscCall(fom.elas.GlobalToLocalWithBC(u, uloc));
  PetscCall(map.Assemble(fom.elas, uloc, &sys));
  PetscCall(VecDuplicate(u, &w));
  PetscCall(MatMultTranspose(sys.K, lambda, w));
  PetscCall(ValuesAt(w, D, ktl));
  PetscCall(VecDuplicate(sys.g, &r));
  PetscCall(MatMult(sys.K, y, r));
  PetscCall(VecAYPX(r, -1.0, sys.g));
  PetscCall(GatherVec(r, gky));
  PetscCall(VecDestroy(&r));
  PetscCall(VecDestroy(&w));
  PetscCall(VecDestroy(&uloc));
  PetscCall(VecDestroy(&u));
  PetscFunctionReturn(0);
}

static PetscErrorCode TangentCheck(MPI_Comm comm, ElasticFOM &fom, ContactMap &map, Vec lambda, PetscReal rtol, const char *label)
{
  std::vector<PetscInt>  D;
  std::vector<PetscReal> lam, uD, yD, k0, g0;
  Vec                    y;
  PetscInt               lo, hi;
  PetscScalar           *a;

  PetscFunctionBeginUser;
  PetscCall(map.SurfaceDofs(comm, &D));
  PetscCall(GatherVec(lambda, &lam));
  PetscCall(ValuesAt(fom.u, D, &uD));
  PetscReal umax = 0;
  for (PetscReal v : uD) umax = std::max(umax, std::abs(v));
  std::mt19937                           rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  yD = uD;
  for (auto &v : yD) v += 0.1 * umax * U(rng); // y != the solution: the y-terms of Q count
  PetscCall(VecDuplicate(fom.u, &y));
  PetscCall(VecSet(y, 0.0));
  PetscCall(VecGetOwnershipRange(y, &lo, &hi));
  PetscCall(VecGetArray(y, &a));
  for (size_t j = 0; j < D.size(); ++j)
    if (D[j] >= lo && D[j] < hi) a[D[j] - lo] = yD[j];
  PetscCall(VecRestoreArray(y, &a));
  // the tangent at the solution (its own assembly first: AssembleTangent uses the last Assemble's points)
  std::vector<PetscReal> zero(D.size(), 0.0);
  PetscCall(Evaluate(fom, map, fom.u, D, zero, 0.0, lambda, y, &k0, &g0));
  ContactTangent tan;
  bool           supported = false;
  PetscCall(map.AssembleTangent(comm, lam, D, yD, &tan, &supported));
  PetscCall(Check(comm, supported, "tangent supported (2D)", supported ? 1.0 : 0.0, 1.0));
  if (!supported) PetscFunctionReturn(0);
  PetscCall(Check(comm, !tan.hRow.empty() && !tan.qRow.empty(), "tangent has geometric-stiffness and gap terms", (double)tan.hRow.size(), 1.0));
  PetscReal hrel = 1e-6;
  PetscCall(PetscOptionsGetReal(NULL, NULL, "-test_fd_h", &hrel, NULL));
  const PetscReal h = hrel * umax;
  for (int dir = 0; dir < 3; ++dir) {
    std::vector<PetscReal> dx(D.size()), kp, km, gp, gm;
    for (auto &v : dx) v = U(rng);
    PetscCall(Evaluate(fom, map, fom.u, D, dx, h, lambda, y, &kp, &gp));
    PetscCall(Evaluate(fom, map, fom.u, D, dx, -h, lambda, y, &km, &gm));
    // the tangent's products H dx, Q dx
    std::vector<PetscReal> Hdx(D.size(), 0.0), Qdx(lam.size(), 0.0);
    auto                   idx = [&](PetscInt dof) { return std::lower_bound(D.begin(), D.end(), dof) - D.begin(); };
    for (size_t e = 0; e < tan.hRow.size(); ++e) Hdx[idx(tan.hRow[e])] += tan.hVal[e] * dx[idx(tan.hCol[e])];
    for (size_t e = 0; e < tan.qRow.size(); ++e) Qdx[tan.qRow[e]] += tan.qVal[e] * dx[idx(tan.qCol[e])];
    PetscReal eh = 0, nh = 0, eq = 0, nq = 0;
    for (size_t j = 0; j < D.size(); ++j) {
      const PetscReal fd = (kp[j] - km[j]) / (2 * h);
      eh += PetscSqr(fd - Hdx[j]);
      nh += PetscSqr(fd);
    }
    for (size_t i = 0; i < lam.size(); ++i) {
      if (!(lam[i] > 0)) continue;
      const PetscReal fd = (gp[i] - gm[i]) / (2 * h);
      eq += PetscSqr(fd - Qdx[i]);
      nq += PetscSqr(fd);
    }
    char what[128];
    std::snprintf(what, sizeof what, "%s, direction %d: |H dx - FD| / |FD| (d(K^T lambda), |FD| %.2e)", label, dir, std::sqrt(nh));
    PetscCall(Check(comm, nh > 0 && std::sqrt(eh / nh) <= rtol, what, nh > 0 ? std::sqrt(eh / nh) : 1.0, rtol));
    std::snprintf(what, sizeof what, "%s, direction %d: |Q dx - FD| / |FD| (d(g - K y), active rows, |FD| %.2e)", label, dir, std::sqrt(nq));
    PetscCall(Check(comm, nq > 0 && std::sqrt(eq / nq) <= rtol, what, nq > 0 ? std::sqrt(eq / nq) : 1.0, rtol));
  }
  PetscCall(VecDestroy(&y));
  PetscFunctionReturn(0);
}

// GatherRowsOnDofs: K_D x and K_D' y from the gathered rows against MatMult / MatMultTranspose with K (x on the
// contact dofs, zero elsewhere; the same random x and y on every rank).
static PetscErrorCode GatherCheck(MPI_Comm comm, const ContactMap &map, Mat K)
{
  std::vector<PetscInt>  D;
  SparseRows             KD;
  PetscInt               R, n, lo, hi;
  std::vector<PetscReal> kx, kty, x, y;
  Vec                    xv, yv, kxv, ktyv;

  PetscFunctionBeginUser;
  PetscCall(map.SurfaceDofs(comm, &D));
  PetscCall(GatherRowsOnDofs(K, D, &KD));
  PetscCall(MatGetSize(K, &R, &n));
  PetscCall(MatCreateVecs(K, &xv, &yv));
  PetscCall(VecDuplicate(yv, &kxv));
  PetscCall(VecDuplicate(xv, &ktyv));
  std::mt19937                           gen(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (size_t j = 0; j < D.size(); ++j) x.push_back(U(gen));
  for (PetscInt i = 0; i < R; ++i) y.push_back(U(gen));
  PetscCall(VecGetOwnershipRange(xv, &lo, &hi));
  for (size_t j = 0; j < D.size(); ++j)
    if (D[j] >= lo && D[j] < hi) PetscCall(VecSetValue(xv, D[j], x[j], INSERT_VALUES));
  PetscCall(VecAssemblyBegin(xv));
  PetscCall(VecAssemblyEnd(xv));
  PetscCall(VecGetOwnershipRange(yv, &lo, &hi));
  for (PetscInt i = lo; i < hi; ++i) PetscCall(VecSetValue(yv, i, y[i], INSERT_VALUES));
  PetscCall(VecAssemblyBegin(yv));
  PetscCall(VecAssemblyEnd(yv));
  PetscCall(MatMult(K, xv, kxv));
  PetscCall(MatMultTranspose(K, yv, ktyv));
  PetscCall(GatherVec(kxv, &kx));
  PetscCall(ValuesAt(ktyv, D, &kty));
  PetscReal ex = 0, nx = 0, ey = 0, ny = 0;
  std::vector<PetscReal> t(D.size(), 0.0);
  for (PetscInt i = 0; i < R; ++i) {
    PetscReal v = 0;
    for (PetscInt e = KD.ptr[i]; e < KD.ptr[i + 1]; ++e) {
      v += KD.val[e] * x[KD.col[e]];
      t[KD.col[e]] += KD.val[e] * y[i];
    }
    ex = std::max(ex, std::abs(v - kx[i]));
    nx = std::max(nx, std::abs(kx[i]));
  }
  for (size_t j = 0; j < D.size(); ++j) {
    ey = std::max(ey, std::abs(t[j] - kty[j]));
    ny = std::max(ny, std::abs(kty[j]));
  }
  const bool shape = KD.rows == R && KD.cols == (PetscInt)D.size() && (PetscInt)KD.ptr.size() == R + 1 && KD.ptr[R] == (PetscInt)KD.col.size() && KD.col.size() == KD.val.size() && KD.ptr[R] > 0;
  PetscCall(Check(comm, shape, "GatherRowsOnDofs: R + 1 row pointers, as many columns as values, some nonzeros", (double)KD.ptr[R], 1.0));
  PetscCall(Check(comm, nx > 0 && ex <= 1e-14 * nx, "GatherRowsOnDofs: K_D x against MatMult (max abs error / max |K x|)", nx > 0 ? ex / nx : 1.0, 1e-14));
  PetscCall(Check(comm, ny > 0 && ey <= 1e-14 * ny, "GatherRowsOnDofs: K_D' y against MatMultTranspose", ny > 0 ? ey / ny : 1.0, 1e-14));
  PetscCall(VecDestroy(&xv));
  PetscCall(VecDestroy(&yv));
  PetscCall(VecDestroy(&kxv));
  PetscCall(VecDestroy(&ktyv));
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  MPI_Comm  comm     = PETSC_COMM_WORLD;
  PetscInt  maxIts   = 7;
  PetscReal forceTol = 1e-8, fdTol = 1e-3, fdTolFixed = 1e-8;
  PetscOptionsBegin(comm, "test_", "test_kacanov_newton", "");
  PetscCall(PetscOptionsInt("-max_its", "Most Newton iterations accepted", NULL, maxIts, &maxIts, NULL));
  PetscCall(PetscOptionsReal("-force_rtol", "Newton vs fixed point contact force", NULL, forceTol, &forceTol, NULL));
  PetscCall(PetscOptionsReal("-fd_rtol", "Tangent vs finite differences, the scene's quadrature", NULL, fdTol, &fdTol, NULL));
  PetscCall(PetscOptionsReal("-fd_rtol_fixed", "Tangent vs finite differences, fixed composite points", NULL, fdTolFixed, &fdTolFixed, NULL));
  PetscOptionsEnd();
  {
    SceneSpec  scene;
    ElasticFOM fom;
    ContactMap map;
    PetscCall(SceneSpecFromOptions(comm, &scene));
    PetscCall(fom.Create(comm, scene));
    if (!scene.params.empty()) PetscCall(fom.SetupAffine());
    PetscCall(fom.SetMu(ParamValues(scene)));
    KacanovSolver fp, nw;
    PetscCall(fp.SetFromOptions(comm));
    PetscCall(nw.SetFromOptions(comm));
    fp.type = "fixed_point";
    nw.type = "newton";
    PetscCall(map.Setup(fom.elas, scene.slave, scene.master));
    map.SetGeometry(&fom.map, fom.mu);
    PetscCall(fp.ShareFactor(fom, map));
    PetscCall(fom.AssembleAndFactor());
    ContactSummary sf, sn;
    PetscCall(fp.Solve(fom, map));
    PetscCall(SummarizeContact(fp.sys, fp.lambda, fom.elas.dim, &sf));
    PetscCall(nw.Solve(fom, map));
    PetscCall(SummarizeContact(nw.sys, nw.lambda, fom.elas.dim, &sn));
    PetscCall(PetscPrintf(comm, "scene %s: fixed point (Anderson %" PetscInt_FMT ") %" PetscInt_FMT " iterations, force %.16g; Newton %" PetscInt_FMT " iterations (%" PetscInt_FMT " Newton steps), force %.16g\n", scene.name.c_str(), fp.loop.anderson, fp.iterations, (double)sf.force, nw.iterations, nw.newtonSteps, (double)sn.force));
    PetscCall(Check(comm, fp.converged && nw.converged, "both converged", 1.0, 1.0));
    PetscCall(Check(comm, nw.iterations <= maxIts, "Newton iterations <= -test_max_its", (double)nw.iterations, (double)maxIts));
    PetscCall(Check(comm, nw.iterations <= fp.iterations, "Newton iterations <= fixed-point iterations", (double)nw.iterations, (double)fp.iterations));
    PetscCall(Check(comm, nw.newtonSteps >= 1, "Newton steps taken", (double)nw.newtonSteps, 1.0));
    const PetscReal df = std::abs(sn.force - sf.force) / std::abs(sf.force);
    PetscCall(Check(comm, sf.force > 0 && df <= forceTol, "contact force: |Newton - fixed point| / |fixed point|", df, forceTol));
    PetscCall(Check(comm, sn.nactive == sf.nactive, "same active count", (double)sn.nactive, (double)sf.nactive));
    // every Newton step refused (-kacanov_newton_max_ratio 1e-6): the fallback is the plain Kacanov
    // iterate, so the iterations are plain Kacanov's (fixed point without Anderson) and the force the same
    KacanovSolver refused, plain;
    PetscCall(refused.SetFromOptions(comm));
    PetscCall(plain.SetFromOptions(comm));
    refused.type           = "newton";
    refused.newtonMaxRatio = 1e-6;
    plain.type             = "fixed_point";
    plain.loop.anderson    = 0;
    ContactSummary sr, sp;
    PetscCall(refused.Solve(fom, map));
    PetscCall(SummarizeContact(refused.sys, refused.lambda, fom.elas.dim, &sr));
    PetscCall(plain.Solve(fom, map));
    PetscCall(SummarizeContact(plain.sys, plain.lambda, fom.elas.dim, &sp));
    PetscCall(PetscPrintf(comm, "every Newton step refused: %" PetscInt_FMT " iterations, force %.16g; plain Kacanov %" PetscInt_FMT " iterations, force %.16g\n", refused.iterations, (double)sr.force, plain.iterations, (double)sp.force));
    PetscCall(Check(comm, refused.newtonSteps == 0 && refused.iterations == plain.iterations, "refused steps: no Newton step, plain Kacanov's iterations", (double)refused.iterations, (double)plain.iterations));
    const PetscReal dr = std::abs(sr.force - sp.force) / std::abs(sp.force);
    PetscCall(Check(comm, dr <= 1e-14, "refused steps: force vs plain Kacanov (the same iterates)", dr, 1e-14));
    // the tangent at the solution: with the scene's quadrature, and with fixed composite points (no moving
    // mortar cuts: the pointwise derivative alone, to rounding)
    PetscCall(TangentCheck(comm, fom, map, nw.lambda, fdTol, "scene's rule"));
    ContactMap fixedPoints;
    PetscCall(fixedPoints.Setup(fom.elas, scene.slave, scene.master));
    fixedPoints.SetGeometry(&fom.map, fom.mu);
    fixedPoints.quadrature = ContactQuadrature::Composite;
    PetscCall(TangentCheck(comm, fom, fixedPoints, nw.lambda, fdTolFixed, "composite"));
    PetscCall(GatherCheck(comm, map, nw.sys.K));
  }
  PetscCall(PetscPrintf(comm, "%s (%d failure(s))\n", failures ? "FAILED" : "passed", failures));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
