// src/offline/validation.cpp: the ROM against the FOM on a test set (include/rbcontact/validation.hpp).
// For each test parameter: the FOM solve (timed), the ROM solve (median of -validate_repeat timed solves
// after a warm-up; operators + EIM + Kacanov + QP, no I/O; timed again in -validate_repeat rounds over the test
// parameters, a sweep's distinct parameters) and the ROM with exact reduced contact terms
// (no EIM: the full contact patch, same quadrature), and their errors: u in the energy norm of A(mu),
// lambda in the l2 norm weighted by the slave mass (int psi_i), the resultant contact force.
// Sweep: the same for a series of truncations (N, R, Mk, Mg) of the ROM, a table of online median time
// against max error (CSV and JSON); share/plot_speed_error.py draws it. The FOM is distributed over the
// ranks, the ROM runs redundantly on every rank (identical data, identical answers); its timed solves run on rank 0
// while the other ranks wait (-validate_time_all_ranks: on every rank at once).
#include "rbcontact/validation.hpp"
#include "rbcontact/options_files.hpp"
#include "rbcontact/greedy_indicator.hpp"
#include "rbcontact/rom_fields.hpp"
#include "rbcontact/kacanov.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/fork_join.hpp"
#include "rbcontact/rom_file.hpp"
#include "rbcontact/snapshot_file.hpp"
#include "rbcontact/snapshot_contact.hpp"
#include "rbcontact/mesh.hpp"
#include <petscblaslapack.h>
#include <chrono>
#include <thread>
#include <algorithm>
#include <numeric>
#include <cmath>
#include <filesystem>
#include <cstring>
#include <iomanip>
#include <sstream>

