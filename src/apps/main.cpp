// src/apps/main.cpp: the rbcontact executable. The first argument is the stage word (fom, offline,
// online, validate, probe, dualbasis); PETSc options follow it. Each stage writes -report <file.json>.
#include <petscsys.h>
#include <slepcsys.h>
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>
#include "rbcontact/options_files.hpp"
#include "rbcontact/provenance.hpp"
#include "stages.hpp"

static const char help[] = "rbcontact: reduced-basis model reduction of frictionless contact.\n"
                           "Usage: rbcontact <stage> [PETSc options]\n"
                           "Stages:\n"
                           "  fom       solve the full-order model of a scene (-options_file runs/<scene>.opts)\n"
                           "  offline   snapshots, bases, EIM -> the ROM file (-rom rom.h5; -offline_stop snapshots|bases)\n"
                           "  online    reduced solve at a parameter (-rom rom.h5 -mu v; -rom_reconstruct fields.h5)\n"
                           "  validate  ROM against FOM on a test set, speed against error (-rom rom.h5 -test_size n; -validate_sweep)\n"
                           "  probe     ROM solved over its parameter box, no FOM: failures, iterations, estimated errors (-rom rom.h5 -probe_size n)\n"
                           "  dualbasis nonnegative dual basis of imported multiplier snapshots (-snapshots f.h5:/dataset)\n"
                           "Options of each stage: README.md and docs/ (contact.md, reference_configuration.md, offline.md, bases.md, eim.md, online.md).\n";

// After a successful stage: a warning per option nobody read (misspelled, or for another solver).
static PetscErrorCode WarnUnusedOptions(const std::string &stage, const std::vector<std::string> &given)
{
  std::vector<std::string> unused;

  PetscFunctionBeginUser;
  PetscCall(rbc::UnusedOptions(stage, &unused, given));
  for (const auto &u : unused) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "rbcontact: warning: %s\n", u.c_str()));
  PetscFunctionReturn(0);
}

// Error handler: the message and a short trace, without PETSc's configure banner; the first line
// names the option, file or value at fault (every check in rbcontact says which; PETSc's messages for a value that does
// not parse name the options holding it, rbc::OptionsHoldingValue).
// The first error of the run, for the failure report (FailureReport).
static std::string firstError;

static PetscErrorCode ConciseErrorHandler(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *ctx)
{
  PetscMPIInt rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (p == PETSC_ERROR_INITIAL) {
    std::fprintf(stderr, "[%d] rbcontact error: %s%s\n", (int)rank, mess ? mess : "(no message)", rbc::OptionsHoldingValue(mess).c_str());
    if (firstError.empty()) firstError = std::string(mess ? mess : "(no message)") + rbc::OptionsHoldingValue(mess) + " (in " + (fun ? fun : "?") + "() at " + (file ? file : "?") + ":" + std::to_string(line) + ")";
  }
  std::fprintf(stderr, "[%d]     in %s() at %s:%d\n", (int)rank, fun ? fun : "?", file ? file : "?", line);
  return n;
}

// With several ranks on the machine's cores, a threaded BLAS (libopenblas0-pthread, installed by
// share/setup.sh) would start its own threads in every rank and oversubscribe the cores: one BLAS thread
// per rank unless OPENBLAS_NUM_THREADS says otherwise (docs/fom_speed.md). A reference BLAS has no such
// symbol: nothing to do.
static PetscErrorCode OneBlasThreadPerRank()
{
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  if (size > 1 && !std::getenv("OPENBLAS_NUM_THREADS")) {
    using SetThreads = void (*)(int);
    if (auto fn = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) fn(1);
  }
  PetscFunctionReturn(0);
}

// A failed run still leaves its -report: {"stage", "converged": false, "error": the first message,
// "error_code", "provenance"}, written by rank 0 alone (the failure need not be collective: no
// communication here), to a temporary file then renamed. A report the stage wrote before failing
// is replaced: the run did not finish. Never onto a device, a path the run refused (an input, another
// output) or an HDF5 file (a ROM, snapshot or field file named by mistake).
static void FailureReport(const std::string &stage, PetscErrorCode ierr, bool anyRank = false)
{
  char        path[PETSC_MAX_PATH_LEN] = "";
  PetscBool   set                      = PETSC_FALSE;
  PetscMPIInt rank                     = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if ((rank != 0 && !anyRank) || PetscOptionsGetString(NULL, NULL, "-report", path, sizeof path, &set) || !set || !path[0]) return;
  rbc::WriteFailureReport(path, stage, firstError.empty() ? std::string("failed on another rank (its message is on stderr)") : firstError, (long long)ierr, true);
}

