// src/offline/offline_greedy.cpp: the greedy training's options, candidate pool, error indicator and picks
// (offline_greedy.hpp, docs/greedy_training.md).
#include "rbcontact/offline_greedy.hpp"
#include "rbcontact/options_files.hpp"
#include "rbcontact/offline_bases.hpp"
#include "rbcontact/offline_rom.hpp"
#include "rbcontact/rom_fields.hpp"
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace rbc {

// GreedyCriterion's names (option values and report keys), in its order
static const char *const kCriterionNames[] = {"residual", "penetration", "max", "estimate"};

PetscErrorCode GreedyOptionsFromOptions(MPI_Comm comm, GreedyOptions *o)
{
  PetscFunctionBeginUser;
  PetscCall(CheckValuesGiven(comm, "greedy_", {"tol", "max_solves", "batch", "indicator", "separation"})); // (the defaults, without a word)
  PetscOptionsBegin(comm, "greedy_", "Greedy training (offline -train_type greedy)", "rbcontact");
  PetscCall(PetscOptionsReal("-tol", "Stop once the largest indicator over the candidates is at most this", "", o->tol, &o->tol, NULL));
  PetscCall(PetscOptionsInt("-max_solves", "FOM solves in all (initial set included)", "", o->maxSolves, &o->maxSolves, NULL));
  PetscCall(PetscOptionsInt("-batch", "Parameters solved per round (0: the number of groups of ranks, whose picks then depend on the rank count)", "", o->batch, &o->batch, NULL));
  PetscCall(PetscOptionsReal("-separation", "Picks of one round at least this many candidate spacings apart", "", o->separation, &o->separation, NULL));
  { // a list option on a PetscInt: a PetscEnum may not hold 3 (UBSan: outside the range of PETSc's one-value enum type)
    PetscInt c = (PetscInt)o->criterion;
    PetscCall(PetscOptionsEList("-indicator", "Measure that ranks the candidates", "", kCriterionNames, (PetscInt)(sizeof kCriterionNames / sizeof *kCriterionNames), kCriterionNames[c], &c, NULL));
    o->criterion = (GreedyCriterion)c;
  }
  PetscCall(PetscOptionsBool("-monitor", "Print every round", "", o->monitor, &o->monitor, NULL));
  PetscOptionsEnd();
  auto num = [](PetscReal v) { // as typed (PETSc's %g would print 0 as "0.")
    std::ostringstream s;
    s << v;
    return s.str();
  };
  PetscCheck(o->tol > 0 && std::isfinite(o->tol), comm, PETSC_ERR_ARG_OUTOFRANGE, "-greedy_tol %s must be > 0", num(o->tol).c_str());
  PetscCheck(o->maxSolves >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-greedy_max_solves %" PetscInt_FMT " must be >= 1", o->maxSolves);
  PetscCheck(o->batch >= 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-greedy_batch %" PetscInt_FMT " must be >= 0 (0: the number of groups of ranks)", o->batch);
  PetscCheck(o->separation >= 0 && std::isfinite(o->separation), comm, PETSC_ERR_ARG_OUTOFRANGE, "-greedy_separation %s must be >= 0", num(o->separation).c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode GreedyPoolFromOptions(MPI_Comm comm, const std::vector<ParamSpec> &params, ParameterSet *pool, PetscInt *ninitial)
{
  ParameterSet init, cand;

  PetscFunctionBeginUser;
  PetscCall(ParameterSetFromOptions(comm, params, "greedy_initial_", &init, "grid", 2));
  // seed 1: a stream apart from the test sets' default seed 0
  PetscCall(ParameterSetFromOptions(comm, params, "greedy_candidates_", &cand, "lhs", 1000, 1));
  PetscCheck(!init.points.empty(), comm, PETSC_ERR_USER_INPUT, "-greedy_initial_*: the initial set is empty");
  *pool = init;
  for (const auto &c : cand.points) {
    bool dup = false;
    for (const auto &x : init.points) dup = dup || x == c;
    if (!dup) pool->points.push_back(c);
  }
  *ninitial = (PetscInt)init.points.size();
  PetscCheck((PetscInt)pool->points.size() > *ninitial, comm, PETSC_ERR_USER_INPUT, "-greedy_candidates_*: no candidate besides the initial set");
  PetscFunctionReturn(0);
}

} // namespace rbc

namespace rbc {

PetscErrorCode GreedyRounds(MPI_Comm world, const GreedyOptions &go, PetscInt ngroups, PetscInt color, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const ParameterSet &pool, PetscInt ninitial, SnapshotFile &file, const SnapshotHeader &h, const GreedySolveFn &solve, Report *rep)
{
  const PetscInt    npool = (PetscInt)pool.points.size(), np = (PetscInt)fom.scene.params.size();
  const PetscInt    batch = go.batch > 0 ? go.batch : ngroups;
  const std::string path  = file.Path();
  // typical spacing of the candidates in the unit box
  const PetscReal spacing = std::pow((PetscReal)std::max<PetscInt>(1, npool - ninitial), -1.0 / std::max<PetscInt>(1, np));
  GreedyIndicator ind;
  JsonValue       rounds = JsonValue::Array();
  std::string     stop;
  PetscInt        failures = 0;
  PetscMPIInt     wrank;
  PetscLogDouble  tInd = 0, tModel = 0;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(world, &wrank));
  PetscCall(ind.Setup(fom));
  const bool byEstimate = go.criterion == GreedyCriterion::Estimate;
  ind.criterion         = byEstimate ? GreedyCriterion::Residual : go.criterion; // (a round without enrichment: the residual)
  std::vector<PetscReal> slaveMass;                                              // the estimate's lambda norm
  if (byEstimate) PetscCall(ReferenceSlaveMass(fom, cmap, order, &slaveMass));
  PetscInt nEstimateRounds = 0;
  for (PetscInt round = 0;; ++round) {
    std::vector<PetscInt> done;
    PetscCall(file.DoneIndices(&done));
    const PetscInt nsolved = (PetscInt)done.size();
    if (nsolved >= go.maxSolves) {
      stop = "max_solves";
      break;
    }
    {
      // a run killed inside a round (some of its picks solved): finish that round's picks first. The model of a
      // partial round would rank the candidates otherwise and the resumed run would not give the uninterrupted ROM.
      std::vector<PetscInt> unfinished;
      for (PetscInt i : file.Pending())
        if (!std::binary_search(done.begin(), done.end(), i) && (PetscInt)unfinished.size() < go.maxSolves - nsolved) unfinished.push_back(i);
      if (!unfinished.empty()) {
        if (go.monitor && wrank == 0) PetscCall(PetscPrintf(PETSC_COMM_SELF, "  greedy: the interrupted round's %zu unsolved pick(s) first\n", unfinished.size()));
        JsonValue r = JsonValue::Object();
        r["round"]           = (long long)round;
        r["solves"]          = (long long)nsolved;
        r["resumed_picks"]   = std::vector<double>(unfinished.begin(), unfinished.end());
        rounds.Push(r);
        PetscCall(solve(unfinished));
        continue;
      }
    }
    // the done snapshots, as a restart would read them
    std::vector<Snapshot> snaps;
    PetscCall(file.Close());
    PetscCall(SnapshotFile::ReadAll(path, &snaps));
    PetscCall(file.Open(world, path, h, true));
    PetscLogDouble t0, t1, t2;
    PetscCall(PetscTime(&t0));
    OfflineBasisSet               bs;
    ReducedModel                  rm;
    std::shared_ptr<ContactPatch> full;
    std::vector<PetscReal>        P;
    PetscInt                      nsub;
    PetscCall(BuildBases(world, fom, order, snaps, h.nmult, &cmap, &bs, go.sensitivities, path));
    PetscCall(BuildExactReducedModel(world, fom, cmap, order, bs.pod.modes, bs.modes, bs.pod.N - bs.nsup, bs.nsup, bs.dual, &rm, &full, &P, &nsub));
    rm.warmStart      = PETSC_FALSE;
    rm.loop.monitor   = PETSC_FALSE;
    rm.recordIterates = false;
    // -greedy_indicator estimate: the answer's sizes inside the enriched bases (BuildBases with -estimate), the
    // estimate's lambda norm; without an enrichment this round (few snapshots: every POD mode and dual vector
    // is needed by the answer's tolerances already) the residual ranks the candidates
    bool estimated = false;
    if (byEstimate) {
      PetscCheck(bs.estimate, world, PETSC_ERR_ARG_INCOMP, "-greedy_indicator estimate needs -estimate (the enriched bases of the online error estimate)");
      if (bs.nDefault > 0 || bs.rDefault > 0) {
        rm.NDefault = bs.nDefault > 0 ? bs.nDefault : bs.pod.N - bs.nsup;
        rm.RDefault = bs.rDefault > 0 ? bs.rDefault : bs.dual.W.cols;
        rm.massGram = SlaveMassGram(bs.dual.W, slaveMass);
        PetscCall(rm.Truncate(-1, -1, -1, -1));
        estimated = true;
        ++nEstimateRounds;
      }
    }
    PetscCall(PetscTime(&t1));
    // the indicator at every candidate not solved; candidate j of those goes to group j mod ngroups
    std::vector<char> isDone(npool, 0);
    for (PetscInt d : done) isDone[d] = 1;
    std::vector<PetscReal> val(3 * npool, -1.0), all(3 * npool);
    PetscInt               j = 0;
    for (PetscInt c = ninitial; c < npool; ++c) {
      if (isDone[c] || j++ % ngroups != color) continue;
      GreedyEstimate e;
      if (estimated) { // the raw changes of u and lambda in the enriched spaces (no mesh); a failed solve first
        ReducedSolution sol;
        full->SetGeometry(&fom.map, pool.points[c]);
        PetscCall(rm.Solve(pool.points[c], &sol));
        const bool ok = sol.converged && sol.estimate.available;
        e.value       = ok ? sol.estimate.uRaw : PETSC_MAX_REAL;
        e.residual    = ok ? sol.estimate.uRaw : PETSC_MAX_REAL;
        e.penetration = ok ? sol.estimate.lambdaRaw : PETSC_MAX_REAL;
      } else PetscCall(ind.EvaluateReduced(fom, cmap, order, rm, *full, bs.pod.modes, bs.dual.W, pool.points[c], &e));
      val[c]             = e.value;
      val[npool + c]     = e.residual;
      val[2 * npool + c] = e.penetration;
    }
    PetscCallMPI(MPI_Allreduce(val.data(), all.data(), 3 * npool, MPIU_REAL, MPIU_MAX, world));
    PetscCall(PetscTime(&t2));
    tModel += t1 - t0;
    tInd += t2 - t1;
    std::vector<PetscReal> eta(all.begin(), all.begin() + npool);
    PetscInt               best = -1, nfail = 0, ncand = 0;
    PetscReal              maxRes = 0, maxPen = 0;
    for (PetscInt c = 0; c < npool; ++c) {
      if (eta[c] < 0) continue;
      ++ncand;
      if (best < 0 || eta[c] > eta[best]) best = c;
      if (eta[c] >= PETSC_MAX_REAL) ++nfail;
      else {
        maxRes = std::max(maxRes, all[npool + c]);
        maxPen = std::max(maxPen, all[2 * npool + c]);
      }
    }
    failures += nfail;
    if (best < 0) {
      stop = "pool";
      break;
    }
    JsonValue r = JsonValue::Object();
    r["round"]           = (long long)round;
    r["solves"]          = (long long)nsolved;
    r["N"]               = (long long)bs.pod.N;
    r["R"]               = (long long)bs.dual.W.cols;
    r["candidates"]      = (long long)ncand;
    r["max_indicator"]   = Finite(std::vector<double>{eta[best]})[0];
    r["indicator"]       = kCriterionNames[(int)(estimated ? GreedyCriterion::Estimate : ind.criterion)];
    if (estimated) { // the raw u and lambda changes of the online estimate (docs/error_estimate.md)
      r["max_estimate_u"]      = (double)maxRes;
      r["max_estimate_lambda"] = (double)maxPen;
    } else {
      r["max_residual"]    = (double)maxRes;
      r["max_penetration"] = (double)maxPen;
    }
    r["rom_failures"]    = (long long)nfail;
    r["argmax"]          = std::vector<double>(pool.points[best].begin(), pool.points[best].end());
    r["seconds_model"]   = (double)(t1 - t0);
    r["seconds_indicator"] = (double)(t2 - t1);
    if (go.monitor && wrank == 0) {
      std::ostringstream m;
      for (auto v : pool.points[best]) m << " " << v;
      PetscCall(PetscPrintf(PETSC_COMM_SELF, "  greedy round %2" PetscInt_FMT ": %3" PetscInt_FMT " solves, N %3" PetscInt_FMT " R %3" PetscInt_FMT ", max indicator %.3e (%s %.3e, %s %.3e, %" PetscInt_FMT " failed) at mu =%s; model %.2f s, indicator %.2f s (%" PetscInt_FMT " candidates)\n", round, nsolved, bs.pod.N, bs.dual.W.cols, (double)eta[best], estimated ? "estimate u" : "residual", (double)maxRes, estimated ? "lambda" : "penetration", (double)maxPen, nfail, m.str().c_str(), (double)(t1 - t0), (double)(t2 - t1), ncand));
    }
    if (eta[best] <= go.tol) {
      r["picked"] = std::vector<double>();
      rounds.Push(r);
      stop = "tol";
      break;
    }
    const std::vector<PetscInt> picks = GreedyPick(eta, pool.points, fom.scene.params, std::min(batch, go.maxSolves - nsolved), go.separation * spacing);
    r["picked"] = std::vector<double>(picks.begin(), picks.end());
    rounds.Push(r);
    PetscCall(file.SetPending(picks));
    PetscCall(solve(picks));
  }
  std::vector<PetscInt> done;
  PetscCall(file.DoneIndices(&done));
  JsonValue &g              = rep->root["greedy"];
  g["pool"]                 = (long long)npool;
  g["initial"]              = (long long)ninitial;
  g["candidates"]           = (long long)(npool - ninitial);
  g["batch"]                = (long long)batch;
  g["tol"]                  = (double)go.tol;
  g["max_solves"]           = (long long)go.maxSolves;
  g["separation"]           = (double)(go.separation * spacing);
  g["indicator"]            = kCriterionNames[(int)go.criterion]; // of the reduced model with exact contact terms (estimate: the online estimate's)
  g["estimate_rounds"]      = (long long)nEstimateRounds; // rounds ranked by the online estimate (-greedy_indicator estimate)
  g["stop"]                 = stop;
  g["reached_tol"]          = stop == "tol";
  g["training_set_size"]    = (long long)done.size();
  g["rom_failures"]         = (long long)failures;
  g["rounds"]               = rounds;
  g["seconds_model"]        = (double)tModel;
  g["seconds_indicator"]    = (double)tInd;
  {
    std::vector<double> idx(done.begin(), done.end());
    g["training_indices"] = idx;
  }
  PetscFunctionReturn(0);
}

} // namespace rbc
