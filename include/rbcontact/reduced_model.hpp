// rbcontact/reduced_model.hpp: the online stage, as a C++ API. ReducedModel holds everything the
// online solve needs, read once from a ROM file (docs/rom_file.md): the parameter box, the coefficient
// functions of the affine terms A^(mu) = sum_q thetaA_q(mu) A^_q, f^(mu) = sum_q thetaF_q(mu) f^_q
// (materials and geometric map serialized), the EIM of the contact map kappa and of the gap gamma
// (interpolation points, B, C_j, D^gamma) with the local contact data around the points (a
// ContactPatch), and warm starts. Solve(mu) runs the reduced Kacanov loop: at each iterate the small
// saddle-point QP with v in R^N, eta in R^R_+ (ReducedQP), stopping rules as the full-order model
// (-rom_kacanov_rtol_primal, -rom_kacanov_rtol_dual, -rom_kacanov_max_it, -rom_kacanov_relaxation,
// -rom_kacanov_monitor; -rom_kacanov_anderson m: Anderson mixing), KKT check -rom_kkt_tol. Nothing in it grows with the mesh.
// Usage: share/examples/online_loop.cpp.
#pragma once
#include <cmath>
#include <memory>
#include <string>
#include <vector>
#include "rbcontact/affine_decomposition.hpp"
#include "rbcontact/kacanov_loop.hpp"
#include "rbcontact/eim.hpp"
#include "rbcontact/fork_join.hpp"
#include "rbcontact/reduced_contact.hpp"
#include "rbcontact/affine_diagonalization.hpp"
#include "rbcontact/reduced_qp.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/surface_outputs.hpp"
#include "rbcontact/rom_file.hpp"

namespace rbc {

// The parameter dependence of A and f: parameter box, materials, geometric map, coefficients.
class ReducedParametrization {
public:
  PetscErrorCode FromFOM(const Elasticity &elas, const GeometryMap &map, const AffineDecomposition &aff);
  void           Write(RomWriter *w) const;
  PetscErrorCode Read(const std::string &file);
  // Coefficient values at mu (after FromFOM or Read).
  void           ThetaA(const std::vector<PetscReal> &mu, std::vector<PetscReal> *th) const;
  void           ThetaF(const std::vector<PetscReal> &mu, std::vector<PetscReal> *th) const;
  // A clear error naming the parameter, the value and the box when mu is outside it (or has the wrong size).
  // what: who gave mu, in the messages ("-mu"; validate names the test parameter and its source)
  PetscErrorCode CheckBox(MPI_Comm comm, const std::vector<PetscReal> &mu, const std::string &what = "-mu") const;
  PetscInt       NumA() const { return (PetscInt)thetaA.size(); }
  // Every coefficient of A a constant (no material parameter, map or parameter enters it): A^(mu) is A^ for every mu.
  bool           AConstant() const;
  PetscInt       NumF() const { return (PetscInt)thetaF.size(); }

  PetscInt                 dim = 2;
  std::vector<ParamSpec>   params;
  std::vector<BodySpec>    bodies;
  GeometryMap              map;
  std::vector<Coefficient> thetaA, thetaF;

private:
  void Light(); // (re)builds the parameter-only Elasticity the coefficients evaluate with (FromFOM, Read)
  std::shared_ptr<Elasticity> light_;
};

// The online error estimate of one reduced solution (docs/error_estimate.md): the change of the answer when
// the last Kacanov iterate's reduced QP is solved again in the enriched spaces the ROM file stores (all its
// POD modes, dual vectors and supremizers; the answer uses the leading NDefault / RDefault of them), at the
// same contact geometry and cubature points, calibrated offline (scale * change + floor). Relative errors
// in the norms validate reports: u in the energy norm of A(mu), lambda in the slave-mass weighted l2 norm,
// the resultant contact force in the Euclidean norm.
struct ErrorEstimate {
  bool        available = false;
  PetscReal   u = 0, lambda = 0, force = 0;          // calibrated estimates
  PetscReal   uRaw = 0, lambdaRaw = 0, forceRaw = 0; // the enriched-space changes themselves
  std::string why;                                   // why there is none (available = false)
};

struct ReducedSolution {
  std::vector<PetscReal> v, lambda; // reduced coordinates: u ~ sum_n v_n theta_n, lambda ~ sum_r lambda_r xi_r
  PetscInt               iterations = 0;
  bool                   converged  = false;
  std::vector<PetscReal> du, dl;      // Kacanov relative changes per iteration
  std::vector<PetscInt>  nactive;     // active reduced multipliers per iteration
  ReducedQPInfo          qp;          // last QP (status, KKT)
  PetscInt               outOfRange = 0; // contact projections at the edge of the stored patch (EIM range)
  std::string            message;     // why it failed (empty on success)
  std::vector<PetscReal> iterates;    // with recordIterates: the v (N each) the contact terms were evaluated at
  // The resultant contact force sum_i lambda_i int psi_i n2 (dim components; its norm is the FOM report's
  // contact_force), from the reduced multipliers and the cubature's (or the exact terms') points at the
  // last Kacanov iterate: no mesh. Empty with the EIM (which interpolates K^ and g^, not the normals) and
  // when the solve failed. docs/online.md, "Outputs of interest".
  std::vector<PetscReal> force;
  ErrorEstimate          estimate; // with ReducedModel::errorEstimate and a ROM file that stores an enrichment
  PetscReal ForceMagnitude() const
  {
    PetscReal s = 0;
    for (PetscReal f : force) s += f * f;
    return std::sqrt(s);
  }
};

class ReducedModel {
public:
  // EIM: empirical interpolation of kappa and gamma (the seed's); Cubature: the exact pointwise kernel
  // at a few points with nonnegative weights (ECSW, empirical_cubature.hpp); Exact: every point.
  enum class ContactMode { EIM, Exact, Cubature };

