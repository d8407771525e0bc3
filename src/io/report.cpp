// src/io/report.cpp: JSON tree for the -report summaries and atomic file writing.
#include "rbcontact/report.hpp"
#include "rbcontact/options_files.hpp"
#include "rbcontact/provenance.hpp"
#include <algorithm>
#include <cmath>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <fstream>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace rbc {

static bool reportRefused = false; // CheckOutputPath / CheckDistinctFiles refused -report (ReportPathRefused)
bool        ReportPathRefused() { return reportRefused; }
static bool failureReported = false; // MarkFailureReported
void        MarkFailureReported() { failureReported = true; }
bool        FailureReported() { return failureReported; }
void        ResetReportMarks()
{
  reportRefused   = false;
  failureReported = false;
}

JsonValue JsonValue::Number(double v) { JsonValue j; j.kind_ = Kind::Number; j.num_ = v; return j; }
JsonValue JsonValue::Integer(long long v) { JsonValue j; j.kind_ = Kind::Integer; j.int_ = v; return j; }
JsonValue JsonValue::String(const std::string &s) { JsonValue j; j.kind_ = Kind::String; j.str_ = s; return j; }
JsonValue JsonValue::Bool(bool b) { JsonValue j; j.kind_ = Kind::Bool; j.bool_ = b; return j; }
JsonValue JsonValue::Array() { JsonValue j; j.kind_ = Kind::Array; return j; }
JsonValue JsonValue::Object() { JsonValue j; j.kind_ = Kind::Object; return j; }

JsonValue::JsonValue(const JsonValue &o) { *this = o; }
JsonValue &JsonValue::operator=(const JsonValue &o)
{
  if (this == &o) return *this;
  kind_ = o.kind_; num_ = o.num_; int_ = o.int_; bool_ = o.bool_; str_ = o.str_; arr_ = o.arr_;
  obj_.clear();
  for (const auto &kv : o.obj_) obj_.emplace_back(kv.first, std::make_unique<JsonValue>(*kv.second));
  return *this;
}

JsonValue &JsonValue::operator[](const std::string &key)
{
  if (kind_ == Kind::Null) kind_ = Kind::Object;
  for (auto &kv : obj_) if (kv.first == key) return *kv.second;
  obj_.emplace_back(key, std::make_unique<JsonValue>());
  return *obj_.back().second;
}
JsonValue &JsonValue::Push(const JsonValue &v)
{
  if (kind_ == Kind::Null) kind_ = Kind::Array;
  arr_.push_back(v);
  return arr_.back();
}
JsonValue &JsonValue::operator=(double v) { return *this = Number(v); }
JsonValue &JsonValue::operator=(int v) { return *this = Integer(v); }
JsonValue &JsonValue::operator=(long v) { return *this = Integer(v); }
JsonValue &JsonValue::operator=(long long v) { return *this = Integer(v); }
JsonValue &JsonValue::operator=(bool v) { return *this = Bool(v); }
JsonValue &JsonValue::operator=(const char *s) { return *this = String(s); }
JsonValue &JsonValue::operator=(const std::string &s) { return *this = String(s); }
JsonValue &JsonValue::operator=(const std::vector<double> &v)
{
  JsonValue a = Array();
  for (double x : v) a.Push(Number(x));
  return *this = a;
}

bool JsonValue::Has(const std::string &key) const { return Get(key) != nullptr; }
const JsonValue *JsonValue::Get(const std::string &key) const
{
  for (const auto &kv : obj_) if (kv.first == key) return kv.second.get();
  return nullptr;
}
double JsonValue::AsNumber() const { return kind_ == Kind::Integer ? (double)int_ : num_; }

// The length of the valid UTF-8 sequence at s[i] (1 to 4), or 0 (an invalid or truncated one).
static size_t Utf8Length(const std::string &s, size_t i)
{
  const unsigned char c = (unsigned char)s[i];
  const size_t        n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if (((unsigned char)s[i + k] >> 6) != 0x2) return 0;
  const unsigned char c1 = n > 1 ? (unsigned char)s[i + 1] : 0; // overlong forms, surrogates, beyond U+10FFFF: invalid
  if ((n == 2 && c < 0xc2) || (n == 3 && ((c == 0xe0 && c1 < 0xa0) || (c == 0xed && c1 >= 0xa0))) || (n == 4 && (c > 0xf4 || (c == 0xf0 && c1 < 0x90) || (c == 0xf4 && c1 >= 0x90)))) return 0;
  return n;
}