namespace rbc {

PetscErrorCode ValidationSettingsFromOptions(MPI_Comm comm, const std::string &reportPath, ValidationSettings *s)
{
  PetscInt  nf = 33; // (one more than taken, here and below: PETSc drops values beyond the buffer silently)
  PetscReal fbuf[33] = {0.2, 0.4, 0.6, 0.8, 1.0}; // (-help prints its first value: the default's)
  PetscBool fset = PETSC_FALSE, sweep = s->sweep ? PETSC_TRUE : PETSC_FALSE, residual = s->residual ? PETSC_TRUE : PETSC_FALSE;
  char      sweepOut[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  {
    std::string stem = reportPath.empty() ? "validate.json" : reportPath;
    if (stem.size() > 5 && stem.compare(stem.size() - 5, 5, ".json") == 0) stem.resize(stem.size() - 5);
    PetscCall(PetscStrncpy(sweepOut, s->sweepOutput.empty() ? (stem + "_sweep").c_str() : s->sweepOutput.c_str(), sizeof sweepOut));
  }
  PetscCall(CheckValuesGiven(comm, {"-validate_repeat", "-validate_threads", "-validate_sweep_R", "-validate_sweep_output", "-validate_sweep_fractions", "-test_snapshots"})); // (the defaults, without a word)
  PetscOptionsBegin(comm, NULL, "rbcontact validate: the ROM against the FOM on a test set", "rbcontact");
  PetscCall(PetscOptionsInt("-validate_repeat", "online solves per test parameter (the median is reported)", "", s->repeat, &s->repeat, NULL));
  {
    PetscBool all = s->timeAllRanks ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(PetscOptionsBool("-validate_time_all_ranks", "time the online solves on every rank at once (default: on rank 0 while the others wait)", "", all, &all, NULL));
    s->timeAllRanks = all;
  }
  PetscCall(PetscOptionsBool("-validate_sweep", "also the speed-against-error sweep over truncated sizes", "", sweep, &sweep, NULL));
  PetscCall(PetscOptionsRealArray("-validate_sweep_fractions", "fractions of N, R (and the EIM sizes) of the sweep's rows", "", fbuf, &nf, &fset));
  PetscCheck(!fset || nf <= 32, comm, PETSC_ERR_ARG_SIZ, "-validate_sweep_fractions takes at most 32 values, more were given");
  PetscCall(PetscOptionsString("-validate_sweep_output", "stem of the sweep's .json and .csv (default: the report's, + _sweep)", "", sweepOut, sweepOut, sizeof sweepOut, NULL));
  {
    PetscInt  rbuf[257] = {0}, nr = 257; // (initialized: -help prints the first value)
    PetscBool rset = PETSC_FALSE;
    PetscCall(PetscOptionsIntArray("-validate_sweep_R", "also the errors with these numbers of dual vectors (all POD modes; untimed)", "", rbuf, &nr, &rset));
    PetscCheck(!rset || nr <= 256, comm, PETSC_ERR_ARG_SIZ, "-validate_sweep_R takes at most 256 values, more were given");
    if (rset) s->rValues.assign(rbuf, rbuf + nr);
  }
  {
    PetscInt  tbuf[65] = {1}, ntb = 65;
    PetscBool tset = PETSC_FALSE;
    PetscCall(PetscOptionsIntArray("-validate_threads", "also time the online solves with these numbers of threads (-rom_threads; report online_time_s.by_threads)", "", tbuf, &ntb, &tset));
    PetscCheck(!tset || ntb <= 64, comm, PETSC_ERR_ARG_SIZ, "-validate_threads takes at most 64 values, more were given");
    if (tset) s->threadValues.assign(tbuf, tbuf + ntb);
  }
  PetscCall(PetscOptionsBool("-validate_residual", "also the residual of each reduced solution on the mesh (the greedy indicator) and its effectivity against the energy error", "", residual, &residual, NULL));
  {
    char      path[PETSC_MAX_PATH_LEN] = "";
    PetscBool tset                     = PETSC_FALSE;
    PetscCall(PetscOptionsString("-test_snapshots", "the FOM solutions of the test set from this snapshot file (written by offline -offline_stop snapshots; its parameters are the test set)", "", path, path, sizeof path, &tset));
    if (tset) s->testSnapshots = path;
  }
  PetscOptionsEnd();
  s->residual = residual;
  PetscCheck(s->repeat >= 1 && s->repeat <= 1000000, comm, PETSC_ERR_ARG_OUTOFRANGE, "-validate_repeat %" PetscInt_FMT " out of range [1, 1e6]", s->repeat);
  if (fset) s->fractions.assign(fbuf, fbuf + nf);
  for (PetscReal f : s->fractions) PetscCheck(f > 0 && f <= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-validate_sweep_fractions: %g is not in (0, 1]", (double)f);
  for (PetscInt t : s->threadValues) PetscCheck(t >= 1 && t <= 256, comm, PETSC_ERR_ARG_OUTOFRANGE, "-validate_threads: %" PetscInt_FMT " threads is not in [1, 256]", t);
  for (PetscInt r : s->rValues) PetscCheck(r >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-validate_sweep_R: %" PetscInt_FMT " dual vectors (at least 1)", r);
  s->sweep       = sweep;
  s->sweepOutput = sweepOut;
  if (!s->sweep) { // the sweep's own options without the sweep: nothing read them (no warning before)
    for (const char *o : {"-validate_sweep_fractions", "-validate_sweep_output", "-validate_sweep_R"}) {
      PetscBool has = PETSC_FALSE;
      PetscCall(PetscOptionsHasName(NULL, NULL, o, &has));
      if (has) PetscCall(PetscPrintf(comm, "rbcontact validate: warning: %s has no effect without -validate_sweep (the speed-against-error sweep)\n", o));
    }
  }
  if (s->sweep) PetscCall(CheckOutputPath(comm, s->sweepOutput + ".json", "-validate_sweep_output"));
  if (s->sweep) PetscCall(CheckOutputPath(comm, s->sweepOutput + ".csv", "-validate_sweep_output (.csv)")); // (a FIFO was replaced, a directory failed after every FOM solve)
  PetscFunctionReturn(0);
}

static PetscLogEvent VAL_FOM = 0, VAL_ROM = 0;
// The poll of the ranks that wait while rank 0 times (microseconds): each wake-up takes a core from rank 0's threads
// for a moment (-validate_threads), so rarely; the wait ends at most this late, once per parameter and timing
constexpr int kWaitPollUs = 2000;

namespace {
// The FOM test solutions of -test_snapshots (a snapshot file of offline -offline_stop snapshots, every one solved),
// checked against the scene as configured now and against the test set (its points, to 1e-14).
PetscErrorCode ReadTestSnapshots(MPI_Comm comm, const std::string &path, const char *opt, const SceneSpec &scene, ElasticFOM &fom, const CanonicalOrder &order, const ContactMap &cmap, const ParameterSet &test, std::vector<Snapshot> *snaps)
{
  SnapshotHeader h;
  PetscFunctionBeginUser;
  PetscCall(SnapshotFile::ReadHeader(path, &h));
  const char *file = path.c_str();
  PetscCheck(h.sceneHash == Fnv1a(SceneFingerprint(scene, fom.map)), comm, PETSC_ERR_USER_INPUT, "%s %s was solved for another configuration of the scene (file: scene '%s'; now '%s'): the options must be those of the ROM", opt, file, h.scene.c_str(), scene.name.c_str());
  PetscCheck(h.ndofs == order.NumDofs() && h.nmult == cmap.NumMultipliers(), comm, PETSC_ERR_USER_INPUT, "%s %s has %" PetscInt_FMT " dofs and %" PetscInt_FMT " multipliers, the mesh now %" PetscInt_FMT " and %" PetscInt_FMT, opt, file, h.ndofs, h.nmult, order.NumDofs(), cmap.NumMultipliers());
  bool same = h.trainingPoints.size() == test.points.size();
  for (size_t j = 0; same && j < test.points.size(); ++j) {
    same = h.trainingPoints[j].size() == test.points[j].size();
    for (size_t i = 0; same && i < test.points[j].size(); ++i) same = std::abs(h.trainingPoints[j][i] - test.points[j][i]) <= 1e-14 * std::max<PetscReal>(1, std::abs(test.points[j][i]));
  }
  PetscCheck(same, comm, PETSC_ERR_USER_INPUT, "%s %s: its parameters (%zu) are not the test set (%zu)", opt, file, h.trainingPoints.size(), test.points.size());
  PetscCall(SnapshotFile::ReadAll(path, snaps));
  { // a greedy training's file solves only its picks among the candidates: "finish it" was advice its restart refuses
    const std::string &o = h.optionsText, g = "-train_type greedy";
    const size_t       k = o.find(g);
    const bool greedy    = k != std::string::npos && (k + g.size() == o.size() || o[k + g.size()] == ' ');
    PetscCheck(!greedy || snaps->size() == test.points.size(), comm, PETSC_ERR_USER_INPUT, "%s %s was written by a greedy training (-train_type greedy): it holds the %zu points the greedy solved among its %zu candidates, not a test set. Write a test set with offline -offline_stop snapshots -train_type random -train_size <n> -snapshots <test.h5> (the scene's options as for the ROM), or leave -test_snapshots out (validate solves the FOM on the -test_* set)", opt, file, snaps->size(), test.points.size());
  }
  PetscCheck(snaps->size() == test.points.size(), comm, PETSC_ERR_USER_INPUT, "%s %s holds %zu of its %zu solutions: finish it with offline -offline_stop snapshots -snapshots_restart -snapshots %s (and the options that wrote it)", opt, file, snaps->size(), test.points.size(), file);
  PetscFunctionReturn(0);
}

// A stored FOM solution as validate uses one: fom.u set from it (fom at its mu), the contact system assembled at that
// u (sys), its multipliers in sys's layout (lambda, created here).
PetscErrorCode StoredSolution(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const Snapshot &snap, ContactSystem *sys, Vec *lambda)
{
  PetscFunctionBeginUser;
  PetscCall(AssembleAtStoredSolution(fom, cmap, order, snap, sys));
  PetscCall(VecDuplicate(sys->weight, lambda));
  PetscCall(CanonicalToMultipliers(order, snap.lambda, *lambda));
  PetscFunctionReturn(0);
}

// Effectivities (estimate / error, one per parameter; not empty) and their summary under j: effectivity,
// min_effectivity, max_effectivity, share_above_1, share_within_20 (the shares of >= 1, and of [1, 20])
void EffectivityStats(const std::vector<double> &eff, JsonValue *j)
{
  (*j)["effectivity"]     = eff;
  (*j)["min_effectivity"] = *std::min_element(eff.begin(), eff.end());
  (*j)["max_effectivity"] = *std::max_element(eff.begin(), eff.end());
  (*j)["share_above_1"]   = (double)std::count_if(eff.begin(), eff.end(), [](double x) { return x >= 1; }) / eff.size();
  (*j)["share_within_20"] = (double)std::count_if(eff.begin(), eff.end(), [](double x) { return x >= 1 && x <= 20; }) / eff.size();
}

struct Errors {
  std::vector<double> u, lambda, force;
  std::vector<double> forceOnline; // the online resultant (ReducedSolution::force, no mesh); empty with the EIM
  std::vector<double> pmaxOnline, halfwidthOnline, radiusOnline; // the online max pressure, half-width (2D), radius (3D) (surface_outputs.hpp)
  std::vector<double> outOfRange; // contact projections at the edge of the stored contact patch, per parameter
  std::vector<double> estU, estLambda, estForce; // the online error estimates (ReducedSolution::estimate), when available
  std::vector<double> rawU, rawLambda, rawForce; // and their enriched-space changes before the calibration
  PetscInt            failed = 0;
  std::string         firstFailure;
  void Fill(JsonValue *j) const
  {
    auto mx   = [](const std::vector<double> &v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); };
    auto mean = [](const std::vector<double> &v) {
      double s = 0;
      for (double x : v) s += x;
      return v.empty() ? 0.0 : s / v.size();
    };
    (*j)["n"]                   = (long long)u.size();
    (*j)["max_rel_err_u"]       = mx(u);
    (*j)["mean_rel_err_u"]      = mean(u);
    (*j)["max_rel_err_lambda"]  = mx(lambda);
    (*j)["mean_rel_err_lambda"] = mean(lambda);
    (*j)["max_rel_err_force"]   = mx(force);
    (*j)["rel_err_u"]           = u;
    (*j)["rel_err_lambda"]      = lambda;
    (*j)["rel_err_force"]       = force;
    // the force computed online from the reduced solution (docs/online.md, "Outputs of interest"); null with the EIM
    if (!forceOnline.empty() && forceOnline.size() == u.size()) {
      (*j)["max_rel_err_force_online"] = mx(forceOnline);
      (*j)["rel_err_force_online"]     = forceOnline;
    } else {
      (*j)["max_rel_err_force_online"] = JsonValue();
      (*j)["rel_err_force_online"]     = JsonValue();
    }
    auto online = [&](const char *key, const std::vector<double> &v) {
      if (!v.empty() && v.size() == u.size()) {
        (*j)[std::string("max_rel_err_") + key + "_online"] = mx(v);
        (*j)[std::string("rel_err_") + key + "_online"]     = v;
      } else (*j)[std::string("max_rel_err_") + key + "_online"] = JsonValue();
    };
    online("max_pressure", pmaxOnline);
    online("halfwidth", halfwidthOnline);
    online("contact_radius", radiusOnline);
    (*j)["out_of_range"]        = outOfRange; // > 0: the patch kept offline (-eim_patch_rings) was too small there
    (*j)["max_out_of_range"]    = mx(outOfRange);
    (*j)["failed"]              = (long long)failed;
    if (failed) (*j)["first_failure"] = firstFailure;
  }
};

// One test parameter's FOM solution.
struct FomSolution {
  std::vector<PetscReal> mu;
  Vec                    u = nullptr, lambda = nullptr;
  PetscReal              energyNorm = 0, lambdaNorm = 0, force[3] = {0, 0, 0}, maxPressure = 0, halfwidth = 0;
};

double Median(std::vector<double> v)
{
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
} // namespace

// Rank 0's n values to every rank, the others waiting asleep, not spinning in MPI (a core for -rom_threads).
static PetscErrorCode BcastAsleep(MPI_Comm comm, double *buf, int n)
{
  MPI_Request req;
  int         done = 0;
  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Ibcast(buf, n, MPI_DOUBLE, 0, comm, &req));
  for (;;) {
    PetscCallMPI(MPI_Test(&req, &done, MPI_STATUS_IGNORE));
    if (done) break;
    std::this_thread::sleep_for(std::chrono::microseconds(kWaitPollUs));
  }
  PetscFunctionReturn(0);
}

// The CPUs of this node's ranks (the union of their affinity masks; collective on comm). Rank 0's threads may use the
// cores of the ranks that wait asleep while it times: mpirun binds each rank to one core by default, and threads
// started inside that binding would share the one core (docs/online.md "Threads").
static PetscErrorCode NodeCpus(MPI_Comm comm, std::vector<int> *cpus)
{
  const int                  nb = 1024;
  std::vector<unsigned char> mine(nb, 0), all(nb, 0);
  MPI_Comm                   node;
  PetscFunctionBeginUser;
  for (int c : ForkJoin::CallerCpus())
    if (c < nb) mine[c] = 1;
  PetscCallMPI(MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node));
  PetscCallMPI(MPI_Allreduce(mine.data(), all.data(), nb, MPI_UNSIGNED_CHAR, MPI_MAX, node));
  PetscCallMPI(MPI_Comm_free(&node));
  cpus->clear();
  for (int c = 0; c < nb; ++c)
    if (all[c]) cpus->push_back(c);
  PetscFunctionReturn(0);
}

// ||e||_A(mu)^2 = sum_q thetaA_q(mu) e'A_q e (the affine terms: no copy of A(mu) per test parameter).
static PetscErrorCode EnergyNorm2(const AffineDecomposition &aff, const std::vector<PetscReal> &mu, Vec e, Vec work, PetscReal *n2)
{
  PetscFunctionBeginUser;
  const std::vector<PetscReal> th = aff.ThetaA(mu);
  *n2                             = 0;
  for (size_t q = 0; q < aff.Aq.size(); ++q) {
    PetscScalar d;
    PetscCall(MatMult(aff.Aq[q], e, work));
    PetscCall(VecDot(e, work, &d));
    *n2 += th[q] * PetscRealPart(d);
  }
  PetscFunctionReturn(0);
}

// The best approximation of F.u in the span of the model's primal basis V, in the energy norm of A(F.mu) (the norm of
// the reported u error): c = A^{-1} r with r = V'A u, A^ = V'A V (the reduced affine terms), and ||u - V c||_A
// relative to ||u||_A. What no reduced solve in this basis can beat: the u error of the ROM against it tells the
// basis from the reduced solve (contact terms, dual basis, stability).
static PetscErrorCode BestApproximation(const ReducedModel &model, const RomBases &bases, const CanonicalOrder &order, const AffineDecomposition &aff, const FomSolution &F, Vec work, Vec work2, double *rel)
{
  PetscFunctionBeginUser;
  const std::vector<PetscReal> th = aff.ThetaA(F.mu);
  PetscCall(VecSet(work, 0.0));
  for (size_t q = 0; q < aff.Aq.size(); ++q) { // work = A(mu) u
    PetscCall(MatMult(aff.Aq[q], F.u, work2));
    PetscCall(VecAXPY(work, th[q], work2));
  }
  const auto    &cols = model.Columns();
  const PetscInt N    = (PetscInt)cols.size();
  std::vector<PetscReal> r(N, 0.0), A, f;
  PetscInt               lo, hi;
  const PetscScalar     *w;
  PetscCall(VecGetOwnershipRange(work, &lo, &hi));
  PetscCall(VecGetArrayRead(work, &w));
  for (PetscInt i = lo; i < hi; ++i) {
    const PetscInt c = order.CanonicalDof(i);
    for (PetscInt n = 0; n < N; ++n) r[n] += PetscRealPart(w[i - lo]) * bases.modes[(size_t)cols[n] * bases.ndofs + c];
  }
  PetscCall(VecRestoreArrayRead(work, &w));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, r.data(), (int)N, MPIU_REAL, MPIU_SUM, PetscObjectComm((PetscObject)work)));
  model.Operators(F.mu, &A, &f); // V'A(mu)V, column-major (symmetric)
  std::vector<PetscReal> c(r);
  PetscBLASInt           n = (PetscBLASInt)N, one = 1, info = 0;
  LAPACKpotrf_("L", &n, A.data(), &n, &info);
  PetscCheck(info == 0, PetscObjectComm((PetscObject)work), PETSC_ERR_LIB, "validate: the reduced stiffness is not positive definite (LAPACK potrf info %d)", (int)info);
  LAPACKpotrs_("L", &n, &one, A.data(), &n, c.data(), &n, &info);
  // ||u - V c||_A from the error itself (not ||u||^2 - r'c: that difference of squares loses the digits of a small error)
  PetscCall(bases.Displacement(model, order, c, work));
  PetscCall(VecAYPX(work, -1.0, F.u));
  PetscReal e2;
  PetscCall(EnergyNorm2(aff, F.mu, work, work2, &e2));
  *rel = F.energyNorm > 0 ? std::sqrt(std::max<PetscReal>(e2, 0)) / F.energyNorm : 0;
  PetscFunctionReturn(0);
}

