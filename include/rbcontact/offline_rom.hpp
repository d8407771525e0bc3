// include/rbcontact/offline_rom.hpp: the online data step of the offline stage (reduced affine terms, EIM of
// the contact map and gap, local contact data, warm starts), written into the ROM file.
#pragma once
#include <slepcbv.h>
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/reduced_model.hpp"
#include <memory>
#include "rbcontact/report.hpp"
#include "rbcontact/rom_file.hpp"
#include "rbcontact/snapshot_file.hpp"

namespace rbc {

// -rom_hyper ecsw|eim|ecsw,eim|eim,ecsw (default ecsw): the hyper-reductions of the contact terms to
// build; the first is the ROM's default online. Checks -ecsw_* too (before the snapshots).
struct HyperChoice {
  bool eim = false, ecsw = true, ecswFirst = true;
};
PetscErrorCode HyperChoiceFromOptions(MPI_Comm comm, HyperChoice *h);

// The contact patch's options (-eim_quadrature_subdivisions: candidate points per slave facet, default 4;
// -eim_patch_rings: rings of master facets kept online, default 2), range-checked; either output may be NULL.
// Read by the offline stage before the snapshots (their check) and by the hyper-reduction.
PetscErrorCode ContactPatchOptions(MPI_Comm comm, PetscInt *nsub, PetscInt *rings);

// V: the primal basis (Npod POD modes then nsup supremizers) on fom's DM; modes: the same, N x ndofs
// row-major in canonical order, on every rank of fom's communicator. order's multipliers are numbered
// here when a resumed run solved no snapshot. ecswTol > 0: the cubature's tolerance instead of -ecsw_tol's
// (-dual_select_refit_ecsw_tol). Report keys eim {...}, rom {...}.
PetscErrorCode OfflineReducedModel(MPI_Comm world, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const std::vector<Snapshot> &snaps, BV V, const std::vector<double> &modes, PetscInt Npod, PetscInt nsup, const DualBasisResult &dual, RomWriter *w, Report *rep, PetscInt nDefault = -1, PetscInt rDefault = -1, PetscReal ecswTol = 0);

// The reduced model with exact contact terms: reduced affine terms V'A_qV, V'f_q and the full contact patch
// (every -eim_quadrature_subdivisions point of the slave facets on the support of the dual basis) with
// P = W' Psi; mode Exact, -rom_kacanov_*/-rom_qp_* options read. The first part of the online data, and
// the model of the greedy training's error indicator (offline_greedy.hpp).
PetscErrorCode BuildExactReducedModel(MPI_Comm world, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, BV V, const std::vector<double> &modes, PetscInt Npod, PetscInt nsup, const DualBasisResult &dual, ReducedModel *rm, std::shared_ptr<ContactPatch> *full, std::vector<PetscReal> *P, PetscInt *nsub);

} // namespace rbc
