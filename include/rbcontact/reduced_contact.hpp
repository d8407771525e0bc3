// rbcontact/reduced_contact.hpp: the contact map of the reduced model, evaluated pointwise. A
// ContactPatch is a compact copy of (part of) the contact surfaces: slave facets carrying fixed
// integration points x (a composite Gauss rule on the reference slave facets), master facets, and
// their displacement nodes carrying the reduced basis values theta_n and the Dirichlet values. At a
// parameter mu and a nodal displacement (reduced coordinates v or a full-order field) it evaluates
//   kappa(n, x) = w_x(mu) [ -theta_n|_1(x) . n2 + theta_n|_2(rho(x)) . n2 ]        (n = 1..N)
//   gamma(x)    = w_x(mu) [ (z - rho(x)) . n2 + (uD|_1(x) - uD|_2(rho(x))) . n2 ]
// with the projection rho and the master normal n2 of the full-order contact map (the same kernel,
// src/contact/contact_point.hpp), so that (K V)_{i n} = sum_x psi_i(x) kappa(n, x) and
// g_i = sum_x psi_i(x) gamma(x) for the composite rule. The full patch (every slave facet of the dual
// basis support, the whole master) serves the offline stage and the "no EIM" reduced model; Restrict()
// keeps the facets around the EIM points only: the online data, independent of the mesh size.
#pragma once
#include <petscsys.h>
#include <array>
#include <string>
#include <vector>
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/fork_join.hpp"
#include "rbcontact/geometry_map.hpp"

namespace rbc {

class ContactPatch {
public:
  struct Point {
    PetscInt  facet = -1;       // slave facet (patch index)
    PetscReal b[3]  = {0, 0, 0}; // barycentric coordinates on it
    PetscReal wfrac = 0;        // weight / facet measure
    PetscInt  row[3] = {-1, -1, -1}; // canonical multiplier row of vertex k (psi = b[k])
  };

  // Full patch from a set-up contact map whose surfaces hold the Dirichlet values (after an
  // Assemble). modes: N x ndofs row-major, canonical dof order. Points on the slave facets with a
  // vertex row in support (canonical multiplier rows; empty = all), nsub x (map's Gauss rule) per facet.
  // Collective (gathers the surfaces); the result is identical on every rank.
  PetscErrorCode BuildFull(MPI_Comm comm, const ContactMap &map, const CanonicalOrder &order, const std::vector<PetscReal> &modes, PetscInt N, const std::vector<char> &support, PetscInt nsub);
  // The patch of the points keep: their slave facets; as master candidates of each point the facets
  // it projected onto (hits[p], master patch indices, collected over the offline evaluations) grown
  // by rings neighbours; one more ring for the vertex normals. Nodes renumbered; theta kept.
  void Restrict(const std::vector<PetscInt> &keep, const std::vector<std::vector<PetscInt>> &hits, PetscInt rings, ContactPatch *out) const;
  // The patch with the basis functions cols (indices into 0..N-1), in that order.
  void SelectBasis(const std::vector<PetscInt> &cols, ContactPatch *out) const;

