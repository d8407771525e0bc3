// tests/test_training_set.cpp: the parameter samples of rbc::ParameterSetFromOptions and the pure
// generators: exact grid values (-x_size 21 on [0.95, 1.15] gives 0.95, 0.96, ..., 1.15), grid
// ordering (last parameter fastest), per-parameter counts, the box centre for one point, Latin
// hypercube stratification, random determinism (same seed equal, other seed different), every
// point in its box, identical sets on every rank, sample files (comments, commas) and the errors
// of bad files (out-of-box line, malformed line, wrong column count) and bad options.
#include "rbcontact/training_set.hpp"
#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

using namespace rbc;

static int         failures = 0;
static PetscMPIInt rank     = 0;

static void Check(bool ok, const std::string &what)
{
  if (!ok) ++failures;
  if (rank == 0 || !ok) std::printf("  [%d] %-5s %s\n", rank, ok ? "ok" : "FAIL", what.c_str());
}

static ParamSpec Param(const char *name, PetscReal lo, PetscReal hi)
{
  ParamSpec p;
  p.name = name;
  p.min  = lo;
  p.max  = hi;
  return p;
}

static bool InBox(const std::vector<std::vector<PetscReal>> &pts, const std::vector<ParamSpec> &ps)
{
  for (const auto &x : pts) {
    if (x.size() != ps.size()) return false;
    for (size_t j = 0; j < ps.size(); ++j)
      if (!(x[j] >= ps[j].min && x[j] <= ps[j].max)) return false;
  }
  return true;
}

