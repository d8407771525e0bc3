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
//   -dual_max_r caps the size; -dual_monitor prints step, selected snapshot, largest error, cond(Gram).
#pragma once
#include <petscsys.h>
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
};

// min_{x >= 0} || Q x - b ||_2 with TAO (default BQPIP, options prefix nnls_, -nnls_tao_type) following
// ../shared/notes/nnls-with-bqpip.md (equilibration, upper bound 2, grtol 0, gatol, inner Cholesky),
// then a Lawson-Hanson active-set polish from TAO's support. Every solve is checked (x >= 0,
// gradient >= -tol, complementarity <= tol); a failed check is retried (tighter gatol, then the
// active-set method alone) and counted in stats.
class NNLSSolver {
public:
  PetscErrorCode SetFromOptions(); // reads the nnls_ options
  PetscErrorCode Solve(const DenseMatrix &Q, const std::vector<PetscReal> &b, std::vector<PetscReal> *x, NNLSStats *stats);
};

struct DualBasisResult {
  std::string           type;
  DenseMatrix           W;          // R x r, every entry >= 0
  std::vector<PetscInt> selected;   // greedy: snapshot index chosen at each step (nmf: empty)
  std::vector<PetscReal> history;   // largest training projection error after each step (greedy), objective per iteration (nmf)
  std::vector<PetscReal> gramCond;  // condition number of W^T W after each step (cpg, mcpg, angle)
  PetscReal             trainMaxErr = 0, trainMaxRelErr = 0; // projection of every snapshot onto the final cone (NNLS), in the chosen norm
  NNLSStats             nnls;
};

// Builds the dual basis of the snapshot matrix L (R x m, nonnegative) with the options above.
PetscErrorCode BuildDualBasis(const DenseMatrix &L, DualBasisResult *res);

// Projection errors of every column of L onto the cone of W (NNLS), in l-infinity or l2.
PetscErrorCode ConeProjectionErrors(const DenseMatrix &W, const DenseMatrix &L, bool linf, std::vector<PetscReal> *err, NNLSStats *stats);

} // namespace rbc
