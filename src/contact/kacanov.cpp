// src/contact/kacanov.cpp: Kacanov fixed-point iterations with the dual solve (dense S and TAO, or the
// matrix-free S of dual_shell.cpp: -fom_dual_matrix), KKT checks and the contact summary (force,
// pressure, active zone).
#include "rbcontact/kacanov.hpp"
#include "rbcontact/options_files.hpp"
#include "contact_point.hpp"
#include "pressure_moments.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <sstream>

namespace rbc {

static PetscLogEvent KAC_Assemble = 0, KAC_Schur = 0, KAC_QP = 0;

KacanovSolver::~KacanovSolver()
{
  (void)VecDestroy(&lambda);
  (void)VecDestroy(&uInit_);
  (void)VecDestroy(&lamInit_);
}

PetscErrorCode KacanovSolver::SetInitialGuess(Vec u, Vec lam)
{
  PetscFunctionBeginUser;
  PetscCall(VecDestroy(&uInit_));
  PetscCall(VecDestroy(&lamInit_));
  PetscCall(VecDuplicate(u, &uInit_));
  PetscCall(VecCopy(u, uInit_));
  PetscCall(VecDuplicate(lam, &lamInit_));
  PetscCall(VecCopy(lam, lamInit_));
  PetscFunctionReturn(0);
}

// The contact QP's TAO had the prefix fom_ until 2026-11-25, shared with the elastic KSP/PC (so that
// -fom_ksp_type cg -fom_pc_type gamg reached TAO's inner KSP on the dense dual matrix). Its prefix is fom_qp_ now;
// a -fom_tao_* option still works for one release, moved to -fom_qp_tao_* with a deprecation warning.
static PetscErrorCode RenameTaoOptions(MPI_Comm comm)
{
  std::vector<std::string> given, lowered, old;

  PetscFunctionBeginUser;
  PetscCall(OptionNames(&given, &lowered));
  for (size_t i = 0; i < given.size(); ++i)
    if (lowered[i].compare(0, 8, "fom_tao_") == 0) old.push_back(given[i]);
  for (const auto &o : old) {
    const std::string now = "-fom_qp_tao_" + o.substr(9);
    char              val[PETSC_MAX_PATH_LEN] = "";
    PetscBool         hasNew = PETSC_FALSE, set = PETSC_FALSE;
    PetscCall(PetscOptionsHasName(NULL, NULL, now.c_str(), &hasNew));
    PetscCheck(!hasNew, comm, PETSC_ERR_USER_INPUT, "%s and its deprecated spelling %s are both given: keep %s", now.c_str(), o.c_str(), now.c_str());
    PetscCall(PetscOptionsGetString(NULL, NULL, o.c_str(), val, sizeof val, &set));
    PetscCall(PetscOptionsSetValue(NULL, now.c_str(), val[0] ? val : NULL));
    PetscCall(PetscOptionsClearValue(NULL, o.c_str()));
    PetscCall(PetscPrintf(comm, "rbcontact: warning: option %s is deprecated (the contact QP has its own prefix fom_qp_): use %s\n", o.c_str(), now.c_str()));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode KacanovSolver::SetFromOptions(MPI_Comm comm)
{
  PetscFunctionBeginUser;
  if (!KAC_Assemble) {
    PetscCall(PetscLogEventRegister("RBCContactAsm", MAT_CLASSID, &KAC_Assemble));
    PetscCall(PetscLogEventRegister("RBCContactSchur", MAT_CLASSID, &KAC_Schur));
    PetscCall(PetscLogEventRegister("RBCContactQP", MAT_CLASSID, &KAC_QP));
  }
  PetscCall(loop.SetFromOptions(comm, "")); // -kacanov_* (Anderson mixing on the contact-dof displacement: dense dual matrix only)
  PetscCall(CheckValuesGiven(comm, {"-kacanov_type", "-kacanov_newton_max_ratio", "-fom_kkt_tol", "-fom_dual_matrix", "-fom_dual_dense_max", "-fom_dual_dense_max_dofs"})); // (the defaults, without a word)
  PetscOptionsBegin(comm, "kacanov_", "Kacanov iterations of the full-order model", "KacanovSolver");
  {
    const char *types[] = {"fixed_point", "newton"};
    PetscInt    t       = type == "fixed_point" ? 0 : 1;
    PetscCall(PetscOptionsEList("-type", "Next input: fixed_point (the image, Anderson-mixed) or newton (Newton step with the contact geometry's derivative; dense dual, 2D)", "docs/fom_speed.md", types, 2, types[t], &t, NULL));
    type = types[t];
  }
  PetscCall(PetscOptionsReal("-newton_max_ratio", "Longest Newton step accepted, in units of the plain step |F(x) - x|", "docs/fom_speed.md", newtonMaxRatio, &newtonMaxRatio, NULL));
  PetscOptionsEnd();
  PetscCheck(newtonMaxRatio > 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-kacanov_newton_max_ratio %g must be > 0", (double)newtonMaxRatio);
  PetscOptionsBegin(comm, "fom_", "Contact FOM", "KacanovSolver");
  PetscCall(PetscOptionsReal("-kkt_tol", "Largest scaled KKT residual accepted", NULL, kktTol, &kktTol, NULL));
  PetscCall(PetscOptionsBool("-kkt_view", "Print lambda, K u - g and g per multiplier at each KKT check", NULL, kktView, &kktView, NULL)); // (read where used before: missing from -help)
  {
    const char *types[] = {"dense", "shell", "saddle", "auto"};
    PetscInt    t       = dualMatrixOption == "dense" ? 0 : dualMatrixOption == "shell" ? 1 : dualMatrixOption == "saddle" ? 2 : 3;
    PetscCall(PetscOptionsEList("-dual_matrix", "Contact QP: dense (S = K A^-1 K^T via the surface compliance), shell (S matrix-free), saddle (active set on the sparse saddle point), auto (dense while small, else saddle)", "docs/contact.md", types, 4, types[t], &t, NULL));
    dualMatrixOption = types[t];
  }
  PetscCall(PetscOptionsInt("-dual_dense_max", "auto: dense S up to this many multipliers, saddle above", NULL, dualDenseMax, &dualDenseMax, NULL));
  PetscCall(PetscOptionsInt("-dual_dense_max_dofs", "auto: dense S only while the compliance G (contact dofs squared) has at most this many rows (memory)", NULL, dualDenseMaxDofs, &dualDenseMaxDofs, NULL));
  PetscOptionsEnd();
  PetscCheck(dualDenseMax >= 0 && dualDenseMaxDofs >= 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-fom_dual_dense_max %" PetscInt_FMT " and -fom_dual_dense_max_dofs %" PetscInt_FMT " must be >= 0 (0: auto always takes the saddle point)", dualDenseMax, dualDenseMaxDofs);
  PetscCheck(kktTol > 0 && std::isfinite(kktTol), comm, PETSC_ERR_ARG_OUTOFRANGE, "-fom_kkt_tol %g must be a finite number > 0", (double)kktTol);
  { // checked here for every QP path (the dense one alone read it: bogus passed with -fom_dual_matrix shell or saddle)
    char m[32] = "auto";
    PetscCall(PetscOptionsGetString(NULL, NULL, "-contact_compliance", m, sizeof m, NULL));
    PetscCheck(!strcmp(m, "auto") || !strcmp(m, "schur") || !strcmp(m, "inverse") || !strcmp(m, "redundant") || !strcmp(m, "solves"), comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-contact_compliance: unknown value '%s' (auto, schur, inverse, redundant or solves)", m);
  }
  PetscCall(RenameTaoOptions(comm));
  PetscCall(qp_.Setup("fom_", comm));
  PetscCall(shell_.SetFromOptions(comm, "fom_"));
  PetscCall(saddle_.SetFromOptions(comm, "fom_"));
  PetscFunctionReturn(0);
}

PetscErrorCode GatherVec(Vec v, std::vector<PetscReal> *full)
{
  VecScatter         sc;
  Vec                all;
  const PetscScalar *a;
  PetscInt           n;

  PetscFunctionBeginUser;
  PetscCall(VecScatterCreateToAll(v, &sc, &all));
  PetscCall(VecScatterBegin(sc, v, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(sc, v, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGetSize(all, &n));
  PetscCall(VecGetArrayRead(all, &a));
  full->resize(n);
  for (PetscInt i = 0; i < n; ++i) (*full)[i] = PetscRealPart(a[i]);
  PetscCall(VecRestoreArrayRead(all, &a));
  PetscCall(VecScatterDestroy(&sc));
  PetscCall(VecDestroy(&all));
  PetscFunctionReturn(0);
}

static const PetscReal kInf = std::numeric_limits<PetscReal>::infinity(); // reported as null in JSON

PetscErrorCode KacanovSolver::ComputeKKT(ElasticFOM &fom)
{
  Vec       r, Ku, res;
  PetscReal nKu, ng, nl, nl1, lmin, rmax, comp, nf;

  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(sys.g, &r));
  PetscCall(VecDuplicate(sys.g, &Ku));
  PetscCall(MatMult(sys.K, fom.u, Ku));
  PetscCall(VecWAXPY(r, -1.0, sys.g, Ku)); // K u - g
  PetscCall(VecNorm(Ku, NORM_INFINITY, &nKu));
  PetscCall(VecNorm(sys.g, NORM_INFINITY, &ng));
  PetscCall(VecNorm(lambda, NORM_INFINITY, &nl));
  PetscCall(VecNorm(lambda, NORM_1, &nl1));
  PetscCall(VecMin(lambda, NULL, &lmin));
  PetscCall(VecMax(r, NULL, &rmax));
  {
    PetscScalar c;
    PetscCall(VecDot(lambda, r, &c));
    comp = std::abs(PetscRealPart(c));
  }
  {
    if (kktView) {
      PetscCall(PetscPrintf(PetscObjectComm((PetscObject)r), "KKT view: lambda, K u - g, g per multiplier\n"));
      PetscCall(VecView(lambda, PETSC_VIEWER_STDOUT_(PetscObjectComm((PetscObject)r))));
      PetscCall(VecView(r, PETSC_VIEWER_STDOUT_(PetscObjectComm((PetscObject)r))));
      PetscCall(VecView(sys.g, PETSC_VIEWER_STDOUT_(PetscObjectComm((PetscObject)r))));
    }
  }
  // Scale of the constraint terms: |K|_inf |u|_inf + |g|_inf (K u - g itself vanishes on a closed gap)
  PetscReal nK, nuinf;
  PetscCall(MatNorm(sys.K, NORM_INFINITY, &nK));
  PetscCall(VecNorm(fom.u, NORM_INFINITY, &nuinf));
  const PetscReal scaleG = std::max(std::max(nK * nuinf, nKu) + ng, PETSC_SMALL * PETSC_SMALL);
  kkt.primal             = std::max(0.0, (double)rmax) / scaleG;
  kkt.dual               = nl > 0 ? std::max(0.0, -(double)lmin) / nl : 0.0;
  kkt.complementarity    = nl1 > 0 ? comp / (nl1 * scaleG) : 0.0;
  // Stationarity A u - f + K^T lambda = 0
  PetscCall(VecDuplicate(fom.u, &res));
  PetscCall(MatMult(fom.A, fom.u, res));
  PetscCall(VecAXPY(res, -1.0, fom.f));
  PetscCall(MatMultTransposeAdd(sys.K, lambda, res, res));
  PetscReal nres;
  PetscCall(VecNorm(res, NORM_2, &nres));
  PetscCall(VecNorm(fom.f, NORM_2, &nf));
  {
    Vec       KtL;
    PetscReal nktl;
    PetscCall(VecDuplicate(fom.u, &KtL));
    PetscCall(MatMultTranspose(sys.K, lambda, KtL));
    PetscCall(VecNorm(KtL, NORM_2, &nktl));
    kkt.stationarity = nres / std::max(nf + nktl, PETSC_SMALL * PETSC_SMALL);
    PetscCall(VecDestroy(&KtL));
  }
  PetscCall(VecDestroy(&res));
  PetscCall(VecDestroy(&r));
  PetscCall(VecDestroy(&Ku));
  PetscFunctionReturn(0);
}

// Rows of K restricted to the columns D, by rows, on every rank (a dense R x nD copy was 54 MB a rank on hertz3d's
// default mesh, zeroed on every Kacanov iterate only to be scanned for its nonzeros).
PetscErrorCode GatherRowsOnDofs(Mat K, const std::vector<PetscInt> &D, SparseRows *KD)
{
  MPI_Comm    comm = PetscObjectComm((PetscObject)K);
  PetscInt    R, rstart, rend;
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(MatGetSize(K, &R, NULL));
  PetscCall(MatGetOwnershipRange(K, &rstart, &rend));
  std::vector<PetscInt>  count((size_t)(rend - rstart), 0), col;
  std::vector<PetscReal> val;
  for (PetscInt r = rstart; r < rend; ++r) {
    PetscInt           nc;
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscCall(MatGetRow(K, r, &nc, &cols, &vals));
    for (PetscInt k = 0; k < nc; ++k) {
      if (PetscRealPart(vals[k]) == 0.0) continue;
      const auto it = std::lower_bound(D.begin(), D.end(), cols[k]);
      PetscCheck(it != D.end() && *it == cols[k], PETSC_COMM_SELF, PETSC_ERR_PLIB, "Constraint column %" PetscInt_FMT " outside the contact dofs", cols[k]);
      col.push_back((PetscInt)(it - D.begin())); // AIJ rows: columns unique and ascending, so are their positions in D
      val.push_back(PetscRealPart(vals[k]));
      ++count[r - rstart];
    }
    PetscCall(MatRestoreRow(K, r, &nc, &cols, &vals));
  }
  std::vector<int> rowsOf(size), rowDispl(size, 0), nnzOf(size), nnzDispl(size, 0);
  int              nrow = (int)count.size(), nnz = (int)col.size();
  PetscCallMPI(MPI_Allgather(&nrow, 1, MPI_INT, rowsOf.data(), 1, MPI_INT, comm));
  PetscCallMPI(MPI_Allgather(&nnz, 1, MPI_INT, nnzOf.data(), 1, MPI_INT, comm));
  for (int q = 1; q < size; ++q) {
    rowDispl[q] = rowDispl[q - 1] + rowsOf[q - 1];
    nnzDispl[q] = nnzDispl[q - 1] + nnzOf[q - 1];
  }
  const size_t total = (size_t)nnzDispl[size - 1] + (size_t)nnzOf[size - 1];
  std::vector<PetscInt> all((size_t)R);
  KD->rows = R;
  KD->cols = (PetscInt)D.size();
  KD->col.resize(total);
  KD->val.resize(total);
  PetscCallMPI(MPI_Allgatherv(count.data(), nrow, MPIU_INT, all.data(), rowsOf.data(), rowDispl.data(), MPIU_INT, comm));
  PetscCallMPI(MPI_Allgatherv(col.data(), nnz, MPIU_INT, KD->col.data(), nnzOf.data(), nnzDispl.data(), MPIU_INT, comm));
  PetscCallMPI(MPI_Allgatherv(val.data(), nnz, MPIU_REAL, KD->val.data(), nnzOf.data(), nnzDispl.data(), MPIU_REAL, comm));
  KD->ptr.assign((size_t)R + 1, 0);
  for (PetscInt i = 0; i < R; ++i) KD->ptr[i + 1] = KD->ptr[i] + all[i];
  PetscFunctionReturn(0);
}

// Values of a global vector at the global indices D, on every rank.
static PetscErrorCode GatherAt(Vec v, const std::vector<PetscInt> &D, std::vector<PetscReal> *out)
{
  IS         is;
  Vec        loc;
  VecScatter sc;

  PetscFunctionBeginUser;
  PetscCall(ISCreateGeneral(PETSC_COMM_SELF, (PetscInt)D.size(), D.data(), PETSC_COPY_VALUES, &is));
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, (PetscInt)D.size(), &loc));
  PetscCall(VecScatterCreate(v, is, loc, NULL, &sc));
  PetscCall(VecScatterBegin(sc, v, loc, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(sc, v, loc, INSERT_VALUES, SCATTER_FORWARD));
  const PetscScalar *a;
  PetscCall(VecGetArrayRead(loc, &a));
  out->assign(D.size(), 0.0);
  for (size_t i = 0; i < D.size(); ++i) (*out)[i] = PetscRealPart(a[i]);
  PetscCall(VecRestoreArrayRead(loc, &a));
  PetscCall(VecScatterDestroy(&sc));
  PetscCall(VecDestroy(&loc));
  PetscCall(ISDestroy(&is));
  PetscFunctionReturn(0);
}

// At u = 0: the weighted gaps g_i / weight_i < 0 beyond rounding are an initial overlap (the deepest, where, how many).
PetscErrorCode KacanovSolver::MeasureInitialOverlap(MPI_Comm comm, const ContactMap &map)
{
  std::vector<PetscReal> g, w, x[3], nm[3], ns[3];

  PetscFunctionBeginUser;
  initialPenetration = 0;
  initialPenetrating = 0;
  PetscCall(GatherVec(sys.g, &g));
  PetscCall(GatherVec(sys.weight, &w));
  PetscInt dim = 0;
  for (; dim < 3 && sys.coord[dim]; ++dim) PetscCall(GatherVec(sys.coord[dim], &x[dim]));
  PetscReal scale = 0; // size of the slave surface: the rounding level of a gap
  for (PetscInt d = 0; d < dim; ++d)
    for (PetscReal c : x[d]) scale = std::max(scale, std::abs(c));
  // a master that faces away from the slave (the far side of the master body, -contact_master block_bottom on
  // sphere_block3d: "an interference fit by 3.1", solved to an energy 8e4 times the right one, exit 0): the slave nodes
  // behind it see master facets whose outward normal points the way their own does, where an interference fit's face each
  // other (the slave inside the master body)
  for (PetscInt d = 0; d < dim; ++d) PetscCall(GatherVec(sys.normal[d], &nm[d]));
  PetscCall(map.SlaveOutwardNormals(comm, ns));
  PetscInt  away = 0;
  PetscReal awayDepth = 0, lo[3] = {PETSC_MAX_REAL, PETSC_MAX_REAL, PETSC_MAX_REAL}, hi[3] = {-PETSC_MAX_REAL, -PETSC_MAX_REAL, -PETSC_MAX_REAL}, span = 0;
  for (PetscInt d = 0; d < dim; ++d)
    for (PetscReal c : x[d]) {
      lo[d] = std::min(lo[d], c);
      hi[d] = std::max(hi[d], c);
    }
  for (PetscInt d = 0; d < dim; ++d) span += g.empty() ? 0 : (hi[d] - lo[d]) * (hi[d] - lo[d]);
  span = std::sqrt(span); // the slave surface's bounding-box diagonal
  for (size_t i = 0; i < g.size(); ++i) {
    if (!(w[i] > 0)) continue;
    const PetscReal gap = g[i] / w[i];
    if (gap < -1e-9 * std::max<PetscReal>(scale, 1e-300)) {
      ++initialPenetrating;
      if (-gap > initialPenetration) {
        initialPenetration = -gap;
        for (PetscInt d = 0; d < dim; ++d) initialPenetrationAt[d] = x[d][i];
      }
      PetscReal dot = 0, a = 0, b = 0;
      for (PetscInt d = 0; d < dim; ++d) {
        dot += nm[d][i] * ns[d][i];
        a += nm[d][i] * nm[d][i];
        b += ns[d][i] * ns[d][i];
      }
      if (a > 0 && b > 0 && dot > 0.5 * std::sqrt(a * b)) { // within 60 degrees of the same direction
        ++away;
        awayDepth = std::max(awayDepth, -gap);
      }
    }
  }
  // most of the nodes behind the master (not a few where an interference fit's surfaces curve away)
  PetscCheck(!(away > 0 && 2 * away >= initialPenetrating), comm, PETSC_ERR_USER_INPUT,
             "the master surface '%s' (-contact_master) faces away from the slave surface '%s': before any deformation %" PetscInt_FMT " of the slave nodes (of %" PetscInt_FMT " behind it, up to %g deep, where the slave surface spans %g) lie behind master facets whose outward normal points the same way as the slave's own outward normal, so the slave is on the side of the master body that surface does not bound; this is not an interference fit (where the two surfaces face each other): name with -contact_master the surface of the master body that faces the slave",
             map.MasterName().c_str(), map.SlaveName().c_str(), away, initialPenetrating, (double)awayDepth, (double)span);
  PetscFunctionReturn(0);
}

// -fom_dual_matrix auto: dense while R <= -fom_dual_dense_max and the contact dofs (the rows of the dense
// compliance G and of the Schur complement behind it) <= -fom_dual_dense_max_dofs, else saddle; D: the
// contact dofs (empty unless dense). Collective.
PetscErrorCode KacanovSolver::ChooseDualMatrix(MPI_Comm comm, const ContactMap &map, std::string *mode, std::vector<PetscInt> *D) const
{
  PetscFunctionBeginUser;
  D->clear();
  *mode = dualMatrixOption;
  if (*mode == "auto" && map.NumMultipliers() > dualDenseMax) *mode = "saddle";
  if (*mode == "auto" || *mode == "dense") PetscCall(map.SurfaceDofs(comm, D));
  contactDofs = D->empty() ? -1 : (PetscInt)D->size();
  if (*mode == "auto") *mode = (PetscInt)D->size() > dualDenseMaxDofs ? "saddle" : "dense";
  if (*mode != "dense") D->clear();
  PetscFunctionReturn(0);
}

PetscErrorCode KacanovSolver::ShareFactor(ElasticFOM &fom, const ContactMap &map) const
{
  std::vector<PetscInt> D;
  std::string           mode;

  PetscFunctionBeginUser;
  PetscCall(ChooseDualMatrix(PetscObjectComm((PetscObject)fom.dm), map, &mode, &D));
  fom.SetSchurDofs(D);
  PetscCall(fom.SetFactorless(mode == "saddle", saddle_.solver == "gamg"));
  PetscFunctionReturn(0);
}

PetscErrorCode KacanovSolver::Solve(ElasticFOM &fom, ContactMap &map)
{
  MPI_Comm       comm = PetscObjectComm((PetscObject)fom.dm);
  Vec            u0, uprev, uloc, usurf, lamPrev = nullptr, tmp, rhs;
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  history = KacanovHistory();
  converged = PETSC_FALSE;
  qpUnsolved_ = qpUnsolvedFirst_ = 0;
  qpUnsolvedWorst_ = 0;
  // Elastic solution u0 = A^{-1} f (solve time)
  PetscCall(PetscTime(&t0));
  std::vector<PetscInt> D;
  std::string           mode;
  PetscCall(ChooseDualMatrix(comm, map, &mode, &D));
  const bool saddle = mode == "saddle", shell = mode == "shell", distributed = saddle || shell;
  PetscCall(VecDuplicate(fom.f, &u0));
  if (!saddle) PetscCall(fom.ApplyInverse(fom.f, u0)); // the saddle point needs no A^{-1} f (nor A's factor)
  PetscCall(PetscTime(&t1));
  fom.times.solve += t1 - t0;
  PetscCall(VecDuplicate(u0, &uprev));
  PetscCall(VecDuplicate(u0, &tmp));
  PetscCall(VecDuplicate(u0, &rhs));
  PetscCall(VecSet(uprev, 0.0));
  PetscCall(DMCreateLocalVector(fom.dm, &uloc));
  PetscCall(VecDuplicate(u0, &usurf)); // u on the contact dofs (dense dual matrix), zero elsewhere
  PetscCall(VecSet(usurf, 0.0));
  std::vector<PetscReal> uDprev, lamWarm, mixed; // the input u_D of the iterate, the previous multipliers (QP warm start)
  PetscCall(VecSet(uloc, 0.0)); // u^0 = 0: the reference configuration
  // Dual Hessian: dense S through the compliance of the contact dofs (once per parameter: every
  // iterate's S = K_D G K_D^T costs dense operations only), or a MATSHELL with no compliance at all.
  const PetscInt R0 = map.NumMultipliers();
  PetscCall(PetscTime(&t0));
  std::vector<PetscReal> u0D;
  dualMatrix = mode;
  if (saddle) saddle_.NewOperator();
  if (saddle && saddle_.WantsNearNullSpace()) { // for GAMG on a PCFIELDSPLIT's u block
    MatNullSpace nsp;
    PetscCall(fom.elas.NearNullSpace(&nsp));
    PetscCall(saddle_.SetNearNullSpace(nsp));
    PetscCall(MatNullSpaceDestroy(&nsp));
  }
  if (!distributed) {
    PetscCall(compliance.Compute(fom, D));
    PetscCall(GatherAt(u0, D, &u0D));
  }
  PetscCall(PetscTime(&t1));
  fom.times.contact += t1 - t0;
  const PetscBLASInt nD = (PetscBLASInt)D.size();
  loop.Begin(distributed ? 0 : (PetscInt)nD); // the shell and saddle paths keep their state distributed: they record their own changes
  mixed.assign(nD, 0.0);
  // -kacanov_type newton: dense dual matrix and 2D (the contact geometry's derivative); plain Kacanov otherwise
  const bool             newton = type == "newton" && !distributed && fom.elas.dim == 2;
  std::vector<PetscReal> image, relaxed, newtonNext; // F(x), the relaxed image, the Newton step's input
  PetscReal              duPrev = kInf;             // the previous iterate's change (Newton: a step that made it grow is not repeated)
  bool                   lastNewton = false;
  newtonSteps = 0;
  // the contact dofs' values x (on D, every rank) into the distributed usurf
  auto setSurface = [&](const std::vector<PetscReal> &x) -> PetscErrorCode {
    PetscInt     lo, hi;
    PetscScalar *us;
    PetscFunctionBeginUser;
    PetscCall(VecGetOwnershipRange(usurf, &lo, &hi));
    PetscCall(VecGetArray(usurf, &us));
    for (PetscBLASInt j = 0; j < nD; ++j)
      if (D[j] >= lo && D[j] < hi) us[D[j] - lo] = x[j];
    PetscCall(VecRestoreArray(usurf, &us));
    PetscFunctionReturn(0);
  };
  // SetInitialGuess: the overlap measured at the reference configuration (as without a guess), then the first
  // geometry at the guess, the multipliers and the QP's start from it, the first changes measured from both
  const bool guessed = uInit_ != nullptr;
  if (guessed) {
    PetscInt nu, ng, nl, nr;
    PetscCall(PetscTime(&t0));
    PetscCall(PetscLogEventBegin(KAC_Assemble, 0, 0, 0, 0));
    PetscCall(map.Assemble(fom.elas, uloc, &sys));
    PetscCall(PetscLogEventEnd(KAC_Assemble, 0, 0, 0, 0));
    PetscCall(MeasureInitialOverlap(comm, map));
    if (!lambda) {
      PetscCall(MatCreateVecs(sys.K, NULL, &lambda));
      PetscCall(PetscObjectSetName((PetscObject)lambda, "lambda"));
    }
    PetscCall(VecGetSize(uInit_, &ng));
    PetscCall(VecGetSize(fom.u, &nu));
    PetscCall(VecGetSize(lamInit_, &nl));
    PetscCall(VecGetSize(lambda, &nr));
    PetscCheck(ng == nu && nl == nr, comm, PETSC_ERR_ARG_SIZ, "KacanovSolver: initial guess of %" PetscInt_FMT " dofs and %" PetscInt_FMT " multipliers for a problem of %" PetscInt_FMT " and %" PetscInt_FMT, ng, nl, nu, nr);
    PetscCall(VecCopy(lamInit_, lambda));
    PetscCall(VecDuplicate(lambda, &lamPrev));
    PetscCall(VecCopy(lambda, lamPrev));
    if (distributed) {
      PetscCall(VecCopy(uInit_, uprev));
      PetscCall(fom.elas.GlobalToLocalWithBC(uInit_, uloc));
      if (saddle) PetscCall(saddle_.SetActiveSet(lambda));
    } else {
      PetscCall(GatherAt(uInit_, D, &uDprev));
      PetscCall(setSurface(uDprev));
      PetscCall(fom.elas.GlobalToLocalWithBC(usurf, uloc));
      PetscCall(GatherVec(lambda, &lamWarm));
    }
    PetscCall(VecDestroy(&uInit_));
    PetscCall(VecDestroy(&lamInit_));
    PetscCall(PetscTime(&t1));
    fom.times.contact += t1 - t0;
  }
  if (loop.monitor) {
    if (distributed) PetscCall(PetscPrintf(comm, "  Kacanov: R = %" PetscInt_FMT " multipliers, %" PetscInt_FMT " contact dofs (-1: not counted), dual matrix %s (-fom_dual_matrix %s, -fom_dual_dense_max %" PetscInt_FMT ", -fom_dual_dense_max_dofs %" PetscInt_FMT ")\n", R0, contactDofs, mode.c_str(), dualMatrixOption.c_str(), dualDenseMax, dualDenseMaxDofs));
    else PetscCall(PetscPrintf(comm, "  Kacanov: R = %" PetscInt_FMT " multipliers, dual matrix dense, %d contact dofs, compliance by %s in %.3f s\n", R0, (int)nD, compliance.method.c_str(), (double)compliance.seconds));
  }

  for (PetscInt k = 1; k <= loop.maxIt; ++k) {
    SparseRows             KD;
    std::vector<PetscReal> T, Sfull, gfull, bfull, lam;
    PetscInt               nact = 0;
    PetscCall(PetscTime(&t0));
    PetscCall(PetscLogEventBegin(KAC_Assemble, 0, 0, 0, 0));
    PetscCall(map.Assemble(fom.elas, uloc, &sys));
    PetscCall(PetscLogEventEnd(KAC_Assemble, 0, 0, 0, 0));
    if (k == 1 && !guessed) PetscCall(MeasureInitialOverlap(comm, map));
    const PetscBool warm = lambda ? PETSC_TRUE : PETSC_FALSE;
    if (!lambda) {
      PetscCall(MatCreateVecs(sys.K, NULL, &lambda));
      PetscCall(PetscObjectSetName((PetscObject)lambda, "lambda"));
      PetscCall(VecSet(lambda, 0.0));
    }
    if (saddle) {
      // the QP on the saddle point: to convergence of the active set on the first iterate, then one
      // active-set step per iterate (the set and the geometry converge together; docs/contact.md)
      PetscCall(PetscLogEventBegin(KAC_QP, 0, 0, 0, 0));
      // -fom_saddle_rtol_forcing: the saddle point to a tolerance tied to the last change of u (1 on the first
      // iterate), exactly once that change is within 100x of -kacanov_rtol_primal
      const PetscReal change = k == 1 ? 1.0 : duPrev > 100 * loop.rtolPrimal ? duPrev : 0.0;
      PetscCall(saddle_.Solve(fom.A, fom.f, sys.K, sys.g, warm, k == 1 ? PETSC_TRUE : PETSC_FALSE, fom.u, lambda, &lastSaddle, change));
      PetscCall(PetscLogEventEnd(KAC_QP, 0, 0, 0, 0));
      nact = lastSaddle.nactive;
      history.dualSteps.push_back(lastSaddle.steps);
      history.factorizations.push_back(lastSaddle.factorizations);
      history.krylov.push_back(lastSaddle.krylov);
    } else if (shell) {
      // b = K u0 - g; lambda (the previous iterate's multipliers) is the warm start
      Vec b;
      PetscCall(VecDuplicate(sys.g, &b));
      PetscCall(MatMult(sys.K, u0, b));
      PetscCall(VecAXPY(b, -1.0, sys.g));
      PetscCall(PetscLogEventBegin(KAC_QP, 0, 0, 0, 0));
      PetscCall(shell_.Solve(fom, sys.K, b, lambda, warm, &lastShell));
      PetscCall(PetscLogEventEnd(KAC_QP, 0, 0, 0, 0));
      PetscCall(VecDestroy(&b));
      const PetscScalar *la;
      PetscInt           nloc;
      PetscCall(VecGetLocalSize(lambda, &nloc));
      PetscCall(VecGetArrayRead(lambda, &la));
      for (PetscInt i = 0; i < nloc; ++i) if (PetscRealPart(la[i]) > 0) ++nact;
      PetscCall(VecRestoreArrayRead(lambda, &la));
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &nact, 1, MPIU_INT, MPI_SUM, comm));
      history.dualSteps.push_back(lastShell.pdasIterations);
      history.dualCG.push_back(lastShell.cgIterations);
    } else {
    // S = K_D G K_D^T, b = K_D u0_D - g
    PetscCall(PetscLogEventBegin(KAC_Schur, 0, 0, 0, 0));
    const PetscBLASInt R = (PetscBLASInt)sys.R;
    PetscCall(GatherRowsOnDofs(sys.K, D, &KD));
    PetscCall(GatherVec(sys.g, &gfull));
    // K_D is sparse (a row touches the dofs of a few facets): T = G K_D^T and S = K_D T by its
    // nonzeros, O(nD nnz + R nnz) instead of dense products
    T.assign((size_t)nD * R, 0.0);
    Sfull.assign((size_t)R * R, 0.0);
    for (PetscInt i = 0; i < R; ++i)
      for (PetscInt e = KD.ptr[i]; e < KD.ptr[i + 1]; ++e) {
        const PetscReal *g = &compliance.G[(size_t)KD.col[e] * nD];
        PetscReal       *t = &T[(size_t)i * nD];
        const PetscReal  k = KD.val[e];
        for (PetscInt q = 0; q < nD; ++q) t[q] += g[q] * k;
      }
    for (PetscInt j = 0; j < R; ++j)
      for (PetscInt i = 0; i < R; ++i) {
        PetscReal v = 0;
        for (PetscInt e = KD.ptr[i]; e < KD.ptr[i + 1]; ++e) v += KD.val[e] * T[(size_t)j * nD + KD.col[e]];
        Sfull[i + (size_t)j * R] = v;
      }
    for (PetscInt i = 0; i < R; ++i)
      for (PetscInt j = 0; j < R; ++j)
        if (j > i) Sfull[i + (size_t)j * R] = Sfull[j + (size_t)i * R] = 0.5 * (Sfull[i + (size_t)j * R] + Sfull[j + (size_t)i * R]);
    bfull.assign(R, 0.0);
    for (PetscInt i = 0; i < R; ++i) {
      PetscReal v = -gfull[i];
      for (PetscInt e = KD.ptr[i]; e < KD.ptr[i + 1]; ++e) v += KD.val[e] * u0D[KD.col[e]];
      bfull[i] = v;
    }
    PetscCall(PetscLogEventEnd(KAC_Schur, 0, 0, 0, 0));
    PetscCall(PetscLogEventBegin(KAC_QP, 0, 0, 0, 0));
    PetscCall(qp_.Solve(sys.R, Sfull, bfull, &lam, &lastQP, lamWarm.empty() ? nullptr : &lamWarm));
    if (!(lastQP.kkt <= kktTol)) { // not solved: named if the loop fails (QPCause), where it was blamed on the fixed point
      if (!qpUnsolved_++) {
        qpUnsolvedFirst_ = k;
        qpUnsolvedInfo_  = lastQP;
      }
      qpUnsolvedWorst_ = std::max(qpUnsolvedWorst_, lastQP.kkt);
    }
    lamWarm = lam;
    PetscCall(PetscLogEventEnd(KAC_QP, 0, 0, 0, 0));
    {
      PetscInt     lo, hi;
      PetscScalar *la;
      PetscCall(VecGetOwnershipRange(lambda, &lo, &hi));
      PetscCall(VecGetArray(lambda, &la));
      for (PetscInt i = lo; i < hi; ++i) la[i - lo] = lam[i];
      PetscCall(VecRestoreArray(lambda, &la));
    }
    for (PetscReal l : lam) if (l > 0) ++nact;
    }
    PetscCall(PetscTime(&t1));
    fom.times.contact += t1 - t0;
    // u = A^{-1} (f - K^T lambda) = u0 - A^{-1} K^T lambda. Dense dual matrix: only the contact dofs
    // are needed for the next geometry, u_D = u0_D - G K_D^T lambda (G = (A^{-1})_DD), and the
    // whole field is solved for once, after the loop. Shell: one back-solve per iterate.
    PetscCall(MatMultTranspose(sys.K, lambda, rhs));
    PetscCall(VecAYPX(rhs, -1.0, fom.f));
    PetscReal du, nl, nlp = 0, ndl;
    if (distributed) {
      PetscReal nu, nup, ndu;
      if (shell) PetscCall(fom.ApplyInverse(rhs, fom.u)); // saddle: u came with lambda
      if (loop.relaxation < 1) PetscCall(VecAXPBY(fom.u, 1 - loop.relaxation, loop.relaxation, uprev));
      PetscCall(VecNorm(fom.u, NORM_2, &nu));
      PetscCall(VecNorm(uprev, NORM_2, &nup));
      PetscCall(VecWAXPY(tmp, -1.0, uprev, fom.u));
      PetscCall(VecNorm(tmp, NORM_2, &ndu));
      du = KacanovLoop::RelChange(ndu, nup, nu);
    } else {
      const PetscBLASInt R = (PetscBLASInt)sys.R, one = 1;
      const PetscScalar  m1 = -1.0, p1 = 1.0;
      std::vector<PetscReal> w(nD, 0.0); // K_D' lambda
      for (PetscBLASInt i = 0; i < R; ++i)
        for (PetscInt e = KD.ptr[i]; e < KD.ptr[i + 1]; ++e) w[KD.col[e]] += KD.val[e] * lam[i];
      std::vector<PetscReal> uD(u0D);
      if (nD) BLASgemv_("N", &nD, &nD, &m1, compliance.G.data(), &nD, w.data(), &one, &p1, uD.data(), &one);
      if (uDprev.empty()) uDprev.assign(nD, 0.0);
      if (newton) image = uD; // F(x) before the relaxation: the Newton step's right-hand side F(x) - x
      du = loop.Relax(uDprev.data(), uD.data()); // the relaxed image and the change of the input
      if (newton) relaxed = uD; // the plain next input; Newton's is chosen after the stopping test
      else {
        // the next geometry: u_D itself, or Anderson's mix of this input (uDprev) and its image (uD)
        loop.Next(uDprev.data(), uD.data(), mixed.data());
        uDprev = mixed;
        PetscCall(setSurface(uDprev));
      }
    }
    PetscCall(PetscTime(&t0));
    fom.times.solve += t0 - t1;

    // Relative changes (of u on the contact dofs with the dense dual matrix, of the whole u with the shell)
    PetscCall(VecNorm(lambda, NORM_2, &nl));
    if (lamPrev) {
      PetscCall(VecNorm(lamPrev, NORM_2, &nlp));
      PetscCall(VecAXPY(lamPrev, -1.0, lambda));
      PetscCall(VecNorm(lamPrev, NORM_2, &ndl));
    } else ndl = nl;
    // The change of lambda relative to max(|lambda_prev|, 1e-6 |A u| / |K|_F): |A u| / |K|_F is the size of a
    // multiplier whose force matches the elastic forces. The floor matters only when lambda is at rounding
    // level (grazing contact: a rigid body touching at one node, lambda ~ 1e-16 changing by 100 % between
    // iterates, never converging relatively); real contact forces are far above it (ring_on_block: |lambda|
    // is 0.25 |A u| / |K|_F), and there the rule is the plain relative one.
    PetscReal nrhs, nK;
    PetscCall(VecNorm(rhs, NORM_2, &nrhs));
    PetscCall(MatNorm(sys.K, NORM_FROBENIUS, &nK));
    const PetscReal lamScale = nK > 0 ? 1e-6 * nrhs / nK : 0.0;
    // (the multipliers of two relaxed inputs: their change scales with the relaxation, so it is taken back out, as
    // KacanovLoop::Relax measures the primal residual before the relaxation)
    const PetscReal dl = lamPrev ? KacanovLoop::RelChange(ndl / loop.relaxation, std::max(nlp, lamScale), nl) : (nl == 0 && lamScale == 0 ? 0.0 : kInf);
    iterations = k;
    char detail[320] = "";
    if (loop.monitor && saddle)
      std::snprintf(detail, sizeof detail, "saddle: active-set steps %" PetscInt_FMT "%s, %" PetscInt_FMT " rows to change, %.2f s", lastSaddle.steps, lastSaddle.symbolic ? " (new pattern)" : "", lastSaddle.changed, (double)lastSaddle.seconds);
    else if (loop.monitor && shell)
      std::snprintf(detail, sizeof detail, "dual shell: TAO its %" PetscInt_FMT " (%" PetscInt_FMT " products), active-set steps %" PetscInt_FMT ", CG its %" PetscInt_FMT ", S products %" PetscInt_FMT ", free-set residual %.2e, kkt %.2e", lastShell.taoIterations, lastShell.taoProducts, lastShell.pdasIterations, lastShell.cgIterations, lastShell.products, (double)lastShell.residual, (double)lastShell.kkt);
    else if (loop.monitor) std::snprintf(detail, sizeof detail, "QP: tao its %" PetscInt_FMT ", polish %" PetscInt_FMT ", kkt %.2e", lastQP.taoIterations, lastQP.polishIterations, (double)lastQP.kkt);
    bool done = false;
    PetscCall(loop.Record(comm, k, du, dl, nact, sys.R, detail, &done));
    if (saddle && lastSaddle.changed) done = false; // the set moved: this K, g's QP is not solved yet
    if (saddle && !lastSaddle.exact) done = false;  // solved to a forcing tolerance: the next iterate solves exactly
    if (!lamPrev) PetscCall(VecDuplicate(lambda, &lamPrev));
    PetscCall(VecCopy(lambda, lamPrev));
    if (distributed) PetscCall(VecCopy(fom.u, uprev));
    if (done) {
      converged = PETSC_TRUE;
      break;
    }
    if (newton) {
      // Newton step on x = F(x) (kacanov_newton.cpp) from this iterate's input uDprev; the plain (relaxed)
      // image when the step is refused or when the last Newton step made the change grow
      KacanovNewtonInfo ni;
      if (lastNewton && du > duPrev) ni.reason = "the last Newton step increased |F(x) - x| / |x|";
      else {
        ContactTangent tan;
        bool           supported = false;
        PetscCall(PetscLogEventBegin(KAC_Assemble, 0, 0, 0, 0));
        PetscCall(map.AssembleTangent(comm, lam, D, image, &tan, &supported));
        PetscCall(PetscLogEventEnd(KAC_Assemble, 0, 0, 0, 0));
        if (!supported) ni.reason = "no tangent of the contact geometry (3D, or a point on too many dofs)";
        else {
          KacanovNewtonData in;
          in.D   = &D;
          in.R   = sys.R;
          in.G   = compliance.G.data();
          in.KD  = &KD;
          in.T   = T.data();
          in.S   = Sfull.data();
          in.lam = lam.data();
          in.tan = &tan;
          in.x   = uDprev.data();
          in.Fx  = image.data();
          PetscCall(KacanovNewtonStep(in, newtonMaxRatio, &newtonNext, &ni));
        }
      }
      if (loop.monitor) {
        if (ni.accepted) PetscCall(PetscPrintf(comm, "        Newton step: |dx|/|F(x)-x| %.3f, %" PetscInt_FMT " active rows, %" PetscInt_FMT " geometric dofs\n", (double)ni.ratio, ni.active, ni.columns));
        else PetscCall(PetscPrintf(comm, "        plain step (%s)\n", ni.reason.c_str()));
      }
      lastNewton = ni.accepted;
      newtonSteps += ni.accepted ? 1 : 0;
      history.newton.push_back(ni.accepted ? 1 : 0);
      uDprev = ni.accepted ? newtonNext : relaxed;
      PetscCall(setSurface(uDprev));
    }
    duPrev = du;
    PetscCall(fom.elas.GlobalToLocalWithBC(distributed ? fom.u : usurf, uloc));
  }
  if (!distributed) { // the whole field at the last multipliers: u = A^{-1} (f - K^T lambda)
    PetscCall(PetscTime(&t0));
    PetscCall(fom.ApplyInverse(rhs, fom.u));
    PetscCall(PetscTime(&t1));
    fom.times.solve += t1 - t0;
  }
  PetscCall(VecDestroy(&u0));
  PetscCall(VecDestroy(&rhs));
  PetscCall(VecDestroy(&uprev));
  PetscCall(VecDestroy(&tmp));
  PetscCall(VecDestroy(&uloc));
  PetscCall(VecDestroy(&usurf));
  PetscCall(VecDestroy(&lamPrev));
  history.du      = loop.history.du;
  history.dl      = loop.history.dl;
  history.nactive = loop.history.nactive;
  if (!converged) {
    std::ostringstream o; // (a gross initial overlap failed with the relaxation hint alone)
    if (initialPenetrating > 0) o << "; the bodies overlapped before any load: " << initialPenetrating << " slave points inside the master, by up to " << initialPenetration << " (the mesh or -mesh_geo_set / the maps put them through each other?)";
    const std::string qp = QPCause(); // (a QP that was not solved failed with the relaxation hint alone)
    SETERRQ(comm, PETSC_ERR_NOT_CONVERGED, "%s", loop.NotConverged(true, qp + o.str(), qp.empty()).c_str());
  }

  PetscCall(ComputeKKT(fom));
  PetscCheck(kkt.Max() <= kktTol, comm, PETSC_ERR_NOT_CONVERGED, "Contact solve rejected: scaled KKT residuals primal %.3e, dual %.3e, complementarity %.3e, stationarity %.3e exceed -fom_kkt_tol %.1e%s", (double)kkt.primal, (double)kkt.dual, (double)kkt.complementarity, (double)kkt.stationarity, (double)kktTol, QPCause().c_str());
  PetscFunctionReturn(0);
}

// Mean facet size of the slave facets with a vertex in the active zone (bounding box of the active rows, grown
// by 1 %) and of the master facets whose centroid lies in that box grown by the slave size: a master clearly
// coarser than the slave there (> 2x) makes the pressure oscillate node to node (docs/contact.md).
static PetscErrorCode MeshRatioWarning(MPI_Comm comm, const ContactMap &map, const std::vector<PetscReal> x[], const std::vector<PetscReal> &lam, std::vector<std::string> *warnings)
{
  const PetscInt         dim = map.Slave().dim;
  PetscReal              lo[3] = {PETSC_MAX_REAL, PETSC_MAX_REAL, PETSC_MAX_REAL}, hi[3] = {-PETSC_MAX_REAL, -PETSC_MAX_REAL, -PETSC_MAX_REAL};
  bool                   any = false;

  PetscFunctionBeginUser;
  for (size_t i = 0; i < lam.size(); ++i)
    if (lam[i] > 0) {
      any = true;
      for (PetscInt d = 0; d < dim; ++d) {
        lo[d] = std::min(lo[d], x[d][i]);
        hi[d] = std::max(hi[d], x[d][i]);
      }
    }
  if (!any) PetscFunctionReturn(0);
  PetscReal diam = 0;
  for (PetscInt d = 0; d < dim; ++d) diam = std::max(diam, hi[d] - lo[d]);
  auto inside = [&](const PetscReal *p, PetscReal grow) {
    for (PetscInt d = 0; d < dim; ++d)
      if (p[d] < lo[d] - grow || p[d] > hi[d] + grow) return false;
    return true;
  };
  PetscReal sum[4] = {0, 0, 0, 0}; // slave size sum, count, master size sum, count
  for (const auto &F : map.Slave().facets) {
    bool in = false;
    for (PetscInt k = 0; k < F.nv && !in; ++k) in = inside(&F.X[k * dim], 0.01 * diam);
    if (in) {
      sum[0] += std::pow(FacetMeasure(F.X.data(), dim), 1.0 / (dim - 1));
      sum[1] += 1;
    }
  }
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, sum, 2, MPIU_REAL, MPIU_SUM, comm));
  if (sum[1] == 0) PetscFunctionReturn(0);
  const PetscReal hs = sum[0] / sum[1];
  for (const auto &F : map.Master().facets) {
    PetscReal c[3] = {0, 0, 0};
    for (PetscInt k = 0; k < F.nv; ++k)
      for (PetscInt d = 0; d < dim; ++d) c[d] += F.X[k * dim + d] / F.nv;
    if (inside(c, hs)) {
      sum[2] += std::pow(FacetMeasure(F.X.data(), dim), 1.0 / (dim - 1));
      sum[3] += 1;
    }
  }
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, sum + 2, 2, MPIU_REAL, MPIU_SUM, comm));
  if (sum[3] == 0) PetscFunctionReturn(0);
  const PetscReal hm = sum[2] / sum[3];
  if (hm > 2 * hs) {
    std::ostringstream o;
    o.precision(3);
    o << "the master surface is " << hm / hs << "x coarser than the slave in the contact zone (facet sizes " << hm << " and " << hs
      << "): the contact pressure oscillates node to node and its peak is overestimated; mesh the master at least as fine as the slave (docs/contact.md)";
    warnings->push_back(o.str());
  }
  PetscFunctionReturn(0);
}

