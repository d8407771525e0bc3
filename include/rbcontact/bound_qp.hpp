// rbcontact/bound_qp.hpp: small dense bound-constrained QPs  min 1/2 x'Hx - c'x  s.t. x >= 0  (H SPD).
// BoundQPActiveSet: primal active-set method (Lawson-Hanson on H), exact up to rounding; used as the
// polish after TAO, as the online reduced solver and as the NNLS polish.
// DualQPSolver: TAO (default BQPIP, options prefix chosen by the caller, e.g. fom_) on PETSC_COMM_SELF
// on an equilibrated problem, then the active-set polish (see ../shared notes nnls-with-bqpip.md).
#pragma once
#include <petsctao.h>
#include <string>
#include <vector>

namespace rbc {

struct BoundQPInfo {
  PetscInt  iterations = 0;  // active-set changes
  PetscBool converged  = PETSC_FALSE;
  PetscReal kkt        = 0;  // max(|min(x, g)|) / scale, g = Hx - c (scaled complementarity/stationarity)
};

// H column-major n x n. x: on input a warm start (its positive entries form the starting support),
// on output the solution. tol: relative tolerance of the optimality test.
PetscErrorCode BoundQPActiveSet(PetscInt n, const PetscReal *H, const PetscReal *c, PetscReal *x, PetscReal tol, PetscInt maxit, BoundQPInfo *info);

// Scaled KKT residual of a candidate x for min 1/2 x'Hx - c'x, x >= 0.
PetscReal BoundQPKKT(PetscInt n, const PetscReal *H, const PetscReal *c, const PetscReal *x);

struct DualQPInfo {
  PetscInt           taoIterations = 0;
  TaoConvergedReason taoReason     = TAO_CONTINUE_ITERATING;
  PetscInt           polishIterations = 0;
  PetscReal          kkt = 0;
};

class DualQPSolver {
public:
  DualQPSolver() = default;
  DualQPSolver(const DualQPSolver &) = delete;
  DualQPSolver &operator=(const DualQPSolver &) = delete;
  ~DualQPSolver();
  // prefix: the stage's prefix; the Tao's is <prefix>qp_ (e.g. "fom_" -> -fom_qp_tao_type, -fom_qp_tao_gatol, and
  // TAO's inner KSP -fom_qp_ksp_type: apart from the elastic solver's -fom_ksp_*); -<prefix>qp_polish.
  // Default -<prefix>tao_type activeset: the active-set method alone, warm-started; bqpip (or any
  // bound-constrained TAO type) runs TAO from zero, then the active-set polish.
  PetscErrorCode Setup(const std::string &prefix, MPI_Comm comm = PETSC_COMM_SELF); // comm: where -help lists the options
  // S: R x R column-major SPD; minimizes 1/2 l'Sl - b'l over l >= 0. warm (optional, size R): a start,
  // e.g. the previous Kacanov iterate's multipliers (its support is the initial active set).
  PetscErrorCode Solve(PetscInt R, const std::vector<PetscReal> &S, const std::vector<PetscReal> &b, std::vector<PetscReal> *lambda, DualQPInfo *info, const std::vector<PetscReal> *warm = nullptr);
  // The settings Setup read (for the advice of a QP that was not solved): TAO in use, its -<prefix>qp_tao_type, the polish
  bool               UsesTao() const { return useTao_; }
  const std::string &TaoType() const { return type_; }
  bool               Polish() const { return polish_; }

private:
  std::string prefix_, type_ = "activeset";
  PetscBool   polish_ = PETSC_TRUE;
  PetscBool   useTao_ = PETSC_FALSE;
};

} // namespace rbc
