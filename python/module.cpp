// python/module.cpp: the Python module rbcontact._rbcontact (pybind11): the online stage of a ROM file
// (rbc::ReducedModel) from Python, with NumPy arrays in and out, and the offline and validate stages of
// the library (RunOffline, RunValidation) with their options scoped to the call. PETSc/SLEPc are initialized on the first
// use (rbcontact.initialize(options) to pass PETSc options first) and finalized at exit; every PETSc error
// becomes a Python RuntimeError carrying PETSc's message (the file, option or value it names).
// Every call into PETSc and the library runs with the GIL released and a mutex held (PETSc's options database and
// error state are global: concurrent calls from threads run one after the other); Ctrl-C is seen at the call's end.
// Integer options beyond 32 bits are refused as by the executable (src/apps/petsc_int_option.cpp is linked in).
// The Python side (python/rbcontact/__init__.py) re-exports these names. docs/python.md.
#include "rbcontact/options_files.hpp"
#include "rbcontact/provenance.hpp"
#include "rbcontact/rom_probe.hpp"
#include "rbcontact/rom_fields.hpp"
#include "rbcontact/offline.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/validation.hpp"
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <slepcsys.h>
#include <limits>
#include <memory>
#include <cxxabi.h>
#include <mutex>
#include <type_traits>
#include <unistd.h>
#include <stdexcept>
#include <string>
#include <vector>

namespace py = pybind11;

