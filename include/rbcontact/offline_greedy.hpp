// include/rbcontact/offline_greedy.hpp: greedy training (offline -train_type greedy, docs/greedy_training.md):
// the candidate pool, the error indicator of a reduced solution computed with the reduced model with
// exact contact terms, the choice of the next FOM parameters, and the rounds (bases, indicator, picks);
// the snapshot solves and their checkpoints are the snapshot stage's (stage_offline.cpp).
#pragma once
#include <slepcbv.h>
#include <functional>
#include <memory>
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/snapshot_file.hpp"
#include "rbcontact/greedy_indicator.hpp"
#include "rbcontact/training_set.hpp"

namespace rbc {

// -greedy_tol (1e-4): stop once the largest indicator over the candidates not solved is at most this;
// -greedy_max_solves (100): FOM solves in all, initial set included; -greedy_batch (2; 0: the number of
// groups of ranks, rank-dependent picks): parameters solved per round; -greedy_separation (2): the picks of one round lie at
// least this many typical candidate spacings apart (unit box); -greedy_indicator residual|penetration|max|estimate
// (residual: the penetration of the reduced constraint is bounded below by the dual basis' truncation,
// which more snapshots do not lower; estimate: the online error estimate's raw u change, with -estimate, the
// residual in a round whose bases have no enrichment yet; docs/greedy_training.md); -greedy_monitor.
struct GreedyOptions {
  PetscReal tol        = 1e-4;
  GreedyCriterion criterion = GreedyCriterion::Residual;
  PetscInt  maxSolves  = 100;
  PetscInt  batch      = 2; // (0, the number of groups of ranks, was the default: picks that depended on the rank count)
  PetscReal separation = 2;
  PetscBool monitor    = PETSC_FALSE;
  bool      sensitivities = false; // the snapshots carry their derivatives (OfflineSettings::sensitivities): the rounds' bases use them
};
PetscErrorCode GreedyOptionsFromOptions(MPI_Comm comm, GreedyOptions *o);

// The pool stored as the snapshot file's training set: the initial set (-greedy_initial_type/size/seed/
// file; default grid 2, the corners of the box) then the candidates (-greedy_candidates_...; default
// lhs 1000, seed 1), candidates equal to an initial point dropped. *ninitial: the initial set's size.
PetscErrorCode GreedyPoolFromOptions(MPI_Comm comm, const std::vector<ParamSpec> &params, ParameterSet *pool, PetscInt *ninitial);

// The rounds after the initial set: each reads the done snapshots of file (closed and reopened: what the
// indicator sees is what a restart would), builds the bases and the reduced model with exact contact
// terms, evaluates the indicator at every candidate not solved (the groups of ranks share them: group
// color of ngroups), stops at -greedy_tol, -greedy_max_solves or an exhausted pool, and solves the picks
// with solve. Report key greedy {...} (docs/greedy_training.md).
using GreedySolveFn = std::function<PetscErrorCode(const std::vector<PetscInt> &)>;
PetscErrorCode GreedyRounds(MPI_Comm world, const GreedyOptions &go, PetscInt ngroups, PetscInt color, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const ParameterSet &pool, PetscInt ninitial, SnapshotFile &file, const SnapshotHeader &h, const GreedySolveFn &solve, Report *rep);

} // namespace rbc
