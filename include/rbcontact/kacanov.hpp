// rbcontact/kacanov.hpp: the contact full-order solve. KacanovSolver runs the fixed-point iterations of
// the seed: iterate k solves the QP  min 1/2 v'Av - f'v  s.t.  K(u^{k-1}) v <= g(u^{k-1})  through its
// dual  min_{lambda >= 0} 1/2 lambda'S lambda - lambda'(K u0 - g),  S = K A^{-1} K^T, u0 = A^{-1} f,
// with A factored once (ElasticFOM) and reused for every back-solve; then u = u0 - A^{-1} K^T lambda
// (dense and shell); or on the sparse saddle point with no factorization of A alone (saddle).
// Stops on the relative changes of u and lambda; non-convergence is an error with the history.
// Options: -kacanov_max_it, -kacanov_rtol_primal, -kacanov_rtol_dual, -kacanov_relaxation,
// -kacanov_monitor, -kacanov_type fixed_point|newton (kacanov_newton.cpp); the dual QP takes the fom_qp_ prefix (-fom_qp_tao_type, its
// TAO's -fom_qp_ksp_*; -fom_qp_polish; the former -fom_tao_* warn); -fom_kkt_tol.
// -fom_dual_matrix dense|shell|saddle|auto (-fom_dual_dense_max R, -fom_dual_dense_max_dofs): dense S through
// the surface compliance (compliance.hpp, then TAO + active-set polish, bound_qp.hpp), S as a MATSHELL with
// the matrix-free primal-dual active-set solver (dual_shell.hpp, options -fom_dual_*), or the primal-dual
// active set on the sparse saddle point, no factorization of A alone (saddle_active_set.hpp, -fom_saddle_*;
// auto's choice above the dense limits).
#pragma once
#include "rbcontact/anderson.hpp"
#include "rbcontact/bound_qp.hpp"
#include "rbcontact/compliance.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/dual_shell.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/kacanov_loop.hpp"
#include "rbcontact/saddle_active_set.hpp"
#include "rbcontact/sparse_rows.hpp"

namespace rbc {

struct KKTResiduals {
  PetscReal primal = 0, dual = 0, complementarity = 0, stationarity = 0;
  PetscReal Max() const { return std::max(std::max(primal, dual), std::max(complementarity, stationarity)); }
};

// The Newton step of the contact-dof fixed point x = F(x) (src/contact/kacanov_newton.cpp, docs/fom_speed.md):
// the data of one dense iterate, on every rank.
struct KacanovNewtonData {
  const std::vector<PetscInt> *D   = nullptr; // the sorted contact dofs (nD)
  PetscInt                     R   = 0;
  const PetscReal             *G   = nullptr; // compliance (A^-1)_DD, nD x nD
  const SparseRows            *KD  = nullptr; // K on D, R x nD (GatherRowsOnDofs)
  const PetscReal             *T   = nullptr; // G K_D^T, nD x R
  const PetscReal             *S   = nullptr; // K_D G K_D^T, R x R
  const PetscReal             *lam = nullptr; // the QP's multipliers at x (R)
  const ContactTangent        *tan = nullptr; // the geometry's derivative at x (lambda, y = F(x))
  const PetscReal             *x = nullptr, *Fx = nullptr; // the input and its image (nD)
};
struct KacanovNewtonInfo {
  bool        accepted = false;
  PetscInt    active = 0, columns = 0; // |A|, |C|
  PetscReal   ratio = 0, pivotRatio = 0; // |dx| / |F(x) - x|; min / max |pivot| of I - J_CC
  std::string reason; // why the step was refused
};
// next = x + dx with (I - J) dx = F(x) - x; info->accepted = false (next untouched) when the step cannot be
// trusted: no active constraint, S_AA not positive definite, I - J singular or ill-conditioned, a
// non-finite step or one longer than maxRatio |F(x) - x|. Serial.
PetscErrorCode KacanovNewtonStep(const KacanovNewtonData &in, PetscReal maxRatio, std::vector<PetscReal> *next, KacanovNewtonInfo *info);

struct KacanovHistory {
  std::vector<PetscReal> du, dl;
  std::vector<PetscInt>  nactive;
  std::vector<PetscInt>  dualSteps, dualCG; // shell dual: active-set steps and CG iterations per iterate (saddle: its steps)
  std::vector<PetscInt>  factorizations, krylov; // saddle: numeric factorizations and GMRES iterations per iterate
  std::vector<PetscInt>  newton; // -kacanov_type newton: 1 if the next input is a Newton step, 0 a plain one
};

class KacanovSolver {
public:
  KacanovSolver() = default;
  KacanovSolver(const KacanovSolver &) = delete;
  KacanovSolver &operator=(const KacanovSolver &) = delete;
  ~KacanovSolver();

