// src/fom/elastic_fom.cpp: assembly, factorization and solve of the elastic full-order model.
#include "rbcontact/fom.hpp"
#include "rbcontact/mesh.hpp"
#include "rbcontact/partition.hpp"
#include <petscsf.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>

namespace rbc {

static PetscLogEvent FOM_Assembly = 0, FOM_Factor = 0, FOM_Solve = 0;

static PetscErrorCode RegisterEvents()
{
  PetscFunctionBeginUser;
  if (!FOM_Assembly) {
    PetscCall(PetscLogEventRegister("RBCFomAssembly", KSP_CLASSID, &FOM_Assembly));
    PetscCall(PetscLogEventRegister("RBCFomFactor", KSP_CLASSID, &FOM_Factor));
    PetscCall(PetscLogEventRegister("RBCFomSolve", KSP_CLASSID, &FOM_Solve));
  }
  PetscFunctionReturn(0);
}

ElasticFOM::~ElasticFOM()
{
  (void)MatDestroy(&schurS_);
  (void)MatDestroy(&schurFactor_);
  (void)VecDestroy(&bLocal_);
  (void)VecDestroy(&xLocal_);
  (void)KSPDestroy(&ksp);
  (void)MatDestroy(&A);
  (void)VecDestroy(&f);
  (void)VecDestroy(&u);
  (void)DMDestroy(&dm);
}

PetscErrorCode ElasticFOM::Create(MPI_Comm comm, const SceneSpec &sc)
{
  DM dmNew;

  PetscFunctionBeginUser;
  PetscCall(MeshLoad(comm, sc, &dmNew));
  PetscCall(CreateOnDM(dmNew, sc));
  PetscCall(DMDestroy(&dmNew));
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::CreateOnDM(DM dmIn, const SceneSpec &sc)
{
  PC pc;

  PetscFunctionBeginUser;
  PetscCall(RegisterEvents());
  scene = sc;
  dm    = dmIn;
  mu    = ParamValues(scene);
  PetscCall(PetscObjectReference((PetscObject)dm));
  PetscCall(map.SetFromOptions(PetscObjectComm((PetscObject)dm), scene));
  {
    PetscInt dim;
    PetscCall(DMGetDimension(dm, &dim));
    PetscCall(map.CheckDimension(PetscObjectComm((PetscObject)dm), dim));
  }
  elas.SetGeometryMap(&map);
  PetscCall(elas.Setup(dm, scene));
  PetscCall(CheckBodiesHeld());
  PetscCall(CheckBodiesApart());
  for (const auto &b : scene.bodies) // P1 locks as nu -> 1/2 (measured: nu 0.499999, contact force +52 % against P2)
    if (elas.degree == 1 && b.nu > 0.49) {
      std::ostringstream o;
      o << "body '" << b.name << "' has nu = " << b.nu << " with P1 elements: linear triangles/tetrahedra lock as nu -> 0.5 (stiffness, stresses and contact forces overestimated); use -fem_degree 2";
      PetscCall(Warn(o.str()));
    }
  PetscCall(KSPCreate(PetscObjectComm((PetscObject)dm), &ksp));
  PetscCall(KSPSetOptionsPrefix(ksp, "fom_"));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscCall(KSPSetTolerances(ksp, 1e-12, 1e-50, PETSC_DEFAULT, 10000));
  PetscCall(KSPSetFromOptions(ksp));
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::SetFactorless(bool on, bool iterative)
{
  PetscBool kset = PETSC_FALSE, pset = PETSC_FALSE;
  PC        pc;

  PetscFunctionBeginUser;
  factorless_ = on;
  if (!on || !iterative) PetscFunctionReturn(0);
  PetscCall(PetscOptionsHasName(NULL, "fom_", "-ksp_type", &kset));
  PetscCall(PetscOptionsHasName(NULL, "fom_", "-pc_type", &pset));
  if (kset || pset) PetscFunctionReturn(0); // the user's choice
  PetscCall(KSPSetType(ksp, KSPCG));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCGAMG)); // AssembleAndFactor attaches the rigid-body near-null space
  PetscCall(KSPSetTolerances(ksp, 1e-10, 1e-50, PETSC_DEFAULT, 5000));
  PetscCall(KSPSetFromOptions(ksp)); // -fom_ksp_rtol etc. still refine it
  PetscFunctionReturn(0);
}

std::string ElasticFOM::ElasticSolverName() const
{
  KSPType kt = NULL;
  PCType  pt = NULL;
  PC      pc;
  if (KSPGetType(ksp, &kt) || KSPGetPC(ksp, &pc) || PCGetType(pc, &pt)) return "unknown";
  return std::string(kt ? kt : "?") + "+" + (pt ? pt : "?");
}

PetscErrorCode ElasticFOM::SetupAffine()
{
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscCall(affine.Build(elas, &map));
  useAffine = true;
  PetscCall(PetscTime(&t1));
  times.assembly += t1 - t0;
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::SetMu(const std::vector<PetscReal> &m)
{
  PetscFunctionBeginUser;
  PetscCheck(m.size() == scene.params.size(), PetscObjectComm((PetscObject)dm), PETSC_ERR_ARG_SIZ, "Parameter vector of size %zu, the scene has %zu parameters", m.size(), scene.params.size());
  for (size_t i = 0; i < m.size(); ++i)
    PetscCheck(m[i] >= scene.params[i].min && m[i] <= scene.params[i].max, PetscObjectComm((PetscObject)dm), PETSC_ERR_ARG_OUTOFRANGE, "%s", OutOfBoxMessage(scene.params[i], m[i]).c_str());
  mu = m;
  PetscCall(elas.SetMu(mu));
  PetscFunctionReturn(0);
}

PetscInt ElasticFOM::GlobalSize() const
{
  PetscInt n = 0;
  if (f) (void)VecGetSize(f, &n);
  return n;
}

// MUMPS on several ranks schedules the factorization dynamically, so its workspace can exceed the
// analysis estimate (+ICNTL(14) percent) and the numeric phase fail with INFOG(1) = -9 -- at
// random, more often on a loaded machine (seen on 2 ranks, 3D P2). The PC then silently fails and
// the solve reports DIVERGED_PC_FAILED. Redo the factorization with a doubled ICNTL(14) (up to 4
// times; a -fom_mat_mumps_icntl_14 option overrides it and ends the retries). INFOG is global, so
// every rank sees the same factor error and takes the same branch.
static PetscErrorCode RefactorIfMumpsOutOfMemory(KSP ksp, Mat A)
{
  PC            pc;
  PetscBool     isfactor, ismumps = PETSC_FALSE;
  MatSolverType st = NULL;

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &isfactor, PCCHOLESKY, PCLU, ""));
  if (!isfactor) PetscFunctionReturn(0);
  PetscCall(PCFactorGetMatSolverType(pc, &st));
  if (st) PetscCall(PetscStrcmp(st, MATSOLVERMUMPS, &ismumps));
  if (!ismumps) PetscFunctionReturn(0);
  for (int attempt = 0; attempt < 4; ++attempt) {
    Mat            F;
    MatFactorError err;
    PetscInt       icntl14;
    PetscCall(PCFactorGetMatrix(pc, &F));
    PetscCall(MatFactorGetError(F, &err));
    if (err != MAT_FACTOR_OUTMEMORY) break;
    PetscCall(MatMumpsGetIcntl(F, 14, &icntl14));
    icntl14 = PetscMax(2 * icntl14, 50);
    PetscCall(PetscInfo(ksp, "MUMPS workspace too small (INFOG(1) = -9): refactoring with ICNTL(14) = %" PetscInt_FMT "\n", icntl14));
    PetscCall(KSPReset(ksp));
    PetscCall(KSPSetOperators(ksp, A, A));
    PetscCall(PCFactorSetUpMatSolverType(pc));
    PetscCall(PCFactorGetMatrix(pc, &F));
    PetscCall(MatMumpsSetIcntl(F, 14, icntl14));
    PetscCall(KSPSetUp(ksp));
    PetscInt used;
    PetscCall(PCFactorGetMatrix(pc, &F));
    PetscCall(MatMumpsGetIcntl(F, 14, &used));
    if (used != icntl14) break; // -fom_mat_mumps_icntl_14 given: the user's value wins, stop
  }
  PetscFunctionReturn(0);
}

