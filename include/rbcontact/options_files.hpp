// rbcontact/options_files.hpp: the options of a run checked around PETSc's reading of them (the executable's main and
// the Python module's stages): the -options_file chain before (PETSc 3.18 follows -options_file inside a file
// recursively, so a file that includes itself overflowed the stack: a segmentation fault, no message), and the
// options nobody read after (misspelled).
#pragma once
#include <petscsys.h>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace rbc {

// Every "-options_file F" among words, and those the files name in turn: each exists and is readable, none includes
// itself, nested at most 16 deep. Files are resolved from the working directory, as PETSc does. Returns "" when all is
// well, else the message ("options file a.opts includes itself through -options_file (a.opts -> b.opts -> a.opts)").
std::string CheckOptionsFiles(const std::vector<std::string> &words);

// The options database in use as (name with its dash, value) pairs, in PetscOptionsGetAll's order; a flag's value is
// empty, a value of several words is joined by spaces. Empty when the database cannot be read (no PETSc error raised:
// the error handler calls it).
std::vector<std::pair<std::string, std::string>> OptionsInUse();

// After a stage ran: the options of the database in use (PETSc's default one, or a pushed one) that nobody read, as
// messages ("option -trian_size 5 was not used by the offline stage (misspelled? ...)"), leaving out the families of
// the other stages a shared scene file carries (-test_* for offline, -train_* for validate, ...). given: the words given
// directly (the command line, the Python keywords): online, probe and dualbasis leave out every option of a scene file but
// their own families, not those given directly.
// The options files the last CheckOptionsFiles visited (the whole -options_file chain, as named): inputs of the run,
// which no output may replace (CheckDistinctFiles; `fom -report in.opts -options_file in.opts` overwrote it, exit 0).
const std::vector<std::string> &OptionsFilesRead();

// Each of these options, where it is given, has a value: PETSc's readers keep the default for an option given without
// one (-rom_N at the end of a command line), without a word. Collective on comm (the options are the same on every rank).
PetscErrorCode CheckValuesGiven(MPI_Comm comm, std::initializer_list<const char *> names);
// The same for -<prefix><name> (names without the dash: {"seed", "type"} with prefix "test_").
PetscErrorCode CheckValuesGiven(MPI_Comm comm, const std::string &prefix, std::initializer_list<const char *> names);
// The Krylov tolerances of the KSP of options prefix `prefix` ("fom_saddle_": -fom_saddle_ksp_rtol, _atol, _max_it), where
// given, before PETSc reads them: rtol a finite number in [0, 1), atol finite and >= 0, max_it >= 1, each with a value.
// (PETSc 3.18 refused a NaN rtol naming no option, and took a NaN atol or a negative max_it without a word.)
PetscErrorCode CheckKSPTolerances(MPI_Comm comm, const std::string &prefix);

PetscErrorCode UnusedOptions(const std::string &stage, std::vector<std::string> *unused, const std::vector<std::string> &given = {});

} // namespace rbc