// "(x, y)" or "(x, y, z)" for a message, as the stream writes each number.
static std::string Point(PetscReal x, PetscReal y, PetscReal z, PetscInt dim)
{
  std::ostringstream o;
  o << "(" << x << ", " << y;
  if (dim == 3) o << ", " << z;
  o << ")";
  return o.str();
}

std::string KacanovSolver::QPCause() const
{
  if (dualMatrix == "saddle") {
    const std::string why = saddle_.LooseSolves();
    return why.empty() ? "" : "; the cause: " + why;
  }
  if (!qpUnsolved_) return "";
  std::ostringstream o;
  const DualQPInfo  &q = qpUnsolvedInfo_;
  o << "; the cause: the contact QP (-fom_dual_matrix dense) was not solved at " << qpUnsolved_ << " of the " << iterations << " Kacanov iterates (scaled KKT residual up to " << qpUnsolvedWorst_ << " > -fom_kkt_tol " << kktTol << "; the first at iterate " << qpUnsolvedFirst_ << ": ";
  if (qp_.UsesTao()) {
    o << "TAO " << qp_.TaoType() << " stopped with " << TaoConvergedReasons[q.taoReason] << " after " << q.taoIterations << " iterations";
    if (qp_.Polish()) o << ", then the active-set polish after " << q.polishIterations << " steps";
    else o << ", kept as it is by -fom_qp_polish 0";
  } else o << "the active-set method stopped after " << q.polishIterations << " steps";
  o << "): the Kacanov iterates carry the QP's error; ";
  if (qp_.UsesTao() && !qp_.Polish()) o << "drop -fom_qp_polish 0 (the active-set polish makes TAO's answer exact), let TAO converge (-fom_qp_tao_max_it, -fom_qp_tao_gatol) or use the default -fom_qp_tao_type activeset";
  else o << "the dual matrix is too ill-conditioned for the dense QP: use -fom_dual_matrix saddle";
  return o.str();
}

