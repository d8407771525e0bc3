// rbcontact/snapshot_contact.hpp: the contact matrices of the training snapshots, K(u_j) on the contact dofs at
// each snapshot's parameter and solution, reassembled by the offline stage from the snapshot file's u (the file no
// longer stores them: docs/snapshot_file.md, version 2). The supremizers and their inf-sup constant use them.
#pragma once
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/snapshot_file.hpp"
#include "rbcontact/sparse_rows.hpp"
#include <vector>

namespace rbc {

struct SnapshotContactMatrices {
  std::vector<PetscInt>   dofs; // the contact dofs (ContactMap::SurfaceDofs) as canonical indices, ascending: the columns
  std::vector<SparseRows> K;    // K[j]: snapshot j's, rows in the canonical multiplier order, columns positions in dofs
  std::vector<PetscInt>   index; // index[j]: snapshot j's position in the training set (for messages)
};

// fom.u := snap's stored displacement (created if absent) and *sys := the contact system assembled at it, with the
// Dirichlet values of fom's current mu (the caller sets fom and the map's geometry at snap's mu); the canonical
// multiplier order built if the caller has not. Collective. (validate -test_snapshots reads its FOM solutions so.)
PetscErrorCode AssembleAtStoredSolution(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const Snapshot &snap, ContactSystem *sys);

// For every snapshot (mu_j, u_j): the map's geometry at mu_j, K(u_j) assembled at u_j (its Dirichlet values at mu_j),
// gathered on every rank in canonical orders (the multiplier order built here if the caller has not). fom's mu, u
// and the map's geometry are set back to those on entry. Collective.
PetscErrorCode AssembleSnapshotContactMatrices(MPI_Comm comm, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const std::vector<Snapshot> &snaps, SnapshotContactMatrices *out);

} // namespace rbc
