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
#pragma once
#include <petscksp.h>
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

private:
  PetscErrorCode Create(ElasticFOM &fom, Mat K);
  PetscErrorCode Diagonal(ElasticFOM &fom, Mat K);
  std::string   prefix_;
  KSP           ksp_ = nullptr;
  Mat           S_   = nullptr;
  DualShellCtx *ctx_ = nullptr;
  PetscReal     rtol_ = 1e-14, atol_ = 0; // atol_ > 0: set by the user

};

} // namespace rbc
