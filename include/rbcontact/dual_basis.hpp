// rbcontact/dual_basis.hpp: nonnegative dual (multiplier) bases from multiplier snapshots, and the
// NNLS cone projections they need. Everything here is small dense linear algebra on the snapshot
// matrix (R multipliers x m snapshots, R ~ 10^2..10^4, m ~ 10^1..10^3): it runs redundantly and
// deterministically on every rank (PETSC_COMM_SELF objects), so every rank holds the same basis.
//   -dual_type nmf|angle|cpg|mcpg
//   nmf:   Lee-Seung multiplicative updates, R given by -dual_r, seeded (-dual_seed), stop on the
//          relative change of the objective (-dual_nmf_rtol, -dual_nmf_max_it)
//   angle: greedy on the projection error onto the linear span of the selected snapshots (-dual_tol)
//   cpg:   cone-projected weak greedy (the seed's algorithm): largest error of the NNLS projection
//          onto the current cone, l-infinity (default) or l2 (-dual_norm linf|l2); stop at -dual_tol
//          (absolute; relative to the largest snapshot norm with -dual_tol_relative)
//   mcpg:  modified CPG (Niakh, Drouet, Ehrlacher, Ern 2022): adds the normalized nonnegative remainder
//          theta - Upsilon, Upsilon = argmin over the cone intersected with {Upsilon <= theta}
//   -dual_max_cond (1e12): a greedy pick that would make cond(W^T W) exceed it (a vector in, or nearly in, the
//          span of the basis but outside its cone: seen on the 3D sphere_block3d) is skipped, W^T W stays invertible
//   -dual_max_r caps the size; -dual_monitor prints step, selected snapshot, largest error, cond(Gram).
//   Implementation: src/reduction/nnls.cpp (NNLS), src/reduction/dual_basis.cpp (the four bases);
//   algorithms, options and measured numbers: docs/dual_basis.md.
#pragma once
#include <petsctao.h>
#include "rbcontact/tao_recipe.hpp"
#include <string>
#include <vector>

namespace rbc {

// Column-major dense matrix.
struct DenseMatrix {
  PetscInt               rows = 0, cols = 0;
  std::vector<PetscReal> a;
  PetscReal       &operator()(PetscInt i, PetscInt j) { return a[i + (size_t)j * rows]; }
  const PetscReal &operator()(PetscInt i, PetscInt j) const { return a[i + (size_t)j * rows]; }
  void Resize(PetscInt r, PetscInt c) { rows = r; cols = c; a.assign((size_t)r * c, 0.0); }
};

struct NNLSStats {
  PetscInt  solves = 0, retries = 0, failures = 0;
  PetscReal maxKKT = 0; // worst scaled KKT residual over the solves
  PetscInt  taoIterations = 0, polishIterations = 0; // totals over the solves
};

// What one NNLS solve did (optional output of NNLSSolver::Solve).
struct NNLSInfo {
  PetscInt           attempts = 0;         // attempts made (tao: TAO, TAO gatol/10, active set; activeset: warm, cold, TAO, TAO gatol/10)
  PetscInt           taoIterations = 0;    // of the accepted attempt (0 if TAO was not used)
  TaoConvergedReason taoReason = TAO_CONTINUE_ITERATING;
  PetscInt           polishIterations = 0; // active-set changes of the Lawson-Hanson polish
  PetscReal          kkt = 0;              // scaled KKT residual (equilibrated problem), see NNLSKKT
  PetscReal          residual = 0;         // ||Q x - b|| with the original Q and b
  PetscBool          ok = PETSC_TRUE;      // kkt <= -nnls_kkt_tol
};

// min_{x >= 0} || Q x - b ||_2 by the Lawson-Hanson active-set method (default -nnls_method activeset,
// warm-started from a previous solution when given), or (-nnls_method tao) with TAO (BQPIP, options prefix nnls_, -nnls_tao_type) following
// ../shared/notes/nnls-with-bqpip.md (equilibration, upper bound 2, grtol 0, gatol, inner Cholesky),
// then a Lawson-Hanson active-set polish from TAO's support. Every solve is checked (x >= 0,
// gradient >= -tol, complementarity <= tol); a failed check is retried (tighter gatol, then the
// active-set method alone) and counted in stats.
//   Options (collective on PETSC_COMM_WORLD, so -help lists them): -nnls_method tao|activeset,
//   -nnls_polish <bool>, -nnls_kkt_tol <1e-9>, -nnls_support_tol <1e-6>, and the Tao's own options
//   with prefix nnls_ (-nnls_tao_type, -nnls_tao_gatol <1e-7>, -nnls_tao_grtol <0>, -nnls_tao_max_it <200>,
//   -nnls_ksp_type <preonly>, -nnls_pc_type <cholesky>). Without SetFromOptions the defaults are used.
// One Tao is kept and reused while the number of columns stays the same (a new one when it changes).
class NNLSSolver {
public:
  NNLSSolver() = default;
  NNLSSolver(const NNLSSolver &) = delete;
  NNLSSolver &operator=(const NNLSSolver &) = delete;
  ~NNLSSolver(); // destroys the cached Tao (call Reset() before PetscFinalize if the solver outlives it)
  PetscErrorCode SetFromOptions(); // reads the nnls_ options
  // stats (may be null) accumulates; info (may be null) describes this solve.
  // start (may be null; size Q.cols): a previous solution whose support starts the active-set method
  // (the cone-projected greedy passes each snapshot's projection of the previous step).
  PetscErrorCode Solve(const DenseMatrix &Q, const std::vector<PetscReal> &b, std::vector<PetscReal> *x, NNLSStats *stats, NNLSInfo *info = nullptr, const std::vector<PetscReal> *start = nullptr);
  PetscErrorCode Reset(); // destroys the cached Tao and problem data

private:
  PetscErrorCode SetupTao(PetscInt n);
  PetscErrorCode SolveTao(const std::vector<PetscReal> &H, const std::vector<PetscReal> &c, PetscBool bounded, PetscReal gatolFactor, std::vector<PetscReal> *y, PetscInt *its, TaoConvergedReason *reason);

