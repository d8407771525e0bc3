// include/rbcontact/surface_outputs.hpp: outputs of interest of a reduced solution that need the pressure
// field on the slave surface: the maximum nodal pressure, the contact half-width (2D) or radius (3D), computed online
// from the reduced multipliers alone (no mesh): the dual basis on the slave vertices W (r x R_fom) and the
// slave facets (reference vertex coordinates, body, the canonical multiplier row of each vertex) are stored
// in the ROM file (/online/outputs). The definitions are the FOM report's (SummarizeContact, kacanov.hpp):
// lambda = W' lambda^, max_pressure = max_i lambda_i, the half-width 2 sqrt(m2/m0 - (m1/m0)^2) of the moments
// m_k = sum_i lambda_i w_i s_i^k along the tangent of the resultant (w_i = int psi_i at mu, s_i = x_i(mu) . t;
// the FOM report's contact_halfwidth_moment, Hertz's a for Hertz's pressure); in 3D the contact radius
// sqrt(5/2 (m2/m0 - |m1/m0|^2)) with m_k the moments of |q|^k, q = x_i(mu) projected on the plane normal to the
// resultant (the FOM report's contact_halfwidth_moment in 3D: Hertz's a for Hertz's p0 sqrt(1 - r^2/a^2)). docs/online.md.
#pragma once
#include <string>
#include <vector>
#include "rbcontact/contact.hpp"
#include "rbcontact/geometry_map.hpp"
#include "rbcontact/rom_file.hpp"

namespace rbc {

struct SurfaceOutputValues {
  PetscReal maxPressure = NAN;   // max_i lambda_i (nodal pressure)
  PetscReal halfwidth   = NAN;   // 2D: the moment half-width (NaN in 3D or without a resultant)
  PetscReal contactLength = NAN; // 2D: 2 x halfwidth
  PetscReal contactRadius = NAN; // 3D: the moment radius sqrt(5/2 (m2/m0 - |m1/m0|^2)) of the pressure in the plane normal
                                 // to the resultant (NaN in 2D or without a resultant)
};

class SurfaceOutputs {
public:
  // Offline: from the slave facets of every rank (ContactSurface::Gather), their vertices' canonical
  // multiplier rows (rowOf(global row)), and the dual basis W (R_fom x r, column-major: column k = xi_k).
  void Build(PetscInt dim, const std::vector<SurfaceFacet> &slave, const std::vector<PetscInt> &canonRow, PetscInt Rfom, PetscInt r, const std::vector<PetscReal> &Wcolmajor);
  // w_i = int psi_i at mu (sum over the facets of |facet(mu)| / vertices): the check against the FOM's weights.
  void Weights(const GeometryMap &map, const std::vector<PetscReal> &mu, std::vector<PetscReal> *w, std::vector<PetscReal> *x) const;
  void Write(RomWriter *w) const;
  // Reads /online/outputs if present (*found false otherwise: files of before 2026-11-25).
  PetscErrorCode Read(const std::string &file, bool *found);
  // The outputs of the reduced multipliers lhat (their first lhat.size() dual vectors) at mu; force: the
  // resultant's direction (dim values; may be empty: no half-width).
  void Evaluate(const GeometryMap &map, const std::vector<PetscReal> &mu, const std::vector<PetscReal> &lhat, const std::vector<PetscReal> &force, SurfaceOutputValues *out) const;
  bool Empty() const { return Rfom_ == 0; }

private:
  PetscInt               dim_ = 2, Rfom_ = 0, r_ = 0;
  std::vector<PetscReal> W_;      // r x Rfom, row-major
  std::vector<PetscReal> facets_; // per slave facet: body, nv, row[3] (canonical, -1), Xref[9]
};

} // namespace rbc
