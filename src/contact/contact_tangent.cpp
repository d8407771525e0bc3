// src/contact/contact_tangent.cpp: ContactMap::AssembleTangent, the derivative of the 2D contact geometry
// with respect to the displacement at the integration points of the last Assemble: the closest-point
// parameter s on the deformed master facet, the master normal n2 (smooth: interpolated unit vertex normals
// of the area-weighted facet normals; or the facet normal), the gap (z - rho) . n2 and the master shape
// values N(s). It gives the geometric stiffness H = d(K^T lambda)/du at fixed lambda and Q = d(g - K y)/du
// at a fixed field y, which the Newton step of the Kacanov loop needs (docs/fom_speed.md). The points are
// held fixed: the motion of the mortar cuts (where the closest master facet changes) is left out, which
// the segment-based rule feels at the ends of the contact zone (5e-7 to 6e-4 relative on the shipped
// scenes; fixed rules: rounding). tests/test_kacanov_newton.cpp checks it against finite differences of
// the assembly.
#include "rbcontact/contact.hpp"
#include "contact_point.hpp"
#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace rbc {

namespace {

constexpr int kMaxVar = 32; // local unknowns of one integration point (2D P2: 6 slave + 8 master at most)
using Dv            = std::array<PetscReal, kMaxVar>;

// The free global dofs one integration point depends on, numbered locally.
struct LocalVars {
  PetscInt dof[kMaxVar];
  int      n        = 0;
  bool     overflow = false;
  int      Index(PetscInt d)
  {
    if (d < 0) return -1; // constrained: not an unknown
    for (int i = 0; i < n; ++i)
      if (dof[i] == d) return i;
    if (n == kMaxVar) {
      overflow = true;
      return -1;
    }
    dof[n] = d;
    return n++;
  }
};

PetscInt VertexNode(const SurfaceFacet &F, PetscInt k)
{
  for (PetscInt a = 0; a < F.nnodes; ++a)
    if (F.nodeKind[a] == k) return a;
  return -1;
}

// Deformed position of vertex k of facet G (the closest-point search's: X + U at the vertex node) and the
// local unknowns of its components.
void DeformedVertex(const SurfaceFacet &G, PetscInt k, LocalVars *V, PetscReal x[2], int var[2])
{
  const PetscInt node = VertexNode(G, k);
  for (PetscInt d = 0; d < 2; ++d) {
    x[d]   = G.X[k * 2 + d] + (node >= 0 ? G.U[node * 2 + d] : 0.0);
    var[d] = node >= 0 ? V->Index(G.dof[node * 2 + d]) : -1;
  }
}

// Unnormalized outward normal of facet G (FacetNormal, 2D) and its derivative.
void FacetNormalD(const SurfaceFacet &G, LocalVars *V, PetscReal nf[2], Dv dnf[2])
{
  PetscReal x0[2], x1[2];
  int       v0[2], v1[2];
  DeformedVertex(G, 0, V, x0, v0);
  DeformedVertex(G, 1, V, x1, v1);
  const PetscReal o = G.outward;
  nf[0]             = o * (x1[1] - x0[1]);
  nf[1]             = -o * (x1[0] - x0[0]);
  dnf[0].fill(0.0);
  dnf[1].fill(0.0);
  if (v1[1] >= 0) dnf[0][v1[1]] += o;
  if (v0[1] >= 0) dnf[0][v0[1]] -= o;
  if (v1[0] >= 0) dnf[1][v1[0]] -= o;
  if (v0[0] >= 0) dnf[1][v0[0]] += o;
}

// n = m / |m| and dn = (I - n n^T) dm / |m| (2D).
void NormalizeD(const PetscReal m[2], const Dv dm[2], int nvar, PetscReal n[2], Dv dn[2])
{
  const PetscReal len = std::sqrt(m[0] * m[0] + m[1] * m[1]);
  for (PetscInt d = 0; d < 2; ++d) n[d] = m[d] / len;
  for (int v = 0; v < nvar; ++v) {
    const PetscReal p = n[0] * dm[0][v] + n[1] * dm[1][v];
    for (PetscInt d = 0; d < 2; ++d) dn[d][v] = (dm[d][v] - n[d] * p) / len;
  }
  for (int v = nvar; v < kMaxVar; ++v) dn[0][v] = dn[1][v] = 0.0;
}

// All ranks' triplets, in rank order (the same on every rank).
PetscErrorCode GatherTriplets(MPI_Comm comm, std::vector<PetscInt> *r, std::vector<PetscInt> *c, std::vector<PetscReal> *v)
{
  PetscMPIInt size, n = (PetscMPIInt)r->size();

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (size == 1) PetscFunctionReturn(0);
  std::vector<PetscMPIInt> counts(size), displs(size, 0);
  PetscCallMPI(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm));
  for (PetscMPIInt q = 1; q < size; ++q) displs[q] = displs[q - 1] + counts[q - 1];
  const size_t           total = (size_t)displs[size - 1] + counts[size - 1];
  std::vector<PetscInt>  ra(total), ca(total);
  std::vector<PetscReal> va(total);
  PetscCallMPI(MPI_Allgatherv(r->data(), n, MPIU_INT, ra.data(), counts.data(), displs.data(), MPIU_INT, comm));
  PetscCallMPI(MPI_Allgatherv(c->data(), n, MPIU_INT, ca.data(), counts.data(), displs.data(), MPIU_INT, comm));
  PetscCallMPI(MPI_Allgatherv(v->data(), n, MPIU_REAL, va.data(), counts.data(), displs.data(), MPIU_REAL, comm));
  r->swap(ra);
  c->swap(ca);
  v->swap(va);
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode ContactMap::AssembleTangent(MPI_Comm comm, const std::vector<PetscReal> &lambda, const std::vector<PetscInt> &D, const std::vector<PetscReal> &yD, ContactTangent *tan, bool *supported) const
{
  PetscFunctionBeginUser;
  *tan       = ContactTangent();
  *supported = slave_.dim == 2;
  if (!*supported) PetscFunctionReturn(0);
  PetscCheck((PetscInt)lambda.size() == R_ && yD.size() == D.size(), comm, PETSC_ERR_ARG_SIZ, "AssembleTangent: %zu multipliers for R = %" PetscInt_FMT ", %zu values for %zu dofs", lambda.size(), R_, yD.size(), D.size());
  // master facets at each master vertex (the smooth normal of a vertex sums their normals)
  std::unordered_map<PetscInt, std::vector<PetscInt>> vfacets;
  for (PetscInt m = 0; m < (PetscInt)masterAll_.size(); ++m)
    for (PetscInt k = 0; k < 2; ++k) vfacets[masterAll_[m].vglobal[k]].push_back(m);
  PetscInt missing = 0, overflow = 0;
  // y at component i of the nodes of facet G: yD on free dofs, the Dirichlet value on constrained ones
  auto yAt = [&](const SurfaceFacet &G, PetscInt i) -> PetscReal {
    if (G.dof[i] < 0) return G.Ubc[i];
    const auto it = std::lower_bound(D.begin(), D.end(), G.dof[i]);
    if (it == D.end() || *it != G.dof[i]) {
      ++missing;
      return 0.0;
    }
    return yD[it - D.begin()];
  };

  for (const IntegrationPoint &P : points_) {
    const SurfaceFacet &F = slave_.facets[P.s], &M = masterAll_[P.m];
    const PetscInt     *rows = F.row.data();
    const PetscReal     w    = P.w;
    PetscReal           psi[2], pres = 0;
    bool                anyActive = false;
    for (PetscInt k = 0; k < 2; ++k) {
      psi[k] = MultiplierShape(multiplier, 2, P.b, k);
      if (rows[k] < 0 || rows[k] >= R_) continue;
      pres += lambda[rows[k]] * psi[k];
      anyActive = anyActive || (lambda[rows[k]] > 0 && psi[k] != 0.0);
    }
    if (pres == 0.0 && !anyActive) continue;

    LocalVars V;
    // the deformed slave point p = z + u_1(z)
    PetscReal Ns[6], z[2] = {0, 0}, p[2];
    Dv        dp[2];
    dp[0].fill(0.0);
    dp[1].fill(0.0);
    FacetBasis(F, P.b, Ns);
    for (PetscInt k = 0; k < 2; ++k)
      for (PetscInt d = 0; d < 2; ++d) z[d] += P.b[k] * F.X[k * 2 + d];
    for (PetscInt d = 0; d < 2; ++d) {
      p[d] = z[d];
      for (PetscInt a = 0; a < F.nnodes; ++a) {
        p[d] += Ns[a] * F.U[a * 2 + d];
        const int v = V.Index(F.dof[a * 2 + d]);
        if (v >= 0) dp[d][v] += Ns[a];
      }
    }
    // the closest point on the deformed master facet: s = (p - y0).t / |t|^2, t = y1 - y0 (clamped: fixed)
    PetscReal y0[2], y1[2];
    int       v0[2], v1[2];
    DeformedVertex(M, 0, &V, y0, v0);
    DeformedVertex(M, 1, &V, y1, v1);
    Dv dy0[2], dy1[2], ds;
    for (PetscInt d = 0; d < 2; ++d) {
      dy0[d].fill(0.0);
      dy1[d].fill(0.0);
      if (v0[d] >= 0) dy0[d][v0[d]] = 1;
      if (v1[d] >= 0) dy1[d][v1[d]] = 1;
    }
    ds.fill(0.0);
    const PetscReal t[2] = {y1[0] - y0[0], y1[1] - y0[1]}, L2 = t[0] * t[0] + t[1] * t[1], s = P.bm[1];
    if (s > 0 && s < 1 && L2 > 0)
      for (int v = 0; v < V.n; ++v) {
        PetscReal a = 0;
        for (PetscInt d = 0; d < 2; ++d) a += (dp[d][v] - dy0[d][v]) * t[d] + (p[d] - y0[d]) * (dy1[d][v] - dy0[d][v]) - 2 * s * t[d] * (dy1[d][v] - dy0[d][v]);
        ds[v] = a / L2;
      }
    // rho (undeformed, physical at mu) and the master normal
    PetscReal rho[2], n2[2];
    Dv        dn2[2];
    for (PetscInt d = 0; d < 2; ++d) rho[d] = (1 - s) * M.X[d] + s * M.X[2 + d];
    if (smoothNormal) {
      PetscReal Na[2][2];
      Dv        dNa[2][2];
      for (PetscInt k = 0; k < 2; ++k) {
        PetscReal m[2] = {0, 0};
        Dv        dm[2];
        dm[0].fill(0.0);
        dm[1].fill(0.0);
        for (PetscInt f : vfacets[M.vglobal[k]]) {
          PetscReal nf[2];
          Dv        dnf[2];
          FacetNormalD(masterAll_[f], &V, nf, dnf);
          for (PetscInt d = 0; d < 2; ++d) {
            m[d] += nf[d];
            for (int v = 0; v < kMaxVar; ++v) dm[d][v] += dnf[d][v];
          }
        }
        NormalizeD(m, dm, kMaxVar, Na[k], dNa[k]);
      }
      PetscReal nt[2];
      Dv        dnt[2];
      for (PetscInt d = 0; d < 2; ++d) {
        nt[d] = (1 - s) * Na[0][d] + s * Na[1][d];
        for (int v = 0; v < kMaxVar; ++v) dnt[d][v] = (Na[1][d] - Na[0][d]) * ds[v] + (1 - s) * dNa[0][d][v] + s * dNa[1][d][v];
      }
      NormalizeD(nt, dnt, kMaxVar, n2, dn2);
    } else {
      PetscReal nf[2];
      Dv        dnf[2];
      FacetNormalD(M, &V, nf, dnf);
      NormalizeD(nf, dnf, kMaxVar, n2, dn2);
    }
    if (V.overflow) {
      ++overflow;
      continue;
    }
    const PetscInt nvar = V.n;
    Dv             dgap;
    for (int v = 0; v < nvar; ++v) {
      dgap[v] = 0;
      for (PetscInt d = 0; d < 2; ++d) dgap[v] += -(M.X[2 + d] - M.X[d]) * ds[v] * n2[d] + (z[d] - rho[d]) * dn2[d][v];
    }
    // master shape values and dN/ds (P1: 1 - s, s; P2: b_k (2 b_k - 1), 4 b0 b1)
    PetscReal Nm[6], dNm[6];
    FacetBasis(M, P.bm, Nm);
    {
      const bool      quadratic = M.nnodes > M.nv;
      const PetscReal b0 = P.bm[0], b1 = P.bm[1];
      for (PetscInt a = 0; a < M.nnodes; ++a) {
        const PetscInt k = M.nodeKind[a];
        dNm[a]           = k == 0 ? (quadratic ? -(4 * b0 - 1) : -1.0) : k == 1 ? (quadratic ? 4 * b1 - 1 : 1.0) : 4 * (b0 - b1);
      }
    }
    // H: d/du of (K^T lambda) = sum of w pres (-Ns n2 on the slave, +Nm n2 on the master)
    if (pres != 0.0) {
      for (PetscInt a = 0; a < F.nnodes; ++a)
        for (PetscInt d = 0; d < 2; ++d) {
          const PetscInt out = F.dof[a * 2 + d];
          if (out < 0) continue;
          for (int v = 0; v < nvar; ++v) {
            const PetscReal val = -w * pres * Ns[a] * dn2[d][v];
            if (val == 0.0) continue;
            tan->hRow.push_back(out);
            tan->hCol.push_back(V.dof[v]);
            tan->hVal.push_back(val);
          }
        }
      for (PetscInt a = 0; a < M.nnodes; ++a)
        for (PetscInt d = 0; d < 2; ++d) {
          const PetscInt out = M.dof[a * 2 + d];
          if (out < 0) continue;
          for (int v = 0; v < nvar; ++v) {
            const PetscReal val = w * pres * (dNm[a] * ds[v] * n2[d] + Nm[a] * dn2[d][v]);
            if (val == 0.0) continue;
            tan->hRow.push_back(out);
            tan->hCol.push_back(V.dof[v]);
            tan->hVal.push_back(val);
          }
        }
    }
    // Q: d/du of (g - K y) = sum of w psi_k (gap + (y_1(z) - y_2(rho)) . n2), rows with lambda > 0
    if (anyActive) {
      PetscReal ys[2] = {0, 0}, ym[2] = {0, 0}, yms[2] = {0, 0}; // y_1(z), y_2(rho), d y_2(rho) / ds
      for (PetscInt d = 0; d < 2; ++d) {
        for (PetscInt a = 0; a < F.nnodes; ++a) ys[d] += Ns[a] * yAt(F, a * 2 + d);
        for (PetscInt a = 0; a < M.nnodes; ++a) {
          const PetscReal ya = yAt(M, a * 2 + d);
          ym[d] += Nm[a] * ya;
          yms[d] += dNm[a] * ya;
        }
      }
      for (PetscInt k = 0; k < 2; ++k) {
        if (rows[k] < 0 || rows[k] >= R_ || !(lambda[rows[k]] > 0) || psi[k] == 0.0) continue;
        for (int v = 0; v < nvar; ++v) {
          PetscReal a = dgap[v];
          for (PetscInt d = 0; d < 2; ++d) a += (ys[d] - ym[d]) * dn2[d][v] - yms[d] * ds[v] * n2[d];
          const PetscReal val = w * psi[k] * a;
          if (val == 0.0) continue;
          tan->qRow.push_back(rows[k]);
          tan->qCol.push_back(V.dof[v]);
          tan->qVal.push_back(val);
        }
      }
    }
  }
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &missing, 1, MPIU_INT, MPI_SUM, comm));
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &overflow, 1, MPIU_INT, MPI_SUM, comm));
  PetscCheck(missing == 0, comm, PETSC_ERR_PLIB, "AssembleTangent: %" PetscInt_FMT " facet dofs outside the contact dofs D", missing);
  if (overflow) { // a master vertex in many facets: not supported (the caller keeps the plain iterate)
    *tan       = ContactTangent();
    *supported = false;
    PetscFunctionReturn(0);
  }
  PetscCall(GatherTriplets(comm, &tan->hRow, &tan->hCol, &tan->hVal));
  PetscCall(GatherTriplets(comm, &tan->qRow, &tan->qCol, &tan->qVal));
  PetscFunctionReturn(0);
}

} // namespace rbc
