// rbcontact/dual_selection.hpp: the number of dual vectors the online stage uses by default, chosen by the offline
// stage on FOM solutions at held-out parameters (docs/dual_basis.md "R chosen on held-out solutions"). The dual
// greedy stops on its error over the training multipliers; with a cubature its last vectors can cost time and make
// lambda worse between training parameters (measured at the finest 3D level: lambda 1.85e-2 with all 162, 1.48e-2
// with 110, on six held-out FOM solutions). The ROM just written is validated at the held-out parameters for a list
// of R (validation.hpp, -validate_sweep_R: every POD mode, the supremizers of the leading R dual vectors); the
// choice goes into the file as /online/dual_select, which the online stage uses unless -rom_R. The file keeps every
// dual vector (-rom_R reaches them all).
#pragma once
#include <string>
#include <vector>
#include <petscsys.h>
#include "rbcontact/report.hpp"
#include "rbcontact/rom_file.hpp"
#include "rbcontact/scene.hpp"
#include "rbcontact/validation.hpp"

namespace rbc {

// Absolute held-out errors (relative errors in validate's measures) under which the rules below do not compare: an
// error at or below its floor is admitted whatever its growth against the reference row (docs/dual_basis.md "Floors").
// 0 (the default): the rules are purely relative.
struct DualErrorFloor {
  PetscReal u = 0, lambda = 0, force = 0;
};

struct DualSelectionOptions {
  PetscInt              size = 0;           // -dual_select_size: random held-out parameters solved by the FOM here (0: off)
  PetscInt              seed = 11;          // -dual_select_seed
  std::string           snapshots;          // -dual_select_snapshots: the held-out FOM solutions from this snapshot file
                                            // (offline -offline_stop snapshots: checkpointed; its parameters are the set;
                                            // it takes precedence over -dual_select_size, e.g. of a scene's options file)
  PetscReal             slack = 0;          // -dual_select_slack: lambda within it of the best held-out row (0: the best;
                                            // 0.1 until 2026-11-28, docs/dual_basis.md)
  PetscReal             guard = 0.1;        // -dual_select_guard: u and force within it of every dual vector's
  PetscReal             minFraction = 0.5;  // -dual_select_min_fraction: the smallest candidate, as a fraction of R
  PetscInt              count = 16;         // -dual_select_count: candidates from there to R, evenly spaced
  std::vector<PetscInt> candidates;         // -dual_select_R: the candidates themselves (R is always added)
  bool                  refit = false;      // -dual_select_refit: below the stored R, the bases cut to the chosen R and the
                                            // online model (the cubature) built again for them (TruncateBases)
  PetscReal             refitSlack = 0.1;   // -dual_select_refit_slack: the refitted model is kept if its held-out lambda is
                                            // within it of the chosen row's (u and force: within -dual_select_guard); the
                                            // guard's default: the chosen row is a minimum over the candidates, biased low
                                            // by their spread (docs/dual_basis.md)
  PetscReal             refitEcswTol = 0;   // -dual_select_refit_ecsw_tol: the refit's cubature tolerance (0: -ecsw_tol's)
  DualErrorFloor        floor;              // -dual_select_floor u,lambda,force: held-out errors at or below these pass
                                            // the relative rules (choice and refit) whatever their growth (0: off)
  PetscInt              truncate = 0;       // -dual_truncate: the bases cut to this many dual vectors before the online
                                            // model is built (0: all; TruncateBases)
  bool Enabled() const { return size > 0 || !snapshots.empty(); }
};

// Reads and checks the options (prefix dual_select_, and -dual_truncate); the offline stage calls it before its
// snapshots (hours on a real scene) and again at the end. Errors: ranges, a missing or unreadable snapshot file,
// -estimate (whose enrichment is the dual vectors beyond the answer's) with a choice or -dual_truncate, -dual_select_refit
// without a choice.
PetscErrorCode DualSelectionFromOptions(MPI_Comm comm, DualSelectionOptions *o);

// The candidates for a file of R dual vectors: -dual_select_R (those above R left out: R is the dual greedy's, not
// known when the options are given) or count values evenly spaced from ceil(minFraction R) to R; sorted, distinct,
// R included.
std::vector<PetscInt> DualSelectionCandidates(const DualSelectionOptions &o, PetscInt R);

// The rule (rows: DualSizeRow, validation.hpp): admissible are the rows that did not fail whose max lambda error is
// within (1 + slack) of the best row's and whose u and force errors, max and mean, are within (1 + guardSlack) of
// those with every dual vector (the row of the largest R); the admissible row of the smallest R is chosen, the
// largest R when none is. An error at or below its floor (u: max and mean u; lambda; force: max and mean force) passes
// its comparison whatever its ratio. Returns the chosen row's index.
size_t ChooseDualSize(const std::vector<DualSizeRow> &rows, PetscReal slack, PetscReal guardSlack, const DualErrorFloor &floor = DualErrorFloor());

// With the options o (DualSelectionFromOptions) enabled: validates the ROM at romPath (w: its writer, holding the
// model) on the held-out FOM solutions for every candidate, chooses R (ChooseDualSize) and, when R is below the
// stored count, writes /online/dual_select (the file rewritten atomically). Report keys: dual_select {enabled,
// heldout, seed or snapshots, slack, guard, candidates [validate's sweep_R rows: R, N, max_rel_err_{u,lambda,force},
// mean_rel_err_{u,lambda,force}, failed], R, N, R_stored, max_rel_err_{u,lambda,force} (the chosen row),
// max_rel_err_{u,lambda,force}_all (every dual vector), fom_median_s}; rom.R_in_use and rom.N_in_use become the
// chosen sizes; time_s.dual_select its seconds. Collective on world.
// chosen (optional): the chosen row (R = the stored count when the options are disabled: .N 0).
PetscErrorCode SelectDualSize(MPI_Comm world, const SceneSpec &scene, const std::string &romPath, const DualSelectionOptions &o, RomWriter *w, Report *rep, DualSizeRow *chosen = nullptr);

// -dual_select_refit: the ROM at romPath, built again for the chosen R (its every dual vector), validated on the same
// held-out solutions; the rule of keeping it (RefitKept): lambda within (1 + refitSlack) of the chosen row's, u and
// force (max and mean) within (1 + guard) of it, each comparison passed also by an error at or below its floor; a failed
// refit never. row: the refitted model's held-out errors.
PetscErrorCode ValidateRefit(MPI_Comm world, const SceneSpec &scene, const std::string &romPath, const DualSelectionOptions &o, DualSizeRow *row);
bool           RefitKept(const DualSizeRow &refit, const DualSizeRow &chosen, PetscReal refitSlack, PetscReal guard, const DualErrorFloor &floor = DualErrorFloor());

} // namespace rbc
