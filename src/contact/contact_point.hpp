// src/contact/contact_point.hpp: the pointwise kernel of the contact map, shared by the full-order
// assembly (ContactMap) and the reduced model's evaluator (ContactPatch), so that both compute the same
// projection, normal and gap: facet measure and normal, and the evaluation of one slave integration
// point (deformed slave point, closest point on the deformed master, master normal, gap, shape values).
// Internal (not installed).
#pragma once
#include <cmath>
#include <limits>
#include <vector>
#include "rbcontact/contact.hpp"

namespace rbc {

inline PetscReal FacetMeasure(const PetscReal *x, PetscInt dim)
{
  if (dim == 2) return std::hypot(x[2] - x[0], x[3] - x[1]);
  const PetscReal a[3] = {x[3] - x[0], x[4] - x[1], x[5] - x[2]}, b[3] = {x[6] - x[0], x[7] - x[1], x[8] - x[2]};
  const PetscReal c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  return 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

// Unnormalized outward normal of a facet with vertices x (length / area weighted).
inline void FacetNormal(const PetscReal *x, PetscInt dim, PetscReal outward, PetscReal n[])
{
  if (dim == 2) {
    n[0] = outward * (x[3] - x[1]);
    n[1] = -outward * (x[2] - x[0]);
    n[2] = 0;
  } else {
    const PetscReal a[3] = {x[3] - x[0], x[4] - x[1], x[5] - x[2]}, b[3] = {x[6] - x[0], x[7] - x[1], x[8] - x[2]};
    n[0] = outward * 0.5 * (a[1] * b[2] - a[2] * b[1]);
    n[1] = outward * 0.5 * (a[2] * b[0] - a[0] * b[2]);
    n[2] = outward * 0.5 * (a[0] * b[1] - a[1] * b[0]);
  }
}

// The unit vertex normal from the accumulated facet normals a (in place): the callers normalize once per
// vertex, not once per integration point and vertex.
inline void NormalizeVertexNormal(PetscReal a[3])
{
  const PetscReal an = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  for (PetscInt d = 0; d < 3; ++d) a[d] /= an;
}

// One slave integration point: slave shape values Ns, closest master facet m (index into the master
// list) at barycentric bm with shape values Nm, unit master normal n2, and the gap (z - rho) . n2 with
// z, rho the undeformed (physical at mu) positions of the slave point and of its master image.
struct ContactPointEval {
  PetscInt  m = -1;
  PetscReal bm[3] = {0, 0, 0}, Ns[6], Nm[6], n2[3] = {0, 0, 0}, gap = 0, dist = 0;
};

// vnormal(M, k): unit normal of vertex k of master facet M (smooth normals; NormalizeVertexNormal).
// find(zdef, &m, bm, &dist): closest point of the deformed master.
template <class Find, class VertexNormal>
inline void EvaluateContactPoint(const SurfaceFacet &F, PetscInt dim, const PetscReal b[], const std::vector<SurfaceFacet> &masters, const PetscReal *mxdef, bool smooth, Find &&find, VertexNormal &&vnormal, ContactPointEval *e)
{
  // the sums over vertices in scalars, not in small arrays on the stack (the compiler paired two components in one
  // vector add whose load waited on the scalar stores of the previous vertex: ~20 % of the reduced model's point
  // kernel); the same operations in the same order as the loops they replace
  const PetscInt nv = dim;
  const bool     d3 = dim == 3;
  PetscReal      z[3], zdef[3];
  FacetBasis(F, b, e->Ns);
  {
    PetscReal z0 = 0, z1 = 0, z2 = 0;
    for (PetscInt k = 0; k < nv; ++k) {
      const PetscReal *X = &F.X[k * dim];
      z0 += b[k] * X[0];
      z1 += b[k] * X[1];
      if (d3) z2 += b[k] * X[2];
    }
    PetscReal w0 = z0, w1 = z1, w2 = z2;
    for (PetscInt a = 0; a < F.nnodes; ++a) {
      const PetscReal *U = &F.U[a * dim];
      w0 += e->Ns[a] * U[0];
      w1 += e->Ns[a] * U[1];
      if (d3) w2 += e->Ns[a] * U[2];
    }
    z[0]    = z0;
    z[1]    = z1;
    z[2]    = z2;
    zdef[0] = w0;
    zdef[1] = w1;
    zdef[2] = w2;
  }
  e->bm[0] = e->bm[1] = e->bm[2] = 0;
  find(zdef, &e->m, e->bm, &e->dist);
  // no facet found: a non-finite point (a corrupt file, a diverged iterate). Facet 0 stands in and the gap is NaN,
  // which the callers' checks of non-finite terms report (never an index of -1)
  const bool lost = e->m < 0;
  if (lost) {
    e->m     = 0;
    e->bm[0] = 1;
  }
  const SurfaceFacet &M = masters[e->m];
  PetscReal           r0 = 0, r1 = 0, r2 = 0, n0 = 0, n1 = 0, nz = 0;
  FacetBasis(M, e->bm, e->Nm);
  for (PetscInt k = 0; k < nv; ++k) {
    const PetscReal *X = &M.X[k * dim];
    r0 += e->bm[k] * X[0];
    r1 += e->bm[k] * X[1];
    if (d3) r2 += e->bm[k] * X[2];
  }
  if (smooth) {
    for (PetscInt k = 0; k < nv; ++k) {
      const PetscReal *a = vnormal(M, k);
      n0 += e->bm[k] * a[0];
      n1 += e->bm[k] * a[1];
      if (d3) nz += e->bm[k] * a[2];
    }
  } else {
    PetscReal n2[3];
    FacetNormal(mxdef + 9 * e->m, dim, M.outward, n2);
    n0 = n2[0];
    n1 = n2[1];
    nz = d3 ? n2[2] : 0;
  }
  PetscReal nn = n0 * n0 + n1 * n1;
  if (d3) nn += nz * nz;
  nn       = std::sqrt(nn);
  e->n2[0] = n0 / nn;
  e->n2[1] = n1 / nn;
  e->n2[2] = d3 ? nz / nn : 0.0;
  e->gap   = 0;
  e->gap += (z[0] - r0) * e->n2[0];
  e->gap += (z[1] - r1) * e->n2[1];
  if (d3) e->gap += (z[2] - r2) * e->n2[2];
  if (lost) e->gap = std::numeric_limits<PetscReal>::quiet_NaN();
}

} // namespace rbc
