// rbcontact/report.hpp: the machine-readable run summary written by every stage (-report file.json).
// Owns a small ordered JSON tree (objects, arrays, numbers, strings, booleans) and its atomic
// write (temp file + rename, rank 0 only). The key names each issue lists are a contract.
#pragma once
#include <petscsys.h>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace rbc {

class JsonValue {
public:
  enum class Kind { Null, Number, Integer, String, Bool, Array, Object };
  JsonValue() = default;
  static JsonValue Number(double v);
  static JsonValue Integer(long long v);
  static JsonValue String(const std::string &s);
  static JsonValue Bool(bool b);
  static JsonValue Array();
  static JsonValue Object();

  // Object access: creates the key (in insertion order) if missing; turns a Null into an Object.
  JsonValue &operator[](const std::string &key);
  // Array append; turns a Null into an Array.
  JsonValue &Push(const JsonValue &v);
  JsonValue &operator=(double v);
  JsonValue &operator=(int v);
  JsonValue &operator=(long v);
  JsonValue &operator=(long long v);
  JsonValue &operator=(bool v);
  JsonValue &operator=(const char *s);
  JsonValue &operator=(const std::string &s);
  JsonValue &operator=(const std::vector<double> &v);

  bool Has(const std::string &key) const;
  const JsonValue *Get(const std::string &key) const;
  double AsNumber() const;
  const std::string &AsString() const { return str_; }
  Kind kind() const { return kind_; }
  std::string Dump(int indent = 0) const;

private:
  Kind kind_ = Kind::Null;
  double num_ = 0;
  long long int_ = 0;
  bool bool_ = false;
  std::string str_;
  std::vector<std::pair<std::string, std::unique_ptr<JsonValue>>> obj_;
  std::vector<JsonValue> arr_;

public:
  JsonValue(const JsonValue &o);
  JsonValue &operator=(const JsonValue &o);
  JsonValue(JsonValue &&) = default;
  JsonValue &operator=(JsonValue &&) = default;
};

// Values at or above PETSc's "infinity" (1e300 here) become NaN, which the JSON writer reports as null.
std::vector<double> Finite(const std::vector<double> &v);

// Broadcasts a string from rank 0 of comm (errors and file contents read on rank 0).
PetscErrorCode BcastString(MPI_Comm comm, std::string *s);

// Writes text to path atomically (path.tmp.<pid> then rename) on rank 0 of comm; errors name the file.
PetscErrorCode WriteFileAtomic(MPI_Comm comm, const std::string &path, const std::string &text);

// The file an output named path is renamed onto: path itself, or where it points when it is a symbolic link
// (so that the link stays a link; the temporary file goes beside the target, on its file system).
std::string OutputTarget(const std::string &path);

// Checks, before any work, that path (given with option; empty: nothing to check) can be written: its
// directory exists and is writable, path is not a directory, nor an existing device, FIFO or socket (the
// rename of the temporary file would replace it: -report /dev/null as root), and the temporary file
// (TemporaryPath(path)) can be created there (a name too long, /proc). Warns (rank 0) about the temporary files of
// path that a killed job left (StaleTemporaries): the next write does not reuse them and they may be large.
// Collective (rank 0 looks).
PetscErrorCode CheckOutputPath(MPI_Comm comm, const std::string &path, const char *option);

// The temporary file an output named path is written to before it is renamed onto OutputTarget(path):
// OutputTarget(path) + ".tmp.<pid>", pid this process's (or, for a collective writer, rank 0's).
std::string TemporaryPath(const std::string &path, long pid);
std::string TemporaryPath(const std::string &path);

// The temporary files of path (TemporaryPath(path, pid) for any pid) whose process no longer runs on this host:
// what a job killed during the write left (a snapshot file's is as large as the file). Files of a process that
// still runs, or that this process may not signal, are not listed; a job on another host writing the same output
// at the same time would be (two jobs writing one file is the user's mistake either way): they are named, never
// removed.
std::vector<std::string> StaleTemporaries(const std::string &path);

// The report of a failed run: {"stage", "converged": false, "error", "error_code"[, "provenance"]} written to path by the
// calling rank alone (temporary file + rename). Never onto a device, a path the run refused (ReportPathRefused), a
// report the stage wrote itself (FailureReported) or an HDF5 file (a ROM or snapshot file named by mistake).
void WriteFailureReport(const char *path, const std::string &stage, const std::string &error, long long code, bool provenance);

// A stage that wrote its full report with "converged": false and the error before failing (the probe's failures)
// marks it, so that the executable's generic failure report does not replace it.
void MarkFailureReported();
bool FailureReported();

// True once CheckOutputPath or CheckDistinctFiles refused the -report path: the failure report (src/apps/main.cpp)
// is then not written there either.
bool ReportPathRefused();

// Clears both marks (ReportPathRefused, FailureReported) for the next run of a process that runs several stages (the
// Python module: a report refused or written by one call kept every later failure from replacing its -report).
void ResetReportMarks();

// Checks, before any work, that the outputs (option, path) name distinct files and none of them names an
// input (option, path): -report equal to -rom, -rom_reconstruct onto the ROM it reads. Empty paths are
// skipped; files compare by device and inode when they exist, else by their resolved directory and name.
// Collective (rank 0 looks).
PetscErrorCode CheckDistinctFiles(MPI_Comm comm, const std::vector<std::pair<std::string, std::string>> &outputs, const std::vector<std::pair<std::string, std::string>> &inputs);

// The report of one stage run: filled by the stage, written by Write() if -report was given, with the
// key "provenance" (rbcontact/provenance.hpp) added unless the stage set it. Collective on comm.
class Report {
public:
  JsonValue root = JsonValue::Object();
  PetscErrorCode Write(MPI_Comm comm, const std::string &path) const;
  // A stage that fails after its work (the probe's failures): "converged": false and the error added, the whole report
  // written, and MarkFailureReported() so that the executable's generic failure report leaves it in place.
  PetscErrorCode WriteFailed(MPI_Comm comm, const std::string &path, const std::string &error);
};

} // namespace rbc
