// include/rbcontact/validation.hpp: the ROM against the FOM on a test set as library API
// (src/offline/validation.cpp; `rbcontact validate` is a thin wrapper): errors of the ROM and of the ROM
// with exact contact terms (u in the energy norm of A(mu), lambda in the slave-mass weighted l2 norm, the
// contact force on the mesh and online), online and FOM timings, and the speed-against-error sweep.
#pragma once
#include <string>
#include <vector>
#include "rbcontact/report.hpp"
#include "rbcontact/scene.hpp"
#include "rbcontact/training_set.hpp"

namespace rbc {

// The ROM with R dual vectors (and their supremizers), every POD mode: max relative errors over the test set
// (-validate_sweep_R; the offline choice of R, dual_selection.hpp). NaN where a solve failed.
struct DualSizeRow {
  PetscInt R = 0, N = 0;
  double   u = 0, lambda = 0, force = 0;             // max over the test set
  double   meanU = 0, meanLambda = 0, meanForce = 0; // mean over the test set
  bool     failed = false;
};

struct ValidationSettings {
  PetscInt               repeat = 100;                        // -validate_repeat: timed online solves per parameter
  bool                   timeAllRanks = false;                // -validate_time_all_ranks: time on every rank at once
                                                              // (default: on rank 0 while the others wait)
  bool                   sweep  = false;                      // -validate_sweep: the speed-against-error table
  std::vector<PetscReal> fractions{0.2, 0.4, 0.6, 0.8, 1.0};  // -validate_sweep_fractions of N, R (and the EIM sizes)
  std::string            sweepOutput;                         // -validate_sweep_output stem (default: the report's + _sweep)
  std::vector<PetscInt>  rValues;                             // -validate_sweep_R: errors of the model with these numbers of dual
                                                              // vectors (and their supremizers), all POD modes in use (untimed)
  std::vector<DualSizeRow> *rRows = nullptr;                  // when not null: those errors, one row per rValues entry
  std::vector<PetscInt>  threadValues;                        // -validate_threads: also timed with these -rom_threads
                                                              // (online_time_s.by_threads [{threads, median, per_parameter_median, speedup_median}])
  bool                   residual = false;                    // -validate_residual: the residual indicator and its effectivity
  bool                   print    = true;                     // the summary line (off for offline -estimate's calibration run)
  std::string            testSnapshots;                       // -test_snapshots: the FOM test solutions from a snapshot file
                                                              // (offline -offline_stop snapshots; its points are the test set)
  std::string            testSnapshotsOption = "validate: -test_snapshots"; // who named that file, in error messages
  // when not null: the error estimate's raw changes and the true errors per test parameter (u, lambda, force), as in
  // the report's estimate block (empty when the ROM gives no estimate)
  std::vector<double>   *estimateRaw = nullptr, *estimateErr = nullptr; // arrays of 3
};

// Reads and checks the settings (one PetscOptionsBegin block); reportPath gives the sweep's default stem.
PetscErrorCode ValidationSettingsFromOptions(MPI_Comm comm, const std::string &reportPath, ValidationSettings *s);

// The ROM at romPath (built for scene as configured now: checked) against the FOM at every point of test.
// Report keys: stage, scene, rom_file, nranks, test and test_exact (= test_no_eim) {n, max_rel_err_u,
// mean_rel_err_u, max_rel_err_lambda, mean_rel_err_lambda, max_rel_err_force, rel_err_*, max_rel_err_force_online,
// failed}, test.mu, online_time_s {median, max, per_parameter_median, repeat, timed_on, threads, by_threads}, fom_time_s {median, all},
// speedup_median, rom_kacanov_iterations, rom {N, R, Mk, Mg, Mc, hyper, ecsw_sum, ndofs}, test_snapshots (the file or
// ""; with it, the FOM solutions and fom_time_s come from the file: docs/online.md "Validation"); with the sweep
// also sweep [rows] and sweep_files; with -validate_sweep_R also sweep_R [rows {R, N, max_rel_err_u,
// max_rel_err_lambda, max_rel_err_force, mean_rel_err_u, mean_rel_err_lambda, mean_rel_err_force, failed}] (the
// offline choice of R, dual_selection.hpp); with -validate_residual also residual {indicator, rel_err_u_energy,
// effectivity, min_effectivity, max_effectivity, share_above_1, share_within_20} (docs/error_estimate.md: the
// residual of the reduced solution assembled on the mesh, not an online quantity). An error if the ROM fails on a
// test parameter. Collective on comm.
PetscErrorCode RunValidation(MPI_Comm comm, const SceneSpec &scene, const std::string &romPath, const ParameterSet &test, const ValidationSettings &s, Report *rep);

// The validate stage from the options database alone, as `rbcontact validate` and the Python module run it: -rom
// (required), ValidationSettingsFromOptions (reportPath: the sweep's default stem), the scene, the test set
// (-test_*), RunValidation.
PetscErrorCode RunValidationFromOptions(MPI_Comm comm, const std::string &reportPath, Report *rep);

} // namespace rbc