static std::string Escape(const std::string &s)
{
  std::string o;
  for (size_t i = 0; i < s.size();) {
    const char c = s[i];
    switch (c) {
    case '"': o += "\\\""; break;
    case '\\': o += "\\\\"; break;
    case '\n': o += "\\n"; break;
    case '\t': o += "\\t"; break;
    default:
      if ((unsigned char)c < 0x20) {
        char b[8];
        std::snprintf(b, sizeof b, "\\u%04x", c);
        o += b;
      } else if ((unsigned char)c >= 0x80) {
        // a byte that is not valid UTF-8 (an option value of another encoding) made the whole report unreadable to a
        // JSON parser (audit of 2026-12-01): it is written as U+FFFD, a valid sequence as it is
        const size_t n = Utf8Length(s, i);
        if (n == 0) o += "\\ufffd";
        else o.append(s, i, n);
        i += n ? n : 1;
        continue;
      } else o += c;
    }
    ++i;
  }
  return o;
}

std::string JsonValue::Dump(int indent) const
{
  std::ostringstream os;
  const std::string pad(indent + 2, ' '), padEnd(indent, ' ');
  switch (kind_) {
  case Kind::Null: os << "null"; break;
  case Kind::Number:
    if (std::isfinite(num_)) { char b[40]; std::snprintf(b, sizeof b, "%.17g", num_); os << b; }
    else os << "null"; // JSON has no NaN/Inf: a non-finite number is reported as null
    break;
  case Kind::Integer: os << int_; break;
  case Kind::String: os << '"' << Escape(str_) << '"'; break;
  case Kind::Bool: os << (bool_ ? "true" : "false"); break;
  case Kind::Array: {
    bool scalars = true;
    for (const auto &v : arr_) if (v.kind_ == Kind::Array || v.kind_ == Kind::Object) scalars = false;
    os << '[';
    for (size_t i = 0; i < arr_.size(); ++i) {
      if (scalars) os << (i ? ", " : "") << arr_[i].Dump(indent + 2);
      else os << (i ? ",\n" : "\n") << pad << arr_[i].Dump(indent + 2);
    }
    if (!scalars && !arr_.empty()) os << '\n' << padEnd;
    os << ']';
  } break;
  case Kind::Object:
    os << '{';
    for (size_t i = 0; i < obj_.size(); ++i) os << (i ? ",\n" : "\n") << pad << '"' << Escape(obj_[i].first) << "\": " << obj_[i].second->Dump(indent + 2);
    if (!obj_.empty()) os << '\n' << padEnd;
    os << '}';
    break;
  }
  return os.str();
}

std::vector<double> Finite(const std::vector<double> &v)
{
  std::vector<double> o(v);
  for (auto &x : o) if (!(std::abs(x) < 1e300)) x = std::nan("");
  return o;
}

PetscErrorCode BcastString(MPI_Comm comm, std::string *s)
{
  unsigned long long n = s->size();

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm));
  s->resize(n);
  if (n) PetscCallMPI(MPI_Bcast(&(*s)[0], (PetscMPIInt)n, MPI_CHAR, 0, comm));
  PetscFunctionReturn(0);
}

PetscErrorCode WriteFileAtomic(MPI_Comm comm, const std::string &path, const std::string &text)
{
  PetscMPIInt rank;
  int         ok = 1;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    const std::string target = OutputTarget(path), tmp = TemporaryPath(path);
    errno = 0;
    std::ofstream f(tmp);
    if (!f) ok = -(errno ? errno : EIO);
    else {
      f << text;
      f.close();
      if (!f || std::rename(tmp.c_str(), target.c_str()) != 0) {
        ok = -(errno ? errno : EIO); // (a full disk: ENOSPC, from the write or the close)
        std::remove(tmp.c_str());
      }
    }
  }
  PetscCallMPI(MPI_Bcast(&ok, 1, MPI_INT, 0, comm));
  PetscCheck(ok > 0, comm, PETSC_ERR_FILE_OPEN, "Cannot write file '%s': %s", path.c_str(), std::strerror(-ok));
  PetscFunctionReturn(0);
}

