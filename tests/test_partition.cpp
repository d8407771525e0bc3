// tests/test_partition.cpp -- owns the test of rbc::DistributeMesh: a 16x16 triangulated box mesh
// created on rank 0 is distributed with the partitioner given by -mesh_partitioner, and we
// check cell-count conservation, that every rank owns cells, the load imbalance (metis),
// run-to-run determinism (metis), and that -mesh_partitioner bogus is rejected. With
// -mesh_partitioner bodies: a mesh of three disjoint boxes, each on one rank (RunBodiesTest).
#include "rbcontact/partition.hpp"

#include <petscdmplex.h>
#include <petscsf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace {

// Per-distribution summary gathered on every rank.
struct PartitionSummary {
  std::vector<PetscInt>  cellsPerRank;    // owned cells per rank
  std::vector<PetscInt>  cellsPerRankBox; // owned cells per rank and box (rank-major; boxes by centroid x: [2k, 2k + 1])
  std::vector<PetscReal> centroidSumPerRank; // sum over owned cells of (x + 2 y) of the centroid
  PetscInt               globalCells = 0;
};

// The unit square split into 16x16 squares, each cut into 2 triangles (512 cells), with the
// whole serial mesh on rank 0 and empty meshes elsewhere (as DMPlexCreateFromFile gives).
// DMPlexCreateBoxMesh(simplex = PETSC_TRUE) cannot be used: in PETSc 3.18 it meshes 2D simplex
// boxes with a generator (Triangle), which Debian's PETSc is not built with.
// With `boxes` = {n_1, n_2, ...}: disjoint unit squares side by side (the k-th on [2k, 2k + 1] x [0, 1]),
// the k-th of n_k x n_k squares: a mesh of several bodies.
PetscErrorCode CreateSerialBoxMesh(MPI_Comm comm, DM *dm, const std::vector<PetscInt> &boxes = {16})
{
  PetscMPIInt rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  std::vector<PetscInt>  cells;
  std::vector<PetscReal> coords;
  for (size_t k = 0; k < boxes.size() && rank == 0; ++k) {
    const PetscInt n = boxes[k], v0 = (PetscInt)coords.size() / 2;
    for (PetscInt j = 0; j <= n; ++j)
      for (PetscInt i = 0; i <= n; ++i) {
        coords.push_back(2.0 * k + (PetscReal)i / n);
        coords.push_back((PetscReal)j / n);
      }
    for (PetscInt j = 0; j < n; ++j)
      for (PetscInt i = 0; i < n; ++i) {
        const PetscInt v00 = v0 + j * (n + 1) + i, v10 = v00 + 1, v01 = v00 + n + 1, v11 = v01 + 1;
        cells.insert(cells.end(), {v00, v10, v11, v00, v11, v01});
      }
  }
  const PetscInt numCells = (PetscInt)cells.size() / 3, numVertices = (PetscInt)coords.size() / 2;
  PetscCall(DMPlexCreateFromCellListPetsc(comm, 2, numCells, numVertices, 3, PETSC_TRUE, cells.data(), 2, coords.data(), dm));
  PetscCall(PetscObjectSetName((PetscObject)*dm, "box"));
  PetscFunctionReturn(0);
}

