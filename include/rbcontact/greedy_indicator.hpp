// rbcontact/greedy_indicator.hpp: the error indicator of the greedy training (offline -train_type greedy,
// docs/greedy_training.md): how far a reduced solution, computed with the reduced model with exact
// contact terms, is from satisfying the full-order contact problem; and the choice of the next FOM
// parameters from the indicators of a candidate pool.
#pragma once
#include <slepcbv.h>
#include <vector>
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/reduced_contact.hpp"
#include "rbcontact/reduced_model.hpp"

namespace rbc {

// Which measure ranks the candidates: GreedyEstimate::residual, ::penetration, the larger, or the online error
// estimate's raw u change in the enriched spaces (offline -estimate; GreedyRounds, docs/greedy_training.md).
enum class GreedyCriterion { Residual, Penetration, Max, Estimate };

// What the indicator measured at one parameter.
struct GreedyEstimate {
  PetscReal residual    = 0; // ||A u_r - f + K(u_r)' W lam_r||_{X^-1} / ||u_r||_X (X: energy at the reference parameter)
  PetscReal penetration = 0; // ||[K(u_r) u_r - g(u_r)]_+||_{M^-1} / ||K(u_r) u_r||_{M^-1} (M: slave mass)
  PetscReal value       = 0; // the criterion's measure (Evaluate: max of the two); +inf when the reduced model fails
  PetscBool converged   = PETSC_TRUE;
  PetscInt  iterations  = 0; // reduced Kacanov iterations
};

// The indicator of a reduced solution (u_r = V v, lam_r = W lhat) in the full-order model: the energy dual
// norm of the equilibrium residual with the reduced multipliers, and the relative penetration left by the
// reduced constraint. Nothing of it is online: it costs a contact assembly, Q matrix products and one
// solve with the factored X per parameter (the offline's indicator, not the online error estimate).
class GreedyIndicator {
public:
  GreedyIndicator() = default;
  GreedyIndicator(const GreedyIndicator &) = delete;
  GreedyIndicator &operator=(const GreedyIndicator &) = delete;
  ~GreedyIndicator();

  // X = A(mu_ref) assembled from fom's affine terms and factored (KSP prefix greedy_x_, Cholesky).
  PetscErrorCode Setup(ElasticFOM &fom);
  // The indicator of a given pair: u (global dof Vec of fom) and lam (FOM multiplier rows, the layout of
  // the constraint ContactMap::Assemble builds, canonical order: lamCanon[i]), at mu.
  PetscErrorCode Evaluate(ElasticFOM &fom, ContactMap &cmap, const CanonicalOrder &order, const std::vector<PetscReal> &mu, Vec u, const std::vector<PetscReal> &lamCanon, GreedyEstimate *est);
  // The reduced model's solution at mu (rm: exact contact terms on the patch full; V its primal basis; W
  // the dual basis, canonical rows) and its indicator.
  PetscErrorCode EvaluateReduced(ElasticFOM &fom, ContactMap &cmap, const CanonicalOrder &order, ReducedModel &rm, ContactPatch &full, BV V, const DenseMatrix &W, const std::vector<PetscReal> &mu, GreedyEstimate *est);
  GreedyCriterion criterion = GreedyCriterion::Max; // what Evaluate puts in est->value

private:
  KSP           ksp_ = nullptr;
  Mat           X_   = nullptr;
  Vec           r_ = nullptr, z_ = nullptr, t_ = nullptr, uloc_ = nullptr, u_ = nullptr, lam_ = nullptr, Ku_ = nullptr;
  ContactSystem sys_;
};

// Up to n candidates (indices into pool with eta >= 0; eta < 0: not a candidate) by decreasing eta,
// each at least minDist (unit-box distance) from those picked before it.
std::vector<PetscInt> GreedyPick(const std::vector<PetscReal> &eta, const std::vector<std::vector<PetscReal>> &pool, const std::vector<ParamSpec> &params, PetscInt n, PetscReal minDist);

} // namespace rbc
