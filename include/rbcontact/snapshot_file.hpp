// rbcontact/snapshot_file.hpp: the snapshot file of the offline stage (one HDF5 file): parameter
// values, displacement u(mu) and multipliers lambda(mu) in a canonical (partition-independent)
// ordering of the reference mesh, Kacanov iterations and KKT residuals per parameter, the contact
// data the EIM will need, and provenance. Written by rank 0 of the communicator only (the HDF5 C
// API, serial): every finished snapshot is written and flushed (H5Fflush) before the next starts,
// and marked done last, so a killed job loses nothing but the snapshot in progress; a file being
// created is written under a temporary name and renamed once its header is complete.
// Also reads snapshot matrices produced by other codes (an HDF5 dataset, rows = dofs, columns =
// snapshots, or a PETSc binary dense matrix).
#pragma once
#include <petscsys.h>
#include <map>
#include <string>
#include <vector>

namespace rbc {

// What identifies the problem a snapshot file belongs to; a restart refuses a file whose header
// differs (message names the file and the first field that differs).
struct SnapshotHeader {
  std::string                          scene;         // scene name
  std::string                          optionsText;   // the scene's options (provenance, not compared)
  unsigned long long                   sceneHash = 0; // hash of the options that define the problem
  unsigned long long                   meshChecksum = 0;
  std::string                          codeVersion;
  std::vector<std::string>             paramNames;
  std::vector<PetscReal>               paramMin, paramMax;
  std::vector<std::vector<PetscReal>>  trainingPoints; // the full training set (ntrain x nparams)
  PetscInt                             ndofs = 0;      // length of u
  PetscInt                             nmult = 0;      // length of lambda (R)
  // The extra arrays (name, length) every Write of this run carries: a new file creates their datasets with the others
  // (no HDF5 metadata written by a Write). Not stored as such, not compared; a Write may still bring others.
  std::vector<std::pair<std::string, PetscInt>> extras;
};

// Per-snapshot data (all arrays in canonical ordering, identical on any rank count).
struct Snapshot {
  PetscInt                                 index = -1; // position in the training set
  std::vector<PetscReal>                   mu;
  std::vector<PetscReal>                   u;      // ndofs
  std::vector<PetscReal>                   lambda; // nmult
  PetscInt                                 kacanovIterations = 0;
  std::vector<PetscReal>                   kkt;    // primal, dual, complementarity, stationarity
  PetscReal                                seconds = 0;
  // Named extra arrays (EIM data: contact map and gap at the converged state, ...), fixed length
  // per name across snapshots (the first snapshot written fixes it). ReadAll skips the version-1 files' dense
  // contact matrices (contact_K, contact_dofs): the offline stage reassembles them from u (SnapshotContactMatrices).
  std::map<std::string, std::vector<PetscReal>> extra;
};

class SnapshotFile {
public:
  SnapshotFile() = default;
  SnapshotFile(const SnapshotFile &) = delete;
  SnapshotFile &operator=(const SnapshotFile &) = delete;
  ~SnapshotFile(); // closes the file (no error on destruction)

  // Creates path (temp file + rename after the header) or, with restart = true and an existing file,
  // opens it and checks that its header matches (sceneHash, meshChecksum, paramNames, boxes, the
  // training points to 1e-14, ndofs, nmult); a version-1 file is upgraded to version 2 (its attribute) before any
  // write. Collective on comm; only rank 0 touches the file.
  PetscErrorCode Open(MPI_Comm comm, const std::string &path, const SnapshotHeader &header, bool restart);
  // Indices of the training set already stored (done flags), on every rank.
  PetscErrorCode DoneIndices(std::vector<PetscInt> *done) const;
  // Rank 0 of comm writes s (others pass through): data, then H5Fflush, then the done flag, flush.
  PetscErrorCode Write(const Snapshot &s);
  PetscErrorCode Close();
  // Greedy training: the picks of the round about to be solved, stored (dataset /snapshots/pending, flushed) before
  // they are solved, so that a run killed inside a round resumes by finishing the same picks before it builds the
  // next model (the model of a partial round would pick other parameters). Collective; rank 0 writes.
  PetscErrorCode SetPending(const std::vector<PetscInt> &picks);
  // The done rows of the open file that lack the extra array name: all of them when /snapshots/extra/<name> does not
  // exist, else those whose row is zero everywhere (never written: the dataset's fill value; a snapshot solved without
  // it in a file another run gave it). Ascending, on every rank. Collective; rank 0 reads one row at a time.
  PetscErrorCode RowsWithoutExtra(const std::string &name, std::vector<PetscInt> *rows) const;
  // The picks stored by the last SetPending (read by Open on a restart; empty when none), on every rank.
  const std::vector<PetscInt> &Pending() const { return pending_; }
  // Copies into this open file the done snapshots of another snapshot file of the same problem (every header
  // field Open compares but the training set) whose parameters are points of this file's training set (to 1e-14)
  // not done here yet; the others are counted in *outside. extras: the extra arrays this run writes with every
  // snapshot: a snapshot lacking one is refused (naming the file), extras not in the list are dropped. Collective;
  // rank 0 reads. Errors name the file (missing, not a snapshot file, another scene/mesh/box).
  PetscErrorCode Import(const std::string &from, const std::vector<std::string> &extras, PetscInt *imported, PetscInt *outside);

  // (Added) State of an open file: its path, the header it was opened with, whether it is open.
  bool                  IsOpen() const { return open_; }
  const std::string    &Path() const { return path_; }
  const SnapshotHeader &Header() const { return header_; }

  // Before Open (which may replace an existing file, -snapshots_restart 0): that from is a snapshot file of the problem
  // of header (every field Import compares). Collective; rank 0 reads the header only. Errors name the file.
  static PetscErrorCode CheckImport(MPI_Comm comm, const std::string &from, const SnapshotHeader &header);

  // The done snapshots of an existing snapshot file at path (*ndone, of *ntrain), or *ndone = -1 when there is no
  // readable snapshot file there. Collective; rank 0 reads.
  static PetscErrorCode DoneCount(MPI_Comm comm, const std::string &path, PetscInt *ndone, PetscInt *ntrain);

  // Reading (any rank, independent; for the basis builders and the tests).
  static PetscErrorCode ReadHeader(const std::string &path, SnapshotHeader *header);
  // All done snapshots, ordered by training index; the contact matrix compacted (CompactContactMatrix) as each is read.
  static PetscErrorCode ReadAll(const std::string &path, std::vector<Snapshot> *snaps);

private:
  MPI_Comm    comm_ = MPI_COMM_NULL;
  std::string path_;
  long long   file_ = -1; // hid_t on rank 0
  SnapshotHeader header_;
  bool        open_ = false;         // on every rank of comm_ after a successful Open
  std::vector<signed char> done_;    // done flags (ntrain), kept identical on every rank
  std::vector<PetscInt>    pending_; // the greedy round's picks (SetPending), on every rank
};

// (Added) Compares the header of a file with the one of the current run: empty if they match, else
// "<field> differs (file: a, now: b)" for the first field that differs (the fields Open checks).
std::string SnapshotHeaderDiff(const SnapshotHeader &file, const SnapshotHeader &now);

// Import a snapshot matrix from another code: "file.h5:/dataset" (HDF5, rows = dofs, columns =
// snapshots; the reader also accepts the transposed layout with -import_transpose) or a PETSc binary
// file holding a dense Mat ("file.bin"). Returns column-major data: cols[j] is snapshot j.
PetscErrorCode ImportSnapshotMatrix(MPI_Comm comm, const std::string &spec, std::vector<std::vector<PetscReal>> *cols);

} // namespace rbc