  PetscErrorCode SetFromOptions(MPI_Comm comm);
  // Solves the contact problem of fom (assembled and factored). On return fom.u is the displacement,
  // lambda (R, distributed like the rows of K) the multipliers, sys the constraint at the last iterate.
  PetscErrorCode Solve(ElasticFOM &fom, ContactMap &map);
  // The next Solve starts from u (free dofs, fom.u's layout: its first geometry is the contact map at u with the
  // parameter's own Dirichlet values) and lambda (the dual QP's warm start and active set) instead of the
  // reference configuration; its first iterate's changes are measured from them, and the initial overlap is
  // still measured at the reference configuration (one more contact assembly). Both copied, used by the next
  // Solve only (offline -snapshots_initial_guess nearest: a nearby parameter's solution). Collective.
  PetscErrorCode SetInitialGuess(Vec u, Vec lambda);
  // Before fom.AssembleAndFactor: when the dual matrix will be dense, hands the contact dofs to the FOM
  // so that one factorization serves the solves and the compliance (ElasticFOM::SetSchurDofs). Collective.
  PetscErrorCode ShareFactor(ElasticFOM &fom, const ContactMap &map) const;
  // The -fom_dual_matrix choice (auto: by R and the number of contact dofs) and, when dense, the contact dofs D.
  PetscErrorCode ChooseDualMatrix(MPI_Comm comm, const ContactMap &map, std::string *mode, std::vector<PetscInt> *D) const;

