// src/apps/stage_fom.cpp: `rbcontact fom`: solve the full-order model of one scene and report.
#include "stages.hpp"
#include "rbcontact/fom.hpp"

namespace rbc {

PetscErrorCode StageFom(MPI_Comm comm)
{
  SceneSpec      scene;
  Report         rep;
  char           reportPath[PETSC_MAX_PATH_LEN] = "", outPath[PETSC_MAX_PATH_LEN] = "";
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-report", reportPath, sizeof reportPath, NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-fom_output", outPath, sizeof outPath, NULL));
  PetscCall(SceneSpecFromOptions(comm, &scene));
  ElasticFOM fom;
  PetscCall(fom.Create(comm, scene));
  PetscCall(fom.AssembleAndFactor());
  PetscCall(fom.SolveElastic());
  PetscCall(PetscTime(&t1));
  fom.times.total = t1 - t0;
  PetscCall(fom.FillReport(&rep));
  rep.root["stage"]   = "fom";
  rep.root["contact"] = false;
  if (outPath[0]) {
    PetscCall(fom.WriteOutput(outPath));
    rep.root["output"] = outPath;
  }
  PetscCall(PetscPrintf(comm, "rbcontact fom: scene %s, %" PetscInt_FMT " dofs, energy %.10e, total %.3f s\n", scene.name.c_str(), fom.GlobalSize(), rep.root["energy"].AsNumber(), (double)fom.times.total));
  PetscCall(rep.Write(comm, reportPath));
  PetscFunctionReturn(0);
}

} // namespace rbc
