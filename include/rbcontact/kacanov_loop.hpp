// rbcontact/kacanov_loop.hpp: the Kacanov fixed-point loop shared by the full-order solve (KacanovSolver,
// input = the displacement of the contact dofs) and the reduced one (ReducedModel, input = the reduced
// coordinates v): its options (-<prefix>kacanov_max_it, _rtol_primal, _rtol_dual, _relaxation, _anderson,
// _monitor), the relaxation of the primal image, the primal change, the stopping rule, Anderson mixing of
// the next input, the monitor line, the history and the non-convergence message. The backends compute the
// image (contact terms at the input, QP, primal image) and the change of their multipliers in their own
// norm. Serial and allocation-free after the first loop of a given size (the ROM solves in microseconds).
#pragma once
#include "rbcontact/anderson.hpp"
#include <string>
#include <vector>

namespace rbc {

struct KacanovLoopHistory {
  std::vector<PetscReal> du, dl;  // relative changes of the primal input and of the multipliers, per iterate
  std::vector<PetscInt>  nactive; // active multipliers per iterate
};

class KacanovLoop {
public:
  KacanovLoop() = default;
  KacanovLoop(PetscReal rtolP, PetscReal rtolD, const char *lbl) : rtolPrimal(rtolP), rtolDual(rtolD), label(lbl) {}
  // Reads -<prefix>kacanov_max_it, _rtol_primal, _rtol_dual, _relaxation, _anderson, _monitor (the current
  // values are the defaults) and checks their ranges. Collective on comm (PetscOptionsBegin).
  PetscErrorCode SetFromOptions(MPI_Comm comm, const std::string &prefix);

  // Starts a loop: clears the history; Anderson mixing (if anderson > 0) on n unknowns (n = 0: the caller
  // keeps a distributed state and calls Record with its own changes).
  void Begin(PetscInt n);
  // g (n values, the image of the input x) <- x + relaxation (g - x); returns the primal change
  // |g - x| / |x| of the image before the relaxation (l2; infinite when x = 0 and g != 0, 0 when both vanish): the
  // fixed-point residual, whatever the relaxation (the relaxed step, relaxation |g - x|, met the tolerance at the first
  // iterate with a relaxation of 1e-4 and returned the warm start as converged until 2026-12-01).
  PetscReal Relax(const PetscReal *x, PetscReal *g) const;
  // Records iterate k (du, dl, nactive of R), prints the monitor line (detail: backend's text or null) and
  // sets *converged: du <= rtolPrimal and dl <= rtolDual, or maxIt == 1 (the linearized model).
  // dualIsChange = false: dl compares with multipliers the loop did not compute (a warm start's, which
  // does not enter the image): it is recorded and printed but not tested. The fixed point is in the
  // primal input alone (the multipliers are the QP's at the input), so du <= rtolPrimal certifies it;
  // only a backend that relaxes the multipliers (relaxation < 1) must keep the dual test.
  PetscErrorCode Record(MPI_Comm comm, PetscInt k, PetscReal du, PetscReal dl, PetscInt nactive, PetscInt R, const char *detail, bool *converged, bool dualIsChange = true);
  // The next input from the input x and its (relaxed) image g: Anderson's mix, or g itself. Returns true
  // when next differs from g (a mix was used).
  bool Next(const PetscReal *x, const PetscReal *g, PetscReal *next);
  // "did not converge in ... iterations (options); last changes ..." with the history when withHistory; when the
  // history ends in a cycle (Cycle), the message says so; otherwise when the primal change of the last 10 iterates stalls
  // (the mean of the last 5 at least 0.9 of the 5 before, all above rtol_primal), it says that.
  // cause: appended to the summary, before the history (e.g. the initial overlap the FOM measured); relaxationHint false
  // when the cause is known not to be the fixed point's (a QP that was not solved): no "try -kacanov_relaxation 0.5"
  std::string NotConverged(bool withHistory, const std::string &cause = "", bool relaxationHint = true) const;
  // The period p (2..12) of a cycle the history ends in: its last 2p iterates repeat the p before them (du and dl to
  // 1e-6 relative, the active counts exactly), the smallest such p; 0 when there is none. *from: the first iterate
  // (1-based) of the repeating stretch. A converging loop's changes fall, so they never repeat.
  PetscInt Cycle(PetscInt *from = nullptr) const;
  // The relative change rule: diff / prev, or 0 / infinity when prev = 0 (cur = 0 / cur != 0).
  static PetscReal RelChange(PetscReal diff, PetscReal prev, PetscReal cur);

  PetscInt           maxIt = 30;
  PetscReal          rtolPrimal = 1e-8, rtolDual = 1e-8, relaxation = 1.0;
  PetscInt           anderson = 3; // depth of Anderson mixing (0: the plain fixed point)
  PetscBool          monitor  = PETSC_FALSE;
  std::string        label    = "Kacanov"; // monitor lines: "  <k> <label> |du|/|u| ..."
  KacanovLoopHistory history;

private:
  std::string    prefix_;
  PetscInt       n_ = 0;
  AndersonMixing aa_;
};

} // namespace rbc
