// src/offline/snapshot_sensitivity.cpp: ParameterSensitivities (rbcontact/snapshot_sensitivity.hpp), the
// derivative of a converged contact solution along every parameter, at a fixed active set and contact geometry.
#include "rbcontact/snapshot_sensitivity.hpp"
#include <petscblaslapack.h>

namespace rbc {

static PetscLogEvent SENS_Solve = 0;

namespace {
// The Schur complement on the active rows, K_A A^-1 K_A', extended by the identity on the inactive rows (so
// that CG runs on the multipliers' layout).
struct ActiveSchur {
  ElasticFOM *fom  = nullptr;
  Mat         K    = nullptr;
  Vec         mask = nullptr; // 1 on the active rows, 0 elsewhere
  Vec         m = nullptr, x = nullptr, y = nullptr;
};

PetscErrorCode ActiveSchurMult(Mat S, Vec in, Vec out)
{
  ActiveSchur *c;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(S, &c));
  PetscCall(VecPointwiseMult(c->m, c->mask, in));
  PetscCall(MatMultTranspose(c->K, c->m, c->x));
  PetscCall(c->fom->ApplyInverse(c->x, c->y));
  PetscCall(MatMult(c->K, c->y, out));
  PetscCall(VecPointwiseMult(out, c->mask, out));
  PetscCall(VecAXPY(out, 1.0, in));       // + in
  PetscCall(VecAXPY(out, -1.0, c->m));    // - mask in: the identity on the inactive rows only
  PetscFunctionReturn(0);
}

// The residual of the contact equilibrium and of the constraint at fixed (u, lambda) in the configuration of mu:
// ru = A(mu) u - f(mu) + K(mu, u)' lambda, rc = K(mu, u) u - g(mu, u) (sys: scratch for the assembly).
PetscErrorCode ResidualAt(ElasticFOM &fom, ContactMap &cmap, Vec u, Vec lam, const std::vector<PetscReal> &mu, Vec uloc, Vec t, ContactSystem *sys, Vec ru, Vec rc)
{
  PetscFunctionBeginUser;
  PetscCall(fom.SetMu(mu)); // the Dirichlet values at mu (no assembly)
  PetscCall(fom.affine.Residual(mu, u, t, ru));
  cmap.SetGeometry(&fom.map, mu);
  PetscCall(fom.elas.GlobalToLocalWithBC(u, uloc));
  PetscCall(cmap.Assemble(fom.elas, uloc, sys));
  PetscCall(MatMultTransposeAdd(sys->K, lam, ru, ru));
  PetscCall(MatMult(sys->K, u, rc));
  PetscCall(VecAXPY(rc, -1.0, sys->g));
  PetscFunctionReturn(0);
}
} // namespace

