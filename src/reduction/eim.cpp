// src/reduction/eim.cpp: the Empirical Interpolation Method on a dense snapshot matrix (serial).
// Owns EIMGreedy (the greedy on the residual matrix S - I_k S, O(n m) per step), EIMCoefficients
// (forward substitution with the unit lower triangular B), EIMInterpolate and the options reader
// EIMOptionsFromOptions (-<prefix>tol|max|monitor|relative, shared -eim_max / -eim_monitor).
// No log event here: the callers register their own. Documentation: docs/eim.md.
#include "rbcontact/eim.hpp"
#include <algorithm>
#include <cmath>

namespace rbc {

PetscErrorCode EIMGreedy(const std::vector<PetscReal> &S, PetscInt n, PetscInt m, const EIMOptions &opt, EIMResult *res)
{
  PetscFunctionBeginUser;
  PetscCheck(res, PETSC_COMM_SELF, PETSC_ERR_ARG_NULL, "EIM %s: null result", opt.name.c_str());
  PetscCheck(n >= 1, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "EIM %s: the functions have %" PetscInt_FMT " entries (need >= 1)", opt.name.c_str(), n);
  PetscCheck(m >= 1, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "EIM %s: %" PetscInt_FMT " snapshots (need >= 1)", opt.name.c_str(), m);
  PetscCheck(S.size() == (size_t)n * (size_t)m, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "EIM %s: the snapshot matrix has %zu entries, expected n x m = %" PetscInt_FMT " x %" PetscInt_FMT, opt.name.c_str(), S.size(), n, m);
  PetscCheck(opt.tol >= 0 && std::isfinite(opt.tol), PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "EIM %s: tolerance %g must be finite and >= 0", opt.name.c_str(), (double)opt.tol);
  PetscCheck(opt.maxM >= 1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "EIM %s: maximum number of functions %" PetscInt_FMT " must be >= 1", opt.name.c_str(), opt.maxM);

  *res   = EIMResult();
  res->n = n;
  PetscReal scale = 0;
  for (PetscInt j = 0; j < m; ++j)
    for (PetscInt i = 0; i < n; ++i) {
      const PetscReal v = S[i + (size_t)j * n];
      PetscCheck(std::isfinite(v), PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "EIM %s: entry %" PetscInt_FMT " of snapshot %" PetscInt_FMT " is non-finite (%g)", opt.name.c_str(), i, j, (double)v);
      scale = std::max(scale, std::abs(v));
    }
  res->scale  = scale;
  res->tolAbs = opt.relative ? opt.tol * scale : opt.tol;
  const PetscReal zeroTol = 1e-14 * scale;

  std::vector<PetscReal> Rm(S); // residuals r_l = s_l - I_k s_l, column-major n x m
  for (PetscInt k = 0;; ++k) {
    // largest |Rm(i,j)|; ties: smallest j, then smallest i (strict > in column-major order)
    PetscReal err = -1;
    PetscInt  js = 0, is = 0;
    for (PetscInt j = 0; j < m; ++j) {
      const PetscReal *r = &Rm[(size_t)j * n];
      for (PetscInt i = 0; i < n; ++i)
        if (std::abs(r[i]) > err) {
          err = std::abs(r[i]);
          js  = j;
          is  = i;
        }
    }
    res->history.push_back(err);
    if (opt.monitor) PetscCall(PetscPrintf(PETSC_COMM_SELF, "  EIM %s M = %" PetscInt_FMT "  max err = %g  (snapshot %" PetscInt_FMT ", point %" PetscInt_FMT ")\n", opt.name.c_str(), k, (double)err, js, is));
    if (err <= res->tolAbs) break;
    if (err <= zeroTol) {
      res->exhausted = true;
      break;
    }
    if (k >= opt.maxM) break;

    // q_k = r_js / r_js(is): vanishes (exactly) at the previous points, 1 at the new one
    const PetscReal  piv = Rm[is + (size_t)js * n];
    const PetscReal *rj  = &Rm[(size_t)js * n];
    const size_t     off = res->Q.size();
    res->Q.resize(off + n);
    PetscReal *q = &res->Q[off];
    for (PetscInt i = 0; i < n; ++i) q[i] = rj[i] / piv;
    q[is] = 1;
    res->points.push_back(is);
    res->selected.push_back(js);
    // I_{k+1} s = I_k s + q_k r_k(x_k), so r_l <- r_l - q_k r_l(x_k) (exactly 0 at x_k)
    for (PetscInt l = 0; l < m; ++l) {
      PetscReal *r = &Rm[(size_t)l * n];
      const PetscReal a = r[is];
      if (a == 0) continue;
      for (PetscInt i = 0; i < n; ++i) r[i] -= a * q[i];
      r[is] = 0;
    }
  }

  const PetscInt M = (PetscInt)res->points.size();
  res->M           = M;
  res->B.assign((size_t)M * M, 0.0);
  for (PetscInt j = 0; j < M; ++j)
    for (PetscInt i = 0; i < M; ++i) res->B[i + (size_t)j * M] = res->Q[res->points[i] + (size_t)j * n];
  PetscFunctionReturn(0);
}

void EIMCoefficients(const EIMResult &res, PetscInt M, const PetscReal *vals, PetscReal *phi)
{
  const PetscInt ld = res.M;
  for (PetscInt i = 0; i < M; ++i) {
    PetscReal s = vals[i];
    for (PetscInt j = 0; j < i; ++j) s -= res.B[i + (size_t)j * ld] * phi[j];
    phi[i] = s / res.B[i + (size_t)i * ld];
  }
}

void EIMInterpolate(const EIMResult &res, PetscInt M, const PetscReal *f, PetscReal *out)
{
  const PetscInt         n = res.n;
  std::vector<PetscReal> vals(M), phi(M);
  for (PetscInt k = 0; k < M; ++k) vals[k] = f[res.points[k]]; // before out is written (out may alias f)
  EIMCoefficients(res, M, vals.data(), phi.data());
  for (PetscInt i = 0; i < n; ++i) out[i] = 0;
  for (PetscInt k = 0; k < M; ++k) {
    const PetscReal *q = &res.Q[(size_t)k * n];
    for (PetscInt i = 0; i < n; ++i) out[i] += phi[k] * q[i];
  }
}

PetscErrorCode EIMOptionsFromOptions(MPI_Comm comm, const std::string &prefix, EIMOptions *opt)
{
  PetscBool   flg = PETSC_FALSE, monitor = opt->monitor ? PETSC_TRUE : PETSC_FALSE, relative = opt->relative ? PETSC_TRUE : PETSC_FALSE;
  std::string maxName = "-" + prefix + "max";

  PetscFunctionBeginUser;
  // shared defaults (no prefix), overridden by the prefixed options below
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-eim_max", &opt->maxM, &flg));
  if (flg && prefix != "eim_") maxName = "-eim_max";
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-eim_monitor", &monitor, NULL));
  PetscOptionsBegin(comm, prefix.empty() ? NULL : prefix.c_str(), "Empirical interpolation", "EIMGreedy");
  PetscCall(PetscOptionsReal("-tol", "Stop when the largest interpolation error over the snapshots is <= tol (times the largest snapshot entry if -relative)", "EIMGreedy", opt->tol, &opt->tol, NULL));
  PetscCall(PetscOptionsInt("-max", "Largest number of interpolation functions (default: -eim_max)", "EIMGreedy", opt->maxM, &opt->maxM, &flg));
  if (flg) maxName = "-" + prefix + "max";
  PetscCall(PetscOptionsBool("-monitor", "Print the largest error and the selected snapshot/point per step (default: -eim_monitor)", "EIMGreedy", monitor, &monitor, NULL));
  PetscCall(PetscOptionsBool("-relative", "The tolerance is relative to the largest snapshot entry in absolute value", "EIMGreedy", relative, &relative, NULL));
  PetscOptionsEnd();
  opt->monitor  = monitor ? true : false;
  opt->relative = relative ? true : false;
  PetscCheck(opt->tol > 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-%stol %g must be > 0", prefix.c_str(), (double)opt->tol);
  PetscCheck(opt->maxM >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s %" PetscInt_FMT " must be >= 1", maxName.c_str(), opt->maxM);
  PetscFunctionReturn(0);
}

} // namespace rbc
