// src/io/provenance.cpp: the provenance record of a run (rbcontact/provenance.hpp).
#include "rbcontact/provenance.hpp"
#include <slepcsys.h>
#include <ctime>
#if defined(__has_include)
  #if __has_include("rbcontact_git_commit.h")
    #include "rbcontact_git_commit.h" // CMake: generated at build time (cmake/git_commit.cmake)
  #endif
#endif
#ifndef RBC_GIT_COMMIT
  #define RBC_GIT_COMMIT "unknown" // Makefile.petsc passes -DRBC_GIT_COMMIT
#endif
#ifndef RBC_VERSION
  #define RBC_VERSION "unknown"
#endif

namespace rbc {

static std::string Trimmed(const char *s)
{
  std::string t = s;
  while (!t.empty() && (t.back() == ' ' || t.back() == '\n')) t.pop_back();
  return t;
}

static std::string UtcNow()
{
  char        buf[32] = "";
  std::time_t t       = std::time(nullptr);
  std::tm     tm{};
  if (gmtime_r(&t, &tm)) std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string CodeVersion() { return RBC_VERSION; }

Provenance LocalProvenance()
{
  Provenance p;
  char       v[256] = "";
  p.version         = RBC_VERSION;
  p.commit          = RBC_GIT_COMMIT;
  if (!PetscGetVersion(v, sizeof v)) p.petsc = Trimmed(v);
  v[0] = 0;
  if (!SlepcGetVersion(v, sizeof v)) p.slepc = Trimmed(v);
  char *all = nullptr;
  if (!PetscOptionsGetAll(NULL, &all) && all) {
    p.options = all;
    (void)PetscFree(all);
  }
  p.date = UtcNow();
  PetscMPIInt size = 1, init = 0;
  MPI_Initialized(&init);
  if (init) MPI_Comm_size(PETSC_COMM_WORLD, &size);
  p.nranks = (int)size;
  return p;
}

std::string VersionLine()
{
  char v[256] = "", w[256] = "";
  (void)PetscGetVersion(v, sizeof v); // (formats the headers' version macros: no PETSc call)
  (void)SlepcGetVersion(w, sizeof w);
  return std::string("rbcontact ") + RBC_VERSION + " (commit " + RBC_GIT_COMMIT + "), " + Trimmed(v) + ", " + Trimmed(w);
}

PetscErrorCode GetProvenance(MPI_Comm comm, Provenance *p)
{
  PetscMPIInt size;

  PetscFunctionBeginUser;
  *p = LocalProvenance();
  PetscCallMPI(MPI_Comm_size(comm, &size));
  p->nranks = (int)size;
  PetscCall(BcastString(comm, &p->date));
  PetscFunctionReturn(0);
}

JsonValue ProvenanceJson(const Provenance &p)
{
  JsonValue j = JsonValue::Object();
  j["version"] = p.version;
  j["commit"]  = p.commit;
  j["petsc"]   = p.petsc;
  j["slepc"]   = p.slepc;
  j["date"]    = p.date;
  j["nranks"]  = p.nranks;
  j["options"] = p.options;
  return j;
}

std::vector<std::pair<std::string, std::string>> ProvenanceAttributes(const Provenance &p)
{
  return {{"code_version", p.version}, {"code_commit", p.commit}, {"petsc_version", p.petsc}, {"slepc_version", p.slepc}, {"created", p.date}, {"run_options", p.options}};
}

} // namespace rbc