// Relative errors of a reduced solution against the FOM solution F (A: the FOM matrix at F.mu).
static PetscErrorCode Compare(const ReducedModel &model, const RomBases &bases, const CanonicalOrder &order, const ContactSystem &sys, PetscInt dim, const AffineDecomposition &aff, const FomSolution &F, const ReducedSolution &sol, Vec work, Vec work2, Vec lwork, double *eu, double *el, double *ef)
{
  PetscFunctionBeginUser;
  PetscCall(bases.Displacement(model, order, sol.v, work));
  PetscCall(VecAYPX(work, -1.0, F.u)); // u_fom - u_rom
  PetscReal e2;
  PetscCall(EnergyNorm2(aff, F.mu, work, work2, &e2));
  *eu = std::sqrt(std::max<PetscReal>(e2, 0)) / F.energyNorm;
  std::vector<PetscReal> lam;
  bases.Multipliers(model, sol.lambda, &lam);
  PetscCall(CanonicalToMultipliers(order, lam, lwork));
  ContactSummary cs;
  PetscCall(SummarizeContact(sys, lwork, dim, &cs));
  PetscReal df = 0, nf = 0;
  for (PetscInt d = 0; d < dim; ++d) {
    df += PetscSqr(cs.forceVec[d] - F.force[d]);
    nf += PetscSqr(F.force[d]);
  }
  *ef = nf > 0 ? std::sqrt(df / nf) : std::sqrt(df);
  // weighted l2: sum_i w_i (lambda_i - lambda_rom_i)^2
  PetscCall(VecAYPX(lwork, -1.0, F.lambda));
  PetscCall(VecPointwiseMult(lwork, lwork, lwork));
  PetscScalar wl;
  PetscCall(VecDot(lwork, sys.weight, &wl));
  *el = F.lambdaNorm > 0 ? std::sqrt(std::max<PetscReal>(PetscRealPart(wl), 0)) / F.lambdaNorm : std::sqrt(std::max<PetscReal>(PetscRealPart(wl), 0));
  PetscFunctionReturn(0);
}

