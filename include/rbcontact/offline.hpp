// include/rbcontact/offline.hpp: the offline stage as library API (src/offline/offline.cpp): the snapshot
// solves of the reference-configuration FOM over a training set, in parallel over parameters (groups of
// ranks) and checkpointed in one HDF5 file; then the bases (offline_bases.hpp), the greedy training
// (offline_greedy.hpp) and the online data (offline_rom.hpp) written to the ROM file. `rbcontact offline`
// is a thin wrapper around RunOffline; an outside program calls the same (share/examples/offline_online.cpp).
#pragma once
#include <string>
#include "rbcontact/report.hpp"
#include "rbcontact/scene.hpp"

namespace rbc {

enum class OfflineStop { Snapshots, Bases, Rom };

// What the offline stage writes and how it runs. The methods' own settings (-train_*, -pod_*, -dual_*,
// -nnls_*, -eim_*, -ecsw_*, -rom_*, -greedy_*) stay in the options database, read by each step's
// SetFromOptions-like function (PetscOptionsSetValue from C++ before RunOffline).
struct OfflineSettings {
  OfflineStop stop = OfflineStop::Rom; // -offline_stop snapshots|bases|rom: the last step
  std::string rom;                     // -rom: the ROM file (bases and rom steps)
  std::string basis;                   // -rom_basis (default: the ROM's stem + .basis.h5, rom step)
  std::string snapshots;               // -snapshots (default: the ROM's stem + .snapshots.h5, rom step)
  bool        restart = true;          // -snapshots_restart (default: false when stopping after the snapshots)
  bool        restartGiven = false;    // -snapshots_restart given explicitly (without it, -offline_stop snapshots refuses to replace a file holding done snapshots)
  bool        monitor = false;         // -snapshots_monitor: one line per solved snapshot with an ETA
  std::string trainType = "grid";      // -train_type grid|random|lhs|file|greedy
  PetscInt    subcomms  = 0;           // -snapshots_subcomm: groups of ranks (0: one per rank below 200k dofs, else 1)
  std::string basisView;               // -offline_basis_output: the bases on the mesh for ParaView (rom_fields.hpp, WriteBasisView)
  bool        sensitivities = false;   // -snapshots_sensitivities: every contact snapshot with du/dmu_i, dlambda/dmu_i (snapshot_sensitivity.hpp) for the bases
  std::vector<std::string> from;       // -snapshots_from a.h5,b.h5: copy their done snapshots at points of this training set (SnapshotFile::Import)
  bool        probe = true;            // -offline_probe: solve the written ROM over its box (-probe_*, rom_probe.hpp)
  bool        probeFail = false;       // -offline_probe_fail: a failure there is an error (default: a warning)
  std::string initialGuess = "zero";   // -snapshots_initial_guess zero|nearest: a contact solve starts from the reference configuration, or from its group's nearest earlier snapshot of this run (snapshot_continuation.hpp)
};

// Reads the settings above (one PetscOptionsBegin block: `rbcontact offline -help` lists them) and checks
// -offline_stop; RunOffline checks the files (a ROM file for the bases and rom steps, writable paths).
PetscErrorCode OfflineSettingsFromOptions(MPI_Comm comm, OfflineSettings *s);

// The whole offline stage for scene on the ranks of world: checks the later steps' options first (hours
// of snapshots on a real scene), solves the training parameters not yet in the snapshot file (resumes a
// killed job), then builds and writes the bases and the ROM (as s.stop says). Report keys: stage, scene,
// ntrain, train_type, nparams, fom_solves, resumed, imported, sensitivities, initial_guess, ndofs, ncontact, kacanov_iterations {min, max, mean},
// affine_terms, time_s {snapshots, total, pod, dual, ...}, nranks, subcomms, snapshots, and the steps' keys
// (pod, dual, nnls, eim, ecsw, rom, greedy, probe). Collective on world.
PetscErrorCode RunOffline(MPI_Comm world, const SceneSpec &scene, const OfflineSettings &s, Report *rep);

// The offline stage from the options database alone, as `rbcontact offline` and the Python module run it:
// OfflineSettingsFromOptions, SceneSpecFromOptions, RunOffline.
PetscErrorCode RunOfflineFromOptions(MPI_Comm world, Report *rep);

} // namespace rbc
