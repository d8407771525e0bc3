// rbcontact/contact.hpp: the discrete non-penetration constraint K(u) v <= g(u) between a slave and a
// master surface of one DMPlex (non-matching meshes). Owns the surface extraction (facets, their
// closure dofs, outward normals), the gathering of the master surface on every rank, the closest-point
// search on the deformed master (uniform bins), and the assembly of K (R x ndofs, MPIAIJ) and g by
// Gauss quadrature on the slave facets (mortar-like) or by nodal collocation. Dimension-generic:
// 2D segments now, 3D triangles through the same code paths. See docs/contact.md for the formulas.
#pragma once
#include <petscdmplex.h>
#include <petscmat.h>
#include <array>
#include <string>
#include <vector>
#include "rbcontact/elasticity.hpp"
#include "rbcontact/geometry_map.hpp"

namespace rbc {

// One surface facet with its displacement nodes (P1: vertices; P2: vertices + edge midpoints).
struct SurfaceFacet {
  PetscInt                     nv = 0;       // geometric vertices (dim)
  std::array<PetscReal, 9>     X{};          // vertex coordinates (reference), nv x dim
  std::array<PetscInt, 3>      vglobal{};    // global vertex numbers (for nodal normals, multiplier rows)
  PetscInt                     nnodes = 0;   // displacement nodes (<= 6)
  std::array<PetscReal, 18>    U{};          // node displacements, nnodes x dim (current iterate)
  std::array<PetscInt, 18>     dof{};        // node global dofs, nnodes x dim; < 0: constrained
  std::array<PetscReal, 18>    Ubc{};        // Dirichlet values of constrained dofs
  std::array<PetscInt, 6>      nodeKind{};   // node i: vertex k (0..2) or edge (3 + e, e = edge (0,1),(1,2),(0,2))
  PetscReal                    outward = 1;  // sign making the facet normal point out of its body
  std::array<PetscReal, 9>     Xref{};       // reference vertex coordinates (X = h_body(mu)(Xref))
  PetscInt                     body = -1;    // body of the facet's cell
  std::array<PetscInt, 3>      row{{-1, -1, -1}}; // slave facets: multiplier row of each vertex
};

// Lagrange basis of the facet nodes at barycentric coordinates b (size nv).
void FacetBasis(const SurfaceFacet &f, const PetscReal b[], PetscReal N[]);

// The slave or master surface: the local facets of a labelled boundary.
class ContactSurface {
public:
  PetscErrorCode Build(const Elasticity &elas, const std::string &label);
  // Refreshes U (current displacement, full local field with Dirichlet values) of every facet.
  PetscErrorCode Update(const Elasticity &elas, Vec uloc);
  // All ranks' facets (for the master).
  PetscErrorCode Gather(MPI_Comm comm, std::vector<SurfaceFacet> *all) const;
  // Physical coordinates X = h_body(mu)(Xref) (identity map: X = Xref).
  void SetGeometry(const GeometryMap *map, const std::vector<PetscReal> &mu);
  std::vector<SurfaceFacet> facets;
  std::vector<PetscInt>     points; // DMPlex facet points, aligned with facets
  PetscInt                  dim = 0;
};

// Closest-point search on a deformed facet soup (uniform bins over facet bounding boxes).
class ClosestPoint {
public:
  // deformed = true: vertices at X + U (vertex dofs); false: reference X.
  PetscErrorCode Build(const std::vector<SurfaceFacet> &facets, PetscInt dim, bool deformed);
  // Only the deformed vertex positions (no bins): for FindAmong on small facet sets.
  void SetVertices(const std::vector<SurfaceFacet> &facets, PetscInt dim, bool deformed);
  // The same in parts (threads): ResizeVertices once, then SetVerticesOf on disjoint ranges [a, b) covering the facets
  void ResizeVertices(PetscInt nf, PetscInt dim);
  void SetVerticesOf(const std::vector<SurfaceFacet> &facets, bool deformed, PetscInt a, PetscInt b);
  // Closest point of p among the facets cand[0..nc) (linear scan, same tie rule as Find).
  void FindAmong(const PetscReal p[], const PetscInt *cand, PetscInt nc, PetscInt *facet, PetscReal b[], PetscReal *dist) const;
  // Closest point of p: facet index, barycentric coordinates, distance.
  void Find(const PetscReal p[], PetscInt *facet, PetscReal b[], PetscReal *dist) const;
  // Deformed vertex positions of facet f.
  const PetscReal *Vertices(PetscInt f) const { return &xdef_[9 * f]; }
  PetscInt NumFacets() const { return (PetscInt)(xdef_.size() / 9); }
  // Squared distance from p to facet f, b its closest point's barycentric coordinates (the searches
  // compare squares: no square root per facet).
  PetscReal DistToFacet2(PetscInt f, const PetscReal p[], PetscReal b[]) const;
  // The facets whose bins meet the box [lo, hi] (a superset of those whose bounding box meets it; after Build).
  void      Candidates(const PetscReal lo[], const PetscReal hi[], std::vector<PetscInt> *c) const;

private:
  PetscInt              dim_ = 2, nv_ = 2;
  std::vector<PetscReal> xdef_;
  std::vector<PetscReal> invLen2_; // 2D: 1 / |x1 - x0|^2 per facet (0 for a degenerate one), set with the vertices
  std::vector<PetscReal> sphere_;  // per facet a bounding sphere (3D: centroid, radius; 2D: midpoint, 0, half length), set with the vertices
  PetscReal             lo_[3] = {0, 0, 0}, h_[3] = {1, 1, 1};
  PetscInt              nb_[3] = {1, 1, 1};
  std::vector<PetscInt> binStart_, binFacets_;
  mutable std::vector<PetscInt> stamp_;
  mutable PetscInt      stampId_ = 0;
};

// What one assembly produces.
struct ContactSystem {
  Mat       K = nullptr;       // R x ndofs (rows: slave vertices, owned where the vertex is owned)
  Vec       g = nullptr;       // R, gap (Dirichlet lifting included)
  Vec       weight = nullptr;  // R, int psi_i over the slave surface (lambda_i is the nodal pressure; force = lambda_i weight_i)
  Vec       normal[3] = {nullptr, nullptr, nullptr}; // R, mean master normal of row i (int psi_i n2 / weight_i)
  Vec       coord[3]  = {nullptr, nullptr, nullptr}; // R, coordinates of slave vertex i in the current geometry (physical at mu)
  Vec       coordRef[3] = {nullptr, nullptr, nullptr}; // R, its reference (mesh file) coordinates: the canonical multiplier order
  PetscInt  R = 0;
  ~ContactSystem();
  PetscErrorCode Destroy();
};

// Gauss: segment-based (mortar) in 2D; Composite: nsub equal pieces per slave facet, Gauss on each (fixed
// points, used by the reduced model); Nodal: collocation at the slave nodes.
enum class ContactQuadrature { Gauss, Composite, Nodal };

// Multiplier shape functions on a slave facet (nv vertices, barycentric b): the standard P1 hats
// psi_k = b_k, or the dual (biorthogonal) ones psi_k = (nv + 1) b_k - 1, for which
// int psi_k phi_j = delta_kj int phi_j on every facet (Wohlmuth): the slave block of K is diagonal
// (lumped), and lambda_i is still the nodal pressure with int psi_i = int phi_i (docs/contact.md).
enum class ContactMultiplier { Standard, Dual };

// The derivative of the contact geometry with respect to the displacement u at which K(u), g(u) were
// assembled (ContactMap::AssembleTangent; docs/fom_speed.md "Newton on the contact dofs"), as triplets on
// global free dofs, the same on every rank (gathered in rank order):
//   H_ij = d (K(u)^T lambda)_i / du_j  at fixed multipliers lambda (the geometric stiffness),
//   Q_rj = d (g(u) - K(u) y)_r / du_j  at a fixed field y, for the rows r with lambda_r > 0.
struct ContactTangent {
  std::vector<PetscInt>  hRow, hCol, qRow, qCol;
  std::vector<PetscReal> hVal, qVal;
};
inline PetscReal MultiplierShape(ContactMultiplier m, PetscInt nv, const PetscReal b[], PetscInt k) { return m == ContactMultiplier::Dual ? (nv + 1) * b[k] - 1 : b[k]; }

// The contact map: slave/master surfaces of a scene and the assembly of K(u), g(u).
class ContactMap {
public:
  // Options: -contact_quadrature gauss|nodal, -contact_quadrature_points n, -contact_normal smooth|facet,
  // -contact_multiplier dual|standard (nodal quadrature: standard, collocation is already diagonal),
  // -contact_segment_search pair|full (2D mortar segments: how the switches of the closest master facet
  // are bisected; the same cuts, full = the closest-point search at every bisection step, the reference),
  // -contact_master_search all|near (each rank holds every master facet, or only those within a margin of its
  // slave facets' bounding box: a slave point whose closest master facet lies within the margin less a band of
  // facet diameters gets the answer of all; a point beyond is out of reach, its row an inactive constraint (its
  // distance to the master as gap, K from the closest facet held); a rank with slave facets and no master facet,
  // or a margin leaving less than 4 slave facet diameters of exact reach, or below the least reach of any point
  // (2 slave + 3 master facet diameters), makes every rank fall back to all for that assembly), -contact_master_search_margin m (default: half the slave surface's bounding-box diagonal +
  // 4 master + 2 slave facet diameters).
  PetscErrorCode Setup(const Elasticity &elas, const std::string &slave, const std::string &master);
  // Moves both surfaces to the physical configuration at mu (reference configuration + map).
  void SetGeometry(const GeometryMap *map, const std::vector<PetscReal> &mu);
  // Assembles K(u), g(u) at the full local field uloc (Dirichlet values included).
  PetscErrorCode Assemble(const Elasticity &elas, Vec uloc, ContactSystem *sys);
  // The tangent of the last Assemble (same u, same integration points; collective): lambda (R, every
  // rank), y on the sorted free dofs D (yD, every rank; constrained dofs take their Dirichlet values).
  // 2D only: *supported = false in 3D, or where a point depends on more than 32 dofs (nothing computed).
  // The integration points are held fixed: the motion of the mortar cuts is left out (docs/fom_speed.md).
  PetscErrorCode AssembleTangent(MPI_Comm comm, const std::vector<PetscReal> &lambda, const std::vector<PetscInt> &D, const std::vector<PetscReal> &yD, ContactTangent *tan, bool *supported) const;
  PetscInt NumMultipliers() const { return R_; }
  // The free global dofs the constraint rows can touch (slave and master facet closures), sorted,
  // the same on every rank.
  PetscErrorCode SurfaceDofs(MPI_Comm comm, std::vector<PetscInt> *D) const;
  // Multiplier rows of the slave vertices that end the slave surface (2D: the vertices of a single
  // slave facet; 3D: the vertices of an edge of a single slave facet) and, per such row, the unit outward normal
  // (reference mesh; 3D: of the sum of them) of the body's boundary facets that continue the surface there (zero if
  // none), the same on every rank (from Setup).
  const std::vector<PetscInt> &SlaveEndRows() const { return endRows_; }
  // 2D: multiplier rows (global, gathered on every rank) with an integration point that the last Assemble
  // projected past an end of the master surface (clamped to its end vertex, beyond it along the surface).
  PetscErrorCode PastMasterEndRows(MPI_Comm comm, std::vector<PetscInt> *rows) const;
  const std::vector<std::array<PetscReal, 3>> &SlaveEndNextNormals() const { return endNext_; }
  const ContactSurface &Slave() const { return slave_; }
  const ContactSurface &Master() const { return master_; }
  const std::string    &SlaveName() const { return slaveName_; }   // -contact_slave
  const std::string    &MasterName() const { return masterName_; } // -contact_master
  // Per multiplier row, the sum of the outward normals (area-weighted, physical configuration at mu, u = 0) of the slave
  // facets around its vertex: the slave body's outward direction there (n[d] of size R, the same on every rank).
  // Collective.
  PetscErrorCode SlaveOutwardNormals(MPI_Comm comm, std::vector<PetscReal> n[3]) const;
  // Reference facet rule: barycentric points (dim per point) and weights summing to 1.
  const std::vector<PetscReal> &QuadraturePoints() const { return quadPoints_; }
  const std::vector<PetscReal> &QuadratureWeights() const { return quadWeights_; }
  ContactQuadrature quadrature = ContactQuadrature::Gauss;
  PetscInt          nquad      = 4;
  PetscInt          nsub       = 4;
  bool              smoothNormal = true;
  ContactMultiplier multiplier   = ContactMultiplier::Dual;
  bool              segmentPairSearch = true;
  bool              masterSearchNear  = false; // -contact_master_search near
  PetscReal         masterSearchMargin = -1;   // -contact_master_search_margin (< 0: automatic)
  // The master facets this rank held at the last Assemble, the whole master's, and the assemblies that fell back
  // from near to all (report key contact_search).
  struct MasterSearchStats {
    PetscInt held = 0, total = 0, fallbacks = 0, assemblies = 0, farPoints = 0; // farPoints: out of reach, last assembly
    PetscInt  belowReach = 0; // fallbacks because the margin is below the least reach of a slave point (reach)
    PetscReal reach      = 0; // 2 slave + 3 master facet diameters, the smallest (last assembly)
  };
  const MasterSearchStats &MasterSearch() const { return searchStats_; }

private:
  // masterAll_ := the master facets near this rank's slave facets (-contact_master_search near): those whose
  // deformed bounding box meets the slave facets' box grown by *margin (the option's, or the automatic one).
  // Collective; the relative order of the facets is that of Gather.
  PetscErrorCode GatherNearMaster(MPI_Comm comm, PetscReal *margin, PetscReal *reach);
  MasterSearchStats searchStats_;
  std::string       slaveName_, masterName_;
  size_t            kReserve_[2] = {0, 0}; // the last assembly's buffered K pieces and entries (the next one reserves as many)
  PetscErrorCode NumberMultipliers(const Elasticity &elas);
  PetscErrorCode FindSlaveEnds(const Elasticity &elas, const std::string &slave);
  void           SegmentFacet(const SurfaceFacet &F, const ClosestPoint &cp, std::vector<std::pair<PetscReal, PetscReal>> *segs) const;
  // 3D: the slave triangle F clipped against the master triangles projected onto its plane (the segment-based
  // mortar rule of 3D: polygon clipping, fan triangulation, the facet rule on every cell). Integration points
  // (slave barycentric b, weight = fraction of the facet x rule weight x meas); false when the projections do
  // not cover F (the end of the master surface): the caller keeps the plain rule there.
  // cand: the master facets near F (every facet within `reach` of a point of F is among them), for the search.
  bool           ClipFacet3(const SurfaceFacet &F, const ClosestPoint &cp, PetscReal meas, std::vector<std::array<PetscReal, 4>> *ipts, std::vector<PetscInt> *cand, PetscReal *reach) const;
  ContactSurface        slave_, master_;
  std::vector<PetscInt> vertexRow_;  // local vertex point - vStart -> multiplier row (-1: not a slave vertex)
  PetscInt              R_ = 0, rStart_ = 0, rEnd_ = 0;
  PetscInt              vStart_ = 0;
  std::vector<PetscReal> quadPoints_, quadWeights_; // reference facet rule (barycentric, nv per point)
  std::vector<SurfaceFacet> masterAll_;
  std::vector<PetscInt>     endRows_;
  std::vector<PetscInt>     pastMasterEnd_; // rows (local list, may repeat) of the last Assemble: PastMasterEndRows
  struct IntegrationPoint {
    PetscInt  s = -1, m = -1;                // slave facet (local), closest master facet (masterAll_)
    PetscReal b[3] = {0, 0, 0}, w = 0, bm[3] = {0, 0, 0};
  };
  std::vector<IntegrationPoint> points_; // the integration points of the last Assemble (AssembleTangent)
  std::vector<std::array<PetscReal, 3>> endNext_;
};

} // namespace rbc
