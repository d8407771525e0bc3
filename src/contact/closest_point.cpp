// src/contact/closest_point.cpp: closest point on a (deformed) facet soup, with a uniform bin grid over
// the facets' bounding boxes and an expanding search box (exact: a facet at distance d from p has a
// bounding box that meets the box [p - d, p + d]).
#include "rbcontact/contact.hpp"
#include <algorithm>
#include <cmath>
#include <vector>

namespace rbc {

void ClosestPoint::SetVertices(const std::vector<SurfaceFacet> &facets, PetscInt dim, bool deformed)
{
  ResizeVertices((PetscInt)facets.size(), dim);
  SetVerticesOf(facets, deformed, 0, (PetscInt)facets.size());
}

void ClosestPoint::ResizeVertices(PetscInt nf, PetscInt dim)
{
  dim_ = dim;
  nv_  = dim;
  // (resize, not assign: every facet's entries are written by SetVerticesOf; 2D leaves the unused ones 0)
  xdef_.resize(9 * nf, 0.0);
  sphere_.resize(4 * nf, 0.0); // a bounding sphere per facet (centre, radius; 2D: midpoint, 0, half length), FindAmong's lower bound
  invLen2_.resize(dim == 2 ? nf : 0, 0.0);
}

void ClosestPoint::SetVerticesOf(const std::vector<SurfaceFacet> &facets, bool deformed, PetscInt a, PetscInt b)
{
  const PetscInt dim = dim_;
  for (PetscInt f = a; f < b; ++f) {
    const SurfaceFacet &F = facets[f];
    for (PetscInt k = 0; k < nv_; ++k) {
      // vertex node i with nodeKind k
      PetscInt node = -1;
      for (PetscInt i = 0; i < F.nnodes; ++i) if (F.nodeKind[i] == k) node = i;
      for (PetscInt d = 0; d < dim; ++d) xdef_[9 * f + k * dim + d] = F.X[k * dim + d] + (deformed && node >= 0 ? F.U[node * dim + d] : 0.0);
    }
  }
  if (dim == 3)
    for (PetscInt f = a; f < b; ++f) {
      const PetscReal *x = &xdef_[9 * f];
      PetscReal       *c = &sphere_[4 * f], r2 = 0;
      for (PetscInt d = 0; d < 3; ++d) c[d] = (x[d] + x[3 + d] + x[6 + d]) / 3;
      for (PetscInt k = 0; k < 3; ++k) {
        PetscReal e = 0;
        for (PetscInt d = 0; d < 3; ++d) e += (x[3 * k + d] - c[d]) * (x[3 * k + d] - c[d]);
        r2 = std::max(r2, e);
      }
      c[3] = std::sqrt(r2) * (1 + 1e-12); // rounding: the sphere must contain the triangle
    }
  if (dim == 2)
    for (PetscInt f = a; f < b; ++f) {
      const PetscReal *x = &xdef_[9 * f], tt = (x[2] - x[0]) * (x[2] - x[0]) + (x[3] - x[1]) * (x[3] - x[1]);
      PetscReal       *c = &sphere_[4 * f];
      invLen2_[f]        = tt > 0 ? 1.0 / tt : 0.0;
      c[0]               = 0.5 * (x[0] + x[2]);
      c[1]               = 0.5 * (x[1] + x[3]);
      c[2]               = 0;
      c[3]               = 0.5 * std::sqrt(tt) * (1 + 1e-12); // rounding: the circle must contain the segment
    }
}

void ClosestPoint::FindAmong(const PetscReal p[], const PetscInt *cand, PetscInt nc, PetscInt *facet, PetscReal b[], PetscReal *dist) const
{
  PetscReal best = PETSC_MAX_REAL; // squared
  *facet         = -1;
  if (dim_ == 2) {
    // DistToFacet2's 2D branch written into the loop (the same arithmetic, so the same facet and
    // coordinates): the reduced model's cubature points call this once per point and iterate over
    // 7-20 candidates, and the call per candidate cost more than the distance (docs/online.md).
    // After the first candidate (the lists are sorted nearest first offline), a segment whose bounding circle
    // (midpoint c, half length r) is out of reach, |p - c| > sqrt(best) + r, is strictly farther than the best so far
    // and skipped, as in 3D below: the same facet and coordinates as the full scan (ties are never skipped).
    PetscReal sbest = 0, sb = PETSC_MAX_REAL;
    for (PetscInt i = 0; i < nc; ++i) {
      const PetscInt   f    = cand[i];
      if (i > 0) {
        const PetscReal *c     = &sphere_[4 * f];
        const PetscReal  reach = sb + c[3];
        if ((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) > reach * reach) continue;
      }
      const PetscReal *x    = &xdef_[9 * f];
      const PetscReal  t[2] = {x[2] - x[0], x[3] - x[1]};
      PetscReal        s    = ((p[0] - x[0]) * t[0] + (p[1] - x[1]) * t[1]) * invLen2_[f];
      s                     = std::min(1.0, std::max(0.0, s));
      const PetscReal q[2]  = {x[0] + s * t[0] - p[0], x[1] + s * t[1] - p[1]};
      const PetscReal dd    = q[0] * q[0] + q[1] * q[1];
      if (dd < best || (dd == best && f < *facet)) {
        best   = dd;
        *facet = f;
        sbest  = s;
        sb     = std::sqrt(best);
      }
    }
    if (*facet >= 0) {
      b[0] = 1 - sbest;
      b[1] = sbest;
    }
    *dist = *facet >= 0 ? std::sqrt(best) : PETSC_MAX_REAL;
    return;
  }
  // 3D: the candidate whose bounding sphere's centre (the centroid c) is nearest first, then the others in the given
  // order, visiting only those whose sphere (radius r) may hold a point at the best distance so far,
  // |p - c| <= sqrt(best) + r: a skipped one is farther than the result, so the facet and coordinates are those
  // of the full scan (ties to the lower facet number, as there; a skipped facet is strictly farther, so no tie is
  // skipped). The reduced model's cubature points spent most of their time in the triangle distances of the full
  // scan, then in a second pass over the candidates (docs/rom3d.md); the lists are sorted nearest first offline, at
  // the training states, but on the finest 3D level's model (48 candidates a point) that first one was the closest
  // for 1 % of the points, and the nearest centre first takes it from 6.4-9.2 to 3.0-3.1 triangle distances a point
  // (5 % of its online time); lists of at most 32 start from the stored first.
  auto visit = [&](PetscInt f) {
    PetscReal       bb[3];
    const PetscReal dd = DistToFacet2(f, p, bb);
    if (dd < best || (dd == best && f < *facet)) {
      best   = dd;
      *facet = f;
      for (PetscInt k = 0; k < nv_; ++k) b[k] = bb[k];
    }
  };
  if (dim_ == 3) { // sphere_ is set with the vertices
    auto centre2 = [&](PetscInt i) {
      const PetscReal *c = &sphere_[4 * cand[i]];
      return (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]);
    };
    // the first visit: the stored first for short lists (sphere_block3d: 19 a point, the closest for half the points;
    // a pass over the centres cost 7 % there), the nearest centre above 32
    // (above 32 the centre distances are computed once, kept for the pruning pass: the same values, so the same visits)
    PetscInt                            first = 0;
    thread_local std::vector<PetscReal> c2;
    const bool                          kept = nc > 32;
    if (kept) {
      c2.resize(nc);
      for (PetscInt i = 0; i < nc; ++i) c2[i] = centre2(i);
      for (PetscInt i = 1; i < nc; ++i)
        if (c2[i] < c2[first]) first = i;
    }
    if (nc > 0) visit(cand[first]);
    PetscReal sb = std::sqrt(best);
    for (PetscInt i = 0; i < nc; ++i) {
      if (i == first) continue;
      const PetscReal reach = sb + sphere_[4 * cand[i] + 3];
      if ((kept ? c2[i] : centre2(i)) > reach * reach) continue;
      const PetscReal before = best;
      visit(cand[i]);
      if (best != before) sb = std::sqrt(best);
    }
  } else
    for (PetscInt i = 0; i < nc; ++i) visit(cand[i]);
  *dist = *facet >= 0 ? std::sqrt(best) : PETSC_MAX_REAL;
}

