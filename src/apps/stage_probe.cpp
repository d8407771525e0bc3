// src/apps/stage_probe.cpp: `rbcontact probe -rom rom.h5 [-probe_size n] -report r.json`: the ROM file
// solved at many parameters of its box without the FOM (rom_probe.hpp): failures of the reduced loop,
// iterations and, where the file stores an error estimate, the largest estimated errors. Fails (exit
// code) when the reduced loop fails at a probe parameter, naming the first with its `online -mu`.
#include "rbcontact/options_files.hpp"
#include "stages.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/rom_fields.hpp"
#include "rbcontact/rom_probe.hpp"

namespace rbc {

PetscErrorCode StageProbe(MPI_Comm comm)
{
  char         romPath[PETSC_MAX_PATH_LEN] = "", reportPath[PETSC_MAX_PATH_LEN] = "";
  PetscBool    set = PETSC_FALSE;
  Report       rep;
  ProbeSummary ps;

  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, NULL, "rbcontact probe: a ROM file solved over its parameter box (no FOM)", "rbcontact");
  PetscCall(PetscOptionsString("-rom", "the ROM file (written by rbcontact offline)", "", romPath, romPath, sizeof romPath, &set));
  PetscCall(PetscOptionsString("-report", "JSON report of the run", "", reportPath, reportPath, sizeof reportPath, NULL));
  PetscOptionsEnd();
  PetscCall(RequireInput(comm, set && romPath[0], "-rom", "probe: give the ROM file with -rom <file.h5> (written by rbcontact offline)"));
  PetscCall(CheckOutputPath(comm, reportPath, "-report"));
  PetscCall(CheckDistinctFiles(comm, {{"-report", reportPath}}, {{"-rom", romPath}}));
  PetscCall(CheckSceneOptions(comm, "probe", romPath)); // (another scene's options file, -body_E: ignored without a word before)
  rep.root["stage"] = "probe";
  PetscCall(ProbeRomFile(comm, romPath, 1000, &rep.root["probe"], &ps));
  const JsonValue &p = rep.root["probe"];
  PetscCall(PetscPrintf(comm, "rbcontact probe: %s, %" PetscInt_FMT " parameters (%s), %" PetscInt_FMT " failed, %.3f s\n", romPath, ps.size, p.Get("type")->AsString().c_str(), ps.failed, p.Get("time_s")->AsNumber()));
  if (const JsonValue *e = p.Get("estimate"))
    PetscCall(PetscPrintf(comm, "  largest estimated errors over them: u %.3e, lambda %.3e, force %.3e\n", e->Get("u")->Get("max")->AsNumber(), e->Get("lambda")->Get("max")->AsNumber(), e->Get("force")->Get("max")->AsNumber()));
  if (ps.outOfRange) PetscCall(PetscPrintf(comm, "rbcontact probe: warning: at %" PetscInt_FMT " of %" PetscInt_FMT " parameters contact projections reached the edge of the stored contact data, where the answers may be wrong (first: %s)\n", ps.outOfRange, ps.size, ps.firstOutOfRange.c_str()));
  if (ps.failed) { // the whole report (the counts, the estimates), with the error, then the exit code
    const std::string err = "probe: the reduced model " + std::string(romPath) + " failed at " + std::to_string((long long)ps.failed) + " of " + std::to_string((long long)ps.size) + " probe parameters; first " + ps.firstFailure;
    PetscCall(rep.WriteFailed(comm, reportPath, err));
    SETERRQ(comm, PETSC_ERR_NOT_CONVERGED, "%s", err.c_str());
  }
  rep.root["converged"] = true;
  PetscCall(rep.Write(comm, reportPath));
  PetscFunctionReturn(0);
}

} // namespace rbc
