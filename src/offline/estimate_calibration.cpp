// src/offline/estimate_calibration.cpp: CalibrateErrorEstimate (rbcontact/estimate_calibration.hpp).
#include "rbcontact/estimate_calibration.hpp"
#include "rbcontact/options_files.hpp"
#include "rbcontact/error_estimate.hpp"
#include "rbcontact/training_set.hpp"
#include "rbcontact/validation.hpp"

namespace rbc {

PetscErrorCode EstimateCalibrationOptions(MPI_Comm world, PetscInt *n, PetscInt *seed, PetscReal *safety)
{
  PetscFunctionBeginUser;
  PetscCall(CheckValuesGiven(world, "estimate_", {"calibration_size", "calibration_seed", "safety", "pod_tol", "dual_tol", "cubature"})); // (the defaults, without a word)
  PetscOptionsBegin(world, "estimate_", "Online error estimate: calibration (offline)", "CalibrateErrorEstimate");
  PetscCall(PetscOptionsInt("-calibration_size", "random parameters where the FOM calibrates the estimate (0: none)", "", *n, n, NULL));
  PetscCall(PetscOptionsInt("-calibration_seed", "seed of those parameters", "", *seed, seed, NULL));
  PetscCall(PetscOptionsReal("-safety", "factor on the fitted calibration (a margin for parameters worse than every calibration point)", "", *safety, safety, NULL));
  PetscOptionsEnd();
  PetscCheck(*safety >= 1 && *safety <= 100, world, PETSC_ERR_ARG_OUTOFRANGE, "-estimate_safety %g out of range [1, 100]", (double)*safety);
  PetscCheck(*n >= 0 && *n <= 100000, world, PETSC_ERR_ARG_OUTOFRANGE, "-estimate_calibration_size %" PetscInt_FMT " out of range [0, 1e5]", *n);
  // (1 or 2 points fitted scales that put the estimate up to 4000x below the error, stored as available; audit of
  // 2026-12-01)
  PetscCheck(*n == 0 || *n >= 3, world, PETSC_ERR_ARG_OUTOFRANGE, "-estimate_calibration_size %" PetscInt_FMT ": at least 3 calibration parameters (1 or 2 fit scales that underestimate the error by orders of magnitude), or 0 for none", *n);
  PetscFunctionReturn(0);
}

PetscErrorCode CalibrateErrorEstimate(MPI_Comm world, const SceneSpec &scene, const std::string &romPath, RomWriter *w, Report *rep)
{
  PetscInt  n = 20, seed = 2026;
  PetscReal safety = 2;
  bool                has = false;
  std::vector<double> sizes;

  PetscFunctionBeginUser;
  PetscCall(EstimateCalibrationOptions(world, &n, &seed, &safety));
  PetscCall(RomReadOptional(romPath, "/online/estimate/default_sizes", &sizes, &has));
  JsonValue &e = rep->root["estimate"];
  e["enrichment"] = (bool)has;
  // (a small training set left nothing beyond the answer's bases: no estimate, without a word; audit I)
  if (!has) PetscCall(PetscPrintf(world, "rbcontact offline: warning: -estimate: the bases hold no function beyond the answer's (every POD mode within -estimate_pod_tol and every dual vector within -estimate_dual_tol is the answer's, or -pod_n fixes N), so the ROM %s has no online error estimate: use more training parameters, or a smaller -estimate_pod_tol / -estimate_dual_tol (docs/error_estimate.md)\n", romPath.c_str()));
  if (has && n == 0) PetscCall(PetscPrintf(world, "rbcontact offline: warning: -estimate_calibration_size 0: the online error estimate is not calibrated (scale 1, floor 0): a raw residual-based indicator, not a bound (docs/error_estimate.md)\n"));
  if (!has || n == 0) PetscFunctionReturn(0); // nothing to calibrate (the bases need every basis function) or not asked

  ParameterSet cal;
  for (const auto &p : scene.params) cal.names.push_back(p.name);
  cal.points = RandomSample(scene.params, n, (unsigned long long)seed);
  ValidationSettings  vs;
  std::vector<double> raw[3], err[3];
  vs.repeat      = 1;
  vs.print       = false;
  vs.estimateRaw = raw;
  vs.estimateErr = err;
  Report vr;
  PetscCall(RunValidation(world, scene, romPath, cal, vs, &vr));
  PetscCheck(raw[0].size() == (size_t)n, world, PETSC_ERR_PLIB, "offline -estimate: the ROM %s gave no error estimate at the calibration parameters", romPath.c_str());
  std::vector<double> scale(3), floor(3), mine(3), maxe(3);
  for (int k = 0; k < 3; ++k) {
    const EstimateCalibration c = CalibrateEstimate(raw[k], err[k]);
    scale[k] = safety * c.scale;
    floor[k] = safety * c.floor;
    mine[k]  = safety * c.minEffectivity;
    maxe[k]  = safety * c.maxEffectivity;
  }
  w->Dataset("/online/estimate/calibration", {2, 3}, {scale[0], scale[1], scale[2], floor[0], floor[1], floor[2]});
  PetscCall(w->Write(world, romPath));
  e["calibration_points"]          = (long long)n;
  e["calibration_seed"]            = (long long)seed;
  e["safety"]                      = (double)safety;
  e["scale"]                       = scale;
  e["floor"]                       = floor;
  e["calibration_min_effectivity"] = mine;
  e["calibration_max_effectivity"] = maxe;
  e["calibration_fom_median_s"]    = vr.root["fom_time_s"]["median"].AsNumber();
  PetscFunctionReturn(0);
}

} // namespace rbc