// Is A without coupling between ranks (an MPIAIJ whose off-process block stores nothing on every rank:
// every body on one rank, -mesh_partitioner bodies)? Then *Ad is this rank's diagonal block. Collective.
static PetscErrorCode BlockDiagonalAcrossRanks(Mat A, PetscBool *yes, Mat *Ad)
{
  PetscBool mpiaij;
  Mat       Ao;
  PetscInt  coupled = 1;

  PetscFunctionBeginUser;
  *Ad = nullptr;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpiaij));
  if (mpiaij) {
    MatInfo  info;
    PetscInt m;
    PetscCall(MatMPIAIJGetSeqAIJ(A, Ad, &Ao, NULL));
    PetscCall(MatGetInfo(Ao, MAT_LOCAL, &info));
    PetscCall(MatGetLocalSize(A, &m, NULL));
    // (a rank without rows, -mesh_partitioner gather: its empty block's factorization failed, blamed on the Dirichlet
    // conditions; the parallel factorization takes it)
    coupled = info.nz_used > 0 || m == 0;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &coupled, 1, MPIU_INT, MPI_MAX, PetscObjectComm((PetscObject)A)));
  *yes = coupled ? PETSC_FALSE : PETSC_TRUE;
  PetscFunctionReturn(0);
}

// One MUMPS Cholesky factorization with the Schur complement on the contact dofs, when the KSP is the
// default direct solver, the compliance is the Schur one, and the run is serial or A has no coupling
// between ranks (each rank then factors its own diagonal block, sequentially, with the Schur complement on
// its part of D: no parallel factorization, no redundant copy). *done = false otherwise: the KSP factors A.
// The symbolic phase is kept across parameters (same pattern).
PetscErrorCode ElasticFOM::FactorWithSchur(bool *done)
{
  PetscMPIInt size;
  PC          pc;
  KSPType     kt;
  PetscBool   preonly, chol, mumps = PETSC_FALSE, local = PETSC_FALSE;
  MatSolverType st = NULL;
  char        m[32] = "auto";
  Mat         Afac  = A;

  PetscFunctionBeginUser;
  *done = false;
  if (schurDofs_.empty()) PetscFunctionReturn(0);
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)dm), &size));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-contact_compliance", m, sizeof m, NULL));
  if (strcmp(m, "auto") && strcmp(m, "schur")) PetscFunctionReturn(0);
  PetscCall(KSPGetType(ksp, &kt));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscStrcmp(kt, KSPPREONLY, &preonly));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCCHOLESKY, &chol));
  if (chol) PetscCall(PCFactorGetMatSolverType(pc, &st));
  if (st) PetscCall(PetscStrcmp(st, MATSOLVERMUMPS, &mumps));
  if (!preonly || !chol || !mumps) PetscFunctionReturn(0);
  if (size > 1) {
    PetscCall(BlockDiagonalAcrossRanks(A, &local, &Afac));
    if (!local) PetscFunctionReturn(0);
  }
  MatFactorInfo        info;
  MatFactorError       err;
  MatFactorSchurStatus status;
  PetscCall(MatFactorInfoInitialize(&info));
  if (schurFactor_ && factored_ != Afac) PetscCall(MatDestroy(&schurFactor_)); // a new matrix: a new symbolic phase
  if (!schurFactor_) {
    // this rank's dofs of D (all of D on one rank), in the numbering of the factored matrix
    PetscInt lo = 0, hi = PETSC_MAX_INT;
    if (local) PetscCall(MatGetOwnershipRange(A, &lo, &hi));
    std::vector<PetscInt> mine;
    for (PetscInt d : schurDofs_)
      if (d >= lo && d < hi) mine.push_back(d - lo);
    PetscCall(MatGetFactor(Afac, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &schurFactor_));
    PetscCall(MatSetOptionsPrefix(schurFactor_, "fom_")); // -fom_mat_mumps_icntl_* as for the KSP's factor
    if (!mine.empty()) {
      IS is;
      PetscCall(ISCreateGeneral(PETSC_COMM_SELF, (PetscInt)mine.size(), mine.data(), PETSC_COPY_VALUES, &is));
      PetscCall(MatFactorSetSchurIS(schurFactor_, is));
      PetscCall(ISDestroy(&is));
    }
    PetscCall(MatCholeskyFactorSymbolic(schurFactor_, Afac, NULL, &info));
    factored_   = Afac;
    schurLocal_ = local;
    schurRank_  = (PetscInt)mine.size();
    PetscCall(VecDestroy(&bLocal_));
    PetscCall(VecDestroy(&xLocal_));
    if (local) {
      PetscInt n;
      PetscCall(MatGetLocalSize(A, &n, NULL));
      PetscCall(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, n, NULL, &bLocal_));
      PetscCall(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, n, NULL, &xLocal_));
    }
  }
  PetscCall(MatCholeskyFactorNumeric(schurFactor_, Afac, &info));
  PetscCall(MatFactorGetError(schurFactor_, &err));
  PetscInt failed = err != MAT_FACTOR_NOERROR ? (PetscInt)err : 0;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPIU_INT, MPI_MAX, PetscObjectComm((PetscObject)dm)));
  err = (MatFactorError)failed;
  std::string moduli; // (moduli 1e14 apart gave the Dirichlet hint alone)
  {
    PetscReal emin = PETSC_MAX_REAL, emax = 0;
    for (const auto &b : scene.bodies) {
      emin = std::min(emin, b.E);
      emax = std::max(emax, b.E);
    }
    if (emin > 0 && emax / emin > 1e8) {
      std::ostringstream o;
      o << ", or moduli too far apart for double precision (-body_E from " << emin << " to " << emax << ")";
      moduli = o.str();
    }
  }
  PetscCheck(err == MAT_FACTOR_NOERROR, PetscObjectComm((PetscObject)dm), PETSC_ERR_NOT_CONVERGED, "The MUMPS Cholesky factorization of the stiffness (with the Schur complement on the %zu contact dofs%s) failed: %s. A zero pivot usually means a body without enough Dirichlet conditions (-dirichlet)%s; out of memory: raise -fom_mat_mumps_icntl_14", schurDofs_.size(), local ? ", each rank its bodies" : "", err == MAT_FACTOR_OUTMEMORY ? "out of memory" : err == MAT_FACTOR_NUMERIC_ZEROPIVOT ? "zero pivot" : "numerical failure", moduli.c_str());
  PetscCall(MatDestroy(&schurS_));
  if (schurRank_ > 0) PetscCall(MatFactorCreateSchurComplement(schurFactor_, &schurS_, &status));
  *done = true;
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::AssembleAndFactor()
{
  PetscLogDouble t0, t1;
  PC             pc;
  PetscBool      isgamg;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscCall(PetscLogEventBegin(FOM_Assembly, 0, 0, 0, 0));
  if (useAffine) PetscCall(affine.Assemble(mu, &A, &f));
  else PetscCall(elas.Assemble(&A, &f));
  PetscCall(PetscLogEventEnd(FOM_Assembly, 0, 0, 0, 0));
  PetscCall(PetscTime(&t1));
  times.assembly += t1 - t0;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCGAMG, &isgamg));
  if (isgamg) {
    MatNullSpace nsp;
    PetscCall(elas.NearNullSpace(&nsp));
    PetscCall(MatSetNearNullSpace(A, nsp));
    PetscCall(MatNullSpaceDestroy(&nsp));
  }
  residualChecked_ = false;
  factorPending_   = true;
  if (!factorless_) PetscCall(Factor());
  if (!u) PetscCall(VecDuplicate(f, &u));
  PetscCall(PetscObjectSetName((PetscObject)u, "displacement"));
  PetscFunctionReturn(0);
}

