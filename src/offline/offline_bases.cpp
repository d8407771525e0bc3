// src/offline/offline_bases.cpp: POD of the displacement snapshots (energy, H1 or l2 inner product of the
// reference configuration) and the nonnegative dual basis of the multiplier snapshots; ROM file.
#include "rbcontact/offline_bases.hpp"
#include <algorithm>
#include <sys/stat.h>
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/pod.hpp"
#include "rbcontact/rom_file.hpp"
#include "rbcontact/supremizers.hpp"
#include "rbcontact/offline_rom.hpp"
#include "rbcontact/estimate_calibration.hpp"
#include "rbcontact/dual_selection.hpp"
#include "rbcontact/rom_fields.hpp"
#include "rbcontact/kacanov.hpp"
#include "rbcontact/mesh.hpp"
#include "rbcontact/report.hpp"
#include <cstdio>
#include <cmath>
#include <unistd.h>
#include <filesystem>
#include <cstring>
#include <sstream>

namespace rbc {

PetscErrorCode ReportDualBasis(MPI_Comm comm, const DualBasisResult &dual, Report *rep)
{
  PetscReal wmin = 0;

  PetscFunctionBeginUser;
  for (PetscReal w : dual.W.a) wmin = std::min(wmin, w);
  PetscCheck(wmin >= 0, comm, PETSC_ERR_PLIB, "dual basis has a negative entry (%g)", (double)wmin);
  JsonValue &d           = rep->root["dual"];
  d["type"]              = dual.type;
  d["r"]                 = (long long)dual.W.cols;
  d["train_max_err"]     = (double)dual.trainMaxErr;
  d["train_max_rel_err"] = (double)dual.trainMaxRelErr;
  d["history"]           = dual.history;
  d["tol_abs"]           = (double)dual.tolAbs;
  d["tol_reached"]       = dual.TolReached();
  d["norm"]              = dual.norm;
  d["gram_cond"]         = Finite(dual.gramCond);
  d["selected"]          = std::vector<double>(dual.selected.begin(), dual.selected.end());
  d["skipped_dependent"] = std::vector<double>(dual.skipped.begin(), dual.skipped.end());
  d["min_entry"]         = (double)wmin;
  JsonValue &n           = rep->root["nnls"];
  n["solves"]            = (long long)dual.nnls.solves;
  n["max_kkt"]           = (double)dual.nnls.maxKKT;
  n["retries"]           = (long long)dual.nnls.retries;
  PetscFunctionReturn(0);
}

void WriteDualBasis(const DualBasisResult &dual, RomWriter *w, bool withBasis)
{
  const PetscInt      r = dual.W.cols, R = dual.W.rows;
  std::vector<double> wt((size_t)r * R);
  for (PetscInt k = 0; k < r; ++k)
    for (PetscInt i = 0; i < R; ++i) wt[(size_t)k * R + i] = dual.W(i, k);
  w->Attr("dual_type", dual.type);
  if (withBasis) w->Dataset("/dual/basis", {(unsigned long long)r, (unsigned long long)R}, wt);
  w->Dataset("/dual/history", {dual.history.size()}, dual.history);
  w->Dataset("/dual/gram_cond", {dual.gramCond.size()}, dual.gramCond);
  w->Dataset("/dual/selected", {dual.selected.size()}, std::vector<double>(dual.selected.begin(), dual.selected.end()));
}

// path as seen from the directory of file (so that the pair can be moved together); path itself when
// they share no root.
static std::string RelativeTo(const std::string &path, const std::string &file)
{
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path  p = fs::absolute(path, ec).lexically_normal(), d = fs::absolute(file, ec).lexically_normal().parent_path();
  const fs::path  r = p.lexically_relative(d);
  return ec || r.empty() ? path : r.string();
}

PetscErrorCode DualSensitivityStepFromOptions(MPI_Comm comm, PetscReal *step)
{
  PetscFunctionBeginUser;
  *step = 0.1;
  PetscOptionsBegin(comm, "dual_", "Predicted multipliers of the sensitivity snapshots (offline)", "OfflineBases");
  PetscCall(PetscOptionsReal("-sensitivity_step", "with -snapshots_sensitivities: the dual greedy also sees [lambda +- step range_i dlambda/dmu_i]_+ (a fraction of the range; 0: not)", "", *step, step, NULL));
  PetscOptionsEnd();
  PetscCheck(*step >= 0 && *step <= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dual_sensitivity_step %g must lie in [0, 1] (a fraction of the parameter's range; 0: no predicted multipliers)", (double)*step);
  PetscFunctionReturn(0);
}

PetscErrorCode CheckSnapshotSensitivities(MPI_Comm world, const std::vector<Snapshot> &snaps, const std::string &path)
{
  PetscFunctionBeginUser;
  for (const auto &sn : snaps) {
    const auto it = sn.extra.find("sensitivity_u");
    const auto il = sn.extra.find("sensitivity_lambda");
    PetscCheck(it != sn.extra.end() && it->second.size() == sn.mu.size() * sn.u.size() && il != sn.extra.end() && il->second.size() == sn.mu.size() * sn.lambda.size(), world, PETSC_ERR_FILE_UNEXPECTED, "-snapshots_sensitivities: snapshot %" PetscInt_FMT " of %s has no sensitivities (solved without -snapshots_sensitivities): drop the option or solve the snapshots again in a new file", sn.index, path.empty() ? "the snapshot file" : path.c_str());
    bool any = false; // a file whose first sensitivity snapshot came after this one reads zeros here
    for (PetscReal x : it->second) any = any || x != 0;
    PetscCheck(any, world, PETSC_ERR_FILE_UNEXPECTED, "-snapshots_sensitivities: snapshot %" PetscInt_FMT " of %s has no sensitivities (all zero: solved without -snapshots_sensitivities): drop the option or solve the snapshots again in a new file", sn.index, path.empty() ? "the snapshot file" : path.c_str());
  }
  PetscFunctionReturn(0);
}

PetscErrorCode EstimateEnrichmentOptions(MPI_Comm world, PetscBool *estimate, PetscReal *estPodTol, PetscReal *estDualTol)
{
  PetscReal podTol = kPODDefaultTol, dualTol = kDualDefaultTol;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetReal(NULL, "pod_", "-tol", &podTol, NULL));
  PetscCall(PetscOptionsGetReal(NULL, "dual_", "-tol", &dualTol, NULL));
  *estimate = PETSC_FALSE;
  PetscOptionsBegin(world, NULL, "Online error estimate (offline)", "OfflineBases");
  PetscCall(PetscOptionsBool("-estimate", "store enriched bases and a calibration for the online error estimate (docs/error_estimate.md)", "", *estimate, estimate, NULL));
  *estPodTol  = podTol * 1e-2;
  *estDualTol = dualTol * 0.1;
  PetscCall(PetscOptionsReal("-estimate_pod_tol", "POD tolerance of the enriched primal space (default -pod_tol / 100)", "", *estPodTol, estPodTol, NULL));
  PetscCall(PetscOptionsReal("-estimate_dual_tol", "dual greedy tolerance of the enriched dual space (default -dual_tol / 10)", "", *estDualTol, estDualTol, NULL));
  PetscOptionsEnd();
  if (*estimate) {
    PetscCheck(*estPodTol >= 0 && *estPodTol <= podTol, world, PETSC_ERR_ARG_OUTOFRANGE, "-estimate_pod_tol %g must lie in [0, -pod_tol = %g]", (double)*estPodTol, (double)podTol);
    PetscCheck(*estDualTol > 0 && *estDualTol <= dualTol, world, PETSC_ERR_ARG_OUTOFRANGE, "-estimate_dual_tol %g must lie in (0, -dual_tol = %g]", (double)*estDualTol, (double)dualTol);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode BuildBases(MPI_Comm world, ElasticFOM &fom, CanonicalOrder &order, const std::vector<Snapshot> &snaps, PetscInt R, ContactMap *cmap, OfflineBasisSet *b, bool sensitivities, const std::string &source)
{
  PetscLogDouble t0, t1, t2;
  char           inner[32] = "energy";
  const PetscInt m = (PetscInt)snaps.size();

  PetscFunctionBeginUser;
  PetscCheck(m > 0, world, PETSC_ERR_ARG_SIZ, "offline: no snapshot to build the bases from");
  // --- the error estimate's enrichment (-estimate): the same bases to tighter tolerances, the answer's sizes noted
  PetscBool estimate = PETSC_FALSE, podNSet = PETSC_FALSE;
  PetscReal podTol = kPODDefaultTol, dualTol = kDualDefaultTol, estPodTol = -1, estDualTol = -1;
  char      dualType[16] = ""; // unset: BuildDualBasis's default, a greedy
  PetscCall(PetscOptionsGetReal(NULL, "pod_", "-tol", &podTol, NULL));
  PetscCall(PetscOptionsGetReal(NULL, "dual_", "-tol", &dualTol, NULL));
  PetscCall(PetscOptionsHasName(NULL, "pod_", "-n", &podNSet));
  PetscCall(PetscOptionsGetString(NULL, "dual_", "-type", dualType, sizeof dualType, NULL));
  PetscCall(EstimateEnrichmentOptions(world, &estimate, &estPodTol, &estDualTol));
  b->estimate = estimate;
  b->nDefault = b->rDefault = -1;
  // --- primal: POD in the chosen inner product of the reference configuration
  PetscCall(PetscTime(&t0));
  PetscOptionsBegin(world, "pod_", "Primal basis (offline)", "OfflineBases");
  PetscCall(PetscOptionsString("-inner", "inner product of the POD: energy, h1 or l2", "", inner, inner, sizeof inner, NULL));
  PetscOptionsEnd();
  b->inner = inner;
  Mat M = nullptr;
  if (!strcmp(inner, "energy")) {
    Vec fref = nullptr;
    PetscCall(fom.SetMu(ParamValues(fom.scene))); // the reference (default) parameter
    if (fom.useAffine) PetscCall(fom.affine.Assemble(fom.mu, &M, &fref));
    else PetscCall(fom.elas.Assemble(&M, &fref));
    PetscCall(VecDestroy(&fref));
  } else if (!strcmp(inner, "h1")) PetscCall(fom.elas.AssembleH1(&M));
  else PetscCheck(!strcmp(inner, "l2"), world, PETSC_ERR_ARG_UNKNOWN_TYPE, "-pod_inner: unknown value '%s' (energy, h1 or l2)", inner);
  // -snapshots_sensitivities: every snapshot's scaled derivatives du/dmu_i (the extra "sensitivity_u", np x ndofs)
  // join the POD's vectors (docs/greedy_training.md "Sensitivity snapshots")
  const bool     sens = sensitivities;
  const PetscInt np = (PetscInt)snaps[0].mu.size(), ndofs = (PetscInt)snaps[0].u.size();
  if (sens) PetscCall(CheckSnapshotSensitivities(world, snaps, source));
  b->dualPredicted = 0;
  // a training parameter listed again adds nothing (the same solution): each parameter's snapshot taken once, so that
  // a repetition cannot tip a mode over the POD's or the dual greedy's tolerance by rounding (tests/hard_cases.py
  // repeated_training; the contact states of the cubature skip repetitions too: offline_rom.cpp)
  std::vector<PetscInt> once;
  for (PetscInt j = 0; j < m; ++j) {
    bool seen = false;
    for (PetscInt k : once) seen = seen || snaps[k].mu == snaps[j].mu;
    if (!seen) once.push_back(j);
  }
  const PetscInt m1 = (PetscInt)once.size();
  b->snapshotsUsed  = m1;
  std::vector<const PetscReal *> cols;
  for (PetscInt j : once) cols.push_back(snaps[j].u.data());
  if (sens)
    for (PetscInt j : once)
      for (PetscInt i = 0; i < np; ++i) cols.push_back(snaps[j].extra.at("sensitivity_u").data() + (size_t)i * ndofs);
  b->sensitivityVectors = sens ? m1 * np : 0;
  std::vector<Vec> X(cols.size());
  {
    PetscInt lo, hi;
    Vec      tmpl;
    PetscCall(DMCreateGlobalVector(fom.dm, &tmpl));
    PetscCall(VecGetOwnershipRange(tmpl, &lo, &hi));
    for (size_t j = 0; j < cols.size(); ++j) {
      PetscScalar *a;
      PetscCall(VecDuplicate(tmpl, &X[j]));
      PetscCall(VecGetArray(X[j], &a));
      for (PetscInt i = lo; i < hi; ++i) a[i - lo] = cols[j][order.CanonicalDof(i)];
      PetscCall(VecRestoreArray(X[j], &a));
    }
    PetscCall(VecDestroy(&tmpl));
  }
  PODResult &pod = b->pod;
  PetscCall(BVDestroy(&pod.modes));
  if (estimate && !podNSet) { // -pod_n fixes the size: no primal enrichment then
    PetscCall(ComputePOD(X, M, &pod, estPodTol));
    const PetscInt n = PODSizeForTolerance(pod, podTol);
    b->nDefault      = n < pod.N ? n : -1;
  } else PetscCall(ComputePOD(X, M, &pod));
  for (auto &v : X) PetscCall(VecDestroy(&v));
  PetscCall(PetscTime(&t1));

  // --- dual: nonnegative basis of the multiplier snapshots (every rank, redundant and deterministic)
  DualBasisResult &dual = b->dual;
  dual                  = DualBasisResult();
  if (R > 0) {
    // -snapshots_sensitivities: besides every snapshot's multipliers, their first-order predictions a step
    // -dual_sensitivity_step (a fraction of each parameter's range) away along +-mu_i, [lambda +- step dlambda_i]_+
    // (nonnegative, so that the cone can hold the tangent of the multipliers; docs/greedy_training.md)
    PetscReal step;
    PetscCall(DualSensitivityStepFromOptions(world, &step));
    std::vector<PetscInt> srcOf(once); // the snapshot of each column of L
    if (sens && step > 0)
      for (PetscInt j : once)
        for (PetscInt i = 0; i < np; ++i)
          for (int sg = 0; sg < 2; ++sg) srcOf.push_back(j);
    DenseMatrix L;
    L.Resize(R, (PetscInt)srcOf.size());
    for (PetscInt c = 0; c < m1; ++c)
      for (PetscInt i = 0; i < R; ++i) L(i, c) = snaps[once[c]].lambda[i];
    for (PetscInt c = m1; c < (PetscInt)srcOf.size(); ++c) {
      const PetscInt   j = srcOf[c], i = (c - m1) / 2 % np;
      const PetscReal  sgn = (c - m1) % 2 ? -step : step;
      const PetscReal *dl  = snaps[j].extra.at("sensitivity_lambda").data() + (size_t)i * R;
      for (PetscInt r = 0; r < R; ++r) L(r, c) = std::max<PetscReal>(0, snaps[j].lambda[r] + sgn * dl[r]);
    }
    b->dualPredicted = (PetscInt)srcOf.size() - m1;
    // -dual_mass_weighted (default off; needs the contact map): the greedy's errors in the slave-mass
    // weighted norm of the reported lambda error, ||x||_M^2 = sum_i int psi_i x_i^2 (reference
    // configuration): rows scaled by sqrt(int psi_i), the basis unscaled after (nonnegativity kept).
    PetscBool massWeighted = PETSC_FALSE;
    PetscOptionsBegin(world, "dual_", "Dual basis (offline)", "OfflineBases");
    PetscCall(PetscOptionsBool("-mass_weighted", "the dual greedy in the slave-mass weighted norm of the reported lambda error", "", massWeighted, &massWeighted, NULL));
    PetscOptionsEnd();
    PetscCheck(!massWeighted || cmap, world, PETSC_ERR_ARG_INCOMP, "-dual_mass_weighted needs the scene's contact surfaces (-contact_slave, -contact_master)");
    std::vector<PetscReal> sw(R, 1.0);
    if (massWeighted) {
      std::vector<PetscReal> w;
      PetscCall(ReferenceSlaveMass(fom, *cmap, order, &w));
      PetscCheck((PetscInt)w.size() == R, world, PETSC_ERR_PLIB, "slave mass of %zu entries for %" PetscInt_FMT " multipliers", w.size(), R);
      for (PetscInt i = 0; i < R; ++i) sw[i] = std::sqrt(std::max<PetscReal>(w[i], 0));
      for (PetscInt j = 0; j < L.cols; ++j)
        for (PetscInt i = 0; i < R; ++i) L(i, j) *= sw[i];
    }
    if (estimate && strcmp(dualType, "nmf")) { // a greedy: its first vectors are those of the looser tolerance
      PetscCall(BuildDualBasis(L, &dual, estDualTol));
      const PetscReal tolAbs = dual.tolAbs * dualTol / estDualTol; // the answer's absolute tolerance
      PetscInt        r      = dual.W.cols;
      for (size_t k = 0; k < dual.history.size(); ++k)
        if (dual.history[k] <= tolAbs) {
          r = (PetscInt)k + 1;
          break;
        }
      b->rDefault = r < dual.W.cols ? r : -1;
    } else PetscCall(BuildDualBasis(L, &dual));
    // an absolute -dual_tol at or above every snapshot's distance to the empty cone keeps no vector: refused here, by
    // name (it came later as "0 supremizers for 0 dual vectors" or "-rom_R 0 out of range", naming no given option)
    PetscCheck(dual.W.cols > 0, world, PETSC_ERR_ARG_OUTOFRANGE, "the dual basis is empty: the tolerance %g (-dual_tol, absolute) is at or above the error of every multiplier snapshot without a basis (%.3e): lower -dual_tol", (double)dual.tolAbs, (double)dual.trainMaxErr);
    for (auto &j : dual.selected)
      if (j >= 0) j = srcOf[j]; // a predicted column counts as its snapshot's (the supremizers' K)
    if (massWeighted)
      for (PetscInt k = 0; k < dual.W.cols; ++k)
        for (PetscInt i = 0; i < R; ++i) dual.W(i, k) = sw[i] > 0 ? dual.W(i, k) / sw[i] : 0.0;
    b->massWeighted = massWeighted;
  }
  PetscCall(PetscTime(&t2));

  // --- supremizers (-pod_supremizers): s_k = A^{-1} K(mu_k)^T xi_k for every dual basis vector xi_k,
  // K(mu_k) the constraint of the snapshot the greedy selected for xi_k (nmf: the snapshot whose
  // multipliers are most aligned with xi_k), A the reference stiffness; their M-orthogonal complement to
  // the POD modes compressed to the fewest directions that keep -pod_supremizers_infsup (default 1) of
  // the full enrichment's inf-sup constant over the training snapshots (supremizers.hpp), and the
  // enlarged primal basis re-orthonormalized in the POD inner product.
  PetscBool             supremizers = PETSC_FALSE;
  PetscInt             &nsup        = b->nsup;
  PetscReal             supRatio;
  SupremizerEnrichment &enr = b->enr;
  nsup                      = 0;
  enr                       = SupremizerEnrichment();
  // (a title of its own: PETSc prints the help of a (prefix, title) block once)
  PetscOptionsBegin(world, "pod_", "Supremizer enrichment (offline)", "OfflineBases");
  PetscCall(PetscOptionsBool("-supremizers", "enrich the POD with supremizers of the dual vectors (inf-sup of the reduced saddle point)", "", supremizers, &supremizers, NULL));
  PetscOptionsEnd();
  PetscCall(SupremizerRatioFromOptions(world, &supRatio));
  if (supremizers && R > 0) {
    const PetscInt   r = dual.W.cols;
    BV               Vs;
    PetscInt         lo, hi;
    std::vector<Vec> sup(r);
    // the snapshots' contact matrices K(u_j) on the contact dofs, reassembled (the snapshot file stores none)
    SnapshotContactMatrices KS;
    PetscCheck(cmap, world, PETSC_ERR_ARG_NULL, "supremizers: no contact map to assemble the snapshots' contact matrices with");
    PetscLogDouble c0, c1;
    PetscCall(PetscTime(&c0));
    PetscCall(AssembleSnapshotContactMatrices(world, fom, *cmap, order, snaps, &KS));
    PetscCall(PetscTime(&c1));
    b->contactSeconds = c1 - c0;
    PetscCall(fom.SetMu(ParamValues(fom.scene)));
    PetscCall(fom.AssembleAndFactor());
    PetscCall(VecGetOwnershipRange(fom.f, &lo, &hi));
    // global dof of each canonical index (owned entries only)
    std::vector<PetscInt> globalOf(order.NumDofs(), -1);
    for (PetscInt i = lo; i < hi; ++i) globalOf[order.CanonicalDof(i)] = i;
    Vec rhs;
    PetscCall(VecDuplicate(fom.f, &rhs));
    for (PetscInt k = 0; k < r; ++k) {
      PetscInt j = k < (PetscInt)dual.selected.size() ? dual.selected[k] : -1;
      if (j < 0) { // nmf: the most aligned snapshot
        PetscReal best = -1;
        for (PetscInt q = 0; q < m; ++q) {
          PetscReal dot = 0, nrm = 0;
          for (PetscInt i = 0; i < R; ++i) { dot += snaps[q].lambda[i] * dual.W(i, k); nrm += snaps[q].lambda[i] * snaps[q].lambda[i]; }
          if (nrm > 0 && dot / std::sqrt(nrm) > best) { best = dot / std::sqrt(nrm); j = q; }
        }
      }
      PetscCheck(j >= 0 && j < m, world, PETSC_ERR_PLIB, "supremizers: dual vector %" PetscInt_FMT " has no snapshot (%" PetscInt_FMT " of %" PetscInt_FMT ")", k, j, m);
      const SparseRows &KD = KS.K[j];
      const auto       &Dc = KS.dofs;
      const PetscInt    nD = (PetscInt)Dc.size();
      PetscCheck(KD.rows == R && KD.cols == nD, world, PETSC_ERR_ARG_SIZ, "supremizers: snapshot %" PetscInt_FMT ": contact matrix %" PetscInt_FMT " x %" PetscInt_FMT " for %" PetscInt_FMT " x %" PetscInt_FMT, snaps[j].index, KD.rows, KD.cols, R, nD);
      std::vector<PetscReal> y(nD, 0.0); // K_D^T xi, K_D by rows (R x nD, canonical orders)
      for (PetscInt i = 0; i < R; ++i)
        for (PetscInt e = KD.ptr[i]; e < KD.ptr[i + 1]; ++e) y[KD.col[e]] += KD.val[e] * dual.W(i, k);
      PetscCall(VecSet(rhs, 0.0));
      for (PetscInt c = 0; c < nD; ++c) {
        const PetscInt g = globalOf[Dc[c]];
        if (g >= 0) PetscCall(VecSetValue(rhs, g, y[c], INSERT_VALUES));
      }
      PetscCall(VecAssemblyBegin(rhs));
      PetscCall(VecAssemblyEnd(rhs));
      PetscCall(VecDuplicate(fom.f, &sup[k]));
      PetscCall(fom.ApplyInverse(rhs, sup[k]));
    }
    PetscCall(VecDestroy(&rhs));
    std::vector<PetscInt> canonical(order.NumDofs());
    for (PetscInt i = 0; i < order.NumDofs(); ++i) canonical[i] = order.CanonicalDof(i);
    PetscCall(EnrichWithSupremizers(pod.modes, sup, KS, dual.W, canonical, supRatio, &Vs, &enr));
    for (auto &v : sup) PetscCall(VecDestroy(&v));
    PetscInt nv;
    PetscCall(BVGetActiveColumns(Vs, NULL, &nv));
    // orthonormality of the enlarged basis (reported as pod.orthonormality_error)
    Mat G;
    PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, nv, nv, NULL, &G));
    PetscCall(BVDot(Vs, Vs, G));
    PetscReal err = 0;
    const PetscScalar *g;
    PetscCall(MatDenseGetArrayRead(G, &g));
    for (PetscInt i = 0; i < nv; ++i)
      for (PetscInt q = 0; q < nv; ++q) err = std::max(err, std::abs(PetscRealPart(g[i + q * nv]) - (i == q ? 1.0 : 0.0)));
    PetscCall(MatDenseRestoreArrayRead(G, &g));
    PetscCall(MatDestroy(&G));
    PetscCall(BVDestroy(&pod.modes));
    pod.modes               = Vs;
    nsup                    = enr.kept;
    pod.N                   = nv;
    pod.orthonormalityError = err;
    PetscCall(PetscInfo(NULL, "supremizers: %" PetscInt_FMT " of %" PetscInt_FMT " compressed directions kept (inf-sup %g, all %g)\n", enr.kept, enr.rank, (double)enr.beta[enr.kept], (double)enr.beta.back()));
  }
  PetscCall(MatDestroy(&M));
  std::vector<double> &modes = b->modes; // N x ndofs, canonical order, on every rank of fom's communicator
  modes.clear();
  for (PetscInt j = 0; j < pod.N; ++j) {
    Vec                 v;
    std::vector<double> c;
    PetscCall(BVGetColumn(pod.modes, j, &v));
    PetscCall(order.DofsToCanonical(v, &c));
    PetscCall(BVRestoreColumn(pod.modes, j, &v));
    modes.insert(modes.end(), c.begin(), c.end());
  }
  {
    MPI_Comm           fcomm = PetscObjectComm((PetscObject)fom.dm);
    unsigned long long nm    = modes.size();
    PetscCallMPI(MPI_Bcast(&nm, 1, MPI_UNSIGNED_LONG_LONG, 0, fcomm));
    modes.resize(nm);
    PetscCallMPI(MPI_Bcast(modes.data(), (int)nm, MPI_DOUBLE, 0, fcomm));
  }
  b->seconds[0] = t1 - t0;
  b->seconds[1] = t2 - t1;
  PetscFunctionReturn(0);
}

PetscErrorCode TruncateBases(OfflineBasisSet *b, PetscInt r)
{
  PetscFunctionBeginUser;
  DualBasisResult &d = b->dual;
  PetscCheck(r >= 1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "TruncateBases: %" PetscInt_FMT " dual vectors (at least 1)", r);
  if (r >= d.W.cols) PetscFunctionReturn(0);
  d.W.a.resize((size_t)d.W.rows * r); // column-major: the leading r columns
  d.W.cols = r;
  if ((PetscInt)d.selected.size() > r) d.selected.resize(r);
  const PetscInt Npod = b->pod.N - b->nsup, nsup = std::min(b->nsup, r), N = Npod + nsup;
  if (N < b->pod.N) {
    const size_t ndofs = b->modes.size() / (size_t)b->pod.N;
    BV           V;
    PetscCall(BVDuplicateResize(b->pod.modes, N, &V)); // carries the modes' inner-product matrix
    for (PetscInt j = 0; j < N; ++j) {
      Vec x;
      PetscCall(BVGetColumn(b->pod.modes, j, &x));
      PetscCall(BVInsertVec(V, j, x));
      PetscCall(BVRestoreColumn(b->pod.modes, j, &x));
    }
    PetscCall(BVDestroy(&b->pod.modes));
    b->pod.modes = V;
    b->modes.resize((size_t)N * ndofs); // N x ndofs, the leading N modes
    b->pod.N = N;
    b->nsup  = nsup;
  }
  PetscFunctionReturn(0);
}

PetscErrorCode OfflineBases(MPI_Comm world, ElasticFOM &fom, CanonicalOrder &order, const std::string &snapPath, const std::string &romPath, const SnapshotHeader &header, Report *rep, ContactMap *cmap, bool onlineRom, const std::string &basisPath, bool partial, bool sensitivities)
{
  PetscMPIInt     wrank;
  OfflineBasisSet bs;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(world, &wrank));
  std::vector<Snapshot> snaps;
  PetscCall(SnapshotFile::ReadAll(snapPath, &snaps));
  const PetscInt m = (PetscInt)snaps.size(), ntrain = (PetscInt)header.trainingPoints.size(), R = header.nmult;
  PetscCheck(m == ntrain || (partial && m > 0), world, PETSC_ERR_USER_INPUT, "Snapshot file '%s' holds %" PetscInt_FMT " of %" PetscInt_FMT " snapshots: finish it first (offline -offline_stop snapshots -snapshots_restart)", snapPath.c_str(), m, ntrain);
  PetscCall(BuildBases(world, fom, order, snaps, R, cmap, &bs, sensitivities, snapPath));
  DualSelectionOptions dso;
  PetscCall(DualSelectionFromOptions(world, &dso));
  const PetscInt rBuilt = bs.dual.W.cols;
  if (R > 0 && dso.truncate > 0) PetscCall(TruncateBases(&bs, dso.truncate)); // -dual_truncate
  PODResult            &pod   = bs.pod;
  DualBasisResult      &dual  = bs.dual;
  const PetscInt       &nsup  = bs.nsup; // TruncateBases (-dual_select_refit) may cut it
  SupremizerEnrichment &enr   = bs.enr;
  std::vector<double>  &modes = bs.modes;
  const char           *inner = bs.inner.c_str();
  if (R > 0) {
    rep->root["dual_mass_weighted"] = bs.massWeighted;
    // a dual basis that keeps (nearly) every training multiplier compresses nothing: the training set is
    // too coarse for the dual tolerance (the greedy's error between training points is not controlled)
    // (-snapshots_sensitivities: the candidates are the snapshots' multipliers and their predicted neighbours)
    const PetscInt rAnswer   = bs.rDefault > 0 ? bs.rDefault : dual.W.cols, cand = bs.snapshotsUsed + bs.dualPredicted;
    // (1 or 2 candidates were left out: exactly the coarsest sets, a lambda error 30x the 7-point set's without a word)
    const bool     tooCoarse = rAnswer >= cand - 1 || cand <= 2;
    rep->root["dual_kept_all_snapshots"] = tooCoarse;
    if (tooCoarse) PetscCall(PetscPrintf(world, "rbcontact offline: warning: the dual basis keeps %" PetscInt_FMT " of the %" PetscInt_FMT " training multipliers: the training set is too coarse for -dual_tol (use more training parameters or a larger -dual_tol)\n", rAnswer, cand));
    // a basis that misses its tolerance (nmf's fixed rank, -dual_max_r, the cone's limit): the report said so, the
    // terminal did not (the ROM 30-60x worse, exit 0), as dualbasis does since 2026-11-29
    if (!dual.TolReached()) PetscCall(PetscPrintf(world, "rbcontact offline: warning: the dual basis misses its tolerance: max training error %.3e > %.3e (%s)\n", (double)dual.trainMaxErr, (double)dual.tolAbs, dual.MissedTolReason(cand).c_str()));
  }

  // --- bases file (-offline_stop bases: the ROM path; full pipeline: basisPath) and ROM file
  const std::string &bpath = onlineRom ? basisPath : romPath;
  RomWriter          w, wr;
  // rom_id: one id for the files of this run (ROM and basis file), checked when they are read together
  std::string romId;
  {
    std::ostringstream id;
    PetscLogDouble     now;
    PetscCall(PetscTime(&now));
    id << std::hex << Fnv1a(std::to_string(header.sceneHash) + " " + std::to_string(now) + " " + std::to_string((long long)getpid()));
    romId = id.str();
    PetscCall(BcastString(world, &romId));
  }
  auto provenance = [&](RomWriter *x) {
    std::ostringstream hs;
    hs << std::hex << header.sceneHash;
    x->Attr("scene", header.scene);
    x->Attr("scene_hash", hs.str());
    x->Attr("rom_id", romId);
    x->Attr("snapshots_code_version", header.codeVersion); // the code that computed the snapshots (this file's own: code_version, code_commit)
    x->Attr("snapshots", snapPath);
    x->Attr("options", header.optionsText);
    x->Attr("pod_inner", inner);
    x->Dataset("/pod/singular_values", {pod.singularValues.size()}, pod.singularValues);
  };
  // the basis file's datasets (w) and, with the online ROM, the online model (wr)
  // (ecswTol > 0: the cubature's tolerance instead of -ecsw_tol's)
  auto writers = [&](RomWriter *bw, RomWriter *rw, PetscReal ecswTol) -> PetscErrorCode {
    PetscFunctionBeginUser;
    if (wrank == 0) {
      provenance(bw);
      std::vector<double> box;
      for (size_t i = 0; i < header.paramMin.size(); ++i) { box.push_back(header.paramMin[i]); box.push_back(header.paramMax[i]); }
      bw->Dataset("/params/box", {header.paramMin.size(), 2}, box);
      bw->Dataset("/pod/modes", {(unsigned long long)pod.N, (unsigned long long)header.ndofs}, modes);
      if (R > 0) WriteDualBasis(dual, bw, true);
    }
    if (onlineRom) {
      PetscCheck(cmap, world, PETSC_ERR_ARG_WRONGSTATE, "offline: the online ROM needs the contact surfaces (-contact_slave, -contact_master)");
      // the online ROM: everything the online stage needs, nothing of the size of the mesh
      PetscCheck(R > 0, world, PETSC_ERR_SUP, "offline: no multipliers (R = 0): nothing to reduce for contact");
      rw->version = 2;
      if (wrank == 0) {
        provenance(rw);
        rw->Attr("basis_file", RelativeTo(basisPath, romPath)); // read back relative to the ROM file (rom_fields.cpp)
        WriteDualBasis(dual, rw, false);
      }
      PetscCall(OfflineReducedModel(world, fom, *cmap, order, snaps, pod.modes, modes, pod.N - nsup, nsup, dual, rw, rep, bs.nDefault, bs.rDefault, ecswTol));
    }
    PetscFunctionReturn(0);
  };
  // -dual_select_refit (docs/dual_basis.md "The cubature refitted to the chosen R"): the bases cut to the chosen R, the
  // online model built again for them (its cubature fitted to the answer's terms only) and validated on the same
  // held-out solutions; kept when RefitKept, else both files and the report as they were
  const DualBasisResult dualBuilt = bs.dual; // R x r: small
  bool                  refitDropped = false;
  PetscInt              nFile = 0, nsupFile = 0; // the files' sizes before a refit
  auto refitChosen = [&](const DualSizeRow &chosen) -> PetscErrorCode {
    PetscLogDouble t0, t1;
    PetscFunctionBeginUser;
    PetscCall(PetscTime(&t0));
    const JsonValue before   = rep->root;
    const long long mcBefore = (long long)rep->root["rom"]["Mc"].AsNumber();
    nFile = pod.N;
    nsupFile = nsup;
    PetscCall(TruncateBases(&bs, chosen.R));
    RomWriter bw, rw;
    PetscCall(writers(&bw, &rw, dso.refitEcswTol)); // -dual_select_refit_ecsw_tol (0: -ecsw_tol's)
    const long long mc       = (long long)rep->root["rom"]["Mc"].AsNumber();
    const double    refitTol = rep->root["ecsw"]["tol"].AsNumber();
    PetscCall(bw.Write(world, bpath));
    PetscCall(rw.Write(world, romPath));
    DualSizeRow row;
    PetscCall(ValidateRefit(world, fom.scene, romPath, dso, &row));
    const bool kept = RefitKept(row, chosen, dso.refitSlack, dso.guard, dso.floor), keptRelative = RefitKept(row, chosen, dso.refitSlack, dso.guard);
    if (!kept) {
      rep->root = before;
      PetscCall(w.Write(world, bpath));
      PetscCall(wr.Write(world, romPath));
      bs.dual      = dualBuilt;
      refitDropped = true;
    }
    PetscCall(PetscTime(&t1));
    JsonValue &r           = rep->root["dual_select"]["refit"];
    r["R"]                 = (long long)row.R;
    r["N"]                 = (long long)row.N;
    r["Mc_before"]         = mcBefore;
    r["Mc"]                = mc;
    r["max_rel_err_u"]     = row.u;
    r["max_rel_err_lambda"] = row.lambda;
    r["max_rel_err_force"] = row.force;
    r["failed"]            = row.failed;
    r["slack"]             = (double)dso.refitSlack;
    r["ecsw_tol"]          = refitTol; // the refit's cubature tolerance (the report's ecsw: the kept model's)
    r["kept"]              = kept;
    r["kept_relative"]     = keptRelative; // the rule without -dual_select_floor
    rep->root["time_s"]["dual_select_refit"] = (double)(t1 - t0);
    PetscCall(PetscPrintf(world, "rbcontact offline: the online model refitted to R %" PetscInt_FMT " (N %" PetscInt_FMT "): Mc %lld -> %lld, held-out max rel err lambda %.3e u %.3e force %.3e (before: %.3e, %.3e, %.3e): %s\n", row.R, row.N, mcBefore, mc, row.lambda, row.u, row.force, chosen.lambda, chosen.u, chosen.force, kept ? (keptRelative ? "kept" : "kept (under -dual_select_floor)") : "not kept (-dual_select_refit_slack, -dual_select_guard, -dual_select_floor), the files as before"));
    PetscFunctionReturn(0);
  };
  PetscCall(writers(&w, &wr, 0));
  // the bases alone (-offline_stop bases) are written now; with the online ROM, after it is built, so
  // that a failed run leaves the previous ROM and basis file together (and rom_id tells a torn pair)
  if (!onlineRom) PetscCall(w.Write(world, bpath));
  if (onlineRom) {
    // the calibration and the held-out choice read the written files: a failure there (an option out of range, a FOM
    // solve) left the new pair in place of the previous one (audit of 2026-12-01), so the previous files are kept aside
    // (hard links) until the last step and put back on a failure
    PreviousFiles   previous(world, {bpath, romPath});
    DualSizeRow     chosen;
    PetscErrorCode  ierr = [&]() -> PetscErrorCode {
      PetscFunctionBeginUser;
      PetscCall(w.Write(world, bpath));
      PetscCall(wr.Write(world, romPath));
      if (bs.estimate) PetscCall(CalibrateErrorEstimate(world, fom.scene, romPath, &wr, rep));
      PetscCall(SelectDualSize(world, fom.scene, romPath, dso, &wr, rep, &chosen)); // -dual_select_*: the answer's R on held-out solutions
      if (dso.refit && chosen.R < dual.W.cols) PetscCall(refitChosen(chosen));
      PetscFunctionReturn(0);
    }();
    if (ierr) {
      previous.Restore();
      PetscFunctionReturn(ierr);
    }
    previous.Drop();
    unsigned long long big[2] = {0, 0};
    std::string        bigName;
    if (wrank == 0) {
      const auto l = wr.Largest();
      bigName      = l.first;
      big[0]       = l.second;
    }
    PetscCallMPI(MPI_Bcast(big, 2, MPI_UNSIGNED_LONG_LONG, 0, world));
    PetscCall(BcastString(world, &bigName));
    rep->root["rom_largest_array"]["name"]    = bigName;
    rep->root["rom_largest_array"]["entries"] = (long long)big[0];
    rep->root["basis_file"]                   = basisPath;
  }

  JsonValue &p = rep->root["pod"];
  p["n"]               = (long long)(refitDropped ? nFile : pod.N); // the files' (a dropped refit cut only the memory's)
  p["inner"]           = inner;
  p["singular_values"] = pod.singularValues;
  p["energy_captured"] = (double)pod.energyCaptured;
  p["orthonormality_error"] = (double)pod.orthonormalityError;
  p["supremizers"]     = (long long)(refitDropped ? nsupFile : nsup);
  p["sensitivity_vectors"] = (long long)bs.sensitivityVectors;
  rep->root["dual"]["predicted_columns"] = (long long)bs.dualPredicted;
  if (enr.candidates > 0) {
    JsonValue &ps             = p["supremizer_enrichment"];
    ps["candidates"]          = (long long)enr.candidates;
    ps["rank"]                = (long long)enr.rank;
    ps["kept"]                = (long long)enr.kept;
    ps["infsup_ratio"]        = (double)enr.ratio;
    ps["inf_sup"]             = (double)enr.beta[enr.kept];
    ps["inf_sup_all"]         = (double)enr.beta.back();
    ps["inf_sup_by_kept"]     = enr.beta;
    ps["sigma"]               = enr.sigma;
    ps["elastic_solver"]      = fom.ElasticSolverName(); // the supremizers' A^{-1}: a MUMPS factor, or CG + GAMG (-fom_saddle_solver gamg)
  }
  if (R > 0) PetscCall(ReportDualBasis(world, dual, rep));
  if (R > 0 && dual.W.cols < rBuilt) rep->root["dual"]["truncated_from"] = (long long)rBuilt; // -dual_truncate, -dual_select_refit
  rep->root["time_s"]["pod"]  = (double)bs.seconds[0];
  rep->root["time_s"]["dual"] = (double)bs.seconds[1];
  rep->root["time_s"]["snapshot_contact"] = (double)bs.contactSeconds; // the snapshots' K(u_j), reassembled for the supremizers
  rep->root["rom_file"]       = romPath;
  PetscFunctionReturn(0);
}

PreviousFiles::PreviousFiles(MPI_Comm comm, const std::vector<std::string> &paths)
{
  PetscMPIInt rank = 0;
  (void)MPI_Comm_rank(comm, &rank);
  if (rank != 0) return;
  for (const auto &p : paths) {
    const std::string target = OutputTarget(p), keep = target + ".previous." + std::to_string((long)getpid());
    if (::link(target.c_str(), keep.c_str()) == 0) kept_.emplace_back(target, keep);
  }
}

void PreviousFiles::Restore()
{
  // atomic: the previous file is back. Where the file was not replaced yet (the failure came first: a full disk while
  // writing it), the link and the file are one inode and rename() does nothing (POSIX): the link is removed instead
  // (it was left beside the file)
  for (const auto &k : kept_) {
    struct stat a, b;
    if (::stat(k.first.c_str(), &a) == 0 && ::stat(k.second.c_str(), &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino) (void)::unlink(k.second.c_str());
    else (void)std::rename(k.second.c_str(), k.first.c_str());
  }
  kept_.clear();
}

void PreviousFiles::Drop()
{
  for (const auto &k : kept_) (void)::unlink(k.second.c_str());
  kept_.clear();
}

PetscErrorCode DualSnapshotMatrix(MPI_Comm comm, const std::string &s, DenseMatrix *Lout)
{
  PetscFunctionBeginUser;
  std::vector<std::vector<PetscReal>> cols;
  if (s.find(':') == std::string::npos && s.size() > 3 && s.substr(s.size() - 3) == ".h5") {
    std::vector<Snapshot> snaps;
    PetscCall(SnapshotFile::ReadAll(s, &snaps));
    for (const auto &sn : snaps) cols.push_back(sn.lambda);
    SnapshotHeader h; // (an unfinished file was used without a word)
    PetscCall(SnapshotFile::ReadHeader(s, &h));
    if (snaps.size() < h.trainingPoints.size()) PetscCall(PetscPrintf(comm, "rbcontact dualbasis: warning: snapshot file %s holds %zu of its %zu snapshots (an unfinished run): the basis is built from those\n", s.c_str(), snaps.size(), h.trainingPoints.size()));
  } else {
    // an rbcontact snapshot file's dataset (s.h5:/snapshots/lambda, ntrain x R) read as a matrix of another code (rows =
    // multipliers) was taken transposed, unfinished rows included, exit 0
    const size_t colon = s.rfind(':');
    if (colon != std::string::npos) {
      SnapshotHeader h;
      PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
      const PetscErrorCode e = SnapshotFile::ReadHeader(s.substr(0, colon), &h);
      PetscCall(PetscPopErrorHandler());
      PetscCheck(e != 0, comm, PETSC_ERR_USER_INPUT, "dualbasis: %s names a dataset in the rbcontact snapshot file %s: give the file itself (-snapshots %s), whose finished rows are read as snapshots", s.c_str(), s.substr(0, colon).c_str(), s.substr(0, colon).c_str());
    }
    PetscCall(ImportSnapshotMatrix(comm, s, &cols));
  }
  PetscCheck(!cols.empty() && !cols[0].empty(), comm, PETSC_ERR_USER_INPUT, "dualbasis: '%s' holds no snapshots", s.c_str());
  DenseMatrix &L    = *Lout;
  PetscReal    vmax = 0, vmin = 0;
  L.Resize((PetscInt)cols[0].size(), (PetscInt)cols.size());
  for (PetscInt j = 0; j < L.cols; ++j)
    for (PetscInt i = 0; i < L.rows; ++i) {
      // (a NaN passed the max/min below and went into the dual basis; an inf hid every negative entry)
      PetscCheck(std::isfinite(cols[j][i]), comm, PETSC_ERR_USER_INPUT, "dualbasis: '%s' holds a non-finite value (%g) in snapshot %" PetscInt_FMT ", entry %" PetscInt_FMT, s.c_str(), (double)cols[j][i], j, i);
      L(i, j) = cols[j][i];
      vmax    = std::max(vmax, std::abs(L(i, j)));
      vmin    = std::min(vmin, L(i, j));
    }
  // multipliers are nonnegative; round-off negatives of imported data are clipped, real ones refused
  PetscCheck(vmin >= -1e-12 * vmax, comm, PETSC_ERR_USER_INPUT, "dualbasis: '%s' has negative entries (min %g, max |.| %g): multiplier snapshots must be nonnegative", s.c_str(), (double)vmin, (double)vmax);
  for (auto &v : L.a) v = std::max(v, 0.0);
  PetscFunctionReturn(0);
}

} // namespace rbc
