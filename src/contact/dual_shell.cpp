// src/contact/dual_shell.cpp: the matrix-free dual QP of a Kacanov iterate: S = K A^{-1} K^T as a
// MATSHELL (one back-solve per product), solved by a primal-dual active-set method with CG on the
// free set (see rbcontact/dual_shell.hpp).
#include "rbcontact/dual_shell.hpp"
#include "rbcontact/tao_recipe.hpp"
#include "rbcontact/options_files.hpp"
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_map>

namespace rbc {

static PetscLogEvent DS_Solve = 0, DS_Diag = 0;

struct DualShellCtx {
  Mat         K   = nullptr;
  ElasticFOM *fom = nullptr;
  Vec         w1 = nullptr, w2 = nullptr; // displacement layout
  Vec         xm = nullptr, mask = nullptr, d = nullptr; // multiplier layout; mask 1 on F, 0 off F
  PetscInt    products = 0;
};

// y = K A^{-1} K^T x
static PetscErrorCode ApplyS(DualShellCtx *c, Vec x, Vec y)
{
  PetscFunctionBeginUser;
  PetscCall(MatMultTranspose(c->K, x, c->w1));
  PetscCall(c->fom->ApplyInverse(c->w1, c->w2));
  PetscCall(MatMult(c->K, c->w2, y));
  ++c->products;
  PetscFunctionReturn(0);
}

// y = P S P x + (I - P) x, P = diag(mask): S_FF on F, identity off F
static PetscErrorCode MaskedMult(Mat S, Vec x, Vec y)
{
  DualShellCtx      *c;
  const PetscScalar *m, *xa;
  PetscScalar       *ya;
  PetscInt           n;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(S, &c));
  PetscCall(VecPointwiseMult(c->xm, c->mask, x));
  PetscCall(ApplyS(c, c->xm, y));
  PetscCall(VecGetLocalSize(y, &n));
  PetscCall(VecGetArrayRead(c->mask, &m));
  PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArray(y, &ya));
  for (PetscInt i = 0; i < n; ++i) ya[i] = PetscRealPart(m[i]) != 0 ? ya[i] : xa[i];
  PetscCall(VecRestoreArray(y, &ya));
  PetscCall(VecRestoreArrayRead(x, &xa));
  PetscCall(VecRestoreArrayRead(c->mask, &m));
  PetscFunctionReturn(0);
}

// The Jacobi diagonal of the masked operator: d on F (an estimate, -fom_dual_diag), 1 off F
static PetscErrorCode MaskedDiagonal(Mat S, Vec diag)
{
  DualShellCtx      *c;
  const PetscScalar *m, *d;
  PetscScalar       *o;
  PetscInt           n;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(S, &c));
  PetscCall(VecGetLocalSize(diag, &n));
  PetscCall(PetscInfo(S, "Jacobi diagonal of the masked dual operator\n"));
  PetscCall(VecGetArrayRead(c->mask, &m));
  PetscCall(VecGetArrayRead(c->d, &d));
  PetscCall(VecGetArray(diag, &o));
  for (PetscInt i = 0; i < n; ++i) o[i] = PetscRealPart(m[i]) != 0 ? d[i] : 1.0;
  PetscCall(VecRestoreArray(diag, &o));
  PetscCall(VecRestoreArrayRead(c->d, &d));
  PetscCall(VecRestoreArrayRead(c->mask, &m));
  PetscFunctionReturn(0);
}

// --- TAO phase: the Jacobi-equilibrated QP min_{y >= 0} 1/2 y'(D S D)y - bs'y, D = diag(d)^{-1/2},
// bs = D b / |D b|, lambda = |D b| D y; its Hessian a MATSHELL of the full S (no mask) -----------------

struct TaoHessCtx {
  DualShellCtx *c     = nullptr;
  Vec           s     = nullptr; // D
  Vec           bs    = nullptr; // scaled b
  Vec           xs    = nullptr; // work
  Vec           shift = nullptr; // diagonal shift set by TAO (MatDiagonalSet / MatShift)
};

// y = D S D x (one product)
static PetscErrorCode ScaledS(TaoHessCtx *t, Vec x, Vec y)
{
  PetscFunctionBeginUser;
  PetscCall(VecPointwiseMult(t->xs, t->s, x));
  PetscCall(ApplyS(t->c, t->xs, y));
  PetscCall(VecPointwiseMult(y, y, t->s));
  PetscFunctionReturn(0);
}

// (D S D + diag(shift)) x
static PetscErrorCode TaoHessMult(Mat H, Vec x, Vec y)
{
  TaoHessCtx *t;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(H, &t));
  PetscCall(ScaledS(t, x, y));
  PetscCall(VecPointwiseMult(t->xs, t->shift, x));
  PetscCall(VecAXPY(y, 1.0, t->xs));
  PetscFunctionReturn(0);
}

// diag(D S D) estimated by d_i / d_i = 1 (exact with -fom_dual_diag exact), plus the shift
static PetscErrorCode TaoHessDiagonal(Mat H, Vec v)
{
  TaoHessCtx *t;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(H, &t));
  PetscCall(VecCopy(t->shift, v));
  PetscCall(VecShift(v, 1.0));
  PetscFunctionReturn(0);
}