  // -fom_dual_matrix saddle, after a Solve: the saddle point of the last Kacanov iterate's K and converged active set
  // with the right-hand side (f, g) (SaddleActiveSetSolver::SolveFixedSet; the parameter sensitivities).
  PetscErrorCode SolveSaddleFixedSet(Vec f, Vec g, Vec u, Vec lam) { return saddle_.SolveFixedSet(f, g, u, lam); }
  PetscReal      SaddleForcing() const { return saddle_.forcing; } // -fom_saddle_rtol_forcing in use
  Vec            lambda = nullptr;
  ContactSystem  sys;
  KacanovHistory history;
  KKTResiduals   kkt;
  PetscInt       iterations = 0;
  PetscBool      converged  = PETSC_FALSE;
  // -kacanov_max_it (30), _rtol_primal, _rtol_dual (1e-8 each), _relaxation, _anderson (3: Anderson mixing of
  // the contact-dof displacement, dense dual matrix), _monitor: the loop shared with the ROM (kacanov_loop.hpp)
  KacanovLoop    loop;
  // -kacanov_type fixed_point|newton: the next input is the (Anderson-mixed) image, or a Newton step on the
  // fixed point with the derivative of the contact geometry (dense dual matrix, 2D; plain steps otherwise).
  // -kacanov_newton_max_ratio: longest Newton step accepted, in units of |F(x) - x|.
  std::string    type = "newton";
  PetscReal      newtonMaxRatio = 10;
  PetscInt       newtonSteps = 0; // accepted Newton steps of the last Solve
  PetscReal      kktTol = 1e-8;
  PetscBool      kktView = PETSC_FALSE; // -fom_kkt_view: print lambda, K u - g and g at each KKT check
  DualQPInfo     lastQP;
  DualShellInfo  lastShell;
  SaddleInfo     lastSaddle;
  SurfaceCompliance compliance;
  std::string    dualMatrixOption = "auto"; // -fom_dual_matrix
  PetscInt       dualDenseMax     = 3000;   // -fom_dual_dense_max: auto = dense up to this R
  PetscInt       dualDenseMaxDofs = 8000;   // -fom_dual_dense_max_dofs: auto = dense up to this many contact dofs (G: 0.5 GB at 8000)
  std::string    dualMatrix;                // used by the last Solve: "dense", "shell" or "saddle" (report key dual_matrix)
  mutable PetscInt contactDofs = -1;        // the contact dofs D counted by the last choice (-1: -fom_dual_matrix shell, not counted)
  // Initial overlap, measured at the first iterate (u = 0: the reference configuration at mu, imposed
  // displacements of the contact surfaces included): the deepest penetration (weighted gap g_i / weight_i
  // < 0, length units, 0 if none), the rows that penetrate, and where the deepest is (ContactSurfaceWarnings).
  PetscReal      initialPenetration = 0, initialPenetrationAt[3] = {0, 0, 0};
  PetscInt       initialPenetrating = 0;

private:
  PetscErrorCode ComputeKKT(ElasticFOM &fom);
  // "; the cause: the contact QP ... was not solved ...: <advice>" when some iterate's dense QP ended above -fom_kkt_tol
  // (its scaled KKT residual), or the saddle point's solves were too loose (SaddleActiveSetSolver::LooseSolves), else "":
  // the cause of a non-convergence or a rejected solve, in place of the relaxation hint
  std::string     QPCause() const;
  PetscInt        qpUnsolved_ = 0, qpUnsolvedFirst_ = 0; // iterates whose QP was not solved, the first of them
  DualQPInfo      qpUnsolvedInfo_;                        // that first one's
  PetscReal       qpUnsolvedWorst_ = 0;                   // the largest scaled KKT residual of those QPs
  // also refuses a master that faces away from the slave (most nodes behind it see its outward normal along their own)
  PetscErrorCode MeasureInitialOverlap(MPI_Comm comm, const ContactMap &map);
  Vec             uInit_ = nullptr, lamInit_ = nullptr; // SetInitialGuess's, until the next Solve
  DualQPSolver    qp_;
  DualShellSolver shell_;
  SaddleActiveSetSolver saddle_;
};

// Contact quantities for reports: resultant normal force, max pressure, active count, half-width (2D).
struct ContactSummary {
  PetscInt  R = 0, nactive = 0;
  PetscReal force = 0, forceVec[3] = {0, 0, 0}, maxPressure = 0, halfwidth = 0;
  PetscReal halfwidthMoment = 0; // 2D: 2 sqrt(int p x^2 / int p), x from the pressure centroid (= a for a Hertz profile); 3D: sqrt(5/2 int p r^2 / int p), the contact radius a of Hertz's profile
  PetscReal pressureSpread = 0; // 2D: max/min - 1 of the nodal pressure over the active nodes but the two ends
  PetscReal pressureRoughness = 0; // 2D: RMS of the second difference of the nodal pressure over the active nodes but the two ends, / their mean (node-to-node oscillation)
};
// Rows of K restricted to the sorted global dofs D, on every rank: R rows in K's global order, the columns their
// positions in D (ascending within a row), exact zeros dropped. Collective.
PetscErrorCode GatherRowsOnDofs(Mat K, const std::vector<PetscInt> &D, SparseRows *KD);

// Warnings about a converged contact solution (collective): the contact zone reaching an end of the
// declared slave surface (contact beyond it is not enforced: the slave may penetrate there).
// An initial overlap (KacanovSolver::initialPenetration > 0) is warned about too: the solver pushes the bodies
// apart as an interference fit, which is rarely what a user meant.
PetscErrorCode ContactSurfaceWarnings(MPI_Comm comm, const KacanovSolver &kac, const ContactMap &map, std::vector<std::string> *warnings);

// The whole of a parallel Vec on every rank (global order).
PetscErrorCode GatherVec(Vec v, std::vector<PetscReal> *full);

PetscErrorCode SummarizeContact(const ContactSystem &sys, Vec lambda, PetscInt dim, ContactSummary *s);

// Hertz's line contact of a cylinder of radius Rc on a half-space, plane strain, per unit thickness, pressed
// by the force P: the contact half-width a = sqrt(4 P Rc / (pi E*)) and the peak pressure p0 = 2 P / (pi a),
// with 1/E* = sum over the scene's first two bodies of (1 - nu^2) / E (`rbcontact fom -hertz_radius`).
void HertzLineContact(const SceneSpec &scene, PetscReal Rc, PetscReal P, PetscReal *a, PetscReal *p0);
// Hertz's point contact of a sphere of radius Rs on a half-space (3D) pressed by P: the contact radius
// a = (3 P Rs / (4 E*))^(1/3) and the peak pressure p0 = 3 P / (2 pi a^2).
void HertzPointContact(const SceneSpec &scene, PetscReal Rs, PetscReal P, PetscReal *a, PetscReal *p0);

} // namespace rbc
