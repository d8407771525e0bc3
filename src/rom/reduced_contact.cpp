// src/rom/reduced_contact.cpp: ContactPatch, the pointwise contact map of the reduced model: built
// from the full-order contact surfaces, restricted to the facets around the EIM points, serialized into
// the ROM file, evaluated with the full-order kernel (src/contact/contact_point.hpp).
#include "rbcontact/reduced_contact.hpp"
#include "rbcontact/rom_file.hpp"
#include "../contact/contact_point.hpp"
#include "dense_kernels.hpp"
#include <algorithm>
#include <array>
#include <map>
#include <set>

namespace rbc {

namespace {
using Key = std::array<PetscReal, 4>;

Key NodeKey(const SurfaceFacet &F, PetscInt a, PetscInt dim)
{
  static const PetscInt edge[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  Key                   k        = {(PetscReal)F.body, 0, 0, 0};
  const PetscInt        kind     = F.nodeKind[a];
  for (PetscInt d = 0; d < dim; ++d) k[1 + d] = kind < 3 ? F.Xref[kind * dim + d] : 0.5 * (F.Xref[edge[kind - 3][0] * dim + d] + F.Xref[edge[kind - 3][1] * dim + d]);
  return k;
}

// Partition-independent facet order: body, then the vertices' reference coordinates sorted.
std::vector<PetscReal> FacetKey(const SurfaceFacet &F, PetscInt dim)
{
  std::vector<std::array<PetscReal, 3>> v(F.nv);
  for (PetscInt k = 0; k < F.nv; ++k)
    for (PetscInt d = 0; d < 3; ++d) v[k][d] = d < dim ? F.Xref[k * dim + d] : 0;
  std::sort(v.begin(), v.end());
  std::vector<PetscReal> key = {(PetscReal)F.body};
  for (auto &x : v) key.insert(key.end(), x.begin(), x.end());
  return key;
}

void SortFacets(std::vector<SurfaceFacet> *f, PetscInt dim)
{
  std::vector<std::pair<std::vector<PetscReal>, PetscInt>> keys;
  for (PetscInt i = 0; i < (PetscInt)f->size(); ++i) keys.emplace_back(FacetKey((*f)[i], dim), i);
  std::sort(keys.begin(), keys.end());
  std::vector<SurfaceFacet> out;
  for (auto &k : keys) out.push_back((*f)[k.second]);
  f->swap(out);
}
} // namespace

PetscErrorCode ContactPatch::BuildFull(MPI_Comm comm, const ContactMap &map, const CanonicalOrder &order, const std::vector<PetscReal> &modes, PetscInt Nb, const std::vector<char> &support, PetscInt nsub)
{
  std::vector<SurfaceFacet> S, M;

  PetscFunctionBeginUser;
  dim          = map.Slave().dim;
  N            = Nb;
  smoothNormal = map.smoothNormal;
  PetscCall(map.Slave().Gather(comm, &S));
  PetscCall(map.Master().Gather(comm, &M));
  SortFacets(&S, dim);
  SortFacets(&M, dim);
  const PetscInt ndofs = order.NumDofs();
  PetscCheck((PetscInt)modes.size() == N * ndofs, comm, PETSC_ERR_ARG_SIZ, "ContactPatch: %zu mode entries for N = %" PetscInt_FMT " x %" PetscInt_FMT " dofs", modes.size(), N, ndofs);

  // Slave facets touching the support; canonical rows
  std::vector<SurfaceFacet> Skeep;
  for (auto F : S) {
    bool in = support.empty();
    for (PetscInt k = 0; k < F.nv; ++k) {
      F.row[k] = F.row[k] >= 0 ? order.CanonicalMultiplier(F.row[k]) : -1;
      if (!in && F.row[k] >= 0 && F.row[k] < (PetscInt)support.size() && support[F.row[k]]) in = true;
    }
    if (in) Skeep.push_back(F);
  }
  // Nodes (by body and reference position) with theta, uD, canonical dofs
  std::map<Key, PetscInt> nodes;
  theta.clear();
  uD.clear();
  canon.clear();
  auto addNodes = [&](std::vector<SurfaceFacet> &fs) {
    for (auto &F : fs)
      for (PetscInt a = 0; a < F.nnodes; ++a) {
        const Key k  = NodeKey(F, a, dim);
        auto      it = nodes.find(k);
        PetscInt  id;
        if (it == nodes.end()) {
          id = (PetscInt)nodes.size();
          nodes.emplace(k, id);
          theta.resize((id + 1) * dim * N, 0.0);
          uD.resize((id + 1) * dim, 0.0);
          canon.resize((id + 1) * dim, -1);
          for (PetscInt d = 0; d < dim; ++d) {
            const PetscInt g = F.dof[a * dim + d];
            if (g >= 0) {
              const PetscInt c = order.CanonicalDof(g);
              canon[id * dim + d] = c;
              for (PetscInt n = 0; n < N; ++n) theta[(id * dim + d) * N + n] = modes[n * ndofs + c];
            } else uD[id * dim + d] = F.Ubc[a * dim + d];
          }
        } else id = it->second;
        for (PetscInt d = 0; d < dim; ++d) F.dof[a * dim + d] = id * dim + d;
      }
  };
  addNodes(Skeep);
  addNodes(M);
  nnode = (PetscInt)nodes.size();
  // Master vertices: compact ids, ends of the master surface
  std::map<Key, PetscInt> verts;
  std::vector<PetscInt>   degree;
  for (auto &F : M)
    for (PetscInt k = 0; k < F.nv; ++k) {
      Key key = {(PetscReal)F.body, 0, 0, 0};
      for (PetscInt d = 0; d < dim; ++d) key[1 + d] = F.Xref[k * dim + d];
      auto it = verts.find(key);
      if (it == verts.end()) {
        it = verts.emplace(key, (PetscInt)verts.size()).first;
        degree.push_back(0);
      }
      F.vglobal[k] = it->second;
      ++degree[it->second];
    }
  nvertex = (PetscInt)verts.size();
  vertexEnd.assign(nvertex, 0);
  for (PetscInt v = 0; v < nvertex; ++v) vertexEnd[v] = degree[v] < (dim == 2 ? 2 : 0) ? 1 : 0;
  slave  = Skeep;
  master = M;
  geomSet_.fill(0); // (SetGeometry: the facets' coordinates are not those of any map yet)
  searchable.assign(master.size(), 1);
  // Integration points: nsub pieces x the map's Gauss rule (2D); the plain rule in 3D
  const auto    &qp = map.QuadraturePoints();
  const auto    &qw = map.QuadratureWeights();
  const PetscInt nq = (PetscInt)qw.size(), nv = dim;
  points.clear();
  for (PetscInt s = 0; s < (PetscInt)slave.size(); ++s) {
    const PetscInt pieces = dim == 2 ? nsub : 1;
    for (PetscInt piece = 0; piece < pieces; ++piece)
      for (PetscInt q = 0; q < nq; ++q) {
        Point P;
        P.facet = s;
        if (dim == 2) {
          const PetscReal t = (piece + qp[q * nv + 1]) / pieces;
          P.b[0] = 1 - t;
          P.b[1] = t;
        } else
          for (PetscInt k = 0; k < nv; ++k) P.b[k] = qp[q * nv + k];
        P.wfrac = qw[q] / pieces;
        for (PetscInt k = 0; k < nv; ++k) P.row[k] = slave[s].row[k];
        points.push_back(P);
      }
  }
  candStart.clear();
  cand.clear();
  PetscFunctionReturn(0);
}

void ContactPatch::Restrict(const std::vector<PetscInt> &keep, const std::vector<std::vector<PetscInt>> &hits, PetscInt rings, ContactPatch *out) const
{
  // master adjacency through shared vertices
  std::vector<std::vector<PetscInt>> vfacets(nvertex);
  for (PetscInt m = 0; m < (PetscInt)master.size(); ++m)
    for (PetscInt k = 0; k < master[m].nv; ++k) vfacets[master[m].vglobal[k]].push_back(m);
  auto grow = [&](std::set<PetscInt> &s) {
    std::set<PetscInt> add;
    for (PetscInt m : s)
      for (PetscInt k = 0; k < master[m].nv; ++k)
        for (PetscInt f : vfacets[master[m].vglobal[k]]) add.insert(f);
    s.insert(add.begin(), add.end());
  };
  std::vector<std::set<PetscInt>> candSets(keep.size());
  std::set<PetscInt>              search, normal, slaves;
  for (size_t i = 0; i < keep.size(); ++i) {
    const PetscInt p = keep[i];
    for (PetscInt m : hits[p]) candSets[i].insert(m);
    for (PetscInt r = 0; r < rings; ++r) grow(candSets[i]);
    search.insert(candSets[i].begin(), candSets[i].end());
    slaves.insert(points[p].facet);
  }
  normal = search;
  grow(normal);
  // new numbering (old order kept: the closest-point tie rule is by index)
  std::map<PetscInt, PetscInt> snew, mnew, nodeNew, vnew;
  for (PetscInt s : slaves) snew.emplace(s, (PetscInt)snew.size());
  for (PetscInt m : normal) mnew.emplace(m, (PetscInt)mnew.size());
  out->dim          = dim;
  out->N            = N;
  out->smoothNormal = smoothNormal;
  out->slave.clear();
  out->master.clear();
  out->geomSet_.fill(0);
  out->searchable.clear();
  auto renode = [&](SurfaceFacet F) {
    for (PetscInt a = 0; a < F.nnodes; ++a) {
      const PetscInt old = F.dof[a * dim] / dim;
      auto           it  = nodeNew.find(old);
      if (it == nodeNew.end()) it = nodeNew.emplace(old, (PetscInt)nodeNew.size()).first;
      for (PetscInt d = 0; d < dim; ++d) F.dof[a * dim + d] = it->second * dim + d;
    }
    return F;
  };
  // the nodes that carry terms first (slave facets, then the candidate master facets), those that serve the
  // vertex normals only after them: the dof sum runs over the first TermDofs() (docs/online.md)
  for (auto &s : snew) renode(slave[s.first]);
  for (auto &m : mnew)
    if (search.count(m.first)) renode(master[m.first]);
  for (auto &s : snew) out->slave.push_back(renode(slave[s.first]));
  for (auto &m : mnew) {
    SurfaceFacet F = renode(master[m.first]);
    for (PetscInt k = 0; k < F.nv; ++k) {
      auto it = vnew.find(F.vglobal[k]);
      if (it == vnew.end()) it = vnew.emplace(F.vglobal[k], (PetscInt)vnew.size()).first;
      F.vglobal[k] = it->second;
    }
    out->master.push_back(F);
    out->searchable.push_back(search.count(m.first) ? 1 : 0);
  }
  out->nnode   = (PetscInt)nodeNew.size();
  out->nvertex = (PetscInt)vnew.size();
  out->theta.assign(out->nnode * dim * N, 0.0);
  out->uD.assign(out->nnode * dim, 0.0);
  out->canon.assign(canon.empty() ? 0 : out->nnode * dim, -1);
  for (auto &nn : nodeNew) {
    for (PetscInt d = 0; d < dim; ++d) {
      out->uD[nn.second * dim + d] = uD[nn.first * dim + d];
      if (!canon.empty()) out->canon[nn.second * dim + d] = canon[nn.first * dim + d];
      for (PetscInt n = 0; n < N; ++n) out->theta[(nn.second * dim + d) * N + n] = theta[(nn.first * dim + d) * N + n];
    }
  }
  out->vertexEnd.assign(out->nvertex, 0);
  for (auto &v : vnew) out->vertexEnd[v.second] = vertexEnd[v.first];
  out->points.clear();
  out->candStart.assign(1, 0);
  out->cand.clear();
  for (size_t i = 0; i < keep.size(); ++i) {
    Point P = points[keep[i]];
    P.facet = snew[P.facet];
    out->points.push_back(P);
    // nearest first (reference centroids): ClosestPoint::FindAmong starts from the candidate with the nearest deformed
    // centroid, then scans in this order and prunes the rest
    const SurfaceFacet &S = slave[points[keep[i]].facet];
    PetscReal           z[3] = {0, 0, 0};
    for (PetscInt k = 0; k < S.nv; ++k)
      for (PetscInt d = 0; d < dim; ++d) z[d] += points[keep[i]].b[k] * S.Xref[k * dim + d];
    std::vector<std::pair<PetscReal, PetscInt>> order;
    for (PetscInt m : candSets[i]) {
      const SurfaceFacet &Mf = master[m];
      PetscReal           d2 = 0;
      for (PetscInt d = 0; d < dim; ++d) {
        PetscReal c = 0;
        for (PetscInt k = 0; k < Mf.nv; ++k) c += Mf.Xref[k * dim + d] / Mf.nv;
        d2 += (z[d] - c) * (z[d] - c);
      }
      order.emplace_back(d2, mnew[m]);
    }
    std::sort(order.begin(), order.end());
    for (auto &o : order) out->cand.push_back(o.second);
    out->candStart.push_back((PetscInt)out->cand.size());
  }
}

PetscInt ContactPatch::TermDofs() const
{
  PetscInt last = -1; // the highest node of a facet that can carry a term: every slave facet, the searchable masters
  for (const auto &F : slave)
    for (PetscInt a = 0; a < F.nnodes; ++a) last = std::max(last, F.dof[a * dim] / dim);
  for (size_t m = 0; m < master.size(); ++m)
    if (searchable.empty() || searchable[m])
      for (PetscInt a = 0; a < master[m].nnodes; ++a) last = std::max(last, master[m].dof[a * dim] / dim);
  return (last + 1) * dim;
}

void ContactPatch::SelectBasis(const std::vector<PetscInt> &cols, ContactPatch *out) const
{
  *out         = *this;
  const PetscInt n = (PetscInt)cols.size();
  out->N       = n;
  out->theta.assign(nnode * dim * n, 0.0);
  for (PetscInt r = 0; r < nnode * dim; ++r)
    for (PetscInt j = 0; j < n; ++j) out->theta[r * n + j] = theta[r * N + cols[j]];
}

void ContactPatch::SetGeometry(const GeometryMap *map, const std::vector<PetscReal> &mu)
{
  // one affine map per body; a body whose map is bitwise the last call's keeps its facets' coordinates and measures
  std::array<Affine, 8> cache;
  std::array<char, 8>   have{}, same{};
  if (meas_.size() != slave.size()) { // the facets were (re)set: every body afresh
    meas_.assign(slave.size(), 0.0);
    geomSet_.fill(0);
  }
  for (int fs = 0; fs < 2; ++fs) {
    auto &facets = fs ? master : slave;
    for (size_t f = 0; f < facets.size(); ++f) {
      SurfaceFacet &F = facets[f];
      Affine        a;
      if (map && F.body >= 0 && F.body < 8) {
        if (!have[F.body]) {
          cache[F.body] = map->Evaluate(F.body, mu);
          have[F.body]  = 1;
          same[F.body]  = geomSet_[F.body] && cache[F.body].G == geomAff_[F.body].G && cache[F.body].t == geomAff_[F.body].t;
        }
        if (same[F.body]) continue;
        a = cache[F.body];
      } else if (map) a = map->Evaluate(F.body, mu);
      for (PetscInt k = 0; k < F.nv; ++k) a.Apply(dim, &F.Xref[k * dim], &F.X[k * dim]);
      if (!fs) meas_[f] = FacetMeasure(F.X.data(), dim);
    }
  }
  for (int b = 0; b < 8; ++b)
    if (have[b]) {
      geomAff_[b] = cache[b];
      geomSet_[b] = 1;
    }
}

void ContactPatch::SetNodal(const std::vector<PetscReal> &U, ForkJoin *pool)
{
  const PetscInt ns = (PetscInt)slave.size(), nm = (PetscInt)master.size();
  auto           copy = [&](std::vector<SurfaceFacet> &fs, PetscInt a, PetscInt b) {
    for (PetscInt f = a; f < b; ++f) {
      SurfaceFacet &F = fs[f];
      for (PetscInt i = 0; i < F.nnodes * dim; ++i) F.U[i] = U[F.dof[i]];
    }
  };
  ForkJoin::ForParts(pool, ns + nm, [&](PetscInt a, PetscInt b, int) { // the slave facets, then the master ones
    copy(slave, std::min(a, ns), std::min(b, ns));
    copy(master, std::max(a, ns) - ns, std::max(b, ns) - ns);
  });
  PrepareMaster(pool);
}

void ContactPatch::SetReduced(const PetscReal *v)
{
  thread_local std::vector<PetscReal> U;
  U.resize(nnode * dim);
  RowDots(nnode * dim, N, theta.data(), v, uD.data(), U.data()); // U = uD + theta v (vectorized over the modes)
  SetNodal(U);
}

void ContactPatch::NodalFromCanonical(const std::vector<PetscReal> &u, std::vector<PetscReal> *U) const
{
  U->resize(nnode * dim);
  for (PetscInt r = 0; r < nnode * dim; ++r) (*U)[r] = r < (PetscInt)canon.size() && canon[r] >= 0 ? u[canon[r]] : uD[r];
}

void ContactPatch::PrepareMaster(ForkJoin *pool)
{
  const PetscInt nm = (PetscInt)master.size();
  binned_           = candStart.size() <= 1;
  if (binned_) (void)cp_.Build(master, dim, true);
  else cp_.ResizeVertices(nm, dim);
  fnormal_.resize(smoothNormal ? 3 * nm : 0);
  // per master facet, in parts on the pool's threads: its deformed vertices and its normal
  ForkJoin::ForParts(pool, nm, [&](PetscInt a, PetscInt b, int) {
    if (!binned_) cp_.SetVerticesOf(master, true, a, b);
    if (smoothNormal)
      for (PetscInt m = a; m < b; ++m) FacetNormal(cp_.Vertices(m), dim, master[m].outward, &fnormal_[3 * m]);
  });
  vnormal_.assign(3 * nvertex, 0.0);
  if (smoothNormal) // the facets' normals summed per vertex in the facets' order (the same bits on any number of parts)
    for (PetscInt m = 0; m < nm; ++m)
      for (PetscInt k = 0; k < master[m].nv; ++k)
        for (PetscInt d = 0; d < 3; ++d) vnormal_[3 * master[m].vglobal[k] + d] += fnormal_[3 * m + d];
  if (smoothNormal) // unit, once per vertex (EvaluateContactPoint); vertices of no facet stay 0 and are never read
    for (PetscInt v = 0; v < nvertex; ++v)
      if (vnormal_[3 * v] != 0 || vnormal_[3 * v + 1] != 0 || vnormal_[3 * v + 2] != 0) NormalizeVertexNormal(&vnormal_[3 * v]);
}

PetscInt ContactPatch::PointTerms(PetscInt p, PetscInt *nt, PetscInt rowIdx[], PetscReal coef[], PetscReal *gamma, PetscInt *hit, PetscReal *wn) const
{
  PetscInt            outside = 0;
  const Point        &P = points[p];
  const SurfaceFacet &F = slave[P.facet];
  const PetscReal     w = P.wfrac * meas_[P.facet];
  const PetscInt     *c = nullptr;
  PetscInt            nc = 0;
  if (!binned_) {
    c  = &cand[candStart[p]];
    nc = candStart[p + 1] - candStart[p];
  }
  ContactPointEval e;
  EvaluateContactPoint(
    F, dim, P.b, master, cp_.Vertices(0), smoothNormal,
    [&](const PetscReal *z, PetscInt *m, PetscReal *bm, PetscReal *dist) {
      if (binned_) cp_.Find(z, m, bm, dist);
      else cp_.FindAmong(z, c, nc, m, bm, dist);
    },
    [&](const SurfaceFacet &Mf, PetscInt k) { return &vnormal_[3 * Mf.vglobal[k]]; }, &e);
  const SurfaceFacet &M = master[e.m];
  if (hit) *hit = e.m;
  // A projection clamped to a vertex that no other candidate shares (and that does not end the
  // master surface) may have a closer point outside the patch: out of the EIM's range.
  if (!binned_)
    for (PetscInt k = 0; k < M.nv; ++k)
      if (e.bm[k] == 1.0 && !vertexEnd[M.vglobal[k]]) {
        PetscInt shared = 0;
        for (PetscInt j = 0; j < nc; ++j)
          for (PetscInt kk = 0; kk < master[c[j]].nv; ++kk) shared += master[c[j]].vglobal[kk] == M.vglobal[k];
        if (shared < 2) ++outside;
      }
  // kappa = w sum_a coef_a theta_a over the slave and master nodal dofs
  PetscReal g = e.gap;
  *nt         = 0;
  for (PetscInt side = 0; side < 2; ++side) {
    const SurfaceFacet &G  = side ? M : F;
    const PetscReal    *Nb = side ? e.Nm : e.Ns;
    const PetscReal     sg = side ? 1.0 : -1.0;
    for (PetscInt a = 0; a < G.nnodes; ++a)
      for (PetscInt d = 0; d < dim; ++d) {
        // written always, kept when nonzero (no branch: a projection onto an edge or vertex has zero shape values)
        const PetscReal cf = sg * Nb[a] * e.n2[d];
        const PetscInt  r  = G.dof[a * dim + d];
        g -= cf * uD[r];
        coef[*nt]   = w * cf;
        rowIdx[*nt] = r;
        *nt += cf != 0.0;
      }
  }
  *gamma = w * g;
  if (wn)
    for (PetscInt d = 0; d < dim; ++d) wn[d] = w * e.n2[d];
  return outside;
}

PetscInt ContactPatch::Evaluate(const PetscInt *idx, PetscInt np, PetscReal *kappa, PetscReal *gamma, PetscInt *hit, PetscReal *wn) const
{
  PetscInt outside = 0;
  for (PetscInt i = 0; i < np; ++i) {
    PetscReal coefs[MaxTerms], g; // 2 sides x (<= 6 nodes x 3 dims: SurfaceFacet::dof)
    PetscInt  ridx[MaxTerms], nt;
    outside += PointTerms(idx[i], &nt, ridx, coefs, &g, hit ? &hit[i] : nullptr, wn ? wn + (size_t)i * dim : nullptr);
    if (kappa) KappaRow(nt, ridx, coefs, kappa + i * N);
    if (gamma) gamma[i] = g;
  }
  return outside;
}

void ContactPatch::KappaRow(PetscInt nt, const PetscInt *rowIdx, const PetscReal *coef, PetscReal *kappa) const
{
  const PetscReal *rows[MaxTerms];
  for (PetscInt t = 0; t < nt; ++t) rows[t] = &theta[rowIdx[t] * N];
  CombineRows(nt, coef, rows, N, kappa); // one combination kernel
}

PetscInt ContactPatch::EvaluateCoefficients(const PetscInt *idx, PetscInt np, PetscInt *nt, PetscInt *rowIdx, PetscReal *coef, PetscReal *gamma, PetscReal *wn, PetscInt *hit) const
{
  PetscInt outside = 0;
  for (PetscInt i = 0; i < np; ++i) outside += PointTerms(idx[i], &nt[i], rowIdx + (size_t)i * MaxTerms, coef + (size_t)i * MaxTerms, &gamma[i], hit ? &hit[i] : nullptr, wn ? wn + (size_t)i * dim : nullptr);
  return outside;
}

void ContactPatch::Serialize(std::vector<std::pair<std::string, std::pair<std::vector<unsigned long long>, std::vector<double>>>> *out) const
{
  auto put = [&](const std::string &name, std::vector<unsigned long long> dims, std::vector<double> data) { out->emplace_back(name, std::make_pair(dims, data)); };
  put("meta", {8}, {(double)dim, (double)N, (double)nnode, (double)nvertex, smoothNormal ? 1.0 : 0.0, (double)slave.size(), (double)master.size(), (double)points.size()});
  put("theta", {(unsigned long long)(nnode * dim), (unsigned long long)std::max<PetscInt>(N, 1)}, N ? std::vector<double>(theta.begin(), theta.end()) : std::vector<double>(nnode * dim, 0.0));
  put("uD", {(unsigned long long)nnode, (unsigned long long)dim}, std::vector<double>(uD.begin(), uD.end()));
  for (PetscInt side = 0; side < 2; ++side) {
    const auto         &fs = side ? master : slave;
    std::vector<double> rec;
    for (size_t f = 0; f < fs.size(); ++f) {
      const SurfaceFacet &F = fs[f];
      std::vector<double> r(32, -1.0);
      r[0] = F.body;
      r[1] = F.nv;
      r[2] = F.nnodes;
      r[3] = F.outward;
      for (int i = 0; i < 9; ++i) r[4 + i] = F.Xref[i];
      for (int a = 0; a < 6; ++a) r[13 + a] = a < F.nnodes ? F.nodeKind[a] : -1;
      for (int a = 0; a < 6; ++a) r[19 + a] = a < F.nnodes ? F.dof[a * dim] / dim : -1;
      for (int k = 0; k < 3; ++k) r[25 + k] = F.vglobal[k];
      for (int k = 0; k < 3; ++k) r[28 + k] = F.row[k];
      r[31] = side ? searchable[f] : 1;
      rec.insert(rec.end(), r.begin(), r.end());
    }
    put(side ? "master" : "slave", {(unsigned long long)fs.size(), 32}, rec);
  }
  put("vertex_end", {(unsigned long long)std::max<PetscInt>(nvertex, 1)}, nvertex ? std::vector<double>(vertexEnd.begin(), vertexEnd.end()) : std::vector<double>{0});
  std::vector<double> pts;
  for (const auto &P : points) pts.insert(pts.end(), {(double)P.facet, P.b[0], P.b[1], P.b[2], P.wfrac, (double)P.row[0], (double)P.row[1], (double)P.row[2]});
  put("points", {(unsigned long long)points.size(), 8}, pts);
  std::vector<double> cs(candStart.begin(), candStart.end()), cc(cand.begin(), cand.end());
  if (cs.empty()) cs.push_back(0);
  if (cc.empty()) cc.push_back(-1);
  put("cand_start", {(unsigned long long)cs.size()}, cs);
  put("cand", {(unsigned long long)cc.size()}, cc);
}

PetscErrorCode ContactPatch::Deserialize(const std::string &file, const std::string &group)
{
  std::vector<unsigned long long> dims;
  std::vector<double>             meta, data;

  PetscFunctionBeginUser;
  geomSet_.fill(0);
  PetscCall(RomReadDataset(file, group + "/meta", &dims, &meta));
  PetscCheck(meta.size() == 8, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s/meta has %zu entries (8 expected)", file.c_str(), group.c_str(), meta.size());
  // every count a whole number in [0, 2^31 - 1] (a larger one wrapped in the products below: 3 x 1431655766 nodes
  // passed as 2 values of uD, and the facets then read past it; review of 2026-12-04), the products in 64 bits
  for (int k : {0, 1, 2, 3, 5, 6, 7})
    PetscCheck(meta[k] >= 0 && meta[k] <= 2147483647.0 && meta[k] == std::floor(meta[k]), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s/meta entry %d is %g, not a count: a corrupt file", file.c_str(), group.c_str(), k, meta[k]);
  dim          = (PetscInt)meta[0];
  N            = (PetscInt)meta[1];
  nnode        = (PetscInt)meta[2];
  nvertex      = (PetscInt)meta[3];
  smoothNormal = meta[4] != 0;
  const size_t ns = (size_t)meta[5], nm = (size_t)meta[6], np = (size_t)meta[7];
  PetscCheck(dim == 2 || dim == 3, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s/meta: dimension %" PetscInt_FMT, file.c_str(), group.c_str(), dim);
  auto need = [&](const std::string &name, unsigned long long n) -> PetscErrorCode {
    PetscFunctionBeginUser;
    PetscCall(RomReadDataset(file, group + "/" + name, &dims, &data));
    PetscCheck(data.size() == n, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s/%s has %zu entries (%llu expected)", file.c_str(), group.c_str(), name.c_str(), data.size(), n);
    PetscCall(RomCheckValues("ROM file " + file, group + "/" + name, data));
    PetscFunctionReturn(0);
  };
  PetscCall(need("theta", (unsigned long long)nnode * (unsigned long long)dim * (unsigned long long)std::max<PetscInt>(N, 1)));
  theta.assign(data.begin(), data.end());
  if (!N) theta.clear();
  PetscCall(need("uD", (unsigned long long)nnode * (unsigned long long)dim));
  uD.assign(data.begin(), data.end());
  for (PetscInt side = 0; side < 2; ++side) {
    const size_t n = side ? nm : ns;
    PetscCall(need(side ? "master" : "slave", (unsigned long long)n * 32));
    auto &fs = side ? master : slave;
    fs.assign(n, SurfaceFacet());
    if (side) searchable.assign(n, 1);
    for (size_t f = 0; f < n; ++f) {
      const double *r = &data[32 * f];
      SurfaceFacet &F = fs[f];
      F.body          = (PetscInt)r[0];
      F.nv            = (PetscInt)r[1];
      F.nnodes        = (PetscInt)r[2];
      F.outward       = r[3];
      PetscCheck(F.nv == dim && F.nnodes >= F.nv && F.nnodes <= 6, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s facet %zu is malformed", file.c_str(), group.c_str(), f);
      for (int i = 0; i < 9; ++i) F.Xref[i] = r[4 + i];
      for (int a = 0; a < F.nnodes; ++a) {
        F.nodeKind[a] = (PetscInt)r[13 + a];
        PetscCheck((F.nodeKind[a] >= 0 && F.nodeKind[a] < F.nv) || (F.nodeKind[a] >= 3 && F.nodeKind[a] <= (dim == 2 ? 3 : 5)), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s facet %zu: node kind %" PetscInt_FMT " out of range", file.c_str(), group.c_str(), f, F.nodeKind[a]);
        const PetscInt node = (PetscInt)r[19 + a];
        PetscCheck(node >= 0 && node < nnode, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s facet %zu: node %" PetscInt_FMT " out of range", file.c_str(), group.c_str(), f, node);
        for (PetscInt d = 0; d < dim; ++d) F.dof[a * dim + d] = node * dim + d;
      }
      for (int k = 0; k < 3; ++k) F.vglobal[k] = (PetscInt)r[25 + k];
      for (int k = 0; k < 3; ++k) F.row[k] = (PetscInt)r[28 + k];
      if (side) {
        searchable[f] = r[31] != 0;
        for (int k = 0; k < F.nv; ++k) PetscCheck(F.vglobal[k] >= 0 && F.vglobal[k] < nvertex, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s facet %zu: vertex out of range", file.c_str(), group.c_str(), f);
      }
      F.X = F.Xref;
    }
  }
  PetscCall(need("vertex_end", std::max<PetscInt>(nvertex, 1)));
  vertexEnd.assign(nvertex, 0);
  for (PetscInt v = 0; v < nvertex; ++v) vertexEnd[v] = data[v] != 0;
  PetscCall(need("points", np * 8));
  points.assign(np, Point());
  for (size_t p = 0; p < np; ++p) {
    const double *r = &data[8 * p];
    points[p].facet = (PetscInt)r[0];
    PetscCheck(points[p].facet >= 0 && points[p].facet < (PetscInt)ns, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s point %zu: facet out of range", file.c_str(), group.c_str(), p);
    for (int k = 0; k < 3; ++k) points[p].b[k] = r[1 + k];
    points[p].wfrac = r[4];
    for (int k = 0; k < 3; ++k) points[p].row[k] = (PetscInt)r[5 + k];
  }
  PetscCall(RomReadDataset(file, group + "/cand_start", &dims, &data));
  candStart.assign(data.begin(), data.end());
  PetscCall(RomReadDataset(file, group + "/cand", &dims, &data));
  cand.assign(data.begin(), data.end());
  if (candStart.size() > 1) {
    PetscCheck(candStart.size() == np + 1 && candStart.front() == 0 && candStart.back() == (PetscInt)cand.size(), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s candidate lists are inconsistent", file.c_str(), group.c_str());
    for (size_t p = 0; p < np; ++p) PetscCheck(candStart[p] <= candStart[p + 1], PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s/cand_start decreases at point %zu: a corrupt file", file.c_str(), group.c_str(), p);
    for (PetscInt m : cand) PetscCheck(m >= 0 && m < (PetscInt)nm, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: %s candidate facet out of range", file.c_str(), group.c_str());
  } else cand.clear();
  meas_.assign(ns, 0.0);
  PetscFunctionReturn(0);
}

} // namespace rbc