PetscErrorCode ParameterSensitivities(ElasticFOM &fom, ContactMap &cmap, KacanovSolver &kac, std::vector<Vec> *du, std::vector<Vec> *dlam, SensitivityInfo *info)
{
  MPI_Comm                     comm = PetscObjectComm((PetscObject)fom.dm);
  const std::vector<PetscReal> mu0  = fom.mu;
  const PetscInt               np   = (PetscInt)mu0.size();
  ActiveSchur                  ctx;
  ContactSystem                sys;
  Vec                          uloc, t, rup, rum, rcp, rcm, bu, du0, rhs, yv;
  Mat                          S   = nullptr;
  KSP                          ksp = nullptr;
  PC                           pc;
  PetscLogDouble               t0, t1;

  PetscFunctionBeginUser;
  if (!SENS_Solve) PetscCall(PetscLogEventRegister("RBCSensitivity", DM_CLASSID, &SENS_Solve));
  PetscCheck(fom.useAffine, comm, PETSC_ERR_SUP, "-snapshots_sensitivities: the scene has no affine decomposition (the derivative of A(mu) and f(mu) comes from it)");
  PetscCheck(kac.lambda && kac.sys.K, comm, PETSC_ERR_ORDER, "-snapshots_sensitivities: no converged contact solution (KacanovSolver::Solve first)");
  PetscCall(PetscLogEventBegin(SENS_Solve, 0, 0, 0, 0));
  PetscCall(PetscTime(&t0));
  *info = SensitivityInfo();
  PetscCall(DMCreateLocalVector(fom.dm, &uloc));
  PetscCall(DMCreateGlobalVector(fom.dm, &t));
  for (Vec *v : {&rup, &rum, &bu, &du0, &ctx.x, &ctx.y}) PetscCall(VecDuplicate(t, v));
  for (Vec *v : {&rcp, &rcm, &rhs, &yv, &ctx.mask, &ctx.m}) PetscCall(VecDuplicate(kac.lambda, v));
  { // the active rows: lambda_r > 0
    const PetscScalar *l;
    PetscScalar       *m;
    PetscInt           n, nact = 0;
    PetscCall(VecGetLocalSize(kac.lambda, &n));
    PetscCall(VecGetArrayRead(kac.lambda, &l));
    PetscCall(VecGetArray(ctx.mask, &m));
    for (PetscInt r = 0; r < n; ++r) {
      m[r] = l[r] > 0 ? 1.0 : 0.0;
      nact += l[r] > 0;
    }
    PetscCall(VecRestoreArray(ctx.mask, &m));
    PetscCall(VecRestoreArrayRead(kac.lambda, &l));
    PetscCallMPI(MPI_Allreduce(&nact, &info->active, 1, MPIU_INT, MPI_SUM, comm));
  }
  // The dense dual path (-fom_dual_matrix dense) holds the compliance G = (A^-1)_DD of this parameter: then
  // S_AA = K_AD G K_AD' is formed and factored (Cholesky) once, every rank the same, instead of CG.
  const bool             dense = kac.dualMatrix == "dense" && !kac.compliance.D.empty() && kac.compliance.G.size() == kac.compliance.D.size() * kac.compliance.D.size();
  info->method = dense ? "dense" : kac.dualMatrix == "saddle" ? "saddle" : "cg";
  if (info->method == "cg") { // the shell path: CG on the active rows' Schur complement
    ctx.fom = &fom;
    ctx.K   = kac.sys.K;
    {
      PetscInt nl, Nl;
      PetscCall(VecGetLocalSize(kac.lambda, &nl));
      PetscCall(VecGetSize(kac.lambda, &Nl));
      PetscCall(MatCreateShell(comm, nl, nl, Nl, Nl, &ctx, &S));
      PetscCall(MatShellSetOperation(S, MATOP_MULT, (void (*)(void))ActiveSchurMult));
    }
    PetscCall(KSPCreate(comm, &ksp));
    PetscCall(KSPSetOptionsPrefix(ksp, "sensitivity_"));
    PetscCall(KSPSetType(ksp, KSPCG));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCSetType(pc, PCNONE));
    PetscCall(KSPSetTolerances(ksp, 1e-10, 1e-300, PETSC_DEFAULT, 10 * info->active + 100));
    PetscCall(KSPSetOperators(ksp, S, S));
    PetscCall(KSPSetFromOptions(ksp));
  }
  std::vector<PetscInt>  act; // the active rows (global), dense path
  std::vector<PetscReal> SA;  // their Schur complement's Cholesky factor
  PetscInt               rlo = 0, rhi = 0;
  PetscCall(VecGetOwnershipRange(kac.lambda, &rlo, &rhi));
  if (dense && info->active > 0) {
    const std::vector<PetscInt> &D  = kac.compliance.D;
    const PetscBLASInt           nD = (PetscBLASInt)D.size();
    SparseRows                   KD;
    std::vector<PetscReal>       lam, T;
    PetscCall(GatherRowsOnDofs(kac.sys.K, D, &KD));
    PetscCall(GatherVec(kac.lambda, &lam));
    const PetscInt R = (PetscInt)lam.size();
    for (PetscInt r = 0; r < R; ++r)
      if (lam[r] > 0) act.push_back(r);
    const PetscBLASInt na = (PetscBLASInt)act.size();
    std::vector<PetscReal> KA((size_t)na * nD, 0.0); // K_AD, na x nD column-major
    for (PetscBLASInt a = 0; a < na; ++a)
      for (PetscInt e = KD.ptr[act[a]]; e < KD.ptr[act[a] + 1]; ++e) KA[a + (size_t)KD.col[e] * na] = KD.val[e];
    T.assign((size_t)nD * na, 0.0); // G K_AD'
    SA.assign((size_t)na * na, 0.0);
    const PetscReal one = 1, zero = 0;
    BLASgemm_("N", "T", &nD, &na, &nD, &one, kac.compliance.G.data(), &nD, KA.data(), &na, &zero, T.data(), &nD);
    BLASgemm_("N", "N", &na, &na, &nD, &one, KA.data(), &na, T.data(), &nD, &zero, SA.data(), &na);
    PetscBLASInt linfo = 0;
    LAPACKpotrf_("L", &na, SA.data(), &na, &linfo);
    PetscCheck(linfo == 0, comm, PETSC_ERR_MAT_CH_ZRPVT, "-snapshots_sensitivities: the Schur complement K_A A^-1 K_A' of the %d active rows is not positive definite (LAPACK potrf info %d): dependent active constraints", (int)na, (int)linfo);
  }
  du->assign(np, nullptr);
  dlam->assign(np, nullptr);
  for (PetscInt i = 0; i < np; ++i) {
    const PetscReal        lo = fom.scene.params[i].min, hi = fom.scene.params[i].max, h = 1e-6 * (hi - lo);
    std::vector<PetscReal> mp = mu0, mm = mu0;
    if (mu0[i] + h <= hi) mp[i] += h;
    if (mu0[i] - h >= lo) mm[i] -= h;
    const PetscReal step = mp[i] - mm[i];
    PetscCheck(step > 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-snapshots_sensitivities: the range of parameter %s is empty", fom.scene.params[i].name.c_str());
    PetscCall(ResidualAt(fom, cmap, fom.u, kac.lambda, mp, uloc, t, &sys, rup, rcp));
    PetscCall(ResidualAt(fom, cmap, fom.u, kac.lambda, mm, uloc, t, &sys, rum, rcm));
    // right-hand side: -(d residual / d mu_i)
    PetscCall(VecAXPBYPCZ(bu, -1.0 / step, 1.0 / step, 0.0, rup, rum));
    PetscCall(VecAXPBYPCZ(rhs, -1.0 / step, 1.0 / step, 0.0, rcp, rcm)); // b_c
    if (info->method == "saddle") { // the saddle point of the converged set, with the solver's own factor
      PetscCall(VecDuplicate(t, &(*du)[i]));
      PetscCall(VecDuplicate(yv, &(*dlam)[i]));
      PetscCall(kac.SolveSaddleFixedSet(bu, rhs, (*du)[i], (*dlam)[i]));
      continue;
    }
    // du0 = A^-1 b_u; S_AA y = K_A du0 - b_c; du = du0 - A^-1 K_A' y
    PetscCall(fom.ApplyInverse(bu, du0));
    PetscCall(MatMult(kac.sys.K, du0, yv));
    PetscCall(VecAYPX(rhs, -1.0, yv));
    PetscCall(VecPointwiseMult(rhs, ctx.mask, rhs));
    PetscCall(VecSet(yv, 0.0));
    if (info->active > 0 && dense) {
      std::vector<PetscReal> b;
      PetscCall(GatherVec(rhs, &b));
      PetscBLASInt           na = (PetscBLASInt)act.size(), one = 1, linfo = 0;
      std::vector<PetscReal> y(na);
      for (PetscBLASInt a = 0; a < na; ++a) y[a] = b[act[a]];
      LAPACKpotrs_("L", &na, &one, SA.data(), &na, y.data(), &na, &linfo);
      PetscCheck(linfo == 0, comm, PETSC_ERR_LIB, "-snapshots_sensitivities: LAPACK potrs info %d", (int)linfo);
      PetscScalar *ya;
      PetscCall(VecGetArray(yv, &ya));
      for (PetscBLASInt a = 0; a < na; ++a)
        if (act[a] >= rlo && act[a] < rhi) ya[act[a] - rlo] = y[a];
      PetscCall(VecRestoreArray(yv, &ya));
    } else if (info->active > 0) {
      KSPConvergedReason reason;
      PetscInt           its;
      PetscCall(KSPSolve(ksp, rhs, yv));
      PetscCall(KSPGetConvergedReason(ksp, &reason));
      PetscCall(KSPGetIterationNumber(ksp, &its));
      PetscCheck(reason > 0, comm, PETSC_ERR_NOT_CONVERGED, "-snapshots_sensitivities: the solve on the %" PetscInt_FMT " active rows (CG on K_A A^-1 K_A') did not converge at mu = (%g, ...) along %s: %s after %" PetscInt_FMT " iterations (-sensitivity_ksp_max_it, -sensitivity_ksp_rtol)", info->active, (double)mu0[0], fom.scene.params[i].name.c_str(), KSPConvergedReasons[reason], its);
      info->cgIterations = std::max(info->cgIterations, its);
    }
    PetscCall(VecPointwiseMult(yv, ctx.mask, yv));
    PetscCall(VecDuplicate(yv, &(*dlam)[i]));
    PetscCall(VecCopy(yv, (*dlam)[i]));
    PetscCall(MatMultTranspose(kac.sys.K, yv, t));
    PetscCall(VecDuplicate(t, &(*du)[i]));
    PetscCall(fom.ApplyInverse(t, (*du)[i]));
    PetscCall(VecAYPX((*du)[i], -1.0, du0));
  }
  PetscCall(fom.SetMu(mu0));
  cmap.SetGeometry(&fom.map, mu0);
  PetscCall(KSPDestroy(&ksp));
  PetscCall(MatDestroy(&S));
  for (Vec *v : {&uloc, &t, &rup, &rum, &bu, &du0, &ctx.x, &ctx.y, &rcp, &rcm, &rhs, &yv, &ctx.mask, &ctx.m}) PetscCall(VecDestroy(v));
  PetscCall(sys.Destroy());
  PetscCall(PetscTime(&t1));
  info->seconds = t1 - t0;
  PetscCall(PetscLogEventEnd(SENS_Solve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

} // namespace rbc