  // Reads a ROM file (any rank; no collective call). Errors name the file and the dataset; after a failed Open the
  // object holds no model (Solve, SetFromOptions and Truncate refuse, naming that file).
  PetscErrorCode Open(const std::string &file);
  // -rom_kacanov_*, -rom_kkt_tol, -rom_warm_start <bool>, -rom_qp_* (ReducedQP), -rom_N, -rom_R, -rom_Mk, -rom_Mg (truncation),
  // -rom_hyper eim|ecsw (the hyper-reduction among those stored; default: the offline stage's first choice),
  // -rom_error_estimate <bool> (default true: every solve estimates its error when the file allows it).
  PetscErrorCode SetFromOptions();
  // Uses the leading n POD modes (and the supremizers of the leading r dual vectors), r dual vectors,
  // mk and mg EIM terms (-1: NDefault/RDefault, i.e. all without an enrichment, for n and r, and RSelected for r
  // where the file has one; MkDefault/MgDefault for mk and mg). Rebuilds the active operators.
  PetscErrorCode Truncate(PetscInt n, PetscInt r, PetscInt mk, PetscInt mg);
  // The reduced solution at mu (inside the box). Never throws on a numerical failure: converged =
  // false and message set (the stages turn that into an error); PETSc errors only for bad input.
  PetscErrorCode Solve(const std::vector<PetscReal> &mu, ReducedSolution *sol);
  // Exact contact terms (no EIM): K^ = P kappa, g^ = P gamma on the full patch (offline, validation);
  // P = W' Psi (Rfull x Q, row-major). Call Truncate afterwards.
  void SetExactContact(std::shared_ptr<ContactPatch> full, const std::vector<PetscReal> &P);
  void SetContactMode(ContactMode m)
  {
    mode_ = m;
    geomMu_.clear();
  }