// Factors the assembled A (with the Schur complement on the contact dofs when they are set)
PetscErrorCode ElasticFOM::Factor()
{
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t1));
  PetscCall(PetscLogEventBegin(FOM_Factor, 0, 0, 0, 0));
  bool shared = false;
  PetscCall(FactorWithSchur(&shared));
  if (!shared) {
    PetscCall(MatDestroy(&schurS_));
    PetscCall(MatDestroy(&schurFactor_));
    schurLocal_ = false;
    PetscCall(KSPSetOperators(ksp, A, A));
    PetscCall(KSPSetUp(ksp));
    PetscCall(RefactorIfMumpsOutOfMemory(ksp, A));
  }
  PetscCall(PetscLogEventEnd(FOM_Factor, 0, 0, 0, 0));
  PetscCall(PetscTime(&t0));
  times.factorization += t0 - t1;
  factorPending_ = false;
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::Warn(const std::string &msg)
{
  PetscFunctionBeginUser;
  warnings.push_back(msg);
  PetscCall(PetscPrintf(PetscObjectComm((PetscObject)dm), "rbcontact: warning: %s\n", msg.c_str()));
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::CheckBodiesApart()
{
  MPI_Comm        comm = PetscObjectComm((PetscObject)dm);
  PetscInt        pStart, pEnd, cStart, cEnd, vStart, vEnd;
  PetscSF         sf;
  const PetscInt *cb = elas.CellBody().data();

  PetscFunctionBeginUser;
  if (scene.bodies.size() < 2) PetscFunctionReturn(0);
  PetscCall(DMPlexGetChart(dm, &pStart, &pEnd));
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
  // per vertex: the smallest body of its cells and minus the largest (both reduced with MIN to the owner)
  std::vector<PetscInt> lo(pEnd - pStart, PETSC_MAX_INT), nhi(pEnd - pStart, PETSC_MAX_INT);
  for (PetscInt c = cStart; c < cEnd; ++c) {
    const PetscInt b = cb[c - cStart];
    if (b < 0) continue;
    PetscInt *cl = NULL, ncl;
    PetscCall(DMPlexGetTransitiveClosure(dm, c, PETSC_TRUE, &ncl, &cl));
    for (PetscInt k = 0; k < ncl; ++k) {
      const PetscInt p = cl[2 * k];
      if (p < vStart || p >= vEnd) continue;
      lo[p - pStart]  = std::min(lo[p - pStart], b);
      nhi[p - pStart] = std::min(nhi[p - pStart], -b);
    }
    PetscCall(DMPlexRestoreTransitiveClosure(dm, c, PETSC_TRUE, &ncl, &cl));
  }
  PetscCall(DMGetPointSF(dm, &sf));
  PetscCall(PetscSFReduceBegin(sf, MPIU_INT, lo.data(), lo.data(), MPI_MIN));
  PetscCall(PetscSFReduceEnd(sf, MPIU_INT, lo.data(), lo.data(), MPI_MIN));
  PetscCall(PetscSFReduceBegin(sf, MPIU_INT, nhi.data(), nhi.data(), MPI_MIN));
  PetscCall(PetscSFReduceEnd(sf, MPIU_INT, nhi.data(), nhi.data(), MPI_MIN));
  const PetscInt  nb        = (PetscInt)scene.bodies.size();
  PetscInt        shared[2] = {0, PETSC_MAX_INT}; // count, and the first pair of bodies (lo * nb + hi)
  PetscInt        nleaves;
  const PetscInt *leaves;
  PetscCall(PetscSFGetGraph(sf, NULL, &nleaves, &leaves, NULL));
  std::vector<char> isLeaf(pEnd - pStart, 0);
  for (PetscInt l = 0; l < std::max<PetscInt>(nleaves, 0); ++l) isLeaf[(leaves ? leaves[l] : l) - pStart] = 1;
  for (PetscInt v = vStart; v < vEnd; ++v) {
    const PetscInt i = v - pStart;
    if (isLeaf[i] || lo[i] == PETSC_MAX_INT || lo[i] == -nhi[i]) continue;
    ++shared[0];
    shared[1] = std::min(shared[1], lo[i] * nb - nhi[i]);
  }
  PetscInt all[2];
  PetscCallMPI(MPI_Allreduce(shared, all, 1, MPIU_INT, MPI_SUM, comm));
  PetscCallMPI(MPI_Allreduce(shared + 1, all + 1, 1, MPIU_INT, MPI_MIN, comm));
  if (all[0] > 0) {
    std::ostringstream o;
    o << all[0] << " mesh vertices belong to cells of two bodies (e.g. '" << scene.bodies[all[1] / nb].name << "' and '" << scene.bodies[all[1] % nb].name
      << "'): the bodies are glued there, and contact acts between the contact surfaces only. Give each body its own points in the .geo if they are to be apart";
    PetscCall(Warn(o.str()));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::CheckBodiesHeld() const
{
  const PetscInt nb = (PetscInt)scene.bodies.size(), dim = elas.dim;
  PetscInt       cStart, cEnd, pStart, pEnd;

  PetscFunctionBeginUser;
  if (nb == 0) PetscFunctionReturn(0);
  // From the Dirichlet labels and the cells around their points (not the section: a DM's local
  // section must not be created before every boundary is added)
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  PetscCall(DMPlexGetChart(dm, &pStart, &pEnd));
  std::vector<PetscInt> held((size_t)nb * dim, 0); // labelled points per body and constrained component
  const auto           &cb = elas.CellBody();
  for (const auto &bc : scene.dirichlet) {
    DMLabel label;
    PetscCall(DMGetLabel(dm, bc.label.c_str(), &label));
    if (!label) continue; // an unknown label is reported by the discretization's set-up
    std::vector<PetscInt> comps = bc.comps;
    if (comps.empty())
      for (PetscInt d = 0; d < dim; ++d) comps.push_back(d);
    for (PetscInt p = pStart; p < pEnd; ++p) {
      PetscInt val;
      PetscCall(DMLabelGetValue(label, p, &val));
      if (val < 0) continue;
      PetscInt *star = NULL, nst;
      PetscCall(DMPlexGetTransitiveClosure(dm, p, PETSC_FALSE, &nst, &star));
      for (PetscInt k = 0; k < nst; ++k) {
        const PetscInt c = star[2 * k];
        if (c < cStart || c >= cEnd || c - cStart >= (PetscInt)cb.size()) continue;
        const PetscInt b = cb[c - cStart];
        if (b >= 0 && b < nb)
          for (PetscInt d : comps)
            if (d >= 0 && d < dim) ++held[(size_t)b * dim + d];
      }
      PetscCall(DMPlexRestoreTransitiveClosure(dm, p, PETSC_FALSE, &nst, &star));
    }
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, held.data(), (int)held.size(), MPIU_INT, MPI_SUM, PetscObjectComm((PetscObject)dm)));
  const char *axis[] = {"x", "y", "z"};
  for (PetscInt b = 0; b < nb; ++b)
    for (PetscInt d = 0; d < dim; ++d)
      PetscCheck(held[(size_t)b * dim + d] > 0, PetscObjectComm((PetscObject)dm), PETSC_ERR_USER_INPUT,
                 "body '%s' has no Dirichlet condition on its %s displacement: it floats (a rigid translation is a null mode of the stiffness%s). Constrain it with -dirichlet (and -dirichlet_<name>_comps)",
                 scene.bodies[b].name.c_str(), axis[d], scene.contact ? "; frictionless contact cannot hold it" : "");
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::ApplyInverse(Vec rhs, Vec x)
{
  KSPConvergedReason reason;

  PetscFunctionBeginUser;
  if (factorPending_) PetscCall(Factor()); // factorless (the saddle-point contact solve): on first use only
  PetscCall(PetscLogEventBegin(FOM_Solve, 0, 0, 0, 0));
  if (schurFactor_ && schurLocal_) {
    // each rank its own block (no coupling between ranks): the local parts of rhs and x as sequential vectors
    const PetscScalar *b;
    PetscScalar       *xa;
    PetscCall(VecGetArrayRead(rhs, &b));
    PetscCall(VecGetArray(x, &xa));
    PetscCall(VecPlaceArray(bLocal_, b));
    PetscCall(VecPlaceArray(xLocal_, xa));
    PetscCall(MatSolve(schurFactor_, bLocal_, xLocal_));
    PetscCall(VecResetArray(bLocal_));
    PetscCall(VecResetArray(xLocal_));
    PetscCall(VecRestoreArray(x, &xa));
    PetscCall(VecRestoreArrayRead(rhs, &b));
    reason = KSP_CONVERGED_ITS;
  } else if (schurFactor_) {
    // MUMPS: condensation, the Schur system (PETSc's dense factorization), expansion. Residuals
    // measured 2.9e-15 (ring_on_block) and 5e-15 (half_disks P2 refine 1), as the plain MUMPS solve.
    PetscCall(MatSolve(schurFactor_, rhs, x));
    reason = KSP_CONVERGED_ITS;
  } else {
    PetscCall(KSPSolve(ksp, rhs, x));
    PetscCall(KSPGetConvergedReason(ksp, &reason));
  }
  PetscCall(PetscLogEventEnd(FOM_Solve, 0, 0, 0, 0));
  if (reason == KSP_DIVERGED_PC_FAILED) {
    // Say why the preconditioner / factorization failed (a zero pivot and an out-of-memory
    // factorization call for different fixes).
    PC              pc;
    PCFailedReason  pcr;
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCGetFailedReasonRank(pc, &pcr));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &pcr, 1, MPI_INT, MPI_MAX, PetscObjectComm((PetscObject)ksp)));
    // a MUMPS factorization says why in INFOG(1) (e.g. -38: -fom_mat_mumps_icntl_28 2 asks for a parallel ordering
    // this MUMPS was built without; -9 and friends: workspace), which the generic zero-pivot hint would hide
    PetscInt  infog1 = 0;
    PetscBool isfactor = PETSC_FALSE;
    PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &isfactor, PCCHOLESKY, PCLU, ""));
    if (isfactor) {
      MatSolverType st = NULL;
      PetscCall(PCFactorGetMatSolverType(pc, &st));
      if (st && !strcmp(st, MATSOLVERMUMPS)) {
        Mat F = NULL;
        PetscCall(PCFactorGetMatrix(pc, &F));
        if (F) PetscCall(MatMumpsGetInfog(F, 1, &infog1));
      }
    }
    PetscCheck(infog1 >= 0, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED, "The elastic solve (KSP prefix fom_) did not converge: the MUMPS factorization failed with INFOG(1) = %" PetscInt_FMT "%s (MUMPS manual, section 8; -fom_mat_mumps_* options set its controls)", infog1,
               infog1 == -38 ? ": a parallel ordering (-fom_mat_mumps_icntl_28 2) that this MUMPS build lacks (PT-Scotch/ParMETIS); drop -fom_mat_mumps_icntl_28" : infog1 == -9 || infog1 == -8 || infog1 == -14 || infog1 == -15 || infog1 == -17 || infog1 == -20 ? ": its workspace is too small: raise -fom_mat_mumps_icntl_14" : infog1 == -10 ? ": the stiffness is numerically singular: a body without enough Dirichlet conditions (-dirichlet)?" : "");
    SETERRQ(PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED, "The elastic solve (KSP prefix fom_) did not converge: DIVERGED_PC_FAILED (%s). A zero pivot usually means a body without enough Dirichlet conditions (-dirichlet)", PCFailedReasons[pcr]);
  }
  // an iterative solver: its own limits first (-fom_ksp_max_it 5 was blamed on the Dirichlet conditions alone)
  PetscBool iterative;
  {
    KSPType kt;
    PetscCall(KSPGetType(ksp, &kt));
    PetscCall(PetscStrcmp(kt, KSPPREONLY, &iterative));
    iterative = iterative ? PETSC_FALSE : PETSC_TRUE;
  }
  PetscCheck(reason > 0, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED, "The elastic solve (KSP prefix fom_) did not converge: %s. %s", KSPConvergedReasons[reason],
             iterative && reason == KSP_DIVERGED_ITS ? "The iterative solver reached -fom_ksp_max_it: raise it, or use a stronger -fom_pc_type (the default is a direct Cholesky factorization)" : "A singular stiffness usually means a body without enough Dirichlet conditions (-dirichlet)");
  if (!residualChecked_) { // the first solve with a new factorization: a direct solver on a singular A says nothing
    Vec       r;
    PetscReal nr, nb;
    PetscCall(VecDuplicate(rhs, &r));
    PetscCall(MatMult(A, x, r));
    PetscCall(VecAXPY(r, -1.0, rhs));
    PetscCall(VecNorm(r, NORM_2, &nr));
    PetscCall(VecNorm(rhs, NORM_2, &nb));
    PetscCall(VecDestroy(&r));
    PetscReal rtol;
    PetscCall(KSPGetTolerances(ksp, &rtol, NULL, NULL, NULL));
    // (an iterative solver stopped by a loose -fom_ksp_rtol was blamed on a singular stiffness)
    PetscCheck(std::isfinite(nr) && nr <= 1e-6 * nb, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED, "The elastic solve (KSP prefix fom_) is inaccurate: relative residual %s (at most 1e-6 is accepted). %s", std::isfinite(nr) && nb > 0 ? std::to_string(nr / nb).c_str() : "not finite",
               iterative && rtol > 1e-7 ? "The iterative solver stopped at its tolerance -fom_ksp_rtol; set it to 1e-8 or below" : "The stiffness is singular or nearly so: a body may rotate or move freely (too few Dirichlet conditions, -dirichlet), or the materials are degenerate");
    residualChecked_ = true;
  }
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::SolveElastic()
{
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscCall(ApplyInverse(f, u));
  PetscCall(PetscTime(&t1));
  times.solve += t1 - t0;
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::FillReport(Report *rep)
{
  PetscMPIInt size;
  PetscReal   energy;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)dm), &size));
  PetscCall(elas.Energy(u, &energy));
  rep->root["scene"]   = scene.name;
  rep->root["ndofs"]   = (long long)GlobalSize();
  rep->root["nranks"]  = (int)size;
  rep->root["partition"] = MeshPartitionUsed(dm); // -mesh_partitioner as applied: none (1 rank), metis, bodies, petsc
  rep->root["degree"]  = (long long)elas.degree;
  rep->root["dim"]     = (long long)elas.dim;
  rep->root["energy"]  = (double)energy;
  JsonValue &t         = rep->root["time_s"];
  t["assembly"]        = (double)times.assembly;
  t["factorization"]   = (double)times.factorization;
  t["contact"]         = (double)times.contact;
  t["solve"]           = (double)times.solve;
  t["total"]           = (double)times.total;
  // peak resident memory (VmHWM of /proc/self/status, Linux; absent elsewhere): the largest rank's and the sum
  {
    double kb = -1;
    if (FILE *fp = std::fopen("/proc/self/status", "r")) {
      char line[256];
      while (std::fgets(line, sizeof line, fp))
        if (!std::strncmp(line, "VmHWM:", 6)) kb = std::atof(line + 6);
      std::fclose(fp);
    }
    double mx = kb, sum = kb, mn = kb;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &mx, 1, MPI_DOUBLE, MPI_MAX, PetscObjectComm((PetscObject)dm)));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &mn, 1, MPI_DOUBLE, MPI_MIN, PetscObjectComm((PetscObject)dm)));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, PetscObjectComm((PetscObject)dm)));
    if (mn >= 0) {
      rep->root["memory"]["peak_rss_mb_max"] = mx / 1024.0; // the largest rank's peak resident set
      rep->root["memory"]["peak_rss_mb_sum"] = sum / 1024.0; // over the ranks
    }
  }
  JsonValue &w         = rep->root["warnings"];
  w                    = std::vector<double>{}; // an array, empty when all is well
  for (const auto &s : warnings) w.Push(JsonValue::String(s));
  PetscFunctionReturn(0);
}

} // namespace rbc
