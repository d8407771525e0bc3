// rbcontact/saddle_active_set.hpp: the contact QP of a Kacanov iterate,
//   min 1/2 u'Au - f'u  s.t.  K u <= g,
// solved on the primal-dual saddle point by a primal-dual active-set method (Hintermueller-Ito-Kunisch:
// semismooth Newton on lambda = max(0, lambda + c (K u - g))), with no dense object and no factorization of A
// alone: each step factors the sparse symmetric indefinite matrix
//   [ A         c K^T P ] [u      ]   [f    ]
//   [ c P K   -s (I-P)  ] [lambda~] = [c P g],   P = diag(active set),  lambda = c lambda~,
// (MUMPS LDL^T by default; KSP prefix fom_saddle_), so the active rows hold as equalities, lambda = 0 off the
// active set (c, s = max diag(A): the multiplier block balanced against A, for the pivots and GMRES). The next set is
// {i active: lambda_i > 0} U {i inactive: (K u - g)_i > tol * scale}. The matrix keeps one pattern for
// all active sets of one K (explicit zeros), so the steps of one Kacanov iterate are numeric
// factorizations only; a K with the pattern of the last one reuses its symbolic analysis too.
// Two uses (docs/contact.md "Saddle point"): Solve() to convergence of the set (-fom_saddle_pdas_inner, and
// always on a cold start), or one step per Kacanov iterate (the default: the active set and the geometry
// converge together; the loop stops only on an unchanged set, SetChanged()).
// Options (prefix fom_saddle_): -pdas_max_it (100), -pdas_tol (1e-10), -pdas_inner, -pdas_monitor,
// -pdas_rtol_loose (1e-4: the solves of a cold start while the set changes; its last set is solved again exactly),
// -reuse_max_changes (10), -previous_guess (on: each step's Krylov solve starts from the last step's solution of
// this parameter, the inactive rows zeroed; the stopping test stays rtol |b|), -rtol_forcing c (1e-3; 0: off, every iterate exactly; else the
// last solve of a Kacanov iterate to c times the iterate's change, within [-ksp_rtol, -pdas_rtol_loose]: Solve's
// change argument), -solver direct|gamg (presets: GMRES on a MUMPS LDL^T factor; FGMRES + Schur
// fieldsplit with GAMG on the u block and LU on the selfp Schur complement), -ksp_* / -pc_* of the solver
// (the u and lambda blocks are the fields "u" and "lambda" of a PCFIELDSPLIT).
#pragma once
#include <petscksp.h>
#include <string>
#include <vector>

namespace rbc {

struct SaddleInfo {
  PetscInt  steps          = 0; // active-set steps (factorizations + solves) of the last Solve
  PetscInt  symbolic       = 0; // 1: a new matrix pattern (K's pattern changed)
  PetscInt  factorizations = 0; // numeric factorizations (the other steps solved with an earlier factor)
  PetscInt  krylov         = 0; // GMRES iterations of all steps
  PetscInt  changed        = 0; // rows whose status changed after the last step (0: the set is the solution's)
  PetscInt  nactive        = 0; // size of the set of the last step
  PetscBool exact          = PETSC_TRUE; // the last step solved to -fom_saddle_ksp_rtol (not to a forcing tolerance)
  PetscReal seconds        = 0; // wall time of the Solve
  std::string kspType, pcType;  // the solver that ran (-fom_saddle_solver's preset or the user's)
};

class SaddleActiveSetSolver {
public:
  SaddleActiveSetSolver() = default;
  SaddleActiveSetSolver(const SaddleActiveSetSolver &) = delete;
  SaddleActiveSetSolver &operator=(const SaddleActiveSetSolver &) = delete;
  ~SaddleActiveSetSolver();

