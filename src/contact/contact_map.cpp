// src/contact/contact_map.cpp: multiplier numbering on the slave vertices and the assembly of the
// linearized non-penetration constraint K(u) v <= g(u) (see docs/contact.md):
//   K_ij = - int_{Gamma_1^c} (phi_j|_1(z) - phi_j|_2(rho(z))) . n2(z) psi_i(z) dz,
//   g_i  =   int_{Gamma_1^c} (z - rho(z)) . n2(z) psi_i(z) dz  -  sum_{j constrained} K_ij u_D,j,
// rho(z) the closest point of the deformed master surface to the deformed slave point z + u_1(z),
// n2 the master's outward unit normal there (facet normal or interpolated nodal normals).
#include "rbcontact/contact.hpp"
#include "rbcontact/options_files.hpp"
#include "contact_point.hpp"
#include <petscsf.h>
#include <petscdt.h>
#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

namespace rbc {

ContactSystem::~ContactSystem() { (void)Destroy(); }

PetscErrorCode ContactSystem::Destroy()
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&K));
  PetscCall(VecDestroy(&g));
  PetscCall(VecDestroy(&weight));
  for (int d = 0; d < 3; ++d) {
    PetscCall(VecDestroy(&normal[d]));
    PetscCall(VecDestroy(&coord[d]));
    PetscCall(VecDestroy(&coordRef[d]));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode ContactMap::NumberMultipliers(const Elasticity &elas)
{
  DM       dm = elas.dm;
  PetscInt pStart, pEnd, vStart, vEnd;
  PetscSF  sf;
  MPI_Comm comm = PetscObjectComm((PetscObject)dm);

  PetscFunctionBeginUser;
  PetscCall(DMPlexGetChart(dm, &pStart, &pEnd));
  PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
  vStart_ = vStart;
  std::vector<PetscInt> flag(pEnd - pStart, 0), row(pEnd - pStart, -1);
  for (PetscInt p : slave_.points) {
    PetscInt *closure = NULL, ncl;
    PetscCall(DMPlexGetTransitiveClosure(dm, p, PETSC_TRUE, &ncl, &closure));
    for (PetscInt c = 0; c < ncl; ++c)
      if (closure[2 * c] >= vStart && closure[2 * c] < vEnd) flag[closure[2 * c] - pStart] = 1;
    PetscCall(DMPlexRestoreTransitiveClosure(dm, p, PETSC_TRUE, &ncl, &closure));
  }
  PetscCall(DMGetPointSF(dm, &sf));
  PetscInt        nroots, nleaves;
  const PetscInt *ilocal;
  PetscCall(PetscSFGetGraph(sf, &nroots, &nleaves, &ilocal, NULL));
  std::vector<char> isLeaf(pEnd - pStart, 0);
  if (nroots >= 0) {
    for (PetscInt l = 0; l < nleaves; ++l) isLeaf[(ilocal ? ilocal[l] : l) - pStart] = 1;
    PetscCall(PetscSFReduceBegin(sf, MPIU_INT, flag.data(), flag.data(), MPI_MAX));
    PetscCall(PetscSFReduceEnd(sf, MPIU_INT, flag.data(), flag.data(), MPI_MAX));
  }
  // Owned slave vertices, ordered by global vertex number
  IS              vnumIS;
  const PetscInt *vnum;
  PetscCall(DMPlexGetVertexNumbering(dm, &vnumIS));
  PetscCall(ISGetIndices(vnumIS, &vnum));
  std::vector<std::pair<PetscInt, PetscInt>> owned;
  for (PetscInt v = vStart; v < vEnd; ++v)
    if (flag[v - pStart] && !isLeaf[v - pStart]) owned.emplace_back(vnum[v - vStart], v);
  PetscCall(ISRestoreIndices(vnumIS, &vnum));
  std::sort(owned.begin(), owned.end());
  PetscInt nown = (PetscInt)owned.size();
  PetscCallMPI(MPI_Scan(&nown, &rEnd_, 1, MPIU_INT, MPI_SUM, comm));
  rStart_ = rEnd_ - nown;
  PetscCallMPI(MPI_Allreduce(&nown, &R_, 1, MPIU_INT, MPI_SUM, comm));
  for (PetscInt i = 0; i < nown; ++i) row[owned[i].second - pStart] = rStart_ + i;
  if (nroots >= 0) {
    PetscCall(PetscSFBcastBegin(sf, MPIU_INT, row.data(), row.data(), MPI_REPLACE));
    PetscCall(PetscSFBcastEnd(sf, MPIU_INT, row.data(), row.data(), MPI_REPLACE));
  }
  vertexRow_.assign(vEnd - vStart, -1);
  for (PetscInt v = vStart; v < vEnd; ++v) vertexRow_[v - vStart] = row[v - pStart];
  PetscFunctionReturn(0);
}

PetscErrorCode ContactMap::Setup(const Elasticity &elas, const std::string &slave, const std::string &master)
{
  MPI_Comm  comm = PetscObjectComm((PetscObject)elas.dm);
  char      quad[64] = "gauss", nrm[64] = "smooth", mult[64] = "dual", seg[64] = "pair";
  PetscBool flg;

  PetscFunctionBeginUser;
  PetscCall(CheckValuesGiven(comm, {"-contact_quadrature", "-contact_quadrature_points", "-contact_quadrature_subdivisions", "-contact_multiplier", "-contact_normal", "-contact_segment_search",
                                    "-contact_master_search", "-contact_master_search_margin", "-contact_compliance"})); // (the defaults, without a word)
  PetscOptionsBegin(comm, NULL, "Contact map: quadrature, normal, multipliers (docs/contact.md)", "ContactMap");
  PetscCall(PetscOptionsString("-contact_quadrature", "Slave quadrature: gauss (segment by segment), composite, nodal", "docs/contact.md", quad, quad, sizeof quad, NULL));
  if (!strcmp(quad, "gauss")) quadrature = ContactQuadrature::Gauss;
  else if (!strcmp(quad, "nodal")) quadrature = ContactQuadrature::Nodal;
  else if (!strcmp(quad, "composite")) quadrature = ContactQuadrature::Composite;
  else SETERRQ(comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-contact_quadrature: unknown value '%s' (gauss, composite or nodal)", quad);
  PetscCall(PetscOptionsInt("-contact_quadrature_subdivisions", "composite: pieces per slave facet", "docs/contact.md", nsub, &nsub, NULL));
  PetscCheck(nsub >= 1 && nsub <= 64, comm, PETSC_ERR_ARG_OUTOFRANGE, "-contact_quadrature_subdivisions %" PetscInt_FMT " out of range [1, 64]", nsub);
  PetscCall(PetscOptionsInt("-contact_quadrature_points", "Gauss points per segment (piece)", "docs/contact.md", nquad, &nquad, &flg));
  PetscCheck(nquad >= 1 && nquad <= 12, comm, PETSC_ERR_ARG_OUTOFRANGE, "-contact_quadrature_points %" PetscInt_FMT " out of range [1, 12]", nquad);
  PetscCall(PetscOptionsString("-contact_normal", "Master normal: smooth (averaged at the vertices) or facet", "docs/contact.md", nrm, nrm, sizeof nrm, NULL));
  if (!strcmp(nrm, "smooth")) smoothNormal = true;
  else if (!strcmp(nrm, "facet")) smoothNormal = false;
  else SETERRQ(comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-contact_normal: unknown value '%s' (smooth or facet)", nrm);
  PetscCall(PetscOptionsString("-contact_multiplier", "Multiplier space: dual (biorthogonal) or standard", "docs/contact.md", mult, mult, sizeof mult, NULL));
  if (!strcmp(mult, "dual")) multiplier = ContactMultiplier::Dual;
  else if (!strcmp(mult, "standard")) multiplier = ContactMultiplier::Standard;
  else SETERRQ(comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-contact_multiplier: unknown value '%s' (dual or standard)", mult);
  if (quadrature == ContactQuadrature::Nodal) multiplier = ContactMultiplier::Standard; // collocation: already diagonal
  // nodal collocation constrains and loads the slave vertices only: with P2 the mid-side nodes carry no contact force (the
  // flat punch 3.7 % low in force, exit 0; audit of 2026-12-01)
  PetscCheck(quadrature != ContactQuadrature::Nodal || elas.degree == 1, comm, PETSC_ERR_SUP, "-contact_quadrature nodal collocates at the slave vertices: with -fem_degree %" PetscInt_FMT " the mid-side nodes would carry no contact force (the flat-punch patch test fails by 4 %%); use -contact_quadrature gauss or composite", elas.degree);
  PetscCall(PetscOptionsString("-contact_segment_search", "Mortar segments: pair (bisection between neighbouring facets) or full", "docs/fom_speed.md", seg, seg, sizeof seg, NULL));
  if (!strcmp(seg, "pair")) segmentPairSearch = true;
  else if (!strcmp(seg, "full")) segmentPairSearch = false;
  else SETERRQ(comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-contact_segment_search: unknown value '%s' (pair or full)", seg);
  {
    char ms[16] = "all";
    PetscCall(PetscOptionsString("-contact_master_search", "Master facets held by each rank: all (gathered) or near (those near its slave facets)", "docs/contact.md", ms, ms, sizeof ms, NULL));
    if (!strcmp(ms, "all")) masterSearchNear = false;
    else if (!strcmp(ms, "near")) masterSearchNear = true;
    else SETERRQ(comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-contact_master_search: unknown value '%s' (all or near)", ms);
    PetscCall(PetscOptionsReal("-contact_master_search_margin", "near: the margin around the slave facets' bounding box (default automatic)", "docs/contact.md", masterSearchMargin, &masterSearchMargin, &flg));
    PetscCheck(!flg || (masterSearchMargin > 0 && std::isfinite(masterSearchMargin)), comm, PETSC_ERR_ARG_OUTOFRANGE, "-contact_master_search_margin %g must be > 0", (double)masterSearchMargin);
  }
  {
    char cm[32] = "auto"; // read by ElasticFOM and SurfaceCompliance (listed here for -help)
    PetscCall(PetscOptionsString("-contact_compliance", "Surface compliance (A^-1)_DD: auto, schur, inverse, redundant or solves", "docs/contact.md", cm, cm, sizeof cm, NULL));
  }
  PetscOptionsEnd();

  // (the same label on both sides: a Kacanov failure on 1 rank, "Dual QP: diagonal entry 2 of S ... is 0" on 2; both
  // sides on one body: converged, force 21 for 0.5, exit 0)
  PetscCheck(slave != master, comm, PETSC_ERR_USER_INPUT, "-contact_slave and -contact_master name the same group '%s': contact is between two surfaces of two bodies", slave.c_str());
  PetscCall(slave_.Build(elas, slave));
  PetscCall(master_.Build(elas, master));
  slaveName_  = slave;
  masterName_ = master;
  {
    PetscInt nb = 0;
    for (const auto *S : {&slave_, &master_})
      for (const auto &F : S->facets) nb = std::max(nb, F.body + 1);
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &nb, 1, MPIU_INT, MPI_MAX, comm));
    std::vector<PetscInt> on(2 * (size_t)nb, 0); // body b has facets on the slave (b) or on the master (nb + b)
    for (const auto &F : slave_.facets)
      if (F.body >= 0) on[F.body] = 1;
    for (const auto &F : master_.facets)
      if (F.body >= 0) on[nb + F.body] = 1;
    if (nb) PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, on.data(), (PetscMPIInt)on.size(), MPIU_INT, MPI_MAX, comm));
    for (PetscInt b = 0; b < nb; ++b)
      PetscCheck(!(on[b] && on[nb + b]), comm, PETSC_ERR_USER_INPUT, "-contact_slave '%s' and -contact_master '%s' both lie on body '%s': contact is between two bodies, the slave surface on one, the master on the other", slave.c_str(), master.c_str(),
                 b < (PetscInt)elas.scene.bodies.size() ? elas.scene.bodies[b].name.c_str() : std::to_string((long long)b).c_str());
  }
  PetscCall(NumberMultipliers(elas));
  for (size_t s = 0; s < slave_.facets.size(); ++s) {
    PetscInt *closure = NULL, ncl, k = 0;
    PetscCall(DMPlexGetTransitiveClosure(elas.dm, slave_.points[s], PETSC_TRUE, &ncl, &closure));
    for (PetscInt c = 0; c < ncl; ++c) {
      const PetscInt pt = closure[2 * c];
      if (pt >= vStart_ && pt < vStart_ + (PetscInt)vertexRow_.size() && k < elas.dim) slave_.facets[s].row[k++] = vertexRow_[pt - vStart_];
    }
    PetscCall(DMPlexRestoreTransitiveClosure(elas.dm, slave_.points[s], PETSC_TRUE, &ncl, &closure));
  }
  PetscCheck(R_ > 0, comm, PETSC_ERR_USER_INPUT, "Contact slave surface '%s' (-contact_slave) has no facets", slave.c_str());
  {
    PetscInt nm = (PetscInt)master_.facets.size();
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &nm, 1, MPIU_INT, MPI_SUM, comm));
    PetscCheck(nm > 0, comm, PETSC_ERR_USER_INPUT, "Contact master surface '%s' (-contact_master) has no facets", master.c_str());
  }
  PetscCall(FindSlaveEnds(elas, slave));
  // Reference facet rule in barycentric coordinates, weights normalized to sum 1.
  const PetscInt  fdim = elas.dim - 1;
  PetscQuadrature q;
  PetscInt        npts;
  const PetscReal *pts, *wts;
  PetscCall(PetscDTStroudConicalQuadrature(fdim, 1, nquad, -1.0, 1.0, &q));
  PetscCall(PetscQuadratureGetData(q, NULL, NULL, &npts, &pts, &wts));
  quadPoints_.clear();
  quadWeights_.clear();
  PetscReal wsum = 0;
  for (PetscInt i = 0; i < npts; ++i) wsum += wts[i];
  for (PetscInt i = 0; i < npts; ++i) {
    PetscReal b[3] = {0, 0, 0};
    if (fdim == 1) { b[1] = 0.5 * (pts[i] + 1); b[0] = 1 - b[1]; }
    else { b[1] = 0.5 * (pts[2 * i] + 1); b[2] = 0.5 * (pts[2 * i + 1] + 1); b[0] = 1 - b[1] - b[2]; }
    for (PetscInt k = 0; k <= fdim; ++k) quadPoints_.push_back(b[k]);
    quadWeights_.push_back(wts[i] / wsum);
  }
  PetscCall(PetscQuadratureDestroy(&q));
  PetscFunctionReturn(0);
}