// A failure on some ranks only (a reader that failed on rank 0 while the others wait in its collectives, an error
// raised by one rank's data) would leave the run hanging: the failed ranks would wait in SlepcFinalize for ranks that
// wait for them. So a failed rank first meets the others in a barrier of its own communicator (never PETSc's, whose
// pending collectives it must not match) and waits -rbc_error_wait seconds (default 10) for every rank to arrive:
// all did when the failure was collective, and the run ends normally with the error. Otherwise it says so, writes
// the failure report (rank 0 may be the one waiting) and calls MPI_Abort, which ends every rank.
static MPI_Comm  exitComm  = MPI_COMM_NULL;
static PetscReal errorWait = 10;

static PetscErrorCode ExitCommCreate()
{
  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetReal(NULL, NULL, "-rbc_error_wait", &errorWait, NULL));
  PetscCheck(errorWait > 0 && errorWait <= 86400, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE, "-rbc_error_wait %g must lie in (0, 86400] seconds", (double)errorWait);
  PetscCallMPI(MPI_Comm_dup(PETSC_COMM_WORLD, &exitComm));
  PetscFunctionReturn(0);
}

static void AbortUnlessAllFailed(const std::string &stage, PetscErrorCode ierr)
{
  PetscMPIInt size = 1, rank = 0, done = 0;
  const double wait = errorWait;
  MPI_Request req;
  if (exitComm == MPI_COMM_NULL) return;
  MPI_Comm_size(exitComm, &size);
  if (size == 1) return;
  MPI_Comm_rank(exitComm, &rank);
  MPI_Ibarrier(exitComm, &req);
  for (const double t0 = MPI_Wtime(); !done && MPI_Wtime() - t0 < wait;) {
    MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    if (!done) usleep(2000);
  }
  if (done) return;
  std::fprintf(stderr, "[%d] rbcontact error: the other ranks did not reach this failure within %g s (-rbc_error_wait): it is this rank's alone, and they would wait for it; aborting the run\n", (int)rank, (double)wait);
  FailureReport(stage, ierr, true);
  MPI_Abort(MPI_COMM_WORLD, (int)ierr);
}

// Test hook (tests/usability_checks.py failure): -rbc_test_fail_rank r raises an error on rank r only, before the
// stage, while the other ranks run it (and wait for rank r in its first collective); with -rbc_test_fail_throw, a C++
// exception instead (the catch in main).
static PetscErrorCode TestFailRank(bool *doThrow)
{
  PetscInt    r = -1;
  PetscMPIInt rank;
  PetscBool   thr = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-rbc_test_fail_rank", &r, NULL));
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-rbc_test_fail_throw", &thr, NULL));
  *doThrow = thr && r == rank;
  PetscCheck(thr || r != rank, PETSC_COMM_SELF, PETSC_ERR_USER, "-rbc_test_fail_rank %d: an error raised on this rank only", (int)rank);
  PetscFunctionReturn(0);
}

static int RunStage(int argc, char **argv, const std::string &stage);

