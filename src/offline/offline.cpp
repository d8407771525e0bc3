// src/offline/offline.cpp: the offline stage as library API (include/rbcontact/offline.hpp): its settings,
// the checks of the later steps' options, the snapshot solves (groups of ranks over the parameters, every
// finished round written to the snapshot file before the next starts: a killed job resumes) and the
// bases and ROM steps (offline_bases.cpp, offline_greedy.cpp, offline_rom.cpp).
#include "rbcontact/options_files.hpp"
#include "rbcontact/offline.hpp"
#include "rbcontact/estimate_calibration.hpp"
#include "rbcontact/rom_probe.hpp"
#include "rbcontact/dual_selection.hpp"
#include "rbcontact/offline_bases.hpp"
#include "rbcontact/offline_greedy.hpp"
#include "rbcontact/offline_rom.hpp"
#include "rbcontact/rom_fields.hpp"
#include "rbcontact/provenance.hpp"
#include "rbcontact/supremizers.hpp"
#include "rbcontact/eim.hpp"
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/kacanov.hpp"
#include "rbcontact/mesh.hpp"
#include "rbcontact/snapshot_continuation.hpp"
#include "rbcontact/snapshot_file.hpp"
#include "rbcontact/snapshot_sensitivity.hpp"
#include "rbcontact/training_set.hpp"
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace rbc {

static PetscLogEvent OFF_Snapshots = 0, OFF_SnapshotSolve = 0, OFF_SnapshotIO = 0;

PetscErrorCode OfflineSettingsFromOptions(MPI_Comm comm, OfflineSettings *s)
{
  char      romPath[PETSC_MAX_PATH_LEN], basisPath[PETSC_MAX_PATH_LEN] = "", viewPath[PETSC_MAX_PATH_LEN], snapPath[PETSC_MAX_PATH_LEN] = "", stop[64] = "rom", trainType[64], guess[64];
  PetscBool restart, monitor = s->monitor ? PETSC_TRUE : PETSC_FALSE, sens = s->sensitivities ? PETSC_TRUE : PETSC_FALSE;
  PetscBool probe = s->probe ? PETSC_TRUE : PETSC_FALSE, probeFail = s->probeFail ? PETSC_TRUE : PETSC_FALSE;
  PetscBool restartSet = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(romPath, s->rom.c_str(), sizeof romPath));
  PetscCall(PetscStrncpy(trainType, s->trainType.c_str(), sizeof trainType));
  PetscCall(PetscStrncpy(viewPath, s->basisView.c_str(), sizeof viewPath));
  PetscCall(PetscStrncpy(guess, s->initialGuess.c_str(), sizeof guess));
  if (s->stop == OfflineStop::Snapshots) PetscCall(PetscStrncpy(stop, "snapshots", sizeof stop));
  if (s->stop == OfflineStop::Bases) PetscCall(PetscStrncpy(stop, "bases", sizeof stop));
  // the companion files' defaults follow -rom, so -help lists them after it
  PetscOptionsBegin(comm, NULL, "rbcontact offline: snapshots, bases and the reduced model", "rbcontact");
  PetscCall(PetscOptionsString("-offline_stop", "last step: snapshots, bases or rom (every step)", "", stop, stop, sizeof stop, NULL));
  PetscCall(PetscOptionsString("-rom", "the ROM file to write (with the bases and rom steps)", "", romPath, romPath, sizeof romPath, NULL));
  {
    // companion files of the ROM: <stem>.snapshots.h5 and <stem>.basis.h5 unless given
    std::string stem = romPath;
    if (stem.size() > 3 && stem.compare(stem.size() - 3, 3, ".h5") == 0) stem.resize(stem.size() - 3);
    if (!strcmp(stop, "rom")) {
      PetscCall(PetscStrncpy(snapPath, (stem + ".snapshots.h5").c_str(), sizeof snapPath));
      PetscCall(PetscStrncpy(basisPath, (stem + ".basis.h5").c_str(), sizeof basisPath));
    }
    if (!s->snapshots.empty()) PetscCall(PetscStrncpy(snapPath, s->snapshots.c_str(), sizeof snapPath));
    if (!s->basis.empty()) PetscCall(PetscStrncpy(basisPath, s->basis.c_str(), sizeof basisPath));
  }
  PetscCall(PetscOptionsString("-rom_basis", "the basis file (default: the ROM's stem + .basis.h5)", "", basisPath, basisPath, sizeof basisPath, NULL));
  PetscCall(PetscOptionsString("-snapshots", "the snapshot file, checkpointed and resumable (default: the ROM's stem + .snapshots.h5)", "", snapPath, snapPath, sizeof snapPath, NULL));
  // the bases step reuses an existing snapshot file of this problem (and completes it if needed)
  restart = strcmp(stop, "snapshots") ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscOptionsBool("-snapshots_restart", "resume from an existing snapshot file of this problem", "", restart, &restart, &restartSet));
  PetscCall(PetscOptionsBool("-snapshots_monitor", "print one line per solved snapshot", "", monitor, &monitor, NULL));
  PetscCall(PetscOptionsBool("-snapshots_sensitivities", "store du/dmu_i, dlambda/dmu_i with every contact snapshot (linear solves with its factor) for the POD and the dual greedy (docs/greedy_training.md)", "", sens, &sens, NULL));
  PetscCall(PetscOptionsString("-train_type", "training set: grid, random, lhs, file (prefix train_) or greedy (prefix greedy_)", "", trainType, trainType, sizeof trainType, NULL));
  PetscCall(PetscOptionsString("-offline_basis_output", "write the POD modes, supremizers and dual basis on the mesh to this HDF5 file (+ .xmf for ParaView)", "", viewPath, viewPath, sizeof viewPath, NULL));
  {
    char     *from[17] = {NULL}; // (one more than taken: PETSc drops values beyond the buffer silently)
    PetscInt  nfrom    = 17;
    PetscBool set      = PETSC_FALSE;
    PetscCall(PetscOptionsStringArray("-snapshots_from", "copy the done snapshots of these snapshot files (same scene and mesh) at points of this training set, before solving the rest", "", from, &nfrom, &set));
    for (PetscInt i = 0; i < (set ? nfrom : 0); ++i) {
      s->from.emplace_back(from[i]);
      PetscCall(PetscFree(from[i]));
    }
    PetscCheck(!set || nfrom <= 16, comm, PETSC_ERR_ARG_SIZ, "-snapshots_from takes at most 16 files, more were given");
  }
  PetscCall(PetscOptionsString("-snapshots_initial_guess", "a contact snapshot's solve starts from: zero (the reference configuration) or nearest (its group's nearest snapshot solved earlier in this run, extrapolated by its sensitivities if stored; docs/offline.md)", "", guess, guess, sizeof guess, NULL));
  PetscCall(PetscOptionsInt("-snapshots_subcomm", "groups of ranks solving the snapshots (0: one per rank below 200k dofs, else 1)", "", s->subcomms, &s->subcomms, NULL));
  PetscCall(PetscOptionsBool("-offline_probe", "after writing the ROM, solve it at -probe_size parameters of its box (no FOM; -probe_type, -probe_seed) and warn where the reduced loop fails (docs/online.md \"Probing a model\")", "", probe, &probe, NULL));
  PetscCall(PetscOptionsBool("-offline_probe_fail", "a failure of the probe is an error (exit code), not a warning; the ROM file stays written", "", probeFail, &probeFail, NULL));
  PetscOptionsEnd();
  PetscCheck(probe || !probeFail, comm, PETSC_ERR_USER_INPUT, "-offline_probe_fail makes the probe's failures an error, but -offline_probe 0 turns the probe off");
  PetscCheck(!strcmp(guess, "zero") || !strcmp(guess, "nearest"), comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-snapshots_initial_guess %s: unknown (zero or nearest)", guess);
  PetscCheck(!strcmp(stop, "snapshots") || !strcmp(stop, "bases") || !strcmp(stop, "rom"), comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-offline_stop %s: unknown step (snapshots, bases or rom, the default: every step)", stop);
  s->stop      = !strcmp(stop, "rom") ? OfflineStop::Rom : !strcmp(stop, "bases") ? OfflineStop::Bases : OfflineStop::Snapshots;
  s->rom       = romPath;
  s->basis     = basisPath;
  s->snapshots = snapPath;
  s->restart   = restart;
  s->restartGiven = restartSet;
  s->monitor   = monitor;
  s->sensitivities = sens;
  s->trainType = trainType;
  s->basisView = viewPath;
  s->initialGuess = guess;
  s->probe     = probe;
  s->probeFail = probeFail;
  PetscFunctionReturn(0); // the files are checked by RunOffline, before any work
}

// Rank 0 reads the mesh file: its checksum and node count.
static PetscErrorCode MeshFacts(MPI_Comm comm, const SceneSpec &scene, unsigned long long *checksum, PetscInt *nnodes)
{
  std::string path;
  PetscMPIInt rank;
  long long   buf[2] = {0, 0};

  PetscFunctionBeginUser;
  PetscCall(MeshGenerate(comm, scene.mesh, &path));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    std::ifstream     f(path, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    const std::string text = ss.str();
    buf[0]                 = (long long)Fnv1a(text);
    // the node count: msh 2.2 has it alone on the line after $Nodes; msh 4.1 (what MeshGenerate writes) has
    // "numEntityBlocks numNodes minNodeTag maxNodeTag" there
    const auto fmt = text.find("$MeshFormat"), pos = text.find("$Nodes");
    const bool v4  = fmt != std::string::npos && text.compare(text.find('\n', fmt) + 1, 1, "4") == 0;
    if (pos != std::string::npos) {
      std::istringstream line(text.substr(text.find('\n', pos) + 1, 200));
      long long          a = 0, b = 0;
      line >> a >> b;
      buf[1] = v4 ? b : a;
    }
  }
  PetscCallMPI(MPI_Bcast(buf, 2, MPI_LONG_LONG, 0, comm));
  *checksum = (unsigned long long)buf[0];
  *nnodes   = (PetscInt)buf[1];
  PetscFunctionReturn(0);
}

PetscErrorCode RunOffline(MPI_Comm world, const SceneSpec &scene, const OfflineSettings &s, Report *report)
{
  Report        &rep = *report;
  const bool      full = s.stop == OfflineStop::Rom, bases = full || s.stop == OfflineStop::Bases;
  const bool      greedy = s.trainType == "greedy";
  const char     *snapPath = s.snapshots.c_str(), *romPath = s.rom.c_str(), *trainType = s.trainType.c_str();
  const PetscBool restart = s.restart ? PETSC_TRUE : PETSC_FALSE, monitor = s.monitor ? PETSC_TRUE : PETSC_FALSE;
  PetscMPIInt     wrank, wsize;
  PetscLogDouble  t0, t1, tSnap0;

  PetscFunctionBeginUser;
  if (!OFF_Snapshots) {
    PetscCall(PetscLogEventRegister("RBCSnapshots", DM_CLASSID, &OFF_Snapshots));
    PetscCall(PetscLogEventRegister("RBCSnapshotSolve", DM_CLASSID, &OFF_SnapshotSolve)); // the FOM solves
    PetscCall(PetscLogEventRegister("RBCSnapshotIO", DM_CLASSID, &OFF_SnapshotIO));       // gather + checkpoint writes (and the wait for the other groups)
  }
  PetscCall(PetscTime(&t0));
  PetscCallMPI(MPI_Comm_rank(world, &wrank));
  PetscCallMPI(MPI_Comm_size(world, &wsize));
  PetscCall(RequireInput(world, !bases || !s.rom.empty(), "-rom", "offline: give the ROM file to write with -rom <file.h5> (or stop after the snapshots: -offline_stop snapshots -snapshots <file.h5>)"));
  PetscCall(RequireInput(world, !s.snapshots.empty(), "-snapshots", "offline: give the snapshot file with -snapshots <file.h5>"));
  if (bases) PetscCall(CheckOutputPath(world, s.rom, "-rom"));
  PetscCall(CheckOutputPath(world, s.snapshots, "-snapshots"));
  for (const auto &from : s.from) PetscCheck(from != s.snapshots, world, PETSC_ERR_ARG_WRONG, "-snapshots_from %s: that is the snapshot file being written (-snapshots)", from.c_str());
  if (full) PetscCall(CheckOutputPath(world, s.basis, "-rom_basis"));
  PetscCheck(s.basisView.empty() || full, world, PETSC_ERR_ARG_INCOMP, "-offline_basis_output needs the whole offline stage (not -offline_stop %s)", bases ? "bases" : "snapshots");
  if (!s.basisView.empty()) PetscCall(CheckOutputPath(world, s.basisView, "-offline_basis_output"));
  if (!s.basisView.empty()) PetscCall(CheckOutputPath(world, XdmfPath(s.basisView), "-offline_basis_output's XDMF"));
  {
    char reportPath[PETSC_MAX_PATH_LEN] = "";
    PetscCall(PetscOptionsGetString(NULL, NULL, "-report", reportPath, sizeof reportPath, NULL));
    std::vector<std::pair<std::string, std::string>> outs = {{"-report", reportPath}, {"-snapshots", s.snapshots}}, ins;
    if (bases) outs.push_back({"-rom", s.rom});
    if (full) outs.push_back({"-rom_basis", s.basis});
    if (!s.basisView.empty()) outs.push_back({"-offline_basis_output", s.basisView});
    for (const auto &from : s.from) ins.push_back({"-snapshots_from", from});
    PetscCall(CheckDistinctFiles(world, outs, ins));
  }
  PetscCheck(!scene.params.empty(), world, PETSC_ERR_USER_INPUT, "offline: the scene declares no parameters (-mu_names)");
  // -train_type greedy (docs/greedy_training.md): the snapshot file's training set is the pool (initial
  // set, then the candidates); the FOM solves the initial set, then the parameters the indicator picks
  ParameterSet  train;
  GreedyOptions gopt;
  PetscInt      ninitial = 0;
  if (greedy) {
    PetscCheck(scene.contact, world, PETSC_ERR_SUP, "-train_type greedy: the indicator is that of a contact scene (-contact_slave, -contact_master)");
    PetscCheck(full, world, PETSC_ERR_ARG_INCOMP, "-train_type greedy builds the reduced model while it trains: it runs the whole offline stage (not -offline_stop %s)", bases ? "bases" : "snapshots");
    PetscCall(GreedyOptionsFromOptions(world, &gopt));
    { // (refused after the initial set's FOM solves before 2026-12-01)
      PetscBool estimate = PETSC_FALSE;
      PetscCall(PetscOptionsGetBool(NULL, NULL, "-estimate", &estimate, NULL));
      PetscCheck(gopt.criterion != GreedyCriterion::Estimate || estimate, world, PETSC_ERR_ARG_INCOMP, "-greedy_indicator estimate needs -estimate (the enriched bases of the online error estimate)");
    }
    gopt.sensitivities = s.sensitivities;
    PetscCall(GreedyPoolFromOptions(world, scene.params, &train, &ninitial));
    // (a budget below the initial set solved the initial set anyway, without a word)
    PetscCheck(gopt.maxSolves >= ninitial, world, PETSC_ERR_ARG_OUTOFRANGE, "-greedy_max_solves %" PetscInt_FMT " is below the %" PetscInt_FMT " points of the initial set (-greedy_initial_type, -greedy_initial_size), which are always solved", gopt.maxSolves, ninitial);
  } else PetscCall(ParameterSetFromOptions(world, scene.params, "train_", &train));
  const PetscInt ntrain = (PetscInt)train.points.size(), np = (PetscInt)scene.params.size();
  if (bases) { // the bases' options, checked before the snapshots (hours on a real scene); read again by OfflineBases
    // (-pod_tol, -pod_n, -pod_inner, -dual_type, -dual_tol were refused only after every snapshot was solved)
    PetscReal        supRatio, step;
    DualBasisOptions dbo;
    PetscCall(SupremizerRatioFromOptions(world, &supRatio));
    PetscCall(DualSensitivityStepFromOptions(world, &step));
    PetscCall(PODCheckOptions(world));
    PetscCall(DualBasisOptionsFromOptions(world, &dbo));
    { // -pod_n beyond the snapshots (with their sensitivities) is known now (it was refused after them)
      PetscInt  n = 0;
      PetscBool set;
      PetscCall(PetscOptionsGetInt(NULL, NULL, "-pod_n", &n, &set));
      const PetscInt nsnap = ntrain * (s.sensitivities ? 1 + np : 1);
      PetscCheck(!set || n <= nsnap, world, PETSC_ERR_ARG_OUTOFRANGE, "-pod_n %" PetscInt_FMT " must lie in [1, %" PetscInt_FMT "] (the number of snapshots%s)", n, nsnap, s.sensitivities ? " with their sensitivities" : "");
    }
  }
  if (full) { // options of the last step, checked before the snapshots (hours on a real scene)
    EIMOptions  eo;
    PetscReal   slack = 0;
    HyperChoice hc;
    PetscCall(HyperChoiceFromOptions(world, &hc));
    { // the online estimate is the cubature's: with the EIM as the online default the calibration found no estimate
      // after its FOM solves, and the files were already replaced (docs/error_estimate.md)
      PetscBool estimate = PETSC_FALSE;
      PetscCall(PetscOptionsGetBool(NULL, NULL, "-estimate", &estimate, NULL));
      PetscCheck(!estimate || (hc.ecsw && hc.ecswFirst), world, PETSC_ERR_ARG_INCOMP, "-estimate needs the empirical cubature as the online default (-rom_hyper ecsw or ecsw,eim): the EIM gives no online error estimate");
      if (estimate) { // (refused after the snapshots and the ROM's writing before 2026-12-01)
        PetscInt  n = 20, seed = 2026;
        PetscReal safety = 2, pt, dt;
        PetscBool e;
        PetscCall(EstimateCalibrationOptions(world, &n, &seed, &safety));
        PetscCall(EstimateEnrichmentOptions(world, &e, &pt, &dt));
      }
    }
    PetscCall(ContactPatchOptions(world, NULL, NULL)); // the contact patch's options of the last step (refused after the snapshots before 2026-12-01)
    PetscCall(EIMOptionsFromOptions(world, "eim_kappa_", &eo));
    PetscCall(EIMOptionsFromOptions(world, "eim_gap_", &eo));
    PetscCall(PetscOptionsGetReal(NULL, NULL, "-eim_select_slack", &slack, NULL));
    DualSelectionOptions dso;
    PetscCall(DualSelectionFromOptions(world, &dso));
    if (!dso.snapshots.empty()) { // the training file as the held-out set: R chosen on the training states themselves
      std::error_code ec;
      const bool      same = dso.snapshots == s.snapshots || std::filesystem::equivalent(dso.snapshots, s.snapshots, ec);
      PetscCheck(!same, world, PETSC_ERR_ARG_INCOMP, "-dual_select_snapshots %s is this run's training snapshot file (-snapshots): the dual basis size is chosen on held-out solutions, so give a test set's file (offline -offline_stop snapshots -train_type random -snapshots <heldout.h5>) or -dual_select_size", dso.snapshots.c_str());
    }
    PetscCheck(slack >= 0, world, PETSC_ERR_ARG_OUTOFRANGE, "-eim_select_slack %g must be >= 0", (double)slack);
    PetscBool held = PETSC_FALSE;
    PetscCall(PetscOptionsHasName(NULL, NULL, "-eim_heldout_type", &held));
    if (held) {
      ParameterSet hs;
      PetscCall(ParameterSetFromOptions(world, scene.params, "eim_heldout_", &hs));
    }
  }

  // Groups of ranks, each solving its share of the parameters. Default: one group per rank for a
  // small mesh (< 200k dofs, where one rank per solve is efficient), one group otherwise.
  unsigned long long checksum = 0;
  PetscInt           nnodes   = 0;
  PetscCall(MeshFacts(world, scene, &checksum, &nnodes));
  PetscCheck(s.subcomms >= 0, world, PETSC_ERR_ARG_OUTOFRANGE, "-snapshots_subcomm %" PetscInt_FMT " must be >= 0 (0: automatic)", s.subcomms); // (-2 ran as 0)
  PetscInt k = s.subcomms > 0 ? s.subcomms : (nnodes * 3 < 200000) ? wsize : 1;
  PetscCheck(k >= 1 && k <= wsize, world, PETSC_ERR_ARG_OUTOFRANGE, "-snapshots_subcomm %" PetscInt_FMT " must lie in [1, %d] (the number of ranks)", k, (int)wsize);
  PetscSubcomm psub;
  PetscCall(PetscSubcommCreate(world, &psub));
  PetscCall(PetscSubcommSetNumber(psub, (PetscInt)k));
  PetscCall(PetscSubcommSetType(psub, PETSC_SUBCOMM_CONTIGUOUS));
  MPI_Comm    group = PetscSubcommChild(psub);
  PetscMPIInt grank;
  PetscCallMPI(MPI_Comm_rank(group, &grank));
  const PetscInt color = psub->color;

  {
    // Every group: the reference-configuration FOM with its affine decomposition and contact map.
    ElasticFOM     fom;
    ContactMap     cmap;
    KacanovSolver  kac;
    CanonicalOrder order;
    PetscCall(fom.Create(group, scene));
    PetscCall(fom.SetupAffine());
    PetscInt ndofs;
    {
      Vec g;
      PetscCall(DMGetGlobalVector(fom.dm, &g));
      PetscCall(VecGetSize(g, &ndofs));
      PetscCall(DMRestoreGlobalVector(fom.dm, &g));
    }
    PetscCall(order.BuildDofs(fom.elas));
    PetscInt               R = 0;
    if (scene.contact) {
      PetscCall(kac.SetFromOptions(group));
      PetscCall(cmap.Setup(fom.elas, scene.slave, scene.master));
      // the reduced contact terms are the segment-based Gauss rule's (docs/hyper_reduction.md): a ROM of a nodal FOM
      // approximated another contact model, 5.6e-2 off in lambda at its own training states, exit 0 (audit I)
      PetscCheck(!full || cmap.quadrature != ContactQuadrature::Nodal, group, PETSC_ERR_SUP, "-contact_quadrature nodal: the reduced model evaluates the contact terms with the segment-based Gauss rule (docs/hyper_reduction.md), so it would approximate another contact model than this FOM's; build the ROM with the default -contact_quadrature gauss (nodal snapshots alone: -offline_stop snapshots or bases)");
      PetscCall(kac.ShareFactor(fom, cmap));
      R = cmap.NumMultipliers();
    }

    SnapshotHeader h;
    h.scene          = scene.name;
    h.sceneHash      = Fnv1a(SceneFingerprint(scene, fom.map));
    h.meshChecksum   = checksum;
    h.codeVersion    = CodeVersion();
    h.paramNames     = train.names;
    for (const auto &p : scene.params) { h.paramMin.push_back(p.min); h.paramMax.push_back(p.max); }
    h.trainingPoints = train.points;
    h.ndofs          = ndofs;
    h.nmult          = R;
    // the extras every snapshot of this run carries (the packing below), created with a new file
    if (scene.contact) h.extras.emplace_back("contact_gap", R);
    if (s.sensitivities) {
      h.extras.emplace_back("sensitivity_u", np * ndofs);
      h.extras.emplace_back("sensitivity_lambda", np * R);
    }
    {
      char *all = NULL;
      PetscCall(PetscOptionsGetAll(NULL, &all));
      h.optionsText = all ? all : "";
      PetscCall(PetscFree(all));
    }
    SnapshotFile file;
    for (const auto &from : s.from) PetscCall(SnapshotFile::CheckImport(world, from, h)); // before Open may replace the file
    if (!restart && !s.restartGiven) {
      // -offline_stop snapshots run again with its own command (a killed job resubmitted): the finished snapshots were
      // thrown away without a word. Replacing a file that holds some is now asked for explicitly.
      PetscInt ndone, nold;
      PetscCall(SnapshotFile::DoneCount(world, snapPath, &ndone, &nold));
      PetscCheck(ndone <= 0, world, PETSC_ERR_USER_INPUT, "Snapshot file '%s' exists and holds %" PetscInt_FMT " finished snapshots (of %" PetscInt_FMT "): resume it with -snapshots_restart (it is checked to belong to this problem first), or replace it with -snapshots_restart 0", snapPath, ndone, nold);
    }
    // (before Open, which may replace a file)
    PetscCheck(!s.sensitivities || scene.contact, world, PETSC_ERR_SUP, "-snapshots_sensitivities: the derivatives are those of a contact solution (-contact_slave, -contact_master)");
    PetscCall(file.Open(world, snapPath, h, restart));
    PetscInt                 imported = 0;
    std::vector<std::string> extras; // what this run writes with every snapshot (the packing below: h.extras)
    for (const auto &e : h.extras) extras.push_back(e.first);
    for (const auto &from : s.from) { // before the done list: the imported snapshots are not solved again
      PetscInt n = 0, outside = 0;
      PetscCall(file.Import(from, extras, &n, &outside));
      imported += n;
      PetscCall(PetscInfo(NULL, "%s: %" PetscInt_FMT " snapshots imported, %" PetscInt_FMT " outside this training set\n", from.c_str(), n, outside));
      if (wrank == 0 && monitor) PetscCall(PetscPrintf(PETSC_COMM_SELF, "  -snapshots_from %s: %" PetscInt_FMT " snapshots imported (%" PetscInt_FMT " at points outside this training set)\n", from.c_str(), n, outside));
    }
    std::vector<PetscInt> done, todo;
    PetscCall(file.DoneIndices(&done));
    for (PetscInt i = 0; i < ntrain; ++i)
      if (std::find(done.begin(), done.end(), i) == done.end()) todo.push_back(i);
    if (!restart) PetscCheck((PetscInt)done.size() == imported, world, PETSC_ERR_PLIB, "new snapshot file with done entries");
    if (s.sensitivities && !done.empty()) {
      // a file solved without them, or in part without them (a run resumed without the option: its rows read zeros),
      // was refused only by the bases step, after every remaining snapshot was solved
      std::vector<PetscInt> without;
      PetscCall(file.RowsWithoutExtra("sensitivity_u", &without));
      if (!without.empty()) {
        std::string rows;
        for (size_t k = 0; k < without.size() && k < 8; ++k) rows += (k ? ", " : "") + std::to_string(without[k] + 1);
        if (without.size() > 8) rows += ", ...";
        SETERRQ(world, PETSC_ERR_FILE_UNEXPECTED, "-snapshots_sensitivities: %zu of the %zu finished snapshots of %s were solved without sensitivities (training points %s): drop the option, or solve them again in a new file (-snapshots_restart 0)", without.size(), done.size(), snapPath, rows.c_str());
      }
    }

    // Packed snapshot: idx, its, seconds, kkt[4], mu[np], u[ndofs], lambda[R], gap[R], and with
    // -snapshots_sensitivities the scaled derivatives (mu_i range) du/dmu_i [np*ndofs], dlambda/dmu_i [np*R]
    const bool             sensOn = s.sensitivities;
    const size_t           L0 = 7 + np + ndofs + 2 * R, L = L0 + (sensOn ? (size_t)np * (ndofs + R) : 0);
    PetscLogDouble         sensSeconds = 0;
    PetscInt               sensIts = 0, sensActive = 0;
    std::string            sensMethod;
    std::vector<PetscReal> pack(L), gathered(wrank == 0 ? L * wsize : 0);
    std::vector<PetscInt>  itsSolved;
    bool                   multOrderBuilt = false;
    // Solves the training points list (indices into train.points) in rounds of k, one per group of ranks;
    // every finished round is written before the next starts.
    PetscInt solvedNow = 0;
    // -snapshots_initial_guess nearest: this group's solutions of this run, the next solve's start
    const bool           nearest = s.initialGuess == "nearest";
    std::vector<PetscReal> ranges;
    for (const auto &p : scene.params) ranges.push_back(p.max - p.min);
    SnapshotContinuation continuation(ranges);
    auto solveList = [&](const std::vector<PetscInt> &list) -> PetscErrorCode {
      const PetscInt rounds = ((PetscInt)list.size() + k - 1) / k;
      for (PetscInt r = 0; r < rounds; ++r) {
        const PetscInt slot = r * k + color;
        const PetscInt idx  = slot < (PetscInt)list.size() ? list[slot] : -1;
        std::fill(pack.begin(), pack.end(), 0.0);
        pack[0] = idx;
        if (idx >= 0) {
          PetscLogDouble s0, s1;
          PetscCall(PetscLogEventBegin(OFF_SnapshotSolve, 0, 0, 0, 0));
          PetscCall(PetscTime(&s0));
          const std::vector<PetscReal> &mu = train.points[idx];
          PetscCall(fom.SetMu(mu));
          PetscCall(fom.AssembleAndFactor());
          std::vector<PetscReal> u, lam, gap;
          if (scene.contact) {
            cmap.SetGeometry(&fom.map, mu);
            if (nearest) { // -snapshots_initial_guess nearest
              Vec       ug, lg;
              PetscReal dist;
              PetscCall(continuation.Predict(mu, &ug, &lg, &dist));
              if (ug) PetscCall(kac.SetInitialGuess(ug, lg));
              PetscCall(VecDestroy(&ug));
              PetscCall(VecDestroy(&lg));
            }
            PetscCall(kac.Solve(fom, cmap));
            PetscCall(PetscTime(&s1)); // the snapshot's seconds: the FOM solve's (validate -test_snapshots reports them)
            if (!multOrderBuilt) {
              PetscCall(order.BuildMultipliers(kac.sys.coordRef, fom.elas.dim));
              multOrderBuilt = true;
            }
            PetscCall(order.MultipliersToCanonical(kac.lambda, &lam));
            PetscCall(order.MultipliersToCanonical(kac.sys.g, &gap));
          } else {
            PetscCall(fom.SolveElastic());
            PetscCall(PetscTime(&s1));
          }
          PetscCall(order.DofsToCanonical(fom.u, &u));
          PetscCall(PetscLogEventEnd(OFF_SnapshotSolve, 0, 0, 0, 0));
          std::vector<std::vector<PetscReal>> dus, dls;
          std::vector<Vec>                    dv, dl;
          if (sensOn) { // after the solve's time: the snapshot's seconds stay the FOM's
            SensitivityInfo si;
            PetscCall(ParameterSensitivities(fom, cmap, kac, &dv, &dl, &si));
            for (PetscInt i = 0; i < np; ++i) {
              dus.emplace_back();
              dls.emplace_back();
              PetscCall(order.DofsToCanonical(dv[i], &dus.back()));
              PetscCall(order.MultipliersToCanonical(dl[i], &dls.back()));
              const PetscReal w = scene.params[i].max - scene.params[i].min; // the derivative over the whole range
              for (auto &x : dus.back()) x *= w;
              for (auto &x : dls.back()) x *= w;
            }
            sensSeconds += si.seconds;
            sensIts    = std::max(sensIts, si.cgIterations);
            sensActive = std::max(sensActive, si.active);
            sensMethod = si.method;
          }
          if (nearest && scene.contact) PetscCall(continuation.Add(mu, fom.u, kac.lambda, dv, dl));
          for (size_t i = 0; i < dv.size(); ++i) {
            PetscCall(VecDestroy(&dv[i]));
            PetscCall(VecDestroy(&dl[i]));
          }
          if (grank == 0) {
            size_t o = 1;
            pack[o++] = kac.iterations;
            pack[o++] = s1 - s0;
            pack[o++] = kac.kkt.primal;
            pack[o++] = kac.kkt.dual;
            pack[o++] = kac.kkt.complementarity;
            pack[o++] = kac.kkt.stationarity;
            for (PetscInt j = 0; j < np; ++j) pack[o++] = mu[j];
            for (PetscInt j = 0; j < ndofs; ++j) pack[o++] = u[j];
            for (PetscInt j = 0; j < R; ++j) pack[o++] = lam[j];
            for (PetscInt j = 0; j < R; ++j) pack[o++] = gap[j];
            o = L0;
            for (const auto &d : dus)
              for (PetscInt j = 0; j < ndofs; ++j) pack[o++] = d[j];
            for (const auto &d : dls)
              for (PetscInt j = 0; j < R; ++j) pack[o++] = d[j];
          }
          itsSolved.push_back(kac.iterations);
        }
        // group roots -> world rank 0 (other ranks send an empty slot)
        PetscCall(PetscLogEventBegin(OFF_SnapshotIO, 0, 0, 0, 0));
        if (grank != 0) pack[0] = -1;
        PetscCallMPI(MPI_Gather(pack.data(), (int)L, MPIU_REAL, gathered.data(), (int)L, MPIU_REAL, 0, world));
        std::vector<Snapshot> snaps;
        if (wrank == 0)
          for (PetscMPIInt q = 0; q < wsize; ++q) {
            const PetscReal *p = &gathered[(size_t)q * L];
            if (p[0] < 0) continue;
            Snapshot s;
            size_t   o = 0;
            s.index             = (PetscInt)p[o++];
            s.kacanovIterations = (PetscInt)p[o++];
            s.seconds           = p[o++];
            s.kkt.assign(p + o, p + o + 4);
            o += 4;
            s.mu.assign(p + o, p + o + np);
            o += np;
            s.u.assign(p + o, p + o + ndofs);
            o += ndofs;
            s.lambda.assign(p + o, p + o + R);
            o += R;
            if (scene.contact) {
              s.extra["contact_gap"].assign(p + o, p + o + R);
              o += R;
            }
            if (sensOn) {
              s.extra["sensitivity_u"].assign(p + L0, p + L0 + (size_t)np * ndofs);
              s.extra["sensitivity_lambda"].assign(p + L0 + (size_t)np * ndofs, p + L);
            }
            snaps.push_back(s);
          }
        PetscInt nsnap = (PetscInt)snaps.size();
        PetscCallMPI(MPI_Bcast(&nsnap, 1, MPIU_INT, 0, world));
        for (PetscInt i = 0; i < nsnap; ++i) PetscCall(file.Write(wrank == 0 ? snaps[i] : Snapshot()));
        PetscCall(PetscLogEventEnd(OFF_SnapshotIO, 0, 0, 0, 0));
        if (monitor && wrank == 0) {
          PetscLogDouble now;
          PetscCall(PetscTime(&now));
          const PetscInt  finished = solvedNow + std::min<PetscInt>((r + 1) * k, (PetscInt)list.size());
          const PetscReal eta      = (now - tSnap0) / finished * (solvedNow + (PetscInt)list.size() - finished);
          for (const auto &s : snaps) {
            std::ostringstream m;
            for (auto v : s.mu) m << " " << v;
            PetscCall(PetscPrintf(PETSC_COMM_SELF, "  snapshot %3" PetscInt_FMT "/%" PetscInt_FMT "  mu =%s  Kacanov its %2" PetscInt_FMT "  %.2f s  [%" PetscInt_FMT "/%" PetscInt_FMT " done, ETA %.1f s]\n", s.index + 1, ntrain, m.str().c_str(), s.kacanovIterations, (double)s.seconds, finished, solvedNow + (PetscInt)list.size(), (double)eta));
          }
        }
      }
      solvedNow += (PetscInt)list.size();
      return 0;
    };
    PetscCall(PetscTime(&tSnap0));
    PetscCall(PetscLogEventBegin(OFF_Snapshots, 0, 0, 0, 0));
    if (!greedy) PetscCall(solveList(todo));
    else {
      std::vector<PetscInt> init;
      for (PetscInt i : todo)
        if (i < ninitial) init.push_back(i);
      PetscCall(solveList(init));
      PetscCall(GreedyRounds(world, gopt, k, color, fom, cmap, order, train, ninitial, file, h, solveList, &rep));
    }
    PetscCall(PetscLogEventEnd(OFF_Snapshots, 0, 0, 0, 0));
    PetscCall(file.Close());
    PetscCall(PetscTime(&t1));

    // statistics over every snapshot solved in this run
    std::vector<int> myIts(itsSolved.begin(), itsSolved.end());
    if (grank != 0) myIts.clear();
    int              cnt = (int)myIts.size();
    std::vector<int> counts(wsize), displs(wsize, 0);
    PetscCallMPI(MPI_Allgather(&cnt, 1, MPI_INT, counts.data(), 1, MPI_INT, world));
    for (int q = 1; q < wsize; ++q) displs[q] = displs[q - 1] + counts[q - 1];
    std::vector<int> allIts(displs[wsize - 1] + counts[wsize - 1]);
    PetscCallMPI(MPI_Allgatherv(myIts.data(), cnt, MPI_INT, allIts.data(), counts.data(), displs.data(), MPI_INT, world));

    rep.root["stage"]       = "offline";
    rep.root["scene"]       = scene.name;
    rep.root["ntrain"]      = (long long)ntrain; // greedy: the pool (greedy.training_set_size: the points solved)
    rep.root["train_type"]  = trainType;
    rep.root["nparams"]     = (long long)np;
    rep.root["fom_solves"]  = (long long)allIts.size();
    rep.root["resumed"]     = (long long)(done.size() - (size_t)imported); // in the file before this run
    rep.root["imported"]    = (long long)imported;       // copied by -snapshots_from
    rep.root["initial_guess"] = s.initialGuess;          // -snapshots_initial_guess
    rep.root["ndofs"]       = (long long)ndofs;
    rep.root["ncontact"]    = (long long)R;
    JsonValue &ki           = rep.root["kacanov_iterations"];
    if (!allIts.empty()) {
      ki["min"]  = (long long)*std::min_element(allIts.begin(), allIts.end());
      ki["max"]  = (long long)*std::max_element(allIts.begin(), allIts.end());
      double sum = 0;
      for (int v : allIts) sum += v;
      ki["mean"] = sum / allIts.size();
    }
    JsonValue at;
    fom.affine.Describe(&at);
    rep.root["affine_terms"]          = at;
    rep.root["time_s"]["snapshots"]   = (double)(t1 - tSnap0);
    rep.root["time_s"]["total"]       = (double)(t1 - t0);
    rep.root["nranks"]                = (int)wsize;
    rep.root["subcomms"]              = (long long)k;
    rep.root["mesh_nodes"]            = (long long)nnodes; // the default -snapshots_subcomm reads it
    rep.root["snapshots"]             = snapPath;
    { // -snapshots_sensitivities: over the snapshots solved in this run (group roots' sums and maxima)
      JsonValue &sj = rep.root["sensitivities"];
      sj["enabled"] = sensOn;
      if (sensOn) {
        double   secs = grank == 0 ? (double)sensSeconds : 0.0;
        PetscInt mx[2] = {sensIts, sensActive};
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &secs, 1, MPI_DOUBLE, MPI_SUM, world));
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, mx, 2, MPIU_INT, MPI_MAX, world));
        sj["seconds"]          = secs;
        sj["cg_iterations_max"] = (long long)mx[0];
        sj["active_rows_max"]   = (long long)mx[1];
        PetscCall(BcastString(world, &sensMethod)); // rank 0 solved a snapshot in this run, or nothing was solved
        sj["method"] = sensMethod.empty() ? "none" : sensMethod;
      }
    }
    if (bases) {
      // every group computes the (deterministic) bases; world rank 0 (group 0's root) writes them
      PetscCall(OfflineBases(world, fom, order, s.snapshots, s.rom, h, &rep, scene.contact ? &cmap : nullptr, full, s.basis, greedy, s.sensitivities));
      if (full && !s.basisView.empty()) PetscCall(WriteBasisView(world, scene, s.rom, s.basisView, &rep));
      if (full && s.probe) { // the written file over its box, as online reads it (rom_probe.hpp)
        ProbeSummary ps;
        PetscCall(ProbeRomFile(world, s.rom, 1000, &rep.root["probe"], &ps));
        if (ps.failed) {
          if (s.probeFail) { // the whole report with the error (the ROM file is written), then the exit code
            const std::string err = "offline: the reduced model " + s.rom + " failed at " + std::to_string((long long)ps.failed) + " of " + std::to_string((long long)ps.size) + " probe parameters (-offline_probe_fail); first " + ps.firstFailure;
            char reportPath[PETSC_MAX_PATH_LEN] = "";
            PetscCall(PetscOptionsGetString(NULL, NULL, "-report", reportPath, sizeof reportPath, NULL));
            PetscCall(rep.WriteFailed(world, reportPath, err));
            SETERRQ(world, PETSC_ERR_NOT_CONVERGED, "%s", err.c_str());
          }
          PetscCall(PetscPrintf(world, "rbcontact offline: warning: the reduced model %s failed at %" PetscInt_FMT " of %" PetscInt_FMT " probe parameters; first %s. The training set does not resolve that part of the box: add training parameters near it (docs/online.md \"Probing a model\")\n", romPath, ps.failed, ps.size, ps.firstFailure.c_str()));
        }
        if (ps.outOfRange) PetscCall(PetscPrintf(world, "rbcontact offline: warning: at %" PetscInt_FMT " of %" PetscInt_FMT " probe parameters contact projections reached the edge of the stored contact data, where the answers may be wrong (first: %s): more -eim_patch_rings, or training parameters near them (docs/online.md \"Probing a model\")\n", ps.outOfRange, ps.size, ps.firstOutOfRange.c_str()));
      }
      PetscCall(PetscTime(&t1));
      rep.root["time_s"]["total"] = (double)(t1 - t0);
    }
    const std::string imp = imported ? ", " + std::to_string((long long)imported) + " imported" : std::string(); // (were counted as resumed)
    PetscCall(PetscPrintf(world, "rbcontact offline: %s, %" PetscInt_FMT " training parameters (%zu solved now, %zu resumed%s), %" PetscInt_FMT " group%s of ranks, %.2f s -> %s\n", scene.name.c_str(), ntrain, allIts.size(), done.size() - (size_t)imported, imp.c_str(), k, k == 1 ? "" : "s", (double)(t1 - t0), bases ? romPath : snapPath));
  }
  PetscCall(PetscSubcommDestroy(&psub));
  PetscFunctionReturn(0);
}

PetscErrorCode RunOfflineFromOptions(MPI_Comm world, Report *rep)
{
  OfflineSettings s;
  SceneSpec       scene;

  PetscFunctionBeginUser;
  PetscCall(OfflineSettingsFromOptions(world, &s));
  PetscCall(SceneSpecFromOptions(world, &scene));
  PetscCall(RunOffline(world, scene, s, rep));
  PetscFunctionReturn(0);
}

} // namespace rbc