PetscErrorCode RunValidation(MPI_Comm comm, const SceneSpec &scene, const std::string &romPathIn, const ParameterSet &test, const ValidationSettings &settings, Report *report)
{
  Report        &rep = *report;
  const char    *romPath = romPathIn.c_str(), *sweepOut = settings.sweepOutput.c_str();
  {
    char reportPath[PETSC_MAX_PATH_LEN] = "";
    PetscCall(PetscOptionsGetString(NULL, NULL, "-report", reportPath, sizeof reportPath, NULL));
    const std::string so = settings.sweep ? settings.sweepOutput : std::string();
    // the inputs validate reads besides the ROM: the test snapshots, the sample file, the basis file (given, or the ROM's
    // beside it); -report onto any of them replaced it with the report, exit 0 (audit of 2026-12-01)
    std::vector<std::pair<std::string, std::string>> ins = {{"-rom", romPathIn}};
    for (const char *opt : {"-test_snapshots", "-test_file", "-rom_basis"}) {
      char v[PETSC_MAX_PATH_LEN] = "";
      PetscCall(PetscOptionsGetString(NULL, NULL, opt, v, sizeof v, NULL));
      if (v[0]) ins.emplace_back(opt, v);
    }
    {
      std::string stored;
      PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
      const PetscErrorCode e = RomReadAttr(romPathIn, "basis_file", &stored);
      PetscCall(PetscPopErrorHandler());
      if (!e && !stored.empty()) ins.emplace_back("(the ROM's basis file)", std::filesystem::path(stored).is_relative() ? (std::filesystem::path(romPathIn).parent_path() / stored).string() : stored);
    }
    PetscCall(CheckDistinctFiles(comm, {{"-report", reportPath}, {"-validate_sweep_output (.json)", so.empty() ? so : so + ".json"}, {"-validate_sweep_output (.csv)", so.empty() ? so : so + ".csv"}}, ins));
  }
  const PetscInt repeat = settings.repeat;
  const bool     sweep  = settings.sweep;
  const auto    &fractions = settings.fractions;
  ReducedModel   model, exact;
  ElasticFOM     fom;
  ContactMap     cmap;
  KacanovSolver  kac;
  CanonicalOrder order;
  RomBases       bases;
  std::string    romScene;
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  if (!VAL_FOM) {
    PetscCall(PetscLogEventRegister("RBCValidateFOM", DM_CLASSID, &VAL_FOM));
    PetscCall(PetscLogEventRegister("RBCValidateROM", DM_CLASSID, &VAL_ROM));
  }
  PetscCall(model.Open(romPath));
  PetscCall(model.SetFromOptions());
  for (PetscInt r : settings.rValues) // before the FOM solves (hours on a fine mesh)
    PetscCheck(r >= 1 && r <= model.Rfull, comm, PETSC_ERR_ARG_OUTOFRANGE, "-validate_sweep_R: %" PetscInt_FMT " dual vectors, the ROM file %s stores %" PetscInt_FMT, r, romPath, model.Rfull);
  PetscCall(RomReadAttr(romPath, "scene", &romScene));
  PetscCheck(scene.name == romScene, comm, PETSC_ERR_USER_INPUT, "validate: the scene of the options is '%s', the ROM %s was built for '%s' (give -options_file runs/%s.opts)", scene.name.c_str(), romPath, romScene.c_str(), romScene.c_str());
  // (a test set outside the ROM's box was blamed on -mu, which nobody gave: the test parameter and its source named)
  for (size_t j = 0; j < test.points.size(); ++j)
    PetscCall(model.par.CheckBox(comm, test.points[j], "test parameter " + std::to_string(j + 1) + " of " + std::to_string(test.points.size()) + (settings.testSnapshots.empty() ? std::string(" (-test_*)") : " (" + settings.testSnapshotsOption + " " + settings.testSnapshots + ")")));

  // the FOM of the scene (reference configuration, affine terms) and the bases
  PetscCall(fom.Create(comm, scene));
  PetscCall(CheckRomScene(comm, romPath, scene, fom.map)); // the same materials, loads, maps, mesh as offline
  PetscCall(fom.SetupAffine());
  PetscCall(order.BuildDofs(fom.elas));
  PetscCall(kac.SetFromOptions(comm));
  PetscCall(cmap.Setup(fom.elas, scene.slave, scene.master));
  PetscCall(bases.Read(comm, model, romPath, order.NumDofs(), cmap.NumMultipliers()));
  PetscCall(kac.ShareFactor(fom, cmap));
  const PetscInt dim = fom.elas.dim;

  // the ROM without EIM: exact reduced contact terms on the full patch (the ROM's contact quadrature)
  {
    std::vector<unsigned long long> dims;
    std::vector<double>             q;
    PetscCall(RomReadDataset(romPath, "/online/eim_quadrature", &dims, &q));
    // (-3 was used: the exact-contact model had no contact, lambda error 1.0 reported, exit 0)
    PetscCheck(q.size() == 1 && q[0] >= 1 && q[0] <= 64 && q[0] == std::floor(q[0]), comm, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/eim_quadrature must hold one number of subdivisions in [1, 64]: a corrupt file", romPath);
    std::shared_ptr<ContactPatch> full;
    std::vector<PetscReal>        P;
    PetscCall(BuildFullContact(fom, cmap, order, bases.modes, bases.N, bases.W, bases.r, (PetscInt)q[0], &full, &P));
    PetscCall(exact.Open(romPath));
    PetscCall(exact.SetFromOptions());
    exact.SetExactContact(full, P);
    exact.SetContactMode(ReducedModel::ContactMode::Exact);
    PetscCall(exact.Truncate((PetscInt)std::count_if(model.Columns().begin(), model.Columns().end(), [&](PetscInt c) { return c < model.Npod; }), model.R(), -1, -1));
  }

  // FOM solutions of the test set (kept for the sweep): solved here, or read from -test_snapshots (each one's u and
  // lambda, its solve's seconds as stored; its contact system assembled at the stored u)
  const PetscInt           nt = (PetscInt)test.points.size();
  std::vector<FomSolution> F(nt);
  std::vector<double>      fomTimes;
  std::vector<std::shared_ptr<ContactSystem>> sysAt(nt);
  std::vector<Snapshot>    stored;
  PetscCheck(nt >= 1, comm, PETSC_ERR_ARG_SIZ, "validate: the test set is empty");
  if (!settings.testSnapshots.empty()) PetscCall(ReadTestSnapshots(comm, settings.testSnapshots, settings.testSnapshotsOption.c_str(), scene, fom, order, cmap, test, &stored));
  for (PetscInt j = 0; j < nt; ++j) {
    F[j].mu = test.points[j];
    ContactSystem  readSys;
    ContactSystem *sys = &kac.sys;
    Vec            lambda = nullptr;
    PetscCall(PetscLogEventBegin(VAL_FOM, 0, 0, 0, 0));
    PetscCall(PetscTime(&t0));
    PetscCall(fom.SetMu(F[j].mu));
    cmap.SetGeometry(&fom.map, F[j].mu);
    if (stored.empty()) {
      PetscCall(fom.AssembleAndFactor());
      PetscCall(kac.Solve(fom, cmap));
      lambda = kac.lambda;
      PetscCall(PetscTime(&t1));
      fomTimes.push_back(t1 - t0);
    } else {
      PetscCall(StoredSolution(fom, cmap, order, stored[j], &readSys, &lambda));
      sys = &readSys;
      fomTimes.push_back(stored[j].seconds);
    }
    PetscCall(PetscLogEventEnd(VAL_FOM, 0, 0, 0, 0));
    PetscCall(VecDuplicate(fom.u, &F[j].u));
    PetscCall(VecCopy(fom.u, F[j].u));
    PetscCall(VecDuplicate(lambda, &F[j].lambda));
    PetscCall(VecCopy(lambda, F[j].lambda));
    Vec       Au;
    PetscReal uAu;
    PetscCall(VecDuplicate(fom.u, &Au));
    PetscCall(EnergyNorm2(fom.affine, F[j].mu, fom.u, Au, &uAu));
    PetscCall(VecDestroy(&Au));
    F[j].energyNorm = std::sqrt(uAu);
    Vec l2;
    PetscCall(VecDuplicate(lambda, &l2));
    PetscCall(VecPointwiseMult(l2, lambda, lambda));
    PetscScalar wl;
    PetscCall(VecDot(l2, sys->weight, &wl));
    PetscCall(VecDestroy(&l2));
    F[j].lambdaNorm = std::sqrt(PetscRealPart(wl));
    ContactSummary cs;
    PetscCall(SummarizeContact(*sys, lambda, dim, &cs));
    for (PetscInt d = 0; d < 3; ++d) F[j].force[d] = cs.forceVec[d];
    F[j].maxPressure = cs.maxPressure;
    F[j].halfwidth   = cs.halfwidthMoment;
    // keep the contact system (weights, normals) of this solution
    auto c = std::make_shared<ContactSystem>();
    PetscCall(VecDuplicate(sys->weight, &c->weight));
    PetscCall(VecCopy(sys->weight, c->weight));
    for (PetscInt d = 0; d < dim; ++d) {
      PetscCall(VecDuplicate(sys->normal[d], &c->normal[d]));
      PetscCall(VecCopy(sys->normal[d], c->normal[d]));
      PetscCall(VecDuplicate(sys->coord[d], &c->coord[d]));
      PetscCall(VecCopy(sys->coord[d], c->coord[d]));
    }
    PetscCall(VecDuplicate(sys->g, &c->g));
    c->R     = sys->R;
    sysAt[j] = c;
    if (!stored.empty()) PetscCall(VecDestroy(&lambda));
  }
  stored.clear();
  Vec work, work2, lwork;
  PetscCall(VecDuplicate(fom.u, &work));
  PetscCall(VecDuplicate(fom.u, &work2));
  PetscCall(VecDuplicate(F[0].lambda, &lwork));

  // ROM (timed) and ROM without EIM on the test set, for one truncation of the model
  // sols (may be null): the converged reduced solutions, in the order of the test parameters
  // mediansNoEstimate (may be null): the same timing with -rom_error_estimate false, when the model estimates
  PetscMPIInt rank;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  // the CPUs for the timed threads (-rom_threads, -validate_threads) of rank 0, the others waiting asleep
  std::vector<int> timingCpus = ForkJoin::CallerCpus();
  PetscInt         maxThreads = model.threads;
  for (PetscInt t : settings.threadValues) maxThreads = std::max(maxThreads, t);
  if (maxThreads > 1 && !settings.timeAllRanks) PetscCall(NodeCpus(comm, &timingCpus));
  // Rounds of m.Solve over the test parameters idx (one round after the other, so that with several parameters no
  // solve follows one at its own parameter), timed on rank 0 while the other ranks wait in the broadcast of its
  // per-parameter medians (-validate_time_all_ranks false): the same solve timed on every rank at once measures the
  // ranks slowing each other down (on the 2-vCPU VM by a third, evenly over the solve's phases), not one online solve
  // (docs/online.md "Validation"). Threads alone on rank 0 run on this node's cores (the caller's own restored after).
  auto timeRounds = [&](ReducedModel &m, const std::vector<PetscInt> &idx, std::vector<double> *meds) -> PetscErrorCode {
    PetscFunctionBeginUser;
    meds->assign(idx.size(), 0.0);
    if (settings.timeAllRanks || rank == 0) {
      const std::vector<int> own   = ForkJoin::CallerCpus();
      const bool             widen = !settings.timeAllRanks && m.threads > 1 && timingCpus.size() > own.size();
      if (widen) (void)ForkJoin::SetCallerCpus(timingCpus); // (the workers' are set by evaluate)
      std::vector<std::vector<double>> ts(idx.size());
      ReducedSolution                  sol;
      for (PetscInt k = 0; k < repeat; ++k)
        for (size_t j = 0; j < idx.size(); ++j) {
          PetscLogDouble a, b;
          PetscCall(PetscTime(&a));
          PetscCall(m.Solve(F[idx[j]].mu, &sol));
          PetscCall(PetscTime(&b));
          ts[j].push_back(b - a);
        }
      if (widen) (void)ForkJoin::SetCallerCpus(own);
      for (size_t j = 0; j < idx.size(); ++j) (*meds)[j] = Median(ts[j]);
    }
    if (!settings.timeAllRanks) PetscCall(BcastAsleep(comm, meds->data(), (int)idx.size()));
    PetscFunctionReturn(0);
  };
  auto evaluate = [&](ReducedModel &m, bool timed, Errors *E, std::vector<double> *medians, std::vector<PetscInt> *its, std::vector<ReducedSolution> *sols, std::vector<double> *mediansNoEstimate = nullptr, std::vector<std::vector<double>> *mediansByThreads = nullptr) -> PetscErrorCode {
    PetscFunctionBeginUser;
    if (timed && rank == 0 && !settings.timeAllRanks) m.SetThreadCpus(timingCpus); // the workers' (timeSolves)
    for (PetscInt j = 0; j < nt; ++j) {
      ReducedSolution sol;
      PetscCall(PetscLogEventBegin(VAL_ROM, 0, 0, 0, 0));
      PetscCall(m.Solve(F[j].mu, &sol)); // warm-up
      // repeated at this parameter (timeRounds)
      auto timeSolves = [&](std::vector<double> *meds) -> PetscErrorCode {
        std::vector<double> med;
        PetscFunctionBeginUser;
        PetscCall(timeRounds(m, {j}, &med));
        meds->push_back(med[0]);
        PetscFunctionReturn(0);
      };
      if (timed && mediansNoEstimate && sol.estimate.available) {
        const PetscBool on = m.errorEstimate;
        m.errorEstimate    = PETSC_FALSE;
        PetscCall(timeSolves(mediansNoEstimate));
        m.errorEstimate = on;
      }
      if (timed) PetscCall(timeSolves(medians));
      if (timed && mediansByThreads) { // -validate_threads: the same solves with other numbers of threads
        const PetscInt t0 = m.threads;
        for (size_t k = 0; k < settings.threadValues.size(); ++k) {
          m.threads = settings.threadValues[k];
          PetscCall(timeSolves(&(*mediansByThreads)[k]));
        }
        m.threads = t0;
      }
      PetscCall(PetscLogEventEnd(VAL_ROM, 0, 0, 0, 0));
      if (!sol.converged) {
        if (!E->failed) { // the parameter named, so that `online -mu` reproduces it
          std::ostringstream o;
          o << "at test parameter " << j << " (";
          for (size_t k = 0; k < F[j].mu.size(); ++k) o << (k ? ", " : "") << (k < scene.params.size() ? scene.params[k].name : "mu" + std::to_string(k)) << " " << std::setprecision(17) << F[j].mu[k];
          o << "; online -mu ";
          for (size_t k = 0; k < F[j].mu.size(); ++k) o << (k ? "," : "") << std::setprecision(17) << F[j].mu[k];
          o << "): " << sol.message;
          E->firstFailure = o.str();
        }
        ++E->failed;
        continue;
      }
      if (its) its->push_back(sol.iterations);
      if (sols) sols->push_back(sol);
      E->outOfRange.push_back((double)sol.outOfRange);
      double eu, el, ef;
      PetscCall(Compare(m, bases, order, *sysAt[j], dim, fom.affine, F[j], sol, work, work2, lwork, &eu, &el, &ef));
      // a NaN error was printed as the maximum or silently left out of it (std::max_element), exit 0
      PetscCheck(std::isfinite(eu) && std::isfinite(el) && std::isfinite(ef), comm, PETSC_ERR_FP, "validate: the relative error at test parameter %" PetscInt_FMT " is not finite (u %g, lambda %g, force %g): the test solution or the reduced one holds non-finite or huge values", j, eu, el, ef);
      E->u.push_back(eu);
      E->lambda.push_back(el);
      E->force.push_back(ef);
      if (sol.estimate.available) {
        E->estU.push_back(sol.estimate.u);
        E->estLambda.push_back(sol.estimate.lambda);
        E->estForce.push_back(sol.estimate.force);
        E->rawU.push_back(sol.estimate.uRaw);
        E->rawLambda.push_back(sol.estimate.lambdaRaw);
        E->rawForce.push_back(sol.estimate.forceRaw);
      }
      if ((PetscInt)sol.force.size() == dim) {
        PetscReal df = 0, nf = 0;
        for (PetscInt d = 0; d < dim; ++d) {
          df += PetscSqr(sol.force[d] - F[j].force[d]);
          nf += PetscSqr(F[j].force[d]);
        }
        E->forceOnline.push_back(nf > 0 ? std::sqrt(df / nf) : std::sqrt(df));
      }
      SurfaceOutputValues so;
      m.SurfaceOutputsOf(F[j].mu, sol, &so);
      if (std::isfinite(so.maxPressure) && F[j].maxPressure > 0) E->pmaxOnline.push_back(std::abs(so.maxPressure - F[j].maxPressure) / F[j].maxPressure);
      if (std::isfinite(so.halfwidth) && F[j].halfwidth > 0) E->halfwidthOnline.push_back(std::abs(so.halfwidth - F[j].halfwidth) / F[j].halfwidth);
      if (std::isfinite(so.contactRadius) && F[j].halfwidth > 0) E->radiusOnline.push_back(std::abs(so.contactRadius - F[j].halfwidth) / F[j].halfwidth); // 3D: the FOM's moment radius
    }
    PetscFunctionReturn(0);
  };
  Errors                E, E0;
  std::vector<double>   medians, mediansNoEstimate;
  std::vector<std::vector<double>> mediansByThreads(settings.threadValues.size());
  std::vector<PetscInt> romIts;
  std::vector<ReducedSolution> sols;
  exact.errorEstimate = PETSC_FALSE;
  PetscCall(evaluate(model, true, &E, &medians, &romIts, settings.residual ? &sols : nullptr, &mediansNoEstimate, &mediansByThreads));
  // The same solves as a sweep: -validate_repeat rounds over the test parameters, so that no solve follows one at its
  // own parameter. Repeating one parameter reuses what a sweep cannot: the patch's geometry at mu, the reduced QP's
  // set-up when D repeats, the branch history of the candidate scans (docs/online.md "Validation"). Per-parameter
  // medians over the rounds; with one test parameter the same as the repeats above.
  std::vector<PetscInt> all(nt);
  std::iota(all.begin(), all.end(), (PetscInt)0);
  std::vector<double>              mediansSweep(nt, 0.0);
  std::vector<std::vector<double>> sweepByThreads(settings.threadValues.size());
  if (!E.failed) {
    PetscCall(timeRounds(model, all, &mediansSweep));
    const PetscInt t0 = model.threads; // -validate_threads: the sweep on those numbers of threads too
    for (size_t k = 0; k < settings.threadValues.size(); ++k) {
      model.threads = settings.threadValues[k];
      PetscCall(timeRounds(model, all, &sweepByThreads[k]));
    }
    model.threads = t0;
  }
  PetscCall(evaluate(exact, false, &E0, nullptr, nullptr, nullptr));
  // the residual indicator of each reduced solution (the greedy's, on the mesh: docs/error_estimate.md) against its
  // energy error: the effectivity an online estimate built on this residual would start from
  std::vector<double> indicator, effectivity;
  if (settings.residual && !E.failed) {
    GreedyIndicator ind;
    ind.criterion = GreedyCriterion::Residual;
    PetscCall(ind.Setup(fom));
    for (PetscInt j = 0; j < nt; ++j) {
      const ReducedSolution &sol = sols[j];
      PetscCall(bases.Displacement(model, order, sol.v, work));
      std::vector<PetscReal> lam;
      bases.Multipliers(model, sol.lambda, &lam);
      GreedyEstimate est;
      PetscCall(ind.Evaluate(fom, cmap, order, F[j].mu, work, lam, &est));
      indicator.push_back(est.residual);
      effectivity.push_back(E.u[j] > 0 ? est.residual / E.u[j] : PETSC_INFINITY);
    }
  }
  PetscCheck(!E.failed, comm, PETSC_ERR_NOT_CONVERGED, "validate: the ROM failed on %" PetscInt_FMT " of %" PetscInt_FMT " test parameters; first: %s", E.failed, nt, E.firstFailure.c_str());

  rep.root["stage"] = "validate";
  rep.root["scene"] = scene.name;
  rep.root["rom_file"] = romPath;
  rep.root["nranks"] = [&] { PetscMPIInt s; MPI_Comm_size(comm, &s); return (long long)s; }();
  E.Fill(&rep.root["test"]);
  E0.Fill(&rep.root["test_no_eim"]); // the ROM with exact contact terms (no hyper-reduction); key kept from the EIM-only releases
  E0.Fill(&rep.root["test_exact"]);
  { // the best approximation of u in the primal basis (energy norm): the basis' share of the u error
    std::vector<double> best(nt);
    for (PetscInt j = 0; j < nt; ++j) PetscCall(BestApproximation(model, bases, order, fom.affine, F[j], work, work2, &best[j]));
    JsonValue &b = rep.root["test_best_approximation"];
    b["rel_err_u"]     = best;
    b["max_rel_err_u"] = best.empty() ? 0.0 : *std::max_element(best.begin(), best.end());
  }
  if (!indicator.empty()) {
    JsonValue &r = rep.root["residual"];
    r["indicator"]        = indicator;
    r["rel_err_u_energy"] = E.u;
    EffectivityStats(effectivity, &r);
  }
  { // the online error estimate against the true errors (docs/error_estimate.md): effectivity = estimate / error
    JsonValue &r = rep.root["estimate"];
    const bool available = !E.estU.empty() && E.estU.size() == E.u.size();
    r["available"]       = available;
    if (available) {
      auto block = [&](const char *key, const std::vector<double> &est, const std::vector<double> &err) {
        JsonValue          &b = r[key];
        std::vector<double> eff(est.size());
        for (size_t k = 0; k < est.size(); ++k) eff[k] = err[k] > 0 ? est[k] / err[k] : (est[k] > 0 ? PETSC_INFINITY : 1.0);
        b["estimate"]     = est;
        b["rel_err"]      = err;
        EffectivityStats(eff, &b);
        b["max_estimate"] = *std::max_element(est.begin(), est.end());
      };
      const std::vector<double> &forceErr = E.forceOnline.size() == E.estForce.size() ? E.forceOnline : E.force;
      if (settings.estimateRaw && settings.estimateErr) {
        settings.estimateRaw[0] = E.rawU;
        settings.estimateRaw[1] = E.rawLambda;
        settings.estimateRaw[2] = E.rawForce;
        settings.estimateErr[0] = E.u;
        settings.estimateErr[1] = E.lambda;
        settings.estimateErr[2] = forceErr;
      }
      block("u", E.estU, E.u);
      block("lambda", E.estLambda, E.lambda);
      // the force the online stage reports (its cubature's, ReducedSolution::force) when there is one
      block("force", E.estForce, forceErr);
      r["scale"] = std::vector<double>(model.estimateScale, model.estimateScale + 3);
      r["floor"] = std::vector<double>(model.estimateFloor, model.estimateFloor + 3);
      // the raw changes (before the calibration): what offline -estimate fits the calibration to
      r["u"]["raw"]      = E.rawU;
      r["lambda"]["raw"] = E.rawLambda;
      r["force"]["raw"]  = E.rawForce;
    }
  }
  {
    std::vector<double> mus;
    for (const auto &mu : test.points) mus.insert(mus.end(), mu.begin(), mu.end());
    rep.root["test"]["mu"] = mus;
  }
  const double onlineMedian = Median(medians), fomMedian = Median(fomTimes);
  rep.root["online_time_s"]["median"] = onlineMedian;
  rep.root["online_time_s"]["max"]    = medians.empty() ? 0.0 : *std::max_element(medians.begin(), medians.end());
  rep.root["online_time_s"]["per_parameter_median"] = medians;
  rep.root["online_time_s"]["repeat"] = (long long)repeat;
  // the sweep's timing (rounds over the test parameters): what a user solving distinct parameters sees
  rep.root["online_time_s"]["sweep_median"]               = Median(mediansSweep);
  rep.root["online_time_s"]["sweep_max"]                  = mediansSweep.empty() ? 0.0 : *std::max_element(mediansSweep.begin(), mediansSweep.end());
  rep.root["online_time_s"]["sweep_per_parameter_median"] = mediansSweep;
  rep.root["online_time_s"]["timed_on"] = settings.timeAllRanks ? "every rank at once" : "rank 0, the other ranks waiting";
  if (!mediansNoEstimate.empty()) { // the solve alone, without the error estimate (same parameters, same repeats)
    rep.root["online_time_s"]["median_without_estimate"] = Median(mediansNoEstimate);
    rep.root["online_time_s"]["estimate_cost_ratio"]     = Median(mediansNoEstimate) > 0 ? onlineMedian / Median(mediansNoEstimate) : 0.0;
  }
  rep.root["online_time_s"]["threads"] = (long long)model.threads; // -rom_threads of the timing above
  rep.root["online_time_s"]["threads_cpus"] = (long long)timingCpus.size(); // the CPUs those threads could use
  for (size_t k = 0; k < settings.threadValues.size(); ++k) { // -validate_threads: the same solves on other numbers of threads
    JsonValue    row;
    const double med = Median(mediansByThreads[k]);
    row["threads"]              = (long long)settings.threadValues[k];
    row["median"]               = med;
    row["per_parameter_median"] = mediansByThreads[k];
    row["speedup_median"]       = med > 0 ? Median(fomTimes) / med : 0.0;
    const double sw             = sweepByThreads[k].empty() ? 0.0 : Median(sweepByThreads[k]); // the sweep's timing
    row["sweep_median"]               = sw;
    row["sweep_per_parameter_median"] = sweepByThreads[k];
    row["speedup_median_sweep"]       = sw > 0 ? Median(fomTimes) / sw : 0.0;
    rep.root["online_time_s"]["by_threads"].Push(row);
  }
  rep.root["test_snapshots"]          = settings.testSnapshots; // "" : the FOM solved here; else fom_time_s as stored
  rep.root["fom_time_s"]["median"]    = fomMedian;
  rep.root["fom_time_s"]["all"]       = fomTimes;
  rep.root["speedup_median"]          = onlineMedian > 0 ? fomMedian / onlineMedian : 0.0;
  rep.root["speedup_median_sweep"]    = Median(mediansSweep) > 0 ? fomMedian / Median(mediansSweep) : 0.0; // (the sweep's timing)
  rep.root["rom_kacanov_iterations"]["max"] = (long long)(romIts.empty() ? 0 : *std::max_element(romIts.begin(), romIts.end()));
  {
    std::vector<double> its(romIts.begin(), romIts.end());
    rep.root["rom_kacanov_iterations"]["mean"]          = its.empty() ? 0.0 : std::accumulate(its.begin(), its.end(), 0.0) / its.size();
    rep.root["rom_kacanov_iterations"]["per_parameter"] = its;
  }
  JsonValue &ro = rep.root["rom"];
  ReportSizes(model, &ro);
  ro["ndofs"] = (long long)order.NumDofs();

  // the errors with fewer dual vectors (and their supremizers), every POD mode of the answer: what the offline
  // stage chooses R on (dual_selection.hpp); the estimate off, as in the sweep below
  // (the sweeps end on the model's own truncation: its sizes if given, else the file's defaults)
  const PetscInt Npod = (PetscInt)std::count_if(model.Columns().begin(), model.Columns().end(), [&](PetscInt c) { return c < model.Npod; });
  const PetscInt R0 = model.R(), Mk0 = model.Mk(), Mg0 = model.Mg();
  auto restoreSizes = [&, given = model.SizesGiven()]() { return given ? model.Truncate(Npod, R0, Mk0, Mg0) : model.Truncate(-1, -1, Mk0, Mg0); };
  if (!settings.rValues.empty()) {
    const PetscBool est0 = model.errorEstimate;
    JsonValue      &rows = rep.root["sweep_R"];
    model.errorEstimate  = PETSC_FALSE;
    for (PetscInt r : settings.rValues) {
      PetscCall(model.Truncate(Npod, r, Mk0, Mg0));
      Errors Es;
      PetscCall(evaluate(model, false, &Es, nullptr, nullptr, nullptr));
      auto mx   = [&](const std::vector<double> &v) { return v.empty() || Es.failed ? NAN : *std::max_element(v.begin(), v.end()); };
      auto mean = [&](const std::vector<double> &v) { return v.empty() || Es.failed ? NAN : std::accumulate(v.begin(), v.end(), 0.0) / v.size(); };
      const DualSizeRow dr{r, model.N(), mx(Es.u), mx(Es.lambda), mx(Es.force), mean(Es.u), mean(Es.lambda), mean(Es.force), Es.failed > 0};
      JsonValue         row;
      row["R"]                   = (long long)r;
      row["N"]                   = (long long)dr.N;
      row["max_rel_err_u"]       = dr.u;
      row["max_rel_err_lambda"]  = dr.lambda;
      row["max_rel_err_force"]   = dr.force;
      row["mean_rel_err_u"]      = dr.meanU;
      row["mean_rel_err_lambda"] = dr.meanLambda;
      row["mean_rel_err_force"]  = dr.meanForce;
      row["failed"]              = (long long)Es.failed;
      if (Es.failed) row["first_failure"] = Es.firstFailure;
      rows.Push(row);
      if (settings.rRows) settings.rRows->push_back(dr);
    }
    model.errorEstimate = est0;
    PetscCall(restoreSizes());
  }

  // speed against error over truncations of the same ROM
  if (sweep) {
    JsonValue         &rows = rep.root["sweep"];
    std::ostringstream csv;
    csv << "N,R,Mk,Mg,online_median_s,max_rel_err_u,max_rel_err_lambda,max_rel_err_force,failed\n";
    const PetscBool est0 = model.errorEstimate;
    model.errorEstimate  = PETSC_FALSE; // the sweep times the solves alone (the estimate's cost: online_time_s)
    for (PetscReal fr : fractions) {
      const PetscInt n = std::max<PetscInt>(1, (PetscInt)std::ceil(fr * Npod - 1e-9)), r = std::max<PetscInt>(1, (PetscInt)std::ceil(fr * R0 - 1e-9));
      const PetscInt mk = (PetscInt)std::ceil(fr * Mk0 - 1e-9), mg = (PetscInt)std::ceil(fr * Mg0 - 1e-9);
      PetscCall(model.Truncate(n, r, mk, mg));
      Errors              Es;
      std::vector<double> meds;
      PetscCall(evaluate(model, true, &Es, &meds, nullptr, nullptr));
      JsonValue row;
      auto      mx = [](const std::vector<double> &v) { return v.empty() ? NAN : *std::max_element(v.begin(), v.end()); };
      row["N"] = (long long)model.N();
      row["R"] = (long long)r;
      row["Mk"] = (long long)mk;
      row["Mg"] = (long long)mg;
      row["online_median_s"] = Median(meds);
      row["max_rel_err_u"] = Es.failed ? NAN : mx(Es.u);
      row["max_rel_err_lambda"] = Es.failed ? NAN : mx(Es.lambda);
      row["max_rel_err_force"] = Es.failed ? NAN : mx(Es.force);
      row["failed"] = (long long)Es.failed;
      if (Es.failed) row["first_failure"] = Es.firstFailure;
      csv.precision(6);
      csv << model.N() << "," << r << "," << mk << "," << mg << "," << Median(meds) << "," << row["max_rel_err_u"].AsNumber() << "," << row["max_rel_err_lambda"].AsNumber() << "," << row["max_rel_err_force"].AsNumber() << "," << Es.failed << "\n";
      rows.Push(row);
    }
    PetscCall(restoreSizes());
    model.errorEstimate = est0;
    csv << "# FOM median " << fomMedian << " s\n";
    JsonValue table;
    table["rows"]            = rows;
    table["fom_median_s"]    = fomMedian;
    table["fom_tolerance"]   = (double)std::max(kac.loop.rtolPrimal, kac.loop.rtolDual);
    table["scene"]           = scene.name;
    table["hyper"]           = model.HyperName();
    table["Mc"]              = (long long)model.Mc();
    table["ndofs"]           = (long long)order.NumDofs();
    PetscCall(WriteFileAtomic(comm, std::string(sweepOut) + ".csv", csv.str()));
    PetscCall(WriteFileAtomic(comm, std::string(sweepOut) + ".json", table.Dump()));
    rep.root["sweep_files"] = std::string(sweepOut) + ".{csv,json}";
  }
  if (settings.print) PetscCall(PetscPrintf(comm, "rbcontact validate: %s, %" PetscInt_FMT " test parameters, N %" PetscInt_FMT " R %" PetscInt_FMT " %s: max rel err u %.3e lambda %.3e force %.3e (exact contact terms: u %.3e lambda %.3e); online median %.3g s (in a sweep %.3g s), FOM median %.3g s, speedup %.0f\n", scene.name.c_str(), nt, model.N(), model.R(), model.HyperSizes().c_str(), rep.root["test"]["max_rel_err_u"].AsNumber(), rep.root["test"]["max_rel_err_lambda"].AsNumber(), rep.root["test"]["max_rel_err_force"].AsNumber(), rep.root["test_no_eim"]["max_rel_err_u"].AsNumber(), rep.root["test_no_eim"]["max_rel_err_lambda"].AsNumber(), onlineMedian, Median(mediansSweep), fomMedian, onlineMedian > 0 ? fomMedian / onlineMedian : 0.0));
  if (settings.print && !E.estU.empty() && E.estU.size() == E.u.size()) {
    JsonValue &r = rep.root["estimate"];
    PetscCall(PetscPrintf(comm, "rbcontact validate: error estimate effectivity (estimate / error) u [%.3g, %.3g], lambda [%.3g, %.3g], force [%.3g, %.3g]; >= 1 on %.0f %% / %.0f %% / %.0f %%; online time with it %.2fx\n", r["u"]["min_effectivity"].AsNumber(), r["u"]["max_effectivity"].AsNumber(), r["lambda"]["min_effectivity"].AsNumber(), r["lambda"]["max_effectivity"].AsNumber(), r["force"]["min_effectivity"].AsNumber(), r["force"]["max_effectivity"].AsNumber(), 100 * r["u"]["share_above_1"].AsNumber(), 100 * r["lambda"]["share_above_1"].AsNumber(), 100 * r["force"]["share_above_1"].AsNumber(), rep.root["online_time_s"].Has("estimate_cost_ratio") ? rep.root["online_time_s"]["estimate_cost_ratio"].AsNumber() : 0.0));
  }
  for (auto &s : F) {
    PetscCall(VecDestroy(&s.u));
    PetscCall(VecDestroy(&s.lambda));
  }
  PetscCall(VecDestroy(&work));
  PetscCall(VecDestroy(&work2));
  PetscCall(VecDestroy(&lwork));
  PetscFunctionReturn(0);
}

PetscErrorCode RunValidationFromOptions(MPI_Comm comm, const std::string &reportPath, Report *rep)
{
  char               romPath[PETSC_MAX_PATH_LEN] = "";
  PetscBool          set                         = PETSC_FALSE;
  SceneSpec          scene;
  ValidationSettings s;
  ParameterSet       test;

  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, NULL, "rbcontact validate: the ROM file", "rbcontact");
  PetscCall(PetscOptionsString("-rom", "the ROM file (written by rbcontact offline)", "", romPath, romPath, sizeof romPath, &set));
  PetscOptionsEnd();
  PetscCall(ValidationSettingsFromOptions(comm, reportPath, &s));
  PetscCall(RequireInput(comm, set && romPath[0], "-rom", "validate: give the ROM file with -rom <file.h5> (written by rbcontact offline)"));
  PetscCall(SceneSpecFromOptions(comm, &scene));
  if (s.testSnapshots.empty()) PetscCall(ParameterSetFromOptions(comm, scene.params, "test_", &test));
  else { // the test set is the file's; the -test_* options of a scene's options file are set aside without a warning
    for (const char *o : {"-test_type", "-test_size", "-test_seed", "-test_file"}) {
      PetscBool has;
      PetscCall(PetscOptionsHasName(NULL, NULL, o, &has));
    }
    // but not a sample file: the scene files set -test_type, -test_size and -test_seed, never -test_file, so one
    // given is the user's own test set (it was dropped without a word for the snapshot file's)
    PetscBool file;
    PetscCall(PetscOptionsHasName(NULL, NULL, "-test_file", &file));
    PetscCheck(!file, comm, PETSC_ERR_ARG_INCOMP, "-test_file and -test_snapshots both give the test set: the snapshot file's parameters are its test set; give one of them");
    SnapshotHeader h;
    PetscCall(SnapshotFile::ReadHeader(s.testSnapshots, &h));
    test.points = h.trainingPoints;
    for (const auto &p : scene.params) test.names.push_back(p.name);
  }
  PetscCall(RunValidation(comm, scene, romPath, test, s, rep));
  PetscFunctionReturn(0);
}

} // namespace rbc
