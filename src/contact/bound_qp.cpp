// src/contact/bound_qp.cpp: dense bound-constrained QP solvers: the active-set method and the TAO
// (BQPIP by default) driver with equilibration and active-set polish.
#include "rbcontact/bound_qp.hpp"
#include "rbcontact/tao_recipe.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>

namespace rbc {

PetscReal BoundQPKKT(PetscInt n, const PetscReal *H, const PetscReal *c, const PetscReal *x)
{
  PetscReal worst = 0, scale = 0;
  for (PetscInt i = 0; i < n; ++i) scale = std::max(scale, std::abs(c[i]));
  for (PetscInt i = 0; i < n; ++i) {
    PetscReal g = -c[i];
    for (PetscInt j = 0; j < n; ++j) g += H[i + j * n] * x[j];
    // optimality: x >= 0, g >= 0, x_i g_i = 0  <=>  min(x_i * h_ii, g_i) = 0 (scaled by the diagonal)
    const PetscReal hx = x[i] * H[i + i * n];
    worst              = std::max(worst, std::abs(std::min(hx, g)));
    if (x[i] < 0) worst = std::max(worst, -hx);
  }
  return scale > 0 ? worst / scale : worst;
}

// Solves H_PP z = c_P by Cholesky; returns false if H_PP is not numerically SPD.
static bool SolveSubsystem(PetscInt n, const PetscReal *H, const PetscReal *c, const std::vector<PetscInt> &P, std::vector<PetscReal> *z)
{
  const PetscBLASInt     m = (PetscBLASInt)P.size(), one = 1;
  std::vector<PetscReal> L(m * m);
  z->assign(m, 0.0);
  for (PetscBLASInt j = 0; j < m; ++j) {
    (*z)[j] = c[P[j]];
    for (PetscBLASInt i = 0; i < m; ++i) L[i + j * m] = H[P[i] + P[j] * n];
  }
  PetscBLASInt info = 0;
  if (!m) return true;
  LAPACKpotrf_("L", &m, L.data(), &m, &info);
  if (info) return false;
  LAPACKpotrs_("L", &m, &one, L.data(), &m, z->data(), &m, &info);
  return info == 0;
}

PetscErrorCode BoundQPActiveSet(PetscInt n, const PetscReal *H, const PetscReal *c, PetscReal *x, PetscReal tol, PetscInt maxit, BoundQPInfo *info)
{
  std::vector<char>      inP(n, 0);
  std::vector<PetscReal> z, w(n);
  PetscReal              cmax = 0;

  PetscFunctionBeginUser;
  info->iterations = 0;
  info->converged  = PETSC_FALSE;
  for (PetscInt i = 0; i < n; ++i) {
    cmax = std::max(cmax, std::abs(c[i]));
    if (x[i] > 0) inP[i] = 1;
    else x[i] = 0;
  }
  if (cmax == 0) { // x = 0 is optimal
    for (PetscInt i = 0; i < n; ++i) x[i] = 0;
    info->converged = PETSC_TRUE;
    PetscFunctionReturn(0);
  }
  bool needInner = std::any_of(inP.begin(), inP.end(), [](char v) { return v != 0; });
  PetscInt lastAdded = -1;
  while (info->iterations < maxit) {
    if (!needInner) {
      // Optimality: w = c - Hx <= tol on the active (zero) set
      PetscInt  j    = -1;
      PetscReal best = tol * cmax;
      for (PetscInt i = 0; i < n; ++i) {
        PetscReal wi = c[i];
        for (PetscInt k = 0; k < n; ++k) wi -= H[i + k * n] * x[k];
        w[i] = wi;
        if (!inP[i] && wi > best && i != lastAdded) { best = wi; j = i; }
      }
      if (j < 0) { info->converged = PETSC_TRUE; break; }
      inP[j]    = 1;
      lastAdded = j;
    }
    needInner = false;
    ++info->iterations;
    // Inner loop: move towards the unconstrained minimizer on P while staying feasible
    for (PetscInt inner = 0; inner < 4 * n + 10; ++inner) {
      std::vector<PetscInt> P;
      for (PetscInt i = 0; i < n; ++i) if (inP[i]) P.push_back(i);
      if (!SolveSubsystem(n, H, c, P, &z)) {
        // singular support: drop the last added index and stop
        if (lastAdded >= 0) inP[lastAdded] = 0;
        info->kkt = BoundQPKKT(n, H, c, x);
        PetscFunctionReturn(0);
      }
      bool feasible = true;
      for (size_t k = 0; k < P.size(); ++k) if (z[k] <= 0) feasible = false;
      if (feasible) {
        for (size_t k = 0; k < P.size(); ++k) x[P[k]] = z[k];
        break;
      }
      PetscReal alpha = 1;
      for (size_t k = 0; k < P.size(); ++k)
        if (z[k] <= 0) alpha = std::min(alpha, x[P[k]] / (x[P[k]] - z[k]));
      for (size_t k = 0; k < P.size(); ++k) {
        const PetscReal old = x[P[k]];
        x[P[k]] += alpha * (z[k] - old);
        // the blocking indices land on zero (up to rounding): leave the support
        if (x[P[k]] <= 1e-14 * (std::abs(old) + std::abs(z[k]))) { x[P[k]] = 0; inP[P[k]] = 0; }
      }
    }
  }
  info->kkt = BoundQPKKT(n, H, c, x);
  PetscFunctionReturn(0);
}

// --- TAO driver -------------------------------------------------------------------------------

DualQPSolver::~DualQPSolver() = default;

PetscErrorCode DualQPSolver::Setup(const std::string &prefix, MPI_Comm comm)
{
  char type[64] = "activeset";

  PetscFunctionBeginUser;
  prefix_ = prefix + "qp_"; // the QP's own prefix: its TAO (and TAO's KSP/PC) never read the elastic solver's options
  // (read with PetscOptionsGet* before 2026-12-02: missing from -help)
  PetscOptionsBegin(comm, prefix_.c_str(), "Contact QP (the dense dual problem)", "DualQPSolver");
  PetscCall(PetscOptionsBool("-polish", "After TAO, the active-set method from its support (exact complementarity)", "docs/contact.md", polish_, &polish_, NULL));
  PetscCall(PetscOptionsString("-tao_type", "activeset (the active-set method alone) or a TAO bound-constrained solver (bqpip, blmvm, tron, ...)", "docs/contact.md", type, type, sizeof type, NULL));
  PetscOptionsEnd();
  // "-<prefix>tao_type activeset" skips TAO: the active-set method alone
  useTao_ = strcmp(type, "activeset") ? PETSC_TRUE : PETSC_FALSE;
  type_   = type;
  PetscFunctionReturn(0);
}

PetscErrorCode DualQPSolver::Solve(PetscInt R, const std::vector<PetscReal> &S, const std::vector<PetscReal> &b, std::vector<PetscReal> *lambda, DualQPInfo *info, const std::vector<PetscReal> *warm)
{
  std::vector<PetscReal> d(R), Ss(S.size()), bs(R), y(R, 0.0);
  PetscReal              bnorm = 0;

  PetscFunctionBeginUser;
  *info = DualQPInfo();
  lambda->assign(R, 0.0);
  if (!R) PetscFunctionReturn(0);
  // Equilibrate: y = D^{-1} lambda, D = diag(S)^{-1/2}; S' = D S D, b' = D b / ||D b||.
  for (PetscInt i = 0; i < R; ++i) {
    PetscCheck(S[i + i * R] > 0, PETSC_COMM_SELF, PETSC_ERR_NOT_CONVERGED, "Dual QP: diagonal entry %" PetscInt_FMT " of S = K A^-1 K^T is %g (a multiplier with no constraint row?)", i, (double)S[i + i * R]);
    d[i] = 1.0 / std::sqrt(S[i + i * R]);
  }
  for (PetscInt j = 0; j < R; ++j)
    for (PetscInt i = 0; i < R; ++i) Ss[i + j * R] = d[i] * S[i + j * R] * d[j];
  for (PetscInt i = 0; i < R; ++i) { bs[i] = d[i] * b[i]; bnorm += bs[i] * bs[i]; }
  bnorm = std::sqrt(bnorm);
  bool anyPositive = false;
  for (PetscInt i = 0; i < R; ++i) if (bs[i] > 0) anyPositive = true;
  if (!anyPositive) { // lambda = 0 is optimal: gradient -b >= 0 at 0
    info->kkt = 0;
    PetscFunctionReturn(0);
  }
  for (PetscInt i = 0; i < R; ++i) bs[i] /= bnorm;
  if (!useTao_ && warm && (PetscInt)warm->size() == R) // y = D^{-1} lambda / ||D b||
    for (PetscInt i = 0; i < R; ++i) y[i] = (*warm)[i] > 0 ? (*warm)[i] / (d[i] * bnorm) : 0.0;

  if (useTao_) {
    Tao   tao;
    Mat   H;
    Vec   x, c, lo, hi;
    TaoQuadratic ctx;
    PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, R, R, NULL, &H));
    PetscScalar *h;
    PetscCall(MatDenseGetArrayWrite(H, &h));
    for (PetscInt k = 0; k < R * R; ++k) h[k] = Ss[k];
    PetscCall(MatDenseRestoreArrayWrite(H, &h));
    PetscCall(MatAssemblyBegin(H, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(H, MAT_FINAL_ASSEMBLY));
    PetscCall(MatSetOption(H, MAT_SPD, PETSC_TRUE));
    PetscCall(VecCreateSeq(PETSC_COMM_SELF, R, &x));
    PetscCall(VecDuplicate(x, &c));
    PetscCall(VecDuplicate(x, &lo));
    PetscCall(VecDuplicate(x, &hi));
    for (PetscInt i = 0; i < R; ++i) PetscCall(VecSetValue(c, i, bs[i], INSERT_VALUES));
    PetscCall(VecAssemblyBegin(c));
    PetscCall(VecAssemblyEnd(c));
    PetscCall(VecSet(x, 0.0));
    PetscCall(VecSet(lo, 0.0));
    PetscCall(VecSet(hi, PETSC_INFINITY));
    ctx.H = H;
    ctx.c = c;
    PetscCall(TaoCreate(PETSC_COMM_SELF, &tao));
    PetscCall(TaoSetOptionsPrefix(tao, prefix_.c_str()));
    PetscCall(TaoSetSolution(tao, x));
    PetscCall(TaoSetQuadratic(tao, &ctx));
    PetscCall(TaoSetVariableBounds(tao, lo, hi));
    PetscCall(TaoBQPIPRecipe(tao)); // the polish makes the answer exact
    PetscCall(TaoSetFromOptions(tao));
    PetscCall(TaoSolve(tao));
    PetscCall(TaoGetConvergedReason(tao, &info->taoReason));
    PetscCall(TaoGetIterationNumber(tao, &info->taoIterations));
    const PetscScalar *xa;
    PetscCall(VecGetArrayRead(x, &xa));
    for (PetscInt i = 0; i < R; ++i) y[i] = std::max(0.0, (double)PetscRealPart(xa[i]));
    PetscCall(VecRestoreArrayRead(x, &xa));
    PetscCall(TaoDestroy(&tao));
    PetscCall(MatDestroy(&H));
    PetscCall(VecDestroy(&x));
    PetscCall(VecDestroy(&c));
    PetscCall(VecDestroy(&lo));
    PetscCall(VecDestroy(&hi));
    // Keep the support only (tiny interior-point values are zeros)
    PetscReal ymax = 0;
    for (PetscInt i = 0; i < R; ++i) ymax = std::max(ymax, y[i]);
    for (PetscInt i = 0; i < R; ++i) if (y[i] < 1e-6 * ymax) y[i] = polish_ ? 0.0 : y[i];
  }
  if (polish_ || !useTao_) {
    BoundQPInfo bi;
    PetscCall(BoundQPActiveSet(R, Ss.data(), bs.data(), y.data(), 1e-14, 10 * R + 100, &bi));
    info->polishIterations = bi.iterations;
  }
  info->kkt = BoundQPKKT(R, Ss.data(), bs.data(), y.data());
  for (PetscInt i = 0; i < R; ++i) (*lambda)[i] = d[i] * y[i] * bnorm;
  PetscFunctionReturn(0);
}

} // namespace rbc
