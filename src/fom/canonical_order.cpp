// src/fom/canonical_order.cpp: partition-independent numbering of dofs and multipliers by sorting
// geometric keys gathered from every rank.
#include "rbcontact/canonical_order.hpp"
#include <algorithm>
#include <array>

namespace rbc {

using Key = std::array<PetscReal, 6>; // body, x, y, z, component, global index

static PetscErrorCode SortKeys(MPI_Comm comm, const std::vector<Key> &mine, PetscInt n, std::vector<PetscInt> *canon)
{
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  std::vector<int> counts(size), displs(size, 0);
  int              c = (int)(mine.size() * 6);
  PetscCallMPI(MPI_Allgather(&c, 1, MPI_INT, counts.data(), 1, MPI_INT, comm));
  for (int r = 1; r < size; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<Key> all((displs[size - 1] + counts[size - 1]) / 6);
  PetscCallMPI(MPI_Allgatherv(mine.data(), c, MPIU_REAL, all.data(), counts.data(), displs.data(), MPIU_REAL, comm));
  PetscCheck((PetscInt)all.size() == n, comm, PETSC_ERR_PLIB, "canonical order: %zu keys for %" PetscInt_FMT " entries", all.size(), n);
  std::sort(all.begin(), all.end(), [](const Key &a, const Key &b) { return std::lexicographical_compare(a.begin(), a.begin() + 5, b.begin(), b.begin() + 5); });
  for (size_t i = 1; i < all.size(); ++i)
    PetscCheck(!std::equal(all[i].begin(), all[i].begin() + 5, all[i - 1].begin()), comm, PETSC_ERR_USER_INPUT, "canonical order: two entries share body, coordinates and component (duplicate mesh nodes in one body?)");
  canon->assign(n, -1);
  for (size_t i = 0; i < all.size(); ++i) (*canon)[(PetscInt)all[i][5]] = (PetscInt)i;
  PetscFunctionReturn(0);
}

PetscErrorCode CanonicalOrder::BuildDofs(const Elasticity &elas)
{
  DM           dm = elas.dm, cdm;
  PetscSection gsec, lsec, csec;
  Vec          coords;
  PetscInt     pStart, pEnd, cStart, cEnd, vStart, vEnd, n, dim = elas.dim;
  const PetscScalar *xc;

  PetscFunctionBeginUser;
  PetscCall(DMGetGlobalSection(dm, &gsec));
  PetscCall(DMGetLocalSection(dm, &lsec));
  PetscCall(DMGetCoordinateDM(dm, &cdm));
  PetscCall(DMGetLocalSection(cdm, &csec));
  PetscCall(DMGetCoordinatesLocal(dm, &coords));
  PetscCall(DMPlexGetChart(dm, &pStart, &pEnd));
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
  {
    Vec g;
    PetscCall(DMGetGlobalVector(dm, &g));
    PetscCall(VecGetSize(g, &n));
    PetscCall(DMRestoreGlobalVector(dm, &g));
  }
  PetscCall(VecGetArrayRead(coords, &xc));
  std::vector<Key> mine;
  for (PetscInt p = pStart; p < pEnd; ++p) {
    PetscInt dof, cdof, off;
    PetscCall(PetscSectionGetDof(lsec, p, &dof));
    PetscCall(PetscSectionGetConstraintDof(lsec, p, &cdof));
    PetscCall(PetscSectionGetOffset(gsec, p, &off)); // < 0: owned by another rank
    if (dof <= 0 || off < 0 || dof - cdof <= 0) continue; // not owned, or fully constrained
    // point coordinates: mean of its vertices. Only the vertices are asked: the coordinate section's chart holds them
    // alone, and PETSc's optimized build read an edge's (P2) dof count and offset from outside it, garbage: a segfault
    // or a node order that changed from run to run (a P2 ROM's fields 13 % off, exit 0; fixed 2026-12-02)
    PetscInt *closure = NULL, ncl, nvert = 0;
    PetscReal x[3] = {0, 0, 0};
    PetscCall(DMPlexGetTransitiveClosure(dm, p, PETSC_TRUE, &ncl, &closure));
    for (PetscInt k = 0; k < ncl; ++k) {
      PetscInt cd, co;
      if (closure[2 * k] < vStart || closure[2 * k] >= vEnd) continue;
      PetscCall(PetscSectionGetDof(csec, closure[2 * k], &cd));
      if (!cd) continue;
      PetscCall(PetscSectionGetOffset(csec, closure[2 * k], &co));
      for (PetscInt d = 0; d < dim; ++d) x[d] += PetscRealPart(xc[co + d]);
      ++nvert;
    }
    PetscCall(DMPlexRestoreTransitiveClosure(dm, p, PETSC_TRUE, &ncl, &closure));
    PetscCheck(nvert > 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "canonical order: mesh point %" PetscInt_FMT " holds dofs but no vertex with coordinates", p);
    for (PetscInt d = 0; d < dim; ++d) x[d] /= nvert;
    // body: any cell in the star of p
    PetscInt *star = NULL, nst, body = -1;
    PetscCall(DMPlexGetTransitiveClosure(dm, p, PETSC_FALSE, &nst, &star));
    for (PetscInt k = 0; k < nst && body < 0; ++k)
      if (star[2 * k] >= cStart && star[2 * k] < cEnd) body = elas.CellBody()[star[2 * k] - cStart];
    PetscCall(DMPlexRestoreTransitiveClosure(dm, p, PETSC_FALSE, &nst, &star));
    // free components in order: which components are constrained?
    const PetscInt *cind = NULL;
    PetscCall(PetscSectionGetConstraintIndices(lsec, p, &cind));
    PetscInt g = off;
    for (PetscInt c = 0; c < dof; ++c) {
      bool constrained = false;
      for (PetscInt k = 0; k < cdof; ++k) if (cind && cind[k] == c) constrained = true;
      if (constrained) continue;
      mine.push_back({(PetscReal)body, x[0], x[1], x[2], (PetscReal)(c % dim), (PetscReal)g++});
    }
  }
  PetscCall(VecRestoreArrayRead(coords, &xc));
  PetscCall(SortKeys(PetscObjectComm((PetscObject)dm), mine, n, &dofCanon_));
  PetscFunctionReturn(0);
}

PetscErrorCode CanonicalOrder::BuildMultipliers(const Vec coord[], PetscInt dim)
{
  PetscInt lo, hi, n;
  const PetscScalar *x[3] = {NULL, NULL, NULL};

  PetscFunctionBeginUser;
  PetscCall(VecGetOwnershipRange(coord[0], &lo, &hi));
  PetscCall(VecGetSize(coord[0], &n));
  for (PetscInt d = 0; d < dim; ++d) PetscCall(VecGetArrayRead(coord[d], &x[d]));
  std::vector<Key> mine;
  for (PetscInt i = lo; i < hi; ++i) mine.push_back({0, PetscRealPart(x[0][i - lo]), PetscRealPart(x[1][i - lo]), dim == 3 ? PetscRealPart(x[2][i - lo]) : 0.0, 0, (PetscReal)i});
  for (PetscInt d = 0; d < dim; ++d) PetscCall(VecRestoreArrayRead(coord[d], &x[d]));
  PetscCall(SortKeys(PetscObjectComm((PetscObject)coord[0]), mine, n, &multCanon_));
  PetscFunctionReturn(0);
}

static PetscErrorCode ToCanonical(Vec v, const std::vector<PetscInt> &canon, std::vector<PetscReal> *out)
{
  MPI_Comm           comm = PetscObjectComm((PetscObject)v);
  PetscMPIInt        rank, size;
  PetscInt           lo, hi;
  const PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(VecGetOwnershipRange(v, &lo, &hi));
  PetscCall(VecGetArrayRead(v, &a));
  std::vector<PetscReal> mine(2 * (hi - lo));
  for (PetscInt i = lo; i < hi; ++i) { mine[2 * (i - lo)] = canon[i]; mine[2 * (i - lo) + 1] = PetscRealPart(a[i - lo]); }
  PetscCall(VecRestoreArrayRead(v, &a));
  std::vector<int> counts(size), displs(size, 0);
  int              c = (int)mine.size();
  PetscCallMPI(MPI_Gather(&c, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm));
  for (int r = 1; r < size; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<PetscReal> all(rank == 0 ? displs[size - 1] + counts[size - 1] : 0);
  PetscCallMPI(MPI_Gatherv(mine.data(), c, MPIU_REAL, all.data(), counts.data(), displs.data(), MPIU_REAL, 0, comm));
  out->clear();
  if (rank == 0) {
    out->assign(canon.size(), 0.0);
    for (size_t k = 0; k < all.size(); k += 2) (*out)[(size_t)all[k]] = all[k + 1];
  }
  PetscFunctionReturn(0);
}

PetscErrorCode CanonicalOrder::DofsToCanonical(Vec v, std::vector<PetscReal> *out) const { return ToCanonical(v, dofCanon_, out); }
PetscErrorCode CanonicalOrder::MultipliersToCanonical(Vec v, std::vector<PetscReal> *out) const { return ToCanonical(v, multCanon_, out); }

} // namespace rbc