PetscErrorCode ClosestPoint::Build(const std::vector<SurfaceFacet> &facets, PetscInt dim, bool deformed)
{
  PetscFunctionBeginUser;
  SetVertices(facets, dim, deformed);
  const PetscInt nf = (PetscInt)facets.size();
  PetscReal lo[3] = {PETSC_MAX_REAL, PETSC_MAX_REAL, PETSC_MAX_REAL}, hi[3] = {PETSC_MIN_REAL, PETSC_MIN_REAL, PETSC_MIN_REAL}, hsum = 0;
  for (PetscInt f = 0; f < nf; ++f) {
    for (PetscInt k = 0; k < nv_; ++k)
      for (PetscInt d = 0; d < dim; ++d) {
        const PetscReal x = xdef_[9 * f + k * dim + d];
        lo[d] = std::min(lo[d], x);
        hi[d] = std::max(hi[d], x);
      }
    PetscReal len = 0;
    for (PetscInt d = 0; d < dim; ++d) len += PetscSqr(xdef_[9 * f + dim + d] - xdef_[9 * f + d]);
    hsum += std::sqrt(len);
  }
  const PetscReal h = nf ? std::max(hsum / nf, 1e-12) : 1.0;
  PetscInt        nbins = 1;
  for (PetscInt d = 0; d < 3; ++d) {
    if (d < dim && nf) {
      lo_[d] = lo[d];
      // about one facet per bin along the surface; cap the total bin count
      nb_[d] = std::max<PetscInt>(1, std::min<PetscInt>((PetscInt)std::ceil((hi[d] - lo[d]) / h), dim == 2 ? 4096 : 256));
      h_[d]  = std::max((hi[d] - lo[d]) / nb_[d], 1e-300);
    } else {
      lo_[d] = 0;
      nb_[d] = 1;
      h_[d]  = 1;
    }
    nbins *= nb_[d];
  }
  // CSR bins -> facets
  std::vector<std::vector<PetscInt>> lists(nbins);
  for (PetscInt f = 0; f < nf; ++f) {
    PetscInt blo[3] = {0, 0, 0}, bhi[3] = {0, 0, 0};
    for (PetscInt d = 0; d < dim; ++d) {
      PetscReal mn = PETSC_MAX_REAL, mx = PETSC_MIN_REAL;
      for (PetscInt k = 0; k < nv_; ++k) { mn = std::min(mn, xdef_[9 * f + k * dim + d]); mx = std::max(mx, xdef_[9 * f + k * dim + d]); }
      blo[d] = std::min(nb_[d] - 1, std::max<PetscInt>(0, (PetscInt)std::floor((mn - lo_[d]) / h_[d])));
      bhi[d] = std::min(nb_[d] - 1, std::max<PetscInt>(0, (PetscInt)std::floor((mx - lo_[d]) / h_[d])));
    }
    for (PetscInt i = blo[0]; i <= bhi[0]; ++i)
      for (PetscInt j = blo[1]; j <= bhi[1]; ++j)
        for (PetscInt k = blo[2]; k <= bhi[2]; ++k) lists[(i * nb_[1] + j) * nb_[2] + k].push_back(f);
  }
  binStart_.assign(nbins + 1, 0);
  binFacets_.clear();
  for (PetscInt b = 0; b < nbins; ++b) {
    binFacets_.insert(binFacets_.end(), lists[b].begin(), lists[b].end());
    binStart_[b + 1] = (PetscInt)binFacets_.size();
  }
  stamp_.assign(nf, -1);
  stampId_ = 0;
  PetscFunctionReturn(0);
}

