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
// Lawson-Hanson's active-set method stopped at the tolerance (the greedy of ECSW); with more points than
// -ecsw_group_points, hierarchically (HierarchicalCubature). Serial dense code:
// every rank given the same data computes bitwise the same result.
// Implementation: src/reduction/empirical_cubature.cpp; method, options, measurements: docs/hyper_reduction.md.
#pragma once
#include <petscsys.h>
#include <functional>
#include <vector>

namespace rbc {

// What the fit measures (-ecsw_fit): every entry of each state's K^ and g^ (Frobenius), or what the reduced
// QP uses of them at the training solutions (lambda_j, v_j): the contact force on the primal modes K^' lambda_j
// and the constraint values K^ v_j - g^ (CubatureActionGram); lambda: the action fit with the constraint values
// measured by the multiplier error they cause (CubatureLambdaMetric, docs/hyper_reduction.md "The lambda fit").
enum class CubatureFit { Terms, Action, Lambda };

struct CubatureOptions {
  CubatureFit fit     = CubatureFit::Action; // -ecsw_fit (docs/hyper_reduction.md: fewer points for the same errors)
  PetscReal tol       = 1e-4;  // stop when ||G (xi - 1)|| <= tol ||G 1|| (relative RMS error of the fitted terms)
  PetscInt  maxPoints = 1000;  // at most this many points (the tolerance decides; a safeguard)
  PetscInt  groupPoints = 8000; // -ecsw_group_points: more quadrature points than this: the hierarchical fit
                                // (HierarchicalCubature); the Gram memory stays about 2.25 x 8 bytes x (this or the union)^2
  bool      monitor   = false; // print "  cubature M = k  rel residual = r" per added point
  bool      shareGroups = true; // -ecsw_share_groups: the hierarchical fit's groups fitted each by one rank of the
                                // communicator (in turn), their points then broadcast; false: every rank fits every
                                // group (the same points and weights, bit for bit; for the test that says so)
  bool      incremental = false; // the Cholesky factor of H(S, S) updated as points enter (O(k^2) a step) instead of
                                 // refactored (O(k^3)); the hierarchical fit's groups and union use it, the one-Gram
                                 // fit keeps the refactoring up to tol (its points and weights as before, bit for bit)
                                 // and updates the factor only where it goes on for the elimination
  bool      fitForce  = false; // -ecsw_fit_force: the action fit also fits the resultant contact force (online output);
                               // off by default: a third term changes what a given -ecsw_tol means (docs/hyper_reduction.md)
  bool      eliminate = true;  // -ecsw_eliminate: the fit goes on to eliminateFrom x tol (at most twice the points that first
                               // reached tol), then points are removed one at a
                               // time while the others, refitted, still reach tol (EliminateCubaturePoints); the plain fit's
                               // result if that ends with no fewer points (docs/hyper_reduction.md "Points eliminated")
  PetscReal eliminateFrom = 0.5; // -ecsw_eliminate_from, in (0, 1]
  bool      lambdaForce = true; // -ecsw_fit_lambda_force: with -ecsw_fit lambda, also the multiplier error that the
                                // forces' error causes through the displacement (CubatureLambdaMetric::forceFactor)
};

struct CubatureResult {
  std::vector<PetscInt>  points;   // selected point indices (into 0..Q-1), in the order of selection
  std::vector<PetscReal> weights;  // their weights xi_p > 0
  std::vector<PetscReal> history;  // relative residual after each added point (history[0] = 1: no point; with the elimination
                                   // it runs on to eliminateFrom x tol, and its last entry is the residual after the elimination;
                                   // when the plain fit's result is returned, its history)
  PetscReal              residual = 1; // final relative residual ||G (xi - 1)|| / ||G 1||
  PetscInt               iterations = 0; // Lawson-Hanson steps (inner removals included)
  PetscInt               eliminated = 0;  // points removed after the fit (CubatureOptions::eliminate)
  PetscInt               plainPoints = 0; // the points of the fit stopped on first reaching tol (without the elimination)
  PetscLogDouble         timeFit = 0, timeLonger = 0, timeEliminate = 0; // seconds: the fit to tol, its continuation to
                                                                         // eliminateFrom x tol, the elimination
};

// The fit restricted to candidate points C (a subset of the Q points): the Gram matrix on C only (|C| x |C|) and the
// target's pieces over every point, b_C = (H 1)_C and c = 1'H1 (H the Q x Q Gram matrix, never formed), so that the
// residual still measures the selected points' terms against the exact ones (sums over all Q points).
struct CubatureCandidates {
  std::vector<PetscInt>  points; // candidate point indices (into 0..Q-1); empty: every point, the Q x Q Gram matrix
  std::vector<PetscReal> b;      // (H 1)_C, filled by CubatureGram / CubatureActionGram
  PetscReal              c = 0;  // 1'H1
  // targetOnly: no Gram matrix and no b, only c and cOwn = 1_C' H_CC 1_C (the candidates' own terms |G_C 1|^2), each
  // ||B'A||_F^2 of the Hadamard factors over all points / over C: the hierarchical fit's first pass (its tolerances)
  bool                   targetOnly = false;
  PetscReal              cOwn = 0;
};

// A state's kappa block (Q x N, row-major, as ContactPatch::Evaluate returns it) by the state's index among the ms
// states. The pointer may be to a buffer that the next call overwrites: the offline stage forms the blocks from the
// points' terms (ContactStates) instead of holding them. The std::vector overloads below read ms contiguous blocks.
using KappaBlocks = std::function<const PetscReal *(PetscInt s)>;

// Options with prefix pre (e.g. "ecsw_"): -<pre>fit, -<pre>fit_force, -<pre>tol, -<pre>max_points, -<pre>group_points, -<pre>monitor.
PetscErrorCode CubatureOptionsFromOptions(MPI_Comm comm, const char *pre, CubatureOptions *opt);

// The Gram matrix H (Q x Q, row-major) of the fitting problem from ms states: kappa snapshots Sk (ms
// blocks of Q x N, row-major per block, as ContactPatch::Evaluate returns them), gamma snapshots Sg
// (ms blocks of Q) and P (R x Q row-major). Each state's K^ and g^ enter scaled to unit norm (a state
// whose K^ or g^ vanishes contributes nothing for that term).
// With cand (points nonempty): H is the Gram matrix on the candidates (|C| x |C|) and cand->b, cand->c are filled.
void CubatureGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, std::vector<PetscReal> *H, CubatureCandidates *cand = nullptr);
void CubatureGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const KappaBlocks &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, std::vector<PetscReal> *H, CubatureCandidates *cand = nullptr);

