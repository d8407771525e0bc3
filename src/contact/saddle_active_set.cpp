// src/contact/saddle_active_set.cpp: the contact QP of a Kacanov iterate on the sparse primal-dual saddle
// point, by a primal-dual active-set method (see rbcontact/saddle_active_set.hpp, docs/contact.md).
// Owns the saddle-point matrix (its layout: each rank's u rows, then its lambda rows), its KSP and the set.
#include "rbcontact/saddle_active_set.hpp"
#include "rbcontact/options_files.hpp"
#include <algorithm>
#include <cmath>
#include <sstream>

namespace rbc {

static PetscLogEvent SAS_Build = 0, SAS_Solve = 0;

SaddleActiveSetSolver::~SaddleActiveSetSolver() { (void)Reset(); }

PetscErrorCode SaddleActiveSetSolver::Reset()
{
  PetscFunctionBeginUser;
  PetscCall(KSPDestroy(&ksp_));
  PetscCall(MatDestroy(&M_));
  PetscCall(VecDestroy(&x_));
  PetscCall(VecDestroy(&b_));
  PetscCall(MatNullSpaceDestroy(&nearNull_));
  lastA_ = nullptr;
  factored_ = false;
  kPattern_.clear();
  active_.clear();
  PetscFunctionReturn(0);
}

PetscErrorCode SaddleActiveSetSolver::SetFromOptions(MPI_Comm comm, const std::string &prefix)
{
  PetscFunctionBeginUser;
  if (!SAS_Build) {
    PetscCall(PetscLogEventRegister("RBCSaddleBuild", MAT_CLASSID, &SAS_Build));
    PetscCall(PetscLogEventRegister("RBCSaddleSolve", MAT_CLASSID, &SAS_Solve));
  }
  prefix_ = prefix + "saddle_";
  // given without a value, PETSc kept the default without a word; the Krylov tolerances are checked before PETSc reads them
  PetscCall(CheckValuesGiven(comm, prefix_, {"pdas_max_it", "pdas_tol", "solver", "pdas_rtol_loose", "rtol_forcing", "reuse_max_changes"}));
  PetscCall(CheckKSPTolerances(comm, prefix_));
  PetscOptionsBegin(comm, prefix_.c_str(), "Contact QP on the saddle point (primal-dual active set, -fom_dual_matrix saddle)", "SaddleActiveSetSolver");
  PetscCall(PetscOptionsInt("-pdas_max_it", "Most active-set steps of one Kacanov iterate (cold start or -pdas_inner)", "docs/contact.md", maxIt, &maxIt, NULL));
  PetscCall(PetscOptionsReal("-pdas_tol", "A row joins the set when its penetration exceeds this times the constraint scale", "docs/contact.md", setTol, &setTol, NULL));
  PetscCall(PetscOptionsBool("-pdas_inner", "Active-set steps to convergence on every Kacanov iterate (else one step per iterate after the first)", "docs/contact.md", inner, &inner, NULL));
  PetscCall(PetscOptionsBool("-pdas_monitor", "One line per active-set step", NULL, monitor, &monitor, NULL));
  {
    const char *types[] = {"direct", "gamg"};
    PetscInt    t       = solver == "gamg" ? 1 : 0;
    PetscCall(PetscOptionsEList("-solver", "Preset of the solver: direct (MUMPS LDL^T) or gamg (FGMRES + Schur-complement fieldsplit, GAMG on u: memory linear in the dofs); -fom_saddle_ksp_*/-pc_* refine either", "docs/contact.md", types, 2, types[t], &t, NULL));
    solver = types[t];
  }
  PetscCall(PetscOptionsReal("-pdas_rtol_loose", "Relative tolerance of the solves while the set still changes on a cold start (the last set is solved to -fom_saddle_ksp_rtol)", "docs/contact.md", looseRtol, &looseRtol, NULL));
  PetscCall(PetscOptionsReal("-rtol_forcing", "Solve a Kacanov iterate's saddle point to this times the loop's last relative change of u, within [-fom_saddle_ksp_rtol, -fom_saddle_pdas_rtol_loose]; the loop stops only after an exact one (0: every iterate exactly; default 1e-3; docs/fom_speed.md)", "docs/fom_speed.md", forcing, &forcing, NULL));
  PetscCall(PetscOptionsBool("-previous_guess", "Start each step's Krylov solve from the last step's solution of the parameter (the stopping test stays rtol |b|)", "docs/contact.md", previousGuess, &previousGuess, NULL));
  PetscCall(PetscOptionsInt("-reuse_max_changes", "Solve with the last factorization (GMRES) while at most this many rows changed status since it (-1: factor every step)", "docs/contact.md", reuseMaxChanges, &reuseMaxChanges, NULL));
  PetscOptionsEnd();
  if (solver == "gamg") { // defaults of the preset; options given on the command line win
    const char *preset[][2] = {{"ksp_type", "fgmres"}, {"ksp_max_it", "2000"}, {"ksp_gmres_restart", "200"}, {"pc_type", "fieldsplit"},
                               {"pc_fieldsplit_type", "schur"}, {"pc_fieldsplit_schur_fact_type", "lower"}, {"pc_fieldsplit_schur_precondition", "selfp"},
                               {"fieldsplit_u_ksp_type", "preonly"}, {"fieldsplit_u_pc_type", "gamg"}, {"fieldsplit_lambda_ksp_type", "preonly"},
                               {"fieldsplit_lambda_pc_type", "lu"}, {"fieldsplit_lambda_pc_factor_mat_solver_type", "mumps"}};
    for (const auto &kv : preset) {
      const std::string name = "-" + prefix_ + kv[0];
      PetscBool         given;
      PetscCall(PetscOptionsHasName(NULL, NULL, name.c_str(), &given));
      if (!given) PetscCall(PetscOptionsSetValue(NULL, name.c_str(), kv[1]));
    }
  }
  {
    char      pc[64] = "";
    PetscBool set    = PETSC_FALSE;
    PetscCall(PetscOptionsGetString(NULL, prefix_.c_str(), "-pc_type", pc, sizeof pc, &set));
    wantsNearNull_ = set && std::string(pc) == PCFIELDSPLIT;
  }
  PetscCheck(maxIt >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%spdas_max_it %" PetscInt_FMT " must be >= 1", prefix_.c_str(), maxIt);
  PetscCheck(setTol >= 0 && setTol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%spdas_tol %g must be in [0, 1)", prefix_.c_str(), (double)setTol);
  PetscCheck(looseRtol > 0 && looseRtol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%spdas_rtol_loose %g must be in (0, 1)", prefix_.c_str(), (double)looseRtol);
  PetscCheck(reuseMaxChanges >= -1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%sreuse_max_changes %" PetscInt_FMT " must be >= -1 (-1: a factorization on every step)", prefix_.c_str(), reuseMaxChanges);
  PetscCheck(forcing >= 0 && forcing < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%srtol_forcing %g must be in [0, 1) (0: every Kacanov iterate solved exactly)", prefix_.c_str(), (double)forcing);
  PetscFunctionReturn(0);
}

std::string SaddleActiveSetSolver::LooseSolves() const
{
  if (!(exactRtol_ > 1e-10)) return "";
  std::ostringstream o;
  o << "the saddle-point solves stop at -" << prefix_ << "ksp_rtol " << exactRtol_;
  if (exactResidual_ > 0) o << " (the last one at a relative residual " << exactResidual_ << ")";
  o << ", above 1e-10: the active-set test reads signs that the solves' error decides (raising -" << prefix_ << "pdas_tol does not help), and the error stays in the KKT residuals; tighten -" << prefix_ << "ksp_rtol to 1e-10 or below (the default is 1e-12) or solve directly (";
  if (fieldsplit_) o << "-" << prefix_ << "solver direct, ";
  o << "-" << prefix_ << "reuse_max_changes -1: a new factorization on every step, exact whatever the tolerance)";
  return o.str();
}

PetscErrorCode SaddleActiveSetSolver::SetNearNullSpace(MatNullSpace nsp)
{
  PetscFunctionBeginUser;
  if (nsp) PetscCall(PetscObjectReference((PetscObject)nsp));
  PetscCall(MatNullSpaceDestroy(&nearNull_));
  nearNull_ = nsp;
  PetscFunctionReturn(0);
}

// Owner of global index j in the ranges r (size + 1 entries)
static PetscMPIInt Owner(const PetscInt *r, PetscMPIInt size, PetscInt j)
{
  return (PetscMPIInt)(std::upper_bound(r, r + size + 1, j) - r - 1);
}

// The saddle point's numbering: each rank's u rows (A's ownership range), then its lambda rows (K's)
struct SaddleLayout {
  PetscMPIInt     size = 0, rank = 0;
  const PetscInt *ur = nullptr, *lr = nullptr; // ownership ranges of u and lambda (size + 1 entries)
  PetscErrorCode  Init(Mat A, Mat K)
  {
    MPI_Comm comm = PetscObjectComm((PetscObject)A);
    PetscFunctionBeginUser;
    PetscCallMPI(MPI_Comm_size(comm, &size));
    PetscCallMPI(MPI_Comm_rank(comm, &rank));
    PetscCall(MatGetOwnershipRanges(A, &ur));
    PetscCall(MatGetOwnershipRanges(K, &lr));
    PetscFunctionReturn(0);
  }
  PetscInt U(PetscInt j) const { return j + lr[Owner(ur, size, j)]; }     // the row of u dof j
  PetscInt L(PetscInt i) const { return i + ur[Owner(lr, size, i) + 1]; } // the row of multiplier i
};

// K's local pattern (row lengths, then the columns), to tell whether the last matrix's pattern still fits
static PetscErrorCode Pattern(Mat K, std::vector<PetscInt> *p)
{
  PetscInt lo, hi;

  PetscFunctionBeginUser;
  p->clear();
  PetscCall(MatGetOwnershipRange(K, &lo, &hi));
  for (PetscInt i = lo; i < hi; ++i) {
    PetscInt        nc;
    const PetscInt *cols;
    PetscCall(MatGetRow(K, i, &nc, &cols, NULL));
    p->push_back(nc);
    p->insert(p->end(), cols, cols + nc);
    PetscCall(MatRestoreRow(K, i, &nc, &cols, NULL));
  }
  PetscFunctionReturn(0);
}

// The KSP of the saddle point on M_ (defaults: GMRES on a MUMPS LDL^T factor; -fom_saddle_solver gamg's preset
// or the user's options), with the fields u and lambda when its PC is a PCFIELDSPLIT
PetscErrorCode SaddleActiveSetSolver::CreateKSP()
{
  MPI_Comm comm = PetscObjectComm((PetscObject)M_);
  PC       pc;
  PetscInt start;

  PetscFunctionBeginUser;
  PetscCall(KSPDestroy(&ksp_));
  PetscCall(KSPCreate(comm, &ksp_));
  PetscCall(KSPSetOptionsPrefix(ksp_, prefix_.c_str()));
  // GMRES on the factor: one iteration on a fresh factorization, a few on the factor of an earlier
  // matrix (the next Kacanov iterate's K, or a few rows' status changed), which saves a factorization
  PetscCall(KSPSetType(ksp_, KSPGMRES));
  PetscCall(KSPSetPCSide(ksp_, PC_RIGHT));
  PetscCall(KSPSetNormType(ksp_, KSP_NORM_UNPRECONDITIONED));
  PetscCall(KSPSetTolerances(ksp_, 1e-12, 1e-300, PETSC_DEFAULT, 30));
  PetscCall(KSPGetPC(ksp_, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscCall(KSPSetFromOptions(ksp_));
  PetscCall(KSPGetTolerances(ksp_, &exactRtol_, NULL, NULL, NULL));
  PetscBool pre;
  PetscCall(PetscObjectTypeCompare((PetscObject)ksp_, KSPPREONLY, &pre));
  canReuse_   = !pre; // preonly cannot tell a stale factor from a fresh one
  factored_   = false;
  newPattern_ = false;
  PetscCall(KSPSetOperators(ksp_, M_, M_));
  PetscCall(KSPGetPC(ksp_, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCFIELDSPLIT, &fieldsplit_));
  PetscCall(MatGetOwnershipRange(M_, &start, NULL));
  if (fieldsplit_) {
    IS isu, isl;
    PetscCall(ISCreateStride(comm, nu_, start, 1, &isu));
    PetscCall(ISCreateStride(comm, nl_, start + nu_, 1, &isl));
    if (nearNull_) PetscCall(PetscObjectCompose((PetscObject)isu, "nearnullspace", (PetscObject)nearNull_)); // for GAMG on the u block
    PetscCall(PCFieldSplitSetIS(pc, "u", isu));
    PetscCall(PCFieldSplitSetIS(pc, "lambda", isl));
    PetscCall(ISDestroy(&isu));
    PetscCall(ISDestroy(&isl));
  }
  PetscFunctionReturn(0);
}

// The saddle-point matrix with the pattern of A and K (all rows of K, explicit zeros where inactive),
// preallocated exactly, and its KSP.
PetscErrorCode SaddleActiveSetSolver::Build(Mat A, Mat K)
{
  MPI_Comm     comm = PetscObjectComm((PetscObject)A);
  SaddleLayout lay;
  Mat          Kt;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(SAS_Build, 0, 0, 0, 0));
  PetscCall(lay.Init(A, K));
  const PetscInt *ur = lay.ur, *lr = lay.lr, rank = lay.rank;
  nu_ = ur[rank + 1] - ur[rank];
  nl_ = lr[rank + 1] - lr[rank];
  const PetscInt start = ur[rank] + lr[rank], n = nu_ + nl_;
  auto mapU = [&](PetscInt j) { return lay.U(j); };
  auto mapL = [&](PetscInt i) { return lay.L(i); };
  auto local = [&](PetscInt c) { return c >= start && c < start + n; };
  PetscCall(MatTranspose(K, MAT_INITIAL_MATRIX, &Kt));
  std::vector<PetscInt> dnz(n, 0), onz(n, 0);
  for (PetscInt j = ur[rank]; j < ur[rank + 1]; ++j) {
    PetscInt        nc;
    const PetscInt *cols;
    const PetscInt  row = j - ur[rank];
    PetscCall(MatGetRow(A, j, &nc, &cols, NULL));
    for (PetscInt k = 0; k < nc; ++k) ++(local(mapU(cols[k])) ? dnz : onz)[row];
    PetscCall(MatRestoreRow(A, j, &nc, &cols, NULL));
    PetscCall(MatGetRow(Kt, j, &nc, &cols, NULL));
    for (PetscInt k = 0; k < nc; ++k) ++(local(mapL(cols[k])) ? dnz : onz)[row];
    PetscCall(MatRestoreRow(Kt, j, &nc, &cols, NULL));
  }
  for (PetscInt i = lr[rank]; i < lr[rank + 1]; ++i) {
    PetscInt        nc;
    const PetscInt *cols;
    const PetscInt  row = nu_ + i - lr[rank];
    PetscCall(MatGetRow(K, i, &nc, &cols, NULL));
    for (PetscInt k = 0; k < nc; ++k) ++(local(mapU(cols[k])) ? dnz : onz)[row];
    PetscCall(MatRestoreRow(K, i, &nc, &cols, NULL));
    ++dnz[row]; // the diagonal
  }
  PetscCall(MatDestroy(&Kt));
  PetscCall(MatDestroy(&M_));
  PetscCall(MatCreate(comm, &M_));
  PetscCall(MatSetSizes(M_, n, n, PETSC_DETERMINE, PETSC_DETERMINE));
  PetscCall(MatSetType(M_, MATAIJ));
  PetscCall(MatSeqAIJSetPreallocation(M_, 0, dnz.data()));
  PetscCall(MatMPIAIJSetPreallocation(M_, 0, dnz.data(), 0, onz.data()));
  PetscCall(MatSetOption(M_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(MatSetOption(M_, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(M_, MAT_SPD, PETSC_FALSE));
  { // a new pattern keeps the layout (A's and K's rows): the last step's solution stays the next one's guess
    Vec      x;
    PetscInt nx = -1;
    PetscCall(MatCreateVecs(M_, &x, NULL));
    if (x_) PetscCall(VecGetLocalSize(x_, &nx));
    PetscBool keep = guess_ && nx == n ? PETSC_TRUE : PETSC_FALSE;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &keep, 1, MPIU_BOOL, MPI_LAND, comm));
    if (keep) PetscCall(VecCopy(x_, x));
    guess_ = keep;
    PetscCall(VecDestroy(&x_));
    PetscCall(VecDestroy(&b_));
    x_ = x;
    PetscCall(VecDuplicate(x_, &b_));
  }
  // Balance: the multiplier rows scaled by c = max diag(A) / |K|_inf (entries of c K of A's size; lambda =
  // c lambda~), the inactive rows' pivot -s = -max diag(A) (c^2 times the size of a diagonal entry of
  // K A^{-1} K^T). Unscaled, a row that changed status left GMRES on an earlier factor stagnating near 1e-11.
  {
    Vec       d;
    PetscReal kinf, amax;
    PetscCall(MatCreateVecs(A, &d, NULL));
    PetscCall(MatGetDiagonal(A, d));
    PetscCall(VecMax(d, NULL, &amax));
    PetscCall(VecDestroy(&d));
    PetscCall(MatNorm(K, NORM_INFINITY, &kinf));
    diagScale_ = amax > 0 ? amax : 1.0;
    kScale_    = amax > 0 && kinf > 0 ? amax / kinf : 1.0;
  }
  if (!ksp_) PetscCall(CreateKSP());
  else {
    PetscCall(KSPSetOperators(ksp_, M_, M_));
    newPattern_ = true;
  }
  PetscCall(PetscLogEventEnd(SAS_Build, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

// The values for the current set: A; K and K^T on the active rows (zeros elsewhere); -s on the inactive
// rows' diagonal. Every entry of the pattern is written, so no zeroing is needed.
PetscErrorCode SaddleActiveSetSolver::Fill(Mat A, Mat K)
{
  SaddleLayout             lay;
  std::vector<PetscInt>    mapped;
  std::vector<PetscScalar> vals;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(SAS_Build, 0, 0, 0, 0));
  PetscCall(lay.Init(A, K));
  const PetscInt *ur = lay.ur, *lr = lay.lr, rank = lay.rank;
  auto mapU = [&](PetscInt j) { return lay.U(j); };
  for (PetscInt j = ur[rank]; j < ur[rank + 1]; ++j) {
    PetscInt           nc;
    const PetscInt    *cols;
    const PetscScalar *v;
    const PetscInt     row = mapU(j);
    PetscCall(MatGetRow(A, j, &nc, &cols, &v));
    mapped.resize(nc);
    for (PetscInt k = 0; k < nc; ++k) mapped[k] = mapU(cols[k]);
    PetscCall(MatSetValues(M_, 1, &row, nc, mapped.data(), v, INSERT_VALUES));
    PetscCall(MatRestoreRow(A, j, &nc, &cols, &v));
  }
  for (PetscInt i = lr[rank]; i < lr[rank + 1]; ++i) {
    PetscInt           nc;
    const PetscInt    *cols;
    const PetscScalar *v;
    const PetscInt     row = i + ur[rank + 1];
    const bool         on  = active_[i - lr[rank]] != 0;
    PetscCall(MatGetRow(K, i, &nc, &cols, &v));
    mapped.resize(nc);
    vals.resize(nc);
    for (PetscInt k = 0; k < nc; ++k) {
      mapped[k] = mapU(cols[k]);
      vals[k]   = on ? kScale_ * v[k] : 0.0;
    }
    PetscCall(MatSetValues(M_, 1, &row, nc, mapped.data(), vals.data(), INSERT_VALUES));
    PetscCall(MatSetValues(M_, nc, mapped.data(), 1, &row, vals.data(), INSERT_VALUES));
    PetscCall(MatRestoreRow(K, i, &nc, &cols, &v));
    const PetscScalar dv = on ? 0.0 : -diagScale_;
    PetscCall(MatSetValues(M_, 1, &row, 1, &row, &dv, INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(M_, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(M_, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscLogEventEnd(SAS_Build, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

// One step: factor and solve with the current set, then the next set from lambda and K u - g
// b_ = [f; c P g] (P the set)
PetscErrorCode SaddleActiveSetSolver::SetRhs(Vec f, Vec g)
{
  const PetscScalar *fa, *ga;
  PetscScalar       *ba;

  PetscFunctionBeginUser;
  PetscCall(VecGetArrayRead(f, &fa));
  PetscCall(VecGetArrayRead(g, &ga));
  PetscCall(VecGetArray(b_, &ba));
  for (PetscInt j = 0; j < nu_; ++j) ba[j] = fa[j];
  for (PetscInt i = 0; i < nl_; ++i) ba[nu_ + i] = active_[i] ? kScale_ * ga[i] : 0.0;
  PetscCall(VecRestoreArray(b_, &ba));
  PetscCall(VecRestoreArrayRead(g, &ga));
  PetscCall(VecRestoreArrayRead(f, &fa));
  PetscFunctionReturn(0);
}

// u, lambda from x_ (lambda = c lambda~ on the set, 0 off it)
PetscErrorCode SaddleActiveSetSolver::GetSolution(Vec u, Vec lambda) const
{
  const PetscScalar *xa;
  PetscScalar       *ua, *la;

  PetscFunctionBeginUser;
  PetscCall(VecGetArrayRead(x_, &xa));
  PetscCall(VecGetArray(u, &ua));
  PetscCall(VecGetArray(lambda, &la));
  for (PetscInt j = 0; j < nu_; ++j) ua[j] = xa[j];
  for (PetscInt i = 0; i < nl_; ++i) la[i] = active_[i] ? kScale_ * xa[nu_ + i] : 0.0;
  PetscCall(VecRestoreArray(lambda, &la));
  PetscCall(VecRestoreArray(u, &ua));
  PetscCall(VecRestoreArrayRead(x_, &xa));
  PetscFunctionReturn(0);
}

PetscErrorCode SaddleActiveSetSolver::SetActiveSet(Vec lambda)
{
  const PetscScalar *la;
  PetscInt           n;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(lambda, &n));
  PetscCall(VecGetArrayRead(lambda, &la));
  active_.assign(n, 0);
  for (PetscInt i = 0; i < n; ++i) active_[i] = PetscRealPart(la[i]) > 0;
  PetscCall(VecRestoreArrayRead(lambda, &la));
  PetscFunctionReturn(0);
}

PetscErrorCode SaddleActiveSetSolver::SolveFixedSet(Vec f, Vec g, Vec u, Vec lambda)
{
  KSPConvergedReason reason;

  PetscFunctionBeginUser;
  PetscCheck(ksp_ && M_, PetscObjectComm((PetscObject)f), PETSC_ERR_ORDER, "SaddleActiveSetSolver::SolveFixedSet: no active-set step to reuse (Solve first)");
  PetscCall(SetRhs(f, g));
  PetscCall(PetscLogEventBegin(SAS_Solve, 0, 0, 0, 0));
  PetscCall(KSPSetTolerances(ksp_, exactRtol_, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT));
  PetscCall(KSPSetReusePreconditioner(ksp_, PETSC_TRUE));
  PetscCall(KSPSetInitialGuessNonzero(ksp_, PETSC_FALSE));
  guess_ = false; // x_ will hold this right-hand side's solution, not a step's
  PetscCall(KSPSolve(ksp_, b_, x_));
  PetscCall(KSPGetConvergedReason(ksp_, &reason));
  PetscCall(PetscLogEventEnd(SAS_Solve, 0, 0, 0, 0));
  PetscCheck(reason > 0, PetscObjectComm((PetscObject)f), PETSC_ERR_NOT_CONVERGED, "Contact saddle-point solve with the converged set failed (%s): -%sksp_* / -%spc_type", KSPConvergedReasons[reason], prefix_.c_str(), prefix_.c_str());
  PetscCall(GetSolution(u, lambda));
  PetscFunctionReturn(0);
}

PetscErrorCode SaddleActiveSetSolver::Step(Mat A, Vec f, Mat K, Vec g, PetscReal rtol, Vec u, Vec lambda, SaddleInfo *info)
{
  MPI_Comm           comm = PetscObjectComm((PetscObject)A);
  KSPConvergedReason reason;
  PetscLogDouble     t0, t1;

  PetscFunctionBeginUser;
  PetscCall(Fill(A, K));
  PetscCall(SetRhs(f, g));
  PetscCall(PetscTime(&t0));
  PetscCall(PetscLogEventBegin(SAS_Solve, 0, 0, 0, 0));
  bool     fresh = !(factored_ && canReuse_ && changedSinceFactor_ <= reuseMaxChanges);
  PetscCall(KSPSetTolerances(ksp_, rtol, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT));
  // the initial guess: the last step's solution of this parameter with the rows now inactive zeroed (their
  // equation is -s lambda~ = 0), or zero (always with KSPPREONLY, which refuses a nonzero guess)
  const PetscBool guess = previousGuess && guess_ && canReuse_ ? PETSC_TRUE : PETSC_FALSE;
  if (guess) {
    PetscScalar *xa;
    PetscCall(VecGetArray(x_, &xa));
    for (PetscInt i = 0; i < nl_; ++i)
      if (!active_[i]) xa[nu_ + i] = 0.0;
    PetscCall(VecRestoreArray(x_, &xa));
  }
  Vec x0 = nullptr; // the guess, kept for a retry with a new factorization
  if (guess && !fresh) {
    PetscCall(VecDuplicate(x_, &x0));
    PetscCall(VecCopy(x_, x0));
  }
  PetscCall(KSPSetInitialGuessNonzero(ksp_, guess));
  const PetscReal addTol = std::max(setTol, rtol > exactRtol_ ? rtol : 0.0); // a loose solve: a loose threshold for adding rows
  PetscInt its   = 0;
  bool stale = false; // the earlier factor cost more than a new one: factor at the next step
  if (!fresh) { // the factor of an earlier matrix as GMRES's preconditioner
    PetscLogDouble r0, r1;
    PetscCall(PetscTime(&r0));
    PetscCall(KSPSetReusePreconditioner(ksp_, PETSC_TRUE));
    PetscCall(KSPSolve(ksp_, b_, x_));
    PetscCall(KSPGetConvergedReason(ksp_, &reason));
    PetscCall(KSPGetIterationNumber(ksp_, &its));
    PetscCall(PetscTime(&r1));
    info->krylov += its;
    if (reason <= 0) fresh = true;
    stale = r1 - r0 > freshSeconds_;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &stale, 1, MPI_CXX_BOOL, MPI_LOR, comm)); // the same decision on every rank
  }
  if (fresh) {
    PetscLogDouble r0, r1;
    PetscCall(PetscTime(&r0));
    // a PCFIELDSPLIT set up on an earlier pattern does not rebuild its blocks correctly (measured: 480 FGMRES
    // iterations instead of 60): a new KSP; a factorization handles the new pattern itself
    if (fieldsplit_ && newPattern_) {
      PetscCall(CreateKSP());
      PetscCall(KSPSetTolerances(ksp_, rtol, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT));
      PetscCall(KSPSetInitialGuessNonzero(ksp_, guess));
    }
    newPattern_ = false;
    if (x0) PetscCall(VecCopy(x0, x_)); // a failed solve with the earlier factor: from the guess again
    PetscCall(KSPSetReusePreconditioner(ksp_, PETSC_FALSE));
    PetscCall(KSPSolve(ksp_, b_, x_));
    PetscCall(KSPGetIterationNumber(ksp_, &its));
    PetscCall(PetscTime(&r1));
    info->krylov += its;
    ++info->factorizations;
    factored_           = true;
    changedSinceFactor_ = 0;
    freshSeconds_       = r1 - r0;
  } else if (stale) factored_ = false;
  PetscCall(VecDestroy(&x0));
  PetscCall(PetscLogEventEnd(SAS_Solve, 0, 0, 0, 0));
  PetscCall(PetscTime(&t1));
  PetscCall(KSPGetConvergedReason(ksp_, &reason));
  PetscCheck(reason > 0, comm, PETSC_ERR_NOT_CONVERGED, "Contact saddle-point solve failed (%s) at active-set step %" PetscInt_FMT ": a failed factorization (-%spc_type, -%spc_factor_mat_solver_type; MUMPS workspace: -%smat_mumps_icntl_14) or the iterative solver's -%sksp_* settings",
             KSPConvergedReasons[reason], info->steps + 1, prefix_.c_str(), prefix_.c_str(), prefix_.c_str(), prefix_.c_str());
  if (rtol <= exactRtol_) { // the residual an exact step reached (LooseSolves; KSPPREONLY computes none: 0)
    PetscReal rn, bn;
    PetscCall(KSPGetResidualNorm(ksp_, &rn));
    PetscCall(VecNorm(b_, NORM_2, &bn));
    exactResidual_ = bn > 0 ? rn / bn : 0;
  }
  PetscCall(GetSolution(u, lambda));
  guess_ = true;
  PetscReal nx;
  PetscCall(VecNorm(x_, NORM_INFINITY, &nx));
  PetscCheck(std::isfinite(nx), comm, PETSC_ERR_FP, "Contact saddle-point solve gave non-finite values at active-set step %" PetscInt_FMT " (-%spc_type)", info->steps + 1, prefix_.c_str());
  // the penetration K u - g and its scale max(|K|_inf |u|_inf, |K u|_inf) + |g|_inf (the KKT check's)
  Vec       pen;
  PetscReal nK, nuinf, nKu, ng;
  PetscCall(VecDuplicate(g, &pen));
  PetscCall(MatMult(K, u, pen));
  PetscCall(VecNorm(pen, NORM_INFINITY, &nKu));
  PetscCall(VecAXPY(pen, -1.0, g));
  PetscCall(MatNorm(K, NORM_INFINITY, &nK));
  PetscCall(VecNorm(u, NORM_INFINITY, &nuinf));
  PetscCall(VecNorm(g, NORM_INFINITY, &ng));
  const PetscReal    scale = std::max(nK * nuinf, nKu) + ng;
  const PetscScalar *pa, *lam;
  PetscInt           changed = 0, nact = 0;
  PetscCall(VecGetArrayRead(pen, &pa));
  PetscCall(VecGetArrayRead(lambda, &lam));
  for (PetscInt i = 0; i < nl_; ++i) {
    const char next = active_[i] ? PetscRealPart(lam[i]) > 0 : PetscRealPart(pa[i]) > addTol * scale;
    changed += next != active_[i];
    nact += active_[i];
    active_[i] = next;
  }
  PetscCall(VecRestoreArrayRead(lambda, &lam));
  PetscCall(VecRestoreArrayRead(pen, &pa));
  PetscCall(VecDestroy(&pen));
  PetscInt c[2] = {changed, nact};
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, c, 2, MPIU_INT, MPI_SUM, comm));
  info->changed = c[0];
  info->nactive = c[1];
  changedSinceFactor_ += c[0];
  ++info->steps;
  if (monitor) PetscCall(PetscPrintf(comm, "      saddle step %" PetscInt_FMT ": %" PetscInt_FMT " active rows, %" PetscInt_FMT " change, %s, %" PetscInt_FMT " Krylov its, %.3f s\n", info->steps, c[1], c[0], fresh ? "new factorization (preconditioner)" : "earlier one", its, (double)(t1 - t0)));
  PetscFunctionReturn(0);
}

PetscErrorCode SaddleActiveSetSolver::Solve(Mat A, Vec f, Mat K, Vec g, PetscBool warm, PetscBool converge, Vec u, Vec lambda, SaddleInfo *info, PetscReal change)
{
  MPI_Comm              comm = PetscObjectComm((PetscObject)A);
  PetscLogDouble        t0, t1;
  std::vector<PetscInt> pat;
  PetscInt              lo, hi;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  *info = SaddleInfo();
  PetscCall(MatGetOwnershipRange(K, &lo, &hi));
  PetscBool kept = warm && (PetscInt)active_.size() == hi - lo ? PETSC_TRUE : PETSC_FALSE;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &kept, 1, MPIU_BOOL, MPI_LAND, comm));
  if (!kept) active_.assign(hi - lo, 0);
  const bool toEnd = converge || inner || !kept;
  // a new matrix (symbolic analysis) unless A and K's pattern are the last ones
  PetscObjectState anz;
  PetscCall(Pattern(K, &pat));
  PetscCall(MatGetNonzeroState(A, &anz));
  PetscBool same = (M_ && A == lastA_ && anz == lastANonzero_ && pat == kPattern_) ? PETSC_TRUE : PETSC_FALSE;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPIU_BOOL, MPI_LAND, comm));
  if (!same) {
    PetscCall(Build(A, K));
    kPattern_.swap(pat);
    lastA_         = A;
    lastANonzero_  = anz;
    info->symbolic = 1;
  }
  std::vector<std::vector<char>> seen; // the sets of this call's steps (a set that comes back on every rank is a cycle)
  bool loose = toEnd && canReuse_ && looseRtol > exactRtol_; // loose solves while the set changes, then the last set exactly
  // -rtol_forcing: the last set to forcing x the Kacanov change instead of exactly (never looser than the loose solves)
  const PetscReal last = forcing > 0 && change > 0 ? std::max(exactRtol_, std::min(forcing * change, std::max(looseRtol, exactRtol_))) : exactRtol_;
  PetscReal used = exactRtol_; // the tolerance of the last step
  for (;;) {
    seen.push_back(active_);
    used = loose ? looseRtol : last;
    PetscCall(Step(A, f, K, g, used, u, lambda, info));
    if (!info->changed && loose && last >= looseRtol) break; // settled under loose solves, as loose as the last one may be
    if (!info->changed && loose) { // the set settled under loose solves: the same set once more, to the last tolerance
      loose = false;
      seen.clear();
      continue;
    }
    if (!info->changed || !toEnd) break;
    std::vector<PetscMPIInt> back(seen.size());
    for (size_t s = 0; s < seen.size(); ++s) back[s] = seen[s] == active_;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, back.data(), (int)back.size(), MPI_INT, MPI_LAND, comm));
    // (inexact solves: their cause, not -pdas_tol, which does not help)
    const std::string why = LooseSolves(), cause = why.empty() ? ": raise -" + prefix_ + "pdas_tol" : "; the cause: " + why;
    PetscCheck(std::find(back.begin(), back.end(), 1) == back.end(), comm, PETSC_ERR_NOT_CONVERGED, "Contact active set cycles after %" PetscInt_FMT " steps (-%spdas_*: a set came back; %" PetscInt_FMT " rows change)%s", info->steps, prefix_.c_str(), info->changed, cause.c_str());
    PetscCheck(info->steps < maxIt, comm, PETSC_ERR_NOT_CONVERGED, "Contact active set not settled in -%spdas_max_it %" PetscInt_FMT " steps (%" PetscInt_FMT " rows still change)%s", prefix_.c_str(), maxIt, info->changed, why.empty() ? "" : ("; the cause: " + why).c_str());
  }
  PetscCall(PetscTime(&t1));
  info->seconds = t1 - t0;
  info->exact   = used <= exactRtol_ ? PETSC_TRUE : PETSC_FALSE;
  {
    KSPType kt;
    PCType  pt;
    PC      pc;
    PetscCall(KSPGetType(ksp_, &kt));
    PetscCall(KSPGetPC(ksp_, &pc));
    PetscCall(PCGetType(pc, &pt));
    info->kspType = kt;
    info->pcType  = pt;
  }
  PetscFunctionReturn(0);
}

} // namespace rbc
