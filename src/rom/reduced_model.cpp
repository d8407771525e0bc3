// src/rom/reduced_model.cpp: the online stage's model: reading/writing its data (ROM file, format 2,
// docs/rom_file.md), truncation, the EIM (or exact) reduced contact terms and the reduced Kacanov loop.
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/options_files.hpp"
#include "rbcontact/warm_start.hpp"
#include "dense_kernels.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <atomic>
#include <numeric>
#include <cmath>
#include <cstring>
#include <sstream>

namespace rbc {

static PetscLogEvent ROM_Solve = 0, ROM_Contact = 0, ROM_QP = 0, ROM_Estimate = 0;
// the cubature's contact terms by phase (-log_view; docs/online.md "Threads"): the patch's displacement and master
// geometry, the points' scans and kernels, the points' sum
static PetscLogEvent ROM_CubDisp = 0, ROM_CubPoints = 0, ROM_CubSum = 0;

static PetscErrorCode RegisterEvents()
{
  PetscFunctionBeginUser;
  if (!ROM_Solve) {
    PetscCall(PetscLogEventRegister("RBCOnlineSolve", DM_CLASSID, &ROM_Solve));
    PetscCall(PetscLogEventRegister("RBCOnlineContact", DM_CLASSID, &ROM_Contact));
    PetscCall(PetscLogEventRegister("RBCOnlineQP", DM_CLASSID, &ROM_QP));
    PetscCall(PetscLogEventRegister("RBCOnlineEstimate", DM_CLASSID, &ROM_Estimate));
    PetscCall(PetscLogEventRegister("RBCOnlineCubDisp", DM_CLASSID, &ROM_CubDisp));
    PetscCall(PetscLogEventRegister("RBCOnlineCubPoints", DM_CLASSID, &ROM_CubPoints));
    PetscCall(PetscLogEventRegister("RBCOnlineCubSum", DM_CLASSID, &ROM_CubSum));
  }
  PetscFunctionReturn(0);
}

namespace {
std::vector<double> CoefRecords(const std::vector<Coefficient> &c)
{
  std::vector<double> r;
  for (const auto &k : c) r.insert(r.end(), {(double)k.tensorBody, (double)k.tensorEntry, (double)k.detBody, (double)k.surfBody, (double)k.param, k.scale});
  return r;
}

std::vector<Coefficient> CoefFromRecords(const std::vector<double> &r)
{
  std::vector<Coefficient> c(r.size() / 6);
  for (size_t i = 0; i < c.size(); ++i) {
    const double *x = &r[6 * i];
    c[i].tensorBody  = (PetscInt)x[0];
    c[i].tensorEntry = (PetscInt)x[1];
    c[i].detBody     = (PetscInt)x[2];
    c[i].surfBody    = (PetscInt)x[3];
    c[i].param       = (PetscInt)x[4];
    c[i].scale       = x[5];
  }
  return c;
}

using U64 = unsigned long long;

PetscErrorCode ReadChecked(const std::string &file, const std::string &name, size_t expect, std::vector<double> *data)
{
  std::vector<U64> dims;
  PetscFunctionBeginUser;
  PetscCall(RomReadDataset(file, name, &dims, data));
  PetscCheck(expect == (size_t)-1 || data->size() == expect, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: dataset %s has %zu entries, %zu expected (corrupt or mismatched file)", file.c_str(), name.c_str(), data->size(), expect);
  PetscCall(RomCheckValues("ROM file " + file, name, *data)); // (1e200 in /online/affine/f crashed the online solve)
  PetscFunctionReturn(0);
}

// The same with the dataset's shape (docs/rom_file.md): the entry count alone let a transposed /online/ecsw/Pw through
// (force +3.5 %, exit 0; audit of 2026-12-01).
PetscErrorCode ReadShaped(const std::string &file, const std::string &name, const std::vector<U64> &shape, std::vector<double> *data)
{
  std::vector<U64> dims;
  PetscFunctionBeginUser;
  PetscCall(RomReadDataset(file, name, &dims, data));
  if (dims != shape) {
    auto str = [](const std::vector<U64> &v) {
      std::string o;
      for (U64 x : v) o += (o.empty() ? "" : " x ") + std::to_string(x);
      return o.empty() ? std::string("a scalar") : o;
    };
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: dataset %s is %s, %s expected (corrupt or mismatched file)", file.c_str(), name.c_str(), str(dims).c_str(), str(shape).c_str());
  }
  PetscCall(RomCheckValues("ROM file " + file, name, *data));
  PetscFunctionReturn(0);
}

// A Gram matrix (R x R, row-major): symmetric to 1e-10 of its largest diagonal entry, with a positive diagonal (a negated
// /online/estimate/mass_gram made the lambda estimate "available" at its floor, 50x below the error)
PetscErrorCode CheckGram(const std::string &file, const char *name, const std::vector<double> &G, size_t R)
{
  double dmax = 0;
  PetscFunctionBeginUser;
  for (size_t i = 0; i < R; ++i) {
    PetscCheck(G[i * R + i] > 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s has the diagonal entry %g at %zu (a Gram matrix: > 0): a corrupt file", file.c_str(), name, G[i * R + i], i);
    dmax = std::max(dmax, G[i * R + i]);
  }
  for (size_t i = 0; i < R; ++i)
    for (size_t j = 0; j < i; ++j)
      PetscCheck(std::abs(G[i * R + j] - G[j * R + i]) <= 1e-10 * dmax, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s is not symmetric (entries (%zu, %zu) and (%zu, %zu)): a corrupt file", file.c_str(), name, i, j, j, i);
  PetscFunctionReturn(0);
}

std::vector<PetscInt> ToInt(const std::vector<double> &d) { return std::vector<PetscInt>(d.begin(), d.end()); }
} // namespace

// ------------------------------------------------------------------ parametrization
PetscErrorCode ReducedParametrization::FromFOM(const Elasticity &elas, const GeometryMap &m, const AffineDecomposition &aff)
{
  PetscFunctionBeginUser;
  dim    = elas.dim;
  params = elas.scene.params;
  bodies = elas.scene.bodies;
  PetscCall(map.FromRecords((PetscInt)bodies.size(), m.Records()));
  thetaA = aff.thetaA;
  thetaF = aff.thetaF;
  Light();
  PetscFunctionReturn(0);
}

void ReducedParametrization::Light()
{
  light_               = std::make_shared<Elasticity>();
  light_->dim          = dim;
  light_->scene.bodies = bodies;
  light_->scene.params = params;
}

void ReducedParametrization::Write(RomWriter *w) const
{
  std::vector<double> box, def, bod;
  std::string         names;
  for (const auto &p : params) {
    box.insert(box.end(), {p.min, p.max});
    def.push_back(p.def);
    names += (names.empty() ? "" : ",") + p.name;
  }
  for (const auto &b : bodies) bod.insert(bod.end(), {b.E, b.nu, (double)b.paramE, (double)b.paramNu});
  w->Attr("param_names", names);
  w->Dataset("/params/box", {params.size(), 2}, box);
  w->Dataset("/params/default", {params.size()}, def);
  w->Dataset("/online/dim", {1}, {(double)dim});
  w->Dataset("/online/bodies", {bodies.size(), 4}, bod);
  std::vector<double> rec = map.Records();
  rec.insert(rec.begin(), (double)(rec.size() / 8));
  w->Dataset("/online/map", {rec.size()}, rec);
  w->Dataset("/online/affine/thetaA", {thetaA.size(), 6}, CoefRecords(thetaA));
  w->Dataset("/online/affine/thetaF", {thetaF.size(), 6}, CoefRecords(thetaF));
}

PetscErrorCode ReducedParametrization::Read(const std::string &file)
{
  std::vector<double> box, def, d, bod, rec;
  std::string         names;

  PetscFunctionBeginUser;
  PetscCall(RomReadAttr(file, "param_names", &names));
  PetscCall(ReadChecked(file, "/params/box", (size_t)-1, &box));
  PetscCall(ReadChecked(file, "/params/default", box.size() / 2, &def));
  params.assign(def.size(), ParamSpec());
  { // one name per parameter (more names were accepted, the extra ones dropped)
    size_t n = names.empty() ? 0 : 1 + (size_t)std::count(names.begin(), names.end(), ',');
    PetscCheck(n == params.size(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: attribute param_names '%s' holds %zu names for the %zu parameters of /params/box: a corrupt file", file.c_str(), names.c_str(), n, params.size());
  }
  std::stringstream ss(names);
  for (size_t i = 0; i < params.size(); ++i) {
    std::getline(ss, params[i].name, ',');
    params[i].min = params[i].value = box[2 * i];
    params[i].max = box[2 * i + 1];
    params[i].def = params[i].value = def[i];
    PetscCheck(params[i].min <= params[i].max && params[i].def >= params[i].min && params[i].def <= params[i].max, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /params/box row %zu [%g, %g] with default %g is not a box holding its default: a corrupt file", file.c_str(), i, (double)params[i].min, (double)params[i].max, (double)params[i].def);
  }
  PetscCall(ReadChecked(file, "/online/dim", 1, &d));
  dim = (PetscInt)d[0];
  PetscCall(ReadChecked(file, "/online/bodies", (size_t)-1, &bod));
  PetscCheck(bod.size() % 4 == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/bodies is malformed", file.c_str());
  bodies.assign(bod.size() / 4, BodySpec());
  for (size_t b = 0; b < bodies.size(); ++b) {
    // the parameters E and nu follow: -1 (a constant) or an index of mu (an index out of range fell back to the constant
    // without a word; review of 2026-12-04)
    for (int k : {2, 3}) {
      const double q = bod[4 * b + k];
      PetscCheck(q == std::floor(q) && q >= -1 && q < (double)params.size(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/bodies row %zu: the parameter of %s is %g, neither -1 nor an index in [0, %zu): a corrupt file", file.c_str(), b, k == 2 ? "E" : "nu", q, params.size());
    }
    bodies[b].E       = bod[4 * b];
    bodies[b].nu      = bod[4 * b + 1];
    bodies[b].paramE  = (PetscInt)bod[4 * b + 2];
    bodies[b].paramNu = (PetscInt)bod[4 * b + 3];
  }
  PetscCall(ReadChecked(file, "/online/map", (size_t)-1, &rec));
  PetscCheck(!rec.empty() && rec.size() == 1 + 8 * (size_t)rec[0], PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/map is malformed", file.c_str());
  rec.erase(rec.begin());
  // each block's {body, type, parameter, ref, v0, v1, v2, axis}: the parameter indexes mu and ref divides (a huge index
  // was a segmentation fault, one past the end a read out of bounds blamed on Kacanov, ref 0 a non-finite QP naming
  // no file; audit of 2026-12-01)
  for (size_t i = 0; i < rec.size(); i += 8) {
    const PetscReal pr = rec[i + 2], ref = rec[i + 3], axis = rec[i + 7];
    PetscCheck(pr >= 0 && pr < (PetscReal)params.size() && pr == std::floor(pr), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/map block %zu: parameter index %g out of range [0, %zu): a corrupt file", file.c_str(), i / 8, (double)pr, params.size());
    PetscCheck(std::isfinite(ref) && ref != 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/map block %zu: reference value %g must be finite and nonzero: a corrupt file", file.c_str(), i / 8, (double)ref);
    PetscCheck(rec[i + 1] != 1 || (axis >= 0 && axis < 3 && axis == std::floor(axis)), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/map block %zu: stretch axis %g out of range [0, 3): a corrupt file", file.c_str(), i / 8, (double)axis);
  }
  PetscCall(map.FromRecords((PetscInt)bodies.size(), rec));
  PetscCall(ReadChecked(file, "/online/affine/thetaA", (size_t)-1, &d));
  thetaA = CoefFromRecords(d);
  // (an empty one was blamed on /online/affine/A's size)
  PetscCheck(!thetaA.empty(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/affine/thetaA holds no coefficient function (the stiffness has at least one term): a corrupt file", file.c_str());
  PetscCall(ReadChecked(file, "/online/affine/thetaF", (size_t)-1, &d));
  thetaF = CoefFromRecords(d);
  for (const auto *cs : {&thetaA, &thetaF})
    for (const auto &c : *cs)
      PetscCheck(c.tensorBody < (PetscInt)bodies.size() && c.detBody < (PetscInt)bodies.size() && c.surfBody < (PetscInt)bodies.size() && c.param < (PetscInt)params.size(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: a coefficient function refers to an unknown body or parameter", file.c_str());
  Light();
  for (const auto *cs : {&thetaA, &thetaF}) // the entry of the effective tensor a coefficient reads
    for (size_t q = 0; q < cs->size(); ++q)
      PetscCheck((*cs)[q].tensorBody < 0 || ((*cs)[q].tensorEntry >= 0 && (*cs)[q].tensorEntry < light_->AuxSize()), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s record %zu: tensor entry %" PetscInt_FMT " out of range [0, %" PetscInt_FMT ")", file.c_str(), cs == &thetaA ? "/online/affine/thetaA" : "/online/affine/thetaF", q, (*cs)[q].tensorEntry, light_->AuxSize());
  PetscFunctionReturn(0);
}

void ReducedParametrization::ThetaA(const std::vector<PetscReal> &mu, std::vector<PetscReal> *th) const
{
  th->resize(thetaA.size());
  for (size_t q = 0; q < thetaA.size(); ++q) (*th)[q] = thetaA[q].Evaluate(*light_, &map, mu);
}

bool ReducedParametrization::AConstant() const
{
  for (const auto &c : thetaA)
    if (c.tensorBody >= 0 || c.detBody >= 0 || c.surfBody >= 0 || c.param >= 0) return false;
  return true;
}

void ReducedParametrization::ThetaF(const std::vector<PetscReal> &mu, std::vector<PetscReal> *th) const
{
  th->resize(thetaF.size());
  for (size_t q = 0; q < thetaF.size(); ++q) (*th)[q] = thetaF[q].Evaluate(*light_, &map, mu);
}

PetscErrorCode ReducedParametrization::CheckBox(MPI_Comm comm, const std::vector<PetscReal> &mu, const std::string &what) const
{
  PetscFunctionBeginUser;
  if (mu.size() != params.size()) {
    std::string names;
    for (const auto &p : params) names += (names.empty() ? "" : ", ") + p.name;
    SETERRQ(comm, PETSC_ERR_ARG_SIZ, "%s: %zu value%s given, the model has %zu parameter%s (%s, in this order)", what.c_str(), mu.size(), mu.size() == 1 ? "" : "s", params.size(), params.size() == 1 ? "" : "s", names.c_str());
  }
  for (size_t i = 0; i < mu.size(); ++i) {
    PetscCheck(std::isfinite(mu[i]), comm, PETSC_ERR_ARG_OUTOFRANGE, "%s: parameter '%s' is not a finite number", what.c_str(), params[i].name.c_str());
    const PetscReal tol = 1e-12 * std::max<PetscReal>(1.0, std::abs(params[i].max - params[i].min));
    PetscCheck(mu[i] >= params[i].min - tol && mu[i] <= params[i].max + tol, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s: %s (the reduced model is trained there only)", what.c_str(), OutOfBoxMessage(params[i], mu[i]).c_str());
  }
  PetscFunctionReturn(0);
}

// ------------------------------------------------------------------ model I/O
std::vector<PetscInt> ReducedColumns(PetscInt Npod, PetscInt nsup, PetscInt n, PetscInt r)
{
  std::vector<PetscInt> cols;
  for (PetscInt i = 0; i < n; ++i) cols.push_back(i);
  for (PetscInt i = 0; i < std::min(nsup, r); ++i) cols.push_back(Npod + i);
  return cols;
}

void ReportSizes(const ReducedModel &m, JsonValue *r)
{
  (*r)["N"]        = (long long)m.N();
  (*r)["R"]        = (long long)m.R();
  (*r)["Mk"]       = (long long)m.Mk();
  (*r)["Mg"]       = (long long)m.Mg();
  (*r)["Mc"]       = (long long)m.Mc();
  (*r)["hyper"]    = m.HyperName();
  (*r)["ecsw_sum"] = m.EcswSumsByDofs() ? "dofs" : "points";
  (*r)["ecsw_precision"] = m.EcswSingle() ? "single" : "double";
  (*r)["gemm"]           = m.GemmName();
  (*r)["factor_a_once"]  = m.AFactored(); // -rom_factor_a_once and in effect (A^ independent of mu, dofs sum in double)
  (*r)["a_diagonalized"] = m.ADiagonalized(); // -rom_diagonalize_a and in effect (A^ with at most two affine terms; dofs sum, or points' sum in float)
  (*r)["threads"]        = (long long)m.threads; // -rom_threads
  (*r)["threads_cpus"]   = (long long)m.ThreadCpus();
  (*r)["kacanov_rtol_primal"] = (double)m.loop.rtolPrimal;
  (*r)["kacanov_rtol_dual"]   = (double)m.loop.rtolDual;
}

void WriteReducedModel(const ReducedModel &m, RomWriter *w)
{
  const U64 N = m.Nfull, R = m.Rfull;
  m.par.Write(w);
  w->Dataset("/online/sizes", {6}, {(double)m.dim, (double)m.Nfull, (double)m.Npod, (double)m.nsup, (double)m.Rfull, 0.0});
  w->Dataset("/online/affine/A", {(U64)m.par.NumA(), N, N}, m.Aq);
  w->Dataset("/online/affine/f", {(U64)m.par.NumF(), N}, m.fq);
  w->Dataset("/online/kappa/meta", {2}, {m.kappaConst ? 1.0 : 0.0, (double)m.MkFull});
  w->Dataset("/online/gap/meta", {2}, {m.gapConst ? 1.0 : 0.0, (double)m.MgFull});
  if (m.kappaConst) w->Dataset("/online/kappa/constant", {N, R}, m.kConstant);
  else if (m.MkFull > 0) {
    std::vector<double> pts;
    for (PetscInt j = 0; j < m.MkFull; ++j) pts.insert(pts.end(), {(double)m.kPoint[j], (double)m.kMode[j]});
    w->Dataset("/online/kappa/points", {(U64)m.MkFull, 2}, pts);
    w->Dataset("/online/kappa/B", {(U64)m.MkFull, (U64)m.MkFull}, m.kB);
    w->Dataset("/online/kappa/C", {(U64)m.MkFull, N, R}, m.kC);
  }
  if (m.gapConst) w->Dataset("/online/gap/constant", {R}, m.gConstant);
  else if (m.MgFull > 0) {
    w->Dataset("/online/gap/points", {(U64)m.MgFull}, std::vector<double>(m.gPoint.begin(), m.gPoint.end()));
    w->Dataset("/online/gap/B", {(U64)m.MgFull, (U64)m.MgFull}, m.gB);
    w->Dataset("/online/gap/C", {(U64)m.MgFull, R}, m.gC);
  }
  w->Dataset("/online/dual_gram", {R, R}, m.dualGram);
  m.surface.Write(w);
  if (!m.cPoint.empty()) {
    w->Dataset("/online/ecsw/points", {(U64)m.cPoint.size()}, std::vector<double>(m.cPoint.begin(), m.cPoint.end()));
    w->Dataset("/online/ecsw/Pw", {R, (U64)m.cPoint.size()}, m.cPw);
  }
  w->Dataset("/online/hyper_default", {1}, {m.hyperDefault == ReducedModel::ContactMode::Cubature ? 1.0 : 0.0});
  // the online Kacanov loop's stopping tolerances the model was built with (-rom_kacanov_rtol_primal, _dual at
  // offline time: matched to the scene's accuracy targets, docs/online.md); online options override them
  w->Dataset("/online/kacanov_rtol", {2}, {(double)m.loop.rtolPrimal, (double)m.loop.rtolDual});
  // the arithmetic of the cubature's dof sum the model was validated with (-rom_ecsw_precision: 64 or 32 bits)
  w->Dataset("/online/ecsw_precision", {1}, {m.ecswSingle ? 32.0 : 64.0});
  if (m.MkDefault >= 0 || m.MgDefault >= 0) w->Dataset("/online/eim_default", {2}, {(double)m.MkDefault, (double)m.MgDefault});
  if (m.RSelected >= 1) w->Dataset("/online/dual_select", {1}, {(double)m.RSelected}); // the answer's R chosen on held-out solutions
  if (m.HasEnrichment()) { // the answer's sizes, the rest is the error estimate's enrichment (docs/error_estimate.md)
    w->Dataset("/online/estimate/default_sizes", {2}, {(double)m.NDefault, (double)m.RDefault});
    w->Dataset("/online/estimate/calibration", {2, 3}, {m.estimateScale[0], m.estimateScale[1], m.estimateScale[2], m.estimateFloor[0], m.estimateFloor[1], m.estimateFloor[2]});
    if (!m.massGram.empty()) w->Dataset("/online/estimate/mass_gram", {R, R}, m.massGram);
  }
  std::vector<std::pair<std::string, std::pair<std::vector<U64>, std::vector<double>>>> items;
  m.patch.Serialize(&items);
  for (auto &it : items) w->Dataset("/online/contact/" + it.first, it.second.first, it.second.second);
  const U64 nw = m.par.params.empty() ? 0 : m.warmMu.size() / m.par.params.size();
  if (nw > 0) {
    w->Dataset("/online/warm/mu", {nw, (U64)m.par.params.size()}, m.warmMu);
    w->Dataset("/online/warm/v", {nw, N}, m.warmV);
    w->Dataset("/online/warm/lambda", {nw, R}, m.warmL);
  }
}

PetscErrorCode ReducedModel::Open(const std::string &path)
{
  PetscFunctionBeginUser;
  // a failed Open left a half-replaced model that still solved (the old model's answer under the new file's name, or
  // a mix of the two files; audit of 2026-12-01): it now leaves no model, and Solve says so (CheckHasModel)
  const PetscErrorCode ierr = Read(path);
  failedOpen_               = ierr ? path : std::string();
  if (ierr) Nfull = 0;
  PetscFunctionReturn(ierr);
}

PetscErrorCode ReducedModel::Read(const std::string &path)
{
  std::string         fmt;
  int                 ver = 0;
  std::vector<double> d;

  PetscFunctionBeginUser;
  file = path;
  PetscCall(RomReadAttr(path, "format", &fmt));
  PetscCheck(fmt == "rbcontact-rom", PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s is not a ROM file (format '%s')", path.c_str(), fmt.c_str());
  PetscCall(RomReadVersion(path, &ver));
  PetscCheck(ver == 2, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s has format_version %d; the online stage reads version 2 (a file of 'offline -offline_stop bases' holds bases only: run offline without -offline_stop)", path.c_str(), ver);
  PetscCall(par.Read(path));
  PetscCall(ReadChecked(path, "/online/sizes", 6, &d));
  PetscCheck(d[0] == 2 || d[0] == 3, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/sizes gives the dimension %g (2 or 3): a corrupt file", path.c_str(), d[0]);
  for (int k = 1; k < 5; ++k)
    PetscCheck(d[k] >= 0 && d[k] == std::floor(d[k]), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/sizes entry %d is %g, not a size: a corrupt file", path.c_str(), k, d[k]);
  dim   = (PetscInt)d[0];
  Nfull = (PetscInt)d[1];
  Npod  = (PetscInt)d[2];
  nsup  = (PetscInt)d[3];
  Rfull = (PetscInt)d[4];
  PetscCheck(Nfull > 0 && Rfull > 0 && Npod + nsup == Nfull && nsup <= Rfull, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: inconsistent sizes N %" PetscInt_FMT " (POD %" PetscInt_FMT " + supremizers %" PetscInt_FMT "), R %" PetscInt_FMT, path.c_str(), Nfull, Npod, nsup, Rfull);
  const size_t N = Nfull, R = Rfull;
  PetscCall(ReadShaped(path, "/online/affine/A", {(U64)par.NumA(), N, N}, &Aq));
  PetscCall(ReadShaped(path, "/online/affine/f", {(U64)par.NumF(), N}, &fq));
  // {constant 0/1, M >= 0} (a negative M was blamed on -rom_Mk, "out of range [0, -3]")
  auto meta = [&](const char *name, bool *cst, PetscInt *M) -> PetscErrorCode {
    PetscFunctionBeginUser;
    PetscCall(ReadChecked(path, name, 2, &d));
    PetscCheck((d[0] == 0 || d[0] == 1) && d[1] >= 0 && d[1] == std::floor(d[1]), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s must hold {0 or 1, a size >= 0}, not {%g, %g}: a corrupt file", path.c_str(), name, d[0], d[1]);
    *cst = d[0] != 0;
    *M   = *cst ? 0 : (PetscInt)d[1];
    PetscFunctionReturn(0);
  };
  PetscCall(meta("/online/kappa/meta", &kappaConst, &MkFull));
  PetscCall(meta("/online/gap/meta", &gapConst, &MgFull));
  PetscCall(ReadShaped(path, "/online/dual_gram", {R, R}, &dualGram));
  PetscCall(CheckGram(path, "/online/dual_gram", dualGram, R));
  PetscCall(patch.Deserialize(path, "/online/contact"));
  PetscCheck(patch.N == Nfull && patch.dim == dim, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: the contact data has %" PetscInt_FMT " basis functions in %" PetscInt_FMT "D, the model %" PetscInt_FMT " in %" PetscInt_FMT "D (/online/contact against /online/sizes)", path.c_str(), patch.N, patch.dim, Nfull, dim);
  if (kappaConst) PetscCall(ReadShaped(path, "/online/kappa/constant", {N, R}, &kConstant));
  else if (MkFull > 0) {
    PetscCall(ReadShaped(path, "/online/kappa/points", {(U64)MkFull, 2}, &d));
    kPoint.resize(MkFull);
    kMode.resize(MkFull);
    for (PetscInt j = 0; j < MkFull; ++j) {
      kPoint[j] = (PetscInt)d[2 * j];
      kMode[j]  = (PetscInt)d[2 * j + 1];
      PetscCheck(kPoint[j] >= 0 && kPoint[j] < patch.NumPoints() && kMode[j] >= 0 && kMode[j] < Nfull, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/kappa/points: entry %" PetscInt_FMT " out of range", path.c_str(), j);
    }
    PetscCall(ReadShaped(path, "/online/kappa/B", {(U64)MkFull, (U64)MkFull}, &kB));
    PetscCall(ReadShaped(path, "/online/kappa/C", {(U64)MkFull, N, R}, &kC));
  }
  if (gapConst) PetscCall(ReadChecked(path, "/online/gap/constant", R, &gConstant));
  else if (MgFull > 0) {
    PetscCall(ReadChecked(path, "/online/gap/points", MgFull, &d));
    gPoint = ToInt(d);
    for (PetscInt p : gPoint) PetscCheck(p >= 0 && p < patch.NumPoints(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/gap/points out of range", path.c_str());
    PetscCall(ReadShaped(path, "/online/gap/B", {(U64)MgFull, (U64)MgFull}, &gB));
    PetscCall(ReadShaped(path, "/online/gap/C", {(U64)MgFull, R}, &gC));
  }
  warmMu.clear();
  warmV.clear();
  warmL.clear();
  {
    bool found;
    std::vector<unsigned long long> wd;
    PetscCall(RomReadOptional(path, "/online/warm/mu", &warmMu, &found, &wd));
    if (!found) warmMu.clear();
    else { // one row of the parameters per warm start (its shape was not checked: review of 2026-12-04)
      PetscCheck(wd.size() == 2 && wd[1] == (unsigned long long)par.params.size(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/warm/mu has %zu dimensions (the last %llu), expected n x %zu (the parameters): a corrupt file", path.c_str(), wd.size(), wd.empty() ? 0ULL : wd.back(), par.params.size());
      const size_t nw = warmMu.size() / std::max<size_t>(1, par.params.size());
      PetscCall(ReadShaped(path, "/online/warm/v", {nw, N}, &warmV));
      PetscCall(ReadShaped(path, "/online/warm/lambda", {nw, R}, &warmL));
    }
  }
  // optional (files of before 2026-11-23 hold the EIM only): the empirical cubature and the default method
  cPoint.clear();
  cPw.clear();
  hyperDefault = ContactMode::EIM;
  {
    bool found;
    PetscCall(RomReadOptional(path, "/online/ecsw/points", &d, &found));
    if (found) {
      cPoint = ToInt(d);
      for (PetscInt p : cPoint) PetscCheck(p >= 0 && p < patch.NumPoints(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/ecsw/points out of range", path.c_str());
      PetscCall(ReadShaped(path, "/online/ecsw/Pw", {R, (U64)cPoint.size()}, &cPw));
      OrderCubaturePoints(); // files written before 2026-11-27 hold them in the fit's order
    }
    PetscCall(RomReadOptional(path, "/online/hyper_default", &d, &found));
    if (found) {
      PetscCheck(d.size() == 1 && (d[0] == 0 || d[0] == 1), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/hyper_default is malformed (one value, 0 for the EIM or 1 for the cubature)", path.c_str());
      PetscCheck(d[0] == 0 || !cPoint.empty(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/hyper_default says the empirical cubature, but /online/ecsw/points is missing: a corrupt file", path.c_str());
      hyperDefault = d[0] == 1 ? ContactMode::Cubature : ContactMode::EIM;
    }
    // the EIM by default (no hyper_default: a file of before 2026-11-23) with no EIM term solved with no contact at all
    PetscCheck(hyperDefault != ContactMode::EIM || HasEIM(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s the EIM, but the file holds no EIM term (/online/kappa/meta, /online/gap/meta): a corrupt file", path.c_str(), found ? "/online/hyper_default says" : "without /online/hyper_default (files of before 2026-11-23) the hyper-reduction is");
  }
  mode_ = hyperDefault;
  { // optional (files written before 2026-11-25's eleventh session have none: the library's defaults): the online Kacanov tolerances
    bool found;
    PetscCall(RomReadOptional(path, "/online/kacanov_rtol", &d, &found));
    if (found) {
      PetscCheck(d.size() == 2 && d[0] > 0 && d[1] > 0 && d[0] < 1 && d[1] < 1, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/kacanov_rtol must hold 2 tolerances in (0, 1) (primal, dual)", path.c_str());
      loop.rtolPrimal = d[0];
      loop.rtolDual   = d[1];
    } else {
      loop.rtolPrimal = kRtolPrimal;
      loop.rtolDual   = kRtolDual;
    }
  }
  { // optional (files written before 2026-11-26 have none: double): the arithmetic of the cubature's dof sum
    bool found;
    PetscCall(RomReadOptional(path, "/online/ecsw_precision", &d, &found));
    PetscCheck(!found || (d.size() == 1 && (d[0] == 32 || d[0] == 64)), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/ecsw_precision must hold 32 or 64 (bits)", path.c_str());
    ecswSingle = found && d[0] == 32;
  }
  MkDefault = MgDefault = -1;
  { // optional: the EIM sizes chosen offline on held-out parameters (absent: all terms)
    bool found;
    PetscCall(RomReadOptional(path, "/online/eim_default", &d, &found));
    if (found) {
      // -1 (all) or a size in [1, M] (0 only where there is no such EIM: {0, x} solved with no contact, as -rom_Mk 0 would)
      auto ok = [](double v, PetscInt M) { return v == std::floor(v) && (v == -1 || (v >= 1 && v <= M) || (v == 0 && M == 0)); };
      PetscCheck(d.size() == 2 && ok(d[0], MkFull) && ok(d[1], MgFull), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/eim_default must hold 2 sizes, -1 or within [1, Mk = %" PetscInt_FMT "] and [1, Mg = %" PetscInt_FMT "]: a corrupt file", path.c_str(), MkFull, MgFull);
      MkDefault = (PetscInt)d[0];
      MgDefault = (PetscInt)d[1];
    }
  }
  RSelected = -1;
  { // optional (files of before 2026-11-27 have none): the answer's dual vectors chosen on held-out FOM solutions
    bool found;
    PetscCall(RomReadOptional(path, "/online/dual_select", &d, &found));
    if (found) {
      PetscCheck(d.size() == 1 && d[0] >= 1 && d[0] <= Rfull && d[0] == std::floor(d[0]), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/dual_select must hold one number of dual vectors within [1, %" PetscInt_FMT "]", path.c_str(), Rfull);
      RSelected = (PetscInt)d[0];
    }
  }
  NDefault = RDefault = -1;
  massGram.clear();
  for (int k = 0; k < 3; ++k) {
    estimateScale[k] = 1;
    estimateFloor[k] = 0;
  }
  { // optional (files of before 2026-11-26 have none): the answer's sizes inside the stored ones and the estimate's data
    bool found;
    PetscCall(RomReadOptional(path, "/online/estimate/default_sizes", &d, &found));
    if (!found) { // the estimate's data without its sizes: another model (all the stored modes) and no estimate, no word
      bool cal = false;
      PetscCall(RomReadOptional(path, "/online/estimate/calibration", &d, &cal));
      PetscCheck(!cal, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/estimate holds a calibration but no default_sizes (the answer's sizes inside the stored bases): a corrupt file", path.c_str());
    }
    if (found) {
      PetscCheck(d.size() == 2 && d[0] >= 1 && d[0] <= Npod && d[1] >= 1 && d[1] <= Rfull && d[0] == std::floor(d[0]) && d[1] == std::floor(d[1]), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/estimate/default_sizes must hold 2 sizes within [1, %" PetscInt_FMT "] (POD modes) and [1, %" PetscInt_FMT "] (dual vectors)", path.c_str(), Npod, Rfull);
      NDefault = (PetscInt)d[0];
      RDefault = (PetscInt)d[1];
      PetscCall(ReadChecked(path, "/online/estimate/calibration", 6, &d));
      for (int k = 0; k < 3; ++k) {
        PetscCheck(std::isfinite(d[k]) && d[k] > 0 && std::isfinite(d[3 + k]) && d[3 + k] >= 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/estimate/calibration: scale %g and floor %g of quantity %d must be > 0 and >= 0", path.c_str(), d[k], d[3 + k], k);
        estimateScale[k] = d[k];
        estimateFloor[k] = d[3 + k];
      }
      PetscCall(RomReadOptional(path, "/online/estimate/mass_gram", &massGram, &found));
      if (!found) massGram.clear();
      PetscCheck(massGram.empty() || massGram.size() == R * R, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/estimate/mass_gram has %zu entries, expected %zu", path.c_str(), massGram.size(), R * R);
      if (!massGram.empty()) PetscCall(CheckGram(path, "/online/estimate/mass_gram", massGram, R));
    }
  }
  { // optional (files of before 2026-11-25): the surface data of the max pressure and the contact half-width
    bool found;
    PetscCall(surface.Read(path, &found));
  }
  PetscCall(Truncate(-1, -1, -1, -1));
  PetscFunctionReturn(0);
}

bool ReducedModel::FusedPointSum() const { return cSingle_ && !cDofs_ && gemmFused && PointSumFusedAvailable(); }

PetscErrorCode ReducedModel::SetFromOptions()
{
  PetscInt  n = -1, r = -1, mk = -1, mg = -1, k = (PetscInt)ecswSum;
  char      hyper[64] = "";
  PetscBool hyperSet = PETSC_FALSE, sumSet = PETSC_FALSE;
  const char *sums[] = {"auto", "points", "dofs"}, *precisions[] = {"double", "single"};
  PetscInt    prec = ecswSingle ? 1 : 0;

  PetscFunctionBeginUser;
  PetscCall(CheckHasModel("SetFromOptions"));
  // an option without its value kept the default without a word (a trailing -rom_N cancelled a file's -rom_N 3)
  PetscCall(CheckValuesGiven(PETSC_COMM_SELF, {"-rom_kkt_tol", "-rom_warm_start_degree", "-rom_threads", "-rom_N", "-rom_R", "-rom_Mk", "-rom_Mg", "-rom_hyper", "-rom_ecsw_sum", "-rom_gemm", "-rom_ecsw_precision"})); // (the loop's: KacanovLoop)
  PetscCall(loop.SetFromOptions(PETSC_COMM_SELF, "rom_"));
  // one block, so that -help lists the reduced model's options with their values (prefix rom_)
  PetscOptionsBegin(PETSC_COMM_SELF, "rom_", "Reduced model (online solve)", "ReducedModel");
  PetscCall(PetscOptionsReal("-kkt_tol", "largest scaled KKT residual of the last reduced QP accepted", "", kktTol, &kktTol, NULL));
  PetscCall(PetscOptionsBool("-warm_start", "start from a fit of the stored training solutions", "", warmStart, &warmStart, NULL));
  PetscCall(PetscOptionsInt("-warm_start_degree", "degree of that fit with several parameters: 1 (affine) or 2 (quadratic)", "", warmDegree, &warmDegree, NULL));
  // a model read from a file; the offline stage's in-memory model sets its mode itself (SetContactMode)
  if (!file.empty()) PetscCall(PetscOptionsString("-hyper", "hyper-reduction of the contact terms among those stored: ecsw or eim (default: the offline stage's first)", "", hyper, hyper, sizeof hyper, &hyperSet));
  PetscCall(PetscOptionsEList("-ecsw_sum", "how the cubature's K^ is summed: by points, by patch dofs, or auto (fewer flops)", "", sums, 3, sums[k], &k, &sumSet));
  {
    const char *gemms[] = {"auto", "blas", "builtin", "fused"};
    PetscInt    gm      = gemmFused ? 0 : gemmBlas ? 1 : 2; // fused and auto differ only in the check below
    PetscBool   gmSet   = PETSC_FALSE;
    PetscCall(PetscOptionsEList("-gemm", "who sums the cubature's outer products (K^ = Pw' kappa, Q' theta): the BLAS's gemm, the built-in AVX2 kernels (for a reference BLAS), fused (the points' sum in single precision with kappa's rows, AVX-512) or auto (fused where the CPU has AVX-512F, else blas)", "", gemms, 4, gemms[gm], &gm, &gmSet));
    if (gmSet) {
      PetscCheck(gm != 3 || PointSumFusedAvailable(), PETSC_COMM_SELF, PETSC_ERR_SUP, "-rom_gemm fused needs a CPU with AVX-512F, which this one lacks: use -rom_gemm auto, blas or builtin");
      gemmBlas  = gm != 2;
      gemmFused = gm == 0 || gm == 3;
    }
  }
  PetscCall(PetscOptionsEList("-ecsw_precision", "arithmetic of the cubature's sum of K^ (by dofs or by points; g^ stays double): double or single, which leaves a noise floor near 1e-6 (u) / 1e-5 (lambda) on the Kacanov changes: for loose tolerances only (docs/online.md)", "", precisions, 2, precisions[prec], &prec, NULL));
  PetscCall(PetscOptionsBool("-factor_a_once", "where A^ does not depend on mu (and the cubature sums by dofs in double precision): factor it once and sum K^ L^{-T} for the QP directly (docs/online.md \"A factored once\")", "", factorAOnce, &factorAOnce, NULL));
  PetscCall(PetscOptionsBool("-diagonalize_a", "where A^ has two affine terms (or one that depends on mu) and the cubature sums by dofs (or by points in single precision): diagonalize A^(mu) for every mu at once (a generalized eigenproblem) and solve the QP where A^ is the identity (docs/online.md \"A diagonalized once\")", "", diagonalizeA, &diagonalizeA, NULL));
  PetscCall(PetscOptionsInt("-threads", "threads of the cubature's contact terms (the patch displacement, the points' scans and kernels, the points' sum; docs/online.md \"Threads\")", "", threads, &threads, NULL));
  PetscCall(PetscOptionsInt("-N", "POD modes used (default: the answer's, all but the estimate's enrichment)", "", n, &n, NULL));
  PetscCall(PetscOptionsInt("-R", "dual vectors used, with their supremizers (default: the answer's: the offline stage's held-out choice, /online/dual_select, else all but the estimate's enrichment)", "", r, &r, NULL));
  PetscCall(PetscOptionsBool("-error_estimate", "estimate the error of every solve in the enriched spaces of the file (docs/error_estimate.md)", "", errorEstimate, &errorEstimate, NULL));
  PetscCall(PetscOptionsInt("-Mk", "EIM terms of kappa used (default: the offline selection)", "", mk, &mk, NULL));
  PetscCall(PetscOptionsInt("-Mg", "EIM terms of the gap used (default: the offline selection)", "", mg, &mg, NULL));
  PetscOptionsEnd();
  PetscCheck(warmDegree == 1 || warmDegree == 2, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_warm_start_degree %" PetscInt_FMT ": 1 (affine) or 2 (quadratic) expected", warmDegree);
  PetscCheck(kktTol > 0 && std::isfinite(kktTol), PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_kkt_tol %g must be a finite number > 0", (double)kktTol);
  // -1 is the default; another negative size meant it too without a word
  // (it said "a size >= 0" where 0 was refused next)
  for (const auto &o : {std::make_pair("-rom_N", n), std::make_pair("-rom_R", r), std::make_pair("-rom_Mk", mk), std::make_pair("-rom_Mg", mg)})
    PetscCheck(o.second >= -1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "%s %" PetscInt_FMT ": a size >= 1, or -1 for the file's default", o.first, o.second);
  PetscCheck(threads >= 1 && threads <= 256, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_threads %" PetscInt_FMT " must be in [1, 256]", threads);
  // no EIM term at all is no contact term (Mk) or no gap (Mg): a converged answer without contact; the internal
  // callers (the EIM's size selection) may still truncate to 0
  PetscCheck(mk != 0 || MkFull == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_Mk 0 out of range [1, %" PetscInt_FMT "]: without an EIM term of kappa the reduced model has no contact (-1: the offline selection)", MkFull);
  PetscCheck(mg != 0 || MgFull == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_Mg 0 out of range [1, %" PetscInt_FMT "]: without an EIM term of the gap the reduced model has no gap (-1: the offline selection)", MgFull);
  PetscCall(qp.SetFromOptions("rom_"));
  qp.residuals = false; // SolveLoop computes them once, for the returned pair
  PetscCall(qpEst_.SetFromOptions("rom_"));
  qpEst_.residuals = false;
  if (hyperSet) {
    std::string h(hyper);
    h = h.substr(0, h.find(',')); // a list (the offline stage's form): its first entry
    if (h == "ecsw") {
      PetscCheck(HasCubature(), PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "-rom_hyper ecsw: the ROM file %s holds no empirical cubature (build it with offline -rom_hyper ecsw)", file.c_str());
      SetContactMode(ContactMode::Cubature);
    } else if (h == "eim") {
      PetscCheck(HasEIM(), PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "-rom_hyper eim: the ROM file %s holds no EIM (build it with offline -rom_hyper eim or ecsw,eim)", file.c_str());
      SetContactMode(ContactMode::EIM);
    } else SETERRQ(PETSC_COMM_SELF, PETSC_ERR_ARG_UNKNOWN_TYPE, "-rom_hyper: unknown value '%s' (eim or ecsw)", hyper);
  }
  if (sumSet) ecswSum = (EcswSum)k;
  ecswSingle = prec == 1;
  PetscCall(Truncate(n, r, mk, mg));
  PetscFunctionReturn(0);
}

PetscErrorCode ReducedModel::CheckHasModel(const char *method) const
{
  PetscFunctionBeginUser;
  // a default-constructed model "solved" (converged, empty solution) and blamed -rom_N ("out of range [1, 0]")
  PetscCheck(Nfull > 0 || failedOpen_.empty(), PETSC_COMM_SELF, PETSC_ERR_ORDER, "ReducedModel::%s: no reduced model: the last Open (of %s) failed", method, failedOpen_.c_str());
  PetscCheck(Nfull > 0, PETSC_COMM_SELF, PETSC_ERR_ORDER, "ReducedModel::%s: no reduced model (Open a ROM file first)", method);
  PetscFunctionReturn(0);
}

PetscErrorCode ReducedModel::Truncate(PetscInt n, PetscInt r, PetscInt mk, PetscInt mg)
{
  PetscFunctionBeginUser;
  PetscCall(CheckHasModel("Truncate"));
  sizesGiven_ = n >= 0 || r >= 0;
  if (n < 0) n = NDefault >= 1 ? std::min(NDefault, Npod) : Npod;
  if (r < 0) r = RDefault >= 1 ? std::min(RDefault, Rfull) : RSelected >= 1 ? std::min(RSelected, Rfull) : Rfull;
  if (mk < 0) mk = MkDefault >= 0 ? std::min(MkDefault, MkFull) : MkFull;
  if (mg < 0) mg = MgDefault >= 0 ? std::min(MgDefault, MgFull) : MgFull;
  PetscCheck(n >= 1 && n <= Npod, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_N %" PetscInt_FMT " out of range [1, %" PetscInt_FMT "] (POD modes in %s)", n, Npod, file.c_str());
  PetscCheck(r >= 1 && r <= Rfull, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_R %" PetscInt_FMT " out of range [1, %" PetscInt_FMT "]", r, Rfull);
  // (a file without an EIM said "out of range [0, 0]")
  PetscCheck(mk <= 0 || MkFull > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_Mk %" PetscInt_FMT ": the ROM file %s holds no EIM of kappa (its hyper-reduction is the cubature, -rom_hyper ecsw; its size is Mc, chosen offline)", mk, file.c_str());
  PetscCheck(mg <= 0 || MgFull > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_Mg %" PetscInt_FMT ": the ROM file %s holds no EIM of the gap (its hyper-reduction is the cubature, -rom_hyper ecsw, or the gap is affine)", mg, file.c_str());
  // (the range said [0, M] where -rom_Mk 0 was refused as out of [1, M]; 0 stays for the internal callers)
  PetscCheck(mk >= 0 && mk <= MkFull, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_Mk %" PetscInt_FMT " out of range [1, %" PetscInt_FMT "]", mk, MkFull);
  PetscCheck(mg >= 0 && mg <= MgFull, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-rom_Mg %" PetscInt_FMT " out of range [1, %" PetscInt_FMT "]", mg, MgFull);
  geomMu_.clear();
  cols_ = ReducedColumns(Npod, nsup, n, r);
  r_  = r;
  mk_ = mk;
  mg_ = mg;
  const PetscInt Na = (PetscInt)cols_.size();
  { // the affine terms of the active columns, contiguous (Operators: A(mu) by axpys instead of strided gathers)
    const size_t qa = Nfull > 0 ? Aq.size() / ((size_t)Nfull * Nfull) : 0;
    aAct_.resize(qa * Na * Na);
    for (size_t q = 0; q < qa; ++q)
      for (PetscInt j = 0; j < Na; ++j)
        for (PetscInt i = 0; i < Na; ++i) aAct_[(q * Na + j) * Na + i] = Aq[(q * Nfull + cols_[i]) * Nfull + cols_[j]];
  }
  // kappa terms restricted to the active rows/columns: Kc_[j] = C_j(0:r, cols) (R x N column-major)
  Kc_.assign((size_t)mk * r * Na, 0.0);
  for (PetscInt j = 0; j < mk; ++j)
    for (PetscInt c = 0; c < Na; ++c)
      for (PetscInt i = 0; i < r; ++i) Kc_[(size_t)j * r * Na + i + (size_t)r * c] = kC[((size_t)j * Nfull + cols_[c]) * Rfull + i];
  KB_.assign((size_t)mk * mk, 0.0);
  for (PetscInt i = 0; i < mk; ++i)
    for (PetscInt j = 0; j < mk; ++j) KB_[i + (size_t)mk * j] = kB[i + (size_t)MkFull * j];
  Gc_.assign((size_t)mg * r, 0.0);
  for (PetscInt j = 0; j < mg; ++j)
    for (PetscInt i = 0; i < r; ++i) Gc_[(size_t)j * r + i] = gC[(size_t)j * Rfull + i];
  GB_.assign((size_t)mg * mg, 0.0);
  for (PetscInt i = 0; i < mg; ++i)
    for (PetscInt j = 0; j < mg; ++j) GB_[i + (size_t)mg * j] = gB[i + (size_t)MgFull * j];
  // the patch points to evaluate (each gives kappa for every mode and gamma)
  evalPoints_.clear();
  kPos_.assign(mk, 0);
  gPos_.assign(mg, 0);
  auto pos = [&](PetscInt p) {
    auto it = std::find(evalPoints_.begin(), evalPoints_.end(), p);
    if (it != evalPoints_.end()) return (PetscInt)(it - evalPoints_.begin());
    evalPoints_.push_back(p);
    return (PetscInt)evalPoints_.size() - 1;
  };
  for (PetscInt j = 0; j < mk; ++j) kPos_[j] = pos(kPoint[j]);
  nkEval_ = (PetscInt)evalPoints_.size(); // the points needing kappa come first
  for (PetscInt j = 0; j < mg; ++j) gPos_[j] = pos(gPoint[j]);
  // cubature weights of the active rows, point by point (M x r)
  const PetscInt rp = PaddedRows(r);
  cPwT_.assign(cPoint.size() * (size_t)rp, 0.0);
  for (size_t p = 0; p < cPoint.size(); ++p)
    for (PetscInt i = 0; i < r; ++i) cPwT_[p * rp + i] = cPw[(size_t)i * cPoint.size() + p];
  { // the cubature's sum: by points or by patch dofs, whichever costs fewer flops (-rom_ecsw_sum); the points'
    // row combination gathers its rows from theta and counts twice (measured: docs/online.md)
    const PetscInt nd = patch.TermDofs(), Mc = (PetscInt)cPoint.size(), nt = 2 * patch.dim * patch.dim; // nt: terms per point (P1: 2 sides x dim nodes x dim); nd: the dofs terms fall on
    // (single precision: the sums do twice the work per vector operation, count half; the gemm of the BLAS half
    // the built-in kernels' time per flop, measured: docs/online.md "The BLAS for the cubature's sums")
    const double sp = ecswSingle ? 0.5 : 1.0, gm = gemmBlas ? 0.5 : 1.0;
    // (the points' row combination: every stored column in double, kappa's used columns in float in single precision)
    const double byPoints = (double)Mc * (2.0 * nt * (ecswSingle ? sp * PaddedRows(Na, 8) : Nfull)) + sp * gm * (double)Mc * rp * (Na + 1), byDofs = sp * ((double)Mc * rp * (nt + 1) + gm * (double)nd * rp * Na);
    cDofs_ = Mc > 0 && (ecswSum == EcswSum::Dofs || (ecswSum == EcswSum::Auto && byDofs < byPoints));
    cNd_   = nd;
    cThetaT_.clear();
    cSingle_ = Mc > 0 && ecswSingle;
    if (cDofs_) {
      cThetaT_.assign((size_t)Na * nd, 0.0);
      for (PetscInt c = 0; c < Na; ++c)
        for (PetscInt a = 0; a < nd; ++a) cThetaT_[(size_t)c * nd + a] = patch.theta[(size_t)a * patch.N + cols_[c]];
      cQ_.assign((size_t)nd * rp, 0.0);
    }
    if (cDofs_ || cSingle_) { // the points' terms (the single points' sum combines kappa from them in float)
      cNt_.assign(Mc, 0);
      cRow_.assign((size_t)Mc * ContactPatch::MaxTerms, 0);
      cCoef_.assign((size_t)Mc * ContactPatch::MaxTerms, 0.0);
    }
    cPwTs_.clear();
    cThetaTs_.clear();
    cThetaFs_.clear();
    cXs_.clear();
    if (cSingle_) {
      const PetscInt rps = PaddedRows(r, 8);
      cPwTs_.assign((size_t)Mc * rps, 0.0f);
      for (PetscInt p = 0; p < Mc; ++p)
        for (PetscInt i = 0; i < r; ++i) cPwTs_[(size_t)p * rps + i] = (float)cPwT_[(size_t)p * rp + i];
      if (cDofs_) cThetaTs_.assign(cThetaT_.begin(), cThetaT_.end());
      else { // theta's used columns in float, rows padded to 8 with zeros (every patch dof x ldf): the nodal
        // displacement and kappa's rows in float
        const PetscInt ldf = PaddedRows(Na, 8), nr = patch.nnode * patch.dim;
        cThetaFs_.assign((size_t)nr * ldf, 0.0f);
        for (PetscInt a = 0; a < nr; ++a)
          for (PetscInt c = 0; c < Na; ++c) cThetaFs_[(size_t)a * ldf + c] = (float)patch.theta[(size_t)a * patch.N + cols_[c]];
        cXs_.assign((size_t)Mc * ldf, 0.0f);
      }
    }
  }
  // A^ independent of mu and the dofs sum in double: A^ = L L' once, and L^{-1} theta(:, cols)' for the sum of K^ L^{-T}
  aFactored_ = false;
  cThetaTw_.clear();
  if (factorAOnce && cDofs_ && !cSingle_ && Na > 0 && par.AConstant()) {
    std::vector<PetscReal> mu0(par.params.size()), A0, f0;
    for (size_t i = 0; i < mu0.size(); ++i) mu0[i] = par.params[i].def;
    AffineAt(mu0, cols_.data(), Na, &A0, &f0);
    ReducedQPInfo info;
    PetscCall(qp.FactorA(Na, A0.data(), &info));
    if (info.status == ReducedQPStatus::Ok) { // (else the per-solve path, whose QP reports the failure)
      // (L^{-1} theta(:, cols)')' = theta(:, cols) L^{-T}: cThetaT_ read as the nd x Na column-major theta(:, cols)
      cThetaTw_.resize(cThetaT_.size());
      RightSolveT(cNd_, Na, qp.FactorL(), cThetaT_.data(), cThetaTw_.data());
      aFactored_ = true;
    }
  }
  // A^ with at most two affine terms, not all constant (a constant A^ is -rom_factor_a_once's): V' A^(mu) V diagonal for
  // every mu, and (theta(:, cols) V)' for the sum of K^ V
  adiag_ = AffineDiagonalization();
  cThetaTsw_.clear();
  cRowsW_ = false;
  if (!aFactored_ && diagonalizeA && (cDofs_ || cSingle_) && Na > 0 && !par.AConstant() && (par.thetaA.size() == 1 || par.thetaA.size() == 2) && aAct_.size() == par.thetaA.size() * (size_t)Na * Na) {
    std::vector<PetscReal> mu0(par.params.size()), th0;
    for (size_t i = 0; i < mu0.size(); ++i) mu0[i] = par.params[i].def;
    par.ThetaA(mu0, &th0);
    bool ok = false;
    PetscCall(adiag_.Set(Na, th0, aAct_.data(), &ok));
    const PetscBLASInt n = (PetscBLASInt)Na;
    const PetscScalar  a1 = 1, b0 = 0;
    if (ok && cDofs_) { // cThetaT_ read as the nd x Na column-major theta(:, cols), times V
      std::vector<PetscReal> tw((size_t)cNd_ * Na);
      const PetscBLASInt     m = (PetscBLASInt)cNd_;
      if (cNd_ > 0) BLASgemm_("N", "N", &m, &n, &n, &a1, cThetaT_.data(), &m, adiag_.V().data(), &n, &b0, tw.data(), &m);
      if (cSingle_) cThetaTsw_.assign(tw.begin(), tw.end());
      else cThetaTw_ = std::move(tw);
    } else if (ok) { // the points' sum in float: its rows theta(a, cols) replaced by theta(a, cols) V (the same storage), the
      // nodal displacement from them and V^{-1} v = V' A^(mu0) v
      const PetscInt         ldf = PaddedRows(Na, 8), nr = patch.nnode * patch.dim;
      std::vector<PetscReal> T((size_t)nr * Na), W((size_t)nr * Na);
      for (PetscInt a = 0; a < nr; ++a)
        for (PetscInt c = 0; c < Na; ++c) T[(size_t)a * Na + c] = patch.theta[(size_t)a * patch.N + cols_[c]];
      const PetscBLASInt m = (PetscBLASInt)nr;
      if (nr > 0) BLASgemm_("T", "N", &n, &m, &n, &a1, adiag_.V().data(), &n, T.data(), &n, &b0, W.data(), &n); // W(:, a) = V' theta(a, cols)'
      for (PetscInt a = 0; a < nr; ++a)
        for (PetscInt c = 0; c < Na; ++c) cThetaFs_[(size_t)a * ldf + c] = (float)W[(size_t)a * Na + c];
      cRowsW_ = true;
    } // (else the per-solve factorization, whose QP reports a matrix that is not positive definite)
  }
  if (!P_.empty()) {
    const size_t Q = P_.size() / Rfull;
    Pact_.assign(P_.begin(), P_.begin() + (size_t)r * Q);
  }
  const size_t np = std::max<size_t>(std::max(evalPoints_.size(), cPoint.size()), full_ ? full_->points.size() : 0);
  kap_.assign(np * Nfull, 0.0);
  gam_.assign(np, 0.0);
  phi_.assign(std::max(mk, mg) + 1, 0.0);
  vals_.assign(std::max(mk, mg) + 1, 0.0);
  K_.assign((size_t)r * Na, 0.0);
  g_.assign(r, 0.0);
  A_.assign((size_t)Na * Na, 0.0);
  f_.assign(Na, 0.0);
  qp.Reserve(Na, r);
  ePwT_.clear();
  eThetaT_.clear();
  if (Na < Nfull || r < Rfull) { // the error estimate's enriched terms (EstimateError): every stored row and column
    qpEst_.Reserve(Nfull, Rfull);
    const PetscInt rpf = PaddedRows(Rfull), Mc = (PetscInt)cPoint.size(), nd = cNd_;
    ePwT_.assign((size_t)Mc * rpf, 0.0);
    for (PetscInt p = 0; p < Mc; ++p)
      for (PetscInt i = 0; i < Rfull; ++i) ePwT_[(size_t)p * rpf + i] = cPw[(size_t)i * Mc + p];
    if (cDofs_) {
      eThetaT_.assign((size_t)Nfull * nd, 0.0);
      for (PetscInt c = 0; c < Nfull; ++c)
        for (PetscInt a = 0; a < nd; ++a) eThetaT_[(size_t)c * nd + a] = patch.theta[(size_t)a * patch.N + c];
    }
  }
  PetscFunctionReturn(0);
}

void ReducedModel::SetExactContact(std::shared_ptr<ContactPatch> full, const std::vector<PetscReal> &P)
{
  geomMu_.clear();
  full_ = full;
  P_    = P;
}

void ReducedModel::Operators(const std::vector<PetscReal> &mu, std::vector<PetscReal> *A, std::vector<PetscReal> *f) const { AffineAt(mu, cols_.data(), (PetscInt)cols_.size(), A, f); }

void ReducedModel::AffineAt(const std::vector<PetscReal> &mu, const PetscInt *cols, PetscInt n, std::vector<PetscReal> *A, std::vector<PetscReal> *f) const
{
  thread_local std::vector<PetscReal> thA, thF;
  par.ThetaA(mu, &thA);
  par.ThetaF(mu, &thF);
  auto col = [&](PetscInt i) { return cols ? cols[i] : i; };
  f->assign(n, 0.0);
  if (A) { // (nullptr: f only)
    A->assign((size_t)n * n, 0.0);
    if (cols == cols_.data() && aAct_.size() == thA.size() * n * n) { // the active columns: Truncate's contiguous copy
      PetscReal *a = A->data();
      for (size_t q = 0; q < thA.size(); ++q) {
        const PetscReal t = thA[q], *c = &aAct_[q * (size_t)n * n];
        for (size_t e = 0; e < (size_t)n * n; ++e) a[e] += t * c[e];
      }
    } else
      for (size_t q = 0; q < thA.size(); ++q)
        for (PetscInt j = 0; j < n; ++j)
          for (PetscInt i = 0; i < n; ++i) (*A)[i + (size_t)n * j] += thA[q] * Aq[(q * Nfull + col(i)) * Nfull + col(j)];
  }
  for (size_t q = 0; q < thF.size(); ++q)
    for (PetscInt i = 0; i < n; ++i) (*f)[i] += thF[q] * fq[q * Nfull + col(i)];
}

// Forward substitution with the unit lower triangular B (M x M, column-major).
static void Forward(PetscInt M, const PetscReal *B, const PetscReal *b, PetscReal *x)
{
  for (PetscInt i = 0; i < M; ++i) {
    PetscReal s = b[i];
    for (PetscInt j = 0; j < i; ++j) s -= B[i + (size_t)M * j] * x[j];
    x[i] = s / B[i + (size_t)M * i];
  }
}

// [K g] (rp x (nc + 1), column-major, g last) = sum over the cubature points of PwT(p, :) (M x rp, point-major) times
// [kappa(p, cols) gamma(p)] of the last point evaluation (cols: nc columns of the stored basis, nullptr: the first nc).
// By patch dofs (cDofs_: Q(a, :) = sum_p coef(p, a) PwT(p, :), then K = Q' theta(:, cols) with ThetaT = theta(:, cols)',
// one blocked kernel over the dofs) or by points (the columns point-contiguous in X, one blocked kernel).
void ReducedModel::CubatureSum(PetscInt rp, const std::vector<PetscReal> &PwT, const std::vector<PetscReal> &ThetaT, const PetscInt *cols, PetscInt nc, std::vector<PetscReal> *Q, std::vector<PetscReal> *X, std::vector<PetscReal> *Kp)
{
  const PetscInt M = (PetscInt)cPoint.size();
  Kp->resize((size_t)rp * (nc + 1));
  if (cDofs_) {
    const PetscInt nd = cNd_; // the dofs terms fall on (ContactPatch::TermDofs)
    Q->assign((size_t)nd * rp, 0.0);
    PetscReal *g = Kp->data() + (size_t)nc * rp;
    std::fill(g, g + rp, 0.0);
    ScatterRows(M, rp, cNt_.data(), ContactPatch::MaxTerms, cRow_.data(), cCoef_.data(), PwT.data(), gam_.data(), Q->data(), g);
    SumOfOuterProducts(nd, rp, nc, Q->data(), ThetaT.data(), Kp->data());
    return;
  }
  // the points' sum from the rows of kappa (its leading nc columns in place; other columns gathered row by row)
  bool prefix = true;
  for (PetscInt c = 0; cols && c < nc && prefix; ++c) prefix = cols[c] == c;
  const PetscReal *kx  = kap_.data();
  PetscInt         ldx = Nfull;
  if (!prefix) {
    X->resize((size_t)M * std::max<PetscInt>(nc, 1));
    for (PetscInt p = 0; p < M; ++p)
      for (PetscInt c = 0; c < nc; ++c) (*X)[(size_t)p * nc + c] = kap_[(size_t)p * Nfull + cols[c]];
    kx  = X->data();
    ldx = std::max<PetscInt>(nc, 1);
  }
  SumOfOuterProductsRows(M, rp, nc, PwT.data(), kx, ldx, Kp->data());
  SumOfOuterProductsRows(M, rp, 1, PwT.data(), gam_.data(), 1, Kp->data() + (size_t)nc * rp); // g^
}

void ReducedModel::OrderCubaturePoints()
{
  const size_t M = cPoint.size();
  if (M < 2 || cPw.size() % M) return;
  const size_t R = cPw.size() / M; // Pw's rows (Rfull)
  std::vector<size_t> perm(M);
  std::iota(perm.begin(), perm.end(), (size_t)0);
  const auto key = [&](size_t a) { return std::make_pair(patch.points[cPoint[a]].facet, cPoint[a]); };
  std::stable_sort(perm.begin(), perm.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
  std::vector<PetscInt>  pt(M);
  std::vector<PetscReal> pw(cPw.size());
  for (size_t j = 0; j < M; ++j) {
    pt[j] = cPoint[perm[j]];
    for (size_t i = 0; i < R; ++i) pw[i * M + j] = cPw[i * M + perm[j]];
  }
  cPoint.swap(pt);
  cPw.swap(pw);
}

PetscInt ReducedModel::ThreadCpus() const { return (PetscInt)(pool_.cpus.empty() ? ForkJoin::CallerCpus().size() : pool_.cpus.size()); }

PetscInt ReducedModel::ContactTerms(const std::vector<PetscReal> &mu, const PetscReal *v, PetscReal *K, PetscReal *g) { return ContactTerms(mu, v, K, g, false); }

PetscInt ReducedModel::ContactTerms(const std::vector<PetscReal> &mu, const PetscReal *v, PetscReal *K, PetscReal *g, bool factored)
{
  const PetscInt Na = (PetscInt)cols_.size(), r = r_;
  thread_local std::vector<PetscReal> vfull;
  vfull.assign(Nfull, 0.0);
  for (PetscInt i = 0; i < Na; ++i) vfull[cols_[i]] = v[i];
  PetscInt out = 0;
  if (mode_ == ContactMode::Exact && full_) {
    ContactPatch  &P = *full_;
    const PetscInt Q = P.NumPoints();
    if (geomMu_ != mu) {
      P.SetGeometry(&par.map, mu);
      geomMu_ = mu;
    }
    P.SetReduced(vfull.data());
    allPoints_.resize(Q);
    for (PetscInt p = 0; p < Q; ++p) allPoints_[p] = p;
    wn_.resize((size_t)Q * P.dim);
    out = P.Evaluate(allPoints_.data(), Q, kap_.data(), gam_.data(), nullptr, wn_.data());
    wnMode_ = ContactMode::Exact;
    // K = Pact kappa(:, cols), g = Pact gamma (Pact r x Q, kappa Q x Nfull, both row-major) by the BLAS: the plain
    // loops strode through kappa by Nfull and took 18 % of an offline stage at 41k dofs (docs/hyper_reduction.md)
    const PetscReal *B   = kap_.data();
    PetscInt         ldb = Nfull;
    bool             lead = true; // the active columns are the leading ones
    for (PetscInt c = 0; c < Na && lead; ++c) lead = cols_[c] == c;
    if (!lead) { // gather the active columns (Q x Na)
      kapAct_.resize((size_t)Q * Na);
      for (PetscInt p = 0; p < Q; ++p)
        for (PetscInt c = 0; c < Na; ++c) kapAct_[(size_t)p * Na + c] = kap_[(size_t)p * Nfull + cols_[c]];
      B   = kapAct_.data();
      ldb = Na;
    }
    PetscBLASInt      m = (PetscBLASInt)r, n = (PetscBLASInt)Na, k = (PetscBLASInt)Q, lda = (PetscBLASInt)Q, lb = (PetscBLASInt)ldb, one = 1;
    const PetscScalar a1 = 1, b0 = 0;
    if (r > 0 && Q > 0) {
      if (Na > 0) BLASgemm_("T", "T", &m, &n, &k, &a1, Pact_.data(), &lda, B, &lb, &b0, K, &m);
      BLASgemv_("T", &k, &m, &a1, Pact_.data(), &lda, gam_.data(), &one, &b0, g, &one);
    } else {
      std::fill(K, K + (size_t)r * Na, 0.0);
      std::fill(g, g + r, 0.0);
    }
    return out;
  }
  if (mode_ == ContactMode::Cubature) {
    // K^ = sum_p xi_p (W'Psi)(:, p) kappa(p, :), g^ likewise, at the cubature points only
    const PetscInt M = (PetscInt)cPoint.size();
    if (geomMu_ != mu) {
      patch.SetGeometry(&par.map, mu);
      geomMu_ = mu;
    }
    // -rom_threads: the regions below split over the points (or the patch's rows) on nth threads
    const int nth = (int)threads;
    static std::atomic<int> checkedFor{1}; // the largest thread count checked in this process (every model, its copies, validate's threads)
    int                     seen = checkedFor.load(std::memory_order_relaxed);
    if (nth > seen && checkedFor.compare_exchange_strong(seen, nth)) { // the first solve on this many threads: say so when they must share cores
      // (once per job and thread count, by the first rank of PETSC_COMM_WORLD: mpirun binds every rank alike, and the
      // solves are not collective, so the ranks cannot agree on one message)
      const PetscInt nc = ThreadCpus();
      PetscMPIInt    wr = 0;
      if (MPI_Comm_rank(PETSC_COMM_WORLD, &wr) != MPI_SUCCESS) wr = 0;
      if (wr == 0 && nc > 0 && nc < nth) PetscCallAbort(PETSC_COMM_SELF, PetscFPrintf(PETSC_COMM_SELF, PETSC_STDERR, "WARNING: -rom_threads %d, but this process may run on %d CPU(s) only, so the threads share them and the solve may run slower than on one thread (mpirun binds each rank to a core by default: run with mpirun --bind-to none, or --map-by slot:PE=%d)\n", nth, (int)nc, nth));
    }
    ForkJoin *pool = nth > 1 ? &pool_.Get(nth) : nullptr;
    // (ContactTerms returns a count, not an error code: the events' calls abort on an error)
    PetscCallAbort(PETSC_COMM_SELF, RegisterEvents()); // (callers other than Solve: the offline stage's)
    auto event = [](PetscLogEvent e, bool begin) { PetscCallAbort(PETSC_COMM_SELF, begin ? PetscLogEventBegin(e, 0, 0, 0, 0) : PetscLogEventEnd(e, 0, 0, 0, 0)); };
    event(ROM_CubDisp, true);
    if (cSingle_ && !cDofs_) { // U = uD + theta(:, cols) v from theta's float copy (half the bytes of the double theta)
      const PetscInt       ldf = PaddedRows(Na, 8), rows = patch.nnode * patch.dim;
      thread_local std::vector<float>     vf;
      thread_local std::vector<PetscReal> U;
      vf.assign(ldf, 0.0f);
      if (cRowsW_) { // the rows are theta(:, cols) V: U = uD + (theta V)(V^{-1} v)
        thread_local std::vector<PetscReal> w;
        w.resize(Na);
        const PetscBLASInt n = (PetscBLASInt)Na, one = 1;
        const PetscScalar  a1 = 1, b0 = 0;
        BLASgemv_("N", &n, &n, &a1, adiag_.VInverse().data(), &n, v, &one, &b0, w.data(), &one);
        for (PetscInt i = 0; i < Na; ++i) vf[i] = (float)w[i];
      } else
        for (PetscInt i = 0; i < Na; ++i) vf[i] = (float)v[i];
      U.resize((size_t)rows);
      // (pointers: a thread_local named inside the lambda would be the worker's own)
      const float *vfp = vf.data();
      PetscReal   *Up  = U.data();
      ForkJoin::ForParts(pool, rows, [&](PetscInt a, PetscInt b, int) {
        if (b > a) RowDotsSingle(b - a, ldf, cThetaFs_.data() + (size_t)a * ldf, vfp, patch.uD.data() + a, Up + a);
      });
      patch.SetNodal(U, pool);
    } else patch.SetReduced(vfull.data());
    event(ROM_CubDisp, false);
    const PetscInt rp = PaddedRows(r);
    SetGemmBlas(gemmBlas); // this model's choice for the sums below (-rom_gemm)
    wn_.resize((size_t)M * patch.dim);
    wnMode_ = ContactMode::Cubature;
    event(ROM_CubPoints, true);
    if (cDofs_ || cSingle_) { // the points' closest-point scans and kernels, nth parts of the points
      std::atomic<PetscInt> outs{0}; // (no allocation on the default, serial path)
      ForkJoin::ForParts(pool, M, [&](PetscInt a, PetscInt b, int) {
        const size_t mt = ContactPatch::MaxTerms, d = patch.dim;
        if (b > a) outs += patch.EvaluateCoefficients(cPoint.data() + a, b - a, cNt_.data() + a, cRow_.data() + a * mt, cCoef_.data() + a * mt, gam_.data() + a, wn_.data() + a * d);
      });
      out += outs.load();
    } else out = patch.Evaluate(cPoint.data(), M, kap_.data(), gam_.data(), nullptr, wn_.data());
    event(ROM_CubPoints, false);
    event(ROM_CubSum, true);
    kapStale_ = cSingle_ && !cDofs_; // kappa's double rows not formed (EstimateError forms them from the terms)
    if (cSingle_) {
      const PetscInt rps = PaddedRows(r, 8), nd = cNd_;
      cK_.resize((size_t)rps * Na);
      if (cDofs_) {
        cQs_.assign((size_t)nd * rps, 0.0f);
        ScatterRowsSingle(M, rps, cNt_.data(), ContactPatch::MaxTerms, cRow_.data(), cCoef_.data(), cPwTs_.data(), cQs_.data());
        SumOfOuterProductsSingle(nd, rps, Na, cQs_.data(), factored && ADiagonalized() ? cThetaTsw_.data() : cThetaTs_.data(), cK_.data());
      } else { // the points' sum: kappa's used columns combined in float from theta's (cThetaFs_), then one sum
        // nth parts of the points, each summed into its own K (the first into cK_), then added in double
        const PetscInt ldf = PaddedRows(Na, 8);
        const size_t   mt  = ContactPatch::MaxTerms;
        // with g^ in double over the same parts (its weights are M x rp doubles: memory traffic worth splitting)
        if ((int)cKt_.size() < nth - 1) cKt_.resize(nth - 1);
        if ((int)cGt_.size() < nth - 1) cGt_.resize(nth - 1);
        for (int t = 1; t < nth; ++t) {
          cKt_[t - 1].resize((size_t)rps * Na);
          cGt_[t - 1].resize(rp);
        }
        cX_.resize(rp);
        const bool blas = gemmBlas;
        ForkJoin::ForParts(pool, M, [&](PetscInt a, PetscInt b, int t) {
          SetGemmBlas(blas); // per thread
          PetscReal *Kt = t ? cKt_[t - 1].data() : cK_.data(), *gt = t ? cGt_[t - 1].data() : cX_.data();
          if (b > a) {
            PointSumSingle(FusedPointSum(), b - a, rps, Na, cNt_.data() + a, mt, cRow_.data() + a * mt, cCoef_.data() + a * mt, cThetaFs_.data(), ldf, cPwTs_.data() + (size_t)a * rps, cXs_.data() + (size_t)a * ldf, Kt);
            SumOfOuterProducts(b - a, rp, 1, cPwT_.data() + (size_t)a * rp, gam_.data() + a, gt); // g^ in double
          } else {
            std::fill(Kt, Kt + (size_t)rps * Na, 0.0);
            std::fill(gt, gt + rp, 0.0);
          }
        });
        for (int t = 1; t < nth; ++t) {
          for (size_t e = 0; e < (size_t)rps * Na; ++e) cK_[e] += cKt_[t - 1][e];
          for (PetscInt i = 0; i < rp; ++i) cX_[i] += cGt_[t - 1][i];
        }
      }
      for (PetscInt c = 0; c < Na; ++c) std::copy(&cK_[(size_t)c * rps], &cK_[(size_t)c * rps] + r, K + (size_t)r * c);
      if (cRowsW_ && !cDofs_ && !factored && r > 0) { // K^ V from the transformed rows: K^ = (K^ V) V^{-1}
        thread_local std::vector<PetscReal> kw;
        kw.assign(K, K + (size_t)r * Na);
        const PetscBLASInt m = (PetscBLASInt)r, n = (PetscBLASInt)Na;
        const PetscScalar  a1 = 1, b0 = 0;
        BLASgemm_("N", "N", &m, &n, &n, &a1, kw.data(), &m, adiag_.VInverse().data(), &n, &b0, K, &m);
      }
      if (cDofs_) {
        cX_.resize(rp);
        SumOfOuterProducts(M, rp, 1, cPwT_.data(), gam_.data(), cX_.data()); // g^ in double
      }
      std::copy(cX_.begin(), cX_.begin() + r, g);
      event(ROM_CubSum, false);
      return out;
    }
    CubatureSum(rp, cPwT_, factored && (AFactored() || ADiagonalized()) ? cThetaTw_ : cThetaT_, cols_.data(), Na, &cQ_, &cX_, &cK_);
    for (PetscInt c = 0; c < Na; ++c) std::copy(&cK_[(size_t)c * rp], &cK_[(size_t)c * rp] + r, K + (size_t)r * c);
    std::copy(&cK_[(size_t)Na * rp], &cK_[(size_t)Na * rp] + r, g);
    event(ROM_CubSum, false);
    return out;
  }
  wnMode_ = ContactMode::EIM; // the EIM interpolates K^ and g^, not the normals: no resultant force
  const PetscInt np = (PetscInt)evalPoints_.size();
  if (np > 0) {
    if (geomMu_ != mu) {
      patch.SetGeometry(&par.map, mu);
      geomMu_ = mu;
    }
    patch.SetReduced(vfull.data());
    // kappa (all modes) only where an EIM point of kappa is; the gap alone elsewhere
    out = patch.Evaluate(evalPoints_.data(), nkEval_, kap_.data(), gam_.data(), nullptr);
    out += patch.Evaluate(evalPoints_.data() + nkEval_, np - nkEval_, nullptr, gam_.data() + nkEval_, nullptr);
  }
  if (kappaConst) {
    for (PetscInt c = 0; c < Na; ++c)
      for (PetscInt i = 0; i < r; ++i) K[i + (size_t)r * c] = kConstant[(size_t)cols_[c] * Rfull + i];
  } else {
    for (PetscInt j = 0; j < mk_; ++j) vals_[j] = kap_[(size_t)kPos_[j] * Nfull + kMode[j]];
    Forward(mk_, KB_.data(), vals_.data(), phi_.data());
    std::fill(K, K + (size_t)r * Na, 0.0);
    for (PetscInt j = 0; j < mk_; ++j) {
      const PetscReal  ph = phi_[j];
      const PetscReal *C  = &Kc_[(size_t)j * r * Na];
      for (size_t e = 0; e < (size_t)r * Na; ++e) K[e] += ph * C[e];
    }
  }
  if (gapConst) {
    for (PetscInt i = 0; i < r; ++i) g[i] = gConstant[i];
  } else {
    for (PetscInt j = 0; j < mg_; ++j) vals_[j] = gam_[gPos_[j]];
    Forward(mg_, GB_.data(), vals_.data(), phi_.data());
    std::fill(g, g + r, 0.0);
    for (PetscInt j = 0; j < mg_; ++j)
      for (PetscInt i = 0; i < r; ++i) g[i] += phi_[j] * Gc_[(size_t)j * r + i];
  }
  return out;
}

PetscErrorCode ReducedModel::Solve(const std::vector<PetscReal> &mu, ReducedSolution *sol)
{
  PetscFunctionBeginUser;
  PetscCall(CheckHasModel("Solve"));
  PetscCall(par.CheckBox(PETSC_COMM_SELF, mu));
  PetscCall(RegisterEvents());
  PetscCall(PetscLogEventBegin(ROM_Solve, 0, 0, 0, 0));
  PetscCall(SolveLoop(mu, sol));
  PetscCall(PetscLogEventEnd(ROM_Solve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

// F = sum_i lambda_i int psi_i n2 (the FOM's resultant) through the contact terms' last evaluation:
// lambda(x_p) times the point's weight and cubature weight = (Pw(:, p)' lambda^) and w_p n2(x_p) (wn_).
// F (d entries) = sum_p (sum_i P(i, p) lambda_i) wn(p, :) over M points and r rows, P r x M row-major: the
// multipliers' weight at each point times w_p n2(x_p) (the cubature's point-major weights: ResultantForce)
static void ForceAtPoints(PetscInt M, PetscInt r, const PetscReal *P, const PetscReal *lambda, const PetscReal *wn, PetscInt d, PetscReal *F)
{
  for (PetscInt k = 0; k < d; ++k) F[k] = 0;
  for (PetscInt p = 0; p < M; ++p) {
    PetscReal l = 0;
    for (PetscInt i = 0; i < r; ++i) l += P[(size_t)i * M + p] * lambda[i];
    for (PetscInt k = 0; k < d; ++k) F[k] += l * wn[(size_t)p * d + k];
  }
}

void ReducedModel::ResultantForce(const std::vector<PetscReal> &lambda, std::vector<PetscReal> *F) const
{
  F->clear();
  const PetscInt r = r_, d = dim;
  if (wnMode_ == ContactMode::EIM || d <= 0) return;
  const bool     exact = wnMode_ == ContactMode::Exact;
  const PetscInt M     = exact ? (PetscInt)(Pact_.size() / std::max<PetscInt>(r, 1)) : (PetscInt)cPoint.size(), rp = PaddedRows(r);
  if ((PetscInt)wn_.size() != M * d || (PetscInt)lambda.size() != r) return;
  F->assign(d, 0.0);
  if (exact) ForceAtPoints(M, r, Pact_.data(), lambda.data(), wn_.data(), d, F->data());
  else { // the points' multipliers l = PwT lambda in one vectorized kernel (rows of PwT contiguous), then sum_p l_p wn_p
    thread_local std::vector<PetscReal> lpad, l;
    lpad.assign(rp, 0.0);
    std::copy(lambda.begin(), lambda.end(), lpad.begin());
    l.assign(M, 0.0);
    RowDots(M, rp, cPwT_.data(), lpad.data(), l.data(), l.data()); // l = 0 + PwT lambda (b and out may alias)
    for (PetscInt p = 0; p < M; ++p)
      for (PetscInt k = 0; k < d; ++k) (*F)[k] += l[p] * wn_[(size_t)p * d + k];
  }
}

PetscErrorCode ReducedModel::SolveLoop(const std::vector<PetscReal> &mu, ReducedSolution *sol)
{
  const PetscInt Na = (PetscInt)cols_.size(), r = r_;

  PetscFunctionBeginUser;
  sol->converged  = false;
  sol->iterations = 0;
  sol->outOfRange = 0;
  sol->message.clear();
  sol->du.clear();
  sol->dl.clear();
  sol->nactive.clear();
  sol->iterates.clear();
  sol->force.clear();
  sol->v.assign(Na, 0.0);
  sol->lambda.assign(r, 0.0);
  if (r > Na) {
    std::ostringstream o;
    o << "the reduced saddle point is not inf-sup stable: R = " << r << " dual vectors for N = " << Na << " primal ones (K^ is R x N: the reduced multipliers are not determined by the problem); rebuild the ROM with -pod_supremizers or use at most -rom_R " << Na;
    sol->message = o.str();
    PetscFunctionReturn(0);
  }
  // (A^(mu) itself is not needed where it is diagonalized once)
  AffineAt(mu, cols_.data(), Na, ADiagonalized() ? nullptr : &A_, &f_);
  // warm start: a combination of the stored reduced solutions of the training parameters (the bracketing
  // interpolation with one parameter, a quadratic or affine least-squares fit with several: warm_start.hpp); the
  // multipliers clipped to the cone
  const size_t np = par.params.size(), nw = np ? warmMu.size() / np : 0;
  const bool   warmed = warmStart && nw > 0;
  if (warmed) {
    thread_local std::vector<PetscReal> width;
    width.resize(np);
    for (size_t i = 0; i < np; ++i) width[i] = par.params[i].max - par.params[i].min;
    for (const auto &[k, w] : WarmStartWeights(warmMu, width, mu, (int)warmDegree)) {
      for (PetscInt i = 0; i < Na; ++i) sol->v[i] += w * warmV[k * Nfull + cols_[i]];
      for (PetscInt i = 0; i < r; ++i) sol->lambda[i] += w * warmL[k * Rfull + i];
    }
    for (PetscInt i = 0; i < r; ++i) sol->lambda[i] = std::max<PetscReal>(sol->lambda[i], 0);
  }
  thread_local std::vector<PetscReal> vprev, lprev, vnew, lnew, vnext;
  // A^ factored once (Truncate): the QP takes K^ L^{-T}; its factor is Truncate's unless another Solve replaced it
  const bool factored = AFactored();
  if (factored && !qp.HasFactor(Na)) {
    PetscCall(qp.FactorA(Na, A_.data(), &sol->qp));
    if (sol->qp.status != ReducedQPStatus::Ok) {
      sol->message = "reduced QP failed before the first Kacanov iteration (" + std::string(ReducedQPStatusName(sol->qp.status)) + "): " + sol->qp.message;
      PetscFunctionReturn(0);
    }
  }
  // A^ diagonalized once (Truncate): d(mu), and the QP in z = diag(d)^{1/2} V^{-1} v, where A^ is the identity and f is
  // diag(d)^{-1/2} V' f; K^ V from the sum, its columns scaled by d^{-1/2}; v = V diag(d)^{-1/2} z
  const bool diag = ADiagonalized(); // (never with factored: Truncate sets one or the other)
  if (diag) {
    thread_local std::vector<PetscReal> thA;
    par.ThetaA(mu, &thA);
    dA_.resize(Na);
    sA_.resize(Na);
    fz_.resize(Na);
    zq_.resize(Na);
    adiag_.Diagonal(thA, dA_.data());
    PetscReal dmax = 0;
    PetscInt  imin = 0;
    for (PetscInt i = 0; i < Na; ++i) {
      dmax = std::max(dmax, std::abs(dA_[i]));
      if (!(dA_[i] >= dA_[imin])) imin = i;
    }
    if (!(dA_[imin] > 64 * PETSC_MACHINE_EPSILON * dmax)) { // as the Cholesky of A^(mu) would report it
      char buf[320];
      std::snprintf(buf, sizeof buf, "reduced matrix A is not symmetric positive definite at this parameter (eigenvalue %g of A(mu) relative to A(mu0), the largest %g): the parameter leaves the range where the affine stiffness is positive definite", (double)dA_[imin], (double)dmax);
      sol->qp.status  = ReducedQPStatus::NotSPD;
      sol->qp.message = buf;
      sol->message    = "reduced QP failed before the first Kacanov iteration (" + std::string(ReducedQPStatusName(sol->qp.status)) + "): " + sol->qp.message;
      PetscFunctionReturn(0);
    }
    for (PetscInt i = 0; i < Na; ++i) sA_[i] = 1 / std::sqrt(dA_[i]);
    const PetscBLASInt n = (PetscBLASInt)Na, one = 1;
    const PetscScalar  a1 = 1, b0 = 0;
    BLASgemv_("T", &n, &n, &a1, adiag_.V().data(), &n, f_.data(), &one, &b0, fz_.data(), &one);
    for (PetscInt i = 0; i < Na; ++i) fz_[i] *= sA_[i];
    qp.SetIdentityA(Na); // (a no-op unless this is the first solve or another solve replaced it)
  }
  loop.Begin(Na);
  vnext.resize(Na);
  for (PetscInt it = 1; it <= loop.maxIt; ++it) {
    vprev = sol->v;
    lprev = sol->lambda;
    if (recordIterates) sol->iterates.insert(sol->iterates.end(), vprev.begin(), vprev.end());
    PetscCall(PetscLogEventBegin(ROM_Contact, 0, 0, 0, 0));
    sol->outOfRange += ContactTerms(mu, vprev.data(), K_.data(), g_.data(), factored || diag); // factored: K_ is K^ L^{-T}; diag: K^ V
    PetscCall(PetscLogEventEnd(ROM_Contact, 0, 0, 0, 0));
    vnew.resize(Na);
    PetscCall(PetscLogEventBegin(ROM_QP, 0, 0, 0, 0));
    if (factored) PetscCall(qp.SolveFactored(Na, r, f_.data(), K_.data(), g_.data(), vnew.data(), sol->lambda.data(), &sol->qp));
    else if (diag) {
      for (PetscInt c = 0; c < Na; ++c)
        for (PetscInt i = 0; i < r; ++i) K_[i + (size_t)r * c] *= sA_[c];
      PetscCall(qp.SolveFactored(Na, r, fz_.data(), K_.data(), g_.data(), zq_.data(), sol->lambda.data(), &sol->qp));
      thread_local std::vector<PetscReal> zs;
      zs.resize(Na);
      for (PetscInt i = 0; i < Na; ++i) zs[i] = sA_[i] * zq_[i];
      const PetscBLASInt n = (PetscBLASInt)Na, one = 1;
      const PetscScalar  a1 = 1, b0 = 0;
      BLASgemv_("N", &n, &n, &a1, adiag_.V().data(), &n, zs.data(), &one, &b0, vnew.data(), &one);
    } else PetscCall(qp.Solve(Na, r, A_.data(), f_.data(), K_.data(), g_.data(), vnew.data(), sol->lambda.data(), &sol->qp));
    PetscCall(PetscLogEventEnd(ROM_QP, 0, 0, 0, 0));
    sol->iterations = it;
    lnew            = sol->lambda;
    if (sol->qp.status != ReducedQPStatus::Ok) {
      sol->message = std::string("reduced QP failed at Kacanov iteration ") + std::to_string(it) + " (" + ReducedQPStatusName(sol->qp.status) + "): " + sol->qp.message;
      sol->v.assign(Na, 0.0);
      sol->lambda.assign(r, 0.0);
      PetscFunctionReturn(0);
    }
    // the relaxed image and the change of the input (KacanovLoop); the multipliers relaxed alike
    sol->v            = vnew;
    const PetscReal du = loop.Relax(vprev.data(), sol->v.data());
    PetscInt        nact = 0;
    PetscReal       nl = 0, dln = 0;
    // changes of the multiplier field W lambda^ (the FOM's rule), in the Gram matrix W'W: the QP's multipliers
    // against the input's, before the relaxation (as the primal change, KacanovLoop::Relax)
    for (PetscInt i = 0; i < r; ++i)
      for (PetscInt j = 0; j < r; ++j) dln += (sol->lambda[i] - lprev[i]) * dualGram[(size_t)i * Rfull + j] * (sol->lambda[j] - lprev[j]);
    for (PetscInt i = 0; i < r; ++i) {
      sol->lambda[i] = lprev[i] + loop.relaxation * (sol->lambda[i] - lprev[i]);
      nact += sol->lambda[i] > 0;
    }
    for (PetscInt i = 0; i < r; ++i)
      for (PetscInt j = 0; j < r; ++j) nl += sol->lambda[i] * dualGram[(size_t)i * Rfull + j] * sol->lambda[j];
    nl  = std::max<PetscReal>(nl, 0);
    dln = std::max<PetscReal>(dln, 0);
    const PetscReal dl = nl > 0 ? std::sqrt(dln / nl) : std::sqrt(dln);
    char            detail[48] = "";
    if (loop.monitor) std::snprintf(detail, sizeof detail, "QP its %" PetscInt_FMT, sol->qp.iterations);
    // the first iterate's multipliers against a warm start's: not a change of the iteration (the image
    // depends on the input v alone), so only du is tested there (relaxation 1: lambda is the QP's)
    const bool dualIsChange = !(it == 1 && warmed && loop.relaxation == 1.0);
    bool       done         = false;
    PetscCall(loop.Record(PETSC_COMM_SELF, it, du, dl, nact, r, loop.monitor ? detail : nullptr, &done, dualIsChange));
    if (done) {
      // the KKT residuals of the last QP only (the loop's QPs skip them: -log_view 1-2 % of a solve)
      if (factored) qp.ResidualsFactored(Na, r, A_.data(), f_.data(), K_.data(), g_.data(), vnew.data(), lnew.data(), &sol->qp);
      else if (diag) qp.ResidualsFactored(Na, r, nullptr, fz_.data(), K_.data(), g_.data(), zq_.data(), lnew.data(), &sol->qp); // in z: A^ = I
      else qp.Residuals(Na, r, A_.data(), f_.data(), K_.data(), g_.data(), vnew.data(), lnew.data(), &sol->qp);
      ResultantForce(lnew, &sol->force);
      sol->converged = true;
      break;
    }
    // the next input (the contact terms are evaluated there): Anderson's mix, or the relaxed image;
    // sol->v stays the QP's solution (consistent with sol->lambda) until the test above has passed
    if (loop.Next(vprev.data(), sol->v.data(), vnext.data())) sol->v = vnext;
  }
  sol->du      = loop.history.du;
  sol->dl      = loop.history.dl;
  sol->nactive = loop.history.nactive;
  if (!sol->converged) {
    sol->message = "reduced model: " + loop.NotConverged(false);
    // the float sum leaves a noise floor on the changes (about 1e-6 on u, 1e-5 on lambda: docs/online.md)
    if (cSingle_) sol->message += "; -rom_ecsw_precision single (the ROM file's or the option's) bounds the attainable changes to about 1e-6 (u) and 1e-5 (lambda): use -rom_ecsw_precision double for tighter tolerances";
    PetscFunctionReturn(0);
  }
  const PetscReal kkt = std::max(std::max(sol->qp.primal, sol->qp.dual), std::max(sol->qp.complementarity, sol->qp.stationarity));
  if (!(kkt <= kktTol)) {
    std::ostringstream o;
    o << "reduced KKT residual " << kkt << " exceeds -rom_kkt_tol " << kktTol << " (primal " << sol->qp.primal << ", dual " << sol->qp.dual << ", complementarity " << sol->qp.complementarity << ", stationarity " << sol->qp.stationarity << ")";
    sol->message   = o.str();
    sol->converged = false;
    PetscFunctionReturn(0);
  }
  PetscCall(EstimateError(mu, sol));
  PetscFunctionReturn(0);
}

PetscErrorCode ReducedModel::EstimateError(const std::vector<PetscReal> &mu, ReducedSolution *sol)
{
  ErrorEstimate &e = sol->estimate;
  const PetscInt Na = (PetscInt)cols_.size(), r = r_, Nf = Nfull, Rf = Rfull;

  PetscFunctionBeginUser;
  e = ErrorEstimate();
  if (!errorEstimate) {
    e.why = "-rom_error_estimate false";
    PetscFunctionReturn(0);
  }
  if (Na >= Nf && r >= Rf) {
    e.why = "no enrichment: the model uses every basis function of the ROM file (rebuild it with offline -estimate, or use fewer with -rom_N/-rom_R)";
    PetscFunctionReturn(0);
  }
  if (!HasEnrichment() && !sizesGiven_) { // the file's default sizes: the dual vectors beyond the held-out choice
    e.why = "no enrichment: the ROM file's dual vectors beyond the R chosen on held-out solutions (offline -dual_select_*) are not an error estimate's enrichment (rebuild with offline -estimate, or use fewer with -rom_N/-rom_R)";
    PetscFunctionReturn(0);
  }
  if (wnMode_ == ContactMode::EIM) {
    e.why = "the EIM interpolates the reduced terms of the answer's sizes only (use -rom_hyper ecsw)";
    PetscFunctionReturn(0);
  }
  PetscCall(PetscLogEventBegin(ROM_Estimate, 0, 0, 0, 0));
  // the contact terms of every stored basis function at the last evaluation's geometry and points:
  // K(i, n) = sum_p Pw(i, p) kappa(p, n), g(i) = sum_p Pw(i, p) gamma(p)
  const bool       exact = wnMode_ == ContactMode::Exact;
  const PetscInt   M     = exact ? (PetscInt)(P_.size() / Rf) : (PetscInt)cPoint.size();
  const PetscReal *Pw    = exact ? P_.data() : cPw.data(); // Rf x M, row-major
  const PetscInt rpf = PaddedRows(Rf);
  if (exact) { // offline / validation only: plain loops over the full quadrature
    eKp_.assign((size_t)rpf * (Nf + 1), 0.0);
    for (PetscInt i = 0; i < Rf; ++i)
      for (PetscInt p = 0; p < M; ++p) {
        const PetscReal wp = Pw[(size_t)i * M + p];
        for (PetscInt n = 0; n < Nf; ++n) eKp_[i + (size_t)rpf * n] += wp * kap_[(size_t)p * Nf + n];
        eKp_[i + (size_t)rpf * Nf] += wp * gam_[p];
      }
  } else {
    if (kapStale_) { // the single points' sum left kappa in float, used columns only: its double rows from the terms
      for (PetscInt p = 0; p < M; ++p) patch.KappaRow(cNt_[p], &cRow_[(size_t)p * ContactPatch::MaxTerms], &cCoef_[(size_t)p * ContactPatch::MaxTerms], &kap_[(size_t)p * Nf]);
      kapStale_ = false;
    }
    SetGemmBlas(gemmBlas);
    CubatureSum(rpf, ePwT_, eThetaT_, nullptr, Nf, &eQ_, &eX_, &eKp_); // the answer's sum, every stored row and column
  }
  eK_.resize((size_t)Rf * Nf);
  for (PetscInt n = 0; n < Nf; ++n) std::copy_n(&eKp_[(size_t)n * rpf], Rf, &eK_[(size_t)Rf * n]);
  eg_.assign(eKp_.begin() + (size_t)Nf * rpf, eKp_.begin() + (size_t)Nf * rpf + Rf);
  AffineAt(mu, nullptr, Nf, &eA_, &ef_); // A(mu), f(mu) of all stored columns
  // the enriched QP, from the answer's multipliers
  ev_.assign(Nf, 0.0);
  el_.assign(Rf, 0.0);
  std::copy(sol->lambda.begin(), sol->lambda.end(), el_.begin());
  ReducedQPInfo info;
  PetscCall(qpEst_.Solve(Nf, Rf, eA_.data(), ef_.data(), eK_.data(), eg_.data(), ev_.data(), el_.data(), &info));
  if (info.status != ReducedQPStatus::Ok) {
    e.why = std::string("the enriched reduced QP failed (") + ReducedQPStatusName(info.status) + "): " + info.message;
    PetscCall(PetscLogEventEnd(ROM_Estimate, 0, 0, 0, 0));
    PetscFunctionReturn(0);
  }
  // u: energy norm of A(mu) of the change, relative to the enriched solution
  eTh_.assign(ev_.begin(), ev_.end()); // the change d = v_enriched - v (answer padded with zeros)
  for (PetscInt i = 0; i < Na; ++i) eTh_[cols_[i]] -= sol->v[i];
  auto energy = [&](const std::vector<PetscReal> &x) {
    PetscReal s = 0;
    for (PetscInt j = 0; j < Nf; ++j) {
      PetscReal t = 0;
      for (PetscInt i = 0; i < Nf; ++i) t += eA_[i + (size_t)Nf * j] * x[i];
      s += x[j] * t;
    }
    return std::max<PetscReal>(s, 0);
  };
  const PetscReal du2 = energy(eTh_), u2 = energy(ev_);
  e.uRaw = u2 > 0 ? std::sqrt(du2 / u2) : std::sqrt(du2);
  // lambda: the slave-mass weighted norm (W'W when the file has no mass Gram)
  const std::vector<PetscReal> &G = massGram.empty() ? dualGram : massGram;
  PetscReal                     dl2 = 0, l2 = 0;
  for (PetscInt i = 0; i < Rf; ++i)
    for (PetscInt j = 0; j < Rf; ++j) {
      const PetscReal g = G[(size_t)i * Rf + j], di = el_[i] - (i < r ? sol->lambda[i] : 0), dj = el_[j] - (j < r ? sol->lambda[j] : 0);
      dl2 += di * g * dj;
      l2 += el_[i] * g * el_[j];
    }
  dl2        = std::max<PetscReal>(dl2, 0);
  e.lambdaRaw = l2 > 0 ? std::sqrt(dl2 / l2) : std::sqrt(dl2);
  // the resultant force of the enriched multipliers at the same points
  if (!sol->force.empty() && (PetscInt)wn_.size() == M * dim) {
    PetscReal F2[3] = {0, 0, 0};
    ForceAtPoints(M, Rf, Pw, el_.data(), wn_.data(), dim, F2);
    PetscReal df = 0, nf = 0;
    for (PetscInt k = 0; k < dim; ++k) {
      df += PetscSqr(F2[k] - sol->force[k]);
      nf += PetscSqr(F2[k]);
    }
    e.forceRaw = nf > 0 ? std::sqrt(df / nf) : std::sqrt(df);
  }
  e.u         = estimateScale[0] * e.uRaw + estimateFloor[0];
  e.lambda    = estimateScale[1] * e.lambdaRaw + estimateFloor[1];
  e.force     = estimateScale[2] * e.forceRaw + estimateFloor[2];
  e.available = true;
  PetscCall(PetscLogEventEnd(ROM_Estimate, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

} // namespace rbc
