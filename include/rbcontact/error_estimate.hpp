// rbcontact/error_estimate.hpp: the calibration of the online error estimate (docs/error_estimate.md). The
// estimate of a reduced solution is a * raw + b, raw the change of the answer in the enriched spaces of the ROM
// file (ReducedModel::EstimateError); a and b are fitted offline on calibration parameters where the true error
// is known (FOM solves), so that the estimate is >= the error there with the smallest largest ratio.
#pragma once
#include <petscsys.h>
#include <vector>

namespace rbc {

struct EstimateCalibration {
  PetscReal scale = 1, floor = 0;  // estimate = scale * raw + floor
  PetscReal minEffectivity = 0;    // on the calibration points, after the fit (>= 1 up to rounding)
  PetscReal maxEffectivity = 0;
  PetscInt  points = 0;            // calibration points with a nonzero error
};

// The (scale, floor) with scale in [1e-2, 1e4] and floor >= 0 that makes scale * raw_k + floor >= err_k at every k
// and minimizes the 90 % quantile of the ratios (scale * raw_k + floor) / err_k (the largest breaks ties; points with
// err_k <= 0 are skipped; none left: scale 1, floor 0). Deterministic: a log grid of scales plus every err_k / raw_k.
EstimateCalibration CalibrateEstimate(const std::vector<PetscReal> &raw, const std::vector<PetscReal> &err);

} // namespace rbc