// The shifts are ours, not MATSHELL's: PETSc 3.18's MATSHELL drops its own MatDiagonalSet / MatShift
// shifts in MatAssemblyEnd (MAT_FINAL_ASSEMBLY), and BQPIP assembles right after shifting, so with the
// native shifts its Newton systems lost the barrier term and it diverged (objective rising, residual
// stuck). INSERT_VALUES sets the diagonal to D, i.e. shift = D - 1 (BQPIP restores to exactly 0).
static PetscErrorCode TaoHessDiagonalSet(Mat H, Vec D, InsertMode mode)
{
  TaoHessCtx *t;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(H, &t));
  if (mode == INSERT_VALUES) {
    PetscCall(VecCopy(D, t->shift));
    PetscCall(VecShift(t->shift, -1.0));
  } else PetscCall(VecAXPY(t->shift, 1.0, D));
  PetscFunctionReturn(0);
}

static PetscErrorCode TaoHessShift(Mat H, PetscScalar a)
{
  TaoHessCtx *t;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(H, &t));
  PetscCall(VecShift(t->shift, a));
  PetscFunctionReturn(0);
}

// H(is, is) for TRON and GPCG (-fom_qp_tao_subset_type subvec, the default): a MATSHELL that scatters into
// a full vector, multiplies by H (with its shifts, if any) and gathers.
struct TaoSubCtx {
  Mat H  = nullptr;
  IS  is = nullptr;
  Vec xf = nullptr, yf = nullptr;
};

static PetscErrorCode TaoSubMult(Mat M, Vec x, Vec y)
{
  TaoSubCtx *sc;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(M, &sc));
  PetscCall(VecSet(sc->xf, 0.0));
  PetscCall(VecISCopy(sc->xf, sc->is, SCATTER_FORWARD, x));
  PetscCall(MatMult(sc->H, sc->xf, sc->yf));
  PetscCall(VecISCopy(sc->yf, sc->is, SCATTER_REVERSE, y));
  PetscFunctionReturn(0);
}

static PetscErrorCode TaoSubDiagonal(Mat M, Vec v)
{
  TaoSubCtx *sc;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(M, &sc));
  PetscCall(MatGetDiagonal(sc->H, sc->yf));
  PetscCall(VecISCopy(sc->yf, sc->is, SCATTER_REVERSE, v));
  PetscFunctionReturn(0);
}

static PetscErrorCode TaoSubDestroy(Mat M)
{
  TaoSubCtx *sc;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(M, &sc));
  PetscCall(ISDestroy(&sc->is));
  PetscCall(VecDestroy(&sc->xf));
  PetscCall(VecDestroy(&sc->yf));
  delete sc;
  PetscFunctionReturn(0);
}

static PetscErrorCode TaoHessSubMatrix(Mat H, IS isrow, IS iscol, MatReuse reuse, Mat *B)
{
  PetscBool same;
  PetscInt  nloc, N;

  PetscFunctionBeginUser;
  PetscCall(ISEqual(isrow, iscol, &same));
  PetscCheck(same, PetscObjectComm((PetscObject)H), PETSC_ERR_SUP, "Dual TAO Hessian shell: only square submatrices H(is, is)");
  PetscCall(ISGetLocalSize(isrow, &nloc));
  PetscCall(ISGetSize(isrow, &N));
  if (reuse == MAT_REUSE_MATRIX) {
    TaoSubCtx *sc;
    PetscInt   m, M;
    PetscCall(MatGetLocalSize(*B, &m, NULL));
    PetscCall(MatGetSize(*B, &M, NULL));
    PetscCheck(m == nloc && M == N, PetscObjectComm((PetscObject)H), PETSC_ERR_ARG_SIZ, "Dual TAO Hessian shell: MAT_REUSE_MATRIX with another size");
    PetscCall(MatShellGetContext(*B, &sc));
    PetscCall(PetscObjectReference((PetscObject)isrow));
    PetscCall(ISDestroy(&sc->is));
    sc->is = isrow;
    PetscFunctionReturn(0);
  }
  auto *sc = new TaoSubCtx;
  sc->H    = H;
  sc->is   = isrow;
  PetscCall(PetscObjectReference((PetscObject)isrow));
  PetscCall(MatCreateVecs(H, &sc->xf, &sc->yf));
  PetscCall(MatCreateShell(PetscObjectComm((PetscObject)H), nloc, nloc, N, N, sc, B));
  PetscCall(MatShellSetOperation(*B, MATOP_MULT, (void (*)(void))TaoSubMult));
  PetscCall(MatShellSetOperation(*B, MATOP_GET_DIAGONAL, (void (*)(void))TaoSubDiagonal));
  PetscCall(MatShellSetOperation(*B, MATOP_DESTROY, (void (*)(void))TaoSubDestroy));
  PetscCall(MatSetOption(*B, MAT_SPD, PETSC_TRUE));
  PetscFunctionReturn(0);
}

static PetscErrorCode TaoObjGrad(Tao, Vec y, PetscReal *f, Vec g, void *ctx)
{
  TaoHessCtx *t = static_cast<TaoHessCtx *>(ctx);
  PetscScalar yHy, by;

  PetscFunctionBeginUser;
  PetscCall(ScaledS(t, y, g));
  PetscCall(VecDot(y, g, &yHy));
  PetscCall(VecDot(y, t->bs, &by));
  *f = 0.5 * PetscRealPart(yHy) - PetscRealPart(by);
  PetscCall(VecAXPY(g, -1.0, t->bs));
  PetscFunctionReturn(0);
}