void ClosestPoint::Candidates(const PetscReal lo[], const PetscReal hi[], std::vector<PetscInt> *c) const
{
  PetscInt blo[3] = {0, 0, 0}, bhi[3] = {0, 0, 0};
  for (PetscInt d = 0; d < dim_; ++d) {
    blo[d] = std::min(nb_[d] - 1, std::max<PetscInt>(0, (PetscInt)std::floor((lo[d] - lo_[d]) / h_[d])));
    bhi[d] = std::min(nb_[d] - 1, std::max<PetscInt>(0, (PetscInt)std::floor((hi[d] - lo_[d]) / h_[d])));
  }
  ++stampId_;
  c->clear();
  for (PetscInt i = blo[0]; i <= bhi[0]; ++i)
    for (PetscInt j = blo[1]; j <= bhi[1]; ++j)
      for (PetscInt k = blo[2]; k <= bhi[2]; ++k) {
        const PetscInt b = (i * nb_[1] + j) * nb_[2] + k;
        for (PetscInt q = binStart_[b]; q < binStart_[b + 1]; ++q) {
          const PetscInt f = binFacets_[q];
          if (stamp_[f] != stampId_) { stamp_[f] = stampId_; c->push_back(f); }
        }
      }
}

// Closest point of a segment or triangle; b = barycentric coordinates of the closest point; returns the
// squared distance.
PetscReal ClosestPoint::DistToFacet2(PetscInt f, const PetscReal p[], PetscReal b[]) const
{
  const PetscReal *x = &xdef_[9 * f];
  if (dim_ == 2) {
    const PetscReal t[2] = {x[2] - x[0], x[3] - x[1]};
    PetscReal       s    = ((p[0] - x[0]) * t[0] + (p[1] - x[1]) * t[1]) * invLen2_[f];
    s                    = std::min(1.0, std::max(0.0, s));
    b[0] = 1 - s;
    b[1] = s;
    const PetscReal q[2] = {x[0] + s * t[0] - p[0], x[1] + s * t[1] - p[1]};
    return q[0] * q[0] + q[1] * q[1];
  }
  // Triangle (Ericson, Real-Time Collision Detection, 5.1.5)
  const PetscReal *a = x, *bb = x + 3, *c = x + 6;
  auto sub = [](const PetscReal *u, const PetscReal *v, PetscReal *w) { for (int i = 0; i < 3; ++i) w[i] = u[i] - v[i]; };
  auto dot = [](const PetscReal *u, const PetscReal *v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  PetscReal ab[3], ac[3], ap[3], bp[3], cp[3];
  sub(bb, a, ab); sub(c, a, ac); sub(p, a, ap);
  PetscReal d1 = dot(ab, ap), d2 = dot(ac, ap), v, w;
  if (d1 <= 0 && d2 <= 0) { b[0] = 1; b[1] = 0; b[2] = 0; }
  else {
    sub(p, bb, bp);
    PetscReal d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) { b[0] = 0; b[1] = 1; b[2] = 0; }
    else {
      PetscReal vc = d1 * d4 - d3 * d2;
      if (vc <= 0 && d1 >= 0 && d3 <= 0) { v = d1 / (d1 - d3); b[0] = 1 - v; b[1] = v; b[2] = 0; }
      else {
        sub(p, c, cp);
        PetscReal d5 = dot(ab, cp), d6 = dot(ac, cp);
        if (d6 >= 0 && d5 <= d6) { b[0] = 0; b[1] = 0; b[2] = 1; }
        else {
          PetscReal vb = d5 * d2 - d1 * d6;
          if (vb <= 0 && d2 >= 0 && d6 <= 0) { w = d2 / (d2 - d6); b[0] = 1 - w; b[1] = 0; b[2] = w; }
          else {
            PetscReal va = d3 * d6 - d5 * d4;
            if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) { w = (d4 - d3) / ((d4 - d3) + (d5 - d6)); b[0] = 0; b[1] = 1 - w; b[2] = w; }
            else {
              PetscReal den = 1 / (va + vb + vc);
              v = vb * den; w = vc * den;
              b[0] = 1 - v - w; b[1] = v; b[2] = w;
            }
          }
        }
      }
    }
  }
  PetscReal q2 = 0;
  for (int i = 0; i < 3; ++i) {
    const PetscReal qi = b[0] * a[i] + b[1] * bb[i] + b[2] * c[i] - p[i];
    q2 += qi * qi;
  }
  return q2;
}

