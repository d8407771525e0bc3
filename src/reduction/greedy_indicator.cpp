// src/reduction/greedy_indicator.cpp: GreedyIndicator (the residual and penetration of a reduced solution
// in the full-order model) and GreedyPick (rbcontact/greedy_indicator.hpp).
#include "rbcontact/greedy_indicator.hpp"
#include <algorithm>
#include <cmath>

namespace rbc {

GreedyIndicator::~GreedyIndicator()
{
  (void)KSPDestroy(&ksp_);
  (void)MatDestroy(&X_);
  for (Vec *v : {&r_, &z_, &t_, &uloc_, &u_, &lam_, &Ku_}) (void)VecDestroy(v);
}

PetscErrorCode GreedyIndicator::Setup(ElasticFOM &fom)
{
  PC  pc;
  Vec fref = nullptr;

  PetscFunctionBeginUser;
  PetscCheck(fom.useAffine, PetscObjectComm((PetscObject)fom.dm), PETSC_ERR_SUP, "greedy training: the scene has no affine decomposition");
  PetscCall(KSPDestroy(&ksp_));
  PetscCall(MatDestroy(&X_));
  PetscCall(fom.affine.Assemble(ParamValues(fom.scene), &X_, &fref)); // the POD's energy inner product
  PetscCall(VecDestroy(&fref));
  PetscCall(KSPCreate(PetscObjectComm((PetscObject)fom.dm), &ksp_));
  PetscCall(KSPSetOptionsPrefix(ksp_, "greedy_x_"));
  PetscCall(KSPSetType(ksp_, KSPPREONLY));
  PetscCall(KSPGetPC(ksp_, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  { // one rank, 2D: PETSc's Cholesky in nested dissection order (half_disks, 11,514 dofs: 0.7 ms a solve against
    // 3.4 ms with MUMPS, whose single right-hand-side solve dominated the indicator); several ranks, or 3D: MUMPS
    // (PETSc's symbolic and numeric Cholesky of sphere_block3d with P2, 55k dofs, took 194 s against MUMPS's 6 s)
    PetscMPIInt size;
    PetscInt    dim;
    PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)fom.dm), &size));
    PetscCall(DMGetDimension(fom.dm, &dim));
    if (size == 1 && dim == 2) PetscCall(PCFactorSetMatOrderingType(pc, MATORDERINGND));
    else PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  }
  PetscCall(KSPSetOperators(ksp_, X_, X_));
  PetscCall(KSPSetFromOptions(ksp_));
  PetscCall(KSPSetUp(ksp_));
  if (!r_) {
    PetscCall(DMCreateGlobalVector(fom.dm, &r_));
    PetscCall(VecDuplicate(r_, &z_));
    PetscCall(VecDuplicate(r_, &t_));
    PetscCall(VecDuplicate(r_, &u_));
    PetscCall(DMCreateLocalVector(fom.dm, &uloc_));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode GreedyIndicator::Evaluate(ElasticFOM &fom, ContactMap &cmap, const CanonicalOrder &order, const std::vector<PetscReal> &mu, Vec u, const std::vector<PetscReal> &lamCanon, GreedyEstimate *est)
{
  MPI_Comm comm = PetscObjectComm((PetscObject)fom.dm);

  PetscFunctionBeginUser;
  PetscCheck(ksp_, comm, PETSC_ERR_ORDER, "GreedyIndicator: call Setup first");
  PetscCheck((PetscInt)lamCanon.size() == order.NumMultipliers(), comm, PETSC_ERR_ARG_SIZ, "GreedyIndicator: %zu multipliers for %" PetscInt_FMT, lamCanon.size(), order.NumMultipliers());
  PetscCall(fom.SetMu(mu)); // the Dirichlet values at mu (no assembly)
  PetscCall(fom.affine.Residual(mu, u, t_, r_)); // A(mu) u - f(mu) through the affine terms
  // + K(u)' lam: the contact constraint at u in the geometry of mu
  cmap.SetGeometry(&fom.map, mu);
  PetscCall(fom.elas.GlobalToLocalWithBC(u, uloc_));
  PetscCall(cmap.Assemble(fom.elas, uloc_, &sys_));
  PetscInt lo, hi;
  if (!lam_) { // the multiplier layout is the contact map's, the same at every assembly
    PetscCall(VecDuplicate(sys_.g, &lam_));
    PetscCall(VecDuplicate(sys_.g, &Ku_));
  }
  Vec lam = lam_, Ku = Ku_;
  PetscCall(VecGetOwnershipRange(lam, &lo, &hi));
  {
    PetscScalar *a;
    PetscCall(VecGetArray(lam, &a));
    for (PetscInt i = lo; i < hi; ++i) a[i - lo] = lamCanon[order.CanonicalMultiplier(i)];
    PetscCall(VecRestoreArray(lam, &a));
  }
  PetscCall(MatMultTransposeAdd(sys_.K, lam, r_, r_));
  // energy dual norm of the residual, energy norm of u
  PetscScalar rz, uXu;
  PetscCall(KSPSolve(ksp_, r_, z_));
  {
    KSPConvergedReason reason;
    PetscCall(KSPGetConvergedReason(ksp_, &reason));
    PetscCheck(reason >= 0, comm, PETSC_ERR_NOT_CONVERGED, "greedy training: the solve with the energy matrix failed (%s)", KSPConvergedReasons[reason]);
  }
  PetscCall(VecDot(r_, z_, &rz));
  PetscCall(MatMult(X_, u, t_));
  PetscCall(VecDot(u, t_, &uXu));
  const PetscReal nu = std::sqrt(std::max<PetscReal>(PetscRealPart(uXu), 0));
  est->residual      = nu > 0 ? std::sqrt(std::max<PetscReal>(PetscRealPart(rz), 0)) / nu : PETSC_MAX_REAL;
  // penetration: [K u - g]_+ in the slave-mass dual norm, relative to K u
  PetscCall(MatMult(sys_.K, u, Ku));
  {
    const PetscScalar *k, *g, *w;
    PetscReal          loc[2] = {0, 0}, glob[2];
    PetscCall(VecGetArrayRead(Ku, &k));
    PetscCall(VecGetArrayRead(sys_.g, &g));
    PetscCall(VecGetArrayRead(sys_.weight, &w));
    for (PetscInt i = 0; i < hi - lo; ++i) {
      const PetscReal wi = PetscRealPart(w[i]);
      if (wi <= 0) continue;
      const PetscReal p = std::max<PetscReal>(0, PetscRealPart(k[i] - g[i]));
      loc[0] += p * p / wi;
      loc[1] += PetscRealPart(k[i]) * PetscRealPart(k[i]) / wi;
    }
    PetscCall(VecRestoreArrayRead(Ku, &k));
    PetscCall(VecRestoreArrayRead(sys_.g, &g));
    PetscCall(VecRestoreArrayRead(sys_.weight, &w));
    PetscCallMPI(MPI_Allreduce(loc, glob, 2, MPIU_REAL, MPIU_SUM, comm));
    est->penetration = glob[1] > 0 ? std::sqrt(glob[0] / glob[1]) : (glob[0] > 0 ? PETSC_MAX_REAL : 0);
  }
  est->value = criterion == GreedyCriterion::Residual ? est->residual : criterion == GreedyCriterion::Penetration ? est->penetration : std::max(est->residual, est->penetration);
  PetscFunctionReturn(0);
}

PetscErrorCode GreedyIndicator::EvaluateReduced(ElasticFOM &fom, ContactMap &cmap, const CanonicalOrder &order, ReducedModel &rm, ContactPatch &full, BV V, const DenseMatrix &W, const std::vector<PetscReal> &mu, GreedyEstimate *est)
{
  ReducedSolution sol;

  PetscFunctionBeginUser;
  full.SetGeometry(&fom.map, mu);
  PetscCall(rm.Solve(mu, &sol));
  est->converged  = sol.converged ? PETSC_TRUE : PETSC_FALSE;
  est->iterations = sol.iterations;
  if (!sol.converged) { // a parameter the model cannot solve is the first to learn
    est->residual = est->penetration = est->value = PETSC_MAX_REAL;
    PetscFunctionReturn(0);
  }
  PetscInt nv;
  PetscCall(BVGetActiveColumns(V, NULL, &nv));
  PetscCheck(nv == (PetscInt)sol.v.size(), PetscObjectComm((PetscObject)fom.dm), PETSC_ERR_ARG_SIZ, "GreedyIndicator: the basis has %" PetscInt_FMT " columns, the reduced solution %zu", nv, sol.v.size());
  std::vector<PetscScalar> q(sol.v.begin(), sol.v.end());
  PetscCall(BVMultVec(V, 1.0, 0.0, u_, q.data()));
  std::vector<PetscReal> lam(W.rows, 0.0);
  for (PetscInt k = 0; k < (PetscInt)sol.lambda.size(); ++k)
    for (PetscInt i = 0; i < W.rows; ++i) lam[i] += W(i, k) * sol.lambda[k];
  PetscCall(Evaluate(fom, cmap, order, mu, u_, lam, est));
  PetscFunctionReturn(0);
}

std::vector<PetscInt> GreedyPick(const std::vector<PetscReal> &eta, const std::vector<std::vector<PetscReal>> &pool, const std::vector<ParamSpec> &params, PetscInt n, PetscReal minDist)
{
  std::vector<PetscInt> order;
  for (PetscInt i = 0; i < (PetscInt)eta.size(); ++i)
    if (eta[i] >= 0) order.push_back(i);
  // decreasing indicator; ties by index (the same picks on every rank count)
  std::stable_sort(order.begin(), order.end(), [&](PetscInt a, PetscInt b) { return eta[a] > eta[b]; });
  std::vector<PetscInt> picks;
  auto                  dist = [&](PetscInt a, PetscInt b) {
    PetscReal s = 0;
    for (size_t j = 0; j < params.size(); ++j) {
      const PetscReal w = params[j].max - params[j].min, d = w > 0 ? (pool[a][j] - pool[b][j]) / w : 0;
      s += d * d;
    }
    return std::sqrt(s);
  };
  for (PetscInt i : order) {
    if ((PetscInt)picks.size() >= n) break;
    bool far = true;
    for (PetscInt p : picks) far = far && dist(i, p) >= minDist;
    if (far) picks.push_back(i);
  }
  return picks;
}

} // namespace rbc