void ContactMap::SetGeometry(const GeometryMap *map, const std::vector<PetscReal> &mu)
{
  slave_.SetGeometry(map, mu);
  master_.SetGeometry(map, mu);
}

PetscErrorCode ContactMap::SurfaceDofs(MPI_Comm comm, std::vector<PetscInt> *D) const
{
  std::vector<PetscInt> mine;
  PetscMPIInt           size;

  PetscFunctionBeginUser;
  for (const auto *surf : {&slave_, &master_})
    for (const auto &F : surf->facets)
      for (PetscInt i = 0; i < F.nnodes * surf->dim; ++i)
        if (F.dof[i] >= 0) mine.push_back(F.dof[i]);
  std::sort(mine.begin(), mine.end());
  mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
  PetscCallMPI(MPI_Comm_size(comm, &size));
  std::vector<int> counts(size), displs(size, 0);
  int              c = (int)mine.size();
  PetscCallMPI(MPI_Allgather(&c, 1, MPI_INT, counts.data(), 1, MPI_INT, comm));
  for (int r = 1; r < size; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  D->resize(displs[size - 1] + counts[size - 1]);
  PetscCallMPI(MPI_Allgatherv(mine.data(), c, MPIU_INT, D->data(), counts.data(), displs.data(), MPIU_INT, comm));
  std::sort(D->begin(), D->end());
  D->erase(std::unique(D->begin(), D->end()), D->end());
  PetscFunctionReturn(0);
}

PetscErrorCode ContactMap::FindSlaveEnds(const Elasticity &elas, const std::string &slave)
{
  DM                    dm   = elas.dm;
  MPI_Comm              comm = PetscObjectComm((PetscObject)dm);
  const PetscInt        dim  = elas.dim;
  std::vector<PetscInt> count(R_, 0); // 2D: slave facets per vertex row; 3D: 1 marks a row on the surface's boundary

  PetscFunctionBeginUser;
  endRows_.clear();
  endNext_.clear();
  if (dim == 2) {
    for (const auto &F : slave_.facets)
      for (PetscInt k = 0; k < F.nv; ++k)
        if (F.row[k] >= 0 && F.row[k] < R_) ++count[F.row[k]];
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, count.data(), (int)R_, MPIU_INT, MPI_SUM, comm));
  } else {
    // 3D (until 2026-12-01 none: a contact zone past the edge of a sphere's slave cap went without a word): the rows of
    // the vertices on an edge that one slave facet alone holds, over all ranks (edges keyed by their vertices' global
    // numbers: an edge between two ranks' facets is interior)
    std::vector<PetscInt> mine; // per facet edge: v0 < v1, row of v0, row of v1
    for (const auto &F : slave_.facets)
      for (PetscInt k = 0; k < 3; ++k) {
        const PetscInt a = k, b = (k + 1) % 3;
        const bool     sw = F.vglobal[a] > F.vglobal[b];
        mine.insert(mine.end(), {sw ? F.vglobal[b] : F.vglobal[a], sw ? F.vglobal[a] : F.vglobal[b], sw ? F.row[b] : F.row[a], sw ? F.row[a] : F.row[b]});
      }
    PetscMPIInt size;
    PetscCallMPI(MPI_Comm_size(comm, &size));
    std::vector<int> len((size_t)size), off((size_t)size + 1, 0);
    const int        m = (int)mine.size();
    PetscCallMPI(MPI_Allgather(&m, 1, MPI_INT, len.data(), 1, MPI_INT, comm));
    for (PetscMPIInt r = 0; r < size; ++r) off[r + 1] = off[r] + len[r];
    std::vector<PetscInt> all((size_t)off[size]);
    PetscCallMPI(MPI_Allgatherv(mine.data(), m, MPIU_INT, all.data(), len.data(), off.data(), MPIU_INT, comm));
    std::map<std::pair<PetscInt, PetscInt>, std::pair<PetscInt, std::array<PetscInt, 2>>> edges;
    for (size_t e = 0; e + 3 < all.size(); e += 4) {
      auto &x = edges[{all[e], all[e + 1]}];
      ++x.first;
      x.second = {all[e + 2], all[e + 3]};
    }
    for (const auto &x : edges)
      if (x.second.first == 1)
        for (PetscInt r : x.second.second)
          if (r >= 0 && r < R_) count[r] = 1;
    for (auto &c : count)
      if (c != 1) c = 0;
  }
  // the boundary facets (not slave) at each end vertex: their outward normals, from their cells' centroids, summed
  // (each boundary facet is on the one rank of its cell)
  DMLabel                bd, sl;
  PetscInt               vStart, vEnd, fStart, fEnd;
  std::vector<PetscReal> next(3 * (size_t)R_, 0.0);
  PetscCall(DMLabelCreate(PETSC_COMM_SELF, "rbc_true_boundary", &bd));
  PetscCall(DMPlexMarkBoundaryFaces(dm, 1, bd));
  PetscCall(DMGetLabel(dm, slave.c_str(), &sl));
  PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
  PetscCall(DMPlexGetHeightStratum(dm, 1, &fStart, &fEnd));
  for (PetscInt v = vStart; v < vEnd; ++v) {
    const PetscInt r = vertexRow_[v - vStart];
    if (r < 0 || count[r] != 1) continue;
    PetscInt *star = NULL, nstar;
    PetscCall(DMPlexGetTransitiveClosure(dm, v, PETSC_FALSE, &nstar, &star)); // the vertex's star: 2D edges, 3D faces among it
    for (PetscInt k = 0; k < nstar; ++k) {
      const PetscInt f = star[2 * k];
      if (f < fStart || f >= fEnd) continue;
      PetscInt isBd, isSlave = -1;
      PetscCall(DMLabelGetValue(bd, f, &isBd));
      if (sl) PetscCall(DMLabelGetValue(sl, f, &isSlave));
      if (isBd != 1 || isSlave >= 0) continue;
      const PetscInt *cells;
      PetscReal       cent[3], fc[3], nrm[3];
      PetscCall(DMPlexGetSupport(dm, f, &cells));
      PetscCall(DMPlexComputeCellGeometryFVM(dm, cells[0], NULL, cent, NULL));
      PetscCall(DMPlexComputeCellGeometryFVM(dm, f, NULL, fc, nrm)); // the facet's centroid and a normal
      PetscReal len = 0, side = 0;
      for (PetscInt d = 0; d < dim; ++d) {
        len += nrm[d] * nrm[d];
        side += nrm[d] * (fc[d] - cent[d]);
      }
      len = std::sqrt(len);
      if (len > 0)
        for (PetscInt d = 0; d < dim; ++d) next[3 * r + d] += (side < 0 ? -1 : 1) * nrm[d] / len;
    }
    PetscCall(DMPlexRestoreTransitiveClosure(dm, v, PETSC_FALSE, &nstar, &star));
  }
  PetscCall(DMLabelDestroy(&bd));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, next.data(), (int)next.size(), MPIU_REAL, MPI_SUM, comm));
  for (PetscInt r = 0; r < R_; ++r)
    if (count[r] == 1) {
      const PetscReal n = std::sqrt(next[3 * r] * next[3 * r] + next[3 * r + 1] * next[3 * r + 1] + next[3 * r + 2] * next[3 * r + 2]);
      endRows_.push_back(r);
      endNext_.push_back({n > 0 ? next[3 * r] / n : 0.0, n > 0 ? next[3 * r + 1] / n : 0.0, n > 0 ? next[3 * r + 2] / n : 0.0});
    }
  PetscFunctionReturn(0);
}

