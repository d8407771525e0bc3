// src/apps/stage_offline.cpp: `rbcontact offline`: the offline stage of the library (include/rbcontact/
// offline.hpp, RunOffline): snapshots of the training set (parallel over parameters, checkpointed,
// resumable), bases and the ROM file; -report writes its summary.
#include "stages.hpp"
#include "rbcontact/offline.hpp"

namespace rbc {

PetscErrorCode StageOffline(MPI_Comm world)
{
  Report rep;
  char   reportPath[PETSC_MAX_PATH_LEN] = "";

  PetscFunctionBeginUser;
  PetscOptionsBegin(world, NULL, "rbcontact offline: report", "rbcontact");
  PetscCall(PetscOptionsString("-report", "JSON report of the run", "", reportPath, reportPath, sizeof reportPath, NULL));
  PetscOptionsEnd();
  PetscCall(CheckOutputPath(world, reportPath, "-report"));
  PetscCall(RunOfflineFromOptions(world, &rep));
  PetscCall(rep.Write(world, reportPath));
  PetscFunctionReturn(0);
}

} // namespace rbc