  // Sizes in use, and of the file.
  PetscInt N() const { return (PetscInt)cols_.size(); }
  PetscInt R() const { return r_; }
  bool SizesGiven() const { return sizesGiven_; } // the last Truncate named n or r (false: the file's defaults)
  PetscInt Mk() const { return mk_; }
  PetscInt Mg() const { return mg_; }
  PetscInt Mc() const { return (PetscInt)cPoint.size(); }
  ContactMode Mode() const { return mode_; }
  bool HasEIM() const { return kappaConst || gapConst || MkFull > 0 || MgFull > 0; }
  bool HasCubature() const { return !cPoint.empty(); }
  // "ecsw" or "eim" (the mode in use), and its sizes for messages: "ECSW Mc 110" or "EIM Mk 43 Mg 10"
  const char *HyperName() const { return mode_ == ContactMode::Cubature ? "ecsw" : "eim"; }
  std::string HyperSizes() const { return mode_ == ContactMode::Cubature ? "ECSW Mc " + std::to_string(Mc()) : "EIM Mk " + std::to_string(mk_) + " Mg " + std::to_string(mg_); }
  // POD column (index into the stored primal basis) of each active reduced coordinate.
  const std::vector<PetscInt> &Columns() const { return cols_; }
  // Reduced A^(mu) (N x N, column-major) and f^(mu).
  void Operators(const std::vector<PetscReal> &mu, std::vector<PetscReal> *A, std::vector<PetscReal> *f) const;
  // The same for the n columns cols of the stored basis (nullptr: the first n); A nullptr: f^ only.
  void AffineAt(const std::vector<PetscReal> &mu, const PetscInt *cols, PetscInt n, std::vector<PetscReal> *A, std::vector<PetscReal> *f) const;
  // Reduced contact terms at (mu, v) in the current mode: K (R x N column-major), g (R). Returns the out-of-range count.
  PetscInt ContactTerms(const std::vector<PetscReal> &mu, const PetscReal *v, PetscReal *K, PetscReal *g);
  // Puts the cubature points (cPoint with cPw's columns) in the order of their slave facets, so that
  // consecutive points share the rows of theta their terms fall on (read from cache, not from memory:
  // docs/online.md "The cubature points in slave facet order"). The same points and weights; the sums
  // change only by rounding. Needs the patch; called by Read and by the offline stage.
  void OrderCubaturePoints();

