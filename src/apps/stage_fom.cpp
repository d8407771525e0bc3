// src/apps/stage_fom.cpp: `rbcontact fom`: solve the full-order model of one scene (elastic, or with
// contact by Kacanov iterations) and write the report and the fields.
#include "stages.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/kacanov.hpp"
#include <cmath>

namespace rbc {

PetscErrorCode StageFom(MPI_Comm comm)
{
  SceneSpec      scene;
  Report         rep;
  char           reportPath[PETSC_MAX_PATH_LEN] = "", outPath[PETSC_MAX_PATH_LEN] = "";
  PetscLogDouble t0, t1;
  PetscReal      hertzRadius = 0;
  PetscBool      hertz = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscBool affine = PETSC_TRUE, affineSet = PETSC_FALSE;
  PetscOptionsBegin(comm, NULL, "rbcontact fom: the full-order model at one parameter", "rbcontact");
  PetscCall(PetscOptionsString("-report", "Write the run's summary (JSON) here", "README.md", reportPath, reportPath, sizeof reportPath, NULL));
  PetscCall(PetscOptionsString("-fom_output", "Write the fields (HDF5 + XDMF for ParaView) here", "README.md", outPath, outPath, sizeof outPath, NULL));
  PetscCall(PetscOptionsReal("-hertz_radius", "Compare with Hertz's contact of a cylinder (2D) or a sphere (3D) of this radius", "docs/contact.md", hertzRadius, &hertzRadius, &hertz));
  PetscCall(PetscOptionsBool("-fom_affine", "Assemble A(mu), f(mu) from the affine terms (default with parameters)", "docs/reference_configuration.md", affine, &affine, &affineSet));
  PetscOptionsEnd();
  // a radius <= 0 or not finite gave a negative or NaN Hertz contact radius in the report, exit 0
  PetscCheck(!hertz || (std::isfinite(hertzRadius) && hertzRadius > 0), comm, PETSC_ERR_ARG_OUTOFRANGE, "-hertz_radius %g must be a finite number > 0 (the radius of Hertz's cylinder in 2D, sphere in 3D)", (double)hertzRadius);
  PetscCall(CheckOutputPath(comm, reportPath, "-report"));
  PetscCall(CheckOutputPath(comm, outPath, "-fom_output"));
  // the XDMF beside it too (a directory there failed after the solve, the new .h5 in place; a FIFO was replaced)
  PetscCall(CheckOutputPath(comm, outPath[0] ? XdmfPath(outPath) : "", "-fom_output's XDMF"));
  char      meshPath[PETSC_MAX_PATH_LEN] = "";
  PetscBool meshSet                      = PETSC_FALSE;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-mesh_file", meshPath, sizeof meshPath, &meshSet));
  PetscCall(CheckDistinctFiles(comm, {{"-report", reportPath}, {"-fom_output", outPath}, {"-fom_output's XDMF", outPath[0] ? XdmfPath(outPath) : ""}}, {{"-mesh_file", meshPath}}));
  PetscCall(SceneSpecFromOptions(comm, &scene));
  ElasticFOM    fom;
  ContactMap    map;
  KacanovSolver kacanov;
  PetscCall(fom.Create(comm, scene));
  // On the reference mesh: A(mu), f(mu) from the affine decomposition (-fom_affine 0: direct assembly)
  if (!affineSet) affine = scene.params.empty() ? PETSC_FALSE : PETSC_TRUE;
  if (affine) PetscCall(fom.SetupAffine());
  PetscCall(fom.SetMu(ParamValues(scene)));
  if (scene.contact) {
    PetscCall(kacanov.SetFromOptions(comm));
    PetscCall(map.Setup(fom.elas, scene.slave, scene.master));
    map.SetGeometry(&fom.map, fom.mu);
    PetscCall(kacanov.ShareFactor(fom, map));
  }
  PetscCall(fom.AssembleAndFactor());
  if (scene.contact) {
    std::vector<std::string> w;
    PetscCall(kacanov.Solve(fom, map));
    PetscCall(ContactSurfaceWarnings(comm, kacanov, map, &w));
    for (const auto &s : w) PetscCall(fom.Warn(s));
  } else PetscCall(fom.SolveElastic());
  { // never write a non-finite answer (nor over a good earlier output): the check comes before any output
    PetscReal nu, nl = 0;
    PetscCall(VecNorm(fom.u, NORM_INFINITY, &nu));
    if (scene.contact) PetscCall(VecNorm(kacanov.lambda, NORM_INFINITY, &nl));
    PetscCheck(std::isfinite(nu) && std::isfinite(nl), comm, PETSC_ERR_FP, "fom: the solution holds non-finite values (displacement %s, multipliers %s): check the scene's data (loads, materials, boundary values) and the solver's messages; nothing was written", std::isfinite(nu) ? "finite" : "NOT finite", std::isfinite(nl) ? "finite" : "NOT finite");
  }
  PetscCall(PetscTime(&t1));
  fom.times.total = t1 - t0;
  PetscCall(fom.FillReport(&rep));
  rep.root["stage"]   = "fom";
  rep.root["contact"] = (bool)scene.contact;
  if (scene.contact) {
    ContactSummary cs;
    PetscCall(SummarizeContact(kacanov.sys, kacanov.lambda, fom.elas.dim, &cs));
    rep.root["converged"]          = (bool)kacanov.converged;
    rep.root["kacanov_iterations"] = (long long)kacanov.iterations;
    rep.root["dual_matrix"]        = kacanov.dualMatrix; // dense, shell or saddle (-fom_dual_matrix)
    if (kacanov.dualMatrix == "dense") rep.root["compliance"] = kacanov.compliance.method; // how G = (A^-1)_DD was computed (-contact_compliance)
    if (kacanov.dualMatrix == "saddle") { // the saddle-point solve (-fom_saddle_*): its solver and totals over the iterates
      JsonValue &sd = rep.root["saddle"];
      PetscInt   nf = 0, nk = 0, ns = 0;
      for (PetscInt v : kacanov.history.factorizations) nf += v;
      for (PetscInt v : kacanov.history.krylov) nk += v;
      for (PetscInt v : kacanov.history.dualSteps) ns += v;
      sd["ksp_type"]       = kacanov.lastSaddle.kspType;
      sd["pc_type"]        = kacanov.lastSaddle.pcType;
      sd["steps"]          = (long long)ns;
      sd["factorizations"] = (long long)nf; // numeric factorizations, or preconditioner set-ups with an iterative solver
      sd["krylov"]         = (long long)nk;
      sd["rtol_forcing"]   = (double)kacanov.SaddleForcing(); // -fom_saddle_rtol_forcing (0: every iterate exactly)
    }
    if (kacanov.contactDofs >= 0) rep.root["contact_dofs"] = (long long)kacanov.contactDofs; // the dofs of the slave and master facets (the rows of the dense G)
    { // the master facets each rank held (-contact_master_search all|near, docs/contact.md "Parallel")
      const auto &ms = map.MasterSearch();
      JsonValue  &j  = rep.root["contact_search"];
      j["type"]              = map.masterSearchNear ? "near" : "all";
      j["master_facets_held_max"] = (long long)ms.held; // the largest count on one rank, last assembly
      j["master_facets_total"]    = (long long)ms.total;
      j["fallbacks"]              = (long long)ms.fallbacks; // near: assemblies that fell back to all
      j["below_reach"]            = (long long)ms.belowReach; // of them: the margin below any point's reach
      j["assemblies"]             = (long long)ms.assemblies;
      j["far_points"]             = (long long)ms.farPoints; // near: integration points out of reach, last assembly
    }
    rep.root["initial_overlap"]["max_penetration"] = (double)kacanov.initialPenetration; // at u = 0 (0: none)
    rep.root["initial_overlap"]["nodes"]           = (long long)kacanov.initialPenetrating;
    rep.root["ncontact"]           = (long long)cs.R;
    rep.root["nactive"]            = (long long)cs.nactive;
    rep.root["contact_force"]      = (double)cs.force;
    rep.root["max_pressure"]       = (double)cs.maxPressure;
    rep.root["contact_halfwidth"]  = fom.elas.dim == 2 ? (double)cs.halfwidth : std::nan(""); // 2D only (null in 3D: it read 0)
    rep.root["contact_halfwidth_moment"] = (double)cs.halfwidthMoment; // 2 sqrt(int p s^2 / int p - ...): Hertz's a; the ROM's online half-width
    if (fom.elas.dim == 2) { // along the surface: 2D only (in 3D they would read 0: absent instead)
      rep.root["pressure_spread"]    = (double)cs.pressureSpread;
      rep.root["pressure_roughness"] = (double)cs.pressureRoughness;
    }
    JsonValue &k                   = rep.root["kkt"];
    k["primal_infeas"]             = (double)kacanov.kkt.primal;
    k["dual_infeas"]               = (double)kacanov.kkt.dual;
    k["complementarity"]           = (double)kacanov.kkt.complementarity;
    k["stationarity"]              = (double)kacanov.kkt.stationarity;
    JsonValue &h                   = rep.root["kacanov_history"];
    h["du"]                        = kacanov.history.du;
    std::vector<double> dl(kacanov.history.dl.begin(), kacanov.history.dl.end()), na(kacanov.history.nactive.begin(), kacanov.history.nactive.end());
    h["dlambda"] = dl;
    h["nactive"] = na;
    rep.root["kacanov_type"] = kacanov.type; // -kacanov_type (newton: plain Kacanov on the shell path and in 3D)
    if (!kacanov.history.newton.empty()) h["newton"] = std::vector<double>(kacanov.history.newton.begin(), kacanov.history.newton.end()); // 1: the next input was a Newton step
    if (!kacanov.history.dualCG.empty()) h["dual_cg"] = std::vector<double>(kacanov.history.dualCG.begin(), kacanov.history.dualCG.end());
    auto asDoubles = [](const std::vector<PetscInt> &v) { return std::vector<double>(v.begin(), v.end()); };
    if (!kacanov.history.dualSteps.empty()) h["dual_steps"] = asDoubles(kacanov.history.dualSteps); // active-set steps per iterate (shell, saddle)
    if (!kacanov.history.factorizations.empty()) { // saddle: numeric factorizations and GMRES iterations per iterate
      h["factorizations"] = asDoubles(kacanov.history.factorizations);
      h["krylov"]         = asDoubles(kacanov.history.krylov);
    }
    if (hertz) {
      PetscReal a, p0;
      if (fom.elas.dim == 3) HertzPointContact(scene, hertzRadius, cs.force, &a, &p0); // a sphere of radius -hertz_radius
      else HertzLineContact(scene, hertzRadius, cs.force, &a, &p0);                      // a cylinder
      JsonValue &hz  = rep.root["hertz"];
      hz["a"]        = (double)cs.halfwidthMoment; // from the pressure's second moment (docs/contact.md)
      hz["a_nodes"]  = fom.elas.dim == 2 ? (double)cs.halfwidth : std::nan(""); // half the extent of the active nodes (2D)
      hz["a_exact"]  = (double)a;
      hz["p0"]       = (double)cs.maxPressure;
      hz["p0_exact"] = (double)p0;
      hz["P"]        = (double)cs.force;
    }
  }
  if (affine) fom.affine.Describe(&rep.root["affine_terms"]);
  rep.root["geometry_map"] = fom.map.Describe(scene);
  if (!scene.params.empty()) {
    JsonValue &m = rep.root["mu"];
    for (const auto &p : scene.params) m[p.name] = (double)p.value;
  }
  if (outPath[0]) {
    std::vector<Vec> cv;
    if (scene.contact) {
      // multipliers (nodal pressures), int psi_i, slave vertex coordinates, mean master normal
      const char *names[] = {"x", "y", "z"}, *nn[] = {"normal_x", "normal_y", "normal_z"};
      PetscCall(PetscObjectSetName((PetscObject)kacanov.lambda, "lambda"));
      PetscCall(PetscObjectSetName((PetscObject)kacanov.sys.weight, "weight"));
      cv = {kacanov.lambda, kacanov.sys.weight};
      for (PetscInt d = 0; d < fom.elas.dim; ++d) {
        PetscCall(PetscObjectSetName((PetscObject)kacanov.sys.coord[d], names[d]));
        PetscCall(PetscObjectSetName((PetscObject)kacanov.sys.normal[d], nn[d]));
        cv.push_back(kacanov.sys.coord[d]);
        cv.push_back(kacanov.sys.normal[d]);
      }
    }
    PetscCall(fom.WriteOutput(outPath, cv));
    rep.root["output"] = outPath;
  }
  PetscCall(PetscPrintf(comm, "rbcontact fom: scene %s, %" PetscInt_FMT " dofs, energy %.10e, total %.3f s\n", scene.name.c_str(), fom.GlobalSize(), rep.root["energy"].AsNumber(), (double)fom.times.total));
  PetscCall(rep.Write(comm, reportPath));
  PetscFunctionReturn(0);
}

} // namespace rbc
