// src/apps/offline_bases.hpp: the bases step of the offline stage (-offline_stop bases): primal POD
// and nonnegative dual basis from a complete snapshot file, written to the ROM file.
#pragma once
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/rom_file.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/snapshot_file.hpp"

namespace rbc {

// group: the ranks of fom (a subcommunicator of world); world rank 0 writes romPath.
// cmap: the scene's contact surfaces (null without contact; -dual_mass_weighted and the online ROM need
// them). onlineRom false: bases only (-offline_stop bases), written to romPath (format_version 1);
// true: the bases go to basisPath and the online ROM (format_version 2, src/apps/offline_rom.cpp) to romPath.
PetscErrorCode OfflineBases(MPI_Comm world, ElasticFOM &fom, CanonicalOrder &order, const std::string &snapPath, const std::string &romPath, const SnapshotHeader &header, Report *rep, ContactMap *cmap = nullptr, bool onlineRom = false, const std::string &basisPath = "");

// Report keys dual {type, r, train_max_err, train_max_rel_err, history, tol_abs, norm, gram_cond,
// selected, min_entry} and nnls {solves, max_kkt, retries}; a negative basis entry is an error.
PetscErrorCode ReportDualBasis(MPI_Comm comm, const DualBasisResult &dual, Report *rep);
// /dual/basis (r rows of R), /dual/history, /dual/gram_cond, /dual/selected.
void WriteDualBasis(const DualBasisResult &dual, RomWriter *w, bool withBasis = true);

} // namespace rbc
