// src/rom/eim_selection.cpp: the default EIM sizes of a reduced model, chosen on held-out parameters
// against the reduced model with exact contact terms (include/rbcontact/eim_selection.hpp, docs/eim.md).
#include "rbcontact/eim_selection.hpp"
#include "rbcontact/training_set.hpp"
#include <algorithm>
#include <cmath>
#include <limits>

namespace rbc {

// sqrt((a-b)' G (a-b) / b' G b) for a symmetric G (n x n, either layout).
static PetscReal RelErr(const std::vector<PetscReal> &G, PetscInt ld, const PetscReal *a, const PetscReal *b, PetscInt n)
{
  PetscReal d = 0, nb = 0;
  for (PetscInt i = 0; i < n; ++i)
    for (PetscInt j = 0; j < n; ++j) {
      const PetscReal g = G[(size_t)i * ld + j];
      d += (a[i] - b[i]) * g * (a[j] - b[j]);
      nb += b[i] * g * b[j];
    }
  d  = std::max<PetscReal>(d, 0);
  nb = std::max<PetscReal>(nb, 0);
  return nb > 0 ? std::sqrt(d / nb) : std::sqrt(d);
}

PetscErrorCode EIMHeldOutError(MPI_Comm comm, ReducedModel &rm, const std::vector<std::vector<PetscReal>> &mus, const std::vector<HeldOutReference> &ref, PetscInt mk, PetscInt mg, PetscReal *err)
{
  PetscMPIInt rank, size;
  PetscReal   e = 0;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(rm.Truncate(-1, -1, mk, mg));
  const PetscInt N = rm.N(), R = rm.R();
  for (size_t k = rank; k < mus.size(); k += size) {
    ReducedSolution sol;
    PetscCall(rm.Solve(mus[k], &sol));
    if (!sol.converged) {
      e = std::numeric_limits<PetscReal>::infinity();
      break;
    }
    const PetscReal eu = RelErr(ref[k].A, N, sol.v.data(), ref[k].sol.v.data(), N);
    const PetscReal el = RelErr(rm.dualGram, rm.Rfull, sol.lambda.data(), ref[k].sol.lambda.data(), R);
    e = std::max(e, std::max(eu, el));
    if (!(e < PETSC_MAX_REAL)) {
      e = std::numeric_limits<PetscReal>::infinity();
      break;
    }
  }
  PetscCall(MPIU_Allreduce(&e, err, 1, MPIU_REAL, MPIU_MAX, comm));
  PetscFunctionReturn(0);
}

// The smallest size (1-based) whose error is within (1 + slack) of the smallest error.
static PetscInt Smallest(const std::vector<PetscReal> &err, PetscReal slack)
{
  PetscReal best = std::numeric_limits<PetscReal>::infinity();
  for (PetscReal e : err) best = std::min(best, e);
  for (size_t m = 0; m < err.size(); ++m)
    if (err[m] <= (1 + slack) * best) return (PetscInt)m + 1;
  return (PetscInt)err.size();
}

PetscErrorCode SelectEIMSizes(MPI_Comm comm, ReducedModel &rm, const std::vector<std::vector<PetscReal>> &mus, PetscReal slack, EIMSelection *sel)
{
  PetscFunctionBeginUser;
  PetscCheck(slack >= 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-eim_select_slack %g must be >= 0", (double)slack);
  *sel         = EIMSelection();
  sel->heldout = (PetscInt)mus.size();
  sel->Mk      = rm.MkFull;
  sel->Mg      = rm.MgFull;
  rm.MkDefault = rm.MgDefault = -1;
  // references: the reduced model with exact contact terms (all terms, every rank: cheap)
  std::vector<HeldOutReference> ref(mus.size());
  std::vector<PetscReal>        f;
  rm.SetContactMode(ReducedModel::ContactMode::Exact);
  PetscCall(rm.Truncate(-1, -1, -1, -1));
  for (size_t k = 0; k < mus.size(); ++k) {
    PetscCall(rm.Solve(mus[k], &ref[k].sol));
    PetscCheck(ref[k].sol.converged, comm, PETSC_ERR_NOT_CONVERGED, "offline: the reduced model with exact contact terms fails at held-out parameter %zu (%g...): %s", k, (double)mus[k][0], ref[k].sol.message.c_str());
    rm.Operators(mus[k], &ref[k].A, &f);
  }
  rm.SetContactMode(ReducedModel::ContactMode::EIM);
  if (!mus.empty()) {
    if (!rm.kappaConst && rm.MkFull > 0) {
      sel->errKappa.resize(rm.MkFull);
      for (PetscInt m = 1; m <= rm.MkFull; ++m) PetscCall(EIMHeldOutError(comm, rm, mus, ref, m, rm.MgFull, &sel->errKappa[m - 1]));
      sel->Mk = Smallest(sel->errKappa, slack);
    }
    if (!rm.gapConst && rm.MgFull > 0) {
      sel->errGap.resize(rm.MgFull);
      for (PetscInt m = 1; m <= rm.MgFull; ++m) PetscCall(EIMHeldOutError(comm, rm, mus, ref, sel->Mk, m, &sel->errGap[m - 1]));
      sel->Mg = Smallest(sel->errGap, slack);
    }
    PetscCall(EIMHeldOutError(comm, rm, mus, ref, sel->Mk, sel->Mg, &sel->err));
  }
  rm.MkDefault = sel->Mk;
  rm.MgDefault = sel->Mg;
  PetscCall(rm.Truncate(-1, -1, -1, -1));
  PetscFunctionReturn(0);
}

std::vector<std::vector<PetscReal>> HeldOutParameters(const std::vector<ParamSpec> &params, const std::vector<std::vector<PetscReal>> &train, PetscInt n, unsigned long long seed)
{
  if (params.size() != 1) return RandomSample(params, n, seed);
  std::vector<PetscReal> v;
  for (const auto &t : train) v.push_back(t[0]);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  std::vector<std::vector<PetscReal>> out;
  for (size_t i = 0; i + 1 < v.size(); ++i) out.push_back({0.5 * (v[i] + v[i + 1])});
  if (out.empty()) return RandomSample(params, n, seed);
  return out;
}

} // namespace rbc
