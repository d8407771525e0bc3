// src/contact/contact_point.hpp: the pointwise kernel of the contact map, shared by the full-order
// assembly (ContactMap) and the reduced model's evaluator (ContactPatch), so that both compute the same
// projection, normal and gap: facet measure and normal, and the evaluation of one slave integration
// point (deformed slave point, closest point on the deformed master, master normal, gap, shape values).
// Internal (not installed).
#pragma once
#include <cmath>
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
  const PetscInt nv = dim;
  PetscReal      z[3] = {0, 0, 0}, zdef[3] = {0, 0, 0};
  FacetBasis(F, b, e->Ns);
  for (PetscInt k = 0; k < nv; ++k)
    for (PetscInt d = 0; d < dim; ++d) z[d] += b[k] * F.X[k * dim + d];
  for (PetscInt d = 0; d < dim; ++d) {
    zdef[d] = z[d];
    for (PetscInt a = 0; a < F.nnodes; ++a) zdef[d] += e->Ns[a] * F.U[a * dim + d];
  }
  e->bm[0] = e->bm[1] = e->bm[2] = 0;
  find(zdef, &e->m, e->bm, &e->dist);
  const SurfaceFacet &M      = masters[e->m];
  PetscReal           rho[3] = {0, 0, 0}, n2[3] = {0, 0, 0};
  FacetBasis(M, e->bm, e->Nm);
  for (PetscInt k = 0; k < nv; ++k)
    for (PetscInt d = 0; d < dim; ++d) rho[d] += e->bm[k] * M.X[k * dim + d];
  if (smooth) {
    for (PetscInt k = 0; k < nv; ++k) {
      const PetscReal *a = vnormal(M, k);
      for (PetscInt d = 0; d < dim; ++d) n2[d] += e->bm[k] * a[d];
    }
  } else FacetNormal(mxdef + 9 * e->m, dim, M.outward, n2);
  PetscReal nn = 0;
  for (PetscInt d = 0; d < dim; ++d) nn += n2[d] * n2[d];
  nn = std::sqrt(nn);
  e->gap = 0;
  for (PetscInt d = 0; d < 3; ++d) e->n2[d] = d < dim ? n2[d] / nn : 0.0;
  for (PetscInt d = 0; d < dim; ++d) e->gap += (z[d] - rho[d]) * e->n2[d];
}

} // namespace rbc