  // --- stored data (file sizes; public so that the offline stage can fill it in memory) ---
  std::string            file;
  ReducedParametrization par;
  PetscInt               dim = 2, Nfull = 0, Npod = 0, nsup = 0, Rfull = 0;
  std::vector<PetscReal> Aq, fq;                     // QA x Nfull x Nfull, QF x Nfull
  bool                   kappaConst = false, gapConst = false;
  PetscInt               MkFull = 0, MgFull = 0;
  PetscInt               MkDefault = -1, MgDefault = -1; // sizes used unless -rom_Mk/-rom_Mg (-1: all; chosen offline on held-out parameters, eim_selection.hpp)
  PetscInt               NDefault = -1, RDefault = -1;   // POD modes and dual vectors of the answer unless -rom_N/-rom_R (-1: all); fewer
                                                         // than stored: the rest is the error estimate's enrichment (/online/estimate)
  std::vector<PetscReal> massGram;                       // W' M W (Rfull x Rfull, M the reference slave mass): the estimate's lambda norm
  PetscReal              estimateScale[3] = {1, 1, 1};   // calibration of the estimate (u, lambda, force), fitted offline:
  PetscReal              estimateFloor[3] = {0, 0, 0};   // estimate = scale * raw + floor (error_estimate.hpp)
  PetscBool              errorEstimate = PETSC_TRUE;     // -rom_error_estimate
  bool HasEnrichment() const { return (NDefault >= 0 && NDefault < Npod) || (RDefault >= 0 && RDefault < Rfull); }
  PetscInt               RSelected = -1;                  // dual vectors of the answer chosen offline on held-out FOM solutions
                                                         // (/online/dual_select, dual_selection.hpp; -1: none): used unless -rom_R,
                                                         // the rest of the stored ones unused (no estimate's enrichment)
  std::vector<PetscInt>  kPoint, kMode, gPoint;      // EIM points: patch point (and mode for kappa)
  std::vector<PetscReal> kB, kC, gB, gC;             // B (M x M, column-major); C_j: Mk x Nfull x Rfull, Mg x Rfull
  std::vector<PetscReal> kConstant, gConstant;       // exact terms when constant: Nfull x Rfull, Rfull
  std::vector<PetscInt>  cPoint;                     // cubature (ECSW) points: patch points
  std::vector<PetscReal> cPw;                        // Rfull x Mc, row-major: xi_p (W' Psi)(:, p)
  ContactMode            hyperDefault = ContactMode::EIM; // the method used unless -rom_hyper
  ContactPatch           patch;                      // local data around the EIM and cubature points
  std::vector<PetscReal> warmMu, warmV, warmL;       // training parameters and their reduced solutions
  std::vector<PetscReal> dualGram;                   // W'W (Rfull x Rfull): the Kacanov change of lambda = W lambda^ is measured in it
  SurfaceOutputs         surface;                    // the dual basis on the slave vertices and the slave facets (optional)
  // Max pressure and (2D) contact half-width of sol at mu from the reduced multipliers (NaN when the file has no
  // /online/outputs, or without an online force for the half-width); not part of Solve: called when wanted.
  void SurfaceOutputsOf(const std::vector<PetscReal> &mu, const ReducedSolution &sol, SurfaceOutputValues *out) const { surface.Evaluate(par.map, mu, sol.lambda, sol.force, out); }
  // options
  // -rom_kacanov_max_it (30), _rtol_primal, _rtol_dual, _relaxation, _anderson (3), _monitor: the loop shared with
  // the FOM (kacanov_loop.hpp). Tolerances matched to the ROM's accuracy targets (docs/online.md): 1e-5 on the
  // primal change (u target 1e-4; the loop's own error is about c/(1-c) times the last change, c <= 0.25
  // measured), 1e-4 on the dual one (lambda target 1e-2); the first iterate's dual change against a warm
  // start's multipliers is recorded, not tested. A ROM file stores the tolerances it was built with
  // (/online/kacanov_rtol, the offline stage's -rom_kacanov_rtol_*): Open sets them, options override them.
  static constexpr PetscReal kRtolPrimal = 1e-5, kRtolDual = 1e-4;
  KacanovLoop                loop{kRtolPrimal, kRtolDual, "ROM Kacanov"};
  PetscReal   kktTol    = 1e-8;
  PetscBool   warmStart = PETSC_TRUE;
  PetscInt    warmDegree = 2; // -rom_warm_start_degree: the polynomial fit with several parameters (warm_start.hpp)
  // -rom_ecsw_sum auto|points|dofs: how the cubature's K^ is summed (the same terms, different order of the
  // sums): points = kappa(p, :) per point, then sum_p Pw(:, p) kappa(p, :) (Mc (nt N + R N) flops); dofs =
  // Q = sum_p Pw(:, p) coef(p, a) per patch dof a first, then K^ = Q theta (Mc nt R + nd R N); auto: the
  // smaller count. docs/online.md, "Where the online time goes".
  enum class EcswSum { Auto, Points, Dofs } ecswSum = EcswSum::Auto;
  bool EcswSumsByDofs() const { return cDofs_; }
  // -rom_ecsw_precision double|single: the dof sum's Q and K^ = Q' theta in float (twice the vector width; g^, the
  // points' kernel and the QP stay double). Measured on sphere_block3d: 248 -> 192 us, errors unchanged to 3 digits
  // (docs/online.md "Single precision"). It leaves a noise floor near 1e-6 (u) / 1e-5 (lambda) on the Kacanov
  // changes: with tolerances near it the loop needs more iterates (half_disks at 1e-5: 2.4 -> 4.85 on average,
  // slower than double). Stored in the ROM file (/online/ecsw_precision); options override it.
  // Since 2026-11-26 the points' sum has a single-precision path too (kappa's rows converted, then one sgemm).
  bool ecswSingle = false;
  bool EcswSingle() const { return cSingle_; }
  // -rom_gemm auto|blas|builtin|fused: the cubature's sums of outer products (K^ = Pw' kappa, Q' theta) by the BLAS's gemm
  // (auto and blas; OpenBLAS 1.5-2.4x the built-in kernels' rate at the 3D sizes) or by the built-in AVX2 kernels (for
  // a reference BLAS); docs/online.md "The BLAS for the cubature's sums".
  bool gemmBlas = true;
  // -rom_gemm fused (and auto where the CPU has AVX-512F): the points' sum in single precision forms kappa's rows
  // chunk by chunk and adds them to K^ in one AVX-512 kernel (PointSumSingle; docs/online.md "The fused points' sum").
  // The other sums stay with the BLAS. Ignored by the dof sum and by double precision.
  // The default (auto) requests it; it is in effect only on such a CPU (FusedPointSum).
  bool gemmFused = true;
  bool FusedPointSum() const; // the points' sum in single precision runs fused (requested, the CPU has AVX-512F)
  // The name of the sum in effect (report key rom.gemm): fused, blas or builtin
  const char *GemmName() const { return FusedPointSum() ? "fused" : gemmBlas ? "blas" : "builtin"; }
  // -rom_factor_a_once (default true): where A^ does not depend on mu (ReducedParametrization::AConstant: a 2D
  // dilation leaves the stiffness unchanged) and the cubature sums by dofs in double precision, A^ = L L' is factored
  // once (Truncate) and the sum gives K^ L^{-T} directly from L^{-1} theta(:, cols)', which the QP takes as it is
  // (ReducedQP::SolveFactored): no comparison of A^ and no triangular solve of K^ per Kacanov iterate
  // (docs/online.md "A factored once"). AFactored(): in effect for the current sizes and mode (report key
  // rom.factor_a_once).
  PetscBool factorAOnce = PETSC_TRUE;
  bool AFactored() const { return aFactored_ && mode_ == ContactMode::Cubature; }
  // -rom_diagonalize_a (default true): where A^(mu) = theta_0(mu) A_0 + theta_1(mu) A_1 (at most two affine terms, not
  // all constant: a 3D dilation of one body, a modulus parameter) and the cubature sums by dofs or, in single precision,
  // by points,
  // Truncate solves the generalized eigenproblem of the two terms once (AffineDiagonalization): V' A^(mu) V =
  // diag(d(mu)) for every mu. The sum gives K^ V from V-transformed basis rows, the QP solves in z = diag(d)^{1/2}
  // V^{-1} v, where A^ is the identity (ReducedQP::SetIdentityA): no Cholesky of A^(mu) and no triangular solve of K^ per
  // parameter (docs/online.md "A diagonalized once"). ADiagonalized(): in effect (report key rom.a_diagonalized).
  PetscBool diagonalizeA = PETSC_TRUE;
  bool ADiagonalized() const { return !adiag_.Empty() && mode_ == ContactMode::Cubature; }
  bool      recordIterates = false;
  // -rom_threads n (default 1): the cubature's contact terms on n threads (the patch's displacement, the points'
  // closest-point scans and kernels, and the points' sum split into n parts of the points; docs/online.md "Threads").
  // The same answer to the float sums' rounding (the parts' sums added in double).
  PetscInt  threads = 1;
  // The CPUs the workers of -rom_threads run on (Linux CPU numbers; empty: the calling thread's, inherited).
  // validate sets them to the cores of the ranks that wait asleep while rank 0 times (-validate_threads).
  void SetThreadCpus(const std::vector<int> &cpus) { pool_.SetCpus(cpus); }
  // How many CPUs those threads may use (report rom.threads_cpus; 0 where the system does not say). Fewer than
  // -rom_threads: the threads share cores (under mpirun's default binding of a rank to a core), and the first
  // threaded solve warns.
  PetscInt ThreadCpus() const;
  ReducedQP qp;

private:
  PetscErrorCode SolveLoop(const std::vector<PetscReal> &mu, ReducedSolution *sol);
  PetscErrorCode Read(const std::string &file);          // Open's reading, into this object (Open keeps it on success only)
  PetscErrorCode CheckHasModel(const char *method) const; // an error unless a model was read or built
  std::string    failedOpen_;                             // the file of the last Open, when it failed (no model since)
  // The error estimate of a converged sol (ErrorEstimate), from the contact terms' last evaluation.
  PetscErrorCode EstimateError(const std::vector<PetscReal> &mu, ReducedSolution *sol);
  // ContactTerms; factored (AFactored() or ADiagonalized() only): K holds K^ L^{-T} (summed from cThetaTw_), or K^ V
  PetscInt ContactTerms(const std::vector<PetscReal> &mu, const PetscReal *v, PetscReal *K, PetscReal *g, bool factored);
  // [K g] of the cubature over the last point evaluation, rows PwT (padded to rp), nc columns (ContactTerms, EstimateError)
  void CubatureSum(PetscInt rp, const std::vector<PetscReal> &PwT, const std::vector<PetscReal> &ThetaT, const PetscInt *cols, PetscInt nc, std::vector<PetscReal> *Q, std::vector<PetscReal> *X, std::vector<PetscReal> *Kp);
  ReducedQP              qpEst_;                      // the enriched QP (all stored sizes)
  std::vector<PetscReal> eA_, ef_, eK_, eKp_, eg_, ev_, el_, eTh_, eQ_, eX_; // enriched operators and scratch
  std::vector<PetscReal> ePwT_, eThetaT_;             // cubature weights of every stored row (M x padded, point-major); theta' of every column
  void           ResultantForce(const std::vector<PetscReal> &lambda, std::vector<PetscReal> *F) const;
  std::vector<PetscReal> wn_;                         // w_p n2(x_p) of the contact terms' last evaluation (points x dim)
  ContactMode            wnMode_ = ContactMode::EIM;  // the mode of that evaluation (EIM: none)
  ContactMode            mode_ = ContactMode::EIM;
  std::vector<PetscInt>  cols_;
  std::vector<PetscReal> kapAct_;                     // exact mode: kappa's active columns when they are not the leading ones
  std::vector<PetscReal> aAct_;                       // Aq of the active columns (QA x Na x Na, column-major; Truncate)
  PetscInt               r_ = 0, mk_ = 0, mg_ = 0;
  bool                   sizesGiven_ = false; // the last Truncate named n or r (not the file's defaults)
  ContactPatch           active_;                     // patch with the active basis columns
  std::vector<PetscInt>  evalPoints_, kPos_, gPos_;   // unique patch points evaluated, positions
  PetscInt               nkEval_ = 0;                 // evalPoints_[0, nkEval_) carry kappa points
  std::vector<PetscReal> A_, f_, Kc_, Gc_, KB_, GB_;  // active operators
  std::vector<PetscReal> kap_, gam_, phi_, vals_, K_, g_, Ath_, fth_;
  std::shared_ptr<ContactPatch> full_;
  ContactPatch           fullActive_;
  std::vector<PetscReal> P_, Pact_;
  std::vector<PetscReal> cPwT_;                       // cubature weights of the active rows, M x PaddedRows(r) (point-major, zero padded)
  std::vector<PetscReal> cX_, cK_;                    // cubature scratch: [kappa gamma] point-contiguous, [K g] padded
  bool                   cDofs_ = false;              // the cubature's K^ summed by patch dofs (-rom_ecsw_sum)
  PetscInt               cNd_   = 0;                  // ... over the dofs [0, cNd_) that terms fall on (ContactPatch::TermDofs)
  bool                   cSingle_ = false;            // the cubature's K^ in float (ecswSingle), by dofs or by points
  std::vector<float>     cPwTs_, cThetaTs_, cQs_;     // ... its weights (M x rp rounded up to 8), theta' and Q (dofs)
  std::vector<float>     cXs_;                        // ... kappa's used columns (M x ldf, Na rounded up to 8, point-major; points)
  std::vector<float>     cThetaFs_;                   // ... theta's used columns (nnode dim x ldf; points: the nodal displacement, kappa's rows from cNt_, cRow_, cCoef_)
  bool                   kapStale_ = false;           // the last evaluation formed kappa in float only (kap_ not its rows)
  std::vector<PetscReal> cThetaT_, cQ_, cCoef_;       // dofs sum: theta(:, cols)' (Na x nd), Q (nd x rp), coefficients
  std::vector<PetscReal> cThetaTw_;                   // factorAOnce: L^{-1} theta(:, cols)' (Na x nd), A^ = L L'
  bool                   aFactored_ = false;          // cThetaTw_ and qp's factor set for the current sizes (Truncate)
  AffineDiagonalization  adiag_;                      // diagonalizeA: V, lambda of A^'s two terms (Truncate; empty: not in effect)
  std::vector<float>     cThetaTsw_;                  // ... dofs sum in single precision: (theta(:, cols) V)' in float (cThetaTw_ holds it in double)
  bool                   cRowsW_ = false;             // ... points' sum in single precision: cThetaFs_ holds theta(:, cols) V (displacement from V^{-1} v)
  std::vector<PetscReal> dA_, sA_, fz_, zq_;          // ... per solve: d(mu), d^{-1/2}, f in z, the QP's z
  std::vector<PetscInt>  cNt_, cRow_;                 // dofs sum: terms per point, their patch dofs
  std::vector<PetscInt>  allPoints_;
  std::vector<PetscReal> geomMu_; // parameter of the patch geometry in place
  ForkJoinHolder         pool_;   // -rom_threads > 1: the workers (a copy of the model starts its own)
  std::vector<std::vector<PetscReal>> cKt_, cGt_; // the points' sum of each thread but the first (rp x Na each), and its g^ (rp)
};

// The stored basis columns of a model of sizes (n, r): the leading n POD modes, then the supremizers of the
// leading r dual vectors (at most nsup), columns Npod + i.
std::vector<PetscInt> ReducedColumns(PetscInt Npod, PetscInt nsup, PetscInt n, PetscInt r);

// The sizes in use into a report object: N, R, Mk, Mg, Mc, hyper (ecsw|eim), ecsw_sum (points|dofs), and the online
// Kacanov tolerances kacanov_rtol_primal, kacanov_rtol_dual.
void ReportSizes(const ReducedModel &m, JsonValue *r);

// Writes the online part of a model (everything Open reads) to w.
void WriteReducedModel(const ReducedModel &m, RomWriter *w);

} // namespace rbc