// Deformed position of the slave point at barycentric b.
static void SlavePoint(const SurfaceFacet &F, PetscInt dim, const PetscReal b[], PetscReal zdef[])
{
  PetscReal Ns[6];
  FacetBasis(F, b, Ns);
  for (PetscInt d = 0; d < dim; ++d) {
    zdef[d] = 0;
    for (PetscInt k = 0; k < F.nv; ++k) zdef[d] += b[k] * F.X[k * dim + d];
    for (PetscInt a = 0; a < F.nnodes; ++a) zdef[d] += Ns[a] * F.U[a * dim + d];
  }
}

// 3D segment-based integration (ClipFacet3). The slave triangle's deformed vertices span a plane with
// orthonormal axes (e1, e2); every master triangle near it is projected onto that plane along its normal and
// clipped against the slave triangle (Sutherland-Hodgman: both convex); each clipped polygon is split into a
// fan of triangles and the facet rule (quadPoints_, quadWeights_) is applied on each. Where the master is
// planar over a cell the integrand is polynomial there, so the rule is exact: a flat punch on non-matching
// meshes transmits a uniform pressure (tests/contact_checks.py flat_punch3d).
bool ContactMap::ClipFacet3(const SurfaceFacet &F, const ClosestPoint &cp, PetscReal meas, std::vector<std::array<PetscReal, 4>> *ipts, std::vector<PetscInt> *candOut, PetscReal *reach) const
{
  using P2 = std::array<PetscReal, 2>;
  PetscReal Z[3][3], e1[3], e2[3], n[3];
  for (PetscInt k = 0; k < 3; ++k) {
    const PetscReal b[3] = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0};
    SlavePoint(F, 3, b, Z[k]);
  }
  const PetscReal a[3] = {Z[1][0] - Z[0][0], Z[1][1] - Z[0][1], Z[1][2] - Z[0][2]};
  FacetNormal(&Z[0][0], 3, 1.0, n); // (Z1 - Z0) x (Z2 - Z0) / 2
  const PetscReal la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), ln = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  candOut->clear();
  *reach = 0;
  if (!(la > 0 && ln > 0)) return false;
  for (PetscInt d = 0; d < 3; ++d) {
    e1[d] = a[d] / la;
    n[d] /= ln;
  }
  e2[0] = n[1] * e1[2] - n[2] * e1[1];
  e2[1] = n[2] * e1[0] - n[0] * e1[2];
  e2[2] = n[0] * e1[1] - n[1] * e1[0];
  auto to2 = [&](const PetscReal *x) { const PetscReal r[3] = {x[0] - Z[0][0], x[1] - Z[0][1], x[2] - Z[0][2]}; return P2{r[0] * e1[0] + r[1] * e1[1] + r[2] * e1[2], r[0] * e2[0] + r[1] * e2[1] + r[2] * e2[2]}; };
  const P2        S[3] = {to2(Z[0]), to2(Z[1]), to2(Z[2])};
  const PetscReal area = 0.5 * ((S[1][0] - S[0][0]) * (S[2][1] - S[0][1]) - (S[2][0] - S[0][0]) * (S[1][1] - S[0][1])); // > 0 by construction
  PetscReal       diam = 0, zmin[3], zmax[3];
  for (PetscInt d = 0; d < 3; ++d) {
    zmin[d] = std::min({Z[0][d], Z[1][d], Z[2][d]});
    zmax[d] = std::max({Z[0][d], Z[1][d], Z[2][d]});
    diam    = std::max(diam, zmax[d] - zmin[d]);
  }
  // slave barycentric coordinates of a point of the plane
  auto bary = [&](const P2 &x, PetscReal b[3]) {
    b[1] = 0.5 * ((x[0] - S[0][0]) * (S[2][1] - S[0][1]) - (S[2][0] - S[0][0]) * (x[1] - S[0][1])) / area;
    b[2] = 0.5 * ((S[1][0] - S[0][0]) * (x[1] - S[0][1]) - (x[0] - S[0][0]) * (S[1][1] - S[0][1])) / area;
    b[0] = 1 - b[1] - b[2];
  };
  PetscReal covered = 0;
  std::vector<std::array<PetscReal, 4>> out;
  std::vector<PetscInt> &cand = *candOut;
  {
    const PetscReal lo[3] = {zmin[0] - diam, zmin[1] - diam, zmin[2] - diam}, hi[3] = {zmax[0] + diam, zmax[1] + diam, zmax[2] + diam};
    cp.Candidates(lo, hi, &cand); // the bins of the closest-point search (Build)
    *reach = diam;                // a facet within diam of a point of F meets the box: it is a candidate
  }
  for (PetscInt m : cand) {
    const PetscReal *y = cp.Vertices(m);
    // near the slave triangle: bounding boxes within one slave diameter
    bool near = true;
    for (PetscInt d = 0; d < 3 && near; ++d) {
      const PetscReal lo = std::min({y[d], y[3 + d], y[6 + d]}), hi = std::max({y[d], y[3 + d], y[6 + d]});
      near = hi >= zmin[d] - diam && lo <= zmax[d] + diam;
    }
    if (!near) continue;
    // the master triangle projected onto the slave plane, counter-clockwise
    std::vector<P2> clip = {to2(y), to2(y + 3), to2(y + 6)};
    const PetscReal ma = (clip[1][0] - clip[0][0]) * (clip[2][1] - clip[0][1]) - (clip[2][0] - clip[0][0]) * (clip[1][1] - clip[0][1]);
    if (std::abs(ma) <= 1e-14 * area) continue; // seen edge-on
    if (ma < 0) std::swap(clip[1], clip[2]);
    std::vector<P2> poly(S, S + 3);
    for (PetscInt e = 0; e < 3 && !poly.empty(); ++e) {
      const P2 &p0 = clip[e], &p1 = clip[(e + 1) % 3];
      auto side = [&](const P2 &q) { return (p1[0] - p0[0]) * (q[1] - p0[1]) - (p1[1] - p0[1]) * (q[0] - p0[0]); };
      std::vector<P2> next;
      for (size_t i = 0; i < poly.size(); ++i) {
        const P2 &u = poly[i], &v = poly[(i + 1) % poly.size()];
        const PetscReal su = side(u), sv = side(v);
        if (su >= 0) next.push_back(u);
        if ((su >= 0) != (sv >= 0)) {
          const PetscReal t = su / (su - sv);
          next.push_back({u[0] + t * (v[0] - u[0]), u[1] + t * (v[1] - u[1])});
        }
      }
      poly.swap(next);
    }
    if (poly.size() < 3) continue;
    for (size_t i = 1; i + 1 < poly.size(); ++i) { // fan from poly[0]
      const P2       &A = poly[0], &B = poly[i], &C = poly[i + 1];
      const PetscReal ar = 0.5 * ((B[0] - A[0]) * (C[1] - A[1]) - (C[0] - A[0]) * (B[1] - A[1]));
      if (!(ar > 1e-14 * area)) continue;
      covered += ar;
      for (size_t qp = 0; qp < quadWeights_.size(); ++qp) {
        const PetscReal *l = &quadPoints_[qp * 3];
        const P2         x = {l[0] * A[0] + l[1] * B[0] + l[2] * C[0], l[0] * A[1] + l[1] * B[1] + l[2] * C[1]};
        PetscReal        b[3];
        bary(x, b);
        out.push_back({b[0], b[1], b[2], quadWeights_[qp] * meas * ar / area});
      }
    }
  }
  // the master's projections overlap only on sets of zero area (a conforming facet soup): covered = area
  // within rounding; anything else (the end of the master, a gap or an overlap of the projections) keeps the plain rule
  if (std::abs(covered - area) > 1e-10 * area) return false;
  ipts->insert(ipts->end(), out.begin(), out.end());
  return true;
}

