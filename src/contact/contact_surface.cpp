// src/contact/contact_surface.cpp: extraction of a labelled boundary's facets with their geometry,
// displacement nodes, global dofs and outward orientation; gathering of a surface on every rank.
#include "rbcontact/contact.hpp"
#include <petscsf.h>
#include <cmath>

namespace rbc {

void FacetBasis(const SurfaceFacet &f, const PetscReal b[], PetscReal N[])
{
  static const PetscInt edge[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  const bool            quadratic  = f.nnodes > f.nv;
  for (PetscInt i = 0; i < f.nnodes; ++i) {
    const PetscInt k = f.nodeKind[i];
    if (k < 3) N[i] = quadratic ? b[k] * (2 * b[k] - 1) : b[k];
    else N[i] = 4 * b[edge[k - 3][0]] * b[edge[k - 3][1]];
  }
}

PetscErrorCode ContactSurface::Build(const Elasticity &elas, const std::string &label)
{
  DM           dm = elas.dm;
  DMLabel      dmlabel;
  PetscSection lsec, gsec;
  PetscInt     fStart, fEnd, vStart, vEnd;
  IS           vnumIS;
  const PetscInt *vnum;

  PetscFunctionBeginUser;
  dim = elas.dim;
  facets.clear();
  points.clear();
  PetscCall(DMGetLabel(dm, label.c_str(), &dmlabel));
  PetscCall(DMGetLocalSection(dm, &lsec));
  PetscCall(DMGetGlobalSection(dm, &gsec));
  PetscCall(DMPlexGetHeightStratum(dm, 1, &fStart, &fEnd));
  PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
  PetscCall(DMPlexGetVertexNumbering(dm, &vnumIS));
  PetscCall(ISGetIndices(vnumIS, &vnum));
  DM           cdm;
  Vec          coords;
  PetscSection csec;
  PetscCall(DMGetCoordinateDM(dm, &cdm));
  PetscCall(DMGetCoordinatesLocal(dm, &coords));
  PetscCall(DMGetLocalSection(cdm, &csec));
  {
    // Facets inside a body (two cells): the body's name given for its surface (-contact_master block), or a curve
    // embedded in a body. Counted on every rank first: checked on the ranks that hold such facets alone, the others
    // waited for them in the next collective (a hang on 2 ranks).
    PetscInt bad = 0;
    MPI_Comm comm;
    PetscCall(PetscObjectGetComm((PetscObject)dm, &comm));
    for (PetscInt p = fStart; p < fEnd && dmlabel; ++p) {
      PetscInt val, nsupp;
      PetscCall(DMLabelGetValue(dmlabel, p, &val));
      if (val < 0) continue;
      PetscCall(DMPlexGetSupportSize(dm, p, &nsupp));
      if (nsupp != 1) ++bad;
    }
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_SUM, comm));
    PetscCheck(bad == 0, comm, PETSC_ERR_USER_INPUT, "Contact surface '%s': %" PetscInt_FMT " of its facets lie inside a body (two cells each), not on its boundary: name a boundary curve of the body (surface in 3D) as the contact surface, not the body itself or a curve embedded in it", label.c_str(), bad);
  }
  for (PetscInt p = fStart; p < fEnd && dmlabel; ++p) {
    PetscInt val;
    PetscCall(DMLabelGetValue(dmlabel, p, &val));
    if (val < 0) continue;
    const PetscInt *support;
    PetscInt        nsupp;
    PetscCall(DMPlexGetSupportSize(dm, p, &nsupp));
    PetscCall(DMPlexGetSupport(dm, p, &support));
    SurfaceFacet f;
    f.nv = dim;
    // Vertex coordinates in closure order
    PetscScalar *cv = NULL;
    PetscInt     ncv;
    PetscCall(DMPlexVecGetClosure(cdm, csec, coords, p, &ncv, &cv));
    PetscCheck(ncv == dim * dim, PETSC_COMM_SELF, PETSC_ERR_SUP, "Contact surface '%s': facet with %" PetscInt_FMT " coordinates (simplex facets only)", label.c_str(), ncv);
    for (PetscInt i = 0; i < ncv; ++i) f.X[i] = PetscRealPart(cv[i]);
    PetscCall(DMPlexVecRestoreClosure(cdm, csec, coords, p, &ncv, &cv));
    // Closure points -> displacement nodes, global dofs
    PetscInt *closure = NULL, ncl;
    PetscInt *idx     = NULL, nidx;
    PetscCall(DMPlexGetTransitiveClosure(dm, p, PETSC_TRUE, &ncl, &closure));
    PetscCall(DMPlexGetClosureIndices(dm, lsec, gsec, p, PETSC_TRUE, &nidx, &idx, NULL, NULL));
    std::vector<PetscInt> verts;
    for (PetscInt c = 0; c < ncl; ++c)
      if (closure[2 * c] >= vStart && closure[2 * c] < vEnd) verts.push_back(closure[2 * c]);
    PetscCheck((PetscInt)verts.size() == dim, PETSC_COMM_SELF, PETSC_ERR_SUP, "Contact surface '%s': facet with %zu vertices", label.c_str(), verts.size());
    for (PetscInt k = 0; k < dim; ++k) {
      const PetscInt g = vnum[verts[k] - vStart];
      f.vglobal[k]     = g < 0 ? -(g + 1) : g;
    }
    PetscInt off = 0;
    for (PetscInt c = 0; c < ncl; ++c) {
      const PetscInt q = closure[2 * c];
      PetscInt       ndof;
      PetscCall(PetscSectionGetDof(lsec, q, &ndof));
      if (!ndof) continue;
      PetscCheck(ndof == dim && f.nnodes < 6, PETSC_COMM_SELF, PETSC_ERR_SUP, "Contact surface '%s': point with %" PetscInt_FMT " dofs (vector Lagrange P1/P2 only)", label.c_str(), ndof);
      PetscInt kind = -1;
      if (q >= vStart && q < vEnd) {
        for (PetscInt k = 0; k < dim; ++k) if (verts[k] == q) kind = k;
      } else {
        const PetscInt *cone;
        PetscInt        csz;
        PetscCall(DMPlexGetConeSize(dm, q, &csz));
        PetscCall(DMPlexGetCone(dm, q, &cone));
        PetscCheck(csz == 2, PETSC_COMM_SELF, PETSC_ERR_SUP, "Contact surface '%s': dofs on a non-edge point", label.c_str());
        PetscInt a = -1, b = -1;
        for (PetscInt k = 0; k < dim; ++k) {
          if (verts[k] == cone[0]) a = k;
          if (verts[k] == cone[1]) b = k;
        }
        const PetscInt lo = PetscMin(a, b), hi = PetscMax(a, b);
        kind = 3 + (lo == 0 && hi == 1 ? 0 : (lo == 1 && hi == 2 ? 1 : 2));
      }
      f.nodeKind[f.nnodes] = kind;
      for (PetscInt d = 0; d < dim; ++d) f.dof[f.nnodes * dim + d] = idx[off + d];
      off += ndof;
      ++f.nnodes;
    }
    PetscCheck(off == nidx, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Contact surface '%s': closure index count mismatch", label.c_str());
    PetscCall(DMPlexRestoreClosureIndices(dm, lsec, gsec, p, PETSC_TRUE, &nidx, &idx, NULL, NULL));
    PetscCall(DMPlexRestoreTransitiveClosure(dm, p, PETSC_TRUE, &ncl, &closure));
    // Outward orientation: the facet normal must point away from its cell.
    PetscReal cc[3] = {0, 0, 0}, fc[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    PetscCall(DMPlexComputeCellGeometryFVM(dm, support[0], NULL, cc, NULL));
    for (PetscInt k = 0; k < dim; ++k)
      for (PetscInt d = 0; d < dim; ++d) fc[d] += f.X[k * dim + d] / dim;
    if (dim == 2) {
      n[0] = f.X[3] - f.X[1];
      n[1] = -(f.X[2] - f.X[0]);
    } else {
      const PetscReal a[3] = {f.X[3] - f.X[0], f.X[4] - f.X[1], f.X[5] - f.X[2]}, b[3] = {f.X[6] - f.X[0], f.X[7] - f.X[1], f.X[8] - f.X[2]};
      n[0] = a[1] * b[2] - a[2] * b[1];
      n[1] = a[2] * b[0] - a[0] * b[2];
      n[2] = a[0] * b[1] - a[1] * b[0];
    }
    PetscReal dot = 0;
    for (PetscInt d = 0; d < dim; ++d) dot += n[d] * (fc[d] - cc[d]);
    f.outward = dot >= 0 ? 1.0 : -1.0;
    f.Xref    = f.X;
    {
      PetscInt cStart;
      PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, NULL));
      f.body = elas.CellBody()[support[0] - cStart];
    }
    facets.push_back(f);
    points.push_back(p);
  }
  PetscCall(ISRestoreIndices(vnumIS, &vnum));
  PetscFunctionReturn(0);
}