// The directory of path ("." without a slash, "/" for a file in the root) and its last component.
static std::string DirOf(const std::string &path)
{
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
}
static std::string NameOf(const std::string &path)
{
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

PetscErrorCode CheckOutputPath(MPI_Comm comm, const std::string &path, const char *option)
{
  PetscMPIInt rank;
  std::string why;

  PetscFunctionBeginUser;
  if (path.empty()) PetscFunctionReturn(0);
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    const std::string dir = DirOf(path);
    struct stat       st;
    if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) why = "the directory '" + dir + "' does not exist";
    else if (access(dir.c_str(), W_OK | X_OK) != 0) why = "the directory '" + dir + "' is not writable";
    else if (stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) why = "it is a directory";
    else if (stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      why = "it is a device, FIFO or socket, not a regular file: outputs are written to a temporary file renamed onto their name, which would replace it (leave the option out to skip this output)";
    else if (stat(path.c_str(), &st) == 0 && access(path.c_str(), W_OK) != 0) why = "the file exists and is not writable";
    else { // the temporary file the writers create (the longest name they use), created and removed
      const std::string tmp = TemporaryPath(path);
      const int         fd  = open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
      if (fd < 0 && errno != EEXIST) why = "cannot create the temporary file '" + tmp + "': " + std::strerror(errno);
      else if (fd >= 0) {
        close(fd);
        std::remove(tmp.c_str());
      }
    }
  }
  PetscCall(BcastString(comm, &why));
  if (!why.empty() && std::string(option) == "-report") reportRefused = true;
  PetscCheck(why.empty(), comm, PETSC_ERR_FILE_OPEN, "%s %s: cannot write there: %s (checked before any work; nothing was computed or written)", option, path.c_str(), why.c_str());
  if (rank == 0)
    for (const auto &t : StaleTemporaries(path)) {
      struct stat st;
      const double mb = stat(t.c_str(), &st) == 0 ? (double)st.st_size / 1048576.0 : 0.0;
      PetscCall(PetscPrintf(PETSC_COMM_SELF, "rbcontact: warning: %s %s: '%s' (%.1f MB) is a temporary file of this output left by a job that no longer runs (killed while writing); it is not reused: remove it\n", option, path.c_str(), t.c_str(), mb));
    }
  PetscFunctionReturn(0);
}

std::string TemporaryPath(const std::string &path, long pid) { return OutputTarget(path) + ".tmp." + std::to_string(pid); }

std::string TemporaryPath(const std::string &path) { return TemporaryPath(path, (long)getpid()); }

std::vector<std::string> StaleTemporaries(const std::string &path)
{
  std::vector<std::string> stale;
  const std::string        target = OutputTarget(path);
  const std::string        dir = DirOf(target), prefix = NameOf(target) + ".tmp.";
  DIR                     *d   = opendir(dir.c_str());
  if (!d) return stale;
  while (const struct dirent *e = readdir(d)) {
    const std::string name = e->d_name;
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos || digits[0] == '0') continue; // not one of ours
    const long pid = std::strtol(digits.c_str(), nullptr, 10);
    if (pid == (long)getpid() || kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue; // its process runs (or may not be signalled)
    const std::string full = target.substr(0, target.size() - NameOf(target).size()) + name; // beside the target
    struct stat       st;
    if (lstat(full.c_str(), &st) == 0 && S_ISREG(st.st_mode)) stale.push_back(full);
  }
  closedir(d);
  std::sort(stale.begin(), stale.end());
  return stale;
}

