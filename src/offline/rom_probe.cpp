// src/offline/rom_probe.cpp: the ROM file solved at many parameters of its box, no FOM (rom_probe.hpp):
// the points split over the ranks, the per-point results summed into arrays every rank holds.
#include "rbcontact/rom_probe.hpp"
#include "rbcontact/options_files.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/training_set.hpp"
#include <cmath>
#include <iomanip>
#include <sstream>

namespace rbc {

static PetscLogEvent PROBE_Solves = 0;

PetscErrorCode ProbeRomFile(MPI_Comm comm, const std::string &romPath, PetscInt defSize, JsonValue *out, ProbeSummary *sum)
{
  ReducedModel   model;
  ParameterSet   pts;
  PetscMPIInt    rank, size;
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  if (!PROBE_Solves) PetscCall(PetscLogEventRegister("RBCProbe", 0, &PROBE_Solves));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscTime(&t0));
  PetscCall(model.Open(romPath));
  PetscCall(model.SetFromOptions());
  std::vector<ParamSpec> box;
  for (const auto &p : model.par.params) box.push_back(p);
  PetscCall(ParameterSetFromOptions(comm, box, "probe_", &pts, "lhs", defSize, 2)); // seed 2: apart from the test sets' and the greedy's streams
  const PetscInt n = (PetscInt)pts.points.size();

  // per point: converged, iterations, out-of-range projections, estimate available; the estimates
  std::vector<PetscInt>  ival(4 * (size_t)n, 0);
  std::vector<PetscReal> est(3 * (size_t)n, 0.0);
  PetscInt               myFirst = PETSC_MAX_INT;
  std::string            myMessage;
  PetscCall(PetscLogEventBegin(PROBE_Solves, 0, 0, 0, 0));
  for (PetscInt i = rank; i < n; i += size) {
    ReducedSolution sol;
    // an error of one solve (not a non-convergence, which Solve reports in sol) is that point's failure: a PetscCall
    // here would leave this rank while the others wait in the reductions below
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    const PetscErrorCode e = model.Solve(pts.points[i], &sol);
    PetscCall(PetscPopErrorHandler());
    if (e) {
      const char *text = nullptr;
      (void)PetscErrorMessage(e, &text, NULL);
      sol           = ReducedSolution();
      sol.converged = false;
      sol.message   = "the reduced solve stopped with PETSc error " + std::to_string((int)e) + " (" + (text ? text : "?") + ")";
    }
    ival[4 * i + 0] = sol.converged ? 1 : 0;
    ival[4 * i + 1] = sol.iterations;
    ival[4 * i + 2] = sol.outOfRange > 0 ? 1 : 0;
    ival[4 * i + 3] = sol.converged && sol.estimate.available ? 1 : 0;
    if (ival[4 * i + 3]) {
      est[3 * i + 0] = sol.estimate.u;
      est[3 * i + 1] = sol.estimate.lambda;
      est[3 * i + 2] = sol.estimate.force;
    }
    if (!sol.converged && myFirst == PETSC_MAX_INT) {
      myFirst   = i;
      myMessage = sol.message;
    }
  }
  PetscCall(PetscLogEventEnd(PROBE_Solves, 0, 0, 0, 0));
  if (n) {
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, ival.data(), (PetscMPIInt)ival.size(), MPIU_INT, MPI_SUM, comm));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, est.data(), (PetscMPIInt)est.size(), MPIU_REAL, MPI_SUM, comm));
  }
  PetscInt first = myFirst;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPIU_INT, MPI_MIN, comm));
  if (first != PETSC_MAX_INT) { // its rank's message to all
    const PetscMPIInt owner = (PetscMPIInt)(first % size);
    unsigned long long len  = rank == owner ? myMessage.size() : 0;
    PetscCallMPI(MPI_Bcast(&len, 1, MPI_UNSIGNED_LONG_LONG, owner, comm));
    myMessage.resize(len);
    if (len) PetscCallMPI(MPI_Bcast(&myMessage[0], (PetscMPIInt)len, MPI_CHAR, owner, comm));
  }
  PetscCall(PetscTime(&t1));
  double secs = t1 - t0;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &secs, 1, MPI_DOUBLE, MPI_MAX, comm));

  // the reduced model's options of this run, which `online -mu` needs too to give the same answer
  std::string romOptions;
  for (const auto &op : OptionsInUse())
    if (op.first.compare(0, 5, "-rom_") == 0 && op.first != "-rom_basis") romOptions += " " + op.first + (op.second.empty() ? "" : " " + op.second);
  auto muText = [&](PetscInt i, bool named) {
    std::ostringstream o;
    o << std::setprecision(17);
    for (size_t k = 0; k < pts.points[i].size(); ++k) {
      if (named) o << (k ? ", " : "") << box[k].name << " " << pts.points[i][k];
      else o << (k ? "," : "") << pts.points[i][k];
    }
    return o.str();
  };
  PetscInt failed = 0, outside = 0, firstOutside = -1, nconv = 0, itMax = 0;
  double   itSum  = 0;
  for (PetscInt i = 0; i < n; ++i) {
    if (!ival[4 * i]) ++failed;
    else {
      ++nconv;
      itMax = std::max(itMax, ival[4 * i + 1]);
      itSum += ival[4 * i + 1];
    }
    if (ival[4 * i + 2] && !outside++) firstOutside = i;
  }
  JsonValue &o = *out;
  o["rom_file"] = romPath;
  o["type"]     = pts.type;
  o["size"]     = (long long)n;
  if (pts.type == "random" || pts.type == "lhs") o["seed"] = (long long)pts.seed;
  o["failed"] = (long long)failed;
  sum->size   = n;
  sum->failed = failed;
  sum->firstFailure.clear();
  if (failed) {
    sum->firstFailure = "at probe parameter " + std::to_string((long long)first) + " (" + muText(first, true) + "; online -mu " + muText(first, false) + romOptions + "): " + myMessage;
    o["first_failure"] = sum->firstFailure;
  }
  if (nconv) {
    o["kacanov_iterations"]["max"]  = (long long)itMax;
    o["kacanov_iterations"]["mean"] = itSum / nconv;
  }
  o["out_of_range"] = (long long)outside;
  sum->outOfRange   = outside;
  sum->firstOutOfRange.clear();
  if (outside) {
    sum->firstOutOfRange    = "probe parameter " + std::to_string((long long)firstOutside) + " (" + muText(firstOutside, true) + "; online -mu " + muText(firstOutside, false) + romOptions + ")";
    o["first_out_of_range"] = sum->firstOutOfRange;
  }
  o["time_s"]       = secs;
  // the largest estimated errors over the converged points that have one
  const char *names[3] = {"u", "lambda", "force"};
  bool        any      = false;
  for (PetscInt i = 0; i < n; ++i) any = any || ival[4 * i + 3];
  o["estimate_available"] = any;
  if (any)
    for (int c = 0; c < 3; ++c) {
      PetscInt arg = -1;
      for (PetscInt i = 0; i < n; ++i)
        if (ival[4 * i + 3] && (arg < 0 || est[3 * i + c] > est[3 * arg + c])) arg = i;
      JsonValue &e = o["estimate"][names[c]];
      e["max"]     = (double)est[3 * arg + c];
      JsonValue m  = JsonValue::Object();
      for (size_t k = 0; k < box.size(); ++k) m[box[k].name] = (double)pts.points[arg][k];
      e["mu"] = m;
    }
  PetscFunctionReturn(0);
}

} // namespace rbc
