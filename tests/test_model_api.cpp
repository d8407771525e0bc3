// tests/test_model_api.cpp: the C++ API's ReducedModel used out of order (audit of 2026-12-01): a default-constructed
// model "solved" (converged, an empty solution) and blamed -rom_N ("out of range [1, 0]"); a failed Open of an opened
// model left it half-replaced and still solving (the old model's answer under the missing file's name). Now every
// method that needs a model refuses without one, naming the cause, and a failed Open leaves no model.
// Run from the source tree with the scene's options (-options_file runs/ring_on_block.opts): it builds a small ROM
// (3 training radii) with the offline stage of the library first.
#include "rbcontact/offline.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/report.hpp"
#include <slepcsys.h>
#include <cstdio>
#include <string>
#include <unistd.h>
#include <vector>

using namespace rbc;

static int         failures = 0;
static std::string lastError; // the first line of the last error (CaptureError)

static void Check(bool ok, const std::string &what)
{
  PetscCallVoid(PetscPrintf(PETSC_COMM_WORLD, "  %-6s %s\n", ok ? "ok" : "FAIL", what.c_str()));
  if (!ok) ++failures;
}

static PetscErrorCode CaptureError(MPI_Comm, int, const char *, const char *, PetscErrorCode n, PetscErrorType p, const char *mess, void *)
{
  if (p == PETSC_ERROR_INITIAL && mess) lastError = mess;
  return n;
}

// calls f with errors returned (not printed); true when it failed with a message holding every word
template <class F> static bool Fails(F f, const std::vector<std::string> &words)
{
  lastError.clear();
  if (PetscPushErrorHandler(CaptureError, NULL)) return false;
  const PetscErrorCode e = f();
  if (PetscPopErrorHandler()) return false;
  bool all = e != 0;
  for (const auto &w : words) all = all && lastError.find(w) != std::string::npos;
  if (!all) PetscCallAbort(PETSC_COMM_WORLD, PetscPrintf(PETSC_COMM_WORLD, "    (error %d: %s)\n", (int)e, lastError.c_str()));
  return all;
}

int main(int argc, char **argv)
{
  PetscCall(SlepcInitialize(&argc, &argv, NULL, NULL));
  long pid = (long)getpid();
  PetscCallMPI(MPI_Bcast(&pid, 1, MPI_LONG, 0, PETSC_COMM_WORLD));
  const std::string rom = "/tmp/rbc_test_model_api_" + std::to_string(pid) + ".h5", missing = "/tmp/rbc_test_model_api_nosuch.h5";
  PetscCall(PetscOptionsSetValue(NULL, "-train_size", "3"));
  PetscCall(PetscOptionsSetValue(NULL, "-rom", rom.c_str()));
  PetscCall(PetscOptionsSetValue(NULL, "-offline_probe", "0"));
  {
    Report rep;
    PetscCall(RunOfflineFromOptions(PETSC_COMM_WORLD, &rep));
  }
  PetscCall(PetscOptionsClearValue(NULL, "-rom"));
  {
    ReducedModel    m;
    ReducedSolution s;
    Check(Fails([&] { return m.Solve({1.02}, &s); }, {"ReducedModel::Solve: no reduced model (Open a ROM file first)"}), "a default-constructed model: Solve refuses");
    Check(Fails([&] { return m.SetFromOptions(); }, {"ReducedModel::SetFromOptions: no reduced model"}), "... SetFromOptions refuses (it blamed -rom_N)");
    Check(Fails([&] { return m.Truncate(-1, -1, -1, -1); }, {"ReducedModel::Truncate: no reduced model"}), "... Truncate refuses");
    PetscCall(m.Open(rom));
    PetscCall(m.SetFromOptions());
    PetscCall(m.Solve({1.02}, &s));
    const double force = s.converged ? s.ForceMagnitude() : 0;
    Check(s.converged && force > 0, "opened: Solve converges with a contact force");
    Check(Fails([&] { return m.Open(missing); }, {missing}), "Open of a missing file fails naming it");
    Check(Fails([&] { return m.Solve({1.02}, &s); }, {"no reduced model: the last Open (of " + missing + ") failed"}), "after the failed Open: Solve refuses, naming that file (it gave the old model's answer)");
    PetscCall(m.Open(rom));
    PetscCall(m.SetFromOptions());
    PetscCall(m.Solve({1.02}, &s));
    Check(s.converged && s.ForceMagnitude() == force, "opened again: the same answer as before");
  }
  PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
  PetscMPIInt rank;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  if (rank == 0)
    for (const char *ext : {"", ".basis.h5", ".snapshots.h5"}) std::remove((ext[0] ? rom.substr(0, rom.size() - 3) + ext : rom).c_str());
  int total = 0;
  PetscCallMPI(MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, PETSC_COMM_WORLD));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_model_api: %s (%d failure%s)\n", total ? "FAILED" : "passed", total, total == 1 ? "" : "s"));
  PetscCall(SlepcFinalize());
  return total ? 1 : 0;
}
