// src/offline/snapshot_contact.cpp: AssembleSnapshotContactMatrices (snapshot_contact.hpp): the training snapshots'
// contact matrices on the contact dofs, reassembled from their displacements.
#include "rbcontact/snapshot_contact.hpp"
#include "rbcontact/kacanov.hpp"
#include <algorithm>

namespace rbc {

PetscErrorCode AssembleSnapshotContactMatrices(MPI_Comm comm, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const std::vector<Snapshot> &snaps, SnapshotContactMatrices *out)
{
  std::vector<PetscInt> D;
  Vec                   u, uloc;
  PetscInt              lo, hi;

  PetscFunctionBeginUser;
  *out                             = SnapshotContactMatrices();
  const std::vector<PetscReal> muIn = fom.mu; // restored at the end, with the map's geometry there
  PetscCall(cmap.SurfaceDofs(comm, &D));
  // the columns: D's canonical indices, ascending; canon[p] = the column of D[p]
  std::vector<std::pair<PetscInt, PetscInt>> cd;
  for (size_t p = 0; p < D.size(); ++p) cd.emplace_back(order.CanonicalDof(D[p]), (PetscInt)p);
  std::sort(cd.begin(), cd.end());
  std::vector<PetscInt> canon(D.size());
  for (size_t j = 0; j < cd.size(); ++j) {
    out->dofs.push_back(cd[j].first);
    canon[cd[j].second] = (PetscInt)j;
  }
  PetscCall(DMCreateGlobalVector(fom.dm, &u));
  PetscCall(DMGetLocalVector(fom.dm, &uloc));
  PetscCall(VecGetOwnershipRange(u, &lo, &hi));
  for (const Snapshot &s : snaps) {
    PetscCheck((PetscInt)s.u.size() == order.NumDofs(), comm, PETSC_ERR_FILE_UNEXPECTED, "snapshot %" PetscInt_FMT ": %zu displacement values for %" PetscInt_FMT " dofs", s.index, s.u.size(), order.NumDofs());
    PetscCall(fom.SetMu(s.mu)); // the Dirichlet values at mu_j
    cmap.SetGeometry(&fom.map, fom.mu);
    PetscScalar *a;
    PetscCall(VecGetArray(u, &a));
    for (PetscInt i = lo; i < hi; ++i) a[i - lo] = s.u[order.CanonicalDof(i)];
    PetscCall(VecRestoreArray(u, &a));
    PetscCall(fom.elas.GlobalToLocalWithBC(u, uloc));
    ContactSystem sys;
    SparseRows    KD;
    PetscCall(cmap.Assemble(fom.elas, uloc, &sys));
    if (order.NumMultipliers() != cmap.NumMultipliers()) PetscCall(order.BuildMultipliers(sys.coordRef, fom.elas.dim));
    PetscCall(GatherRowsOnDofs(sys.K, D, &KD));
    // rows to the canonical multiplier order, columns to the canonical dof order (ascending within a row)
    SparseRows &K = out->K.emplace_back();
    K.rows        = KD.rows;
    K.cols        = KD.cols;
    std::vector<PetscInt> rowOf(KD.rows); // rowOf[c]: the global row of canonical row c
    for (PetscInt g = 0; g < KD.rows; ++g) rowOf[order.CanonicalMultiplier(g)] = g;
    K.ptr.assign(1, 0);
    K.col.reserve(KD.col.size());
    K.val.reserve(KD.val.size());
    std::vector<std::pair<PetscInt, PetscReal>> row;
    for (PetscInt c = 0; c < KD.rows; ++c) {
      const PetscInt g = rowOf[c];
      row.clear();
      for (PetscInt e = KD.ptr[g]; e < KD.ptr[g + 1]; ++e) row.emplace_back(canon[KD.col[e]], KD.val[e]);
      std::sort(row.begin(), row.end());
      for (const auto &cv : row) {
        K.col.push_back(cv.first);
        K.val.push_back(cv.second);
      }
      K.ptr.push_back((PetscInt)K.col.size());
    }
    out->index.push_back(s.index);
  }
  PetscCall(DMRestoreLocalVector(fom.dm, &uloc));
  PetscCall(VecDestroy(&u));
  if (muIn.size() == fom.scene.params.size()) {
    PetscCall(fom.SetMu(muIn));
    cmap.SetGeometry(&fom.map, fom.mu);
  }
  PetscFunctionReturn(0);
}

} // namespace rbc