// 2D: pieces [s0, s1] of the slave segment (parameter t, b = (1 - t, t)) on which the closest master
// facet does not change; the switch points are located by bisection to 1e-13. Where the closest facet is
// ma at one end of an interval and mb at the other and the two are neighbours on the master (a common
// vertex), the bisection compares those two facets only (two squared distances per step, the search's tie
// rule: the lower index wins) and the closest-point search at the switch and at the middle of each of the
// two pieces confirms that no third facet is closest in between; otherwise (facets that are not
// neighbours: a facet between them may be closest somewhere) the interval is bisected with the search.
// The cuts are then those of the bisection with the full search at every step (the only method before
// 2026-11-25, ~45 searches per switch: 90 % of the contact assembly; -contact_segment_search full):
// tests/contact_checks.py segments, docs/fom_speed.md.
void ContactMap::SegmentFacet(const SurfaceFacet &F, const ClosestPoint &cp, std::vector<std::pair<PetscReal, PetscReal>> *segs) const
{
  auto pointAt = [&](PetscReal t, PetscReal z[3]) {
    const PetscReal b[3] = {1 - t, t, 0};
    SlavePoint(F, 2, b, z);
  };
  auto facetAt = [&](PetscReal t) {
    PetscReal z[3], bm[3], dist;
    PetscInt  m;
    pointAt(t, z);
    cp.Find(z, &m, bm, &dist);
    return m;
  };
  segs->clear();
  std::vector<std::array<PetscReal, 4>> stack = {{0.0, 1.0, (PetscReal)facetAt(0.0), (PetscReal)facetAt(1.0)}};
  std::vector<PetscReal>                cuts  = {0.0, 1.0};
  while (!stack.empty()) {
    const auto iv = stack.back();
    stack.pop_back();
    if (iv[2] == iv[3] || iv[1] - iv[0] < 1e-13) {
      if (iv[2] != iv[3]) cuts.push_back(0.5 * (iv[0] + iv[1]));
      continue;
    }
    const PetscInt      ma = (PetscInt)iv[2], mb = (PetscInt)iv[3];
    const SurfaceFacet &Fa = masterAll_[ma], &Fb = masterAll_[mb];
    const bool adjacent = Fa.vglobal[0] == Fb.vglobal[0] || Fa.vglobal[0] == Fb.vglobal[1] || Fa.vglobal[1] == Fb.vglobal[0] || Fa.vglobal[1] == Fb.vglobal[1];
    if (segmentPairSearch && adjacent) { // the switch between the two end facets, found among them only, then confirmed by the search
      const PetscInt two[2] = {std::min(ma, mb), std::max(ma, mb)};
      PetscReal      a = iv[0], b = iv[1];
      while (b - a >= 1e-13) {
        const PetscReal tm = 0.5 * (a + b);
        PetscReal       z[3], bm[3], dist;
        PetscInt        m;
        pointAt(tm, z);
        cp.FindAmong(z, two, 2, &m, bm, &dist);
        if (m == ma) a = tm;
        else b = tm;
      }
      const PetscReal t = 0.5 * (a + b);
      const PetscInt mt = facetAt(t);
      if ((mt == ma || mt == mb) && facetAt(0.5 * (iv[0] + t)) == ma && facetAt(0.5 * (t + iv[1])) == mb) {
        cuts.push_back(t);
        continue;
      }
    }
    const PetscReal tm = 0.5 * (iv[0] + iv[1]);
    const PetscReal mm = (PetscReal)facetAt(tm);
    stack.push_back({iv[0], tm, iv[2], mm});
    stack.push_back({tm, iv[1], mm, iv[3]});
  }
  std::sort(cuts.begin(), cuts.end());
  for (size_t i = 0; i + 1 < cuts.size(); ++i)
    if (cuts[i + 1] > cuts[i]) segs->emplace_back(cuts[i], cuts[i + 1]);
}

