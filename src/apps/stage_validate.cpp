// src/apps/stage_validate.cpp: `rbcontact validate -options_file runs/<scene>.opts -rom rom.h5
// -test_type random -test_size 20 -test_seed 7 -report v.json`: the ROM against the FOM on a test set
// (the library's RunValidation, include/rbcontact/validation.hpp); -validate_sweep adds the
// speed-against-error table that share/plot_speed_error.py draws.
#include "stages.hpp"
#include "rbcontact/validation.hpp"

namespace rbc {

PetscErrorCode StageValidate(MPI_Comm comm)
{
  char               romPath[PETSC_MAX_PATH_LEN] = "", reportPath[PETSC_MAX_PATH_LEN] = "";
  PetscBool          set = PETSC_FALSE;
  SceneSpec          scene;
  Report             rep;
  ValidationSettings s;
  ParameterSet       test;

  PetscFunctionBeginUser;
  // the stage's own options: -help lists them (the test set's, prefix test_, and the reduced model's,
  // prefix rom_, follow)
  PetscOptionsBegin(comm, NULL, "rbcontact validate: ROM file and report", "rbcontact");
  PetscCall(PetscOptionsString("-rom", "the ROM file (written by rbcontact offline)", "", romPath, romPath, sizeof romPath, &set));
  PetscCall(PetscOptionsString("-report", "JSON report of the run", "", reportPath, reportPath, sizeof reportPath, NULL));
  PetscOptionsEnd();
  PetscCheck(set && romPath[0], comm, PETSC_ERR_USER_INPUT, "validate: give the ROM file with -rom <file.h5> (written by rbcontact offline)");
  PetscCall(ValidationSettingsFromOptions(comm, reportPath, &s));
  PetscCall(CheckOutputPath(comm, reportPath, "-report"));
  PetscCall(SceneSpecFromOptions(comm, &scene));
  PetscCall(ParameterSetFromOptions(comm, scene.params, "test_", &test));
  PetscCall(RunValidation(comm, scene, romPath, test, s, &rep));
  PetscCall(rep.Write(comm, reportPath));
  PetscFunctionReturn(0);
}

} // namespace rbc
