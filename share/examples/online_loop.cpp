// share/examples/online_loop.cpp: the online stage as a library call, in a loop. Opens a ROM file
// (written by `rbcontact offline ... -rom rom.h5`) once and solves the reduced contact problem at 11
// values of the first parameter across its box (the other parameters at their defaults), printing the
// Kacanov iterations, the first reduced coordinates and the time of each solve. Copy it as a start.
// Build: CMakeLists.txt builds it as build/bin/rbc_example_online_loop (links the library rbcontact).
// Run:   build/bin/rbc_example_online_loop -rom rom.h5 [-rom_kacanov_monitor] [-rom_R 5 ...] (-rom_* options: reduced_model.hpp)
#include <petsctime.h>
#include <slepcsys.h>
#include <algorithm>
#include <vector>
#include "rbcontact/reduced_model.hpp"

static const char help[] = "Solves a reduced contact model at 11 parameters: -rom rom.h5\n";

int main(int argc, char **argv)
{
  char                 romPath[PETSC_MAX_PATH_LEN] = "";
  PetscBool            set                         = PETSC_FALSE;
  rbc::ReducedModel    model;
  rbc::ReducedSolution sol;

  PetscCall(SlepcInitialize(&argc, &argv, NULL, help));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-rom", romPath, sizeof romPath, &set));
  PetscCheck(set && romPath[0], PETSC_COMM_WORLD, PETSC_ERR_USER_INPUT, "give the ROM file with -rom <file.h5>");

  // Read everything the online solve needs, once; then the -rom_* options (tolerances, truncation).
  PetscCall(model.Open(romPath));
  PetscCall(model.SetFromOptions());
  const auto &params = model.par.params; // the parameter box (name, min, max, def of each parameter)
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s: N %" PetscInt_FMT " R %" PetscInt_FMT " Mk %" PetscInt_FMT " Mg %" PetscInt_FMT ", %s in [%g, %g]\n", romPath,
                        model.N(), model.R(), model.Mk(), model.Mg(), params[0].name.c_str(), (double)params[0].min, (double)params[0].max));

  std::vector<PetscReal> mu;
  for (const auto &p : params) mu.push_back(p.def); // defaults; the loop varies mu[0]
  const int n = 11;
  for (int k = 0; k < n; ++k) {
    const PetscReal t = (PetscReal)k / (n - 1);
    mu[0]             = (1 - t) * params[0].min + t * params[0].max; // exactly min and max at the ends
    PetscCall(model.par.CheckBox(PETSC_COMM_WORLD, mu));              // a clear error outside the box

    PetscLogDouble t0, t1;
    PetscCall(PetscTime(&t0));
    PetscCall(model.Solve(mu, &sol)); // PETSc errors only for bad input; numerical trouble -> sol.converged
    PetscCall(PetscTime(&t1));
    if (!sol.converged) { // e.g. no Kacanov convergence: say why and stop
      PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s = %g: not converged: %s\n", params[0].name.c_str(), (double)mu[0], sol.message.c_str()));
      PetscCall(SlepcFinalize());
      return 1;
    }
    // u ~ sum_n v_n theta_n (reduced coordinates sol.v), lambda ~ sum_r lambda_r xi_r (sol.lambda)
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s = %.4f  iterations %2" PetscInt_FMT "  v[0:3] =", params[0].name.c_str(), (double)mu[0], sol.iterations));
    for (size_t i = 0; i < std::min<size_t>(3, sol.v.size()); ++i) PetscCall(PetscPrintf(PETSC_COMM_WORLD, " % .6e", (double)sol.v[i]));
    // the resultant contact force, computed online without the mesh (empty with -rom_hyper eim)
    if (!sol.force.empty()) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "  force %.6e", (double)sol.ForceMagnitude()));
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "  time %.2e s\n", (double)(t1 - t0)));
  }
  PetscCall(PetscOptionsLeft(NULL)); // PETSc's list of the options nobody read ("Option left: name:-rom_kacanov_monitr"): a misspelling
  PetscCall(SlepcFinalize());
  return 0;
}