// The action fit's per-state scalings (each state's terms to unit norm over the training solutions), the same in every
// call of CubatureActionGram on the same states and training solutions: given one, a call fills it (when empty) or uses
// it, instead of forming every state's exact reduced terms again (R x Q x N a state: at 5e5 3D dofs as much as the
// Gram products of the hierarchical fit's calls).
struct CubatureScalings {
  std::vector<PetscReal> s1, s2; // ms each
};

// The lambda fit's metric at the training solutions: per solution j, T_j (k_j x R, row-major) such that ||T_j dr|| is the
// first-order change of the multiplier lambda = W lambda^ in the slave-mass norm caused by an error dr of the reduced
// constraint values K^ v_j - g^ (on the free set F_j = {r : lambda^_j(r) > 0}, the reduced QP's equality rows):
// d lambda^_F = S_F^{-1} dr_F, S_F = K^_F A^{-1} K^_F', so T_j = L_F' S_F^{-1} E_F with M_F = L_F L_F' (M: W' diag(w) W
// on the free set). Empty rows for a solution without contact.
// The multiplier error has a second first-order part, from an error dF = dK' lambda_j of the contact forces through the
// displacement: d lambda^_F = -S_F^{-1} K^_F A^{-1} dF, i.e. ||C_j dF|| with C_j = L_F' S_F^{-1} K^_F A^{-1} (k_j x N).
// The fit takes it with one metric for all solutions, G = mean_j C_j' C_j = Fg Fg' (forceFactor, N x rank, row-major;
// empty: the term is left out): sum_j ||Fg' dK_s' lam_j||^2 in the constraint term's per-state scaling.
struct CubatureLambdaMetric {
  std::vector<std::vector<PetscReal>> T; // nt blocks, k_j x R row-major
  std::vector<PetscReal>              forceFactor;
  PetscInt                            forceRank = 0;
  // y(p) = kappa_s(p, :) . v_j at every point (Q), for state s and training solution j; empty: from the kappa blocks
  // (the fit takes one solution at a time: the blocks would be formed nt times)
  std::function<void(PetscInt s, PetscInt j, PetscReal *y)> kappaTimes;
};
// One solution's T (k x R, row-major, returned k): A (N x N, column-major, SPD) the reduced stiffness, K (R x N,
// column-major) the exact reduced constraint at the solution, lam (R) its coefficients, M (R x R) the mass Gram of W.
// S_F, M_F (and A) are factored with a ridge of 1e-12, then 1e-9, of their largest diagonal entry when rounding makes them
// indefinite; T empty (k = 0) if even that fails. With C: also C_j (k x N, row-major; empty with T).
PetscInt CubatureLambdaWeights(PetscInt R, PetscInt N, const PetscReal *A, const PetscReal *K, const PetscReal *lam, const std::vector<PetscReal> &M, std::vector<PetscReal> *T, std::vector<PetscReal> *C = nullptr);
// The factor Fg (N x rank, row-major) of G = (1/n) sum of the n blocks' C' C (each k x N, row-major; empty ones skipped and
// not counted): the eigenvectors of G scaled by the square roots of its eigenvalues, those above 1e-8 of the largest.
PetscInt CubatureLambdaForceFactor(PetscInt N, const std::vector<std::vector<PetscReal>> &C, std::vector<PetscReal> *Fg);

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
// With metric (the lambda fit), the constraint term is measured by the multiplier error it causes:
//   sum_j ||T_j (dK_s v_j - dg_s)||^2 / sum_j (||T_j K^_s v_j||^2 + ||T_j g^_s||^2),  H += sum_j ((T_j P)'(T_j P)) o (Y_j Y_j'),
// and, with its forceFactor, the forces' part in the same scaling, sum_j ||Fg' dK_s' lam_j||^2, i.e. the force term's
// columns Zk extended by the scaled columns kappa_s Fg.
// Zk and Y are formed `block` states at a time (0: as many as fit in about 64 MB), never whole: at 41k 3D dofs
// they were 2.9 + 2.3 GB (docs/rom3d.md). The block size changes H only by rounding. With cand, as CubatureGram.
void CubatureActionGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const std::vector<PetscReal> &Lam, const std::vector<PetscReal> &Vs, PetscInt nt, std::vector<PetscReal> *H, const std::vector<PetscReal> &Sw = {}, PetscInt dim = 0, PetscInt block = 0, CubatureCandidates *cand = nullptr, CubatureScalings *scalings = nullptr, const CubatureLambdaMetric *metric = nullptr);
void CubatureActionGram(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const KappaBlocks &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const std::vector<PetscReal> &Lam, const std::vector<PetscReal> &Vs, PetscInt nt, std::vector<PetscReal> *H, const std::vector<PetscReal> &Sw = {}, PetscInt dim = 0, PetscInt block = 0, CubatureCandidates *cand = nullptr, CubatureScalings *scalings = nullptr, const CubatureLambdaMetric *metric = nullptr);

