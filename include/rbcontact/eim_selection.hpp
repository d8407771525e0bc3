// rbcontact/eim_selection.hpp: the EIM sizes the online stage uses by default, chosen on held-out
// parameters. The EIM greedy stops on its error over the training states; on a piecewise smooth
// contact map (the master trace is piecewise linear along the master surface) more terms can
// generalize worse to the states between training parameters (measured, docs/eim.md). For each
// candidate size the reduced model with EIM is solved at held-out parameters and compared with the
// reduced model with exact contact terms (same bases): the error of the EIM alone. The smallest size
// within (1 + slack) of the best error is the default; the file keeps every term (-rom_Mk up to Mk).
#pragma once
#include <petscsys.h>
#include <vector>
#include "rbcontact/reduced_model.hpp"

namespace rbc {

struct EIMSelection {
  PetscInt               Mk = 0, Mg = 0;     // chosen sizes
  PetscInt               heldout = 0;        // held-out parameters used
  std::vector<PetscReal> errKappa, errGap;   // errKappa[m-1]: max over held-out of the error with Mk = m (Mg all); errGap[m-1]: Mg = m with the chosen Mk
  PetscReal              err = 0;            // error at the chosen sizes
};

// A held-out parameter's reference: the reduced solution with exact contact terms and A^(mu).
struct HeldOutReference {
  ReducedSolution        sol;
  std::vector<PetscReal> A; // N x N: the energy norm of the u error
};

// Held-out error of the EIM at sizes (mk, mg): the max over the parameters of max(rel. error of u in
// the reduced energy norm v'A^(mu)v, rel. error of lambda in W'W) against the references ref (one per
// parameter); a non-converged solve counts as +inf. The parameters are split over the ranks of comm
// (every rank holds the same model); the result is the same on every rank.
PetscErrorCode EIMHeldOutError(MPI_Comm comm, ReducedModel &rm, const std::vector<std::vector<PetscReal>> &mus, const std::vector<HeldOutReference> &ref, PetscInt mk, PetscInt mg, PetscReal *err);

// rm: a complete model (EIM terms, patch, warm starts, exact contact terms set by SetExactContact).
// Solves the exact-contact references, scans Mk = 1..MkFull (Mg = MgFull), then Mg = 1..MgFull, and
// sets rm.MkDefault, rm.MgDefault. Leaves rm in EIM mode truncated to the chosen sizes.
// Errors: a held-out parameter where the exact-contact reduced model does not converge.
PetscErrorCode SelectEIMSizes(MPI_Comm comm, ReducedModel &rm, const std::vector<std::vector<PetscReal>> &mus, PetscReal slack, EIMSelection *sel);

// The default held-out parameters for a training set: with one parameter the midpoints of the
// consecutive distinct training values; otherwise n random points of the box (seed).
std::vector<std::vector<PetscReal>> HeldOutParameters(const std::vector<ParamSpec> &params, const std::vector<std::vector<PetscReal>> &train, PetscInt n, unsigned long long seed);

} // namespace rbc
