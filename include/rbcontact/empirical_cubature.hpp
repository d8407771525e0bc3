// rbcontact/empirical_cubature.hpp: empirical cubature of the reduced contact terms (energy-conserving
// sampling and weighting, ECSW: Farhat, Chapman, Avery 2015; empirical cubature method, ECM: Hernandez
// et al. 2017). The exact reduced terms at a state s (parameter and displacement) are sums over the Q
// points of the contact quadrature,
//   K^_s = sum_p P_{:,p} kappa_s(p,:),   g^_s = sum_p P_{:,p} gamma_s(p)     (P = W' Psi, R x Q),
// with kappa, gamma the exact pointwise contact kernel (src/contact/contact_point.hpp). The cubature
// keeps a few points S with weights xi_p >= 0,
//   K^_s ~ sum_{p in S} xi_p P_{:,p} kappa_s(p,:),   g^_s likewise,
// fitted on the training states by a sparse nonnegative least-squares problem: min ||G (xi - 1)|| over
// xi >= 0 with few nonzeros, G stacking every state's terms (each state's K^ and g^ scaled to unit
// Frobenius norm). Nonnegative weights keep every reduced row a nonnegative combination of pointwise
// gaps, as in the full-order model. Dimension-generic (the points are patch points, 2D or 3D).
// Solved in Gram form H = G'G (Q x Q, the Hadamard product of P'P with the states' kernel Grams) by
// Lawson-Hanson's active-set method stopped at the tolerance (the greedy of ECSW). Serial dense code:
// every rank given the same data computes bitwise the same result.
// Implementation: src/reduction/empirical_cubature.cpp; method, options, measurements: docs/hyper_reduction.md.
#pragma once
#include <petscsys.h>
#include <vector>

namespace rbc {

// What the fit measures (-ecsw_fit): every entry of each state's K^ and g^ (Frobenius), or what the reduced
// QP uses of them at the training solutions (lambda_j, v_j): the contact force on the primal modes K^' lambda_j
// and the constraint values K^ v_j - g^ (CubatureActionGram).
enum class CubatureFit { Terms, Action };

struct CubatureOptions {
  CubatureFit fit     = CubatureFit::Action; // -ecsw_fit (docs/hyper_reduction.md: fewer points for the same errors)
  PetscReal tol       = 1e-4;  // stop when ||G (xi - 1)|| <= tol ||G 1|| (relative RMS error of the fitted terms)
  PetscInt  maxPoints = 1000;  // at most this many points (the tolerance decides; a safeguard)
  bool      monitor   = false; // print "  cubature M = k  rel residual = r" per added point
  bool      fitForce  = false; // -ecsw_fit_force: the action fit also fits the resultant contact force (online output);
                               // off by default: a third term changes what a given -ecsw_tol means (docs/hyper_reduction.md)
};

struct CubatureResult {
  std::vector<PetscInt>  points;   // selected point indices (into 0..Q-1), in the order of selection
  std::vector<PetscReal> weights;  // their weights xi_p > 0
  std::vector<PetscReal> history;  // relative residual after each added point (history[0] = 1: no point)
  PetscReal              residual = 1; // final relative residual ||G (xi - 1)|| / ||G 1||
  PetscInt               iterations = 0; // Lawson-Hanson steps (inner removals included)
};

// Options with prefix pre (e.g. "ecsw_"): -<pre>fit, -<pre>fit_force, -<pre>tol, -<pre>max_points, -<pre>monitor.
PetscErrorCode CubatureOptionsFromOptions(MPI_Comm comm, const char *pre, CubatureOptions *opt);

// The Gram matrix H (Q x Q, row-major) of the fitting problem from ms states: kappa snapshots Sk (ms
// blocks of Q x N, row-major per block, as ContactPatch::Evaluate returns them), gamma snapshots Sg
// (ms blocks of Q) and P (R x Q row-major). Each state's K^ and g^ enter scaled to unit norm (a state
// whose K^ or g^ vanishes contributes nothing for that term).
void CubatureGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, std::vector<PetscReal> *H);

// The Gram matrix of the action fit: per state s, with the nt training solutions Lam (nt x R, row-major)
// and Vs (nt x N, row-major),
//   sum_j ||dK_s' lam_j||^2 / sum_j ||K^_s' lam_j||^2 + sum_j ||dK_s v_j - dg_s||^2 / sum_j (||K^_s v_j||^2 + ||g^_s||^2),
// dK, dg the cubature's errors: H = ((P'Lam')(Lam P)) o (Zk Zk') + (P'P) o (Y Y'), Zk the scaled kappa
// columns, Y(p, (s, j)) = kappa_s(p, :) v_j - gamma_s(p) scaled. Weighted Frobenius norms: the row directions
// no training multiplier takes and the columns no training solution uses weigh little.
// With Sw (ms blocks of Q x dim, row-major: each point's weight times its unit master normal, w_p n2(x_p),
// ContactPatch::Evaluate's wn), a third term fits the resultant contact force F_s(lam_j) = sum_p
// (P' lam_j)(p) w_p n2(x_p), the output of interest the online stage computes from the cubature (docs/online.md):
//   + sum_j ||dF_s(lam_j)||^2 / sum_j ||F_s(lam_j)||^2,   i.e. H += ((P'Lam')(Lam P)) o (Zf Zf').
// Zk and Y are formed `block` states at a time (0: as many as fit in about 64 MB), never whole: at 41k 3D dofs
// they were 2.9 + 2.3 GB (docs/rom3d.md). The block size changes H only by rounding.
void CubatureActionGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const std::vector<PetscReal> &Lam, const std::vector<PetscReal> &Vs, PetscInt nt, std::vector<PetscReal> *H, const std::vector<PetscReal> &Sw = {}, PetscInt dim = 0, PetscInt block = 0);

// Per state, the relative errors of the cubature's K^ (Frobenius) and g^ (l2) against the exact ones.
void CubatureStateErrors(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const CubatureResult &res, std::vector<PetscReal> *errK, std::vector<PetscReal> *errG);

// Sparse NNLS in Gram form: min over xi >= 0 of (xi - 1)' H (xi - 1), points added greedily (largest
// gradient) until the relative residual sqrt((xi - 1)' H (xi - 1) / 1' H 1) <= opt.tol.
// Errors: H not Q x Q or non-finite -> PETSC_ERR_ARG_*; tolerance not reached within maxPoints or
// before the gradient vanishes -> result returned with its residual (the caller decides).
PetscErrorCode EmpiricalCubature(const std::vector<PetscReal> &H, PetscInt Q, const CubatureOptions &opt, CubatureResult *res);

} // namespace rbc
