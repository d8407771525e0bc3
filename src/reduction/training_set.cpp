// src/reduction/training_set.cpp: parameter samples in the scene's box (training and test sets).
// Owns the -<prefix>type/size/seed/file options, the tensor grid, the uniform random and Latin
// hypercube generators (xoshiro256** seeded through splitmix64: the same numbers on any platform
// and compiler) and the reader of sample files (one point per line, checked against the box).
#include "rbcontact/report.hpp"
#include "rbcontact/training_set.hpp"
#include "rbcontact/options_files.hpp"
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace rbc {

namespace {

// splitmix64 (Steele, Lea, Flood 2014): expands the user's seed into the generator state.
std::uint64_t SplitMix64(std::uint64_t *x)
{
  std::uint64_t z = (*x += 0x9E3779B97F4A7C15ULL);
  z               = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z               = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// xoshiro256** 1.0 (Blackman, Vigna 2018).
class Xoshiro256 {
public:
  explicit Xoshiro256(std::uint64_t seed)
  {
    for (auto &w : s_) w = SplitMix64(&seed);
  }
  std::uint64_t Next()
  {
    const std::uint64_t r = Rotl(s_[1] * 5, 7) * 9, t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = Rotl(s_[3], 45);
    return r;
  }
  // Uniform in [0, 1): the top 53 bits (exactly representable).
  double Uniform() { return (double)(Next() >> 11) * 0x1.0p-53; }
  // Uniform integer in [0, n) without modulo bias (rejection).
  std::uint64_t Below(std::uint64_t n)
  {
    const std::uint64_t limit = UINT64_MAX - UINT64_MAX % n;
    std::uint64_t       x;
    do x = Next();
    while (x >= limit);
    return x % n;
  }

private:
  static std::uint64_t Rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t        s_[4];
};

// lo + t (hi - lo), clamped to the box (rounding must never leave it).
PetscReal Affine(const ParamSpec &p, double t)
{
  const PetscReal v = p.min + t * (p.max - p.min);
  return std::min(p.max, std::max(p.min, v));
}

std::string Names(const std::vector<ParamSpec> &params)
{
  std::string s;
  for (const auto &p : params) s += (s.empty() ? "" : ",") + p.name;
  return s.empty() ? "none" : s;
}

// The most samples a training set holds (a tensor grid, random or LHS set, or a sample file).
const size_t kMaxSamples = 10000000;

// Reads a sample file; returns an error message (empty: success).
std::string ReadSampleFile(const std::string &path, const std::string &option, const std::vector<ParamSpec> &params, std::vector<std::vector<PetscReal>> *pts)
{
  std::ifstream f(path);
  if (!f) return "Cannot open the parameter sample file '" + path + "' (" + option + "): no such file or not readable";
  std::string line;
  for (long lineno = 1; std::getline(f, line); ++lineno) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    // a comma or semicolon separates values: an empty field beside one ("1.0," in a one-parameter file read as 1.0, or a
    // value lost in "0.9,,0.1") is refused, as an empty entry of a list option is
    if (line.find_first_of(",;") != std::string::npos) {
      size_t start = 0;
      for (size_t k = 0; k <= line.size(); ++k) {
        if (k < line.size() && line[k] != ',' && line[k] != ';') continue;
        if (line.find_first_not_of(" \t\r", start) >= k) {
          std::ostringstream m;
          m << "Parameter sample file '" << path << "' line " << lineno << ": an empty value " << (k == line.size() ? "after the last" : "before a") << " separator (a comma too many?)";
          return m.str();
        }
        start = k + 1;
      }
    }
    for (char &c : line)
      if (c == ',' || c == ';' || c == '\t' || c == '\r') c = ' ';
    std::istringstream     ss(line);
    std::string            tok;
    std::vector<PetscReal> x;
    while (ss >> tok) {
      errno         = 0;
      char  *end    = nullptr;
      double v      = std::strtod(tok.c_str(), &end);
      if (end == tok.c_str() || *end != 0 || errno == ERANGE || !std::isfinite(v)) {
        std::ostringstream m;
        m << "Parameter sample file '" << path << "' line " << lineno << ": '" << tok << "' is not a finite number";
        return m.str();
      }
      x.push_back(v);
    }
    if (x.empty()) continue;
    if (x.size() != params.size()) {
      std::ostringstream m;
      m << "Parameter sample file '" << path << "' line " << lineno << " has " << x.size() << " values; the scene has " << params.size() << " parameters (" << Names(params) << ")";
      return m.str();
    }
    for (size_t j = 0; j < x.size(); ++j)
      if (x[j] < params[j].min || x[j] > params[j].max) {
        // the shortest digits that tell the value from the box's ends (the box was printed with 17 digits)
        return "Parameter sample file '" + path + "' line " + std::to_string(lineno) + ": " + OutOfBoxMessage(params[j], x[j]);
      }
    if (pts->size() == kMaxSamples) // (an 80 MB file took 3.6 GB and a minute before this cap)
      return "Parameter sample file '" + path + "' line " + std::to_string(lineno) + ": more than " + std::to_string(kMaxSamples) + " samples (the cap of every training set)";
    pts->push_back(x);
  }
  if (f.bad()) return "Error reading the parameter sample file '" + path + "'";
  if (pts->empty()) return "Parameter sample file '" + path + "' holds no samples (only comments or blank lines)";
  return std::string();
}


} // namespace

std::vector<std::vector<PetscReal>> GridSample(const std::vector<ParamSpec> &params, const std::vector<PetscInt> &counts)
{
  const size_t          np = params.size();
  std::vector<PetscInt> n(np, 1);
  for (size_t j = 0; j < np; ++j) n[j] = std::max<PetscInt>(1, counts.empty() ? 1 : (counts.size() == 1 ? counts[0] : counts[j]));
  size_t total = 1;
  for (PetscInt c : n) total *= (size_t)c;
  std::vector<std::vector<PetscReal>> pts(total, std::vector<PetscReal>(np));
  // Axis values: exact endpoints, one count -> the box centre.
  std::vector<std::vector<PetscReal>> axis(np);
  for (size_t j = 0; j < np; ++j) {
    const ParamSpec &p = params[j];
    for (PetscInt i = 0; i < n[j]; ++i) {
      PetscReal v;
      if (n[j] == 1) v = 0.5 * (p.min + p.max);
      else if (i == 0) v = p.min;
      else if (i == n[j] - 1) v = p.max;
      else v = p.min + (PetscReal)i * (p.max - p.min) / (PetscReal)(n[j] - 1);
      axis[j].push_back(v);
    }
  }
  // Last parameter fastest.
  for (size_t k = 0; k < total; ++k) {
    size_t r = k;
    for (size_t j = np; j-- > 0;) {
      pts[k][j] = axis[j][r % (size_t)n[j]];
      r /= (size_t)n[j];
    }
  }
  return pts;
}

std::vector<std::vector<PetscReal>> RandomSample(const std::vector<ParamSpec> &params, PetscInt n, unsigned long long seed)
{
  Xoshiro256                          rng(seed);
  std::vector<std::vector<PetscReal>> pts(std::max<PetscInt>(0, n), std::vector<PetscReal>(params.size()));
  for (auto &x : pts)
    for (size_t j = 0; j < params.size(); ++j) x[j] = Affine(params[j], rng.Uniform());
  return pts;
}

std::vector<std::vector<PetscReal>> LatinHypercubeSample(const std::vector<ParamSpec> &params, PetscInt n, unsigned long long seed)
{
  Xoshiro256                          rng(seed);
  const size_t                        m = (size_t)std::max<PetscInt>(0, n);
  std::vector<std::vector<PetscReal>> pts(m, std::vector<PetscReal>(params.size()));
  std::vector<size_t>                 perm(m);
  for (size_t j = 0; j < params.size(); ++j) {
    // Fisher-Yates with our generator (std::shuffle is implementation-defined).
    for (size_t i = 0; i < m; ++i) perm[i] = i;
    for (size_t i = m; i > 1; --i) std::swap(perm[i - 1], perm[rng.Below(i)]);
    for (size_t i = 0; i < m; ++i) {
      // A uniform point inside stratum perm[i] of n equal strata.
      const double t = ((double)perm[i] + rng.Uniform()) / (double)m;
      // Rounding of k + u (u close to 1) must not move the point to stratum k + 1.
      const double top = (double)(perm[i] + 1) / (double)m;
      pts[i][j]        = Affine(params[j], std::min(t, std::nextafter(top, 0.0)));
    }
  }
  return pts;
}

PetscErrorCode ParameterSetFromOptions(MPI_Comm comm, const std::vector<ParamSpec> &params, const char *prefix, ParameterSet *set, const char *defType, PetscInt defSize, PetscInt defSeed)
{
  const std::string pre = prefix ? prefix : "";
  const std::string optType = "-" + pre + "type", optSize = "-" + pre + "size", optSeed = "-" + pre + "seed", optFile = "-" + pre + "file";
  char              typeBuf[64] = "", fileBuf[PETSC_MAX_PATH_LEN] = "";
  PetscInt          sizes[65], nsizes = 65, seed = defSeed; // (one more than taken: PETSc drops values beyond the buffer silently)
  std::fill(sizes, sizes + 65, defSize); // (-help printed an uninitialised default, different every run)
  PetscBool         flgSize = PETSC_FALSE, flgFile = PETSC_FALSE;
  std::string       type, file;
  PetscMPIInt       rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(PetscStrncpy(typeBuf, defType, sizeof typeBuf));
  // (a trailing -test_seed kept the default and cancelled an options file's value, exit 0; audit of 2026-12-01)
  PetscCall(CheckValuesGiven(comm, prefix, {"type", "seed", "file"}));
  PetscOptionsBegin(comm, prefix, "Parameter samples", "rbcontact");
  PetscCall(PetscOptionsString("-type", "Sample type: grid, random, lhs or file", "ParameterSetFromOptions", typeBuf, typeBuf, sizeof typeBuf, NULL));
  type = typeBuf;
  PetscCall(PetscOptionsIntArray("-size", "grid: points per parameter (one count or one per parameter); random/lhs: number of samples", "ParameterSetFromOptions", sizes, &nsizes, &flgSize));
  PetscCall(PetscOptionsInt("-seed", "Seed of random and lhs samples", "ParameterSetFromOptions", seed, &seed, NULL));
  PetscCall(PetscOptionsString("-file", "Sample file (type file): one point per line", "ParameterSetFromOptions", fileBuf, fileBuf, sizeof fileBuf, &flgFile));
  file = fileBuf;
  PetscOptionsEnd();

  PetscCheck(type == "grid" || type == "random" || type == "lhs" || type == "file", comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "Unknown value '%s' for option %s (grid, random, lhs or file%s)", type.c_str(), optType.c_str(), pre == "train_" ? "; the offline stage also takes greedy" : "");
  PetscCheck(seed >= 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s %" PetscInt_FMT " must be >= 0", optSeed.c_str(), seed);
  // a file given with another type was ignored without a word (the user meant those points)
  PetscCheck(!flgFile || type == "file", comm, PETSC_ERR_USER_INPUT, "%s %s is read only with %s file (here %s %s)", optFile.c_str(), file.c_str(), optType.c_str(), optType.c_str(), type.c_str());
  PetscCheck(!flgSize || nsizes <= 64, comm, PETSC_ERR_ARG_SIZ, "%s takes at most 64 values, more were given", optSize.c_str());
  {
    PetscBool named = PETSC_FALSE; // PETSc reports a list option without a value as not set: the default ran silently
    PetscCall(PetscOptionsHasName(NULL, prefix, "-size", &named));
    PetscCheck(!named || (flgSize && nsizes >= 1), comm, PETSC_ERR_USER_INPUT, "option %s is given without a value", optSize.c_str());
  }
  std::vector<PetscInt> counts;
  if (flgSize) counts.assign(sizes, sizes + nsizes);
  for (PetscInt c : counts) PetscCheck(c >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s: %" PetscInt_FMT " samples; every count must be >= 1", optSize.c_str(), c);

  set->names.clear();
  set->type = type;
  set->seed = seed;
  for (const auto &p : params) set->names.push_back(p.name);
  set->points.clear();
  if (type == "grid") {
    if (counts.empty()) counts.assign(1, defSize);
    PetscCheck(counts.size() == 1 || counts.size() == params.size(), comm, PETSC_ERR_USER_INPUT, "%s has %zu counts; give one count, or one per parameter (the scene has %zu parameters: %s)", optSize.c_str(), counts.size(), params.size(), Names(params).c_str());
    double total = 1;
    for (size_t j = 0; j < params.size(); ++j) total *= (double)(counts.size() == 1 ? counts[0] : counts[j]);
    PetscCheck(total <= 1e7, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s: the tensor grid would have %.0f points (more than 10000000)", optSize.c_str(), total);
    set->points = GridSample(params, counts);
  } else if (type == "random" || type == "lhs") {
    if (counts.empty()) counts.assign(1, defSize);
    PetscCheck(counts.size() == 1, comm, PETSC_ERR_USER_INPUT, "%s: %s %s takes one number of samples (a list of counts is for %s grid)", optSize.c_str(), optType.c_str(), type.c_str(), optType.c_str());
    PetscCheck(counts[0] <= 10000000, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s %" PetscInt_FMT ": more than 10000000 samples", optSize.c_str(), counts[0]);
    set->points = type == "random" ? RandomSample(params, counts[0], (unsigned long long)seed) : LatinHypercubeSample(params, counts[0], (unsigned long long)seed);
  } else {
    PetscCheck(flgFile && !file.empty(), comm, PETSC_ERR_USER_INPUT, "%s file needs %s <path>", optType.c_str(), optFile.c_str());
    // Rank 0 reads and checks, then broadcasts the status and the points.
    std::string                         err;
    std::vector<std::vector<PetscReal>> pts;
    if (rank == 0) err = ReadSampleFile(file, optFile, params, &pts);
    PetscCall(BcastString(comm, &err));
    PetscCheck(err.empty(), comm, PETSC_ERR_FILE_READ, "%s", err.c_str());
    unsigned long long     n = pts.size();
    std::vector<PetscReal> flat;
    PetscCallMPI(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm));
    if (rank == 0)
      for (const auto &x : pts) flat.insert(flat.end(), x.begin(), x.end());
    flat.resize(n * params.size());
    if (!flat.empty()) PetscCallMPI(MPI_Bcast(flat.data(), (PetscMPIInt)flat.size(), MPIU_REAL, 0, comm));
    pts.assign(n, std::vector<PetscReal>(params.size()));
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < params.size(); ++j) pts[i][j] = flat[i * params.size() + j];
    set->points = std::move(pts);
  }
  // Every point in the box (the generators clamp; this guards against a box with min > max).
  for (size_t i = 0; i < set->points.size(); ++i)
    for (size_t j = 0; j < params.size(); ++j) {
      const PetscReal v = set->points[i][j];
      PetscCheck(v >= params[j].min && v <= params[j].max, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s %s: sample %zu has parameter '%s' = %g outside its box [%g, %g]", optType.c_str(), type.c_str(), i, params[j].name.c_str(), (double)v, (double)params[j].min, (double)params[j].max);
    }
  PetscFunctionReturn(0);
}

} // namespace rbc