// Runs ParameterSetFromOptions with errors returned (not printed); the message goes to *msg.
static PetscErrorCode TryFromOptions(const std::vector<ParamSpec> &ps, const char *prefix, ParameterSet *set, PetscErrorCode *code, std::string *msg)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  *code = ParameterSetFromOptions(PETSC_COMM_WORLD, ps, prefix, set);
  PetscCall(PetscPopErrorHandler());
  msg->clear();
  if (*code) {
    char *specific = NULL;
    PetscCall(PetscErrorMessage(*code, NULL, &specific));
    if (specific) *msg = specific;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode ExpectError(const std::vector<ParamSpec> &ps, const char *prefix, const std::string &what, const std::vector<std::string> &needles)
{
  ParameterSet   set;
  PetscErrorCode code;
  std::string    msg;

  PetscFunctionBeginUser;
  PetscCall(TryFromOptions(ps, prefix, &set, &code, &msg));
  bool ok = code != 0;
  for (const auto &n : needles) ok = ok && msg.find(n) != std::string::npos;
  Check(ok, what + " -> error: " + (msg.empty() ? "(none)" : msg));
  PetscFunctionReturn(0);
}

static unsigned long long Hash(const std::vector<std::vector<PetscReal>> &pts)
{
  unsigned long long h = 1469598103934665603ULL;
  for (const auto &x : pts)
    for (PetscReal v : x) {
      unsigned char b[sizeof v];
      std::memcpy(b, &v, sizeof v);
      for (unsigned char c : b) h = (h ^ c) * 1099511628211ULL;
    }
  return h;
}

static PetscErrorCode SameOnAllRanks(const std::vector<std::vector<PetscReal>> &pts, const std::string &what)
{
  unsigned long long h = Hash(pts), lo, hi;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&h, &lo, 1, MPI_UNSIGNED_LONG_LONG, MPI_MIN, PETSC_COMM_WORLD));
  PetscCallMPI(MPI_Allreduce(&h, &hi, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, PETSC_COMM_WORLD));
  Check(lo == hi, what + ": identical on every rank");
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));

  const std::vector<ParamSpec> one = {Param("load", 0.95, 1.15)};
  const std::vector<ParamSpec> two = {Param("E", 1.0, 2.0), Param("nu", 0.1, 0.3)};
  const std::vector<ParamSpec> three = {Param("a", -1.0, 1.0), Param("b", 0.0, 1e-3), Param("c", 100.0, 250.0)};

  // 1. -x_size 21 on [0.95, 1.15] (default type grid).
  {
    ParameterSet   set;
    PetscErrorCode code;
    std::string    msg;
    PetscCall(PetscOptionsSetValue(NULL, "-x_size", "21"));
    PetscCall(TryFromOptions(one, "x_", &set, &code, &msg));
    Check(code == 0 && set.points.size() == 21 && set.names == std::vector<std::string>{"load"}, "grid -x_size 21: 21 points, names");
    double err = 0;
    for (size_t i = 0; i < set.points.size(); ++i) err = std::max(err, std::fabs(set.points[i][0] - (0.95 + 0.01 * (double)i)));
    char buf[128];
    std::snprintf(buf, sizeof buf, "grid values 0.95 + 0.01 i (max error %.2e <= 1e-15)", err);
    Check(code == 0 && err <= 1e-15, buf);
    Check(code == 0 && set.points.front()[0] == 0.95 && set.points.back()[0] == 1.15, "grid endpoints exactly 0.95 and 1.15");
    PetscCall(SameOnAllRanks(set.points, "grid"));
    PetscCall(PetscOptionsClearValue(NULL, "-x_size"));
  }
  // 2. One point: the box centre; 2D grids.
  {
    auto c = GridSample(two, {1});
    Check(c.size() == 1 && c[0][0] == 1.5 && std::fabs(c[0][1] - 0.2) < 1e-16, "grid of size 1 = the box centre");
    auto g = GridSample(two, {5});
    bool ok = g.size() == 25;
    for (size_t k = 0; ok && k < 25; ++k) {
      const double e = 1.0 + 0.25 * (double)(k / 5), nu = 0.1 + 0.05 * (double)(k % 5);
      ok = std::fabs(g[k][0] - e) < 1e-15 && std::fabs(g[k][1] - nu) < 1e-15;
    }
    Check(ok, "2D grid 5 x 5: point k = (E_{k/5}, nu_{k%5}), last parameter fastest");
    auto g2 = GridSample(two, {3, 4});
    ok      = g2.size() == 12 && g2[0][0] == 1.0 && g2[0][1] == 0.1 && g2[3][0] == 1.0 && g2[3][1] == 0.3 && g2[4][0] == 1.5 && g2[4][1] == 0.1 && g2[11][0] == 2.0 && g2[11][1] == 0.3;
    Check(ok && InBox(g2, two), "grid with one count per parameter (3 x 4)");
    // The same through the options (a list).
    ParameterSet   set;
    PetscErrorCode code;
    std::string    msg;
    PetscCall(PetscOptionsSetValue(NULL, "-y_type", "grid"));
    PetscCall(PetscOptionsSetValue(NULL, "-y_size", "3,4"));
    PetscCall(TryFromOptions(two, "y_", &set, &code, &msg));
    Check(code == 0 && set.points == g2, "-y_size 3,4 == GridSample(3, 4)");
    PetscCall(PetscOptionsClearValue(NULL, "-y_type"));
    PetscCall(PetscOptionsClearValue(NULL, "-y_size"));
  }
  // 3. Latin hypercube: each of n strata of every parameter hit exactly once.
  for (PetscInt n : {1, 7, 64}) {
    auto pts = LatinHypercubeSample(three, n, 42);
    bool ok  = (PetscInt)pts.size() == n && InBox(pts, three);
    for (size_t j = 0; ok && j < three.size(); ++j) {
      std::vector<int> hits(n, 0);
      for (const auto &x : pts) {
        const double t = (x[j] - three[j].min) / (three[j].max - three[j].min);
        const long   b = std::min<long>(n - 1, (long)std::floor(t * (double)n));
        ++hits[b];
      }
      for (int h : hits) ok = ok && h == 1;
    }
    Check(ok, "LHS n = " + std::to_string(n) + ": every stratum of every parameter hit exactly once, in the box");
  }
  {
    auto a = LatinHypercubeSample(three, 20, 3), b = LatinHypercubeSample(three, 20, 3), c = LatinHypercubeSample(three, 20, 4);
    Check(a == b && a != c, "LHS: same seed equal, other seed different");
  }
  // 4. Random: determinism, seeds, box.
  {
    auto a = RandomSample(three, 50, 0), b = RandomSample(three, 50, 0), c = RandomSample(three, 50, 1);
    Check(a == b, "random: two calls with the same seed are equal");
    Check(a != c, "random: different seeds differ");
    Check(InBox(a, three) && InBox(c, three), "random: all points in the box");
    double mean = 0;
    auto   big  = RandomSample(one, 4000, 9);
    for (const auto &x : big) mean += x[0] / 4000;
    Check(std::fabs(mean - 1.05) < 0.01, "random: sample mean near the box centre");
    // Options path: -z_type random -z_size 13 -z_seed 5 == RandomSample(13, 5), same on all ranks.
    ParameterSet   set;
    PetscErrorCode code;
    std::string    msg;
    PetscCall(PetscOptionsSetValue(NULL, "-z_type", "random"));
    PetscCall(PetscOptionsSetValue(NULL, "-z_size", "13"));
    PetscCall(PetscOptionsSetValue(NULL, "-z_seed", "5"));
    PetscCall(TryFromOptions(three, "z_", &set, &code, &msg));
    Check(code == 0 && set.points == RandomSample(three, 13, 5), "-z_type random -z_size 13 -z_seed 5 == RandomSample(13, 5)");
    PetscCall(SameOnAllRanks(set.points, "random"));
    PetscCall(PetscOptionsSetValue(NULL, "-z_type", "lhs"));
    PetscCall(TryFromOptions(three, "z_", &set, &code, &msg));
    Check(code == 0 && set.points == LatinHypercubeSample(three, 13, 5), "-z_type lhs == LatinHypercubeSample(13, 5)");
    PetscCall(PetscOptionsClearValue(NULL, "-z_seed"));
    PetscCall(TryFromOptions(three, "z_", &set, &code, &msg));
    Check(code == 0 && set.points == LatinHypercubeSample(three, 13, 0), "default seed 0");
    // Option errors.
    PetscCall(PetscOptionsSetValue(NULL, "-z_type", "bogus"));
    PetscCall(ExpectError(three, "z_", "-z_type bogus", {"Unknown value 'bogus' for option -z_type"}));
    PetscCall(PetscOptionsSetValue(NULL, "-z_type", "lhs"));
    PetscCall(PetscOptionsSetValue(NULL, "-z_size", "3,4"));
    PetscCall(ExpectError(three, "z_", "-z_type lhs -z_size 3,4", {"-z_size"}));
    PetscCall(PetscOptionsSetValue(NULL, "-z_type", "grid"));
    PetscCall(ExpectError(three, "z_", "-z_type grid -z_size 3,4 for 3 parameters", {"-z_size", "3 parameters"}));
    PetscCall(PetscOptionsSetValue(NULL, "-z_size", "0"));
    PetscCall(ExpectError(three, "z_", "-z_size 0", {"-z_size"}));
    PetscCall(PetscOptionsClearValue(NULL, "-z_size"));
    PetscCall(PetscOptionsSetValue(NULL, "-z_type", "file"));
    PetscCall(ExpectError(three, "z_", "-z_type file without -z_file", {"-z_file"}));
    PetscCall(PetscOptionsClearValue(NULL, "-z_type"));
    PetscCall(PetscOptionsClearValue(NULL, "-z_size"));
  }
  // 5. Sample files (written by rank 0, read through the options).
  {
    long pid = (long)getpid();
    PetscCallMPI(MPI_Bcast(&pid, 1, MPI_LONG, 0, PETSC_COMM_WORLD));
    const std::string base = "/tmp/rbc_test_training_set_" + std::to_string(pid);
    const std::string good = base + "_good.txt", out = base + "_out.txt", bad = base + "_bad.txt", cols = base + "_cols.txt", empty = base + "_empty.txt";
    const std::string trail = base + "_trail.txt", twice = base + "_twice.txt";
    if (rank == 0) {
      std::ofstream(good) << "# E nu\n1.0, 0.1\n\n  1.5 0.2   # a comment\n2.0,0.3\n1.25\t0.15\n";
      std::ofstream(out) << "# header\n1.0 0.1\n1.5 0.35\n";
      std::ofstream(bad) << "1.0 0.1\n1.5 0.2\n\n1.2 zero.2x\n";
      std::ofstream(cols) << "1.0 0.1 7\n";
      std::ofstream(empty) << "# nothing\n\n";
      std::ofstream(trail) << "1.0\n1.05,  # a trailing comma\n";
      std::ofstream(twice) << "1.0,0.1\n1.5,,0.2\n";
    }
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    ParameterSet   set;
    PetscErrorCode code;
    std::string    msg;
    PetscCall(PetscOptionsSetValue(NULL, "-f_type", "file"));
    PetscCall(PetscOptionsSetValue(NULL, "-f_file", good.c_str()));
    PetscCall(TryFromOptions(two, "f_", &set, &code, &msg));
    const std::vector<std::vector<PetscReal>> expect = {{1.0, 0.1}, {1.5, 0.2}, {2.0, 0.3}, {1.25, 0.15}};
    Check(code == 0 && set.points == expect, "file: 4 samples (comments, blank lines, commas, tabs) read exactly" + (msg.empty() ? std::string() : ": " + msg));
    PetscCall(SameOnAllRanks(set.points, "file"));
    PetscCall(PetscOptionsSetValue(NULL, "-f_file", out.c_str()));
    PetscCall(ExpectError(two, "f_", "file with a point outside the box (line 3), the box in its shortest digits (17 before)", {out, "line 3", "'nu' = 0.35 is outside its box [0.1, 0.3]"}));
    PetscCall(PetscOptionsSetValue(NULL, "-f_file", bad.c_str()));
    PetscCall(ExpectError(two, "f_", "file with a malformed line (line 4)", {bad, "line 4", "zero.2x", "not a finite number"}));
    PetscCall(PetscOptionsSetValue(NULL, "-f_file", cols.c_str()));
    PetscCall(ExpectError(two, "f_", "file with 3 columns for 2 parameters", {cols, "line 1", "3 values", "2 parameters"}));
    PetscCall(PetscOptionsSetValue(NULL, "-f_file", empty.c_str()));
    PetscCall(ExpectError(two, "f_", "file without samples", {empty, "no samples"}));
    // an empty value beside a comma: a one-parameter file's "1.05," was read as 1.05 until 2026-12-01
    PetscCall(PetscOptionsSetValue(NULL, "-f_file", trail.c_str()));
    PetscCall(ExpectError(one, "f_", "one-parameter file with a trailing comma (line 2)", {trail, "line 2", "empty value after the last separator"}));
    PetscCall(PetscOptionsSetValue(NULL, "-f_file", twice.c_str()));
    PetscCall(ExpectError(two, "f_", "file with two commas in a row (line 2)", {twice, "line 2", "empty value before a separator"}));
    PetscCall(PetscOptionsSetValue(NULL, "-f_file", (base + "_missing.txt").c_str()));
    PetscCall(ExpectError(two, "f_", "missing file", {base + "_missing.txt", "-f_file"}));
    PetscCall(PetscOptionsClearValue(NULL, "-f_type"));
    PetscCall(PetscOptionsClearValue(NULL, "-f_file"));
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    if (rank == 0)
      for (const auto &f : {good, out, bad, cols, empty, trail, twice}) std::remove(f.c_str());
  }

  int total = 0;
  PetscCallMPI(MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, PETSC_COMM_WORLD));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_training_set: %s (%d failure%s)\n", total ? "FAILED" : "passed", total, total == 1 ? "" : "s"));
  PetscCall(PetscFinalize());
  return total ? 1 : 0;
}