PetscErrorCode ContactSurface::Update(const Elasticity &elas, Vec uloc)
{
  PetscSection lsec;

  PetscFunctionBeginUser;
  PetscCall(DMGetLocalSection(elas.dm, &lsec));
  for (size_t i = 0; i < facets.size(); ++i) {
    PetscScalar *vals = NULL;
    PetscInt     n;
    PetscCall(DMPlexVecGetClosure(elas.dm, lsec, uloc, points[i], &n, &vals));
    SurfaceFacet &f = facets[i];
    PetscCheck(n == f.nnodes * dim, PETSC_COMM_SELF, PETSC_ERR_PLIB, "closure size mismatch");
    for (PetscInt j = 0; j < n; ++j) {
      f.U[j] = PetscRealPart(vals[j]);
      f.Ubc[j] = f.dof[j] < 0 ? f.U[j] : 0.0;
    }
    PetscCall(DMPlexVecRestoreClosure(elas.dm, lsec, uloc, points[i], &n, &vals));
  }
  PetscFunctionReturn(0);
}

void ContactSurface::SetGeometry(const GeometryMap *map, const std::vector<PetscReal> &mu)
{
  for (auto &f : facets) {
    const Affine a = map ? map->Evaluate(f.body, mu) : Affine();
    for (PetscInt k = 0; k < f.nv; ++k) a.Apply(dim, &f.Xref[k * dim], &f.X[k * dim]);
  }
}

PetscErrorCode ContactSurface::Gather(MPI_Comm comm, std::vector<SurfaceFacet> *all) const
{
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  const int           bytes = (int)sizeof(SurfaceFacet);
  std::vector<int>    counts(size), displs(size);
  int                 mine = (int)(facets.size() * bytes);
  PetscCallMPI(MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm));
  long long total = 0;
  for (int r = 0; r < size; ++r) { displs[r] = (int)total; total += counts[r]; }
  PetscCheck(total < 2147483647LL, comm, PETSC_ERR_SUP, "Master surface too large to gather (%lld bytes)", total);
  all->resize(total / bytes);
  // SurfaceFacet is trivially copyable: gather raw bytes (homogeneous cluster assumed).
  PetscCallMPI(MPI_Allgatherv(facets.data(), mine, MPI_BYTE, all->data(), counts.data(), displs.data(), MPI_BYTE, comm));
  PetscFunctionReturn(0);
}

} // namespace rbc
