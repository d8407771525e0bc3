// src/io/options_files.cpp: the -options_file chain checked before PETSc reads it (options_files.hpp).
#include "rbcontact/options_files.hpp"
#include <petscsys.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <functional>
#include <sstream>

namespace rbc {

// Option families a shared scene file (runs/<scene>.opts) may carry for the stages that consume them:
// an unused option of a family this stage does not consume is not reported (no false positives from
// the other stages' settings); any other unused option is (a misspelling: -kacanov_max_iter).
static bool OtherStagesOption(const std::string &stage, const std::string &name, const std::vector<std::string> &given)
{
  struct Family {
    const char *prefix, *stages;
  };
  static const Family fam[] = {{"train_", "offline"},      {"snapshots", "offline dualbasis"}, {"offline_", "offline"}, {"pod_", "offline"},
                               {"dual_", "offline dualbasis"}, {"nnls_", "offline dualbasis"}, {"mcpg_", "offline dualbasis"}, {"nmf_", "offline dualbasis"},
                               {"eim_", "offline"},        {"ecsw_", "offline"},             {"rom_", "offline online validate probe"}, {"online_", "online"},
                               {"test_", "validate"},      {"validate_", "validate"},        {"import_", "dualbasis"},
                               {"greedy_", "offline"},     {"probe_", "offline probe"}};
  std::string skipped; // families of the offline steps -offline_stop leaves out
  if (stage == "offline") {
    char      stop[32] = "";
    PetscBool set      = PETSC_FALSE;
    (void)PetscOptionsGetString(NULL, NULL, "-offline_stop", stop, sizeof stop, &set);
    if (set && !std::strcmp(stop, "snapshots")) skipped = " pod_ dual_ nnls_ mcpg_ nmf_ eim_ ecsw_ rom_ ";
    else if (set && !std::strcmp(stop, "bases")) skipped = " eim_ ecsw_ rom_ ";
    // a scene file may ship both trainings' settings: the greedy's (-greedy_*) with a grid run, -train_size with a greedy one
    char type[32] = "";
    (void)PetscOptionsGetString(NULL, NULL, "-train_type", type, sizeof type, NULL);
    if (!std::strcmp(type, "greedy") && name != "train_type") skipped += " train_ ";
    else skipped += " greedy_ ";
  }
  for (const auto &f : fam)
    if (name.compare(0, std::strlen(f.prefix), f.prefix) == 0)
      return (" " + std::string(f.stages) + " ").find(" " + stage + " ") == std::string::npos || skipped.find(" " + std::string(f.prefix) + " ") != std::string::npos;
  // online, probe and dualbasis read their own families only (online: plus the scene with -rom_reconstruct): the rest of
  // a scene file given to them is not theirs, but an option given directly (the command line, the Python keywords) is
  // (-mmu 1.1 solved at the default parameter, -reprot wrote no report, without a word until 2026-12-01)
  bool own = stage != "dualbasis" && stage != "probe" && stage != "online";
  if (stage == "online") {
    PetscBool rec = PETSC_FALSE;
    (void)PetscOptionsHasName(NULL, NULL, "-rom_reconstruct", &rec);
    own = rec;
  }
  return !own && std::find(given.begin(), given.end(), "-" + name) == given.end();
}

bool IsOptionName(const std::string &word) { return word.size() > 1 && word[0] == '-' && !std::isdigit((unsigned char)word[1]) && word[1] != '.'; }

bool HasEmptyListEntry(const std::string &value) { return !value.empty() && (value.front() == ',' || value.back() == ',' || value.find(",,") != std::string::npos); }

std::vector<std::pair<std::string, std::string>> OptionsInUse()
{
  std::vector<std::pair<std::string, std::string>> out;
  char                                            *all = nullptr;
  if (PetscOptionsGetAll(NULL, &all) || !all) return out;
  std::istringstream in(all);
  for (std::string tok; in >> tok;) {
    if (IsOptionName(tok)) out.emplace_back(tok, "");
    else if (!out.empty()) out.back().second += (out.back().second.empty() ? "" : " ") + tok;
  }
  (void)PetscFree(all);
  return out;
}

PetscErrorCode RequireInput(MPI_Comm comm, bool given, const char *option, const char *message)
{
  PetscBool help = PETSC_FALSE;

  PetscFunctionBeginUser;
  if (given) PetscFunctionReturn(0);
  PetscCall(PetscOptionsHasHelp(NULL, &help));
  if (help) {
    PetscCall(PetscPrintf(comm, "\nrbcontact -help: the options above are those read before the stage needs %s, where it stops (nothing was run).\n"
                                "A stage lists each option as it reads it: give %s (and the scene, -options_file runs/<scene>.opts) to see the rest;\n"
                                "with its inputs, -help runs the stage, as PETSc programs do. Every option is described in README.md (Options) and docs/.\n",
                          option, option));
    throw HelpStop(std::string("-help: stopped before ") + option);
  }
  SETERRQ(comm, PETSC_ERR_USER_INPUT, "%s", message);
}

std::string OptionsHoldingValue(const char *mess)
{
  std::string       m = mess ? mess : "", word;
  const std::string a = "Input string ", b = "Unknown logical value: ";
  if (m.compare(0, a.size(), a) == 0) { // the value may hold spaces ("-mu '1.0 0.09'": the first word named -mu_default 1.0,0.09)
    size_t e = std::string::npos;
    for (const char *tail : {" has no ", " is out of "})
      if (m.find(tail, a.size()) != std::string::npos) e = std::min(e, m.find(tail, a.size()));
    word = m.substr(a.size(), (e == std::string::npos ? m.find(' ', a.size()) : e) - a.size());
  }
  else if (m.compare(0, b.size(), b) == 0) word = m.substr(b.size());
  if (word.empty()) return "";
  std::string found;
  for (const auto &o : OptionsInUse()) {
    std::istringstream vals(o.second);
    for (std::string v; std::getline(vals, v, ',');)
      if (v == word) {
        found += (found.empty() ? "" : ", ") + o.first + " " + o.second;
        break;
      }
  }
  const std::string spaces = word.find(' ') != std::string::npos ? "; a list takes commas, not spaces" : "";
  return found.empty() ? (spaces.empty() ? "" : " (" + spaces.substr(2) + ")") : " (option " + found + spaces + ")";
}

PetscErrorCode CheckListEntries(MPI_Comm comm)
{
  std::string bad;

  PetscFunctionBeginUser;
  for (const auto &o : OptionsInUse())
    if (bad.empty() && HasEmptyListEntry(o.second)) bad = o.first + " " + o.second;
  PetscCheck(bad.empty(), comm, PETSC_ERR_USER_INPUT, "option %s: an empty entry in the list (a comma too many?)", bad.c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode CheckValuesGiven(MPI_Comm comm, std::initializer_list<const char *> names)
{
  PetscFunctionBeginUser;
  for (const char *n : names) {
    PetscBool has = PETSC_FALSE, set = PETSC_FALSE;
    char      v[8] = "";
    PetscCall(PetscOptionsHasName(NULL, NULL, n, &has));
    if (has) PetscCall(PetscOptionsGetString(NULL, NULL, n, v, sizeof v, &set));
    PetscCheck(!has || (set && v[0]), comm, PETSC_ERR_USER_INPUT, "option %s is given without a value", n);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode CheckValuesGiven(MPI_Comm comm, const std::string &prefix, std::initializer_list<const char *> names)
{
  PetscFunctionBeginUser;
  for (const char *n : names) {
    const std::string full = "-" + prefix + n;
    PetscCall(CheckValuesGiven(comm, {full.c_str()}));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode CheckKSPTolerances(MPI_Comm comm, const std::string &prefix)
{
  const std::string p = "-" + prefix + "ksp_";
  PetscReal         rtol = 0, atol = 0;
  PetscInt          maxIt = 1;
  PetscBool         set;

  PetscFunctionBeginUser;
  PetscCall(CheckValuesGiven(comm, prefix + "ksp_", {"rtol", "atol", "max_it"}));
  PetscCall(PetscOptionsGetReal(NULL, NULL, (p + "rtol").c_str(), &rtol, &set));
  PetscCheck(!set || (rtol >= 0 && rtol < 1), comm, PETSC_ERR_ARG_OUTOFRANGE, "%srtol %g must be a number in [0, 1)", p.c_str(), (double)rtol);
  PetscCall(PetscOptionsGetReal(NULL, NULL, (p + "atol").c_str(), &atol, &set));
  PetscCheck(!set || (atol >= 0 && std::isfinite(atol)), comm, PETSC_ERR_ARG_OUTOFRANGE, "%satol %g must be a finite number >= 0", p.c_str(), (double)atol);
  PetscCall(PetscOptionsGetInt(NULL, NULL, (p + "max_it").c_str(), &maxIt, &set));
  PetscCheck(!set || maxIt >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "%smax_it %" PetscInt_FMT " must be >= 1", p.c_str(), maxIt);
  PetscFunctionReturn(0);
}

PetscErrorCode UnusedOptions(const std::string &stage, std::vector<std::string> *out, const std::vector<std::string> &given)
{
  PetscInt n;
  char   **names, **values;

  PetscFunctionBeginUser;
  out->clear();
  PetscCall(PetscOptionsLeftGet(NULL, &n, &names, &values));
  for (PetscInt i = 0; i < n; ++i) {
    const std::string name = names[i][0] == '-' ? names[i] + 1 : names[i];
    if (OtherStagesOption(stage, name, given)) continue;
    out->push_back("option -" + name + (values[i] ? " " + std::string(values[i]) : std::string()) + " was not used by the " + stage + " stage (misspelled? `rbcontact " + stage + " -help` lists the options)");
  }
  PetscCall(PetscOptionsLeftRestore(NULL, &n, &names, &values));
  PetscFunctionReturn(0);
}

static std::vector<std::pair<std::string, std::string>> optionsFilesRead; // of the last CheckOptionsFiles: (option, file)

const std::vector<std::pair<std::string, std::string>> &OptionsFilesRead() { return optionsFilesRead; }

std::string CheckOptionsFilesOnRankZero(MPI_Comm comm, const std::vector<std::string> &words)
{
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string bad = rank == 0 ? CheckOptionsFiles(words) : std::string();
  if (rank != 0) optionsFilesRead.clear();
  unsigned long long n = bad.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm);
  bad.resize(n);
  if (n) MPI_Bcast(&bad[0], (int)n, MPI_CHAR, 0, comm);
  return bad;
}

std::string CheckOptionsFiles(const std::vector<std::string> &words)
{
  std::vector<std::string>                                      chain, shown;
  std::map<std::string, double>                                 reads; // by resolved path: the files PETSc reads for it (itself and its -options_file's)
  const double                                                  maxReads = 256;
  optionsFilesRead.clear();
  // a YAML options file (-options_file_yaml F, PETSc follows it from the command line, PETSC_OPTIONS and options files):
  // an input of the run, not parsed here (its own -options_file entries are not followed)
  const auto yaml = [&](const std::string &file) {
    const std::pair<std::string, std::string> f("-options_file_yaml", file);
    if (std::find(optionsFilesRead.begin(), optionsFilesRead.end(), f) == optionsFilesRead.end()) optionsFilesRead.push_back(f);
  };
  // *n: the files PETSc reads when it inserts this one. A file included several times is read as often (3 -options_file
  // lines naming one file, nested 15 deep: 3^15 reads, a hang in this check and in PETSc); each file is parsed here once.
  std::function<std::string(const std::string &, int, double *)> visit = [&](const std::string &file, int depth, double *n) -> std::string {
    char buf[PATH_MAX];
    if (!realpath(file.c_str(), buf)) return "options file " + file + " (-options_file): " + std::strerror(errno);
    const std::string canon = buf;
    if (std::find(chain.begin(), chain.end(), canon) != chain.end()) {
      std::string path;
      for (const auto &s : shown) path += s + " -> ";
      return "options file " + file + " includes itself through -options_file (" + path + file + ")";
    }
    if (const auto r = reads.find(canon); r != reads.end()) {
      *n = r->second;
      return "";
    }
    if (depth >= 16) return "options file " + file + ": -options_file nested more than 16 deep";
    std::ifstream in(file);
    if (!in) return "options file " + file + " (-options_file): cannot be read";
    chain.push_back(canon);
    shown.push_back(file);
    if (const std::pair<std::string, std::string> f("-options_file", file); std::find(optionsFilesRead.begin(), optionsFilesRead.end(), f) == optionsFilesRead.end()) optionsFilesRead.push_back(f);
    *n = 1;
    for (std::string line; std::getline(in, line);) {
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      std::istringstream       ls(line);
      std::vector<std::string> tok;
      for (std::string t; ls >> t;) tok.push_back(t);
      for (size_t k = 0; k + 1 < tok.size(); ++k)
        if (tok[k] == "-options_file_yaml") yaml(tok[k + 1]);
        else if (tok[k] == "-options_file") {
          double            m = 0;
          const std::string e = visit(tok[k + 1], depth + 1, &m);
          if (!e.empty()) return e;
          *n += m;
          if (*n > maxReads) {
            char msg[64];
            std::snprintf(msg, sizeof msg, "%.4g", *n);
            return "options file " + file + " makes PETSc read options files " + msg + " times or more through -options_file (more than " + std::to_string((int)maxReads) + "; " + tok[k + 1] +
                   " and the files it includes are read once for every -options_file line naming it): include each file once";
          }
        }
    }
    chain.pop_back();
    shown.pop_back();
    reads[canon] = *n;
    return "";
  };
  double total = 0;
  // What PETSc 3.18's PetscOptionsInsert reads before the command line: ~/.petscrc, ./.petscrc and ./petscrc (where they
  // exist, unless the command line says -skip_petscrc), then the environment's PETSC_OPTIONS; an -options_file in any of
  // them recursed in PETSc without a check here (a self-including .petscrc: a stack overflow, not a message).
  // PETSC_OPTIONS_YAML (a YAML string) and the contents of -options_file_yaml files are not followed here: a YAML file
  // is only listed among the inputs (OptionsFilesRead).
  bool skip = false;
  for (size_t i = 0; i < words.size(); ++i)
    if (words[i] == "-skip_petscrc") {
      const std::string v = i + 1 < words.size() ? words[i + 1] : "";
      skip = !(!strcasecmp(v.c_str(), "0") || !strcasecmp(v.c_str(), "false") || !strcasecmp(v.c_str(), "no") || !strcasecmp(v.c_str(), "off")); // (PETSc's case-insensitive bool)
    }
  std::vector<std::string> rc;
  if (!skip) {
    if (const char *home = std::getenv("HOME"); home && home[0]) rc.push_back(std::string(home) + "/.petscrc");
    rc.push_back(".petscrc");
    rc.push_back("petscrc");
  }
  for (const auto &file : rc) {
    struct stat st;
    // PETSc reads it where it is a readable file and skips it silently otherwise
    if (::stat(file.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || ::access(file.c_str(), R_OK) != 0) continue;
    double            n = 0;
    const std::string e = visit(file, 0, &n);
    if (!e.empty()) return e + " (a file PETSc reads at every start; -skip_petscrc skips it)";
    total += n;
  }
  const auto tooMany = [&](const std::string &where) {
    return "the options files " + where + " make PETSc read options files more than " + std::to_string((int)maxReads) + " times: include each file once";
  };
  if (total > maxReads) return tooMany("of ~/.petscrc, ./.petscrc and ./petscrc");
  if (const char *env = std::getenv("PETSC_OPTIONS")) {
    std::istringstream       es(env);
    std::vector<std::string> tok;
    for (std::string t; es >> t;) tok.push_back(t);
    for (size_t i = 0; i + 1 < tok.size(); ++i)
      if (tok[i] == "-options_file_yaml") yaml(tok[i + 1]);
      else if (tok[i] == "-options_file") {
        double            n = 0;
        const std::string e = visit(tok[i + 1], 0, &n);
        if (!e.empty()) return e + " (named in the environment's PETSC_OPTIONS)";
        total += n;
        if (total > maxReads) return tooMany("named in the environment's PETSC_OPTIONS");
      }
  }
  for (size_t i = 0; i + 1 < words.size(); ++i)
    if (words[i] == "-options_file_yaml") yaml(words[i + 1]);
    else if (words[i] == "-options_file") {
      double            n = 0;
      const std::string e = visit(words[i + 1], 0, &n);
      if (!e.empty()) return e;
      total += n;
      if (total > maxReads) return "the command line's -options_file files make PETSc read options files more than " + std::to_string((int)maxReads) + " times (" + words[i + 1] + " among them): include each file once";
    }
  return "";
}

} // namespace rbc