  // prefix "fom_" -> -fom_saddle_pdas_max_it, -fom_saddle_ksp_type, ...
  PetscErrorCode SetFromOptions(MPI_Comm comm, const std::string &prefix);
  // A (N x N, SPD), f, K (R x N, rows distributed like lambda), g. warm: start from the set kept from the
  // last call (the previous Kacanov iterate or parameter), else from the empty set (the unconstrained u
  // decides the first set). converge (or -pdas_inner, or no kept set): step until the set does not change;
  // else one step (info->changed > 0: the set moved, the QP at this K, g is not solved yet).
  // change: the Kacanov loop's last relative change of u (1 on its first iterate; 0: solve exactly); with
  // -rtol_forcing c > 0 the last step is solved to c * change (within [-ksp_rtol, -pdas_rtol_loose]) instead of
  // -ksp_rtol (info->exact false), an inexact Kacanov iterate whose error stays below the change it measures.
  // Out: u, lambda of the last step's set (lambda = 0 off it).
  PetscErrorCode Solve(Mat A, Vec f, Mat K, Vec g, PetscBool warm, PetscBool converge, Vec u, Vec lambda, SaddleInfo *info, PetscReal change = 0);
  // One solve with the set and the matrix of the last step, no set update:
  //   [A  K_P'] [u     ]   [f  ]
  //   [K_P  0 ] [lambda] = [g_P],  P the set, lambda = 0 off it
  // (the parameter sensitivities of the converged solution, snapshot_sensitivity.hpp), with the last step's
  // preconditioner reused (GMRES to the exact solve's rtol). Errors: no step yet, or a solve that fails.
  PetscErrorCode SolveFixedSet(Vec f, Vec g, Vec u, Vec lambda);
  // Forget the set and the factorization.
  PetscErrorCode Reset();
  // "" while the solves' tolerance (-ksp_rtol) is at most 1e-10; else why the inexact solves limit the active set and
  // the KKT residuals, and the advice (the cause of a cycling set, a non-convergence or a rejected solve: raising
  // -pdas_tol, the advice of a cycle, does not help there; audit of 2026-12-01)
  std::string LooseSolves() const;
  // The rigid-body modes of A (for a PCFIELDSPLIT's GAMG on the u block; kept by reference), wanted only when
  // the options ask for a PCFIELDSPLIT (-fom_saddle_solver gamg or -fom_saddle_pc_type fieldsplit).
  PetscErrorCode SetNearNullSpace(MatNullSpace nsp);
  bool WantsNearNullSpace() const { return wantsNearNull_; }
  // A has new values (a new parameter): the next step factors afresh (the set is kept as a start).
  // The first step of a parameter starts its Krylov solve from zero (no guess from another parameter).
  void NewOperator() { factored_ = false; guess_ = false; }
  // The set to start the next warm Solve from: the rows where lambda (distributed like K's rows) is positive
  // (KacanovSolver::SetInitialGuess: the multipliers of a nearby parameter).
  PetscErrorCode SetActiveSet(Vec lambda);

  PetscInt  maxIt   = 100;
  PetscReal setTol  = 1e-10;
  PetscReal looseRtol = 1e-4; // -pdas_rtol_loose
  PetscReal forcing   = 1e-3; // -rtol_forcing: the last solve of a Kacanov iterate to forcing x its change (0: to -ksp_rtol; default since 2026-11-28, docs/fom_speed.md)
  PetscBool inner   = PETSC_FALSE; // -pdas_inner: to convergence on every Kacanov iterate
  PetscBool monitor = PETSC_FALSE;
  PetscInt  reuseMaxChanges = 10; // -reuse_max_changes
  PetscBool previousGuess = PETSC_TRUE; // -previous_guess
  std::string solver = "direct";  // -solver direct|gamg (a preset of the KSP/PC options)

private:
  PetscErrorCode Build(Mat A, Mat K);
  PetscErrorCode CreateKSP();
  PetscErrorCode Fill(Mat A, Mat K);
  PetscErrorCode Step(Mat A, Vec f, Mat K, Vec g, PetscReal rtol, Vec u, Vec lambda, SaddleInfo *info);
  PetscErrorCode SetRhs(Vec f, Vec g);                   // b_ = [f; c P g]
  PetscErrorCode GetSolution(Vec u, Vec lambda) const;   // u, lambda = c lambda~ (0 off the set) from x_
  std::string            prefix_;
  KSP                    ksp_ = nullptr;
  Mat                    M_   = nullptr; // the saddle-point matrix
  MatNullSpace           nearNull_ = nullptr;
  bool                   wantsNearNull_ = false;
  Vec                    x_ = nullptr, b_ = nullptr;
  Mat                    lastA_ = nullptr; // the A M_ was built for, and its nonzero state (pattern check)
  PetscObjectState       lastANonzero_ = -1;
  std::vector<PetscInt>  kPattern_;        // K's local rows: row lengths then columns (pattern check)
  std::vector<char>      active_;          // the set, on this rank's rows of K
  PetscReal              diagScale_ = 1, kScale_ = 1; // s, c (Build)
  PetscInt               nu_ = 0, nl_ = 0; // local sizes of u and lambda
  bool                   factored_ = false, canReuse_ = false, newPattern_ = false; // newPattern_: M_ rebuilt since the last set-up
  bool                   guess_ = false; // x_ holds the last step's solution of this parameter (the next step's initial guess)
  PetscBool              fieldsplit_ = PETSC_FALSE;
  PetscInt               changedSinceFactor_ = 0; // rows whose status changed since the last factorization
  PetscReal              freshSeconds_ = 0;       // wall time of the last solve with a new factorization
  PetscReal              exactRtol_ = 1e-12;      // the KSP's rtol after its options (-fom_saddle_ksp_rtol)
  PetscReal              exactResidual_ = 0;      // the relative residual of the last solve to exactRtol_
};

} // namespace rbc
