// rbcontact/provenance.hpp: where a result came from. The project version and the git commit it was
// built from, the PETSc and SLEPc versions, the run's options, the number of ranks and the date (UTC):
// every JSON report (Report::Write adds the key "provenance") and every HDF5 file rbcontact writes
// (the attributes of ProvenanceAttributes) carry them.
#pragma once
#include <petscsys.h>
#include <string>
#include <utility>
#include <vector>
#include "rbcontact/report.hpp"

namespace rbc {

struct Provenance {
  std::string version; // the project's (CMakeLists.txt)
  std::string commit;  // git commit of the source tree at build time (+ "-dirty"), or "unknown"
  std::string petsc, slepc;
  std::string options; // PetscOptionsGetAll: the command line and the -options_file contents
  std::string date;    // ISO 8601, UTC
  int         nranks = 1;
};

// Collective on comm (the date is rank 0's).
PetscErrorCode GetProvenance(MPI_Comm comm, Provenance *p);
// The same without communication (the caller's clock; nranks of PETSC_COMM_WORLD): for rank-0-only writers.
Provenance LocalProvenance();
JsonValue  ProvenanceJson(const Provenance &p);
// HDF5 string attributes: code_version, code_commit, petsc_version, slepc_version, created (date),
// run_options.
std::vector<std::pair<std::string, std::string>> ProvenanceAttributes(const Provenance &p);
// The project version ("0.1.0"): the snapshot file's code_version.
std::string CodeVersion();
// One line for `rbcontact --version`: "rbcontact 0.1.0 (commit <sha>), PETSc Release Version 3.18.4, ..., SLEPc ...".
// Needs neither MPI nor PETSc initialized.
std::string VersionLine();

} // namespace rbc
