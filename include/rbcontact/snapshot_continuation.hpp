// rbcontact/snapshot_continuation.hpp: the initial guess of a snapshot's contact solve from the snapshots its
// group of ranks solved earlier in the same run (offline -snapshots_initial_guess nearest): the solution at the
// nearest of those parameters (distance in units of each parameter's range), extrapolated to first order by its
// derivatives when the snapshots carry them (-snapshots_sensitivities), the multipliers clipped at zero.
// Owns copies of the kept solutions (u, lambda and their derivatives: 1 + np vectors of each a snapshot).
#pragma once
#include <petscvec.h>
#include <vector>

namespace rbc {

class SnapshotContinuation {
public:
  explicit SnapshotContinuation(std::vector<PetscReal> ranges) : ranges_(std::move(ranges)) {}
  SnapshotContinuation(const SnapshotContinuation &)            = delete;
  SnapshotContinuation &operator=(const SnapshotContinuation &) = delete;
  ~SnapshotContinuation();

  // Keeps copies of the solution (u, lambda) at mu and, when given (np each, else empty), its derivatives
  // du[i], dlambda[i] along mu_i (unscaled: per unit of mu_i).
  PetscErrorCode Add(const std::vector<PetscReal> &mu, Vec u, Vec lambda, const std::vector<Vec> &du, const std::vector<Vec> &dlambda);
  // The guess at mu: *u, *lambda created (the caller destroys them), *distance to the solution it comes from
  // (in ranges); both null when nothing is kept yet.
  PetscErrorCode Predict(const std::vector<PetscReal> &mu, Vec *u, Vec *lambda, PetscReal *distance) const;

private:
  struct Entry {
    std::vector<PetscReal> mu;
    Vec                    u = nullptr, lambda = nullptr;
    std::vector<Vec>       du, dlambda;
  };
  std::vector<PetscReal> ranges_;
  std::vector<Entry>     entries_;
};

} // namespace rbc
