// rbcontact/rom_probe.hpp: a ROM file solved over its whole parameter box without the FOM (the offline
// stage's last step and the `probe` stage): does the reduced Kacanov loop converge everywhere, how many
// iterates does it take, and, where the file stores an error estimate, how large are the estimated
// errors and where. A training set that does not resolve some corner of the box shows up here as a
// failure (a reduced loop that cycles, docs/greedy_training.md) before any user meets it online.
// docs/online.md "Probing a model".
#pragma once
#include <petscsys.h>
#include <string>
#include "rbcontact/report.hpp"

namespace rbc {

struct ProbeSummary {
  PetscInt    size = 0, failed = 0, outOfRange = 0;
  std::string firstFailure;    // the first failing probe parameter, with the `online -mu` that reproduces it
  std::string firstOutOfRange; // the first whose contact projections reached the edge of the stored contact data
};

// Opens romPath on every rank of comm (the reduced model's -rom_* options apply, as online), draws the
// parameters from the file's box (-probe_type lhs|random|grid|file, -probe_size n, -probe_seed s,
// -probe_file f; defaults lhs, defSize, seed 2: apart from the test sets' and the greedy's candidates'
// streams), splits them over the ranks, and writes out: rom_file, type, size, seed, failed, first_failure,
// kacanov_iterations {max, mean} (converged points), out_of_range (points with projections at the edge of
// the stored contact data, as online warns) and first_out_of_range, time_s, estimate_available, and with an estimate estimate {u, lambda, force: {max, mu}} (the
// largest estimated error and its parameter). The same numbers on every rank count. Collective on comm.
PetscErrorCode ProbeRomFile(MPI_Comm comm, const std::string &romPath, PetscInt defSize, JsonValue *out, ProbeSummary *sum);

} // namespace rbc