static PetscErrorCode TaoHessNoop(Tao, Vec, Mat, Mat, void *)
{
  PetscFunctionBeginUser;
  PetscFunctionReturn(0);
}

// The inner KSP of the TAO (if its type has one): prefix fom_dual_tao_ (not fom_, the prefix of the
// FOM's own Cholesky KSP), jacobi (the Hessian is a shell: no factorization), cg for BQPIP (the recipe's
// preonly + cholesky needs an assembled matrix). Again after TaoSetFromOptions if -fom_qp_tao_type made a new KSP.
static PetscErrorCode ConfigureTaoKSP(Tao tao, const std::string &kspPrefix)
{
  KSP         ksp;
  PC          pc;
  const char *pre;
  PetscBool   bqpip;

  PetscFunctionBeginUser;
  PetscCall(TaoGetKSP(tao, &ksp));
  if (!ksp) PetscFunctionReturn(0);
  PetscCall(KSPGetOptionsPrefix(ksp, &pre));
  if (pre && kspPrefix == pre) PetscFunctionReturn(0);
  PetscCall(KSPSetOptionsPrefix(ksp, kspPrefix.c_str()));
  PetscCall(PetscObjectTypeCompare((PetscObject)tao, TAOBQPIP, &bqpip));
  if (bqpip) PetscCall(KSPSetType(ksp, KSPCG));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCJACOBI));
  PetscCall(KSPSetFromOptions(ksp));
  PetscFunctionReturn(0);
}

static PetscErrorCode DestroyCtx(DualShellCtx **c)
{
  PetscFunctionBeginUser;
  if (*c) {
    PetscCall(VecDestroy(&(*c)->w1));
    PetscCall(VecDestroy(&(*c)->w2));
    PetscCall(VecDestroy(&(*c)->xm));
    PetscCall(VecDestroy(&(*c)->mask));
    PetscCall(VecDestroy(&(*c)->d));
    delete *c;
    *c = nullptr;
  }
  PetscFunctionReturn(0);
}

DualShellSolver::~DualShellSolver()
{
  (void)KSPDestroy(&ksp_);
  (void)MatDestroy(&S_);
  (void)DestroyCtx(&ctx_);
}

