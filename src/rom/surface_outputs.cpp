// src/rom/surface_outputs.cpp: the maximum pressure and the contact half-width (2D) or radius (3D) of a reduced solution from
// the dual basis on the slave vertices and the slave facets (include/rbcontact/surface_outputs.hpp).
#include "rbcontact/surface_outputs.hpp"
#include "../contact/contact_point.hpp"
#include "../contact/pressure_moments.hpp"
#include <algorithm>
#include <cmath>

namespace rbc {

static constexpr size_t kRec = 14; // body, nv, row[3], Xref[9]

void SurfaceOutputs::Build(PetscInt dim, const std::vector<SurfaceFacet> &slave, const std::vector<PetscInt> &canonRow, PetscInt Rfom, PetscInt r, const std::vector<PetscReal> &Wc)
{
  dim_  = dim;
  Rfom_ = Rfom;
  r_    = r;
  W_.assign((size_t)r * Rfom, 0.0);
  for (PetscInt k = 0; k < r; ++k)
    for (PetscInt i = 0; i < Rfom; ++i) W_[(size_t)k * Rfom + i] = Wc[i + (size_t)k * Rfom];
  facets_.clear();
  for (const auto &F : slave) {
    std::vector<PetscReal> rec(kRec, -1.0);
    rec[0] = F.body;
    rec[1] = F.nv;
    for (PetscInt k = 0; k < F.nv; ++k) rec[2 + k] = F.row[k] >= 0 ? canonRow[F.row[k]] : -1;
    for (PetscInt i = 0; i < 9; ++i) rec[5 + i] = F.Xref[i];
    facets_.insert(facets_.end(), rec.begin(), rec.end());
  }
}

void SurfaceOutputs::Weights(const GeometryMap &map, const std::vector<PetscReal> &mu, std::vector<PetscReal> *w, std::vector<PetscReal> *x) const
{
  w->assign(Rfom_, 0.0);
  x->assign((size_t)Rfom_ * 3, 0.0);
  for (size_t f = 0; f + kRec <= facets_.size(); f += kRec) {
    const PetscReal *rec = &facets_[f];
    const PetscInt   nv  = (PetscInt)rec[1];
    const Affine     a   = map.Evaluate((PetscInt)rec[0], mu);
    PetscReal        X[9] = {0};
    for (PetscInt k = 0; k < nv; ++k) a.Apply(dim_, rec + 5 + k * dim_, X + k * dim_);
    const PetscReal meas = FacetMeasure(X, dim_); // the facet's measure at mu (a segment or a triangle)
    for (PetscInt k = 0; k < nv; ++k) {
      const PetscInt i = (PetscInt)rec[2 + k];
      if (i < 0 || i >= Rfom_) continue;
      (*w)[i] += meas / nv;
      for (PetscInt d = 0; d < dim_; ++d) (*x)[3 * (size_t)i + d] = X[k * dim_ + d];
    }
  }
}

void SurfaceOutputs::Write(RomWriter *w) const
{
  if (Empty()) return;
  w->Dataset("/online/outputs/meta", {3}, {(double)dim_, (double)Rfom_, (double)r_});
  w->Dataset("/online/outputs/W", {(unsigned long long)r_, (unsigned long long)Rfom_}, W_);
  w->Dataset("/online/outputs/slave_facets", {(unsigned long long)(facets_.size() / kRec), (unsigned long long)kRec}, facets_);
}

PetscErrorCode SurfaceOutputs::Read(const std::string &file, bool *found)
{
  std::vector<double> meta;

  PetscFunctionBeginUser;
  Rfom_ = r_ = 0;
  W_.clear();
  facets_.clear();
  PetscCall(RomReadOptional(file, "/online/outputs/meta", &meta, found));
  if (!*found) PetscFunctionReturn(0);
  PetscCheck(meta.size() == 3 && (meta[0] == 2 || meta[0] == 3) && meta[1] >= 1 && meta[2] >= 1, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/outputs/meta is malformed", file.c_str());
  dim_  = (PetscInt)meta[0];
  Rfom_ = (PetscInt)meta[1];
  r_    = (PetscInt)meta[2];
  bool                            f1, f2;
  std::vector<unsigned long long> dims;
  PetscCall(RomReadOptional(file, "/online/outputs/W", &W_, &f1, &dims));
  PetscCall(RomReadOptional(file, "/online/outputs/slave_facets", &facets_, &f2));
  // (the shape too: a transposed W gave a max pressure of 0, exit 0)
  const bool shaped = dims.size() == 2 && dims[0] == (unsigned long long)r_ && dims[1] == (unsigned long long)Rfom_;
  PetscCheck(f1 && f2 && shaped && facets_.size() % kRec == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/outputs is incomplete or has the wrong sizes (W must be %" PetscInt_FMT " x %" PetscInt_FMT "; corrupt file?)", file.c_str(), r_, Rfom_);
  for (size_t f = 0; f < facets_.size(); f += kRec) {
    const PetscInt nv = (PetscInt)facets_[f + 1];
    PetscCheck(nv == dim_, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/outputs/slave_facets: a facet with %" PetscInt_FMT " vertices in %" PetscInt_FMT "D", file.c_str(), nv, dim_);
    for (PetscInt k = 0; k < nv; ++k) PetscCheck(facets_[f + 2 + k] >= -1 && facets_[f + 2 + k] < Rfom_, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "ROM file %s: /online/outputs/slave_facets: a multiplier row out of range", file.c_str());
  }
  PetscFunctionReturn(0);
}

void SurfaceOutputs::Evaluate(const GeometryMap &map, const std::vector<PetscReal> &mu, const std::vector<PetscReal> &lhat, const std::vector<PetscReal> &force, SurfaceOutputValues *out) const
{
  *out = SurfaceOutputValues();
  if (Empty() || lhat.empty() || (PetscInt)lhat.size() > r_) return;
  std::vector<PetscReal> lam(Rfom_, 0.0), w, x;
  for (size_t k = 0; k < lhat.size(); ++k)
    for (PetscInt i = 0; i < Rfom_; ++i) lam[i] += lhat[k] * W_[k * Rfom_ + i];
  out->maxPressure = 0;
  for (PetscReal l : lam) out->maxPressure = std::max(out->maxPressure, l);
  PetscReal fn = 0;
  for (PetscReal f : force) fn += f * f;
  fn = std::sqrt(fn);
  if (force.size() != (size_t)dim_ || !(fn > 0)) return;
  Weights(map, mu, &w, &x);
  if (dim_ == 3) { // the contact radius by the pressure's second moment in the plane normal to the resultant (SummarizeContact)
    const PetscReal  nh[3] = {force[0] / fn, force[1] / fn, force[2] / fn};
    PressureMoments3 pm(nh);
    for (PetscInt i = 0; i < Rfom_; ++i) pm.Add(x[3 * (size_t)i], x[3 * (size_t)i + 1], x[3 * (size_t)i + 2], lam[i] * w[i]);
    PetscReal a;
    if (pm.Radius(&a)) out->contactRadius = a;
    return;
  }
  const PetscReal  t[2] = {-force[1] / fn, force[0] / fn};
  PressureMoments2 pm;
  for (PetscInt i = 0; i < Rfom_; ++i) pm.Add(x[3 * (size_t)i] * t[0] + x[3 * (size_t)i + 1] * t[1], lam[i] * w[i]);
  PetscReal a;
  if (pm.HalfWidth(&a)) {
    out->halfwidth     = a;
    out->contactLength = 2 * a;
  }
}

} // namespace rbc
