// rbcontact/eim.hpp: the Empirical Interpolation Method (Barrault, Maday, Nguyen, Patera 2004) on a
// dense snapshot matrix S (n entries x m snapshots, column-major): the greedy selection of the
// interpolation points and functions, the interpolation coefficients and the interpolant.
// Pure serial dense code (no PETSc objects): any rank may call it, and every rank given the same S
// computes bitwise the same result.
//   Options (EIMOptionsFromOptions, prefix P, e.g. "eim_kappa_"): -Ptol <1e-6> (> 0), -Pmax <50> (>= 1),
//   -Pmonitor, -Prelative <bool>; the shared -eim_max and -eim_monitor are defaults the prefixed ones
//   override.
//   Implementation: src/reduction/eim.cpp; algorithm, options and the meaning of the history: docs/eim.md.
#pragma once
#include <petscsys.h>
#include <string>
#include <vector>

namespace rbc {

struct EIMOptions {
  PetscReal   tol      = 1e-6;   // stop when the max interpolation error over the snapshots <= tol (times the scale if relative)
  bool        relative = true;   // error relative to max_j ||s_j||_inf (the largest snapshot entry in absolute value)
  PetscInt    maxM     = 50;     // at most this many functions
  bool        monitor  = false;  // print "  EIM <name> M = k  max err = e  (snapshot j, point i)" per step via PetscPrintf(PETSC_COMM_SELF,...)
  std::string name     = "eim";
};

struct EIMResult {
  PetscInt               n = 0, M = 0;  // function length, number of functions/points
  std::vector<PetscInt>  points;        // M selected entry indices in [0, n)
  std::vector<PetscReal> Q;             // n x M column-major: q_j, scaled so that q_j[points[j]] = 1
  std::vector<PetscReal> B;             // M x M column-major, B(i,j) = q_j[points[i]]: unit lower triangular
  std::vector<PetscReal> history;       // history[k] = max over snapshots of ||s - I_k s||_inf (absolute), k = 0..M (history[0] = max ||s||_inf)
  std::vector<PetscInt>  selected;      // snapshot picked at each step (size M)
  PetscReal              scale = 1;     // max_j ||s_j||_inf
  bool                   exhausted = false; // stopped because the residuals are all (numerically) zero before tol/maxM
  PetscReal              tolAbs = 0;    // the absolute tolerance the greedy used (tol, times scale if relative)
};

// Greedy EIM on the m snapshots S (n x m, column-major). Collective on nothing (pure serial, any rank may call).
// Errors: n < 1, m < 1, non-finite entries -> PETSC_ERR_ARG_* with a message.
PetscErrorCode EIMGreedy(const std::vector<PetscReal> &S, PetscInt n, PetscInt m, const EIMOptions &opt, EIMResult *res);
// phi = B(0:M,0:M)^{-1} vals by forward substitution (M <= res.M: the EIM is hierarchical, any leading M works).
void EIMCoefficients(const EIMResult &res, PetscInt M, const PetscReal *vals, PetscReal *phi);
// Interpolant I_M f = Q(:,0:M) phi, phi from f at the points (f has length n). out has length n.
void EIMInterpolate(const EIMResult &res, PetscInt M, const PetscReal *f, PetscReal *out);
// Sets opt from the options database: -<prefix>tol, -<prefix>max, -<prefix>monitor, -<prefix>relative <bool>
// (e.g. prefix "eim_kappa_" gives -eim_kappa_tol). Also honors a shared "-eim_max" and "-eim_monitor" (no prefix) as defaults
// that the prefixed ones override. Range checks: tol > 0 (error naming the option and value), max >= 1.
PetscErrorCode EIMOptionsFromOptions(MPI_Comm comm, const std::string &prefix, EIMOptions *opt);

} // namespace rbc