PetscErrorCode ContactSurfaceWarnings(MPI_Comm comm, const KacanovSolver &kac, const ContactMap &map, std::vector<std::string> *warnings)
{
  std::vector<PetscReal> lam, x[3], n[3];
  const ContactSystem   &sys = kac.sys;
  const PetscInt         dim = map.Slave().dim;

  PetscFunctionBeginUser;
  if (kac.initialPenetrating > 0) {
    std::ostringstream o;
    o << "initial overlap: " << kac.initialPenetrating << " slave node(s) lie inside the master body before any deformation (deepest " << kac.initialPenetration << " at " << Point(kac.initialPenetrationAt[0], kac.initialPenetrationAt[1], kac.initialPenetrationAt[2], dim)
      << "); the solver pushes the bodies apart as an interference fit. If that is not meant, check the bodies' positions (the mesh, -mesh_geo_set, the geometric map at this mu)";
    warnings->push_back(o.str());
  }
  if (const auto &ms = map.MasterSearch(); ms.belowReach > 0) {
    std::ostringstream o;
    o << "-contact_master_search_margin " << map.masterSearchMargin << " is below the reach of any slave point (its distance plus 2 slave and 3 master facet diameters: at least " << ms.reach
      << " here): " << ms.belowReach << " of the " << ms.assemblies << " contact assemblies used every master facet (-contact_master_search all), as no point could be found with the facets near it; give a margin of at least " << ms.reach << ", or leave the default";
    warnings->push_back(o.str());
  }
  // gathered once for the three checks below: multipliers, their largest value, slave vertex coordinates
  PetscCall(GatherVec(kac.lambda, &lam));
  for (PetscInt d = 0; d < dim; ++d) PetscCall(GatherVec(sys.coord[d], &x[d]));
  PetscReal lmax = 0;
  for (PetscReal l : lam) lmax = std::max(lmax, l);
  auto active = [&](PetscInt r) { return lmax > 0 && lam[r] > 1e-10 * lmax; };

  PetscCall(MeshRatioWarning(comm, map, x, lam, warnings));
  { // active rows projected past an end of the master surface: contact there is measured to the end vertex
    std::vector<PetscInt> past;
    PetscCall(map.PastMasterEndRows(comm, &past));
    PetscInt nact = 0, worst = -1;
    for (PetscInt r : past)
      if (active(r)) {
        ++nact;
        if (worst < 0 || lam[r] > lam[worst]) worst = r;
      }
    if (nact > 0) {
      std::ostringstream o;
      o << "the contact zone runs past an end of the master surface: " << nact << " active slave node(s) lie beyond it (e.g. the node at " << Point(x[0][worst], x[1][worst], dim == 3 ? x[2][worst] : 0, dim) << " of the undeformed configuration, pressure " << lam[worst]
        << "); their contact is measured to the master's end vertex, not to the body beyond it: declare a larger master surface";
      warnings->push_back(o.str());
    }
  }
  const auto &ends = map.SlaveEndRows();
  const auto &next = map.SlaveEndNextNormals();
  if (ends.empty()) PetscFunctionReturn(0);
  for (PetscInt d = 0; d < dim; ++d) PetscCall(GatherVec(sys.normal[d], &n[d]));
  PetscInt nfacing = 0, worst = -1;
  for (size_t e = 0; e < ends.size(); ++e) {
    const PetscInt r = ends[e];
    // the body's boundary continuing past the end faces the master (its outward normal against the
    // master's, which points to the slave): contact there is possible but not enforced. A surface that
    // ends at a corner of its body (a flat punch's edge: the next side is parallel to the master normal) is not.
    PetscReal dot = 0;
    for (PetscInt d = 0; d < dim; ++d) dot += next[e][d] * n[d][r];
    if (dot < -0.5 && active(r)) {
      ++nfacing;
      if (worst < 0 || lam[r] > lam[worst]) worst = r;
      if (dim == 2) { // (2D: two ends at most, each named)
        std::ostringstream o;
        o << "the contact zone reaches the end of the slave surface at (" << x[0][r] << ", " << x[1][r] << ") (pressure " << lam[r] << " there, max " << lmax
          << "): contact beyond the declared surface is not enforced and the bodies may interpenetrate there; declare a larger slave (and master) surface";
        warnings->push_back(o.str());
      }
    }
  }
  if (dim == 3 && nfacing > 0) { // one warning for the edge's nodes
    std::ostringstream o;
    o << "the contact zone reaches the edge of the slave surface: " << nfacing << " active node(s) on it (e.g. at " << Point(x[0][worst], x[1][worst], x[2][worst], 3) << ", pressure " << lam[worst] << " there, max " << lmax
      << "): contact beyond the declared surface is not enforced and the bodies may interpenetrate there; declare a larger slave (and master) surface";
    warnings->push_back(o.str());
  }
  PetscFunctionReturn(0);
}