// An empty bounding box (lo > hi in every direction).
static void EmptyBox(PetscReal lo[3], PetscReal hi[3])
{
  for (PetscInt d = 0; d < 3; ++d) {
    lo[d] = PETSC_MAX_REAL;
    hi[d] = -PETSC_MAX_REAL;
  }
}

// The deformed vertices' bounding box of a facet (the geometry of the closest-point search) and its diagonal.
static PetscReal FacetBox(const SurfaceFacet &F, PetscInt dim, PetscReal lo[3], PetscReal hi[3])
{
  EmptyBox(lo, hi);
  for (PetscInt k = 0; k < F.nv; ++k) {
    PetscInt node = -1;
    for (PetscInt i = 0; i < F.nnodes; ++i)
      if (F.nodeKind[i] == k) node = i;
    for (PetscInt d = 0; d < dim; ++d) {
      const PetscReal x = F.X[k * dim + d] + (node >= 0 ? F.U[node * dim + d] : 0.0);
      lo[d]             = std::min(lo[d], x);
      hi[d]             = std::max(hi[d], x);
    }
  }
  PetscReal diag = 0;
  for (PetscInt d = 0; d < dim; ++d) diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
  return std::sqrt(diag);
}

PetscErrorCode ContactMap::GatherNearMaster(MPI_Comm comm, PetscReal *margin, PetscReal *reach)
{
  const PetscInt dim = slave_.facets.empty() ? (master_.facets.empty() ? 2 : master_.facets[0].nv) : slave_.facets[0].nv;
  PetscMPIInt    size;
  PetscReal      box[6], lo[3], hi[3], h[2] = {0, 0};

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  // this rank's slave box (empty: lo > hi), the largest facet diameters
  EmptyBox(box, box + 3);
  for (const auto &F : slave_.facets) {
    h[0] = std::max(h[0], FacetBox(F, dim, lo, hi));
    for (PetscInt d = 0; d < dim; ++d) {
      box[d]     = std::min(box[d], lo[d]);
      box[3 + d] = std::max(box[3 + d], hi[d]);
    }
  }
  for (const auto &F : master_.facets) h[1] = std::max(h[1], FacetBox(F, dim, lo, hi));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, h, 2, MPIU_REAL, MPI_MAX, comm));
  { // the least reach of a slave point (at distance 0: 2 slave + 3 master facet diameters, Assemble's test)
    PetscReal hmin[2] = {PETSC_MAX_REAL, PETSC_MAX_REAL};
    for (const auto &F : slave_.facets) hmin[0] = std::min(hmin[0], FacetBox(F, dim, lo, hi));
    for (const auto &F : master_.facets) hmin[1] = std::min(hmin[1], FacetBox(F, dim, lo, hi));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, hmin, 2, MPIU_REAL, MPI_MIN, comm));
    *reach = hmin[0] < PETSC_MAX_REAL && hmin[1] < PETSC_MAX_REAL ? 2 * hmin[0] + 3 * hmin[1] : 0;
  }
  std::vector<PetscReal> boxes(6 * size);
  PetscCallMPI(MPI_Allgather(box, 6, MPIU_REAL, boxes.data(), 6, MPIU_REAL, comm));
  PetscReal diag = 0;
  {
    PetscReal all[6];
    EmptyBox(all, all + 3);
    for (PetscMPIInt r = 0; r < size; ++r)
      for (PetscInt d = 0; d < dim; ++d) {
        all[d]     = std::min(all[d], boxes[6 * r + d]);
        all[3 + d] = std::max(all[3 + d], boxes[6 * r + 3 + d]);
      }
    for (PetscInt d = 0; d < dim; ++d)
      if (all[3 + d] >= all[d]) diag += (all[3 + d] - all[d]) * (all[3 + d] - all[d]);
    diag = std::sqrt(diag);
  }
  *margin = masterSearchMargin > 0 ? masterSearchMargin : 0.5 * diag + 4 * h[1] + 2 * h[0];
  if (*margin < *reach) { // no slave point can be within reach: Assemble uses every master facet (nothing to exchange)
    masterAll_.clear();
    PetscFunctionReturn(0);
  }
  // each local master facet to every rank whose grown slave box it meets
  const int                      bytes = (int)sizeof(SurfaceFacet);
  std::vector<std::vector<char>> out(size);
  for (const auto &F : master_.facets) {
    FacetBox(F, dim, lo, hi);
    for (PetscMPIInt r = 0; r < size; ++r) {
      bool meets = boxes[6 * r] <= boxes[6 * r + 3]; // a rank without slave facets needs none
      for (PetscInt d = 0; d < dim && meets; ++d) meets = lo[d] <= boxes[6 * r + 3 + d] + *margin && hi[d] >= boxes[6 * r + d] - *margin;
      if (meets) out[r].insert(out[r].end(), reinterpret_cast<const char *>(&F), reinterpret_cast<const char *>(&F) + bytes);
    }
  }
  std::vector<int> scount(size), rcount(size), sdispl(size), rdispl(size);
  long long        stot = 0, rtot = 0;
  for (PetscMPIInt r = 0; r < size; ++r) {
    scount[r] = (int)out[r].size();
    sdispl[r] = (int)stot;
    stot += scount[r];
  }
  PetscCheck(stot < 2147483647LL, comm, PETSC_ERR_SUP, "Master surface too large to exchange (%lld bytes)", stot);
  PetscCallMPI(MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, comm));
  for (PetscMPIInt r = 0; r < size; ++r) {
    rdispl[r] = (int)rtot;
    rtot += rcount[r];
  }
  PetscCheck(rtot < 2147483647LL, comm, PETSC_ERR_SUP, "Master surface too large to exchange (%lld bytes)", rtot);
  std::vector<char> sbuf(stot);
  for (PetscMPIInt r = 0; r < size; ++r) std::copy(out[r].begin(), out[r].end(), sbuf.begin() + sdispl[r]);
  masterAll_.resize(rtot / bytes);
  // SurfaceFacet is trivially copyable: raw bytes, as Gather (homogeneous cluster assumed)
  PetscCallMPI(MPI_Alltoallv(sbuf.data(), scount.data(), sdispl.data(), MPI_BYTE, masterAll_.data(), rcount.data(), rdispl.data(), MPI_BYTE, comm));
  PetscFunctionReturn(0);
}