  PetscBool useTao_ = PETSC_FALSE, polish_ = PETSC_TRUE;
  PetscReal kktTol_ = 1e-9, supportTol_ = 1e-6;
  Tao       tao_ = nullptr;
  Mat       H_   = nullptr;
  Vec       x_ = nullptr, c_ = nullptr, lo_ = nullptr, hi_ = nullptr;
  TaoQuadratic quad_; // H_, c_ for TAO
  PetscInt  n_ = -1;
  // equilibrated copy of the last Q (reused while Q does not change, e.g. all snapshots of a greedy step)
  DenseMatrix            lastQ_, Qs_;
  std::vector<PetscReal> colNorm_, Hs_;
  std::vector<PetscInt>  cols_; // nonzero columns of Q
  bool                   nonnegative_ = true;
};

// Lawson-Hanson active-set NNLS on Q itself (least-squares subproblems by Householder QR of the passive
// columns, LAPACK geqrf/ormqr/trtrs): min ||Q x - b|| over x >= 0 for any Q (nonnegative or not,
// rank-deficient allowed: columns that would make the passive set numerically dependent are rejected).
// x: on input its positive entries are the starting support (empty: classic Lawson-Hanson from 0);
// on output the solution. Used as TAO's polish, as the fallback of NNLSSolver and for mcpg's subproblem.
PetscErrorCode NNLSLawsonHanson(const DenseMatrix &Q, const std::vector<PetscReal> &b, std::vector<PetscReal> *x, PetscInt maxit, PetscInt *iterations);

// Scaled KKT residual of x for min ||Q x - b||, x >= 0, i.e. that of the equilibrated problem (unit
// columns, ||b|| = 1): with y_j = x_j ||q_j|| / ||b|| and g_j = (Q^T (Q x - b))_j / (||q_j|| ||b||),
// max_j max(|min(y_j, g_j)|, |y_j g_j|) over the nonzero columns (0 iff optimal; covers x >= 0,
// g >= 0 on the zeros and complementarity).
PetscReal NNLSKKT(const DenseMatrix &Q, const std::vector<PetscReal> &b, const std::vector<PetscReal> &x);

struct DualBasisResult {
  std::string           type;
  DenseMatrix           W;          // R x r, every entry >= 0
  std::vector<PetscInt> selected;   // greedy: snapshot index chosen at each step (nmf: empty)
  std::vector<PetscInt> skipped;    // greedy: snapshots whose pick would have made cond(W^T W) > -dual_max_cond (not added)
  std::vector<PetscReal> history;   // largest training projection error after each step (greedy), objective per iteration (nmf)
  std::vector<PetscReal> gramCond;  // condition number of W^T W after each step (cpg, mcpg, angle); nmf: of the final W
  PetscReal             trainMaxErr = 0, trainMaxRelErr = 0; // projection of every snapshot onto the final cone (NNLS), in the chosen norm
  NNLSStats             nnls;
  std::string           norm = "linf";      // norm of the errors: linf or l2
  PetscReal             initialMaxErr = 0;  // largest snapshot norm (the error of the empty basis)
  PetscReal             tolAbs = 0;         // the absolute tolerance the greedy used (after -dual_tol_relative)
  // Whether the basis meets it (nmf does not read -dual_tol; a greedy may stop at -dual_max_r or at the cone's limit).
  bool TolReached() const { return trainMaxErr <= tolAbs * (1 + 1e-12); }
  // Why it does not, for a warning (snapshots: the number of candidate columns): nmf's fixed rank, every snapshot kept,
  // the cone's limit, a greedy whose own error met the tolerance while the cone projection's did not (angle measures
  // the distance to the span), or -dual_max_r (the last reason said before 2026-12-01 even where -dual_max_r was unset).
  std::string MissedTolReason(PetscInt snapshots) const
  {
    if (type == "nmf") return "nmf has the fixed rank -dual_r and does not read -dual_tol";
    if (W.cols >= snapshots) return "every snapshot is in the basis";
    if (!skipped.empty()) return "the remaining snapshots lie in the span of the basis but outside its cone (-dual_max_cond)";
    if (!history.empty() && history.back() <= tolAbs * (1 + 1e-12)) return "the greedy met the tolerance in its own measure (" + std::string(type == "angle" ? "angle: the distance to the span" : "its selection error") + "), the projection onto the cone of the basis does not";
    return "-dual_max_r stopped the greedy";
  }
  std::vector<PetscReal> trainErr;          // final projection error of every snapshot (NNLS onto the cone of W)
  PetscReal             mcpgMinRemainder = 0;    // mcpg: min over steps of min(theta - Upsilon) / ||theta|| before clipping (>= -1e-12)
  PetscReal             mcpgMaxLDPViolation = 0; // mcpg: max over steps of the LDP solution's violation of Upsilon <= theta (before restoration), / ||theta||
};

// Builds the dual basis of the snapshot matrix L (R x m, nonnegative) with the options above.
// Collective on PETSC_COMM_WORLD only for reading options; the computation is local and identical on every rank.
// tolOverride >= 0: this tolerance instead of -dual_tol (offline -estimate's enriched space; relative with -dual_tol_relative).
PetscErrorCode BuildDualBasis(const DenseMatrix &L, DualBasisResult *res, PetscReal tolOverride = -1);
// -dual_tol's default (read by BuildDualBasis, and by offline -estimate).
constexpr PetscReal kDualDefaultTol = 1e-3;
static const char *const kDualTypes[] = {"nmf", "angle", "cpg", "mcpg"};
static const char *const kDualNorms[] = {"linf", "l2"};
// The -dual_* options of BuildDualBasis, checked where they do not depend on the snapshots (the offline stage calls it
// before the snapshots: hours on a real scene).
struct DualBasisOptions {
  PetscInt  type = 2, norm = 0, r = 5, seed = 1, nmfMaxIt = 2000, maxR = -1; // type, norm: indices of kDualTypes, kDualNorms; maxR -1: all
  PetscReal tol = kDualDefaultTol, nmfRtol = 1e-6, feasTol = 1e-12, maxCond = 1e12;
  PetscBool tolRelative = PETSC_FALSE, monitor = PETSC_FALSE;
};
PetscErrorCode DualBasisOptionsFromOptions(MPI_Comm comm, DualBasisOptions *o);

// Projection errors of every column of L onto the cone of W (NNLS), in l-infinity or l2.
// solver: a configured NNLSSolver to use (null: a local one, configured from the options: collective).
// warm (may be null): per snapshot, the coefficients of its previous projection (in/out; padded with zeros
// for columns added since), the start of each NNLS.
PetscErrorCode ConeProjectionErrors(const DenseMatrix &W, const DenseMatrix &L, bool linf, std::vector<PetscReal> *err, NNLSStats *stats, NNLSSolver *solver = nullptr, std::vector<std::vector<PetscReal>> *warm = nullptr);

// mcpg's subproblem: Upsilon = W y, y = argmin ||theta - W y|| s.t. y >= 0, W y <= theta (theta >= 0).
// Solved as a least-squares problem with inequality constraints by Lawson-Hanson's LSI -> LDP -> NNLS
// reduction (see docs/dual_basis.md), then made feasible by scaling Upsilon by s <= 1.
// remainderMin: min_i (theta - Upsilon)_i / ||theta|| of the returned Upsilon (feasibility, >= 0 up to
// rounding); ldpViolation: max_i (Upsilon - theta)_i / ||theta|| of the LDP solution before the scaling.
PetscErrorCode ConeLowerProjection(const DenseMatrix &W, const std::vector<PetscReal> &theta, std::vector<PetscReal> *upsilon, PetscReal *remainderMin, PetscReal *ldpViolation = nullptr);

// cond(W^T W) = lambda_max / lambda_min of the Gram matrix (LAPACK syev); inf if lambda_min <= n eps lambda_max
// (numerically singular: values above ~1e15 are not resolved through the Gram matrix).
PetscErrorCode GramConditionNumber(const DenseMatrix &W, PetscReal *cond);

} // namespace rbc
