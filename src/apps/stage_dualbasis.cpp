// src/apps/stage_dualbasis.cpp: `rbcontact dualbasis`: a nonnegative dual basis of a multiplier
// snapshot matrix from any source: "file.h5:/dataset" or a PETSc binary matrix from another code
// (rows = multipliers, columns = snapshots), or a snapshot file of the offline stage.
#include "rbcontact/options_files.hpp"
#include "stages.hpp"
#include "rbcontact/offline_bases.hpp"
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/rom_file.hpp"

namespace rbc {

PetscErrorCode StageDualBasis(MPI_Comm comm)
{
  char           spec[PETSC_MAX_PATH_LEN] = "", reportPath[PETSC_MAX_PATH_LEN] = "", out[PETSC_MAX_PATH_LEN] = "";
  PetscBool      set;
  Report         rep;
  PetscLogDouble t0, t1, t2;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscOptionsBegin(comm, NULL, "rbcontact dualbasis: a nonnegative dual basis of multiplier snapshots", "rbcontact");
  PetscCall(PetscOptionsString("-snapshots", "the multiplier snapshots: file.h5:/dataset, a PETSc binary matrix, or an offline snapshot file", "", spec, spec, sizeof spec, &set));
  PetscCall(PetscOptionsString("-report", "JSON report of the run", "", reportPath, reportPath, sizeof reportPath, NULL));
  PetscCall(PetscOptionsString("-dual_out", "write the basis (and its history) to this HDF5 file", "", out, out, sizeof out, NULL));
  PetscOptionsEnd();
  PetscCall(RequireInput(comm, set && spec[0], "-snapshots", "dualbasis: give the multiplier snapshots with -snapshots file.h5:/dataset (or a PETSc binary matrix, or an offline snapshot file)"));
  PetscCall(CheckOutputPath(comm, reportPath, "-report"));
  PetscCall(CheckOutputPath(comm, out, "-dual_out"));
  {
    std::string in = spec; // file.h5:/dataset
    if (in.find(":/") != std::string::npos) in = in.substr(0, in.find(":/"));
    PetscCall(CheckDistinctFiles(comm, {{"-report", reportPath}, {"-dual_out", out}}, {{"-snapshots", in}}));
  }
  {
    // check the basis type before reading possibly large data
    char type[32] = "cpg";
    PetscCall(PetscOptionsGetString(NULL, NULL, "-dual_type", type, sizeof type, NULL));
    const std::string t(type);
    PetscCheck(t == "nmf" || t == "angle" || t == "cpg" || t == "mcpg", comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-dual_type: unknown value '%s' (nmf, angle, cpg or mcpg)", type);
  }
  DenseMatrix L;
  PetscCall(DualSnapshotMatrix(comm, spec, &L));
  PetscCall(PetscTime(&t1));
  DualBasisResult dual;
  PetscCall(BuildDualBasis(L, &dual));
  PetscCall(PetscTime(&t2));

  rep.root["stage"]     = "dualbasis";
  rep.root["snapshots"] = spec;
  rep.root["R_fom"]     = (long long)L.rows;
  rep.root["m"]         = (long long)L.cols;
  PetscCall(ReportDualBasis(comm, dual, &rep));
  rep.root["time_s"]["dual"]  = (double)(t2 - t1);
  rep.root["time_s"]["total"] = (double)(t2 - t0);
  if (out[0]) {
    RomWriter w;
    WriteDualBasis(dual, &w);
    w.Attr("snapshots", spec);
    PetscCall(w.Write(comm, out));
    rep.root["dual_out"] = out;
  }
  PetscCall(PetscPrintf(comm, "rbcontact dualbasis: %s, %" PetscInt_FMT " multipliers x %" PetscInt_FMT " snapshots -> r = %" PetscInt_FMT ", max training error %.3e (rel. %.3e), %.2f s\n", dual.type.c_str(), L.rows, L.cols, dual.W.cols, (double)dual.trainMaxErr, (double)dual.trainMaxRelErr, (double)(t2 - t1)));
  if (!dual.TolReached()) { // (exit 0 without a word before; report key dual.tol_reached)
    PetscCall(PetscPrintf(comm, "rbcontact dualbasis: warning: the basis misses its tolerance: max training error %.3e > %.3e (%s)\n", (double)dual.trainMaxErr, (double)dual.tolAbs, dual.MissedTolReason(L.cols).c_str()));
  }
  PetscCall(rep.Write(comm, reportPath));
  PetscFunctionReturn(0);
}

} // namespace rbc
