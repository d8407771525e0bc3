// include/rbcontact/offline_bases.hpp: the bases step of the offline stage (-offline_stop bases): primal POD
// and nonnegative dual basis from a snapshot file (or snapshots in memory), written to the ROM file.
#pragma once
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/rom_file.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/pod.hpp"
#include "rbcontact/snapshot_file.hpp"
#include "rbcontact/supremizers.hpp"

namespace rbc {

// group: the ranks of fom (a subcommunicator of world); world rank 0 writes romPath.
// cmap: the scene's contact surfaces (null without contact; -dual_mass_weighted and the online ROM need
// them). onlineRom false: bases only (-offline_stop bases), written to romPath (format_version 1);
// true: the bases go to basisPath and the online ROM (format_version 2, src/offline/offline_rom.cpp) to romPath.
// partial: the training set is the done snapshots of the file (a greedy run declares its candidate pool);
// otherwise every training point must be done. sensitivities: BuildBases' (the file's derivatives, checked and used).
PetscErrorCode OfflineBases(MPI_Comm world, ElasticFOM &fom, CanonicalOrder &order, const std::string &snapPath, const std::string &romPath, const SnapshotHeader &header, Report *rep, ContactMap *cmap = nullptr, bool onlineRom = false, const std::string &basisPath = "", bool partial = false, bool sensitivities = false);

// The bases of a set of snapshots, in memory (the bases step, and every round of the greedy training).
struct OfflineBasisSet {
  PODResult            pod;   // pod.modes: N columns on fom's DM, the POD modes then nsup supremizers
  DualBasisResult      dual;  // the nonnegative dual basis (R > 0)
  PetscInt             nsup = 0;
  SupremizerEnrichment enr;
  std::string          inner = "energy"; // -pod_inner
  std::vector<double>  modes;            // the same N columns, N x ndofs canonical, on every rank of fom's communicator
  bool                 massWeighted = false;
  PetscLogDouble       seconds[2]   = {0, 0}; // POD, dual basis
  PetscLogDouble       contactSeconds = 0;      // the snapshots' contact matrices reassembled for the supremizers
  // -estimate (docs/error_estimate.md): the bases are computed to the tighter -estimate_pod_tol / -estimate_dual_tol;
  // the answer uses the leading nDefault POD modes and rDefault dual vectors (what -pod_tol / -dual_tol choose), the
  // rest is the online error estimate's enrichment (-1: none of that kind)
  bool                 estimate = false;
  PetscInt             nDefault = -1, rDefault = -1;
  PetscInt             sensitivityVectors = 0; // -snapshots_sensitivities: the scaled du/dmu_i among the POD's vectors
  PetscInt             dualPredicted      = 0; // and the predicted multipliers [lambda +- step dlambda_i]_+ among the dual greedy's
  PetscInt             snapshotsUsed      = 0; // the snapshots of distinct parameters (a repeated parameter's taken once)
};
// POD (-pod_*; with sensitivities of the snapshots and their derivatives), dual basis (-dual_*; with sensitivities
// also the predicted multipliers), supremizers (-pod_supremizers*) of snaps; R: multipliers (0: no contact).
// sensitivities (OfflineSettings::sensitivities): the snapshots' derivatives are checked (CheckSnapshotSensitivities,
// source names the snapshot file in its errors) and used. Collective on fom's communicator; world names the stage in messages.
// -dual_sensitivity_step (default 0.1, in [0, 1], else an error naming it): with -snapshots_sensitivities the dual
// greedy also sees [lambda +- step (range_i dlambda/dmu_i)]_+ for every snapshot and parameter.
PetscErrorCode DualSensitivityStepFromOptions(MPI_Comm comm, PetscReal *step);
// -snapshots_sensitivities: every snapshot holds its derivatives (the extra "sensitivity_u", nparams x ndofs, not
// all zero), else an error naming path (empty: "the snapshot file") and the snapshot.
PetscErrorCode CheckSnapshotSensitivities(MPI_Comm world, const std::vector<Snapshot> &snaps, const std::string &path);
PetscErrorCode BuildBases(MPI_Comm world, ElasticFOM &fom, CanonicalOrder &order, const std::vector<Snapshot> &snaps, PetscInt R, ContactMap *cmap, OfflineBasisSet *b, bool sensitivities = false, const std::string &source = "");

// The bases cut to the leading r dual vectors and the supremizers of those (the columns the online stage uses with
// -rom_R r, ReducedColumns): dual.W keeps its first r columns, the POD keeps its modes and min(nsup, r) supremizers
// (pod.modes and modes). Nothing changes when r >= the dual vectors there are. What the offline stage fits to the
// bases after them (the cubature) then fits only the answer's sizes (-dual_truncate, -dual_select_refit;
// docs/dual_basis.md "The cubature refitted to the chosen R").
PetscErrorCode TruncateBases(OfflineBasisSet *b, PetscInt r);

// The multiplier snapshots of `rbcontact dualbasis -snapshots spec` as a matrix (rows = multipliers, columns =
// snapshots): "file.h5:/dataset" or a PETSc binary matrix (ImportSnapshotMatrix), or an offline snapshot file
// (its lambda); negative entries beyond round-off (-1e-12 max |.|) are refused, round-off ones clipped to 0.
PetscErrorCode DualSnapshotMatrix(MPI_Comm comm, const std::string &spec, DenseMatrix *L);

// -estimate and the enrichment's tolerances (-estimate_pod_tol, -estimate_dual_tol), checked against -pod_tol and
// -dual_tol; the offline stage calls it before the snapshots too (they were refused after them).
PetscErrorCode EstimateEnrichmentOptions(MPI_Comm world, PetscBool *estimate, PetscReal *estPodTol, PetscReal *estDualTol);

// The files at paths (their link targets), as they are before a step that replaces them and may fail after: rank 0
// keeps each existing one aside as a hard link (<file>.previous.<pid>); Restore puts them back (atomic renames), Drop
// forgets them. A killed run leaves the .previous files beside the new ones.
class PreviousFiles {
public:
  PreviousFiles(MPI_Comm comm, const std::vector<std::string> &paths);
  PreviousFiles(const PreviousFiles &)            = delete;
  PreviousFiles &operator=(const PreviousFiles &) = delete;
  ~PreviousFiles() { Drop(); }
  void Restore();
  void Drop();

private:
  std::vector<std::pair<std::string, std::string>> kept_; // target, its hard link
};

// Report keys dual {type, r, train_max_err, train_max_rel_err, history, tol_abs, norm, gram_cond,
// selected, min_entry} and nnls {solves, max_kkt, retries}; a negative basis entry is an error.
PetscErrorCode ReportDualBasis(MPI_Comm comm, const DualBasisResult &dual, Report *rep);
// /dual/basis (r rows of R), /dual/history, /dual/gram_cond, /dual/selected.
void WriteDualBasis(const DualBasisResult &dual, RomWriter *w, bool withBasis = true);

} // namespace rbc
