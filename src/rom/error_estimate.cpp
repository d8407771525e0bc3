// src/rom/error_estimate.cpp: CalibrateEstimate (rbcontact/error_estimate.hpp).
#include "rbcontact/error_estimate.hpp"
#include <algorithm>
#include <cmath>

namespace rbc {

EstimateCalibration CalibrateEstimate(const std::vector<PetscReal> &raw, const std::vector<PetscReal> &err)
{
  EstimateCalibration    c;
  std::vector<PetscReal> r, e;
  for (size_t k = 0; k < std::min(raw.size(), err.size()); ++k)
    if (err[k] > 0 && std::isfinite(err[k]) && std::isfinite(raw[k])) {
      r.push_back(std::max<PetscReal>(raw[k], 0));
      e.push_back(err[k]);
    }
  c.points = (PetscInt)e.size();
  if (e.empty()) return c;
  const PetscReal lo = 1e-2, hi = 1e4;
  // for a scale a, the smallest admissible floor and the largest ratio it leaves
  auto floorOf = [&](PetscReal a) {
    PetscReal b = 0;
    for (size_t k = 0; k < e.size(); ++k) b = std::max(b, e[k] - a * r[k]);
    return b;
  };
  // the objective: the 90 % quantile of the effectivities (the largest is set by the one calibration point with
  // the smallest error; the measure is a share of the points), the largest as tie-break
  std::vector<PetscReal> eff(e.size());
  auto                   worst = [&](PetscReal a) {
    const PetscReal b = floorOf(a);
    for (size_t k = 0; k < e.size(); ++k) eff[k] = (a * r[k] + b) / e[k];
    std::sort(eff.begin(), eff.end());
    const size_t q = std::min(e.size() - 1, (size_t)std::ceil(0.9 * e.size()) - 1);
    return eff[q] + 1e-6 * eff.back();
  };
  std::vector<PetscReal> cand;
  for (int i = 0; i <= 600; ++i) cand.push_back(lo * std::pow(hi / lo, i / 600.0));
  for (size_t k = 0; k < e.size(); ++k)
    if (r[k] > 0) cand.push_back(std::min(hi, std::max(lo, e[k] / r[k])));
  PetscReal best = cand[0], bestW = worst(cand[0]);
  for (PetscReal a : cand) {
    const PetscReal w = worst(a);
    if (w < bestW * (1 - 1e-12) || (w <= bestW * (1 + 1e-12) && floorOf(a) < floorOf(best))) {
      best  = a;
      bestW = w;
    }
  }
  c.scale = best;
  c.floor = floorOf(best);
  c.minEffectivity = PETSC_MAX_REAL;
  for (size_t k = 0; k < e.size(); ++k) {
    const PetscReal eff = (c.scale * r[k] + c.floor) / e[k];
    c.minEffectivity    = std::min(c.minEffectivity, eff);
    c.maxEffectivity    = std::max(c.maxEffectivity, eff);
  }
  return c;
}

} // namespace rbc
