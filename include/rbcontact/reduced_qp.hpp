// rbcontact/reduced_qp.hpp: the small dense saddle-point QP of the online (reduced) stage,
//   min_v 1/2 v'Av - f'v  s.t.  D v <= c     (A N x N SPD, D R x N, N, R <= ~60),
// solved through its dual  min_{lambda >= 0} 1/2 lambda'S lambda - b'lambda,  S = D A^{-1} D',
// b = D A^{-1} f - c, then v = A^{-1}(f - D'lambda). ReducedQP owns the method (a Lawson-Hanson-type
// active-set method on S with Cholesky factors of S restricted to the free set: the fast, exact default;
// or TAO BQPIP as a cross-check), its workspace (no heap allocation in Solve after Reserve on the
// active-set path), the status/diagnostics of a solve and the scaled KKT residuals.
// Implementation: src/rom/reduced_qp.cpp; method, options, statuses and timings: docs/reduced_qp.md.
#pragma once
#include <petsctao.h>
#include "rbcontact/tao_recipe.hpp"
#include <string>
#include <vector>

namespace rbc {

enum class ReducedQPType { ActiveSet, Tao };
enum class ReducedQPStatus { Ok = 0, NotSPD, Infeasible, Singular, MaxIt, TaoFailed };
const char *ReducedQPStatusName(ReducedQPStatus);

struct ReducedQPInfo {
  ReducedQPStatus status = ReducedQPStatus::Ok;
  PetscInt        iterations = 0; // activeset: solves with the Cholesky factor of S on the free set + ray steps; tao: TAO iterations
  PetscInt        nactive    = 0; // multipliers > 0 (tao: > 1e-6 max lambda, an interior point has no exact zeros)
  // Scaled KKT residuals of the returned (v, lambda), r = D v - c, sc = ||c||_inf + ||D||_inf ||v||_inf:
  //   primal = max(max_i r_i, 0) / sc, dual = max_i max(-lambda_i, 0) / ||lambda||_inf,
  //   complementarity = |lambda'r| / (||lambda||_inf sc), stationarity = ||Av - f + D'lambda||_inf / (||f||_inf + ||A||_inf ||v||_inf)
  PetscReal   primal = 0, dual = 0, complementarity = 0, stationarity = 0;
  std::string message; // human-readable reason when status != Ok, with a hint when useful (empty when Ok)
};

class ReducedQP {
public:
  ReducedQP() = default;
  ReducedQP(const ReducedQP &) = delete;
  ReducedQP &operator=(const ReducedQP &) = delete;
  ~ReducedQP(); // destroys the TAO objects if any (call Reset() first if the solver outlives PetscFinalize)

  // -<prefix>qp_type activeset|tao (default activeset), -<prefix>qp_max_it (default 200), and for the
  // TAO cross-check the options of a Tao with prefix "<prefix>qp_" (-<prefix>qp_tao_type <bqpip>,
  // -<prefix>qp_tao_gatol <1e-7>, -<prefix>qp_tao_grtol <0>, -<prefix>qp_tao_max_it <200>,
  // -<prefix>qp_ksp_type <preonly>, -<prefix>qp_pc_type <cholesky>). Not collective (PETSC_COMM_SELF).
  PetscErrorCode SetFromOptions(const std::string &prefix); // e.g. prefix "rom_" -> -rom_qp_type

  // Reserves workspace for sizes up to N, R: Solve with sizes within it never allocates (activeset path).
  void Reserve(PetscInt N, PetscInt R);

  // All arrays column-major: A (N x N, its lower triangle is factored), f (N), D (R x N), c (R).
  // lambda (R): in = warm start (its positive entries are the initial free-set guess; zeros for none),
  // out = multipliers. v (N): out. Returns PETSc errors only for PETSc failures and for non-finite
  // entries in A, f, D or c (PETSC_ERR_FP); a numerical failure is reported in info->status/message,
  // with v and lambda left finite. info->message is empty when the status is Ok.
  PetscErrorCode Solve(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *D, const PetscReal *c, PetscReal *v, PetscReal *lambda, ReducedQPInfo *info);

  PetscErrorCode Reset(); // destroys the TAO objects and forgets the cached factorization

