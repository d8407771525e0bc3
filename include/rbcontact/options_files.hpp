// rbcontact/options_files.hpp: the options of a run checked around PETSc's reading of them (the executable's main and
// the Python module's stages): the -options_file chain before (PETSc 3.18 follows -options_file inside a file
// recursively, so a file that includes itself overflowed the stack: a segmentation fault, no message), and the
// options nobody read after (misspelled).
#pragma once
#include <petscsys.h>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace rbc {

// Every "-options_file F" among words, and those the files name in turn: each exists and is readable, none includes
// itself, nested at most 16 deep. Files are resolved from the working directory, as PETSc does. Returns "" when all is
// well, else the message ("options file a.opts includes itself through -options_file (a.opts -> b.opts -> a.opts)").
std::string CheckOptionsFiles(const std::vector<std::string> &words);

// CheckOptionsFiles where PETSc reads the files (rank 0 of comm reads every options file, ~/.petscrc and PETSC_OPTIONS,
// and broadcasts them), its answer on every rank; MPI started, PETSc not needed (plain MPI calls). Checked on every rank,
// a file rank 0 reads but another rank cannot see (a node-local path) stopped that rank alone while rank 0 went on into
// PETSc's start: the run hung. OptionsFilesRead is then rank 0's. Collective.
std::string CheckOptionsFilesOnRankZero(MPI_Comm comm, const std::vector<std::string> &words);

// A word of a command line that names an option (-rom, -rom_N), not a value (-1, -.5).
bool IsOptionName(const std::string &word);

// A list value with an empty entry: ",100,100", "100,,100", "100," (CheckListEntries).
bool HasEmptyListEntry(const std::string &value);

// The options database in use as (name with its dash, value) pairs, in PetscOptionsGetAll's order; a flag's value is
// empty, a value of several words is joined by spaces. Empty when the database cannot be read (no PETSc error raised:
// the error handler calls it).
std::vector<std::pair<std::string, std::string>> OptionsInUse();

// After a stage ran: the options of the database in use (PETSc's default one, or a pushed one) that nobody read, as
// messages ("option -trian_size 5 was not used by the offline stage (misspelled? ...)"), leaving out the families of
// the other stages a shared scene file carries (-test_* for offline, -train_* for validate, ...). given: the words given
// directly (the command line, the Python keywords): online, probe and dualbasis leave out every option of a scene file but
// their own families, not those given directly.
// For PETSc's messages on a value that does not parse ("Input string 100abc has no numeric value", "... has no integer
// value", "... is out of the range of a 32-bit integer", "Unknown logical value: maybe"), which name no option: the
// options in use whose value holds that word, as " (option -train_size 4294967301)"; "" for any other message. For
// error handlers (the executable's, the Python module's).
std::string OptionsHoldingValue(const char *mess);

// No option in use has a list value with an empty entry (-body_E ,100,100: PETSc's "String of length zero has no
// numerical value", naming no option; -body_E 100,,100 read as 100,100 without a word; a trailing comma dropped):
// refused, naming the option. Collective on comm.
PetscErrorCode CheckListEntries(MPI_Comm comm);

// The options files the last CheckOptionsFiles visited (the whole -options_file chain, as named, and the
// -options_file_yaml files named on the way, not parsed): inputs of the run, which no output may replace
// (CheckDistinctFiles; `fom -report in.opts -options_file in.opts` overwrote it, exit 0; so did
// `-options_file_yaml a.yaml -report a.yaml` until 2026-12-04).
const std::vector<std::pair<std::string, std::string>> &OptionsFilesRead(); // (option, file)

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

// -help without an input the stage needs (rbcontact fom -help: no -mesh_file): the options read so far are listed, and
// the stage ends there with exit 0 instead of an error (PETSc lists an option as it is read, so the rest of the listing
// needs the inputs: docs/bad_input.md "-help"). Thrown by RequireInput, caught by the executable's main (the Python
// module turns it into a RuntimeError).
struct HelpStop : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The check of a stage's required input (given: the option holds a value). Missing: with -help, a note naming option
// and HelpStop; otherwise the error PETSC_ERR_USER_INPUT with message. Collective on comm.
PetscErrorCode RequireInput(MPI_Comm comm, bool given, const char *option, const char *message);

} // namespace rbc
