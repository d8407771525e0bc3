// tests/test_check.hpp: the pass/fail line of the C++ tests. Check prints one line per check (rank 0) and counts
// the failures; collective: a check fails when it fails on any rank.
#pragma once
#include <petscsys.h>

namespace rbctest {

inline int failures = 0;

inline PetscErrorCode Check(MPI_Comm comm, bool ok, const char *what, double v, double bound)
{
  int okl = ok ? 1 : 0, okg = 0;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&okl, &okg, 1, MPI_INT, MPI_MIN, comm));
  PetscCall(PetscPrintf(comm, "  %-6s %-70s %.3e (bound %.1e)\n", okg ? "ok" : "FAIL", what, v, bound));
  if (!okg) ++failures;
  PetscFunctionReturn(0);
}

} // namespace rbctest
