// bench/bench_online_ab.cpp: micro benchmark (not a test) comparing two configurations of one ROM's online solve
// in one process, in alternating blocks, so that the VM's slow and fast phases (25-40 % on the 2-vCPU development VM,
// lasting seconds to minutes) fall on both alike. Each configuration is a comma-separated list of option=value
// (rom_gemm=blas,rom_N=100: -rom_* options in the model's own database, which ReducedModel::SetFromOptions reads;
// PETSc would take a value that starts with a dash for an option of its own). Prints the medians of both, the median
// of the per-pair ratios b / a and its range over the pairs (docs/online.md "The fused points' sum").
// -mu_random n: the solves cycle through n uniform random parameters of the box (-mu_seed s, default 1), the same
// sequence for both, instead of repeating one -mu: a sweep's distinct parameters, where nothing of the previous
// solve's reduced QP can be reused (docs/online.md "A factored once").
// Usage: build/bin/rbc_bench_online_ab -rom rom.h5 [-mu 1.1,0.045 | -mu_random 50] -a rom_gemm=blas -b rom_gemm=auto
//        [-pairs 30] [-block 20]
#include <petsctime.h>
#include <slepcsys.h>
#include <algorithm>
#include <random>
#include <sstream>
#include <string>
#include <vector>
#include "rbcontact/reduced_model.hpp"

namespace {
struct Variant {
  std::string         options;
  rbc::ReducedModel   model;
  std::vector<double> times;
};

// option=value pairs as -option value into the model's own database
PetscErrorCode Configure(const std::string &rom, Variant *v)
{
  std::istringstream in(v->options);
  std::string        w, rest;
  PetscOptions       db;
  PetscFunctionBeginUser;
  while (std::getline(in, w, ',')) {
    if (w.empty()) continue;
    const size_t eq = w.find('=');
    PetscCheck(eq != std::string::npos && eq > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "'%s' in \"%s\" is not option=value", w.c_str(), v->options.c_str());
    const std::string key = w.substr(0, eq), val = w.substr(eq + 1);
    rest += "-" + key + " " + val + " ";
  }
  PetscCall(PetscOptionsCreate(&db));
  PetscCall(PetscOptionsInsertString(db, rest.c_str()));
  PetscCall(PetscOptionsPush(db));
  PetscCall(v->model.Open(rom));
  PetscCall(v->model.SetFromOptions());
  PetscCall(PetscOptionsPop());
  PetscCall(PetscOptionsDestroy(&db));
  PetscFunctionReturn(0);
}

double Median(std::vector<double> x)
{
  std::sort(x.begin(), x.end());
  return x.empty() ? 0.0 : x.size() % 2 ? x[x.size() / 2] : 0.5 * (x[x.size() / 2 - 1] + x[x.size() / 2]);
}
} // namespace

int main(int argc, char **argv)
{
  char      rom[PETSC_MAX_PATH_LEN] = "", a[512] = "", b[512] = "";
  PetscReal mu[9]; // (one more than taken: PETSc drops values beyond the buffer silently)
  PetscInt  nmu = 9, pairs = 30, block = 20, nrand = 0, seed = 1;
  PetscBool set = PETSC_FALSE, muSet = PETSC_FALSE;

  PetscCall(SlepcInitialize(&argc, &argv, NULL, "rbc_bench_online_ab -rom rom.h5 -a \"options\" -b \"options\"\n"));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-rom", rom, sizeof rom, &set));
  PetscCheck(set && rom[0], PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "give the ROM file with -rom <file.h5>");
  PetscCall(PetscOptionsGetString(NULL, NULL, "-a", a, sizeof a, NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-b", b, sizeof b, NULL));
  PetscCall(PetscOptionsGetRealArray(NULL, NULL, "-mu", mu, &nmu, &muSet));
  PetscCheck(!muSet || nmu <= 8, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "-mu takes at most 8 values, more were given");
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-pairs", &pairs, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-block", &block, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-mu_random", &nrand, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-mu_seed", &seed, NULL));
  PetscCheck(nrand >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-mu_random %" PetscInt_FMT " must be >= 0", nrand);
  PetscCheck(!(nrand && muSet), PETSC_COMM_SELF, PETSC_ERR_ARG_INCOMP, "give -mu or -mu_random, not both");
  PetscCheck(pairs >= 1 && block >= 1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-pairs %" PetscInt_FMT " and -block %" PetscInt_FMT " must be >= 1", pairs, block);

  std::vector<Variant> v(2);
  v[0].options = a;
  v[1].options = b;
  for (auto &x : v) PetscCall(Configure(rom, &x));
  std::vector<PetscReal> m;
  if (muSet) m.assign(mu, mu + nmu);
  else
    for (const auto &p : v[0].model.par.params) m.push_back(p.def);
  PetscCall(v[0].model.par.CheckBox(PETSC_COMM_SELF, m));
  std::vector<std::vector<PetscReal>> mus(1, m);
  if (nrand) {
    std::mt19937 gen((unsigned)seed);
    mus.assign(nrand, m);
    for (auto &x : mus)
      for (size_t i = 0; i < x.size(); ++i) x[i] = std::uniform_real_distribution<double>(v[0].model.par.params[i].min, v[0].model.par.params[i].max)(gen);
  }

  rbc::ReducedSolution sol;
  std::vector<double>  ratios;
  for (PetscInt k = -1; k < pairs; ++k) { // k = -1: warm-up of both
    double med[2];
    for (int i = 0; i < 2; ++i) {
      std::vector<double> t;
      for (PetscInt j = 0; j < block; ++j) {
        PetscLogDouble t0, t1;
        PetscCall(PetscTime(&t0));
        PetscCall(v[i].model.Solve(mus[(size_t)((k + 1) * block + j) % mus.size()], &sol));
        PetscCall(PetscTime(&t1));
        PetscCheck(sol.converged, PETSC_COMM_SELF, PETSC_ERR_NOT_CONVERGED, "variant %c: %s", "ab"[i], sol.message.c_str());
        t.push_back(t1 - t0);
      }
      med[i] = Median(t);
      if (k >= 0) v[i].times.insert(v[i].times.end(), t.begin(), t.end());
    }
    if (k >= 0) ratios.push_back(med[1] / med[0]);
  }
  std::sort(ratios.begin(), ratios.end());
  const std::string which = nrand ? std::to_string(nrand) + " random parameters, seed " + std::to_string(seed) : std::string("one parameter");
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "%s: %" PetscInt_FMT " pairs of %" PetscInt_FMT " solves (%s)\n| variant | options | median |\n|---|---|---|\n", rom, pairs, block, which.c_str()));
  for (int i = 0; i < 2; ++i) PetscCall(PetscPrintf(PETSC_COMM_SELF, "| %c | %s | %.4g ms |\n", "ab"[i], v[i].options.c_str(), 1e3 * Median(v[i].times)));
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "b / a: median of the pairs' ratios %.3f (range %.3f-%.3f)\n", Median(ratios), ratios.front(), ratios.back()));
  PetscCall(SlepcFinalize());
  return 0;
}
