// src/apps/offline_bases.hpp: the bases step of the offline stage (-offline_stop bases): primal POD
// and nonnegative dual basis from a complete snapshot file, written to the ROM file.
#pragma once
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/snapshot_file.hpp"

namespace rbc {

// group: the ranks of fom (a subcommunicator of world); world rank 0 writes romPath.
PetscErrorCode OfflineBases(MPI_Comm world, ElasticFOM &fom, const CanonicalOrder &order, const std::string &snapPath, const std::string &romPath, const SnapshotHeader &header, Report *rep);

} // namespace rbc
