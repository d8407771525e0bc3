// src/apps/petsc_int_option.cpp: PETSc 3.18's PetscOptionsStringToInt, which every integer option of the
// executable goes through (PetscOptionsInt, PetscOptionsGetInt, the int arrays), with a range check. PETSc
// converts with strtol and casts to the 32-bit PetscInt without a word, so -rom_N 4294967297 ran with N 1 and
// -train_size 4294967299 trained 3 points (docs/bad_input.md). Defined in the executable, this definition
// takes the place of the library's (ELF symbol interposition; the library calls it through its PLT):
// the same special words and messages, plus "out of the range of a 32-bit integer". Linked into the Python module
// too (CMakeLists.txt), where it does the same when the module loads PETSc (it comes first in the lookup scope of the
// libraries it loads), not when PETSc was loaded before it (petsc4py imported first: python/module.cpp warns).
// tests: bad_input_stages.cmake `int_value_wraps`, python_checks.py.
#include <petscsys.h>
#include <cerrno>
#include <climits>
#include <cstdlib>

extern "C" PetscErrorCode PetscOptionsStringToInt(const char name[], PetscInt *a)
{
  size_t    len;
  PetscBool decide, tdefault, mouse;

  PetscFunctionBegin;
  PetscCall(PetscStrlen(name, &len));
  PetscCheck(len, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "character string of length zero has no numerical value");
  PetscCall(PetscStrcasecmp(name, "PETSC_DEFAULT", &tdefault));
  if (!tdefault) PetscCall(PetscStrcasecmp(name, "DEFAULT", &tdefault));
  PetscCall(PetscStrcasecmp(name, "PETSC_DECIDE", &decide));
  if (!decide) PetscCall(PetscStrcasecmp(name, "DECIDE", &decide));
  PetscCall(PetscStrcasecmp(name, "mouse", &mouse));
  if (tdefault) *a = PETSC_DEFAULT;
  else if (decide) *a = PETSC_DECIDE;
  else if (mouse) *a = -1;
  else {
    char *end = nullptr;
    errno     = 0;
    const long long v = std::strtoll(name, &end, 10);
    PetscCheck((size_t)(end - name) == len, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Input string %s has no integer value (do not include . in it)", name);
    PetscCheck(errno != ERANGE && v >= PETSC_MIN_INT && v <= PETSC_MAX_INT, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Input string %s is out of the range of a %d-bit integer", name, (int)(8 * sizeof(PetscInt)));
    *a = (PetscInt)v;
  }
  PetscFunctionReturn(0);
}
