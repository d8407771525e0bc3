// rbcontact/dual_shell.hpp: the matrix-free dual QP of one Kacanov iterate,
//   min_{lambda >= 0} 1/2 lambda'S lambda - b'lambda,   S = K A^{-1} K^T never formed,
// by a primal-dual active-set method (Hintermueller-Ito-Kunisch: semismooth Newton on
// lambda = max(0, lambda - c (S lambda - b))). Each step solves S_FF lambda_F = b_F on the current free
// set F by CG (KSP prefix fom_dual_, default cg + jacobi, rtol 1e-14) on a MATSHELL that masks S to F
// (identity off F); a product with S is one back-solve with the factored A (ElasticFOM::ApplyInverse).
// lambda = 0 off F; F is then updated from the sign of lambda (on F) and of S lambda - b (off F), until
// it does not change under an exact solve: the last step is an exact solve on the final support.
// While F changes, CG stops early (-pdas_rtol_loose); a set that repeats under exact solves is an error.
// Options (prefix fom_dual_): -pdas_max_it (100), -pdas_rtol_loose (1e-3), -pdas_tol (1e-12, scaled
// threshold for adding a multiplier), -pdas_monitor, -diag lumped|exact (Jacobi diagonal:
// diag(K diag(A)^{-1} K^T), or exact by R products), -ksp_* / -pc_* of the CG.
// Optional TAO phase before the active-set method (-fom_dual_shell_tao, default off: with BQPIP it costs
// 700-1000 products on the ring, 2-3x the shell time; docs/contact.md): TAO (prefix fom_qp_: -fom_qp_tao_type,
// default BQPIP by TaoBQPIPRecipe, at most -fom_qp_tao_max_it 50 iterations) on the Jacobi-equilibrated S
// (a second MATSHELL, full S, unit diagonal estimate, with its own MatDiagonalSet / MatShift: BQPIP
// shifts the diagonal in place and MATSHELL's native shifts do not survive its MatAssemblyEnd),
// bounds [0, inf]; its inner KSP has prefix fom_dual_tao_ (cg + jacobi for BQPIP; TRON / GPCG get
// H(free, free) as a MATSHELL too). Entries above -fom_dual_shell_tao_support (1e-6) * max are the first
// free set of the active-set method, which then finishes exactly as without TAO. The phase runs on cold
// starts only (no previous support), on every Kacanov iterate with -fom_dual_shell_tao_warm.
#pragma once
#include <petscksp.h>
#include <petsctao.h>
#include <string>
#include "rbcontact/fom.hpp"

namespace rbc {

struct DualShellCtx; // the MATSHELL's data (dual_shell.cpp)

struct DualShellInfo {
  PetscInt  pdasIterations = 0; // CG solves on a free set (the last one on the final set)
  PetscInt  cgIterations   = 0; // CG iterations of all of them
  PetscInt  products       = 0; // products with S = back-solves, CG + set updates + diagonal
  PetscInt  nfree          = 0; // size of the final free set
  PetscReal residual       = 0; // true |S_FF lambda_F - b_F|_2 / |b_F|_2 on the final set
  PetscReal kkt            = 0; // max_i |min(lambda_i sqrt(d_i), (S lambda - b)_i / sqrt(d_i))| / |b / sqrt(d)|_inf
  // TAO phase (-fom_dual_shell_tao; all 0 when it did not run)
  PetscInt           taoIterations = 0; // TAO iterations
  PetscInt           taoKSP        = 0; // iterations of TAO's inner KSP (each one a product)
  PetscInt           taoProducts   = 0; // products with S in the TAO phase (included in products)
  PetscInt           taoSupport    = 0; // size of the free set taken from TAO
  TaoConvergedReason taoReason     = TAO_CONTINUE_ITERATING;
  PetscReal          taoShiftDrift = 0; // max |diagonal shift left on the TAO Hessian shell| after TaoSolve
};

class DualShellSolver {
public:
  DualShellSolver() = default;
  DualShellSolver(const DualShellSolver &) = delete;
  DualShellSolver &operator=(const DualShellSolver &) = delete;
  ~DualShellSolver();

  // prefix: e.g. "fom_" -> -fom_dual_pdas_max_it, -fom_dual_ksp_rtol, ...
  PetscErrorCode SetFromOptions(MPI_Comm comm, const std::string &prefix);
  // K: R x N constraint rows (distributed like lambda), b: R. lambda: in = warm start if warm (its
  // positive entries and one product decide the first free set), out = the solution (>= 0).
  PetscErrorCode Solve(ElasticFOM &fom, Mat K, Vec b, Vec lambda, PetscBool warm, DualShellInfo *info);

  PetscInt    maxIt   = 100;
  PetscReal   setTol  = 1e-12;
  PetscReal   looseRtol = 1e-3; // CG rtol while the free set still changes (-pdas_rtol_loose)
  std::string diag    = "lumped";
  PetscBool   monitor = PETSC_FALSE; // -fom_dual_pdas_monitor
  PetscBool   useTao  = PETSC_FALSE; // -fom_dual_shell_tao (off with -fom_qp_tao_type activeset)
  PetscBool   taoWarm = PETSC_FALSE; // -fom_dual_shell_tao_warm: TAO on warm starts too
  PetscReal   taoSupport = 1e-6;     // -fom_dual_shell_tao_support: free if > this * max

private:
  PetscErrorCode Create(ElasticFOM &fom, Mat K);
  PetscErrorCode Diagonal(ElasticFOM &fom, Mat K);
  PetscErrorCode TaoPhase(Vec b, Vec lambda, PetscBool warm, DualShellInfo *info);
  std::string   taoPrefix_; // "fom_": the TAO's prefix
  std::string   prefix_;
  KSP           ksp_ = nullptr;
  Mat           S_   = nullptr;
  DualShellCtx *ctx_ = nullptr;
  PetscReal     rtol_ = 1e-14, atol_ = 0; // atol_ > 0: set by the user

};

} // namespace rbc
