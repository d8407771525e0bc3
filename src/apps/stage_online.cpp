// src/apps/stage_online.cpp: `rbcontact online -rom rom.h5 -mu v1[,v2] -report r.json`: opens the ROM
// file, solves the reduced contact problem at mu (ReducedModel, the C++ API), reports the reduced
// solution, its KKT residuals and timings (-online_repeat n: median of n timed solves after one
// warm-up). -rom_reconstruct out.h5 (with the scene, -options_file runs/<scene>.opts) writes the full
// fields: displacement and contact pressure, with XDMF (src/offline/rom_fields.cpp).
#include "stages.hpp"
#include "rbcontact/options_files.hpp"
#include "rbcontact/rom_fields.hpp"
#include "rbcontact/geometry_map.hpp"
#include "rbcontact/scene.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/report.hpp"
#include <cstring>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rbc {

PetscErrorCode StageOnline(MPI_Comm comm)
{
  char           romPath[PETSC_MAX_PATH_LEN] = "", reportPath[PETSC_MAX_PATH_LEN] = "", recPath[PETSC_MAX_PATH_LEN] = "";
  PetscBool      set;
  PetscInt       repeat = 1;
  PetscLogDouble t0, t1;
  Report         rep;
  ReducedModel   model;
  ReducedSolution sol;

  PetscInt       nmu = 65;       // (one more than taken: PETSc drops values beyond the buffer silently)
  PetscReal      muIn[65] = {0}; // -help prints muIn[0] of an unset -mu
  PetscBool      muSet = PETSC_FALSE;

  PetscFunctionBeginUser;
  // the stage's own options in one block: -help lists them (the reduced model's follow, prefix rom_)
  PetscOptionsBegin(comm, NULL, "rbcontact online: one reduced solve from a ROM file", "rbcontact");
  PetscCall(PetscOptionsString("-rom", "the ROM file (written by rbcontact offline)", "", romPath, romPath, sizeof romPath, &set));
  PetscCall(PetscOptionsRealArray("-mu", "the parameter values (default: the scene's defaults stored in the file)", "", muIn, &nmu, &muSet));
  PetscCall(PetscOptionsString("-report", "JSON report of the run", "", reportPath, reportPath, sizeof reportPath, NULL));
  PetscCall(PetscOptionsString("-rom_reconstruct", "write the full fields of the reduced solution to this HDF5 file (+ .xmf; needs the scene options and the basis file)", "", recPath, recPath, sizeof recPath, NULL));
  PetscCall(PetscOptionsInt("-online_repeat", "solve this many times and report the median time", "", repeat, &repeat, NULL));
  PetscOptionsEnd();
  PetscCall(RequireInput(comm, set && romPath[0], "-rom", "online: give the ROM file with -rom <file.h5> (written by rbcontact offline)"));
  {
    PetscBool hasMu = PETSC_FALSE;
    PetscCall(PetscOptionsHasName(NULL, NULL, "-mu", &hasMu));
    PetscCheck(!hasMu || (muSet && nmu > 0), comm, PETSC_ERR_USER_INPUT, "option -mu is given without a value (the scene's defaults are used only without -mu)");
    PetscCheck(!muSet || nmu <= 64, comm, PETSC_ERR_ARG_SIZ, "option -mu takes at most 64 values, more were given");
    for (PetscInt i = 0; muSet && i < nmu; ++i) PetscCheck(std::isfinite(muIn[i]), comm, PETSC_ERR_USER_INPUT, "option -mu: value %" PetscInt_FMT " of the list is not a finite number (inf or nan)", i + 1);
  }
  PetscCall(CheckOutputPath(comm, reportPath, "-report"));
  PetscCall(CheckOutputPath(comm, recPath, "-rom_reconstruct"));
  PetscCall(CheckOutputPath(comm, recPath[0] ? XdmfPath(recPath) : "", "-rom_reconstruct's XDMF"));
  {
    char basisPath[PETSC_MAX_PATH_LEN] = "";
    PetscCall(PetscOptionsGetString(NULL, NULL, "-rom_basis", basisPath, sizeof basisPath, NULL));
    PetscCall(CheckDistinctFiles(comm, {{"-report", reportPath}, {"-rom_reconstruct", recPath}, {"-rom_reconstruct's XDMF", recPath[0] ? XdmfPath(recPath) : ""}}, {{"-rom", romPath}, {"-rom_basis", basisPath}}));
  }
  PetscCheck(repeat >= 1 && repeat <= 10000000, comm, PETSC_ERR_ARG_OUTOFRANGE, "-online_repeat %" PetscInt_FMT " out of range [1, 1e7]", repeat);
  PetscCall(PetscTime(&t0));
  PetscCall(model.Open(romPath));
  PetscCall(model.SetFromOptions());
  if (!recPath[0]) PetscCall(CheckSceneOptions(comm, "online", romPath)); // (-rom_reconstruct checks the scene itself)
  PetscCall(PetscTime(&t1));
  const double tOpen = t1 - t0;
  // mu: -mu values, default the parameters' defaults
  std::vector<PetscReal> mu;
  for (const auto &p : model.par.params) mu.push_back(p.def);
  if (muSet) mu.assign(muIn, muIn + nmu); // CheckBox names a wrong count or value
  PetscCall(model.par.CheckBox(comm, mu));
  // one warm-up solve, then the timed ones (the online time: operators + EIM + Kacanov + QP, no I/O)
  PetscCall(model.Solve(mu, &sol));
  std::vector<double> times;
  for (PetscInt k = 0; k < repeat; ++k) {
    PetscCall(PetscTime(&t0));
    PetscCall(model.Solve(mu, &sol));
    PetscCall(PetscTime(&t1));
    times.push_back(t1 - t0);
  }
  std::sort(times.begin(), times.end());
  PetscCheck(sol.converged, comm, PETSC_ERR_NOT_CONVERGED, "online: %s", sol.message.c_str());
  if (sol.outOfRange) // (it named the EIM for an ECSW model too)
    PetscCall(PetscPrintf(comm, "rbcontact online: warning: %" PetscInt_FMT " contact projections fell at the edge of the stored contact data (the master facets stored for the %s's points: outside its training range; more -eim_patch_rings, or training parameters near this one)\n", sol.outOfRange, std::strcmp(model.HyperName(), "ecsw") ? "EIM" : "cubature"));

  rep.root["stage"] = "online";
  rep.root["rom_file"] = romPath;
  JsonValue &m      = rep.root["mu"];
  for (size_t i = 0; i < mu.size(); ++i) m[model.par.params[i].name] = (double)mu[i];
  rep.root["converged"]          = sol.converged;
  rep.root["kacanov_iterations"] = (long long)sol.iterations;
  rep.root["kacanov_history"]["du"] = sol.du;
  rep.root["kacanov_history"]["dlambda"] = sol.dl;
  rep.root["u_hat"]              = sol.v;
  rep.root["lambda_hat"]         = sol.lambda;
  rep.root["nactive_hat"]        = (long long)(sol.nactive.empty() ? 0 : sol.nactive.back());
  rep.root["out_of_range"]       = (long long)sol.outOfRange;
  // outputs of interest from the reduced solution alone (no mesh): the resultant contact force
  JsonValue &o = rep.root["outputs"];
  if (sol.force.empty()) {
    o["contact_force"] = JsonValue();
    o["force"]         = JsonValue();
  } else {
    o["contact_force"] = (double)sol.ForceMagnitude();
    o["force"]         = std::vector<double>(sol.force.begin(), sol.force.end());
  }
  SurfaceOutputValues so; // NaN (JSON null) without the surface data or the online force
  model.SurfaceOutputsOf(mu, sol, &so);
  o["max_pressure"]      = (double)so.maxPressure;
  o["contact_halfwidth"] = (double)so.halfwidth;
  o["contact_length"]    = (double)so.contactLength;
  o["contact_radius"]    = (double)so.contactRadius; // 3D (null in 2D)
  // the online error estimate (docs/error_estimate.md): relative errors of u (energy), lambda (slave-mass l2), force
  JsonValue &ee = rep.root["error_estimate"];
  ee["available"] = sol.estimate.available;
  if (sol.estimate.available) {
    ee["u"]          = (double)sol.estimate.u;
    ee["lambda"]     = (double)sol.estimate.lambda;
    ee["force"]      = (double)sol.estimate.force;
    ee["raw"]["u"]      = (double)sol.estimate.uRaw;
    ee["raw"]["lambda"] = (double)sol.estimate.lambdaRaw;
    ee["raw"]["force"]  = (double)sol.estimate.forceRaw;
  } else ee["why"] = sol.estimate.why;
  JsonValue &k                   = rep.root["kkt"];
  k["primal_infeas"]             = (double)sol.qp.primal;
  k["dual_infeas"]               = (double)sol.qp.dual;
  k["complementarity"]           = (double)sol.qp.complementarity;
  k["stationarity"]              = (double)sol.qp.stationarity;
  JsonValue &r                   = rep.root["rom"];
  r["file"]                      = romPath;
  ReportSizes(model, &r);
  rep.root["time_s"]["open"]     = tOpen;
  rep.root["time_s"]["solve_median"] = times[times.size() / 2];
  rep.root["time_s"]["solve_min"]    = times.front();
  rep.root["time_s"]["solve_max"]    = times.back();
  rep.root["repeat"]             = (long long)repeat;
  if (recPath[0]) {
    PetscCall(ReconstructFields(comm, model, sol, mu, recPath, &rep));
    rep.root["reconstruct"] = recPath;
  }
  char forceText[160] = "";
  if (!sol.force.empty()) std::snprintf(forceText, sizeof forceText, ", contact force %.6g", (double)sol.ForceMagnitude());
  if (sol.estimate.available) std::snprintf(forceText + strlen(forceText), sizeof forceText - strlen(forceText), ", estimated rel errors u %.2e lambda %.2e force %.2e", (double)sol.estimate.u, (double)sol.estimate.lambda, (double)sol.estimate.force);
  PetscCall(PetscPrintf(comm, "rbcontact online: %s, N %" PetscInt_FMT " R %" PetscInt_FMT " %s, %" PetscInt_FMT " Kacanov iterations%s, solve %.3g s (median of %" PetscInt_FMT ")\n", romPath, model.N(), model.R(), model.HyperSizes().c_str(), sol.iterations, forceText, times[times.size() / 2], repeat));
  PetscCall(rep.Write(comm, reportPath));
  PetscFunctionReturn(0);
}

} // namespace rbc
