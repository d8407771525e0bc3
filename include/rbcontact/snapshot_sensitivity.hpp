// rbcontact/snapshot_sensitivity.hpp: the parameter sensitivities du/dmu_i of a converged contact solution,
// the Hermite snapshots of `offline -snapshots_sensitivities` (docs/greedy_training.md "Sensitivity snapshots"):
// each FOM solve then also yields the derivative of u along every parameter, by linear solves with the factor
// the solve already holds, and the POD sees the tangent of the solution manifold at every training point.
#pragma once
#include "rbcontact/kacanov.hpp"

namespace rbc {

struct SensitivityInfo {
  PetscInt  active       = 0; // rows held as equalities (lambda_r > 0)
  PetscInt  cgIterations = 0; // the largest count over the parameters (CG on the active rows' Schur complement; 0: dense)
  std::string method = "cg";      // how the system was solved: "dense" (S_AA from the compliance), "saddle" or "cg"
  PetscReal seconds      = 0;
};

// For every parameter i, the derivative of the solution of the contact problem at fom.mu along mu_i with the
// active set {r : lambda_r > 0} and the contact geometry of the last Kacanov iterate (kac.sys.K) held fixed:
//   [ A(mu)  K_A' ] [ du    ]      d  [ A(mu) u - f(mu) + K(mu, u)' lambda ]
//   [ K_A    0    ] [ dlam_A ] = - ---- [ (K(mu, u) u - g(mu, u))_A          ]    at fixed (u, lambda),
//                                dmu_i
// the right-hand side by central differences of that residual (step 1e-6 of the parameter's range, one-sided at
// the box's edges; the contact map reassembled at mu +- h), the system through its Schur complement on the
// active rows: with the dense dual path (-fom_dual_matrix dense) S_AA = K_AD G K_AD' from its compliance G, formed
// and factored (Cholesky) once; with the saddle path (saddle) the saddle point of the converged set itself, with that
// solver's factor or preconditioner (SaddleActiveSetSolver::SolveFixedSet: one solve a parameter, no factorization of
// A alone); on the shell path CG (prefix sensitivity_, rtol 1e-10) on K_A A^-1 K_A' with fom's A^-1. The Kacanov
// solution is the fixed point of this linearization, so du is the tangent of u(mu) up to the variation of the
// contact geometry with u (checked against central differences of FOM solutions: tests/offline_checks.py
// `sensitivities`). A non-converged solve is an error naming its options. Needs the affine decomposition
// (fom.SetupAffine). On return fom.mu and cmap's geometry are those of the call; du: global vectors of fom.dm,
// dlam: vectors of the multipliers' layout (zero on the inactive rows), created here (the caller destroys them).
PetscErrorCode ParameterSensitivities(ElasticFOM &fom, ContactMap &cmap, KacanovSolver &kac, std::vector<Vec> *du, std::vector<Vec> *dlam, SensitivityInfo *info);

} // namespace rbc