void ClosestPoint::Find(const PetscReal p[], PetscInt *facet, PetscReal b[], PetscReal *dist) const
{
  PetscReal best = PETSC_MAX_REAL; // squared
  *facet         = -1;
  *dist          = PETSC_MAX_REAL;
  const PetscInt nf = NumFacets();
  if (!nf) return;
  PetscReal r = 0;
  for (PetscInt d = 0; d < dim_; ++d) r = std::max(r, h_[d]);
  std::vector<PetscInt> cand;
  PetscReal             span = 0;
  for (PetscInt d = 0; d < dim_; ++d) span = std::max(span, h_[d] * nb_[d] + std::abs(p[d] - lo_[d]) + std::abs(p[d] - (lo_[d] + h_[d] * nb_[d])));
  for (;;) {
    PetscReal lo[3], hi[3];
    PetscReal nbox = 1; // bins the box covers: once they outnumber the facets, test every facet (exact)
    for (PetscInt d = 0; d < dim_; ++d) {
      lo[d] = p[d] - r;
      hi[d] = p[d] + r;
      const PetscReal a = std::max(0.0, std::floor((lo[d] - lo_[d]) / h_[d])), z = std::min<PetscReal>(nb_[d] - 1, std::floor((hi[d] - lo_[d]) / h_[d]));
      nbox *= std::max<PetscReal>(1, z - a + 1);
    }
    if (nbox > nf) {
      for (PetscInt f = 0; f < nf; ++f) {
        PetscReal       bb[3];
        const PetscReal dd = DistToFacet2(f, p, bb);
        if (dd < best || (dd == best && f < *facet)) {
          best   = dd;
          *facet = f;
          for (PetscInt k = 0; k < nv_; ++k) b[k] = bb[k];
        }
      }
      *dist = std::sqrt(best);
      return;
    }
    Candidates(lo, hi, &cand);
    for (PetscInt f : cand) {
      PetscReal bb[3];
      const PetscReal dd = DistToFacet2(f, p, bb);
      if (dd < best || (dd == best && f < *facet)) {
        best   = dd;
        *facet = f;
        for (PetscInt k = 0; k < nv_; ++k) b[k] = bb[k];
      }
    }
    if (*facet >= 0) *dist = std::sqrt(best);
    if (*dist <= r || r > span) break;
    r *= 2;
  }
}

} // namespace rbc