// Per state, the relative errors of the cubature's K^ (Frobenius) and g^ (l2) against the exact ones.
void CubatureStateErrors(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const CubatureResult &res, std::vector<PetscReal> *errK, std::vector<PetscReal> *errG);
void CubatureStateErrors(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const KappaBlocks &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const CubatureResult &res, std::vector<PetscReal> *errK, std::vector<PetscReal> *errG);

// Sparse NNLS in Gram form: min over xi >= 0 of (xi - 1)' H (xi - 1), points added greedily (largest
// gradient) until the relative residual sqrt((xi - 1)' H (xi - 1) / 1' H 1) <= opt.tol.
// Errors: H not Q x Q or non-finite -> PETSC_ERR_ARG_*; tolerance not reached within maxPoints or
// before the gradient vanishes -> result returned with its residual (the caller decides).
// With cand (points nonempty): H is the candidates' Gram matrix, b and c come from cand, the selected points are
// returned as indices into 0..Q-1.
// With opt.eliminate, the fit that reached opt.tol is then thinned by EliminateCubaturePoints.
PetscErrorCode EmpiricalCubature(const std::vector<PetscReal> &H, PetscInt Q, const CubatureOptions &opt, CubatureResult *res, const CubatureCandidates *cand = nullptr);

// Backward elimination after a fit (the point-removal step of Hernandez et al.'s continuous ECM, CMAME 2024, on the
// fixed points): the support S (its least-squares weights positive, as Lawson-Hanson ends) loses, one at a time, the
// point whose removal raises the residual least, z_j^2 / (H(S, S)^{-1})_jj, among those after which the others'
// least-squares weights stay positive and the relative residual stays <= tol. The inverse (updated by rank one) only
// predicts; each removal is solved with the Cholesky factor updated by the deletion and checked exactly. H is the Gram
// matrix on the Q points (row-major), b and c the target (b = (H 1) over every point, c = 1'H1); x (Q entries) gets
// the new weights, rel the relative residual. Returns the number of points removed; S keeps the order of those that stay.
PetscInt EliminateCubaturePoints(const std::vector<PetscReal> &H, PetscInt Q, const std::vector<PetscReal> &b, PetscReal c, PetscReal tol, std::vector<PetscInt> *S, std::vector<PetscReal> *x, PetscReal *rel);
// The Gram matrices' Hadamard products are accumulated a block of columns at a time (at most this many columns; 0, the
// default: n / 8 of n, at least 64; the candidates' states are also gathered up to this many columns, or n^2 / 8 entries, before each
// product). For tests, which exercise the blocks on small sizes; the result changes by rounding only.
void SetCubatureGramColumnBlock(PetscInt columns);
// The elimination's inverse formed afresh after this many removals (0, the default: max(64, k / 8) of k points). For
// tests, which reach the refresh on small sizes; the result changes only where the predictions order the trials differently.
void SetCubatureEliminationRefresh(PetscInt removals);