std::string OutputTarget(const std::string &path)
{
  struct stat st;
  if (lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return path;
  char buf[PATH_MAX];
  if (realpath(path.c_str(), buf)) return buf;
  // a dangling link: the file it names, relative to the link's directory
  const ssize_t n = readlink(path.c_str(), buf, sizeof buf - 1);
  if (n <= 0) return path;
  buf[n]                  = 0;
  const std::string link  = buf;
  const size_t      slash = path.find_last_of('/');
  return link[0] == '/' || slash == std::string::npos ? link : path.substr(0, slash + 1) + link;
}

// A key that is the same for two names of one file: device and inode when it exists, else the resolved
// directory and the name.
static std::string FileKey(const std::string &path)
{
  struct stat st;
  if (stat(path.c_str(), &st) == 0) return "inode " + std::to_string((unsigned long long)st.st_dev) + ":" + std::to_string((unsigned long long)st.st_ino);
  const std::string target = OutputTarget(path);
  const std::string dir = DirOf(target), name = NameOf(target);
  char buf[PATH_MAX];
  return std::string("path ") + (realpath(dir.c_str(), buf) ? buf : dir.c_str()) + "/" + name;
}

PetscErrorCode CheckDistinctFiles(MPI_Comm comm, const std::vector<std::pair<std::string, std::string>> &outputs, const std::vector<std::pair<std::string, std::string>> &inputsGiven)
{
  PetscMPIInt rank;
  std::string why;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    std::vector<std::string>                         ko, ki;
    std::vector<std::pair<std::string, std::string>> inputs = inputsGiven; // and every options file of the run
    for (const auto &f : OptionsFilesRead()) inputs.push_back(f);
    for (const auto &o : outputs) ko.push_back(o.second.empty() ? std::string() : FileKey(o.second));
    for (const auto &i : inputs) ki.push_back(i.second.empty() ? std::string() : FileKey(i.second));
    for (size_t a = 0; a < outputs.size() && why.empty(); ++a) {
      if (ko[a].empty()) continue;
      for (size_t b = a + 1; b < outputs.size() && why.empty(); ++b)
        if (ko[a] == ko[b]) {
          why           = outputs[a].first + " " + outputs[a].second + " and " + outputs[b].first + " " + outputs[b].second + " name the same file: one output would replace the other";
          reportRefused = reportRefused || outputs[a].first == "-report" || outputs[b].first == "-report";
        }
      for (size_t b = 0; b < inputs.size() && why.empty(); ++b)
        if (ko[a] == ki[b]) {
          why           = "the output " + outputs[a].first + " " + outputs[a].second + " is the input " + inputs[b].first + " " + inputs[b].second + ": writing it would replace what is read";
          reportRefused = reportRefused || outputs[a].first == "-report";
        }
    }
  }
  PetscCall(BcastString(comm, &why));
  PetscCheck(why.empty(), comm, PETSC_ERR_ARG_WRONG, "%s (checked before any work; nothing was computed or written)", why.c_str());
  PetscFunctionReturn(0);
}

void WriteFailureReport(const char *path, const std::string &stage, const std::string &error, long long code, bool provenance)
{
  JsonValue r = JsonValue::Object();
  r["stage"]       = stage;
  r["converged"]   = false;
  r["error"]       = error;
  r["error_code"]  = code;
  if (provenance) r["provenance"] = ProvenanceJson(LocalProvenance());
  const std::string target = OutputTarget(path), tmp = TemporaryPath(path);
  struct stat       st;
  if (stat(target.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) return; // a directory or device (refused by CheckOutputPath): never replaced
  if (ReportPathRefused()) return;                                 // the path the run refused (an input, another output)
  if (FailureReported()) return;                                   // the stage wrote its own, with the error
  {
    char       sig[8] = {0};
    FILE      *h      = std::fopen(target.c_str(), "rb");
    const bool hdf5   = h && std::fread(sig, 1, 8, h) == 8 && std::memcmp(sig, "\x89HDF\r\n\x1a\n", 8) == 0;
    if (h) std::fclose(h);
    if (hdf5) return;
  }
  FILE *f = std::fopen(tmp.c_str(), "w");
  if (!f) return;
  const std::string text = r.Dump() + "\n";
  const bool        ok   = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !ok || std::rename(tmp.c_str(), target.c_str()) != 0) {
    std::remove(tmp.c_str());
    std::fprintf(stderr, "rbcontact: could not write the failure report %s\n", path);
  }
}

PetscErrorCode Report::WriteFailed(MPI_Comm comm, const std::string &path, const std::string &error)
{
  PetscFunctionBeginUser;
  root["converged"] = false;
  root["error"]     = error;
  PetscCall(Write(comm, path));
  MarkFailureReported();
  PetscFunctionReturn(0);
}

PetscErrorCode Report::Write(MPI_Comm comm, const std::string &path) const
{
  PetscFunctionBeginUser;
  if (path.empty()) PetscFunctionReturn(0);
  if (root.Has("provenance")) PetscCall(WriteFileAtomic(comm, path, root.Dump() + "\n"));
  else {
    Provenance p;
    JsonValue  out = root;
    PetscCall(GetProvenance(comm, &p));
    out["provenance"] = ProvenanceJson(p);
    PetscCall(WriteFileAtomic(comm, path, out.Dump() + "\n"));
  }
  PetscFunctionReturn(0);
}

} // namespace rbc