PetscErrorCode Summarize(DM dm, PartitionSummary *s, PetscInt nbox = 1)
{
  MPI_Comm    comm;
  PetscMPIInt size;
  PetscInt    cStart, cEnd, nOwned = 0;
  PetscReal   centroidSum = 0.0;
  PetscSF     sf;
  PetscInt    nLeaves = 0;
  const PetscInt *leaves = nullptr;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectGetComm((PetscObject)dm, &comm));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  // Owned cells: not a leaf of the point SF (overlap 0 means all local cells are owned).
  PetscCall(DMGetPointSF(dm, &sf));
  PetscCall(PetscSFGetGraph(sf, nullptr, &nLeaves, &leaves, nullptr));
  std::vector<char>     ghost(static_cast<size_t>(cEnd - cStart), 0);
  std::vector<PetscInt> perBox(static_cast<size_t>(nbox), 0);
  for (PetscInt l = 0; l < nLeaves && nLeaves > 0; ++l) {
    const PetscInt p = leaves ? leaves[l] : l;
    if (p >= cStart && p < cEnd) ghost[p - cStart] = 1;
  }
  for (PetscInt c = cStart; c < cEnd; ++c) {
    PetscReal vol, centroid[3] = {0, 0, 0};

    if (ghost[c - cStart]) continue;
    PetscCall(DMPlexComputeCellGeometryFVM(dm, c, &vol, centroid, nullptr));
    centroidSum += centroid[0] + 2.0 * centroid[1];
    ++nOwned;
    ++perBox[std::min<PetscInt>(nbox - 1, (PetscInt)(centroid[0] / 2.0))];
  }
  s->cellsPerRankBox.assign(static_cast<size_t>(size * nbox), 0);
  PetscCallMPI(MPI_Allgather(perBox.data(), (PetscMPIInt)nbox, MPIU_INT, s->cellsPerRankBox.data(), (PetscMPIInt)nbox, MPIU_INT, comm));
  s->cellsPerRank.assign(static_cast<size_t>(size), 0);
  s->centroidSumPerRank.assign(static_cast<size_t>(size), 0.0);
  PetscCallMPI(MPI_Allgather(&nOwned, 1, MPIU_INT, s->cellsPerRank.data(), 1, MPIU_INT, comm));
  PetscCallMPI(MPI_Allgather(&centroidSum, 1, MPIU_REAL, s->centroidSumPerRank.data(), 1, MPIU_REAL, comm));
  s->globalCells = 0;
  for (PetscInt n : s->cellsPerRank) s->globalCells += n;
  PetscFunctionReturn(0);
}

PetscErrorCode DistributeAndSummarize(MPI_Comm comm, PartitionSummary *s)
{
  DM dm;

  PetscFunctionBeginUser;
  PetscCall(CreateSerialBoxMesh(comm, &dm));
  PetscCall(rbc::DistributeMesh(&dm));
  {
    const char *name = nullptr;
    PetscBool   same = PETSC_FALSE;

    PetscCall(PetscObjectGetName((PetscObject)dm, &name));
    PetscCall(PetscStrcmp(name, "box", &same));
    PetscCheck(same, comm, PETSC_ERR_PLIB, "DistributeMesh did not keep the DM name: got '%s'", name);
  }
  PetscCall(Summarize(dm, s));
  PetscCall(DMDestroy(&dm));
  PetscFunctionReturn(0);
}