// The Gram system of the fit on candidates (nullptr: every point, H Q x Q): CubatureGram or CubatureActionGram bound to
// their data.
using CubatureGramFunction = std::function<void(CubatureCandidates *, std::vector<PetscReal> *)>;

struct CubatureHierarchy {
  PetscInt               groups = 1;     // 1: one Gram matrix of every point
  PetscInt               candidates = 0; // points of the final fit (the union of the groups' points)
  PetscReal              groupTol = 0;   // the groups' tolerance
  std::vector<PetscReal> groupResiduals;
};

// The cubature of Q points. Q <= opt.groupPoints (or 0): EmpiricalCubature on the Gram matrix of every point. Otherwise
// hierarchically, with Gram matrices of at most opt.groupPoints points (memory |group|^2, not Q^2): the points split
// into K contiguous groups (the patch points come facet by facet: groups are pieces of the surface); each group fitted
// to its own terms G_g 1 at tol_g = opt.tol |G 1| / sum_g |G_g 1|, so that the groups' weights together fit the whole
// terms within opt.tol (triangle inequality); then the fit of the whole terms (every point's) among the union of the
// groups' points, which therefore reaches opt.tol. The reported residual is against the exact terms of every point.
// Errors: a group not reaching tol_g (PETSC_ERR_NOT_CONVERGED, naming -ecsw_max_points and -ecsw_group_points).
// Parallel: collective on comm; with collectiveGram, gram is called by every rank for every group in the same order (it may sum over comm),
// and must give every rank the same matrix. With opt.shareGroups the groups' fits (independent once their matrices are
// formed) are dealt to the ranks in turn, group g to rank g mod size, each rank fitting while the others fit theirs, and
// the points broadcast: the result is the same bit for bit as every rank fitting every group, in about 1/size of the
// fits' time (memory: a rank keeps its group's matrix while the next ones of its batch are formed, at most twice one).
// PETSC_COMM_SELF: the serial fit. collectiveGram false: gram is local (every rank holds every state), and with
// opt.shareGroups a rank forms only the Gram matrices of the groups it fits (the first pass's targets still all).
PetscErrorCode HierarchicalCubature(MPI_Comm comm, PetscInt Q, const CubatureOptions &opt, const CubatureGramFunction &gram, CubatureResult *res, CubatureHierarchy *info = nullptr, bool collectiveGram = true);

} // namespace rbc
