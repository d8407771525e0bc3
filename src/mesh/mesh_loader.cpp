// src/mesh/mesh_loader.cpp: gmsh .geo -> .msh generation (cached, atomic), DMPlex reading with
// physical names as labels, label checks, and distribution.
#include "rbcontact/mesh.hpp"
#include "rbcontact/partition.hpp"
#include "rbcontact/report.hpp"
#include "gmsh_check.hpp"
#include <petscsf.h>
#include <fcntl.h>
#include <spawn.h>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <cctype>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <climits>
#include <map>
#include <set>
#include <sstream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

extern char **environ;

#ifndef RBC_GMSH_EXECUTABLE
  #define RBC_GMSH_EXECUTABLE "gmsh"
#endif
#ifndef RBC_SOURCE_DIR
  #define RBC_SOURCE_DIR "."
#endif
#ifndef RBC_INSTALL_DATA_DIR
  #define RBC_INSTALL_DATA_DIR "/usr/local/share/rbcontact"
#endif

namespace rbc {

static PetscLogEvent MESH_Generate = 0, MESH_Load = 0;

unsigned long long Fnv1a(const std::string &s, unsigned long long h)
{
  for (unsigned char c : s) { h ^= c; h *= 1099511628211ULL; }
  return h;
}

static bool FileExists(const std::string &p)
{
  struct stat st;
  return stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// Where a relative data file (a mesh of runs/<scene>.opts) is looked for, in this order: the working
// directory, $RBC_DATA_DIR, the installed share/rbcontact beside the running program (<bin>/../share/
// rbcontact: an installed rbcontact, even moved), the configured install prefix's, and the source tree, the
// last only for a program that is not installed (no share/rbcontact beside it: the build tree's binary, an
// example): an installed binary never reads the build machine's checkout.
static std::vector<std::string> DataDirs()
{
  std::vector<std::string> d;
  bool                     installed = false;
  if (const char *e = std::getenv("RBC_DATA_DIR")) d.push_back(e);
  char          exe[PETSC_MAX_PATH_LEN];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n > 0) {
    exe[n]              = 0;
    const std::string s = exe;
    d.push_back(s.substr(0, s.find_last_of('/')) + "/../share/rbcontact");
    struct stat st;
    installed = stat(d.back().c_str(), &st) == 0 && S_ISDIR(st.st_mode);
  }
  d.push_back(RBC_INSTALL_DATA_DIR);
  if (!installed) d.push_back(RBC_SOURCE_DIR);
  return d;
}

PetscErrorCode ResolveDataFile(MPI_Comm comm, const std::string &file, std::string *path)
{
  PetscFunctionBeginUser;
  path->clear();
  std::string looked = "the working directory";
  if (FileExists(file)) *path = file;
  else if (!file.empty() && file[0] != '/')
    for (const auto &dir : DataDirs()) {
      if (FileExists(dir + "/" + file)) {
        *path = dir + "/" + file;
        break;
      }
      looked += ", " + dir;
    }
  PetscCheck(!path->empty(), comm, PETSC_ERR_FILE_OPEN, "Mesh file '%s' not found (given by -mesh_file; looked in %s)", file.c_str(), looked.c_str());
  PetscCall(PetscInfo(NULL, "mesh file %s -> %s\n", file.c_str(), path->c_str())); // -info shows which copy was used
  PetscFunctionReturn(0);
}

static bool EndsWith(const std::string &s, const std::string &suf) { return s.size() >= suf.size() && s.compare(s.size() - suf.size(), suf.size(), suf) == 0; }

// The text of a .geo and of every file it pulls in (Include "f", Merge "f", relative to the including file's directory,
// recursively): the mesh cache key (an edited included file reused the stale mesh), and where -mesh_geo_set's names
// are looked for. A file that cannot be read adds a mark only (gmsh then says what is wrong). Each file is read once
// (seen, by its resolved path): a .geo that included itself several times took time and memory exponential in the
// depth (3 self-includes: 3^16 reads, a hang before gmsh ran). A file that includes itself, directly or through
// others (chain: the files being read), is an error, the chain in *cycle (gmsh said "Unable to open file").
static void GeoSources(const std::string &path, std::vector<std::string> *chain, std::set<std::string> *seen, std::string *text, std::string *cycle)
{
  char              real[PATH_MAX];
  const std::string id = realpath(path.c_str(), real) ? std::string(real) : path;
  if (std::find(chain->begin(), chain->end(), id) != chain->end()) {
    if (cycle->empty()) {
      for (const auto &c : *chain) *cycle += (cycle->empty() ? "" : " -> ") + c.substr(c.find_last_of('/') + 1);
      *cycle += " -> " + id.substr(id.find_last_of('/') + 1);
    }
    return;
  }
  if (!seen->insert(id).second) return; // (its text is in the key already)
  std::ifstream f(path);
  if (!f) {
    *text += "|unreadable";
    return;
  }
  std::ostringstream all;
  all << f.rdbuf();
  const std::string t   = all.str();
  const auto        cut = path.find_last_of('/');
  const std::string dir = cut == std::string::npos ? "" : path.substr(0, cut + 1);
  *text += (chain->empty() ? "" : "|include\n") + t; // (not the paths: a clone elsewhere shares the cache)
  if (chain->size() >= 16) return;
  chain->push_back(id);
  for (const char *kw : {"Include", "Merge"})
    for (size_t at = t.find(kw); at != std::string::npos; at = t.find(kw, at + 1)) {
      const size_t q0 = t.find('"', at), q1 = q0 == std::string::npos ? q0 : t.find('"', q0 + 1);
      if (q1 == std::string::npos || t.find_first_not_of(" \t", at + std::strlen(kw)) != q0) continue;
      const std::string inc = t.substr(q0 + 1, q1 - q0 - 1);
      GeoSources(!inc.empty() && inc[0] == '/' ? inc : dir + inc, chain, seen, text, cycle);
    }
  chain->pop_back();
}

// Whether the .geo sources assign the variable name (NAME = ... or a DefineConstant entry NAME = {...}): gmsh
// -setnumber of an unknown name only defines an unused variable, so a misspelled -mesh_geo_set left the default mesh.
static bool GeoAssigns(const std::string &text, const std::string &name)
{
  for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1)) {
    const bool startOk = at == 0 || !(std::isalnum((unsigned char)text[at - 1]) || text[at - 1] == '_');
    size_t     k       = at + name.size();
    if (!startOk || (k < text.size() && (std::isalnum((unsigned char)text[k]) || text[k] == '_'))) continue;
    while (k < text.size() && (text[k] == ' ' || text[k] == '\t')) ++k;
    if (k < text.size() && text[k] == '=' && (k + 1 >= text.size() || text[k + 1] != '=')) return true;
  }
  return false;
}

