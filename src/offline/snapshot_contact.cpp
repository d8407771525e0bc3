// src/offline/snapshot_contact.cpp: AssembleAtStoredSolution and AssembleSnapshotContactMatrices (snapshot_contact.hpp):
// the contact system at a stored solution, and the training snapshots' contact matrices on the contact dofs.
#include "rbcontact/snapshot_contact.hpp"
#include "rbcontact/kacanov.hpp"
#include <algorithm>

namespace rbc {

PetscErrorCode AssembleAtStoredSolution(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const Snapshot &snap, ContactSystem *sys)
{
  PetscInt     lo, hi;
  PetscScalar *a;
  Vec          uloc;

  PetscFunctionBeginUser;
  PetscCheck((PetscInt)snap.u.size() == order.NumDofs(), PetscObjectComm((PetscObject)fom.dm), PETSC_ERR_FILE_UNEXPECTED, "snapshot %" PetscInt_FMT ": %zu displacement values for %" PetscInt_FMT " dofs", snap.index, snap.u.size(), order.NumDofs());
  if (!fom.u) PetscCall(DMCreateGlobalVector(fom.dm, &fom.u));
  PetscCall(VecGetOwnershipRange(fom.u, &lo, &hi));
  PetscCall(VecGetArray(fom.u, &a));
  for (PetscInt i = lo; i < hi; ++i) a[i - lo] = snap.u[order.CanonicalDof(i)];
  PetscCall(VecRestoreArray(fom.u, &a));
  PetscCall(DMGetLocalVector(fom.dm, &uloc));
  PetscCall(fom.elas.GlobalToLocalWithBC(fom.u, uloc));
  PetscCall(cmap.Assemble(fom.elas, uloc, sys));
  PetscCall(DMRestoreLocalVector(fom.dm, &uloc));
  if (order.NumMultipliers() != cmap.NumMultipliers()) PetscCall(order.BuildMultipliers(sys->coordRef, fom.elas.dim));
  PetscFunctionReturn(0);
}

PetscErrorCode AssembleSnapshotContactMatrices(MPI_Comm comm, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const std::vector<Snapshot> &snaps, SnapshotContactMatrices *out)
{
  std::vector<PetscInt> D;

  PetscFunctionBeginUser;
  *out                             = SnapshotContactMatrices();
  const std::vector<PetscReal> muIn = fom.mu; // restored at the end, with the map's geometry there, and fom.u
  Vec                          uIn  = nullptr;
  if (fom.u) PetscCall(VecDuplicate(fom.u, &uIn));
  if (fom.u) PetscCall(VecCopy(fom.u, uIn));
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
  for (const Snapshot &s : snaps) {
    PetscCall(fom.SetMu(s.mu)); // the Dirichlet values at mu_j
    cmap.SetGeometry(&fom.map, fom.mu);
    ContactSystem sys;
    SparseRows    KD;
    PetscCall(AssembleAtStoredSolution(fom, cmap, order, s, &sys));
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
  if (uIn) {
    PetscCall(VecCopy(uIn, fom.u));
    PetscCall(VecDestroy(&uIn));
  }
  if (muIn.size() == fom.scene.params.size()) {
    PetscCall(fom.SetMu(muIn));
    cmap.SetGeometry(&fom.map, fom.mu);
  }
  PetscFunctionReturn(0);
}

} // namespace rbc