// -mesh_partitioner bodies: three disjoint boxes of 128, 72 and 32 cells. As many boxes as ranks: box k
// on rank k; fewer ranks: whole boxes, the largest first to the least loaded rank (2 ranks: 128 | 104);
// one box on 2 ranks: refused (more ranks than bodies). Every box's cells on one rank.
PetscErrorCode RunBodiesTest(MPI_Comm comm, PetscMPIInt size)
{
  const std::vector<PetscInt> boxes = {8, 6, 4};
  const PetscInt              nbox  = (PetscInt)boxes.size();
  PartitionSummary            s;
  DM                          dm;

  PetscFunctionBeginUser;
  PetscCall(CreateSerialBoxMesh(comm, &dm, boxes));
  PetscCall(rbc::DistributeMesh(&dm));
  PetscCall(Summarize(dm, &s, nbox));
  const char *used = rbc::MeshPartitionUsed(dm);
  PetscCall(DMDestroy(&dm));
  PetscCheck(!std::strcmp(used, size > 1 ? "bodies" : "none"), comm, PETSC_ERR_PLIB, "MeshPartitionUsed says '%s'", used);
  PetscCall(PetscPrintf(comm, "partitioner bodies, %d ranks: cells per rank", size));
  for (PetscMPIInt r = 0; r < size; ++r) PetscCall(PetscPrintf(comm, " %" PetscInt_FMT, s.cellsPerRank[r]));
  PetscCall(PetscPrintf(comm, "\n"));
  for (PetscInt b = 0; b < nbox; ++b) {
    PetscInt owners = 0, cells = 0;
    for (PetscMPIInt r = 0; r < size; ++r) {
      owners += s.cellsPerRankBox[r * nbox + b] > 0;
      cells += s.cellsPerRankBox[r * nbox + b];
    }
    PetscCheck(owners == 1 && cells == 2 * boxes[b] * boxes[b], comm, PETSC_ERR_PLIB, "box %" PetscInt_FMT " (%" PetscInt_FMT " cells) is split over %" PetscInt_FMT " ranks (%" PetscInt_FMT " cells found)", b, 2 * boxes[b] * boxes[b], owners, cells);
  }
  std::vector<PetscInt> expect;
  if (size == 1) expect = {232};
  else if (size == 2) expect = {128, 104};
  else if (size == 3) expect = {128, 72, 32};
  for (size_t r = 0; r < expect.size(); ++r)
    PetscCheck(s.cellsPerRank[r] == expect[r], comm, PETSC_ERR_PLIB, "rank %zu owns %" PetscInt_FMT " cells, expected %" PetscInt_FMT, r, s.cellsPerRank[r], expect[r]);
  if (size > 1) { // one body, several ranks: a clear error
    PetscErrorCode ierr;
    PetscCall(CreateSerialBoxMesh(comm, &dm));
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));
    ierr = rbc::DistributeMesh(&dm);
    PetscCall(PetscPopErrorHandler());
    PetscCheck(ierr == PETSC_ERR_ARG_OUTOFRANGE, comm, PETSC_ERR_PLIB, "-mesh_partitioner bodies with 1 body on %d ranks: error %d, expected %d", size, (int)ierr, (int)PETSC_ERR_ARG_OUTOFRANGE);
    PetscCall(DMDestroy(&dm));
    // auto: the same mesh goes to METIS
    PetscCall(PetscOptionsSetValue(nullptr, "-mesh_partitioner", "auto"));
    PetscCall(CreateSerialBoxMesh(comm, &dm));
    PetscCall(rbc::DistributeMesh(&dm));
    used = rbc::MeshPartitionUsed(dm);
    PetscCheck(!std::strcmp(used, "metis"), comm, PETSC_ERR_PLIB, "-mesh_partitioner auto with 1 body on %d ranks used '%s', expected metis", size, used);
    PetscCall(DMDestroy(&dm));
    // auto with several bodies: by bodies
    PetscCall(CreateSerialBoxMesh(comm, &dm, boxes));
    PetscCall(rbc::DistributeMesh(&dm));
    used = rbc::MeshPartitionUsed(dm);
    PetscCheck(!std::strcmp(used, "bodies"), comm, PETSC_ERR_PLIB, "-mesh_partitioner auto with 3 bodies on %d ranks used '%s', expected bodies", size, used);
    PetscCall(DMDestroy(&dm));
    PetscCall(PetscOptionsSetValue(nullptr, "-mesh_partitioner", "bodies"));
  }
  PetscCall(PetscPrintf(comm, "partition test passed\n"));
  PetscFunctionReturn(0);
}

