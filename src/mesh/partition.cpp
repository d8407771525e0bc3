// src/mesh/partition.cpp -- owns rbc::DistributeMesh: selection of the mesh partitioner
// (-mesh_partitioner), our serial METIS k-way partition of the cell dual graph handed to
// PETSc through a shell PetscPartitioner (Debian's PETSc has no ParMETIS), and the
// in-place DMPlexDistribute of the mesh, logged under the PetscLogEvent "RBCMeshDistrib".
#include "rbcontact/partition.hpp"

#include <metis.h>

#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace rbc {
namespace {

PetscLogEvent g_mesh_distrib_event = 0;
bool          g_mesh_distrib_event_registered = false;

PetscErrorCode RegisterEvents()
{
  PetscFunctionBeginUser;
  if (!g_mesh_distrib_event_registered) {
    PetscCall(PetscLogEventRegister("RBCMeshDistrib", DM_CLASSID, &g_mesh_distrib_event));
    g_mesh_distrib_event_registered = true;
  }
  PetscFunctionReturn(0);
}

// PETSc partitioner types that are registered in PetscPartitionerList but need an external
// package this PETSc build may lack (they would only fail later, deep inside DMPlexDistribute).
bool ExternalPartitionerMissing(const char *name)
{
#if !defined(PETSC_HAVE_PARMETIS)
  if (!std::strcmp(name, PETSCPARTITIONERPARMETIS)) return true;
#endif
#if !defined(PETSC_HAVE_PTSCOTCH)
  if (!std::strcmp(name, PETSCPARTITIONERPTSCOTCH)) return true;
#endif
#if !defined(PETSC_HAVE_CHACO)
  if (!std::strcmp(name, PETSCPARTITIONERCHACO)) return true;
#endif
  return false;
}

std::string ValidPartitionerNames()
{
  std::string names = "metis";
#if defined(PETSC_HAVE_PTSCOTCH)
  names += ", " PETSCPARTITIONERPTSCOTCH;
#endif
#if defined(PETSC_HAVE_PARMETIS)
  names += ", " PETSCPARTITIONERPARMETIS;
#endif
#if defined(PETSC_HAVE_CHACO)
  names += ", " PETSCPARTITIONERCHACO;
#endif
  names += ", " PETSCPARTITIONERSIMPLE ", " PETSCPARTITIONERGATHER ", " PETSCPARTITIONERSHELL
           ", " PETSCPARTITIONERMATPARTITIONING;
  return names;
}

// Is `name` usable as -mesh_partitioner? "metis" (ours) or any registered PetscPartitioner
// type whose external package is compiled in (user-registered types included).
PetscErrorCode PartitionerNameIsValid(const char *name, PetscBool *valid)
{
  PetscErrorCode (*create)(PetscPartitioner) = nullptr;
  PetscPartitioner probe                       = nullptr;

  PetscFunctionBeginUser;
  *valid = PETSC_FALSE;
  if (!std::strcmp(name, "metis")) {
    *valid = PETSC_TRUE;
    PetscFunctionReturn(0);
  }
  if (ExternalPartitionerMissing(name)) PetscFunctionReturn(0);
  // PetscPartitionerRegisterAll() is private; creating a partitioner guarantees registration.
  PetscCall(PetscPartitionerCreate(PETSC_COMM_SELF, &probe));
  PetscCall(PetscPartitionerDestroy(&probe));
  PetscCall(PetscFunctionListFind(PetscPartitionerList, name, &create));
  *valid = create ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(0);
}

// Compute a METIS k-way partition of the cell dual graph of dm (nparts = comm size) and load
// it into the shell partitioner `part`. The distributed CSR graph from
// DMPlexCreatePartitionerGraph (vertices = locally owned cells, globally numbered rank by rank)
// is gathered on rank 0, partitioned serially there, and the owner ranks of each local vertex
// are scattered back. Each rank then hands its own vertices, grouped by target rank, to
// PetscPartitionerShellSetPartition.
PetscErrorCode SetMetisShellPartition(DM dm, PetscInt seed, PetscPartitioner part)
{
  MPI_Comm    comm;
  PetscMPIInt size, rank;
  PetscInt    nv = 0, *offsets = nullptr, *adjacency = nullptr;
  IS          globalNumbering = nullptr;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectGetComm((PetscObject)dm, &comm));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));

  PetscCall(DMPlexCreatePartitionerGraph(dm, 0, &nv, &offsets, &adjacency, &globalNumbering));
  PetscCall(ISDestroy(&globalNumbering));
  const PetscInt ne = (nv > 0 && offsets) ? offsets[nv] : 0;

  // Local vertex degrees and adjacency (global numbering), to be gathered on rank 0.
  std::vector<PetscInt> degree(static_cast<size_t>(nv));
  for (PetscInt v = 0; v < nv; ++v) degree[v] = offsets[v + 1] - offsets[v];
  std::vector<PetscInt> localAdj(adjacency, adjacency + ne);
  PetscCall(PetscFree(offsets));
  PetscCall(PetscFree(adjacency));

  PetscMPIInt nvLocal, neLocal;
  PetscCall(PetscMPIIntCast(nv, &nvLocal));
  PetscCall(PetscMPIIntCast(ne, &neLocal));
  std::vector<PetscMPIInt> nvAll(rank == 0 ? size : 0), neAll(rank == 0 ? size : 0);
  std::vector<PetscMPIInt> nvDispl(rank == 0 ? size : 0), neDispl(rank == 0 ? size : 0);
  PetscCallMPI(MPI_Gather(&nvLocal, 1, MPI_INT, nvAll.data(), 1, MPI_INT, 0, comm));
  PetscCallMPI(MPI_Gather(&neLocal, 1, MPI_INT, neAll.data(), 1, MPI_INT, 0, comm));
  PetscInt nvTotal = 0, neTotal = 0;
  if (rank == 0) {
    for (PetscMPIInt r = 0; r < size; ++r) {
      PetscCall(PetscMPIIntCast(nvTotal, &nvDispl[r]));
      PetscCall(PetscMPIIntCast(neTotal, &neDispl[r]));
      nvTotal += nvAll[r];
      neTotal += neAll[r];
    }
  }
  std::vector<PetscInt> gDegree(static_cast<size_t>(nvTotal)), gAdj(static_cast<size_t>(neTotal));
  PetscCallMPI(MPI_Gatherv(degree.data(), nvLocal, MPIU_INT, gDegree.data(), nvAll.data(), nvDispl.data(), MPIU_INT, 0, comm));
  PetscCallMPI(MPI_Gatherv(localAdj.data(), neLocal, MPIU_INT, gAdj.data(), neAll.data(), neDispl.data(), MPIU_INT, 0, comm));

  // Serial METIS on rank 0. The status is broadcast so that a failure errors out collectively.
  std::vector<PetscInt> gPart(static_cast<size_t>(nvTotal), 0);
  PetscInt              status[2] = {METIS_OK, 0}; // {METIS status, edge cut}
  if (rank == 0 && size > 1 && nvTotal > 0) {
    const bool fits = nvTotal <= static_cast<PetscInt>(std::numeric_limits<idx_t>::max()) &&
                      neTotal <= static_cast<PetscInt>(std::numeric_limits<idx_t>::max());
    if (!fits) {
      status[0] = METIS_ERROR_INPUT;
    } else {
      std::vector<idx_t> xadj(static_cast<size_t>(nvTotal) + 1), adjncy(gAdj.begin(), gAdj.end());
      std::vector<idx_t> metisPart(static_cast<size_t>(nvTotal), 0);
      xadj[0] = 0;
      for (PetscInt v = 0; v < nvTotal; ++v) xadj[v + 1] = xadj[v] + static_cast<idx_t>(gDegree[v]);
      idx_t nvtxs = static_cast<idx_t>(nvTotal), ncon = 1, nparts = static_cast<idx_t>(size), edgecut = 0;
      idx_t options[METIS_NOPTIONS];
      METIS_SetDefaultOptions(options);
      options[METIS_OPTION_NUMBERING] = 0;
      options[METIS_OPTION_SEED]      = static_cast<idx_t>(seed);
      options[METIS_OPTION_CONTIG]    = 0;
      status[0] = METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.data(), nullptr, nullptr, nullptr, &nparts, nullptr, nullptr, options,
                                      &edgecut, metisPart.data());
      status[1] = static_cast<PetscInt>(edgecut);
      for (PetscInt v = 0; v < nvTotal; ++v) gPart[v] = static_cast<PetscInt>(metisPart[v]);
    }
  }
  PetscCallMPI(MPI_Bcast(status, 2, MPIU_INT, 0, comm));
  PetscCheck(status[0] == METIS_OK, comm, PETSC_ERR_LIB, "METIS_PartGraphKway failed with status %" PetscInt_FMT " (graph: %" PetscInt_FMT " vertices)", status[0],
             nvTotal);
  if (rank == 0) {
    std::vector<PetscInt> partSizes(static_cast<size_t>(size), 0);
    std::string           sizesStr;
    for (PetscInt v = 0; v < nvTotal; ++v) ++partSizes[gPart[v]];
    for (PetscInt n : partSizes) sizesStr += " " + std::to_string(n);
    PetscCall(PetscInfo(part, "METIS k-way partition of %" PetscInt_FMT " cells into %d parts (seed %" PetscInt_FMT "): edge cut %" PetscInt_FMT ", part sizes%s\n", nvTotal,
                        size, seed, status[1], sizesStr.c_str()));
  }

  // Owner rank of each local graph vertex.
  std::vector<PetscInt> localPart(static_cast<size_t>(nv));
  PetscCallMPI(MPI_Scatterv(gPart.data(), nvAll.data(), nvDispl.data(), MPIU_INT, localPart.data(), nvLocal, MPIU_INT, 0, comm));

  // Group the local vertices by target rank (stable: increasing local index within a rank).
  std::vector<PetscInt> sizes(static_cast<size_t>(size), 0), start(static_cast<size_t>(size), 0), points(static_cast<size_t>(nv));
  for (PetscInt v = 0; v < nv; ++v) {
    PetscCheck(localPart[v] >= 0 && localPart[v] < size, PETSC_COMM_SELF, PETSC_ERR_LIB, "METIS returned invalid part %" PetscInt_FMT, localPart[v]);
    ++sizes[localPart[v]];
  }
  for (PetscMPIInt r = 1; r < size; ++r) start[r] = start[r - 1] + sizes[r - 1];
  for (PetscInt v = 0; v < nv; ++v) points[start[localPart[v]]++] = v;
  PetscCall(PetscPartitionerShellSetPartition(part, size, sizes.data(), points.data()));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode DistributeMesh(DM *dm)
{
  MPI_Comm         comm;
  PetscMPIInt      size;
  const char      *prefix       = nullptr;
  const char      *defaultName  = "metis";
  char             partName[256] = "metis";
  PetscInt         seed          = 0;
  PetscBool        valid         = PETSC_FALSE;
  PetscPartitioner part          = nullptr;
  DM               dmDist        = nullptr;

  PetscFunctionBeginUser;
  PetscCheck(dm && *dm, PETSC_COMM_SELF, PETSC_ERR_ARG_NULL, "rbc::DistributeMesh: null DM");
  PetscCall(PetscObjectGetComm((PetscObject)*dm, &comm));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscObjectGetOptionsPrefix((PetscObject)*dm, &prefix));
  PetscCall(RegisterEvents());

  PetscOptionsBegin(comm, prefix, "Mesh distribution options", "DM");
  PetscCall(PetscOptionsString("-mesh_partitioner", "Mesh partitioner: metis (serial METIS via a shell partitioner) or a PetscPartitioner type",
                               "rbc::DistributeMesh", defaultName, partName, sizeof(partName), nullptr));
  PetscCall(PetscOptionsInt("-mesh_metis_seed", "METIS_OPTION_SEED for -mesh_partitioner metis", "rbc::DistributeMesh", seed, &seed, nullptr));
  PetscOptionsEnd();

  // Validate before the early return so that a bad option is reported on one rank too.
  PetscCall(PartitionerNameIsValid(partName, &valid));
  PetscCheck(valid, comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "Unknown value '%s' for option -%smesh_partitioner; valid partitioners: %s", partName, prefix ? prefix : "",
             ValidPartitionerNames().c_str());
  if (size == 1) PetscFunctionReturn(0);

  PetscCall(PetscLogEventBegin(g_mesh_distrib_event, *dm, 0, 0, 0));
  PetscCall(PetscPartitionerCreate(comm, &part));
  PetscCall(PetscObjectSetOptionsPrefix((PetscObject)part, prefix));
  if (!std::strcmp(partName, "metis")) {
    PetscCall(PetscPartitionerSetType(part, PETSCPARTITIONERSHELL));
    PetscCall(SetMetisShellPartition(*dm, seed, part));
  } else {
    PetscCall(PetscPartitionerSetType(part, partName));
    PetscCall(PetscPartitionerSetFromOptions(part));
  }
  PetscCall(DMPlexSetPartitioner(*dm, part));
  PetscCall(DMPlexDistribute(*dm, 0, nullptr, &dmDist));
  PetscCall(PetscPartitionerViewFromOptions(part, (PetscObject)*dm, "-mesh_partitioner_view"));
  PetscCall(PetscPartitionerDestroy(&part));
  if (dmDist) {
    const char *name = nullptr;

    PetscCall(PetscObjectGetName((PetscObject)*dm, &name));
    PetscCall(PetscObjectSetName((PetscObject)dmDist, name));
    PetscCall(PetscObjectSetOptionsPrefix((PetscObject)dmDist, prefix));
    PetscCall(DMDestroy(dm));
    *dm = dmDist;
  }
  PetscCall(PetscLogEventEnd(g_mesh_distrib_event, *dm, 0, 0, 0));
  PetscFunctionReturn(0);
}

} // namespace rbc