int main(int argc, char **argv)
{
  if (argc == 2 && (!std::strcmp(argv[1], "--version") || !std::strcmp(argv[1], "-version") || !std::strcmp(argv[1], "version"))) {
    std::printf("%s\n", rbc::VersionLine().c_str());
    return 0;
  }
  if (argc == 2 && (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-help") || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "help"))) {
    std::printf("%s(`rbcontact <stage> -help` lists the options of a stage; `rbcontact --version` the version.)\n", help); // (was "error: the first argument must be a stage word", exit 1)
    return 0;
  }
  if (argc < 2 || argv[1][0] == '-') {
    std::fprintf(stderr, "%s\nerror: the first argument must be a stage word (fom, ...); `rbcontact --help` prints this, `rbcontact <stage> -help` a stage's options\n", help);
    return 1;
  }
  const std::string stage = argv[1];
  // Drop the stage word: PETSc sees the options only.
  for (int i = 1; i < argc - 1; ++i) argv[i] = argv[i + 1];
  --argc;

  // MPI before PETSc, which then leaves MPI_Finalize to this function: the options files are checked before PETSc reads
  // them (a self-including file overflowed its stack) and where it reads them, on rank 0, with one answer for every rank
  // (checked on each rank, a file that only rank 0 could see stopped the other ranks while rank 0 started PETSc: a hang)
  int provided = 0, rank = 0;
  MPI_Init_thread(&argc, &argv, PETSC_MPI_THREAD_REQUIRED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::string bad = rbc::CheckOptionsFilesOnRankZero(MPI_COMM_WORLD, std::vector<std::string>(argv + 1, argv + argc));
  if (!bad.empty()) { // PETSc is not initialized
    if (rank == 0) std::fprintf(stderr, "[0] rbcontact error: %s\n", bad.c_str());
    for (int i = 1; rank == 0 && i + 1 < argc; ++i)
      if (!std::strcmp(argv[i], "-report") && argv[i + 1][0]) rbc::WriteFailureReport(argv[i + 1], stage, bad, (long long)PETSC_ERR_FILE_OPEN, false);
    MPI_Finalize();
    return (int)PETSC_ERR_FILE_OPEN;
  }
  const int code = RunStage(argc, argv, stage);
  MPI_Finalize();
  return code;
}

// The stage under PETSc, MPI started (main).
static int RunStage(int argc, char **argv, const std::string &stage)
{
  const std::vector<std::string> given(argv + 1, argv + argc); // the options given on the command line (WarnUnusedOptions)
  PetscCall(SlepcInitialize(&argc, &argv, NULL, help));
  PetscCall(OneBlasThreadPerRank());
  {
    PetscBool full = PETSC_FALSE;
    PetscCall(PetscOptionsGetBool(NULL, NULL, "-rbc_full_traceback", &full, NULL));
    if (!full) PetscCall(PetscPushErrorHandler(ConciseErrorHandler, NULL));
  }
  PetscErrorCode ierr = ExitCommCreate();
  if (!ierr) ierr = rbc::CheckListEntries(PETSC_COMM_WORLD);
  bool doThrow = false;
  if (!ierr) ierr = TestFailRank(&doThrow);
  try {
    if (doThrow) throw std::runtime_error("-rbc_test_fail_rank with -rbc_test_fail_throw: an exception thrown on this rank only");
    if (ierr) {
    } else if (stage == "fom") ierr = rbc::StageFom(PETSC_COMM_WORLD);
    else if (stage == "offline") ierr = rbc::StageOffline(PETSC_COMM_WORLD);
    else if (stage == "dualbasis") ierr = rbc::StageDualBasis(PETSC_COMM_WORLD);
    else if (stage == "online") ierr = rbc::StageOnline(PETSC_COMM_WORLD);
    else if (stage == "validate") ierr = rbc::StageValidate(PETSC_COMM_WORLD);
    else if (stage == "probe") ierr = rbc::StageProbe(PETSC_COMM_WORLD);
    else {
      firstError = "unknown stage '" + stage + "' (known: fom, offline, online, validate, probe, dualbasis)";
      PetscCall(PetscPrintf(PETSC_COMM_WORLD, "rbcontact: %s\n", firstError.c_str()));
      ierr = PETSC_ERR_ARG_UNKNOWN_TYPE;
    }
  } catch (const rbc::HelpStop &h) { // -help without the stage's input: the options read so far were listed (RequireInput)
    firstError = std::string(h.what()) + " (nothing was run)"; // a -report is replaced all the same: never an earlier run's left in place
    FailureReport(stage, 0);
    PetscCallMPI(MPI_Comm_free(&exitComm));
    PetscCall(SlepcFinalize());
    return 0;
  } catch (const std::exception &e) { // a C++ exception through the stage (std::bad_alloc: a size beyond memory): said, reported, then
    // MPI_Abort, since the other ranks may wait in a collective
    const bool  mem = dynamic_cast<const std::bad_alloc *>(&e) != nullptr;
    PetscMPIInt rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    firstError = std::string(mem ? "out of memory (std::bad_alloc): a size option too large for this machine?" : "C++ exception: ") + (mem ? "" : e.what());
    std::fprintf(stderr, "[%d] rbcontact error: %s\n", (int)rank, firstError.c_str());
    ierr = mem ? PETSC_ERR_MEM : PETSC_ERR_LIB;
    FailureReport(stage, ierr, true); // by this rank: rank 0 may be waiting elsewhere
    MPI_Abort(MPI_COMM_WORLD, (int)ierr);
  }
  if (ierr) {
    // The error message was printed by PETSc's handler; the report says the run failed; exit non-zero.
    FailureReport(stage, ierr);
    AbortUnlessAllFailed(stage, ierr);
    if (exitComm != MPI_COMM_NULL) MPI_Comm_free(&exitComm);
    (void)SlepcFinalize();
    return (int)ierr;
  }
  PetscCall(WarnUnusedOptions(stage, given));
  PetscCallMPI(MPI_Comm_free(&exitComm));
  PetscCall(SlepcFinalize());
  return 0;
}