PetscErrorCode RunTest()
{
  MPI_Comm         comm = PETSC_COMM_WORLD;
  PetscMPIInt      size;
  char             partName[256] = "metis";
  PartitionSummary serial, first, second;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-mesh_partitioner", partName, sizeof(partName), nullptr));
  const bool isMetis = !std::strcmp(partName, "metis");
  if (!std::strcmp(partName, "bodies")) {
    PetscCall(RunBodiesTest(comm, size));
    PetscFunctionReturn(0);
  }

  // Reference: the undistributed mesh.
  {
    DM dm;
    PetscCall(CreateSerialBoxMesh(comm, &dm));
    PetscCall(Summarize(dm, &serial));
    PetscCall(DMDestroy(&dm));
  }
  PetscCheck(serial.globalCells == 2 * 16 * 16, comm, PETSC_ERR_PLIB, "Expected %d cells in the serial box mesh, got %" PetscInt_FMT, 2 * 16 * 16,
             serial.globalCells);

  PetscCall(DistributeAndSummarize(comm, &first));
  PetscCheck(first.globalCells == serial.globalCells, comm, PETSC_ERR_PLIB, "Global cell count not preserved: %" PetscInt_FMT " before, %" PetscInt_FMT " after",
             serial.globalCells, first.globalCells);
  PetscReal total = 0.0, serialTotal = 0.0;
  for (PetscMPIInt r = 0; r < size; ++r) {
    PetscCheck(first.cellsPerRank[r] > 0, comm, PETSC_ERR_PLIB, "Rank %d owns no cells after distribution with %s", r, partName);
    total += first.centroidSumPerRank[r];
    serialTotal += serial.centroidSumPerRank[r];
  }
  PetscCheck(std::abs(total - serialTotal) <= 1e-10 * std::abs(serialTotal), comm, PETSC_ERR_PLIB, "Sum of cell centroids changed: %.15g vs %.15g", (double)total,
             (double)serialTotal);
  const PetscInt  maxCells  = *std::max_element(first.cellsPerRank.begin(), first.cellsPerRank.end());
  const PetscReal mean      = (PetscReal)first.globalCells / size;
  const PetscReal imbalance = maxCells / mean;
  PetscCall(PetscPrintf(comm, "partitioner %s, %d ranks: cells per rank", partName, size));
  for (PetscMPIInt r = 0; r < size; ++r) PetscCall(PetscPrintf(comm, " %" PetscInt_FMT, first.cellsPerRank[r]));
  PetscCall(PetscPrintf(comm, "; imbalance max/mean = %.4f\n", (double)imbalance));

  if (isMetis) {
    PetscCheck(imbalance <= 1.1, comm, PETSC_ERR_PLIB, "METIS imbalance %.4f > 1.1", (double)imbalance);
    PetscCall(DistributeAndSummarize(comm, &second));
    for (PetscMPIInt r = 0; r < size; ++r) {
      PetscCheck(first.cellsPerRank[r] == second.cellsPerRank[r], comm, PETSC_ERR_PLIB,
                 "METIS partition not deterministic: rank %d owns %" PetscInt_FMT " then %" PetscInt_FMT " cells", r, first.cellsPerRank[r], second.cellsPerRank[r]);
      const PetscReal a = first.centroidSumPerRank[r], b = second.centroidSumPerRank[r];
      PetscCheck(std::abs(a - b) <= 1e-12 * std::max<PetscReal>(1.0, std::abs(a)), comm, PETSC_ERR_PLIB,
                 "METIS partition not deterministic: rank %d centroid sum %.17g then %.17g", r, (double)a, (double)b);
    }
  }

  // An unknown partitioner must be rejected with an error (on every rank count).
  {
    DM             dm;
    PetscErrorCode ierr;

    PetscCall(CreateSerialBoxMesh(comm, &dm));
    PetscCall(PetscOptionsSetValue(nullptr, "-mesh_partitioner", "bogus"));
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));
    ierr = rbc::DistributeMesh(&dm);
    PetscCall(PetscPopErrorHandler());
    PetscCall(PetscOptionsSetValue(nullptr, "-mesh_partitioner", partName));
    PetscCheck(ierr != 0, comm, PETSC_ERR_PLIB, "DistributeMesh accepted -mesh_partitioner bogus");
    PetscCheck(ierr == PETSC_ERR_ARG_UNKNOWN_TYPE, comm, PETSC_ERR_PLIB, "DistributeMesh with -mesh_partitioner bogus failed with error %d, expected %d", (int)ierr,
               (int)PETSC_ERR_ARG_UNKNOWN_TYPE);
    PetscCall(DMDestroy(&dm));
  }
  PetscCall(PetscPrintf(comm, "partition test passed\n"));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, nullptr, nullptr));
  PetscCall(RunTest());
  PetscCall(PetscFinalize());
  return 0;
}