// How a child process ended (RunLogged).
struct ChildEnd {
  int  code   = -1;    // exit code, -1 when it did not exit normally
  int  signal = 0;     // the signal that ended it
  bool hung   = false; // still running 10 s after its log said its parser gave up: killed
};

// Whether the log holds gmsh's last parser error: gmsh 4.8, aborting its parser inside an Include'd file, may close a
// file twice and then wait forever on the stdio lock (measured: a .geo including ring_on_block.geo twice hung 2 runs
// in 4, "glibc detected an invalid stdio handle" and an abort in the others).
static bool ParserGaveUp(const std::string &log)
{
  std::ifstream f(log);
  std::string   line;
  while (std::getline(f, line))
    if (line.find("Too many errors") != std::string::npos) return true;
  return false;
}

// Runs argv[0] with argv (no shell: the names and paths are passed as they are), its output to log; how it ended
// (started false: it could not be started).
static ChildEnd RunLogged(const std::vector<std::string> &args, const std::string &log, bool *started)
{
  ChildEnd            end;
  std::vector<char *> argv;
  for (const auto &a : args) argv.push_back(const_cast<char *>(a.c_str()));
  argv.push_back(nullptr);
  *started = false;
  posix_spawn_file_actions_t fa;
  if (posix_spawn_file_actions_init(&fa) != 0) return end;
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawn_file_actions_addclose(&fa, 0);
  pid_t pid;
  const int rc = posix_spawnp(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return end;
  *started    = true;
  int        status = 0;
  const auto t0     = std::chrono::steady_clock::now();
  auto       since  = [&]() { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  double     gaveUp = -1, checked = 0; // when the log said the parser gave up; when it was last read
  for (;;) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) return end;
    const double t = since();
    if (gaveUp < 0 && t - checked >= 1) {
      checked = t;
      if (ParserGaveUp(log)) gaveUp = t;
    }
    if (gaveUp >= 0 && t - gaveUp > 10) {
      kill(pid, SIGKILL);
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
      end.hung = true;
      return end;
    }
    usleep(t < 1 ? 2000 : 50000); // (most meshes take well under a second)
  }
  if (WIFEXITED(status)) end.code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) end.signal = WTERMSIG(status);
  return end;
}