PetscErrorCode SummarizeContact(const ContactSystem &sys, Vec lambda, PetscInt dim, ContactSummary *s)
{
  std::vector<PetscReal> lam, w, n[3], x[3];

  PetscFunctionBeginUser;
  PetscCall(GatherVec(lambda, &lam));
  PetscCall(GatherVec(sys.weight, &w));
  for (PetscInt d = 0; d < dim; ++d) {
    PetscCall(GatherVec(sys.normal[d], &n[d]));
    PetscCall(GatherVec(sys.coord[d], &x[d]));
  }
  *s   = ContactSummary();
  s->R = (PetscInt)lam.size();
  PetscReal lmax = 0;
  for (PetscReal l : lam) lmax = std::max(lmax, l);
  // active: above 1e-10 of the largest multiplier (as ContactSurfaceWarnings): an interior-point QP without its
  // active-set polish (-fom_qp_polish 0) leaves values of 1e-16 to 1e-11 that counted as contact (45 active nodes for
  // 15, the half-width 3.2x; audit of 2026-12-01)
  const PetscReal athr = 1e-10 * lmax;
  for (size_t i = 0; i < lam.size(); ++i) {
    // lambda_i is the coefficient of the pressure field in the hat basis psi_i (docs/contact.md):
    // nodal pressure lambda_i, resultant int p n2 = sum_i lambda_i int psi_i n2.
    if (lam[i] > athr) ++s->nactive;
    for (PetscInt d = 0; d < dim; ++d) s->forceVec[d] += lam[i] * w[i] * n[d][i];
    s->maxPressure = std::max(s->maxPressure, lam[i]);
  }
  for (PetscInt d = 0; d < dim; ++d) s->force += s->forceVec[d] * s->forceVec[d];
  s->force = std::sqrt(s->force);
  // 3D: the contact radius from the pressure's second moment in the plane normal to the resultant,
  // a = sqrt(5/2 (int p |q|^2 / int p - |int p q / int p|^2)) (= a for Hertz's p0 sqrt(1 - r^2/a^2))
  if (dim == 3 && s->force > 0) {
    const PetscReal  nh[3] = {s->forceVec[0] / s->force, s->forceVec[1] / s->force, s->forceVec[2] / s->force};
    PressureMoments3 pm(nh);
    for (size_t i = 0; i < lam.size(); ++i) pm.Add(x[0][i], x[1][i], x[2][i], lam[i] * w[i]);
    (void)pm.Radius(&s->halfwidthMoment);
  }
  // 2D half-width: extent of the active nodes along the tangent of the mean normal, half of it.
  if (dim == 2 && s->nactive && s->force > 0) {
    const PetscReal t[2] = {-s->forceVec[1] / s->force, s->forceVec[0] / s->force};
    std::vector<std::pair<PetscReal, PetscReal>> active; // (tangent coordinate, nodal pressure)
    for (size_t i = 0; i < lam.size(); ++i)
      if (lam[i] > athr) active.emplace_back(x[0][i] * t[0] + x[1][i] * t[1], lam[i]);
    std::sort(active.begin(), active.end());
    {
      // second moment of the pressure along the tangent (exact a for p0 sqrt(1 - x^2/a^2))
      PressureMoments2 pm;
      for (size_t i = 0; i < lam.size(); ++i) pm.Add(x[0][i] * t[0] + x[1][i] * t[1], lam[i] * w[i]);
      (void)pm.HalfWidth(&s->halfwidthMoment);
    }
    s->halfwidth = 0.5 * (active.back().first - active.front().first);
    if (active.size() >= 3) {
      PetscReal pmin = PETSC_MAX_REAL, pmax = 0;
      for (size_t i = 1; i + 1 < active.size(); ++i) {
        pmin = std::min(pmin, active[i].second);
        pmax = std::max(pmax, active[i].second);
      }
      s->pressureSpread = pmin > 0 ? pmax / pmin - 1 : PETSC_INFINITY;
    }
    if (active.size() >= 5) { // interior nodes 1..n-2, second differences at 2..n-3
      PetscReal mean = 0, d2 = 0;
      for (size_t i = 1; i + 1 < active.size(); ++i) mean += active[i].second;
      mean /= (PetscReal)(active.size() - 2);
      for (size_t i = 2; i + 2 < active.size(); ++i) d2 += PetscSqr(active[i - 1].second - 2 * active[i].second + active[i + 1].second);
      s->pressureRoughness = mean > 0 ? std::sqrt(d2 / (PetscReal)(active.size() - 4)) / mean : 0;
    }
  }
  PetscFunctionReturn(0);
}

// The contact modulus E* of the scene's first two bodies: 1/E* = sum (1 - nu^2) / E.
static PetscReal ContactModulus(const SceneSpec &scene)
{
  PetscReal inv = 0;
  for (size_t b = 0; b < 2 && b < scene.bodies.size(); ++b) inv += (1 - scene.bodies[b].nu * scene.bodies[b].nu) / scene.bodies[b].E;
  return 1.0 / inv;
}

void HertzPointContact(const SceneSpec &scene, PetscReal Rs, PetscReal P, PetscReal *a, PetscReal *p0)
{
  *a  = std::cbrt(3 * P * Rs / (4 * ContactModulus(scene)));
  *p0 = 3 * P / (2 * PETSC_PI * *a * *a);
}

void HertzLineContact(const SceneSpec &scene, PetscReal Rc, PetscReal P, PetscReal *a, PetscReal *p0)
{
  *a  = std::sqrt(4 * P * Rc / (PETSC_PI * ContactModulus(scene)));
  *p0 = 2 * P / (PETSC_PI * *a);
}

} // namespace rbc