PetscErrorCode DualShellSolver::SetFromOptions(MPI_Comm comm, const std::string &prefix)
{
  char      dtype[16] = "lumped";
  PetscBool set;

  PetscFunctionBeginUser;
  if (!DS_Solve) {
    PetscCall(PetscLogEventRegister("RBCDualPDAS", KSP_CLASSID, &DS_Solve));
    PetscCall(PetscLogEventRegister("RBCDualDiag", KSP_CLASSID, &DS_Diag));
  }
  prefix_ = prefix + "dual_";
  // given without a value, PETSc kept the default without a word; the CG's tolerances are checked before PETSc reads them
  PetscCall(CheckValuesGiven(comm, prefix_, {"pdas_max_it", "pdas_rtol_loose", "pdas_tol", "diag", "shell_tao_support"}));
  PetscCall(CheckKSPTolerances(comm, prefix_));
  PetscOptionsBegin(comm, prefix_.c_str(), "Matrix-free dual QP (primal-dual active set + CG)", "DualShellSolver");
  PetscCall(PetscOptionsInt("-pdas_max_it", "Maximum active-set steps", NULL, maxIt, &maxIt, NULL));
  PetscCall(PetscOptionsReal("-pdas_rtol_loose", "CG rtol while the free set changes (then -ksp_rtol)", NULL, looseRtol, &looseRtol, NULL));
  PetscCall(PetscOptionsReal("-pdas_tol", "Add a multiplier when its scaled gradient is below -tol |b|", NULL, setTol, &setTol, NULL));
  PetscCall(PetscOptionsBool("-pdas_monitor", "Print each active-set step", NULL, monitor, &monitor, NULL));
  PetscCall(PetscOptionsString("-diag", "Jacobi diagonal: lumped (diag(K diag(A)^-1 K^T)) or exact (R products)", NULL, dtype, dtype, sizeof dtype, &set));
  PetscCall(PetscOptionsBool("-shell_tao", "TAO (-fom_qp_tao_type, default bqpip) on the shell first, its support starts the active-set method", NULL, useTao, &useTao, NULL));
  PetscCall(PetscOptionsBool("-shell_tao_warm", "Run the TAO phase on warm starts too (default: only when there is no previous support)", NULL, taoWarm, &taoWarm, NULL));
  PetscCall(PetscOptionsReal("-shell_tao_support", "TAO entries above this times their max start the free set", NULL, taoSupport, &taoSupport, NULL));
  PetscOptionsEnd();
  taoPrefix_ = std::string(prefix) + "qp_"; // the dual QP's TAO prefix, as in dense mode (bound_qp.cpp)
  {
    char tt[64] = "";
    PetscCall(PetscOptionsGetString(NULL, taoPrefix_.c_str(), "-tao_type", tt, sizeof tt, NULL));
    if (!strcmp(tt, "activeset")) useTao = PETSC_FALSE; // as in dense mode: the active-set method alone
  }
  diag = dtype;
  PetscCheck(diag == "lumped" || diag == "exact", comm, PETSC_ERR_ARG_OUTOFRANGE, "-%sdiag %s: use lumped or exact", prefix_.c_str(), dtype);
  PetscCheck(maxIt >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%spdas_max_it %" PetscInt_FMT " must be >= 1", prefix_.c_str(), maxIt);
  // (a NaN or negative value was taken without a word until 2026-12-02: NaN never adds a multiplier, a negative
  // loose tolerance made every solve exact)
  PetscCheck(looseRtol > 0 && looseRtol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%spdas_rtol_loose %g must be in (0, 1)", prefix_.c_str(), (double)looseRtol);
  PetscCheck(setTol >= 0 && setTol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%spdas_tol %g must be in [0, 1)", prefix_.c_str(), (double)setTol);
  PetscCheck(taoSupport >= 0 && taoSupport < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%sshell_tao_support %g must be in [0, 1) (a fraction of the largest TAO multiplier)", prefix_.c_str(), (double)taoSupport);
  PetscCall(KSPDestroy(&ksp_));
  PetscCall(KSPCreate(comm, &ksp_));
  PetscCall(KSPSetOptionsPrefix(ksp_, prefix_.c_str()));
  PetscCall(KSPSetType(ksp_, KSPCG));
  {
    PC pc;
    PetscCall(KSPGetPC(ksp_, &pc));
    PetscCall(PCSetType(pc, PCJACOBI));
  }
  // the true (unpreconditioned) residual relative to |b_F|; the floor is set per solve from |b|
  PetscCall(KSPSetNormType(ksp_, KSP_NORM_UNPRECONDITIONED));
  PetscCall(KSPSetTolerances(ksp_, 1e-14, PETSC_DEFAULT, PETSC_DEFAULT, 10000));
  PetscCall(KSPSetInitialGuessNonzero(ksp_, PETSC_TRUE));
  PetscCall(KSPSetFromOptions(ksp_));
  {
    PetscReal dt;
    PetscInt  mi;
    PetscCall(KSPGetTolerances(ksp_, &rtol_, &atol_, &dt, &mi));
    PetscCall(PetscOptionsHasName(NULL, prefix_.c_str(), "-ksp_atol", &set));
    if (!set) atol_ = 0;
  }
  PetscFunctionReturn(0);
}

PetscErrorCode DualShellSolver::Create(ElasticFOM &fom, Mat K)
{
  MPI_Comm comm = PetscObjectComm((PetscObject)K);
  PetscInt m, M;

  PetscFunctionBeginUser;
  PetscCheck(ksp_, comm, PETSC_ERR_ORDER, "DualShellSolver: call SetFromOptions first");
  ctx_ = new DualShellCtx;
  PetscCall(MatGetLocalSize(K, &m, NULL));
  PetscCall(MatGetSize(K, &M, NULL));
  PetscCall(VecDuplicate(fom.f, &ctx_->w1));
  PetscCall(VecDuplicate(fom.f, &ctx_->w2));
  PetscCall(MatCreateVecs(K, NULL, &ctx_->xm));
  PetscCall(VecDuplicate(ctx_->xm, &ctx_->mask));
  PetscCall(VecDuplicate(ctx_->xm, &ctx_->d));
  PetscCall(MatCreateShell(comm, m, m, M, M, ctx_, &S_));
  PetscCall(MatShellSetOperation(S_, MATOP_MULT, (void (*)(void))MaskedMult));
  PetscCall(MatShellSetOperation(S_, MATOP_GET_DIAGONAL, (void (*)(void))MaskedDiagonal));
  PetscCall(MatSetOption(S_, MAT_SPD, PETSC_TRUE));
  PetscCall(KSPSetOperators(ksp_, S_, S_));
  PetscFunctionReturn(0);
}

// ctx_->d: lumped d_i = sum_j K_ij^2 / A_jj (cheap, exact for a diagonal A), or exact d_i = (K A^{-1} K^T)_ii
PetscErrorCode DualShellSolver::Diagonal(ElasticFOM &fom, Mat K)
{
  PetscInt lo, hi;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(DS_Diag, 0, 0, 0, 0));
  PetscCall(MatGetOwnershipRange(K, &lo, &hi));
  if (diag == "lumped") {
    Vec          s;
    Mat          Ks;
    PetscScalar *d;
    PetscCall(VecDuplicate(fom.f, &s));
    PetscCall(MatGetDiagonal(fom.A, s));
    PetscCall(VecSqrtAbs(s));
    PetscCall(VecReciprocal(s));
    PetscCall(MatDuplicate(K, MAT_COPY_VALUES, &Ks));
    PetscCall(MatDiagonalScale(Ks, NULL, s)); // K_ij / sqrt(A_jj)
    PetscCall(VecGetArray(ctx_->d, &d));
    for (PetscInt r = lo; r < hi; ++r) {
      PetscInt           nc;
      const PetscScalar *v;
      PetscReal          sum = 0;
      PetscCall(MatGetRow(Ks, r, &nc, NULL, &v));
      for (PetscInt k = 0; k < nc; ++k) sum += PetscRealPart(v[k] * PetscConj(v[k]));
      PetscCall(MatRestoreRow(Ks, r, &nc, NULL, &v));
      d[r - lo] = sum;
    }
    PetscCall(VecRestoreArray(ctx_->d, &d));
    PetscCall(MatDestroy(&Ks));
    PetscCall(VecDestroy(&s));
  } else {
    Vec      e, y;
    PetscInt R;
    PetscCall(MatGetSize(K, &R, NULL));
    PetscCall(VecDuplicate(ctx_->d, &e));
    PetscCall(VecDuplicate(ctx_->d, &y));
    for (PetscInt i = 0; i < R; ++i) {
      PetscCall(VecSet(e, 0.0));
      if (i >= lo && i < hi) PetscCall(VecSetValue(e, i, 1.0, INSERT_VALUES));
      PetscCall(VecAssemblyBegin(e));
      PetscCall(VecAssemblyEnd(e));
      PetscCall(ApplyS(ctx_, e, y));
      if (i >= lo && i < hi) {
        PetscScalar v;
        PetscCall(VecGetValues(y, 1, &i, &v));
        PetscCall(VecSetValue(ctx_->d, i, v, INSERT_VALUES));
      }
    }
    PetscCall(VecAssemblyBegin(ctx_->d));
    PetscCall(VecAssemblyEnd(ctx_->d));
    PetscCall(VecDestroy(&e));
    PetscCall(VecDestroy(&y));
  }
  PetscReal dmin;
  PetscInt  imin;
  PetscCall(VecMin(ctx_->d, &imin, &dmin));
  PetscCheck(dmin > 0, PetscObjectComm((PetscObject)K), PETSC_ERR_NOT_CONVERGED, "Dual QP: diagonal entry %" PetscInt_FMT " of S = K A^-1 K^T is %g (a multiplier with no constraint row?)", imin, (double)dmin);
  PetscCall(PetscLogEventEnd(DS_Diag, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

// TAO on the equilibrated QP; lambda (in: a warm start if warm) out: TAO's answer, >= 0, entries at or
// below taoSupport * max set to 0 (all 0 if TAO gave nothing usable: the active-set method starts cold).
PetscErrorCode DualShellSolver::TaoPhase(Vec b, Vec lambda, PetscBool warm, DualShellInfo *info)
{
  MPI_Comm   comm = PetscObjectComm((PetscObject)b);
  TaoHessCtx t;
  Tao        tao;
  Mat        H;
  Vec        y, lo, hi;
  PetscInt   m, M;
  PetscReal  bsnorm;
  const PetscInt p0 = ctx_->products;

  PetscFunctionBeginUser;
  t.c = ctx_;
  PetscCall(VecDuplicate(b, &t.s));
  PetscCall(VecDuplicate(b, &t.bs));
  PetscCall(VecDuplicate(b, &t.xs));
  PetscCall(VecDuplicate(b, &y));
  PetscCall(VecDuplicate(b, &lo));
  PetscCall(VecDuplicate(b, &hi));
  PetscCall(VecCopy(ctx_->d, t.s));
  PetscCall(VecSqrtAbs(t.s));
  PetscCall(VecReciprocal(t.s));
  PetscCall(VecPointwiseMult(t.bs, t.s, b));
  PetscCall(VecNorm(t.bs, NORM_2, &bsnorm));
  PetscCall(VecScale(t.bs, 1.0 / bsnorm));
  // y = D^{-1} lambda / |D b| (a warm start for the TAO types that use one; BQPIP only clamps it)
  if (warm) {
    PetscCall(VecPointwiseDivide(y, lambda, t.s));
    PetscCall(VecScale(y, 1.0 / bsnorm));
  } else PetscCall(VecSet(y, 0.0));
  PetscCall(VecSet(lo, 0.0));
  PetscCall(VecSet(hi, PETSC_INFINITY));
  // A new Hessian shell per solve (cheap): nothing survives from an earlier TaoSolve
  PetscCall(VecGetLocalSize(b, &m));
  PetscCall(VecGetSize(b, &M));
  PetscCall(VecDuplicate(b, &t.shift));
  PetscCall(VecSet(t.shift, 0.0));
  PetscCall(MatCreateShell(comm, m, m, M, M, &t, &H));
  PetscCall(MatShellSetManageScalingShifts(H)); // the shifts below (see TaoHessDiagonalSet)
  PetscCall(MatShellSetOperation(H, MATOP_MULT, (void (*)(void))TaoHessMult));
  PetscCall(MatShellSetOperation(H, MATOP_DIAGONAL_SET, (void (*)(void))TaoHessDiagonalSet));
  PetscCall(MatShellSetOperation(H, MATOP_SHIFT, (void (*)(void))TaoHessShift));
  PetscCall(MatShellSetOperation(H, MATOP_GET_DIAGONAL, (void (*)(void))TaoHessDiagonal));
  PetscCall(MatShellSetOperation(H, MATOP_CREATE_SUBMATRIX, (void (*)(void))TaoHessSubMatrix));
  PetscCall(MatSetOption(H, MAT_SPD, PETSC_TRUE));
  PetscCall(MatAssemblyBegin(H, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(H, MAT_FINAL_ASSEMBLY));

  const std::string kspPrefix = prefix_ + "tao_"; // fom_dual_tao_
  PetscCall(TaoCreate(comm, &tao));
  PetscCall(TaoSetOptionsPrefix(tao, taoPrefix_.c_str()));
  PetscCall(TaoBQPIPRecipe(tao));                // BQPIP, gatol 1e-7, grtol 0 (then the KSP below)
  PetscCall(TaoSetMaximumIterations(tao, 50));   // a start for the active-set method, not the answer
  PetscCall(ConfigureTaoKSP(tao, kspPrefix));
  PetscCall(TaoSetSolution(tao, y));
  PetscCall(TaoSetObjectiveAndGradient(tao, NULL, TaoObjGrad, &t));
  PetscCall(TaoSetHessian(tao, H, H, TaoHessNoop, &t));
  PetscCall(TaoSetVariableBounds(tao, lo, hi));
  PetscCall(TaoSetFromOptions(tao));
  PetscCall(ConfigureTaoKSP(tao, kspPrefix));
  PetscCall(TaoSolve(tao));
  PetscCall(TaoGetConvergedReason(tao, &info->taoReason));
  PetscCall(TaoGetIterationNumber(tao, &info->taoIterations));
  PetscCall(TaoGetLinearSolveIterations(tao, &info->taoKSP));
  info->taoProducts = ctx_->products - p0;
  PetscCall(VecNorm(t.shift, NORM_INFINITY, &info->taoShiftDrift)); // BQPIP restores its shifts
  PetscCall(TaoDestroy(&tao));
  PetscCall(MatDestroy(&H));
  // lambda = |D b| D y, clipped at 0; entries <= taoSupport * max are zeros of an interior point
  PetscReal ymax, ynorm;
  PetscCall(VecNorm(y, NORM_2, &ynorm));
  PetscCall(VecPointwiseMult(lambda, t.s, y));
  PetscCall(VecScale(lambda, bsnorm));
  PetscCall(VecMax(lambda, NULL, &ymax));
  PetscInt n, cnt = 0;
  PetscCall(VecGetLocalSize(lambda, &n));
  {
    PetscScalar *l;
    PetscCall(VecGetArray(lambda, &l));
    for (PetscInt i = 0; i < n; ++i) {
      if (!(PetscIsNormalReal(ynorm) && ymax > 0) || !(PetscRealPart(l[i]) > taoSupport * ymax)) l[i] = 0;
      else ++cnt;
    }
    PetscCall(VecRestoreArray(lambda, &l));
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &cnt, 1, MPIU_INT, MPI_SUM, comm));
  info->taoSupport = cnt;
  if (monitor) PetscCall(PetscPrintf(comm, "      dual TAO phase: %" PetscInt_FMT " its (%s), %" PetscInt_FMT " KSP its, %" PetscInt_FMT " products; support %" PetscInt_FMT " (> %g max); shift left on the Hessian shell %.1e\n", info->taoIterations, TaoConvergedReasons[info->taoReason], info->taoKSP, info->taoProducts, cnt, (double)taoSupport, (double)info->taoShiftDrift));
  PetscCall(VecDestroy(&t.s));
  PetscCall(VecDestroy(&t.bs));
  PetscCall(VecDestroy(&t.xs));
  PetscCall(VecDestroy(&t.shift));
  PetscCall(VecDestroy(&y));
  PetscCall(VecDestroy(&lo));
  PetscCall(VecDestroy(&hi));
  PetscFunctionReturn(0);
}

// Order-independent fingerprint of a distributed index set (cycle detection).
static PetscErrorCode SetFingerprint(MPI_Comm comm, PetscInt lo, const std::vector<char> &F, uint64_t *h, PetscInt *count)
{
  uint64_t loc[2] = {0, 0}, glob[2];

  PetscFunctionBeginUser;
  for (size_t i = 0; i < F.size(); ++i)
    if (F[i]) {
      uint64_t z = (uint64_t)(lo + (PetscInt)i) + 0x9e3779b97f4a7c15ULL; // splitmix64
      z          = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z          = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      loc[0] += z ^ (z >> 31);
      ++loc[1];
    }
  PetscCallMPI(MPI_Allreduce(loc, glob, 2, MPI_UINT64_T, MPI_SUM, comm));
  *h     = glob[0];
  *count = (PetscInt)glob[1];
  PetscFunctionReturn(0);
}

PetscErrorCode DualShellSolver::Solve(ElasticFOM &fom, Mat K, Vec b, Vec lambda, PetscBool warm, DualShellInfo *info)
{
  MPI_Comm           comm = PetscObjectComm((PetscObject)K);
  PetscInt           n, lo, hi;
  PetscReal          bmax;
  Vec                mu, rhs;
  std::vector<char>  F;
  std::vector<PetscReal> sd; // sqrt(d)

  PetscFunctionBeginUser;
  *info = DualShellInfo();
  PetscCall(VecMax(b, NULL, &bmax));
  if (!(bmax > 0)) { // gradient -b >= 0 at 0: lambda = 0 is optimal (exactly)
    PetscCall(VecSet(lambda, 0.0));
    PetscFunctionReturn(0);
  }
  PetscCall(PetscLogEventBegin(DS_Solve, 0, 0, 0, 0));
  if (ctx_) { // another discretization than the last Solve: new work vectors and shell
    PetscInt nu, nuw, nl, nlw;
    PetscCall(VecGetLocalSize(fom.f, &nu));
    PetscCall(VecGetLocalSize(ctx_->w1, &nuw));
    PetscCall(VecGetLocalSize(b, &nl));
    PetscCall(VecGetLocalSize(ctx_->xm, &nlw));
    if (nu != nuw || nl != nlw) {
      PetscCall(MatDestroy(&S_));
      PetscCall(DestroyCtx(&ctx_));
    }
  }
  if (!ctx_) PetscCall(Create(fom, K));
  ctx_->K        = K;
  ctx_->fom      = &fom;
  ctx_->products = 0;
  PetscCall(Diagonal(fom, K));
  PetscCall(VecGetLocalSize(b, &n));
  PetscCall(VecGetOwnershipRange(b, &lo, &hi));
  PetscCall(VecDuplicate(b, &mu));
  PetscCall(VecDuplicate(b, &rhs));
  F.assign(n, 0);
  sd.resize(n);
  PetscReal bscale = 0, bnorm;
  {
    const PetscScalar *d, *ba;
    PetscCall(VecGetArrayRead(ctx_->d, &d));
    PetscCall(VecGetArrayRead(b, &ba));
    for (PetscInt i = 0; i < n; ++i) {
      sd[i]  = std::sqrt(PetscRealPart(d[i]));
      bscale = std::max(bscale, std::abs(PetscRealPart(ba[i])) / sd[i]);
    }
    PetscCall(VecRestoreArrayRead(b, &ba));
    PetscCall(VecRestoreArrayRead(ctx_->d, &d));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bscale, 1, MPIU_REAL, MPIU_MAX, comm));
  }
  PetscCall(VecNorm(b, NORM_2, &bnorm));
  // TAO phase (cold starts; warm ones too with -fom_dual_shell_tao_warm): lambda = its support
  PetscReal lmax = 0;
  if (warm) PetscCall(VecMax(lambda, NULL, &lmax));
  if (useTao && (!(lmax > 0) || taoWarm)) {
    PetscCall(TaoPhase(b, lambda, lmax > 0 ? PETSC_TRUE : PETSC_FALSE, info));
    PetscCall(VecMax(lambda, NULL, &lmax));
    warm = PETSC_TRUE;
  }
  // First free set: warm, the previous Kacanov iterate's (or TAO's) support (lambda > 0), lambda its
  // start for CG; cold (or no previous contact): F = {b_i > 0}, the first semismooth Newton step from 0.
  if (!warm) lmax = 0;
  {
    PetscScalar       *l;
    const PetscScalar *ba;
    PetscCall(VecGetArray(lambda, &l));
    PetscCall(VecGetArrayRead(b, &ba));
    for (PetscInt i = 0; i < n; ++i) {
      if (lmax > 0) F[i] = PetscRealPart(l[i]) > 0;
      else F[i] = PetscRealPart(ba[i]) > 0;
      if (!F[i] || !(lmax > 0)) l[i] = 0;
    }
    PetscCall(VecRestoreArrayRead(b, &ba));
    PetscCall(VecRestoreArray(lambda, &l));
  }
  std::unordered_map<uint64_t, PetscInt> seen; // fingerprint of F -> step
  PetscBool converged = PETSC_FALSE;
  PetscInt  cycleFrom = -1;
  // Inexact phase: CG to -pdas_rtol_loose while F changes; then exact solves (rtol) until F stays.
  PetscBool tight = looseRtol > rtol_ ? PETSC_FALSE : PETSC_TRUE;
  for (PetscInt it = 1; it <= maxIt; ++it) {
    // CG on S_FF lambda_F = b_F, started from the current lambda (0 off F)
    {
      uint64_t h   = 0;
      PetscInt cnt = 0;
      PetscCall(SetFingerprint(comm, lo, F, &h, &cnt));
      auto found = seen.find(h);
      if (found != seen.end()) {
        if (tight) { cycleFrom = found->second; break; }
        tight = PETSC_TRUE; // a repeated set under inexact solves: decide the rest exactly
        seen.clear();
      }
      seen[h]      = it;
      info->nfree  = cnt;
    }
    {
      PetscScalar       *m, *r;
      const PetscScalar *ba;
      PetscCall(VecGetArray(ctx_->mask, &m));
      PetscCall(VecGetArray(rhs, &r));
      PetscCall(VecGetArrayRead(b, &ba));
      for (PetscInt i = 0; i < n; ++i) {
        m[i] = F[i] ? 1.0 : 0.0;
        r[i] = F[i] ? ba[i] : 0.0;
      }
      PetscCall(VecRestoreArrayRead(b, &ba));
      PetscCall(VecRestoreArray(rhs, &r));
      PetscCall(VecRestoreArray(ctx_->mask, &m));
    }
    // F changed: a new state of S_ makes the PC take the new Jacobi diagonal
    PetscCall(MatAssemblyBegin(S_, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(S_, MAT_FINAL_ASSEMBLY));
    const PetscReal rtol = tight ? rtol_ : looseRtol, addTol = tight ? setTol : std::max(setTol, looseRtol);
    PetscCall(KSPSetTolerances(ksp_, rtol, atol_ > 0 ? atol_ : 1e-2 * rtol * bnorm, PETSC_DEFAULT, PETSC_DEFAULT));
    PetscCall(KSPSolve(ksp_, rhs, lambda));
    KSPConvergedReason reason;
    PetscInt           its;
    PetscCall(KSPGetConvergedReason(ksp_, &reason));
    PetscCall(KSPGetIterationNumber(ksp_, &its));
    info->cgIterations += its;
    info->pdasIterations = it;
    // mu = S lambda - b on all multipliers: the residual on F, the sign test off F
    PetscCall(ApplyS(ctx_, lambda, mu));
    PetscCall(VecAXPY(mu, -1.0, b));
    PetscReal rF = 0, bF = 0;
    PetscInt  changes = 0, added = 0;
    {
      PetscScalar       *l;
      const PetscScalar *mua, *ba;
      PetscCall(VecGetArray(lambda, &l));
      PetscCall(VecGetArrayRead(mu, &mua));
      PetscCall(VecGetArrayRead(b, &ba));
      for (PetscInt i = 0; i < n; ++i) {
        const PetscReal li = PetscRealPart(l[i]), mi = PetscRealPart(mua[i]);
        if (F[i]) {
          rF += mi * mi;
          bF += PetscRealPart(ba[i]) * PetscRealPart(ba[i]);
          if (!(li > 0)) { F[i] = 0; ++changes; }
        } else {
          l[i] = 0; // exactly zero off F
          if (mi / sd[i] < -addTol * bscale) { F[i] = 1; ++changes; ++added; }
        }
        if (!F[i]) l[i] = 0;
      }
      PetscCall(VecRestoreArrayRead(b, &ba));
      PetscCall(VecRestoreArrayRead(mu, &mua));
      PetscCall(VecRestoreArray(lambda, &l));
      PetscReal loc[4] = {rF, bF, (PetscReal)changes, (PetscReal)added}, glob[4];
      PetscCallMPI(MPI_Allreduce(loc, glob, 4, MPIU_REAL, MPIU_SUM, comm));
      info->residual = glob[1] > 0 ? std::sqrt(glob[0] / glob[1]) : 0;
      changes        = (PetscInt)glob[2];
      added          = (PetscInt)glob[3];
    }
    if (monitor) PetscCall(PetscPrintf(comm, "      dual step %2" PetscInt_FMT " (%s): free %5" PetscInt_FMT ", CG %4" PetscInt_FMT " its (%s), residual on F %.2e; then %" PetscInt_FMT " added, %" PetscInt_FMT " removed\n", it, tight ? "exact" : "loose", info->nfree, its, KSPConvergedReasons[reason], (double)info->residual, added, changes - added));
    if (reason < 0) {
      PetscCall(VecDestroy(&mu));
      PetscCall(VecDestroy(&rhs));
      SETERRQ(comm, PETSC_ERR_NOT_CONVERGED, "Matrix-free dual QP (-fom_dual_matrix shell): CG on the free set (%" PetscInt_FMT " multipliers, active-set step %" PetscInt_FMT ") failed: %s after %" PetscInt_FMT " iterations, true relative residual %.3e (-%sksp_rtol %g, -%sksp_max_it; or -fom_dual_matrix dense)", info->nfree, it, KSPConvergedReasons[reason], its, (double)info->residual, prefix_.c_str(), (double)rtol_, prefix_.c_str());
    }
    if (!changes) {
      if (tight) { converged = PETSC_TRUE; break; }
      tight = PETSC_TRUE; // confirm the set with an exact solve (from the current lambda)
      seen.clear();
    }
  }
  // Scaled KKT of the QP: min(lambda_i sqrt(d_i), mu_i / sqrt(d_i)) = 0
  {
    const PetscScalar *l, *mua;
    PetscReal          worst = 0;
    PetscCall(VecGetArrayRead(lambda, &l));
    PetscCall(VecGetArrayRead(mu, &mua));
    for (PetscInt i = 0; i < n; ++i) worst = std::max(worst, std::abs(std::min(PetscRealPart(l[i]) * sd[i], PetscRealPart(mua[i]) / sd[i])));
    PetscCall(VecRestoreArrayRead(mu, &mua));
    PetscCall(VecRestoreArrayRead(lambda, &l));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPIU_REAL, MPIU_MAX, comm));
    info->kkt = worst / bscale;
  }
  info->products = ctx_->products;
  PetscCall(VecDestroy(&mu));
  PetscCall(VecDestroy(&rhs));
  PetscCall(PetscLogEventEnd(DS_Solve, 0, 0, 0, 0));
  PetscCheck(cycleFrom < 0, comm, PETSC_ERR_NOT_CONVERGED, "Matrix-free dual QP (-fom_dual_matrix shell): the primal-dual active-set method cycles (the free set of step %" PetscInt_FMT " came back at step %" PetscInt_FMT ", %" PetscInt_FMT " free multipliers); use -fom_dual_matrix dense", cycleFrom, info->pdasIterations + 1, info->nfree);
  PetscCheck(converged, comm, PETSC_ERR_NOT_CONVERGED, "Matrix-free dual QP (-fom_dual_matrix shell): the free set still changed after %" PetscInt_FMT " active-set steps (-%spdas_max_it); use -fom_dual_matrix dense", maxIt, prefix_.c_str());
  PetscFunctionReturn(0);
}

} // namespace rbc
