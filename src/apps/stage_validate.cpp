// src/apps/stage_validate.cpp: `rbcontact validate -options_file runs/<scene>.opts -rom rom.h5
// -test_type random -test_size 20 -test_seed 7 -report v.json`: the ROM against the FOM on a test set
// (the library's RunValidation, include/rbcontact/validation.hpp); -validate_sweep adds the
// speed-against-error table that share/plot_speed_error.py draws.
#include "stages.hpp"
#include "rbcontact/validation.hpp"

namespace rbc {

PetscErrorCode StageValidate(MPI_Comm comm)
{
  char   reportPath[PETSC_MAX_PATH_LEN] = "";
  Report rep;

  PetscFunctionBeginUser;
  // the stage's own options: -help lists them (the ROM file, the test set's, prefix test_, and the reduced
  // model's, prefix rom_, follow)
  PetscOptionsBegin(comm, NULL, "rbcontact validate: report", "rbcontact");
  PetscCall(PetscOptionsString("-report", "JSON report of the run", "", reportPath, reportPath, sizeof reportPath, NULL));
  PetscOptionsEnd();
  PetscCall(CheckOutputPath(comm, reportPath, "-report"));
  PetscCall(RunValidationFromOptions(comm, reportPath, &rep));
  PetscCall(rep.Write(comm, reportPath));
  PetscFunctionReturn(0);
}

} // namespace rbc
