// share/examples/offline_online.cpp: the whole pipeline as library calls, in a loop. For a scene given by
// its options (-options_file runs/<scene>.opts), builds reduced models from training sets of growing size
// (RunOffline: snapshots, bases, hyper-reduction, ROM file), checks each against the full-order model on a
// small test set (RunValidation) and solves it online (ReducedModel) at the default parameters, printing
// sizes, errors and the contact force. The offline and validation settings are PETSc options, so a
// program sets them with PetscOptionsSetValue (here -train_size) or takes them from the command line.
// Build: CMakeLists.txt builds it as build/bin/rbc_example_offline_online (links the library rbcontact).
// Run:   build/bin/rbc_example_offline_online -options_file runs/ring_on_block.opts [-sizes 3,5] [-test_size 3]
#include <slepcsys.h>
#include <string>
#include <vector>
#include "rbcontact/offline.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/validation.hpp"

static const char help[] = "Offline, validation and online solves of a scene's reduced models: -options_file runs/<scene>.opts [-sizes 3,5]\n";

int main(int argc, char **argv)
{
  PetscInt        sizes[17] = {3, 5}, nsizes = 17; // (one more than taken: PETSc drops values beyond the buffer silently)
  PetscBool       set       = PETSC_FALSE;
  rbc::SceneSpec  scene;

  PetscCall(SlepcInitialize(&argc, &argv, NULL, help));
  PetscCall(PetscOptionsGetIntArray(NULL, NULL, "-sizes", sizes, &nsizes, &set));
  if (!set) nsizes = 2;
  PetscCheck(nsizes <= 16, PETSC_COMM_WORLD, PETSC_ERR_ARG_SIZ, "-sizes takes at most 16 values, more were given");
  PetscCall(rbc::SceneSpecFromOptions(PETSC_COMM_WORLD, &scene)); // meshes, bodies, contact, parameters
  PetscCall(PetscOptionsSetValue(NULL, "-train_type", "grid"));
  PetscCall(PetscOptionsSetValue(NULL, "-test_type", "random"));
  PetscCall(PetscOptionsSetValue(NULL, "-test_seed", "3"));
  PetscCall(PetscOptionsSetValue(NULL, "-validate_repeat", "3"));
  PetscBool hasTestSize = PETSC_FALSE;
  PetscCall(PetscOptionsHasName(NULL, NULL, "-test_size", &hasTestSize));
  if (!hasTestSize) PetscCall(PetscOptionsSetValue(NULL, "-test_size", "3"));

  for (PetscInt i = 0; i < nsizes; ++i) {
    // offline: a ROM file per training size (its snapshot and basis files beside it)
    const std::string rom = "rom_train" + std::to_string((long long)sizes[i]) + ".h5";
    PetscCall(PetscOptionsSetValue(NULL, "-train_size", std::to_string((long long)sizes[i]).c_str()));
    rbc::OfflineSettings off;
    off.rom = rom;
    PetscCall(rbc::OfflineSettingsFromOptions(PETSC_COMM_WORLD, &off)); // fills the companion files' names
    rbc::Report offRep;
    PetscCall(rbc::RunOffline(PETSC_COMM_WORLD, scene, off, &offRep));

    // validation against the full-order model on the test set (-test_*)
    rbc::ValidationSettings vs;
    rbc::ParameterSet       test;
    rbc::Report             valRep;
    PetscCall(rbc::ValidationSettingsFromOptions(PETSC_COMM_WORLD, "", &vs));
    PetscCall(rbc::ParameterSetFromOptions(PETSC_COMM_WORLD, scene.params, "test_", &test));
    PetscCall(rbc::RunValidation(PETSC_COMM_WORLD, scene, rom, test, vs, &valRep));

    // online: the reduced model alone (no mesh), at the default parameters
    rbc::ReducedModel    model;
    rbc::ReducedSolution sol;
    PetscCall(model.Open(rom));
    PetscCall(model.SetFromOptions());
    std::vector<PetscReal> mu;
    for (const auto &p : model.par.params) mu.push_back(p.def);
    PetscCall(model.Solve(mu, &sol));
    PetscCheck(sol.converged, PETSC_COMM_WORLD, PETSC_ERR_NOT_CONVERGED, "%s: %s", rom.c_str(), sol.message.c_str());
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "train %" PetscInt_FMT ": %s N %" PetscInt_FMT " R %" PetscInt_FMT ", max rel err u %.3e lambda %.3e force %.3e, online force at the defaults %.6e\n", sizes[i], rom.c_str(), model.N(), model.R(),
                          valRep.root["test"]["max_rel_err_u"].AsNumber(), valRep.root["test"]["max_rel_err_lambda"].AsNumber(), valRep.root["test"]["max_rel_err_force"].AsNumber(), sol.force.empty() ? 0.0 : (double)sol.ForceMagnitude()));
  }
  PetscCall(SlepcFinalize());
  return 0;
}