// mkdir -p
static bool MakeDirs(const std::string &dir)
{
  for (size_t at = dir.find('/', 1);; at = dir.find('/', at + 1)) {
    const std::string d = dir.substr(0, at);
    if (!d.empty() && mkdir(d.c_str(), 0755) != 0 && errno != EEXIST) return false;
    if (at == std::string::npos) break;
  }
  struct stat st;
  return stat(dir.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

PetscErrorCode MeshGenerate(MPI_Comm comm, const MeshSpec &spec, std::string *mshPath)
{
  PetscMPIInt rank;
  std::string src;
  int         ok = 1;
  char        msg[2048] = "";

  PetscFunctionBeginUser;
  if (!MESH_Generate) PetscCall(PetscLogEventRegister("RBCMeshGenerate", DM_CLASSID, &MESH_Generate));
  PetscCall(ResolveDataFile(comm, spec.file, &src));
  if (!EndsWith(src, ".geo")) {
    *mshPath = src;
    PetscFunctionReturn(0);
  }
  PetscCall(PetscLogEventBegin(MESH_Generate, 0, 0, 0, 0));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  // Cache key: the text of the .geo and of the files it includes + numbers + clscale + output format.
  std::ostringstream key;
  std::string        sources;
  std::set<std::string>    seen;
  std::vector<std::string> chain;
  std::string              cycle;
  GeoSources(src, &chain, &seen, &sources, &cycle);
  PetscCheck(cycle.empty(), comm, PETSC_ERR_USER_INPUT, "mesh '%s' includes itself through Include or Merge (%s): gmsh cannot read it", src.c_str(), cycle.c_str());
  key << sources;
  for (const auto &kv : spec.geoNumbers)
    PetscCheck(GeoAssigns(sources, kv.first), comm, PETSC_ERR_USER_INPUT, "-mesh_geo_set / -mu_geo_set: '%s' is not a variable of '%s' (nor of the files it includes): gmsh would ignore it and mesh the default geometry", kv.first.c_str(), src.c_str());
  char scale[64];
  std::snprintf(scale, sizeof scale, "%.12g", (double)spec.clscale);
  key << "|clscale=" << scale;
  // gmsh writes format 4.1: PETSc 3.18's reader of format 2.2 also puts the elements whose elementary
  // (entity) tag equals a physical tag into that physical group (measured: pin_in_hole.geo's "pin_core",
  // tag 13, received the master arc Circle(13)); 4.1 keeps entities and physical groups apart
  key << "|format=msh41";
  std::vector<std::string> setnum;
  for (const auto &kv : spec.geoNumbers) {
    char v[64];
    std::snprintf(v, sizeof v, "%.17g", (double)kv.second);
    key << "|" << kv.first << "=" << v;
    setnum.insert(setnum.end(), {"-setnumber", kv.first, v});
  }
  std::string base = src.substr(src.find_last_of('/') == std::string::npos ? 0 : src.find_last_of('/') + 1);
  base             = base.substr(0, base.size() - 4);
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", Fnv1a(key.str()));
  *mshPath = spec.cacheDir + "/" + base + "-" + hash + ".msh";
  if (rank == 0 && !FileExists(*mshPath)) {
    if (!MakeDirs(spec.cacheDir)) {
      ok = 0;
      std::snprintf(msg, sizeof msg, "cannot create mesh cache directory '%s' (-mesh_cache_dir or RBC_MESH_CACHE)", spec.cacheDir.c_str());
    } else {
      const std::string tmp = *mshPath + ".tmp." + std::to_string((long)getpid()) + ".msh";
      const std::string log = *mshPath + ".log";
      std::vector<std::string> args = {RBC_GMSH_EXECUTABLE, "-3", src, "-clscale", scale};
      args.insert(args.end(), setnum.begin(), setnum.end());
      args.insert(args.end(), {"-format", "msh41", "-v", "2", "-o", tmp});
      std::string cmd; // (shown in the message)
      for (const auto &a : args) cmd += (cmd.empty() ? "" : " ") + a;
      // no shell (std::system before 2026-11-29: a -mesh_geo_set name ran as a command, a ' in a path broke the line)
      bool           started = false;
      const ChildEnd end     = RunLogged(args, log, &started);
      const int      rc      = started ? end.code : -1;
      {
        // gmsh exits 0 after some errors (an unknown -setnumber, a file it cannot read): its log decides too
        std::ifstream lf(log);
        std::string   line;
        bool          err = false;
        while (!err && std::getline(lf, line)) err = line.rfind("Error", 0) == 0;
        if (rc == 0 && err) std::remove(tmp.c_str());
      }
      if (rc != 0 || !FileExists(tmp)) {
        ok = 0;
        std::remove(tmp.c_str());
        // how gmsh ended, and its first error line
        // (e.g. "Error : 'x.geo', line 2: syntax error") so the user need not open the log.
        std::string how = !started ? "it could not be started" : end.hung ? "it hung after its parser gave up, and was ended: a gmsh 4.8 fault on errors in an Include'd file" : end.signal ? "killed by signal " + std::to_string(end.signal) : "exit code " + std::to_string(end.code);
        std::string first;
        {
          std::ifstream lf(log);
          std::string   line;
          while (first.empty() && std::getline(lf, line))
            if (line.find("Error") != std::string::npos) first = line.substr(0, 300);
        }
        std::snprintf(msg, sizeof msg, "gmsh failed on '%s' (%s)%s%s; command: %s; see %s", src.c_str(), how.c_str(), first.empty() ? "" : ": ", first.c_str(), cmd.c_str(), log.c_str());
      } else if (std::rename(tmp.c_str(), mshPath->c_str()) != 0) {
        ok = 0;
        std::snprintf(msg, sizeof msg, "cannot move generated mesh to '%s'", mshPath->c_str());
      }
    }
  }
  PetscCallMPI(MPI_Bcast(&ok, 1, MPI_INT, 0, comm));
  PetscCallMPI(MPI_Bcast(msg, sizeof msg, MPI_CHAR, 0, comm));
  PetscCheck(ok, comm, PETSC_ERR_FILE_UNEXPECTED, "%s", msg);
  PetscCall(PetscLogEventEnd(MESH_Generate, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode GlobalPointCount(DM dm, bool cells, PetscInt *n)
{
  PetscSF         sf;
  PetscInt        pStart, pEnd, nleaves;
  const PetscInt *leaves;

  PetscFunctionBeginUser;
  if (cells) PetscCall(DMPlexGetHeightStratum(dm, 0, &pStart, &pEnd));
  else PetscCall(DMPlexGetDepthStratum(dm, 0, &pStart, &pEnd));
  PetscCall(DMGetPointSF(dm, &sf));
  PetscCall(PetscSFGetGraph(sf, NULL, &nleaves, &leaves, NULL));
  PetscInt owned = pEnd - pStart;
  for (PetscInt l = 0; l < PetscMax(nleaves, 0); ++l) {
    const PetscInt p = leaves ? leaves[l] : l;
    if (p >= pStart && p < pEnd) --owned;
  }
  PetscCallMPI(MPI_Allreduce(&owned, n, 1, MPIU_INT, MPI_SUM, PetscObjectComm((PetscObject)dm)));
  PetscFunctionReturn(0);
}

PetscErrorCode MeshPhysicalNames(DM dm, std::vector<std::string> *names)
{
  MPI_Comm    comm = PetscObjectComm((PetscObject)dm);
  PetscInt    n;
  PetscMPIInt size;
  std::string mine; // this rank's names, one per line

  PetscFunctionBeginUser;
  names->clear();
  PetscCall(DMGetNumLabels(dm, &n));
  for (PetscInt l = 0; l < n; ++l) {
    const char *name;
    PetscCall(DMGetLabelName(dm, l, &name));
    const std::string s(name);
    if (s == "depth" || s == "celltype" || s == "Cell Sets" || s == "Face Sets" || s == "Vertex Sets" || s == "Edge Sets" || s == "marker") continue;
    mine += s + "\n";
  }
  // the union over the ranks, in order of first appearance (a rank may lack a label: on 2 ranks the "does not exist"
  // message of rank 1 listed no names until 2026-12-01)
  PetscCallMPI(MPI_Comm_size(comm, &size));
  std::vector<int> len((size_t)size), off((size_t)size + 1, 0);
  const int        m = (int)mine.size();
  PetscCallMPI(MPI_Allgather(&m, 1, MPI_INT, len.data(), 1, MPI_INT, comm));
  for (PetscMPIInt r = 0; r < size; ++r) off[r + 1] = off[r] + len[r];
  std::string all((size_t)off[size], '\0');
  PetscCallMPI(MPI_Allgatherv(mine.data(), m, MPI_CHAR, &all[0], len.data(), off.data(), MPI_CHAR, comm));
  for (size_t a = 0, b; a < all.size(); a = b + 1) {
    b = all.find('\n', a);
    const std::string s = all.substr(a, b - a);
    if (std::find(names->begin(), names->end(), s) == names->end()) names->push_back(s);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MeshCheckLabel(DM dm, const std::string &name, const char *option, const std::string &file)
{
  DMLabel  label;
  PetscInt n = 0, range[2] = {PETSC_MAX_INT, PETSC_MAX_INT}; // smallest value, minus the largest

  PetscFunctionBeginUser;
  PetscCall(DMGetLabel(dm, name.c_str(), &label));
  if (label) {
    IS              is;
    const PetscInt *v;
    PetscCall(DMLabelGetValueIS(label, &is));
    PetscCall(ISGetSize(is, &n));
    PetscCall(ISGetIndices(is, &v));
    for (PetscInt i = 0; i < n; ++i) {
      range[0] = std::min(range[0], v[i]);
      range[1] = std::min(range[1], -v[i]);
    }
    PetscCall(ISRestoreIndices(is, &v));
    PetscCall(ISDestroy(&is));
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPIU_INT, MPI_MAX, PetscObjectComm((PetscObject)dm)));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, range, 2, MPIU_INT, MPI_MIN, PetscObjectComm((PetscObject)dm)));
  // one name, two physical tags (a .msh merged from several files or edited): the boundary conditions read one tag, so
  // the elements of the other were left free (an audit's ring held at one end: force 0.0167 for 0.4996, exit 0)
  PetscCheck(!n || range[0] == -range[1], PetscObjectComm((PetscObject)dm), PETSC_ERR_USER_INPUT, "Physical name '%s' (option %s) has several physical tags in mesh '%s' (%" PetscInt_FMT " to %" PetscInt_FMT "): rbcontact reads one tag per name; give the group one tag", name.c_str(), option, file.c_str(), range[0], -range[1]);
  if (!n) {
    std::vector<std::string> names;
    std::string              all;
    PetscCall(MeshPhysicalNames(dm, &names));
    for (const auto &s : names) all += (all.empty() ? "" : ", ") + s;
    SETERRQ(PetscObjectComm((PetscObject)dm), PETSC_ERR_USER_INPUT, "Physical name '%s' (option %s) does not exist in mesh '%s'; it has: %s (PETSc 3.18's reader keeps the groups of cells and of facets: a Physical Point, and in 3D a Physical Curve, is not read)", name.c_str(), option, file.c_str(), all.c_str());
  }
  PetscFunctionReturn(0);
}

// gmsh format 2.2 files: PETSc 3.18's reader (with -dm_plex_gmsh_use_regions) puts an element into every
// physical group whose tag equals one of the element's tags, the elementary (entity) tag included. An
// element of entity 13 in physical group 12 lands in group 13 as well when one exists: a wrong mesh
// (measured: pin_in_hole's master arc, Circle(13), became part of "pin_core", tag 13: an imposed
// displacement on the master, contact enforced on half the arc). Refuse such files, naming the clash.
// The message, or "" (rank 0, before the reader). generated: the .msh was meshed from a .geo (the advice differs).
static std::string Gmsh22TagClash(const std::string &msh, const std::string &option, bool generated)
{
  std::string why;
  {
    std::ifstream f(msh);
    std::string   line;
    bool          v2 = false;
    std::map<std::pair<int, int>, std::string> groups; // (dim, tag) -> name
    while (f && std::getline(f, line)) {
      if (line.rfind("$MeshFormat", 0) == 0) {
        std::getline(f, line);
        v2 = !line.empty() && line[0] == '2';
        if (!v2) break;
        std::istringstream fmt(line);
        double             version = 0;
        int                binary  = 0;
        fmt >> version >> binary;
        if (binary == 1) { // its $Elements cannot be read as text: the check below would find nothing (an audit's pin_in_hole: exit 0, force 0.503 for 0.358)
          why = "mesh '" + msh + "' (" + option + ") is in binary gmsh format 2.2, whose element tags cannot be checked against PETSc 3.18's reader (which mislabels the elements of an entity whose tag equals another physical group's): write it in format 4.1 (gmsh -format msh41" +
                (generated ? "; remove Mesh.MshFileVersion and Mesh.Binary from the .geo" : "") + ") or as ASCII 2.2";
          break;
        }
      } else if (line.rfind("$PhysicalNames", 0) == 0) {
        int n = 0;
        f >> n;
        for (int i = 0; i < n; ++i) {
          int         d, t;
          std::string name;
          if (!(f >> d >> t)) break; // (a count beyond the file: 2e9 failed reads before, 30 s and more)
          std::getline(f, name);
          const size_t a = name.find('"'), b = name.rfind('"');
          groups[{d, t}] = (a != std::string::npos && b > a) ? name.substr(a + 1, b - a - 1) : name;
        }
      } else if (line.rfind("$Elements", 0) == 0) {
        auto dimOf = [](int type) { // the element types PETSc 3.18's reader knows (gmsh_check.cpp refuses the others)
          if (type == 15) return 0;
          if (type == 1 || type == 8 || (type >= 26 && type <= 28) || (type >= 62 && type <= 66)) return 1;
          if ((type >= 2 && type <= 3) || (type >= 9 && type <= 10) || type == 16 || (type >= 20 && type <= 25) || (type >= 36 && type <= 51)) return 2;
          return 3;
        };
        long n = 0;
        f >> n;
        std::getline(f, line);
        // PETSc 3.18.5's reader matches every tag (at most 16) of the cells and of the facets (the mesh's dimension and
        // the one below) against the groups of their dimension: the entity tag, and in a partitioned file the partition
        // count and the partition tags; points and, in 3D, curves are labelled by their physical tag alone. The mesh's
        // dimension is known at the end: the first clash of each dimension is kept until then.
        std::map<int, std::string> clash; // element dimension -> message
        int                        top = 0;
        for (long e = 0; e < n && std::getline(f, line); ++e) {
          std::istringstream in(line);
          int                id = 0, type = 0, ntags = 0, phys = 0;
          in >> id >> type >> ntags >> phys;
          const int dim = dimOf(type);
          top           = std::max(top, dim);
          if (clash.count(dim)) continue;
          for (int t = 1; t < std::min(ntags, 16); ++t) {
            int tag = 0;
            if (!(in >> tag)) break;
            if (tag == phys) continue;
            const auto g = groups.find({dim, tag});
            if (g == groups.end()) continue;
            const auto         own     = groups.find({dim, phys});
            const std::string  ownName = own != groups.end() ? own->second : std::to_string(phys);
            std::ostringstream m;
            m << "mesh '" << msh << "' (" << option << ") is in gmsh format 2.2 and ";
            if (t == 1) m << "its entity " << tag << " (of physical group '" << ownName << "') has the tag of physical group '" << g->second << "'";
            else m << "its element " << id << " (of physical group '" << ownName << "') carries the tag " << tag << " of physical group '" << g->second << "' as its " << (t == 2 ? "partition count" : "partition tag") << " (a partitioned file)";
            m << ": PETSc 3.18's reader would put those elements into '" << g->second << "' too (a wrong mesh). ";
            if (t == 1) m << (generated ? "Remove Mesh.MshFileVersion from the .geo (rbcontact meshes it in format 4.1)" : "Write it with gmsh -format msh41") << " (or give the physical groups tags no entity uses)";
            else m << "Write it without partitions (gmsh without -part" << (generated ? ", no Mesh.NbPartitions in the .geo" : "") << "): rbcontact partitions the mesh itself";
            clash[dim] = m.str();
            break;
          }
        }
        for (int d : {top, top - 1})
          if (why.empty() && d > 0 && clash.count(d)) why = clash[d];
        break;
      }
    }
  }
  return why;
}

// Before the reader: the bodies of -bodies with no physical group of the mesh's dimension in the $PhysicalNames of
// an ASCII .msh ("" when every body has one, or when the file says nothing that can be read).
static std::string BodiesWithoutGroup(const std::string &msh, const SceneSpec &scene)
{
  std::ifstream in(msh);
  std::string   line;
  while (std::getline(in, line) && line.rfind("$PhysicalNames", 0) != 0) {}
  if (!in) return "";
  int n = 0;
  if (!(in >> n) || n <= 0) return "";
  std::vector<std::pair<int, std::string>> groups; // dimension, name
  int                                      top = 0;
  for (int i = 0; i < n; ++i) {
    int         dim, tag;
    std::string name;
    if (!(in >> dim >> tag) || !std::getline(in, name)) return "";
    const size_t a = name.find('"'), b = name.rfind('"');
    groups.emplace_back(dim, a != std::string::npos && b > a ? name.substr(a + 1, b - a - 1) : name);
    top = std::max(top, dim);
  }
  if (top < 2) return ""; // no cells in any group: left to the reader
  std::string all;
  for (const auto &g : groups) all += (all.empty() ? "" : ", ") + g.second + " (" + std::to_string(g.first) + "D)";
  for (const auto &b : scene.bodies) {
    if (b.name == "all") continue;
    bool found = false;
    for (const auto &g : groups) found = found || (g.second == b.name && g.first == top);
    if (!found)
      return "Physical name '" + b.name + "' (option -bodies) does not exist as a group of dimension " + std::to_string(top) + " (its groups: " + all + "): misspelled, or the body's " + (top == 3 ? "volume has no Physical Volume" : "surface has no Physical Surface") + " (gmsh then saves its boundary without its cells)";
  }
  return "";
}

PetscErrorCode MeshLoad(MPI_Comm comm, const SceneSpec &scene, DM *dm)
{
  std::string msh;
  PetscBool   set;

  PetscFunctionBeginUser;
  if (!MESH_Load) PetscCall(PetscLogEventRegister("RBCMeshLoad", DM_CLASSID, &MESH_Load));
  PetscCall(MeshGenerate(comm, scene.mesh, &msh));
  PetscCall(PetscLogEventBegin(MESH_Load, 0, 0, 0, 0));
  PetscCall(PetscOptionsHasName(NULL, NULL, "-dm_plex_gmsh_use_regions", &set));
  if (!set) PetscCall(PetscOptionsSetValue(NULL, "-dm_plex_gmsh_use_regions", "true"));
  // A mesh our generator wrote (a .geo source meshed by gmsh into the cache, by a temporary file and a rename) is
  // complete; a user's .msh may not be.
  const bool generated = EndsWith(scene.mesh.file, ".geo");
  if (EndsWith(msh, ".msh")) {
    // Rank 0 reads the text before PETSc's reader: the format 2.2 tag clash; a body of -bodies whose cells are in no
    // physical group (gmsh then saves only its boundary curves, which PETSc's reader refuses on rank 0 while the other
    // ranks wait in its collectives: a hang on 2 ranks for a generated mesh, which is not parsed on rank 0 first); in
    // a user's file, everything the reader would mishandle (GmshStructureProblem: an element pointing at an undefined
    // node, counts that disagree with the data, undefined entities, a NUL byte, a format other than 4.1 ASCII or binary
    // and 2.2 ASCII, ...): the reader sees no user's file the check has not read.
    std::string why;
    PetscMPIInt r0;
    PetscCallMPI(MPI_Comm_rank(comm, &r0));
    if (r0 == 0) {
      // a user's file: its structure first (counts, tags and references PETSc's reader trusts: gmsh_check.hpp), so that
      // the checks below read a sound file
      std::string missing = generated ? "" : GmshStructureProblem(msh);
      why                 = missing.empty() ? Gmsh22TagClash(msh, "-mesh_file " + scene.mesh.file, generated) : "";
      if (why.empty() && missing.empty()) missing = BodiesWithoutGroup(msh, scene);
      if (!missing.empty()) why = "Mesh '" + msh + "' (from -mesh_file " + scene.mesh.file + "): " + missing;
    }
    PetscCall(BcastString(comm, &why));
    PetscCheck(why.empty(), comm, PETSC_ERR_FILE_UNEXPECTED, "%s", why.c_str());
  }
  {
    PetscErrorCode ierr = 0;
    PetscMPIInt    size, rank;
    PetscCallMPI(MPI_Comm_size(comm, &size));
    PetscCallMPI(MPI_Comm_rank(comm, &rank));
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    if (size > 1 && !generated) {
      // PETSc's gmsh reader parses the file on rank 0 while the other ranks wait in collectives:
      // a malformed file made rank 0 return an error and the others hang. So on several ranks,
      // rank 0 first parses a user's file alone (PETSC_COMM_SELF) and every rank learns the outcome
      // (this second parse cost 0.35 s of a 2.3 s FOM at ring_on_block refine 2, 2 ranks: not done
      // for the meshes we generate).
      if (rank == 0) {
        DM probe = NULL;
        ierr     = DMPlexCreateFromFile(PETSC_COMM_SELF, msh.c_str(), "rbcontact", PETSC_TRUE, &probe);
        if (!ierr) ierr = DMDestroy(&probe);
      }
      PetscCallMPI(MPI_Bcast(&ierr, 1, MPI_INT, 0, comm));
    }
    if (!ierr) ierr = DMPlexCreateFromFile(comm, msh.c_str(), "rbcontact", PETSC_TRUE, dm);
    PetscCall(PetscPopErrorHandler());
    if (ierr) {
      const char *what = NULL;
      PetscCall(PetscErrorMessage(ierr, &what, NULL));
      if (generated) // (gmsh wrote it: "not a valid gmsh file?" pointed at the wrong cause)
        SETERRQ(comm, PETSC_ERR_FILE_UNEXPECTED, "PETSc's reader refused the mesh gmsh made of %s ('%s'; PETSc error %d: %s): a physical group of curves (surfaces in 3D) that bound no body, a .geo that meshes nothing, or a Mesh.MshFileVersion other than 4.1 set in the .geo?", scene.mesh.file.c_str(), msh.c_str(), (int)ierr, what ? what : "?");
      SETERRQ(comm, PETSC_ERR_FILE_UNEXPECTED, "Cannot read mesh '%s' (from -mesh_file %s): not a valid gmsh file? (PETSc error %d: %s)", msh.c_str(), scene.mesh.file.c_str(), (int)ierr, what ? what : "?");
    }
  }
  PetscCall(PetscObjectSetName((PetscObject)*dm, scene.name.c_str()));
  {
    // Curved (second-order) gmsh elements: PETSc's reader keeps their mid-edge nodes as a coordinate field of
    // degree 2, which the straight-simplex assembly and contact geometry do not read (the geometry check below
    // then called them inverted). Said as what it is.
    DM           cdm;
    PetscObject  disc     = NULL;
    PetscInt     cdegree  = 1;
    PetscClassId id;
    PetscCall(DMGetCoordinateDM(*dm, &cdm));
    PetscInt nf;
    PetscCall(DMGetNumFields(cdm, &nf));
    if (nf > 0) PetscCall(DMGetField(cdm, 0, NULL, &disc));
    if (disc) {
      PetscCall(PetscObjectGetClassId(disc, &id));
      if (id == PETSCFE_CLASSID) {
        PetscSpace sp;
        PetscCall(PetscFEGetBasisSpace((PetscFE)disc, &sp));
        PetscCall(PetscSpaceGetDegree(sp, &cdegree, NULL));
      }
    }
    PetscCheck(cdegree <= 1, comm, PETSC_ERR_USER_INPUT, "Mesh '%s' (from -mesh_file %s) has curved elements of order %" PetscInt_FMT " (gmsh Mesh.ElementOrder or -order): rbcontact reads straight triangles and tetrahedra; mesh with order 1 and use -fem_degree 2 for quadratic displacements", msh.c_str(), scene.mesh.file.c_str(), cdegree);
  }
  {
    // Each cell's Jacobian: inverted cells (a gmsh surface meshed clockwise) give an indefinite stiffness; degenerate
    // ones (coincident nodes, an element pointing at a wrong node) a singular one; non-finite coordinates anything. All
    // three were called "inverted" (DMPlexCheckGeometry's failure), with the advice to reverse a Curve Loop.
    PetscInt dim, cStart, cEnd, count[3] = {0, 0, 0}; // non-finite, degenerate, inverted
    PetscReal lo[3] = {PETSC_MAX_REAL, PETSC_MAX_REAL, PETSC_MAX_REAL}, hi[3] = {-PETSC_MAX_REAL, -PETSC_MAX_REAL, -PETSC_MAX_REAL};
    Vec       coords;
    PetscCall(DMGetDimension(*dm, &dim));
    PetscCall(DMGetCoordinatesLocal(*dm, &coords));
    {
      const PetscScalar *x;
      PetscInt           n;
      PetscCall(VecGetLocalSize(coords, &n));
      PetscCall(VecGetArrayRead(coords, &x));
      for (PetscInt i = 0; i < n; ++i) {
        if (!std::isfinite(PetscRealPart(x[i]))) ++count[0];
        else {
          lo[i % dim] = std::min(lo[i % dim], PetscRealPart(x[i]));
          hi[i % dim] = std::max(hi[i % dim], PetscRealPart(x[i]));
        }
      }
      PetscCall(VecRestoreArrayRead(coords, &x));
    }
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPIU_REAL, MPIU_MIN, comm));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPIU_REAL, MPIU_MAX, comm));
    PetscReal ext = 0; // the mesh's extent: a cell whose |J| is below 1e-12 ext^dim has (nearly) no volume
    for (PetscInt d = 0; d < dim; ++d) ext = std::max(ext, hi[d] - lo[d]);
    PetscCall(DMPlexGetHeightStratum(*dm, 0, &cStart, &cEnd));
    for (PetscInt c = cStart; c < cEnd && !count[0]; ++c) {
      PetscReal v0[3], J[9], invJ[9], detJ;
      PetscCall(DMPlexComputeCellGeometryAffineFEM(*dm, c, v0, J, invJ, &detJ));
      if (!std::isfinite(detJ)) ++count[0];
      else if (std::fabs(detJ) <= 1e-12 * std::pow(ext, (PetscReal)dim)) ++count[1];
      else if (detJ < 0) ++count[2];
    }
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, count, 3, MPIU_INT, MPI_SUM, comm));
    PetscCheck(!count[0], comm, PETSC_ERR_USER_INPUT, "Mesh '%s' (from -mesh_file %s) has non-finite node coordinates (%" PetscInt_FMT " values or cells): a corrupt file", msh.c_str(), scene.mesh.file.c_str(), count[0]);
    PetscCheck(!count[1], comm, PETSC_ERR_USER_INPUT, "Mesh '%s' (from -mesh_file %s) has %" PetscInt_FMT " degenerate cells (no area or volume): coincident nodes, or elements that point at wrong nodes", msh.c_str(), scene.mesh.file.c_str(), count[1]);
    PetscCheck(!count[2], comm, PETSC_ERR_USER_INPUT, "Mesh '%s' (from -mesh_file %s) has %" PetscInt_FMT " inverted (negatively oriented) cells: orient every gmsh surface counter-clockwise (reverse its Curve Loop) and regenerate", msh.c_str(), scene.mesh.file.c_str(), count[2]);
  }
  // Every physical name the scene uses must exist.
  for (const auto &b : scene.bodies)
    if (b.name != "all") PetscCall(MeshCheckLabel(*dm, b.name, "-bodies", scene.mesh.file));
  for (const auto &bc : scene.dirichlet) PetscCall(MeshCheckLabel(*dm, bc.label, "-dirichlet", scene.mesh.file));
  for (const auto &t : scene.tractions) PetscCall(MeshCheckLabel(*dm, t.label, "-traction", scene.mesh.file));
  if (scene.contact) {
    PetscCall(MeshCheckLabel(*dm, scene.slave, "-contact_slave", scene.mesh.file));
    PetscCall(MeshCheckLabel(*dm, scene.master, "-contact_master", scene.mesh.file));
  }
  // Boundary labels must hold the closure (vertices, edges) for essential conditions and contact.
  {
    std::vector<std::string> bnames;
    for (const auto &bc : scene.dirichlet) bnames.push_back(bc.label);
    if (scene.contact) { bnames.push_back(scene.slave); bnames.push_back(scene.master); }
    for (const auto &n : bnames) {
      DMLabel l;
      PetscCall(DMCreateLabel(*dm, n.c_str())); // ranks without cells before distribution lack it
      PetscCall(DMGetLabel(*dm, n.c_str(), &l));
      PetscCall(DMPlexLabelComplete(*dm, l));
    }
  }
  PetscCall(DistributeMesh(dm));
  // DMSetFromOptions of a DMPlex distributes it again by default (-dm_distribute, with PETSc's own
  // partitioner): that silently replaced the -mesh_partitioner partition by another one, different
  // from run to run (ring_on_block, 2 ranks, metis: 3045/2902 cells became 2944/3003, 2953/2994,
  // ...). The mesh is distributed already: turn that default off (an explicit -dm_distribute wins).
  PetscCall(DMPlexDistributeSetDefault(*dm, PETSC_FALSE));
  PetscCall(DMSetFromOptions(*dm));
  PetscCall(DMViewFromOptions(*dm, NULL, "-dm_view"));
  PetscCall(PetscLogEventEnd(MESH_Load, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

} // namespace rbc