  // Physical geometry at mu (map may be null: identity). The facets of a body whose affine map is bitwise the one of
  // the previous call keep their coordinates (ring_on_block: the block's, for every radius).
  void SetGeometry(const GeometryMap *map, const std::vector<PetscReal> &mu);
  // Nodal displacement: U = theta v + uD (reduced coordinates, length N) or a given nodal field
  // (nnode x dim, Dirichlet values included).
  void SetReduced(const PetscReal *v);
  // pool (may be null): the facets' copies, deformed master vertices and facet normals in parts on its threads
  void SetNodal(const std::vector<PetscReal> &U, ForkJoin *pool = nullptr);
  // Nodal field (nnode x dim) of a full-order free-dof vector in canonical order (Dirichlet values added).
  void NodalFromCanonical(const std::vector<PetscReal> &u, std::vector<PetscReal> *U) const;
  // kappa (np x N, row-major) and gamma (np) at points idx[0..np); hit (optional): master facet found;
  // wn (optional, np x dim): the point's weight times its unit master normal, w n2 (the resultant contact
  // force is sum_x lambda(x) w_x n2(x)). Returns the number of projections that fell on the edge of a
  // restricted patch (out of range).
  PetscInt Evaluate(const PetscInt *idx, PetscInt np, PetscReal *kappa, PetscReal *gamma, PetscInt *hit, PetscReal *wn = nullptr) const;
  // The same before the combination with theta: kappa(i, :) = sum_{t < nt[i]} coef[i][t] theta(rowIdx[i][t], :)
  // (at most MaxTerms terms per point, stored with stride MaxTerms), and gamma. Same return value.
  static constexpr PetscInt MaxTerms = 36; // 2 sides x (<= 6 nodes x 3 dims: SurfaceFacet::dof)
  PetscInt EvaluateCoefficients(const PetscInt *idx, PetscInt np, PetscInt *nt, PetscInt *rowIdx, PetscReal *coef, PetscReal *gamma, PetscReal *wn = nullptr, PetscInt *hit = nullptr) const;
  // One point's kappa row (N) from its nt terms: the combination Evaluate makes (the same kernel, the same bits).
  void KappaRow(PetscInt nt, const PetscInt *rowIdx, const PetscReal *coef, PetscReal *kappa) const;
  PetscInt NumPoints() const { return (PetscInt)points.size(); }
  // The dofs [0, TermDofs()) hold every node a term can fall on (slave facets, searchable master facets); the
  // rest serve the master vertex normals only. Restrict numbers the term nodes first (older files: up to nnode * dim).
  PetscInt TermDofs() const;

  // Serialization: named float64 arrays (row-major) and their shapes, for the ROM file.
  void Serialize(std::vector<std::pair<std::string, std::pair<std::vector<unsigned long long>, std::vector<double>>>> *out) const;
  PetscErrorCode Deserialize(const std::string &file, const std::string &group);

  PetscInt dim = 2, N = 0, nnode = 0, nvertex = 0;
  bool     smoothNormal = true;
  std::vector<SurfaceFacet> slave, master; // dof[a * dim + d] = node * dim + d; master vglobal: patch vertex ids
  std::vector<PetscInt>     canon;         // (nnode * dim) canonical free dof, -1: constrained (offline only, not serialized)
  std::vector<PetscReal>    theta;         // (nnode * dim) x N
  std::vector<PetscReal>    uD;            // nnode x dim
  std::vector<char>         searchable;    // master facet may be a projection target
  std::vector<char>         vertexEnd;     // master patch vertex that ends the full master surface
  std::vector<Point>        points;
  std::vector<PetscInt>     candStart, cand; // per point master candidates (CSR); empty: all searchable, binned

private:
  // The master's deformed vertices and vertex normals from the facets' U (pool: in parts on its threads)
  void PrepareMaster(ForkJoin *pool = nullptr);
  PetscInt PointTerms(PetscInt p, PetscInt *nt, PetscInt rowIdx[], PetscReal coef[], PetscReal *gamma, PetscInt *hit, PetscReal *wn) const;
  std::vector<PetscReal> meas_;    // slave facet measure at mu
  std::vector<PetscReal> vnormal_; // nvertex x 3
  std::vector<PetscReal> fnormal_; // master facets x 3: their normals (PrepareMaster, smooth normals)
  std::vector<PetscInt>  vcount_;  // per point scratch
  ClosestPoint           cp_;
  // SetGeometry's last affine map of bodies 0..7 (geomSet_: applied to every facet of that body since the facets were set)
  std::array<Affine, 8> geomAff_{};
  std::array<char, 8>   geomSet_{};
  bool                   binned_ = false;
};

} // namespace rbc
