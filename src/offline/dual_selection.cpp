// src/offline/dual_selection.cpp: SelectDualSize and its rule (rbcontact/dual_selection.hpp).
#include "rbcontact/dual_selection.hpp"
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include "rbcontact/snapshot_file.hpp"
#include "rbcontact/training_set.hpp"

namespace rbc {

PetscErrorCode DualSelectionFromOptions(MPI_Comm comm, DualSelectionOptions *o)
{
  char      path[PETSC_MAX_PATH_LEN] = "";
  PetscInt  rbuf[257] = {0}, nr = 257, nf = 4; // (one value more than taken: PETSc drops the values beyond the buffer silently)
  PetscReal fbuf[4] = {o->floor.u, o->floor.lambda, o->floor.force, 0};
  PetscBool fset = PETSC_FALSE;
  PetscBool pset = PETSC_FALSE, rset = PETSC_FALSE, estimate = PETSC_FALSE, refit = o->refit ? PETSC_TRUE : PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, "dual_select_", "The answer's dual vectors chosen on held-out FOM solutions (offline)", "SelectDualSize");
  PetscCall(PetscOptionsInt("-size", "random held-out parameters, solved by the FOM at the end of the offline stage (0: no choice; -dual_select_snapshots takes precedence)", "", o->size, &o->size, NULL));
  PetscCall(PetscOptionsInt("-seed", "seed of those parameters", "", o->seed, &o->seed, NULL));
  PetscCall(PetscOptionsString("-snapshots", "the held-out FOM solutions from this snapshot file (offline -offline_stop snapshots: checkpointed)", "", path, path, sizeof path, &pset));
  PetscCall(PetscOptionsReal("-slack", "the smallest R whose held-out lambda error is within this relative slack of the best (0: the best)", "", o->slack, &o->slack, NULL));
  PetscCall(PetscOptionsReal("-guard", "an R is admissible only if its held-out u and force errors (max and mean) are within this relative slack of every dual vector's", "", o->guard, &o->guard, NULL));
  PetscCall(PetscOptionsReal("-min_fraction", "the smallest candidate R as a fraction of the dual vectors stored", "", o->minFraction, &o->minFraction, NULL));
  PetscCall(PetscOptionsInt("-count", "candidates from there to all, evenly spaced", "", o->count, &o->count, NULL));
  PetscCall(PetscOptionsIntArray("-R", "the candidates themselves (all dual vectors always added)", "", rbuf, &nr, &rset));
  PetscCall(PetscOptionsBool("-refit", "below the stored count: the bases cut to the chosen R and the online model (its cubature) built again for them", "", refit, &refit, NULL));
  PetscCall(PetscOptionsReal("-refit_slack", "the refitted model kept if its held-out lambda error is within this relative slack of the chosen row's", "", o->refitSlack, &o->refitSlack, NULL));
  PetscCall(PetscOptionsReal("-refit_ecsw_tol", "the refit's cubature tolerance (0: -ecsw_tol's)", "", o->refitEcswTol, &o->refitEcswTol, NULL));
  PetscCall(PetscOptionsRealArray("-floor", "u,lambda,force: held-out max (and mean) errors at or below these pass the choice's and the refit's relative rules (0: off; e.g. a quarter of the targets)", "", fbuf, &nf, &fset));
  PetscOptionsEnd();
  if (fset) {
    PetscCheck(nf == 3, comm, PETSC_ERR_ARG_SIZ, "-dual_select_floor takes 3 values (u,lambda,force: relative errors), %s given", nf < 4 ? std::to_string(nf).c_str() : "more than 3");
    for (PetscInt k = 0; k < 3; ++k) PetscCheck(std::isfinite((double)fbuf[k]) && fbuf[k] >= 0 && fbuf[k] < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_floor: the %s floor %g is not in [0, 1) (relative errors)", k == 0 ? "u" : k == 1 ? "lambda" : "force", (double)fbuf[k]);
    o->floor = DualErrorFloor{fbuf[0], fbuf[1], fbuf[2]};
  }
  o->refit = refit == PETSC_TRUE;
  PetscOptionsBegin(comm, "dual_", "The dual basis cut before the online model is built (offline)", "TruncateBases");
  PetscCall(PetscOptionsInt("-truncate", "keep the leading dual vectors (and their supremizers) only, before the online model (0: all)", "", o->truncate, &o->truncate, NULL));
  PetscOptionsEnd();
  if (pset) o->snapshots = path;
  PetscCheck(!rset || nr <= 256, comm, PETSC_ERR_ARG_SIZ, "-dual_select_R takes at most 256 values, more were given");
  if (rset) o->candidates.assign(rbuf, rbuf + nr);
  PetscCheck(o->size >= 0 && o->size <= 10000, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_size %" PetscInt_FMT " out of range [0, 1e4]", o->size);
  PetscCheck(o->slack >= 0 && o->slack <= 10, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_slack %g out of range [0, 10]", (double)o->slack);
  PetscCheck(o->guard >= 0 && o->guard <= 10, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_guard %g out of range [0, 10]", (double)o->guard);
  PetscCheck(o->minFraction > 0 && o->minFraction <= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_min_fraction %g is not in (0, 1]", (double)o->minFraction);
  PetscCheck(o->count >= 1 && o->count <= 1000, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_count %" PetscInt_FMT " out of range [1, 1000]", o->count);
  PetscCheck(o->refitSlack >= 0 && o->refitSlack <= 10, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_refit_slack %g out of range [0, 10]", (double)o->refitSlack);
  PetscCheck(o->refitEcswTol >= 0 && o->refitEcswTol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_refit_ecsw_tol %g out of range [0, 1) (0: -ecsw_tol's)", (double)o->refitEcswTol);
  PetscCheck(o->truncate >= 0 && o->truncate <= 1000000, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_truncate %" PetscInt_FMT " out of range [0, 1e6] (0: every dual vector)", o->truncate);
  PetscCheck(!o->refit || o->Enabled(), comm, PETSC_ERR_ARG_INCOMP, "-dual_select_refit refits the model for the R chosen on held-out solutions: give -dual_select_size or -dual_select_snapshots");
  for (PetscInt r : o->candidates) PetscCheck(r >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_select_R: %" PetscInt_FMT " dual vectors (at least 1)", r);
  if (!o->snapshots.empty()) {
    std::error_code ec;
    PetscCheck(std::filesystem::is_regular_file(o->snapshots, ec), comm, PETSC_ERR_FILE_OPEN, "-dual_select_snapshots %s: no such file (write it with offline -offline_stop snapshots -train_type random -snapshots %s)", o->snapshots.c_str(), o->snapshots.c_str());
    SnapshotHeader h;
    PetscCall(SnapshotFile::ReadHeader(o->snapshots, &h));
    PetscCheck(!h.trainingPoints.empty(), comm, PETSC_ERR_FILE_UNEXPECTED, "-dual_select_snapshots %s holds no parameters", o->snapshots.c_str());
  }
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-estimate", &estimate, NULL));
  PetscCheck(!(o->truncate > 0 && estimate), comm, PETSC_ERR_ARG_INCOMP, "-dual_truncate cuts the dual vectors beyond the answer's; it does not combine with -estimate, whose enrichment they are");
  PetscCheck(!(o->Enabled() && estimate), comm, PETSC_ERR_ARG_INCOMP, "-dual_select_%s chooses the answer's R among all stored dual vectors; it does not combine with -estimate, whose enrichment is the dual vectors beyond the answer's", o->snapshots.empty() ? "size" : "snapshots");
  PetscFunctionReturn(0);
}

std::vector<PetscInt> DualSelectionCandidates(const DualSelectionOptions &o, PetscInt R)
{
  std::vector<PetscInt> c;
  if (!o.candidates.empty()) {
    for (PetscInt r : o.candidates)
      if (r <= R) c.push_back(r); // the dual greedy's R is not known before the offline stage: larger ones are R
  } else {
    const PetscInt lo = std::max<PetscInt>(1, (PetscInt)std::ceil(o.minFraction * R - 1e-9));
    for (PetscInt k = 0; k < o.count; ++k) c.push_back(o.count == 1 ? R : lo + (PetscInt)std::lround((double)(R - lo) * k / (o.count - 1)));
  }
  c.push_back(R);
  std::sort(c.begin(), c.end());
  c.erase(std::unique(c.begin(), c.end()), c.end());
  return c;
}

// e within factor x ref, or at or below its floor (false for a NaN e)
static bool Within(PetscReal e, PetscReal factor, PetscReal ref, PetscReal floor)
{
  return e <= factor * ref || e <= floor;
}

size_t ChooseDualSize(const std::vector<DualSizeRow> &rows, PetscReal slack, PetscReal guardSlack, const DualErrorFloor &floor)
{
  size_t all = 0;
  for (size_t k = 1; k < rows.size(); ++k)
    if (rows[k].R > rows[all].R) all = k;
  double best = INFINITY;
  for (const auto &r : rows)
    if (!r.failed) best = std::min(best, r.lambda);
  const DualSizeRow &a      = rows[all];
  size_t             chosen = rows.size(); // none yet
  for (size_t k = 0; k < rows.size(); ++k) {
    const DualSizeRow &r = rows[k];
    // u and force no worse than with every dual vector, at the worst parameter and on average (a max over a few
    // held-out parameters is set by one of them and hides a change at the others)
    const PetscReal g     = 1 + guardSlack;
    const bool      guard = a.failed || (Within(r.u, g, a.u, floor.u) && Within(r.force, g, a.force, floor.force) && Within(r.meanU, g, a.meanU, floor.u) && Within(r.meanForce, g, a.meanForce, floor.force));
    const bool admissible = !r.failed && Within(r.lambda, 1 + slack, best, floor.lambda) && guard;
    if (admissible && (chosen == rows.size() || r.R < rows[chosen].R)) chosen = k;
  }
  return chosen == rows.size() ? all : chosen;
}

// The held-out parameters (those of -dual_select_snapshots, whose FOM solutions validate reads, or -dual_select_size
// random ones, solved by it) and validate's settings for them: one timed solve, no table printed.
static PetscErrorCode HeldOutSet(const SceneSpec &scene, const DualSelectionOptions &o, ParameterSet *held, ValidationSettings *vs)
{
  PetscFunctionBeginUser;
  for (const auto &p : scene.params) held->names.push_back(p.name);
  if (o.snapshots.empty()) held->points = RandomSample(scene.params, o.size, (unsigned long long)o.seed);
  else {
    SnapshotHeader h;
    PetscCall(SnapshotFile::ReadHeader(o.snapshots, &h));
    held->points            = h.trainingPoints;
    vs->testSnapshots       = o.snapshots;
    vs->testSnapshotsOption = "offline: -dual_select_snapshots";
  }
  vs->repeat = 1;
  vs->print  = false;
  PetscFunctionReturn(0);
}

// The count of dual vectors stored in the ROM file at romPath (/online/sizes).
static PetscErrorCode StoredDualCount(MPI_Comm world, const std::string &romPath, PetscInt *R)
{
  std::vector<unsigned long long> dims;
  std::vector<double>             sizes; // {dim, N, N_pod, n_supremizers, R, 0} (docs/rom_file.md)

  PetscFunctionBeginUser;
  PetscCall(RomReadDataset(romPath, "/online/sizes", &dims, &sizes));
  PetscCheck(sizes.size() == 6, world, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/sizes holds %zu values, expected 6", romPath.c_str(), sizes.size());
  *R = (PetscInt)sizes[4];
  PetscFunctionReturn(0);
}

PetscErrorCode SelectDualSize(MPI_Comm world, const SceneSpec &scene, const std::string &romPath, const DualSelectionOptions &o, RomWriter *w, Report *rep, DualSizeRow *chosen)
{
  PetscFunctionBeginUser;
  JsonValue &d = rep->root["dual_select"];
  d["enabled"] = o.Enabled();
  PetscInt R;
  PetscCall(StoredDualCount(world, romPath, &R));
  if (chosen) *chosen = DualSizeRow{R, 0};
  if (!o.Enabled()) PetscFunctionReturn(0);
  PetscLogDouble t0, t1;
  PetscCall(PetscTime(&t0));
  ParameterSet       held;
  ValidationSettings vs;
  PetscCall(HeldOutSet(scene, o, &held, &vs));
  vs.rValues = DualSelectionCandidates(o, R);
  std::vector<DualSizeRow> rows;
  vs.rRows = &rows;
  Report vr;
  PetscCall(RunValidation(world, scene, romPath, held, vs, &vr));

  d["candidates"] = vr.root["sweep_R"]; // validate's rows (-validate_sweep_R), one per candidate
  const DualSizeRow &c = rows[ChooseDualSize(rows, o.slack, o.guard, o.floor)], &a = rows.back();
  if (chosen) *chosen = c;
  if (c.R < R) { // R itself: no dataset (the file's default), the file as written
    w->Dataset("/online/dual_select", {1}, {(double)c.R});
    PetscCall(w->Write(world, romPath));
  }
  d["heldout"] = (long long)held.points.size();
  if (o.snapshots.empty()) d["seed"] = (long long)o.seed;
  else d["snapshots"] = o.snapshots;
  d["slack"]                         = (double)o.slack;
  d["guard"]                         = (double)o.guard;
  d["floor"]                         = std::vector<double>{(double)o.floor.u, (double)o.floor.lambda, (double)o.floor.force};
  d["R_relative"]                    = (long long)rows[ChooseDualSize(rows, o.slack, o.guard)].R; // the rule without the floors
  d["R"]                             = (long long)c.R;
  d["N"]                             = (long long)c.N;
  d["R_stored"]                      = (long long)R;
  d["max_rel_err_u"]                 = c.u;
  d["max_rel_err_lambda"]            = c.lambda;
  d["max_rel_err_force"]             = c.force;
  d["max_rel_err_u_all"]             = a.u;
  d["max_rel_err_lambda_all"]        = a.lambda;
  d["max_rel_err_force_all"]         = a.force;
  d["fom_median_s"]                  = vr.root["fom_time_s"]["median"].AsNumber();
  PetscCall(PetscTime(&t1));
  rep->root["time_s"]["dual_select"] = (double)(t1 - t0); // the held-out FOM solves (none from a file) and the validations
  rep->root["rom"]["R_in_use"]       = (long long)c.R;
  rep->root["rom"]["N_in_use"]       = (long long)c.N;
  PetscCall(PetscPrintf(world, "rbcontact offline: R chosen on %zu held-out FOM solutions: %" PetscInt_FMT " of %" PetscInt_FMT " dual vectors (N %" PetscInt_FMT "), max rel err lambda %.3e u %.3e force %.3e (all %" PetscInt_FMT ": %.3e, %.3e, %.3e)\n", held.points.size(), c.R, R, c.N, c.lambda, c.u, c.force, R, a.lambda, a.u, a.force));
  PetscFunctionReturn(0);
}

PetscErrorCode ValidateRefit(MPI_Comm world, const SceneSpec &scene, const std::string &romPath, const DualSelectionOptions &o, DualSizeRow *row)
{
  PetscFunctionBeginUser;
  ParameterSet       held;
  ValidationSettings vs;
  PetscCall(HeldOutSet(scene, o, &held, &vs));
  PetscInt R;
  PetscCall(StoredDualCount(world, romPath, &R));
  vs.rValues = {R};
  std::vector<DualSizeRow> rows;
  vs.rRows = &rows;
  Report vr;
  PetscCall(RunValidation(world, scene, romPath, held, vs, &vr));
  PetscCheck(rows.size() == 1, world, PETSC_ERR_PLIB, "ValidateRefit: %zu rows for one R", rows.size());
  *row = rows[0];
  PetscFunctionReturn(0);
}

bool RefitKept(const DualSizeRow &refit, const DualSizeRow &chosen, PetscReal refitSlack, PetscReal guard, const DualErrorFloor &floor)
{
  const PetscReal g = 1 + guard;
  return !refit.failed && Within(refit.lambda, 1 + refitSlack, chosen.lambda, floor.lambda) && Within(refit.u, g, chosen.u, floor.u) && Within(refit.force, g, chosen.force, floor.force) && Within(refit.meanU, g, chosen.meanU, floor.u) &&
         Within(refit.meanForce, g, chosen.meanForce, floor.force);
}

} // namespace rbc