// Per-row sums of one contact assembly on every global row of the multipliers (R is small: the slave nodes), with
// the rows touched in the order first touched
struct RowAccumulator {
  std::vector<PetscScalar> weight, g, normal[3], coord[3], coordRef[3];
  std::vector<PetscInt>    rows, coordRows;
  std::vector<char>        seen, seenCoord;
  RowAccumulator(PetscInt R, PetscInt dim) : weight(R, 0.0), g(R, 0.0), seen(R, 0), seenCoord(R, 0)
  {
    for (PetscInt d = 0; d < dim; ++d) {
      normal[d].assign(R, 0.0);
      coord[d].assign(R, 0.0);
      coordRef[d].assign(R, 0.0);
    }
  }
  void Touch(PetscInt r)
  {
    if (!seen[r]) {
      seen[r] = 1;
      rows.push_back(r);
    }
  }
  void TouchCoord(PetscInt r)
  {
    if (!seenCoord[r]) {
      seenCoord[r] = 1;
      coordRows.push_back(r);
    }
  }
};

PetscErrorCode ContactMap::Assemble(const Elasticity &elas, Vec uloc, ContactSystem *sys)
{
  MPI_Comm       comm = PetscObjectComm((PetscObject)elas.dm);
  const PetscInt dim  = elas.dim, nv = dim;
  PetscInt       nlocal, N;

  PetscFunctionBeginUser;
  PetscCall(sys->Destroy());
  sys->R = R_;
  {
    Vec gv;
    PetscCall(DMGetGlobalVector(elas.dm, &gv));
    PetscCall(VecGetLocalSize(gv, &nlocal));
    PetscCall(VecGetSize(gv, &N));
    PetscCall(DMRestoreGlobalVector(elas.dm, &gv));
  }
  PetscCall(VecCreateMPI(comm, rEnd_ - rStart_, R_, &sys->g));
  PetscCall(VecDuplicate(sys->g, &sys->weight));
  for (PetscInt d = 0; d < dim; ++d) {
    PetscCall(VecDuplicate(sys->g, &sys->normal[d]));
    PetscCall(VecDuplicate(sys->g, &sys->coord[d]));
    PetscCall(VecDuplicate(sys->g, &sys->coordRef[d]));
  }
  PetscCall(VecSet(sys->g, 0.0));
  PetscCall(VecSet(sys->weight, 0.0));

  // Current displacement on both surfaces; the master is gathered on every rank.
  PetscCall(slave_.Update(elas, uloc));
  PetscCall(master_.Update(elas, uloc));
  { // a non-finite displacement would send the closest-point search out of its bins: refuse it here
    PetscInt bad = 0;
    for (const auto *surf : {&slave_, &master_})
      for (const auto &F : surf->facets)
      {
        for (PetscInt i = 0; i < F.nnodes * dim; ++i) bad |= !std::isfinite(F.U[i]);
        for (PetscInt i = 0; i < F.nv * dim; ++i) bad |= !std::isfinite(F.X[i]);
      }
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_MAX, comm));
    PetscCheck(!bad, comm, PETSC_ERR_FP, "contact: the displacement or the geometry of the contact surfaces holds non-finite values (a NaN in the data, or a singular elastic solve): the contact map cannot be evaluated");
  }
  ClosestPoint cp;
  ++searchStats_.assemblies;
  // near (docs/contact.md "Parallel"): a point within reach of the margin (below, per point) sees the answer of
  // all; a point beyond is out of reach: its K entries come from the closest facet held and its gap is its distance
  // to the master (an inactive constraint, as in all); a rank with slave facets and no master facet, or a point out
  // of reach at less than half the margin (large facets there), makes every rank assemble again with all; so does a
  // margin below the least reach of a point (2 slave + 3 master facet diameters): no point could be within reach, and
  // those in contact were out of reach with their gap taken as their distance to the facets held, not to the master
  // (a margin of 1e-7 on ring_on_block: contact lost, the Kacanov iterates cycled; until 2026-12-02)
  PetscReal searchMargin = PETSC_MAX_REAL; // near: the margin in use (PETSC_MAX_REAL: every master facet held)
  PetscInt  farPoints = 0, nearFar = 0;
  if (masterSearchNear) {
    PetscReal reach = 0;
    PetscCall(GatherNearMaster(comm, &searchMargin, &reach));
    searchStats_.reach = reach;
    const bool below = searchMargin < reach; // (the same on every rank)
    PetscInt   bad   = below || (masterAll_.empty() && !slave_.facets.empty());
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_MAX, comm));
    if (!bad) PetscCall(cp.Build(masterAll_, dim, true));
    else {
      searchStats_.belowReach += below ? 1 : 0;
      ++searchStats_.fallbacks;
      searchMargin = PETSC_MAX_REAL;
      PetscCall(master_.Gather(comm, &masterAll_));
      PetscCall(cp.Build(masterAll_, dim, true));
    }
  } else {
    PetscCall(master_.Gather(comm, &masterAll_));
    PetscCall(cp.Build(masterAll_, dim, true));
  }
  {
    PetscInt held = (PetscInt)masterAll_.size(), total = (PetscInt)master_.facets.size();
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &held, 1, MPIU_INT, MPI_MAX, comm));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPIU_INT, MPI_SUM, comm));
    searchStats_.held  = held;
    searchStats_.total = total;
  }
  // Nodal normals of the deformed master (area-weighted facet normals)
  std::unordered_map<PetscInt, std::array<PetscReal, 3>> vnormal;
  if (smoothNormal) {
    for (PetscInt m = 0; m < (PetscInt)masterAll_.size(); ++m) {
      PetscReal n[3];
      FacetNormal(cp.Vertices(m), dim, masterAll_[m].outward, n);
      for (PetscInt k = 0; k < nv; ++k) {
        auto &a = vnormal[masterAll_[m].vglobal[k]];
        for (PetscInt d = 0; d < 3; ++d) a[d] += n[d];
      }
    }
    for (auto &kv : vnormal) NormalizeVertexNormal(kv.second.data()); // unit, once per vertex (EvaluateContactPoint)
  }

  // 2D: the vertices that end the master surface (in one master facet only)
  std::unordered_map<PetscInt, PetscInt> vcount;
  if (dim == 2)
    for (const auto &M : masterAll_)
      for (PetscInt k = 0; k < nv; ++k) ++vcount[M.vglobal[k]];
  pastMasterEnd_.clear();
  points_.clear();

  std::vector<PetscInt>    near3, kRow, kCol, kPtr(1, 0);
  std::vector<PetscScalar> kVal;
  // the row vectors accumulated here by global row and set once at the end (one VecSetValue per contribution was 13 %
  // of the contact assembly on hertz3d, 2026-11-26): weight, normal, g (added), coordinates (inserted)
  RowAccumulator           acc(R_, dim);
  kRow.reserve(kReserve_[0]);
  kCol.reserve(kReserve_[1]);
  kVal.reserve(kReserve_[1]);
  // a slave facet's contributions to its rows summed first, over its integration points (one piece per facet and row
  // instead of one per integration point and row: 3D clipping gives tens of points a facet, and the buffered pieces
  // were tens of MB per assembly on hertz3d, 2026-11-26); slot marks a column's place in the facet's list fCol, fVal
  // and fHit hold [column][row of the facet]
  std::vector<PetscInt>    slot((size_t)N, -1), fCol;
  std::vector<PetscScalar> fVal;
  std::vector<char>        fHit;
  bool                     rowHit[3];
  PetscReal                reach3 = 0;
  const PetscInt           nq = (PetscInt)quadWeights_.size();
  for (size_t s = 0; s < slave_.facets.size(); ++s) {
    const SurfaceFacet &F    = slave_.facets[s];
    const PetscReal     meas = FacetMeasure(F.X.data(), dim);
    const PetscInt     *rows = F.row.data();
    // Integration points of this slave facet (barycentric b, weight w)
    std::vector<std::array<PetscReal, 4>> ipts;
    near3.clear();
    reach3 = 0;
    if (quadrature == ContactQuadrature::Nodal) {
      for (PetscInt k = 0; k < nv; ++k) {
        std::array<PetscReal, 4> q = {0, 0, 0, meas / nv}; // weight: int psi_k over this facet
        q[k] = 1.0;
        ipts.push_back(q);
      }
    } else if (quadrature == ContactQuadrature::Composite && dim == 2) {
      // Fixed composite rule (nsub equal pieces, Gauss on each): the points do not depend on u (the
      // rule the reduced model's empirical interpolation uses, docs/eim.md).
      for (PetscInt k = 0; k < nsub; ++k)
        for (PetscInt qp = 0; qp < (PetscInt)quadWeights_.size(); ++qp) {
          const PetscReal t = (k + quadPoints_[qp * nv + 1]) / nsub;
          ipts.push_back({1 - t, t, 0, quadWeights_[qp] * meas / nsub});
        }
    } else if (dim == 2 && quadrature == ContactQuadrature::Gauss) {
      // Segment-based (mortar) integration: split [0, 1] where the projection changes master facet,
      // so that every piece sees one smooth master facet; Gauss on each piece.
      std::vector<std::pair<PetscReal, PetscReal>> segs;
      SegmentFacet(F, cp, &segs);
      for (const auto &sg : segs)
        for (PetscInt qp = 0; qp < (PetscInt)quadWeights_.size(); ++qp) {
          const PetscReal t = sg.first + (sg.second - sg.first) * quadPoints_[qp * nv + 1];
          ipts.push_back({1 - t, t, 0, quadWeights_[qp] * meas * (sg.second - sg.first)});
        }
    } else if (dim == 3 && quadrature == ContactQuadrature::Gauss && ClipFacet3(F, cp, meas, &ipts, &near3, &reach3)) {
      // segment-based: the slave triangle clipped against the projected master triangles (ClipFacet3)
    } else {
      for (PetscInt qp = 0; qp < nq; ++qp) ipts.push_back({quadPoints_[qp * nv], quadPoints_[qp * nv + 1], quadPoints_[qp * nv + 2], quadWeights_[qp] * meas});
    }
    for (PetscInt k = 0; k < nv; ++k) rowHit[k] = false;
    for (const auto &ip : ipts) {
      const PetscReal  b[3] = {ip[0], ip[1], ip[2]}, w = ip[3];
      ContactPointEval e;
      PetscReal        found = 0; // the distance to the closest master facet held
      EvaluateContactPoint(
        F, dim, b, masterAll_, cp.Vertices(0), smoothNormal,
        [&](const PetscReal *p, PetscInt *m, PetscReal *bm, PetscReal *dist) {
          // 3D clipped facets: the closest point among the facets near F is the global one when it lies within
          // their reach (a closer facet would be among them); else the bin search
          if (!near3.empty()) {
            cp.FindAmong(p, near3.data(), (PetscInt)near3.size(), m, bm, dist);
            if (*m >= 0 && *dist < reach3) {
              found = *dist;
              return;
            }
          }
          cp.Find(p, m, bm, dist);
          found = *dist;
        },
        [&](const SurfaceFacet &M, PetscInt k) { return vnormal[M.vglobal[k]].data(); }, &e);
      {
        IntegrationPoint P;
        P.s = (PetscInt)s;
        P.m = e.m;
        P.w = w;
        for (PetscInt k = 0; k < 3; ++k) {
          P.b[k]  = b[k];
          P.bm[k] = e.bm[k];
        }
        points_.push_back(P);
      }
      const SurfaceFacet &M = masterAll_[e.m];
      const PetscReal    *Ns = e.Ns, *Nm = e.Nm, *n2 = e.n2;
      // -contact_master_search near: within reach when the found facet f, the facets around its vertices (within
      // found + diam f) and the 3D clipping's neighbours (within found + diam F + diam f) are surely held
      bool far = false;
      if (searchMargin < PETSC_MAX_REAL) {
        PetscReal lo[3], hi[3];
        far = found + 2 * FacetBox(F, dim, lo, hi) + 3 * FacetBox(M, dim, lo, hi) > searchMargin;
        nearFar += far && found < 0.5 * searchMargin; // out of reach by its facets' size, not its distance
      }
      const PetscReal gap = far ? found : e.gap;
      farPoints += far;
      if (dim == 2 && !far)
        for (PetscInt k = 0; k < 2; ++k)
          if (e.bm[k] == 1.0 && vcount[M.vglobal[k]] == 1) {
            // clamped to an end vertex: past the end when the slave point lies beyond it along the facet
            const PetscReal *xm = cp.Vertices(e.m), *xe = xm + 2 * k, *xo = xm + 2 * (1 - k);
            PetscReal        z[3], t[2] = {xe[0] - xo[0], xe[1] - xo[1]};
            SlavePoint(F, dim, b, z);
            const PetscReal len = std::sqrt(t[0] * t[0] + t[1] * t[1]);
            if (len > 0 && ((z[0] - xe[0]) * t[0] + (z[1] - xe[1]) * t[1]) / len > 1e-6 * len)
              for (PetscInt j = 0; j < nv; ++j)
                if (b[j] != 0.0) pastMasterEnd_.push_back(rows[j]);
          }
      for (PetscInt k = 0; k < nv; ++k) {
        const PetscReal psi = MultiplierShape(multiplier, nv, b, k);
        const PetscInt  r   = rows[k];
        if (b[k] != 0.0) { // weight and mean normal with the (positive) hat b_k: int psi_i = int b_i for both multipliers
          acc.Touch(r);
          acc.weight[r] += w * b[k];
          for (PetscInt d = 0; d < dim; ++d) acc.normal[d][r] += w * b[k] * n2[d];
        }
        if (psi == 0.0) continue;
        PetscScalar gk  = w * psi * gap;
        auto        add = [&](PetscInt col, PetscScalar v) {
          PetscInt &sl = slot[col];
          if (sl < 0) {
            sl = (PetscInt)fCol.size();
            fCol.push_back(col);
            fVal.insert(fVal.end(), nv, 0.0);
            fHit.insert(fHit.end(), nv, 0);
          }
          fVal[(size_t)sl * nv + k] += v;
          fHit[(size_t)sl * nv + k] = 1;
        };
        for (PetscInt a = 0; a < F.nnodes; ++a)
          for (PetscInt d = 0; d < dim; ++d) {
            const PetscReal coef = -w * psi * Ns[a] * n2[d];
            if (F.dof[a * dim + d] >= 0) add(F.dof[a * dim + d], coef);
            else gk -= coef * F.Ubc[a * dim + d];
          }
        for (PetscInt a = 0; a < M.nnodes; ++a)
          for (PetscInt d = 0; d < dim; ++d) {
            const PetscReal coef = w * psi * Nm[a] * n2[d];
            if (M.dof[a * dim + d] >= 0) add(M.dof[a * dim + d], coef);
            else gk -= coef * M.Ubc[a * dim + d];
          }
        rowHit[k] = true;
        acc.Touch(r);
        acc.g[r] += gk;
      }
    }
    // the facet's rows buffered (K's exact pattern preallocates it below), its columns unmarked
    for (PetscInt k = 0; k < nv; ++k) {
      if (!rowHit[k]) continue;
      kRow.push_back(rows[k]);
      for (size_t j = 0; j < fCol.size(); ++j)
        if (fHit[j * nv + k]) {
          kCol.push_back(fCol[j]);
          kVal.push_back(fVal[j * nv + k]);
        }
      kPtr.push_back((PetscInt)kCol.size());
    }
    for (PetscInt c : fCol) slot[c] = -1;
    fCol.clear();
    fVal.clear();
    fHit.clear();
    for (PetscInt k = 0; k < nv; ++k) {
      acc.TouchCoord(rows[k]);
      for (PetscInt d = 0; d < dim; ++d) {
        acc.coord[d][rows[k]]    = F.X[k * dim + d];
        acc.coordRef[d][rows[k]] = F.Xref[k * dim + d];
      }
    }
  }
  kReserve_[0] = kRow.size();
  kReserve_[1] = kCol.size();
  {
    PetscInt c[2] = {farPoints, nearFar};
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, c, 2, MPIU_INT, MPI_SUM, comm));
    farPoints = c[0];
    nearFar   = c[1];
  }
  if (nearFar > 0) { // a point out of reach closer than half the margin (large facets there): this assembly again with all
    PetscCall(MatDestroy(&sys->K));
    ++searchStats_.fallbacks;
    const bool near  = masterSearchNear;
    masterSearchNear = false;
    --searchStats_.assemblies;
    PetscErrorCode ierr = Assemble(elas, uloc, sys);
    masterSearchNear = near;
    PetscCall(ierr);
    PetscFunctionReturn(0);
  }
  searchStats_.farPoints = farPoints;
  // The buffered rows merged: one row per multiplier with its columns sorted and unique, the contributions of an entry
  // summed in the order they came (facet by facet, each facet's already summed over its integration points); a
  // slave node's row came in one piece per adjacent slave facet (measured 2026-11-26: the MatSetValues of the
  // unmerged pieces, one per integration point then, were half of the contact assembly on hertz3d)
  std::vector<PetscInt>    mRow, mPtr(1, 0), mCol;
  std::vector<PetscScalar> mVal;
  {
    // the pieces bucketed by row (stable), then each row's entries accumulated through a column marker
    std::vector<PetscInt> start((size_t)R_ + 1, 0), piece(kRow.size());
    for (PetscInt r : kRow) ++start[(size_t)r + 1];
    for (PetscInt r = 0; r < R_; ++r) start[(size_t)r + 1] += start[r];
    {
      std::vector<PetscInt> next(start.begin(), start.end() - 1);
      for (size_t i = 0; i < kRow.size(); ++i) piece[next[kRow[i]]++] = (PetscInt)i;
    }
    std::vector<std::pair<PetscInt, PetscScalar>>      entries; // this row's (column, sum); slot: unmarked above
    for (PetscInt r = 0; r < R_; ++r) {
      if (start[r] == start[(size_t)r + 1]) continue;
      entries.clear();
      for (PetscInt k = start[r]; k < start[(size_t)r + 1]; ++k)
        for (PetscInt e = kPtr[piece[k]]; e < kPtr[piece[k] + 1]; ++e) {
          PetscInt &sl = slot[kCol[e]];
          if (sl < 0) {
            sl = (PetscInt)entries.size();
            entries.emplace_back(kCol[e], 0.0);
          }
          entries[sl].second += kVal[e];
        }
      for (const auto &cv : entries) slot[cv.first] = -1;
      std::sort(entries.begin(), entries.end(), [](const std::pair<PetscInt, PetscScalar> &a, const std::pair<PetscInt, PetscScalar> &b) { return a.first < b.first; });
      mRow.push_back(r);
      for (const auto &cv : entries) {
        mCol.push_back(cv.first);
        mVal.push_back(cv.second);
      }
      mPtr.push_back((PetscInt)mCol.size());
    }
  }
  // K with its exact pattern (a MATPREALLOCATOR pass over the merged rows, then the values: a fixed guess of 48 per
  // row reallocated K's storage for almost every row of a 3D surface, 476 times per assembly on hertz3d)
  {
    Mat pre;
    PetscCall(MatCreate(comm, &pre));
    PetscCall(MatSetSizes(pre, rEnd_ - rStart_, nlocal, R_, N));
    PetscCall(MatSetType(pre, MATPREALLOCATOR));
    PetscCall(MatSetUp(pre));
    for (size_t i = 0; i < mRow.size(); ++i) PetscCall(MatSetValues(pre, 1, &mRow[i], mPtr[i + 1] - mPtr[i], mCol.data() + mPtr[i], mVal.data() + mPtr[i], ADD_VALUES));
    PetscCall(MatAssemblyBegin(pre, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(pre, MAT_FINAL_ASSEMBLY));
    PetscCall(MatCreate(comm, &sys->K));
    PetscCall(MatSetSizes(sys->K, rEnd_ - rStart_, nlocal, R_, N));
    PetscCall(MatSetType(sys->K, MATAIJ));
    PetscCall(MatPreallocatorPreallocate(pre, PETSC_FALSE, sys->K));
    PetscCall(MatDestroy(&pre));
    PetscCall(MatSetOption(sys->K, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
    for (size_t i = 0; i < mRow.size(); ++i) PetscCall(MatSetValues(sys->K, 1, &mRow[i], mPtr[i + 1] - mPtr[i], mCol.data() + mPtr[i], mVal.data() + mPtr[i], ADD_VALUES));
  }
  PetscCall(MatAssemblyBegin(sys->K, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(sys->K, MAT_FINAL_ASSEMBLY));
  {
    std::vector<PetscScalar> v(acc.rows.size());
    auto set = [&](Vec x, const std::vector<PetscInt> &rs, const std::vector<PetscScalar> &a, InsertMode mode) -> PetscErrorCode {
      PetscFunctionBeginUser;
      v.resize(rs.size());
      for (size_t i = 0; i < rs.size(); ++i) v[i] = a[rs[i]];
      PetscCall(VecSetValues(x, (PetscInt)rs.size(), rs.data(), v.data(), mode));
      PetscFunctionReturn(0);
    };
    PetscCall(set(sys->weight, acc.rows, acc.weight, ADD_VALUES));
    PetscCall(set(sys->g, acc.rows, acc.g, ADD_VALUES));
    for (PetscInt d = 0; d < dim; ++d) {
      PetscCall(set(sys->normal[d], acc.rows, acc.normal[d], ADD_VALUES));
      PetscCall(set(sys->coord[d], acc.coordRows, acc.coord[d], INSERT_VALUES));
      PetscCall(set(sys->coordRef[d], acc.coordRows, acc.coordRef[d], INSERT_VALUES));
    }
  }
  Vec all[11] = {sys->g, sys->weight, sys->normal[0], sys->normal[1], sys->normal[2], sys->coord[0], sys->coord[1], sys->coord[2], sys->coordRef[0], sys->coordRef[1], sys->coordRef[2]};
  for (Vec v : all)
    if (v) {
      PetscCall(VecAssemblyBegin(v));
      PetscCall(VecAssemblyEnd(v));
    }
  for (PetscInt d = 0; d < dim; ++d) PetscCall(VecPointwiseDivide(sys->normal[d], sys->normal[d], sys->weight));
  PetscFunctionReturn(0);
}

PetscErrorCode ContactMap::SlaveOutwardNormals(MPI_Comm comm, std::vector<PetscReal> n[3]) const
{
  const PetscInt         dim = slave_.dim;
  std::vector<PetscReal> sum((size_t)3 * R_, 0.0);

  PetscFunctionBeginUser;
  for (const auto &F : slave_.facets) {
    PetscReal nf[3] = {0, 0, 0};
    FacetNormal(F.X.data(), dim, F.outward, nf);
    for (PetscInt k = 0; k < F.nv; ++k)
      if (F.row[k] >= 0)
        for (PetscInt d = 0; d < dim; ++d) sum[(size_t)3 * F.row[k] + d] += nf[d];
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, sum.data(), (int)sum.size(), MPIU_REAL, MPIU_SUM, comm));
  for (PetscInt d = 0; d < 3; ++d) {
    n[d].assign(R_, 0.0);
    for (PetscInt r = 0; r < R_; ++r) n[d][r] = sum[(size_t)3 * r + d];
  }
  PetscFunctionReturn(0);
}

PetscErrorCode ContactMap::PastMasterEndRows(MPI_Comm comm, std::vector<PetscInt> *rows) const
{
  PetscMPIInt size, n = (PetscMPIInt)pastMasterEnd_.size();

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  std::vector<PetscMPIInt> counts(size), displs(size, 0);
  PetscCallMPI(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm));
  for (PetscMPIInt i = 1; i < size; ++i) displs[i] = displs[i - 1] + counts[i - 1];
  rows->resize((size_t)displs[size - 1] + counts[size - 1]);
  PetscCallMPI(MPI_Allgatherv(pastMasterEnd_.data(), n, MPIU_INT, rows->data(), counts.data(), displs.data(), MPIU_INT, comm));
  std::sort(rows->begin(), rows->end());
  rows->erase(std::unique(rows->begin(), rows->end()), rows->end());
  PetscFunctionReturn(0);
}

} // namespace rbc
