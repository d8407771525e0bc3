// rbcontact/estimate_calibration.hpp: the offline half of the online error estimate (offline -estimate,
// docs/error_estimate.md): FOM solves at calibration parameters, the raw estimates of the just-written ROM
// there, the fitted calibration (error_estimate.hpp) written into the ROM file.
#pragma once
#include <string>
#include "rbcontact/report.hpp"
#include "rbcontact/rom_file.hpp"
#include "rbcontact/scene.hpp"

namespace rbc {

// -estimate_calibration_size n (default 20; 0: no calibration, scale 1 and floor 0), -estimate_calibration_seed s:
// n random parameters of the scene's box; `rbcontact validate` of the ROM at romPath there (w: its writer, which
// holds the model), and the calibration of u, lambda and the online force (CalibrateEstimate, times
// -estimate_safety, default 2) into /online/estimate/calibration (the file rewritten atomically). Report keys
// estimate {enrichment, calibration_points, calibration_seed, safety, scale, floor, calibration_min_effectivity,
// calibration_max_effectivity (u, lambda, force), calibration_fom_median_s}. Collective on world.
PetscErrorCode CalibrateErrorEstimate(MPI_Comm world, const SceneSpec &scene, const std::string &romPath, RomWriter *w, Report *rep);
// Its options (-estimate_calibration_size, _seed, -estimate_safety), checked; *n, *seed, *safety hold the defaults on
// entry. The offline stage checks them before the snapshots too.
PetscErrorCode EstimateCalibrationOptions(MPI_Comm world, PetscInt *n, PetscInt *seed, PetscReal *safety);

} // namespace rbc