namespace {

std::string lastError; // the first message of the failing PETSc call (PETSC_ERROR_INITIAL)

PetscErrorCode CaptureErrorHandler(MPI_Comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *)
{
  if (p == PETSC_ERROR_INITIAL) lastError = std::string(mess ? mess : "(no message)") + rbc::OptionsHoldingValue(mess) + " (in " + (fun ? fun : "?") + "() at " + (file ? file : "?") + ":" + std::to_string(line) + ")";
  return n;
}

// Throws the captured PETSc message for a non-zero error code.
void Check(PetscErrorCode ierr)
{
  if (!ierr) return;
  std::string msg = lastError.empty() ? "PETSc error " + std::to_string((int)ierr) : lastError;
  lastError.clear();
  throw std::runtime_error(msg);
}

// PETSc (its options database, its error handler) and the library's state are global and not thread-safe: every call
// into them runs through Serialized, with this mutex held and the GIL released, so that other Python threads run
// meanwhile (a stage takes minutes) and calls from several threads run one after the other. What runs there touches
// no Python object; warnings are issued after, with the GIL held and the mutex free (a warning filter may call back
// into the module). The mutex is never held while waiting for the GIL, so taking it with the GIL held (~Model) cannot
// deadlock.
std::mutex libraryMutex;

// The GIL is taken back in the function's body, never in a destructor: a daemon thread that asks for it while the
// interpreter finalizes is ended by pthread_exit, whose forced unwind out of a destructor (pybind11's
// gil_scoped_release) was std::terminate, SIGABRT at the exit (audit J, 2026-12-02). During finalization the thread
// does not take it back at all: it waits for the process to end.
template <class F>
auto Serialized(F &&f) -> decltype(f())
{
  PyThreadState *ts      = PyEval_SaveThread();
  auto           restore = [ts] {
    while (_Py_IsFinalizing()) pause(); // the process is exiting: this (daemon) thread must not run Python again
    PyEval_RestoreThread(ts);
  };
  try {
    std::unique_lock<std::mutex> lock(libraryMutex); // released before the GIL is taken again
    if constexpr (std::is_void_v<decltype(f())>) {
      f();
      lock.unlock();
      restore();
    } else {
      auto r = f();
      lock.unlock();
      restore();
      return r;
    }
  } catch (abi::__forced_unwind &) {
    throw; // the thread is being ended (by restore): let it go
  } catch (...) {
    restore(); // the mutex was released by the unwinding
    throw;
  }
}

void Warn(PyObject *category, const std::string &message)
{
  if (PyErr_WarnEx(category, message.c_str(), 1) < 0) throw py::error_already_set(); // warnings turned into errors
}

bool initializedHere = false, exiting = false, mpiBeganHere = false; // (mpiBeganHere: MPI started by Initialize, finalized by Finalize)
int  liveModels      = 0; // PETSc is finalized at exit once no ReducedModel (which may hold PETSc objects) is alive
std::vector<std::string> initOptions;              // initialize()'s, checked after the first model read them
bool                     initOptionsChecked = false;

std::string Shown(std::string w)
{
  for (size_t k; (k = w.find('\0')) != std::string::npos;) w.replace(k, 1, "\\0");
  return w;
}

// The words of a call (initialize's options, a stage's keywords and words), before PETSc reads them: a NUL character
// cuts a word where PETSc reads it (rom="a\0b" opened 'a'), an empty word makes the option before it a flag
// (report="" wrote no report, sizes=[] ran the defaults), a list with an empty entry (sizes=[3, "", 5]) lost it
// without a word (the executable refuses it: rbc::CheckListEntries), a double quote would end PETSc's quoting of
// a value with spaces. Refused, naming the option (the keyword) and its value.
void CheckWords(const std::vector<std::string> &words, const std::string &who)
{
  for (size_t i = 0; i < words.size(); ++i) {
    const std::string &w      = words[i];
    const bool         isName = rbc::IsOptionName(w);
    const std::string  option = isName || i == 0 || !rbc::IsOptionName(words[i - 1]) ? "" : "option " + Shown(words[i - 1]) + " ";
    if (w.find('\0') != std::string::npos) throw std::runtime_error(who + ": " + (option.empty() ? "the word '" + Shown(w) + "'" : option + "'" + Shown(w) + "'") + ": a NUL character in the value");
    if (w.empty()) throw std::runtime_error(who + ": " + (option.empty() ? "an empty word" : option + "is given an empty value ('' or an empty list; None leaves an option out)"));
    if (!isName && rbc::HasEmptyListEntry(w)) throw std::runtime_error(who + ": " + option + w + ": an empty entry in the list (a comma too many?)");
    if (w.find('"') != std::string::npos) throw std::runtime_error(who + ": an option value may not hold a double quote: " + w);
  }
}

// Once PETSc runs: whether its integer options go through the range check of src/apps/petsc_int_option.cpp, linked
// into this module, which takes the place of PETSc's own when the module loaded PETSc (ELF symbol interposition),
// not when PETSc was loaded before it (petsc4py imported first): tried on an options database of its own.
bool IntRangeChecked()
{
  static int state = -1;
  if (state < 0) {
    PetscOptions o   = nullptr;
    PetscInt     v   = 0;
    PetscBool    set = PETSC_FALSE;
    state            = 0;
    if (!PetscPushErrorHandler(PetscReturnErrorHandler, NULL)) {
      if (!PetscOptionsCreate(&o)) {
        if (!PetscOptionsSetValue(o, "-rbc_int_range_check", "4294967297")) state = PetscOptionsGetInt(o, NULL, "-rbc_int_range_check", &v, &set) != 0;
        (void)PetscOptionsDestroy(&o);
      }
      (void)PetscPopErrorHandler();
    }
  }
  return state == 1;
}

// PETSc started with these options unless it runs already (under the mutex).
void Initialize(const std::vector<std::string> &options)
{
  // MPI cannot start again in a process: after rbcontact.finalize() every call raises (it aborted the interpreter)
  if (PetscFinalizeCalled) throw std::runtime_error("rbcontact: PETSc was finalized (rbcontact.finalize()); it cannot be started again in this process");
  if (PetscInitializeCalled) {
    if (!options.empty()) throw std::runtime_error("rbcontact.initialize: PETSc is already initialized; pass the options before the first ReducedModel");
    return;
  }
  CheckWords(options, "rbcontact.initialize");
  // MPI first (unless mpi4py or another library started it), for the check of the options files where PETSc reads them:
  // on rank 0, one answer for every rank (checked on each rank, a file only rank 0 could see raised on the other ranks
  // while rank 0 started PETSc: a hang under mpirun)
  {
    int up = 0, down = 0, provided = 0;
    MPI_Initialized(&up);
    MPI_Finalized(&down);
    if (down) throw std::runtime_error("rbcontact: MPI was finalized; PETSc cannot be started again in this process");
    if (!up) {
      if (MPI_Init_thread(nullptr, nullptr, PETSC_MPI_THREAD_REQUIRED, &provided) != MPI_SUCCESS) throw std::runtime_error("rbcontact: MPI_Init_thread failed");
      mpiBeganHere = true;
    }
  }
  {
    const std::string bad = rbc::CheckOptionsFilesOnRankZero(MPI_COMM_WORLD, options);
    if (!bad.empty()) throw std::runtime_error("rbcontact.initialize: " + bad);
  }
  // MPI and PETSc keep argv: it lives as long as the process, and ends with a null pointer (MPI_Init reads it)
  static std::vector<std::string> args;
  static std::vector<char *>      argv;
  args = {"rbcontact-python"};
  args.insert(args.end(), options.begin(), options.end());
  argv.clear();
  for (auto &a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  int    argc = (int)args.size();
  char **av   = argv.data();
  if (SlepcInitialize(&argc, &av, NULL, NULL)) throw std::runtime_error("rbcontact: SlepcInitialize failed");
  initializedHere = true;
  initOptions     = options;
  if (PetscPushErrorHandler(CaptureErrorHandler, NULL)) throw std::runtime_error("rbcontact: PetscPushErrorHandler failed");
}

// Every entry point first: PETSc started (Initialize), and once a warning if the integer options are not range-checked.
void Start(const std::vector<std::string> &options = {})
{
  static bool warned  = false;
  const bool  checked = Serialized([&] {
    Initialize(options);
    return IntRangeChecked();
  });
  if (!checked && !warned) {
    warned = true;
    Warn(PyExc_RuntimeWarning, "rbcontact: PETSc was loaded before this module (by petsc4py?): integer options beyond 32 bits are not refused and "
                               "wrap (4294967297 is read as 1); import rbcontact first");
  }
}

void Finalize()
{
  if (initializedHere && PetscInitializeCalled && !PetscFinalizeCalled) (void)SlepcFinalize();
  initializedHere = false;
  int down = 0;
  MPI_Finalized(&down);
  if (mpiBeganHere && !down) MPI_Finalize(); // (PETSc leaves MPI to whoever started it)
  mpiBeganHere = false;
}

// At interpreter exit: finalize now, or when the last model goes.
void AtExit()
{
  Serialized([] {
    exiting = true;
    if (liveModels == 0) Finalize();
  });
}

// One reduced solution, as Python sees it.
struct Solution {
  py::array_t<double> v, lambda_hat, force;
  bool                converged = false;
  PetscInt            iterations = 0;
  double              contactForce = std::numeric_limits<double>::quiet_NaN();
  double              maxPressure = std::numeric_limits<double>::quiet_NaN(), halfwidth = std::numeric_limits<double>::quiet_NaN(), contactLength = std::numeric_limits<double>::quiet_NaN(),
                      contactRadius = std::numeric_limits<double>::quiet_NaN();
  // the online error estimate (docs/error_estimate.md): estimated relative errors, nan when the ROM file has none
  double              estU = std::numeric_limits<double>::quiet_NaN(), estLambda = std::numeric_limits<double>::quiet_NaN(), estForce = std::numeric_limits<double>::quiet_NaN();
  std::string         message;
  PetscInt            outOfRange = 0; // contact projections at the edge of the stored contact data (the command line warns)
};

py::array_t<double> Array(const std::vector<PetscReal> &x)
{
  py::array_t<double> a((py::ssize_t)x.size());
  auto                m = a.mutable_unchecked<1>();
  for (size_t i = 0; i < x.size(); ++i) m((py::ssize_t)i) = x[i];
  return a;
}

// Opened by Open (PETSc started, the constructor under the mutex).
class Model {
public:
  explicit Model(const std::string &file)
  {
    ++liveModels;
    try {
      Check(model_.Open(file));
      Check(model_.SetFromOptions());
    } catch (...) {
      --liveModels;
      throw;
    }
  }
  ~Model()
  {
    std::lock_guard<std::mutex> lock(libraryMutex); // with the GIL (also during the interpreter's exit)
    (void)model_.qp.Reset();                        // its PETSc objects, while PETSc is up
    if (--liveModels == 0 && exiting) Finalize();
  }
  Model(const Model &)            = delete;
  Model &operator=(const Model &) = delete;

  // obj as a C-contiguous float64 array: a complex array was cast to its real part without a word (forcecast), a bool
  // taken as 1.0, and a copy that could not be allocated (a broadcast view of 1e12 rows) a segmentation fault
  static py::array_t<double, py::array::c_style | py::array::forcecast> RealArray(py::object obj, const std::string &who)
  {
    py::array in = py::array::ensure(obj);
    if (!in) throw py::type_error(who + ": expected an array of parameter values");
    const char kind = in.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u') throw py::type_error(who + ": expected real parameter values, got dtype " + std::string(py::str(in.dtype())));
    auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(in);
    if (!a) {
      PyErr_SetString(PyExc_MemoryError, (who + ": cannot make a contiguous float64 copy of the array of " + std::to_string((long long)in.size()) + " values").c_str());
      throw py::error_already_set();
    }
    return a;
  }

  Solution Solve(py::object obj)
  {
    auto a = RealArray(obj, "solve");
    if (a.ndim() > 1) throw py::type_error("solve: expected a sequence of parameter values (one point), got an array of " + std::to_string((long long)a.ndim()) + " dimensions");
    const std::vector<PetscReal> m(a.data(), a.data() + a.size());
    rbc::ReducedSolution         sol;
    rbc::SurfaceOutputValues     so;
    Serialized([&] {
      Check(model_.par.CheckBox(PETSC_COMM_SELF, m, "solve")); // a clear error naming the parameter, its value and the box (it blamed -mu)
      Check(model_.Solve(m, &sol));
      if (sol.converged) model_.SurfaceOutputsOf(m, sol, &so);
    });
    Solution s;
    s.v          = Array(sol.v);
    s.lambda_hat = Array(sol.lambda);
    s.force      = Array(sol.force);
    s.converged  = sol.converged;
    s.iterations = sol.iterations;
    if (!sol.force.empty() && sol.converged) s.contactForce = sol.ForceMagnitude();
    if (sol.converged) {
      s.maxPressure   = so.maxPressure;
      s.halfwidth     = so.halfwidth;
      s.contactLength = so.contactLength;
      s.contactRadius = so.contactRadius;
      if (sol.estimate.available) {
        s.estU      = sol.estimate.u;
        s.estLambda = sol.estimate.lambda;
        s.estForce  = sol.estimate.force;
      }
    }
    s.message    = sol.message;
    s.outOfRange = sol.outOfRange;
    // (said by the command line's online, silent here until 2026-12-02; audit J)
    if (sol.converged && sol.outOfRange > 0) Warn(PyExc_RuntimeWarning, "rbcontact: " + std::to_string((long long)sol.outOfRange) + " contact projections fell at the edge of the stored contact data (outside the training range): the answer may be wrong; more -eim_patch_rings offline, or training parameters near this one (Solution.out_of_range)");
    return s;
  }

  // The contact force at every row of mus (n x p): one NumPy array of n values. A solve that does not
  // converge raises (its message names the parameter), unless nan_on_failure.
  py::array_t<double> ContactForces(py::object obj, bool nanOnFailure)
  {
    auto           mus = RealArray(obj, "contact_forces");
    const PetscInt np  = (PetscInt)model_.par.params.size();
    if (mus.ndim() == 1 && np == 1) mus = mus.reshape({mus.shape(0), (py::ssize_t)1});
    if (mus.ndim() != 2 || mus.shape(1) != np) throw std::runtime_error("contact_forces: expected an array of shape (n, " + std::to_string(np) + ") (one row per parameter point)");
    const py::ssize_t   n = mus.shape(0);
    py::array_t<double> out(n);
    const double       *in = mus.data(); // C-contiguous (RealArray), n x np; both arrays stay alive through the call
    double             *o  = out.mutable_data();
    py::ssize_t         edgeRows = 0, firstEdge = -1;
    Serialized([&] {
      std::vector<PetscReal> m(np);
      rbc::ReducedSolution   sol;
      for (py::ssize_t k = 0; k < n; ++k) {
        for (PetscInt i = 0; i < np; ++i) m[i] = in[k * np + i];
        Check(model_.par.CheckBox(PETSC_COMM_SELF, m, "contact_forces: row " + std::to_string((long long)k))); // (it blamed -mu, no row)
        Check(model_.Solve(m, &sol));
        if (sol.force.empty() && sol.converged) throw std::runtime_error("contact_forces: this ROM's hyper-reduction (" + std::string(model_.HyperName()) + ") computes no online force; use the ECSW cubature (-rom_hyper ecsw)");
        if (!sol.converged) {
          if (!nanOnFailure) throw std::runtime_error("contact_forces: the reduced model did not converge at row " + std::to_string((long long)k) + ": " + sol.message);
          o[k] = std::numeric_limits<double>::quiet_NaN();
        } else o[k] = sol.ForceMagnitude();
        if (sol.converged && sol.outOfRange > 0 && edgeRows++ == 0) firstEdge = k;
      }
    });
    if (edgeRows > 0) Warn(PyExc_RuntimeWarning, "rbcontact: contact_forces: at " + std::to_string((long long)edgeRows) + " row(s) (first: row " + std::to_string((long long)firstEdge) + ") contact projections fell at the edge of the stored contact data: those forces may be wrong (solve() gives Solution.out_of_range per point)");
    return out;
  }

  py::list Parameters() const
  {
    py::list l;
    for (const auto &p : model_.par.params) l.append(py::make_tuple(p.name, (double)p.min, (double)p.max));
    return l;
  }

  rbc::ReducedModel model_;
};

// The options database of one stage call: pushed as PETSc's default for the call, popped and destroyed
// after it (also on an error), so one call's options never leak into the next or into the models. The words
// were checked (CheckWords, CheckOptionsFiles: an options file that includes itself made PETSc recurse until the
// interpreter crashed).
class ScopedOptions {
public:
  explicit ScopedOptions(const std::vector<std::string> &tokens)
  {
    std::string line;
    for (const auto &t : tokens) line += (t.find(' ') != std::string::npos ? "\"" + t + "\"" : t) + " ";
    Check(PetscOptionsCreate(&opts_));
    try {
      Check(PetscOptionsInsertString(opts_, line.c_str())); // -options_file included
      Check(PetscOptionsPush(opts_));
    } catch (...) {
      (void)PetscOptionsDestroy(&opts_);
      throw;
    }
  }
  ~ScopedOptions()
  {
    (void)PetscOptionsPop();
    (void)PetscOptionsDestroy(&opts_);
  }
  ScopedOptions(const ScopedOptions &)            = delete;
  ScopedOptions &operator=(const ScopedOptions &) = delete;

private:
  PetscOptions opts_ = nullptr;
};

// The value of the last -report among the words (the one PETSc would read), "" if none or not a path.
std::string ReportWord(const std::vector<std::string> &words)
{
  std::string r;
  for (size_t i = 0; i + 1 < words.size(); ++i)
    if (words[i] == "-report") r = words[i + 1];
  return r.find('\0') != std::string::npos || rbc::IsOptionName(r) ? "" : r;
}

// RunStage under the mutex: the report as text, the options nobody read in unused.
std::string RunStageLocked(const std::string &stage, const std::vector<std::string> &options, std::vector<std::string> *unused)
{
  if (stage != "offline" && stage != "validate" && stage != "probe") throw std::runtime_error("rbcontact: unknown stage '" + stage + "' (offline, validate or probe; online: ReducedModel)");
  rbc::ResetReportMarks(); // an earlier call's refused or written report does not keep this call's failure from its -report
  PetscMPIInt rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  std::unique_ptr<ScopedOptions> scope;
  {
    long long code = PETSC_ERR_USER_INPUT;
    try {
      CheckWords(options, "rbcontact." + stage);
      const std::string bad = rbc::CheckOptionsFilesOnRankZero(PETSC_COMM_WORLD, options);
      code                  = PETSC_ERR_FILE_OPEN;
      if (!bad.empty()) throw std::runtime_error("rbcontact." + stage + ": " + bad);
      scope = std::make_unique<ScopedOptions>(options);
    } catch (const std::exception &e) { // as the command line: options that cannot be read still replace the -report among the words
      const std::string r = ReportWord(options);
      if (rank == 0 && !r.empty()) rbc::WriteFailureReport(r.c_str(), stage, e.what(), code, false);
      throw;
    }
  }
  char reportPath[PETSC_MAX_PATH_LEN] = "";
  Check(PetscOptionsGetString(NULL, NULL, "-report", reportPath, sizeof reportPath, NULL));
  Check(rbc::CheckOutputPath(PETSC_COMM_WORLD, reportPath, "-report"));
  rbc::Report rep;
  try {
    Check(rbc::CheckListEntries(PETSC_COMM_WORLD)); // those of its options files too
    if (stage == "offline") Check(rbc::RunOfflineFromOptions(PETSC_COMM_WORLD, &rep));
    else if (stage == "probe") { // the report whatever the failures (they are the answer; the command line's stage exits with an error)
      char romPath[PETSC_MAX_PATH_LEN] = "";
      Check(PetscOptionsGetString(NULL, NULL, "-rom", romPath, sizeof romPath, NULL));
      if (!romPath[0]) throw std::runtime_error("rbcontact.probe: give the ROM file (rom=...)");
      Check(rbc::CheckDistinctFiles(PETSC_COMM_WORLD, {{"-report", reportPath}}, {{"-rom", romPath}}));
      Check(rbc::CheckSceneOptions(PETSC_COMM_WORLD, "probe", romPath)); // as the command line's probe
      rbc::ProbeSummary ps;
      rep.root["stage"] = "probe";
      Check(rbc::ProbeRomFile(PETSC_COMM_WORLD, romPath, 1000, &rep.root["probe"], &ps));
    } else Check(rbc::RunValidationFromOptions(PETSC_COMM_WORLD, reportPath, &rep));
  } catch (const std::exception &e) { // as the command line: a failed run replaces an earlier report with its failure
    if (rank == 0 && reportPath[0]) rbc::WriteFailureReport(reportPath, stage, e.what(), 1, true);
    throw;
  }
  // options of this call nobody read (a misspelled keyword: trian_size=5 ran the file's 21 points without a word)
  Check(rbc::UnusedOptions(stage, unused, options));
  if (!unused->empty()) {
    rbc::JsonValue &w = rep.root["warnings"];
    for (const auto &u : *unused) w.Push(rbc::JsonValue::String(u));
  }
  Check(rep.Write(PETSC_COMM_WORLD, reportPath));
  return rep.root.Dump();
}

// Runs the offline, validate or probe stage of the library (RunOffline, RunValidation, ProbeRomFile) with these
// command-line options only (not those of initialize()); returns the stage's JSON report as text. -report is written
// too (with the warnings, which are then issued: a filter turning them into errors raises after the report).
std::string RunStage(const std::string &stage, const std::vector<std::string> &options)
{
  Start();
  std::vector<std::string> unused;
  std::string              text = Serialized([&] { return RunStageLocked(stage, options, &unused); });
  for (const auto &u : unused) Warn(PyExc_UserWarning, "rbcontact." + stage + ": " + u);
  return text;
}

// A ROM file opened (Python's ReducedModel(file)); the first one also says which options of initialize() nobody read
// (misspelled: -rom_kacanov_monitr), as the command line's online stage does.
std::unique_ptr<Model> OpenModel(py::object path)
{
  // a str or an os.PathLike (pathlib.Path was a TypeError); a NUL character refused (the path was cut there: another file
  // opened without a word; audit J)
  const std::string file = py::str(py::module_::import("os").attr("fsdecode")(path));
  if (file.find('\0') != std::string::npos) throw std::runtime_error("rbcontact.ReducedModel: the file name '" + Shown(file) + "' holds a NUL character");
  Start();
  std::vector<std::string> unused;
  auto                     model = Serialized([&] {
    auto m = std::make_unique<Model>(file);
    if (!initOptionsChecked && initializedHere) {
      initOptionsChecked = true;
      Check(rbc::UnusedOptions("online", &unused, initOptions));
    }
    return m;
  });
  for (const auto &u : unused) Warn(PyExc_UserWarning, "rbcontact.initialize: " + u);
  return model;
}

} // namespace

PYBIND11_MODULE(_rbcontact, m)
{
  m.doc() = "rbcontact: the online stage of a reduced contact model (ROM file from `rbcontact offline`). Every call runs with "
            "the GIL released; calls from several threads run one after the other (PETSc's options database is global). "
            "Ctrl-C is seen when the running call ends.";
  m.attr("__version__")  = rbc::CodeVersion();  // the project's version (CMakeLists.txt)
  m.attr("version_line") = rbc::VersionLine(); // as `rbcontact --version`: version, git commit, PETSc and SLEPc
  m.def("initialize", [](const std::vector<std::string> &options) { Start(options); }, py::arg("options") = std::vector<std::string>{},
        "Initialize PETSc/SLEPc with these command-line options (e.g. ['-rom_kacanov_monitor']); optional, "
        "done with no options by the first ReducedModel, which warns about the options nobody read");
  m.def("finalize", [] {
    Serialized([] {
      if (liveModels == 0) Finalize();
      else throw std::runtime_error("rbcontact.finalize: delete the ReducedModel objects first");
    });
  }, "Finalize PETSc/SLEPc (done at exit)");
  m.def("_run_stage", &RunStage, py::arg("stage"), py::arg("options"),
        "Run the offline, validate or probe stage with these command-line options; the JSON report as text");
  py::class_<Solution>(m, "Solution", "One reduced solution")
    .def_readonly("v", &Solution::v, "reduced displacement coordinates (N)")
    .def_readonly("lambda_hat", &Solution::lambda_hat, "reduced multiplier coordinates (R)")
    .def_readonly("force", &Solution::force, "resultant contact force vector (dim; empty with the EIM)")
    .def_readonly("contact_force", &Solution::contactForce, "its norm (the FOM report's contact_force; nan with the EIM)")
    .def_readonly("max_pressure", &Solution::maxPressure, "max nodal contact pressure (the FOM report's max_pressure; nan without the ROM file's surface data)")
    .def_readonly("contact_halfwidth", &Solution::halfwidth, "2D: the moment half-width of the pressure (the FOM report's contact_halfwidth_moment)")
    .def_readonly("contact_length", &Solution::contactLength, "2D: twice the half-width")
    .def_readonly("contact_radius", &Solution::contactRadius, "3D: the moment contact radius of the pressure (the FOM report's contact_halfwidth_moment, Hertz's a); NaN in 2D")
    .def_readonly("error_u", &Solution::estU, "estimated relative error of u in the energy norm (nan: the ROM file has no error estimate, offline -estimate)")
    .def_readonly("error_lambda", &Solution::estLambda, "estimated relative error of the multipliers (slave-mass weighted l2)")
    .def_readonly("error_force", &Solution::estForce, "estimated relative error of the contact force")
    .def_readonly("converged", &Solution::converged)
    .def_readonly("iterations", &Solution::iterations, "reduced Kacanov iterations")
    .def_readonly("message", &Solution::message, "why the solve failed (empty on success)")
    .def_readonly("out_of_range", &Solution::outOfRange, "contact projections at the edge of the stored contact data (> 0: the answer may be wrong; a RuntimeWarning says so)")
    .def("__repr__", [](const Solution &s) { return "<rbcontact.Solution converged=" + std::string(s.converged ? "True" : "False") + " iterations=" + std::to_string((long long)s.iterations) + " contact_force=" + std::to_string(s.contactForce) + ">"; });
  py::class_<Model>(m, "ReducedModel", "A ROM file opened for online solves (rbc::ReducedModel)")
    .def(py::init(&OpenModel), py::arg("file"))
    .def("solve", &Model::Solve, py::arg("mu"), "The reduced solution at mu (a sequence of parameter values)")
    .def("contact_forces", &Model::ContactForces, py::arg("mus"), py::arg("nan_on_failure") = false,
         "The contact force at every row of mus (shape (n, number of parameters), or (n,) with one parameter)")
    .def_property_readonly("parameters", &Model::Parameters, "[(name, min, max)] of the parameter box")
    .def_property_readonly("N", [](const Model &x) { return x.model_.N(); })
    .def_property_readonly("R", [](const Model &x) { return x.model_.R(); })
    .def_property_readonly("hyper", [](const Model &x) { return std::string(x.model_.HyperName()); })
    .def_property_readonly("file", [](const Model &x) { return x.model_.file; });
  py::module_::import("atexit").attr("register")(py::cpp_function([]() { AtExit(); }));
}
