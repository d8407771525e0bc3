// snapshot_continuation.cpp: SnapshotContinuation, the nearest earlier snapshot (extrapolated by its
// derivatives) as the initial guess of the next contact solve (docs/offline.md "Initial guesses").
#include "rbcontact/snapshot_continuation.hpp"
#include <cmath>
#include <petscsys.h>

namespace rbc {

static PetscErrorCode Copy(Vec v, Vec *c)
{
  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(v, c));
  PetscCall(VecCopy(v, *c));
  PetscFunctionReturn(0);
}

SnapshotContinuation::~SnapshotContinuation()
{
  for (auto &e : entries_) {
    (void)VecDestroy(&e.u);
    (void)VecDestroy(&e.lambda);
    for (auto &v : e.du) (void)VecDestroy(&v);
    for (auto &v : e.dlambda) (void)VecDestroy(&v);
  }
}

PetscErrorCode SnapshotContinuation::Add(const std::vector<PetscReal> &mu, Vec u, Vec lambda, const std::vector<Vec> &du, const std::vector<Vec> &dlambda)
{
  PetscFunctionBeginUser;
  PetscCheck(mu.size() == ranges_.size() && du.size() == dlambda.size() && (du.empty() || du.size() == mu.size()), PetscObjectComm((PetscObject)u), PETSC_ERR_ARG_SIZ, "SnapshotContinuation: %zu parameters, %zu ranges, %zu and %zu derivatives", mu.size(), ranges_.size(), du.size(), dlambda.size());
  Entry e;
  e.mu = mu;
  PetscCall(Copy(u, &e.u));
  PetscCall(Copy(lambda, &e.lambda));
  for (size_t i = 0; i < du.size(); ++i) {
    e.du.emplace_back();
    e.dlambda.emplace_back();
    PetscCall(Copy(du[i], &e.du.back()));
    PetscCall(Copy(dlambda[i], &e.dlambda.back()));
  }
  entries_.push_back(std::move(e));
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotContinuation::Predict(const std::vector<PetscReal> &mu, Vec *u, Vec *lambda, PetscReal *distance) const
{
  PetscFunctionBeginUser;
  *u = *lambda = nullptr;
  *distance    = PETSC_MAX_REAL;
  const Entry *best = nullptr;
  for (const auto &e : entries_) { // the first of equally near ones: the same choice on every rank of the group
    PetscReal d2 = 0;
    for (size_t i = 0; i < mu.size(); ++i) {
      const PetscReal t = (mu[i] - e.mu[i]) / (ranges_[i] > 0 ? ranges_[i] : 1.0);
      d2 += t * t;
    }
    if (std::sqrt(d2) < *distance) {
      *distance = std::sqrt(d2);
      best      = &e;
    }
  }
  if (!best) PetscFunctionReturn(0);
  PetscCall(Copy(best->u, u));
  PetscCall(Copy(best->lambda, lambda));
  for (size_t i = 0; i < best->du.size(); ++i) { // first order: u + sum_i du/dmu_i (mu_i - mu0_i)
    PetscCall(VecAXPY(*u, mu[i] - best->mu[i], best->du[i]));
    PetscCall(VecAXPY(*lambda, mu[i] - best->mu[i], best->dlambda[i]));
  }
  PetscInt     n;
  PetscScalar *l;
  PetscCall(VecGetLocalSize(*lambda, &n));
  PetscCall(VecGetArray(*lambda, &l));
  for (PetscInt j = 0; j < n; ++j) l[j] = PetscMax(PetscRealPart(l[j]), 0.0);
  PetscCall(VecRestoreArray(*lambda, &l));
  PetscFunctionReturn(0);
}

} // namespace rbc