  // A that does not change between solves (a reduced model whose A^ does not depend on mu): FactorA factors it once
  // (info NotSPD as Solve would report it); SolveFactored then takes GT = D L^{-T} (R x N, column-major; A = L L',
  // L = FactorL(), lower N x N) in place of A and D, and skips the comparison of A with the previous call's and the
  // triangular solve of D that Solve does. The caller forms GT itself, e.g. from basis rows transformed by L^{-1}.
  // Same outputs, statuses and residual definitions as Solve (its residuals from D = GT L', formed once, and the A of
  // FactorA). A Solve with another A (or Reset) replaces the factor: HasFactor(N) tells, SolveFactored refuses.
  PetscErrorCode FactorA(PetscInt N, const PetscReal *A, ReducedQPInfo *info);
  bool           HasFactor(PetscInt N) const { return factored_ && cN_ == N; }
  // A = I (coordinates in which the caller's A is the identity: AffineDiagonalization): L = I, and SolveFactored,
  // ResidualsFactored skip the triangular solves and products with it (GT = D). HasIdentity(N) tells.
  void           SetIdentityA(PetscInt N);
  bool           HasIdentity(PetscInt N) const { return HasFactor(N) && unit_; }
  const PetscReal *FactorL() const { return L_.data(); }
  PetscErrorCode SolveFactored(PetscInt N, PetscInt R, const PetscReal *f, const PetscReal *GT, const PetscReal *c, PetscReal *v, PetscReal *lambda, ReducedQPInfo *info);
  // The scaled KKT residuals (as Residuals) of (v, lambda) for the data of the last SolveFactored, D = GT L' formed here.
  // A nullptr: the A of FactorA or SetIdentityA.
  void ResidualsFactored(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *GT, const PetscReal *c, const PetscReal *v, const PetscReal *lambda, ReducedQPInfo *info);

  ReducedQPType type  = ReducedQPType::ActiveSet;
  PetscInt      maxIt = 200;
  // Reuse the Cholesky factor of A when A is bitwise equal to the previous call's, and S (and D L^{-T})
  // when D is too (memcmp on every call); f and c always enter the setup.
  bool reuseFactorization = true;
  // false: Solve leaves the scaled KKT residuals of info at 0 on the active-set path (a loop that only
  // needs them for its last solve calls Residuals then; TAO always computes them: its status needs them).
  bool residuals = true;
  // The scaled KKT residuals of (v, lambda) for the data of the last Solve (same A, D: the norms of its
  // set-up), into info->primal, dual, complementarity, stationarity.
  void Residuals(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *D, const PetscReal *c, const PetscReal *v, const PetscReal *lambda, ReducedQPInfo *info) { KKT(N, R, A, f, D, c, v, lambda, info); }

private:
  PetscErrorCode Setup(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *D, const PetscReal *c, ReducedQPInfo *info);
  PetscErrorCode FactorInto(PetscInt N, const PetscReal *A, ReducedQPInfo *info);
  void           DualHessian(PetscInt N, PetscInt R);
  void           RightHandSide(PetscInt N, PetscInt R, const PetscReal *f, const PetscReal *c);
  PetscErrorCode Finish(PetscInt N, PetscInt R, PetscReal *v, PetscReal *lambda, ReducedQPInfo *info);
  void           TaoStatus(PetscInt R, const PetscReal *lambda, ReducedQPInfo *info);
  void           ActiveSet(PetscInt R, PetscReal *l, ReducedQPInfo *info);
  PetscErrorCode SolveTao(PetscInt R, PetscReal *l, ReducedQPInfo *info);
  PetscErrorCode SetupTao(PetscInt R);
  void           Recover(PetscInt N, PetscInt R, const PetscReal *l, PetscReal *v);
  void           KKT(PetscInt N, PetscInt R, const PetscReal *A, const PetscReal *f, const PetscReal *D, const PetscReal *c, const PetscReal *v, const PetscReal *lambda, ReducedQPInfo *info);
  bool           AppendFree(PetscInt R, PetscInt k, PetscInt j, PetscReal *pivot2);
  bool           Refactor(PetscInt R, PetscInt k);

  std::string prefix_;
  PetscInt    nCap_ = 0, rCap_ = 0;
  // cache of the last A, D (bitwise) and what depends only on them
  bool                   cachedA_ = false, cachedD_ = false;
  bool                   factored_ = false; // L_ is FactorA's factor of A (Ac_, N = cN_)
  bool                   unit_     = false; // ... set by SetIdentityA: L_ = Ac_ = I
  PetscInt               cN_ = -1, cR_ = -1;
  std::vector<PetscReal> Ac_, Dc_;
  PetscReal              normA_ = 0, normD_ = 0; // ||A||_inf, ||D||_inf
  std::vector<PetscReal> L_;  // Cholesky factor of A (lower, N x N)
  std::vector<PetscReal> G_;  // R x N: diag(s) D L^{-T} (the transpose of L^{-1} D' diag(s))
  std::vector<PetscReal> S_;  // R x R: diag(s) S diag(s) (unit diagonal where S_ii > 0), full
  std::vector<PetscReal> s_;  // R: equilibration, s_i = S_ii^{-1/2} (1 if S_ii = 0)
  // per-solve data
  std::vector<PetscReal> y_, b_, Lf_, l_, z_, w_, t_, tN_, tR_;
  std::vector<PetscInt>  P_;   // free set (ordered like the rows of Lf_)
  std::vector<char>      inP_, blocked_;
  // TAO cross-check
  Tao tao_ = nullptr;
  Mat H_   = nullptr;
  TaoQuadratic quad_; // H_, cv_ for TAO
  Vec x_ = nullptr, cv_ = nullptr, lo_ = nullptr, hi_ = nullptr;
  PetscInt taoR_ = -1;
};

} // namespace rbc
