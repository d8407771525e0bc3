// src/mesh/partition.cpp -- owns rbc::DistributeMesh: selection of the mesh partitioner
// (-mesh_partitioner), our serial METIS k-way partition of the cell dual graph handed to
// PETSc through a shell PetscPartitioner (Debian's PETSc has no ParMETIS), the partition by
// whole bodies (connected components of that graph) through the same shell, and the
// in-place DMPlexDistribute of the mesh, logged under the PetscLogEvent "RBCMeshDistrib".
#include "rbcontact/partition.hpp"

#include <metis.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace rbc {
namespace {

PetscLogEvent g_mesh_distrib_event = 0;
bool          g_mesh_distrib_event_registered = false;

// the partition used, composed with a distributed DM as a PetscContainer holding one of these (static) names
const char *const kPartitionNames[] = {"none", "metis", "bodies", "petsc"};

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
  std::string names = "auto, metis, bodies";
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
  if (!std::strcmp(name, "metis") || !std::strcmp(name, "bodies") || !std::strcmp(name, "auto")) {
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

// The cell dual graph of dm gathered on rank 0 (DMPlexCreatePartitionerGraph: vertices = locally
// owned cells, globally numbered rank by rank): CSR on rank 0, and the local vertex counts of every
// rank (for scattering the owners back).
struct GatheredGraph {
  PetscInt                 nv = 0;              // local vertices (cells) of this rank
  std::vector<PetscInt>    xadj, adjncy;        // rank 0: the whole graph (CSR)
  std::vector<PetscMPIInt> nvAll, nvDispl;      // rank 0: vertex counts and offsets per rank
};

PetscErrorCode GatherDualGraph(DM dm, GatheredGraph *g)
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
  g->nv             = nv;

  // Local vertex degrees and adjacency (global numbering), to be gathered on rank 0.
  std::vector<PetscInt> degree(static_cast<size_t>(nv));
  for (PetscInt v = 0; v < nv; ++v) degree[v] = offsets[v + 1] - offsets[v];
  std::vector<PetscInt> localAdj(adjacency, adjacency + ne);
  PetscCall(PetscFree(offsets));
  PetscCall(PetscFree(adjacency));

  PetscMPIInt nvLocal, neLocal;
  PetscCall(PetscMPIIntCast(nv, &nvLocal));
  PetscCall(PetscMPIIntCast(ne, &neLocal));
  std::vector<PetscMPIInt> neAll(rank == 0 ? size : 0), neDispl(rank == 0 ? size : 0);
  g->nvAll.assign(rank == 0 ? size : 0, 0);
  g->nvDispl.assign(rank == 0 ? size : 0, 0);
  PetscCallMPI(MPI_Gather(&nvLocal, 1, MPI_INT, g->nvAll.data(), 1, MPI_INT, 0, comm));
  PetscCallMPI(MPI_Gather(&neLocal, 1, MPI_INT, neAll.data(), 1, MPI_INT, 0, comm));
  PetscInt nvTotal = 0, neTotal = 0;
  if (rank == 0) {
    for (PetscMPIInt r = 0; r < size; ++r) {
      PetscCall(PetscMPIIntCast(nvTotal, &g->nvDispl[r]));
      PetscCall(PetscMPIIntCast(neTotal, &neDispl[r]));
      nvTotal += g->nvAll[r];
      neTotal += neAll[r];
    }
  }
  std::vector<PetscInt> gDegree(static_cast<size_t>(nvTotal));
  g->adjncy.resize(static_cast<size_t>(neTotal));
  PetscCallMPI(MPI_Gatherv(degree.data(), nvLocal, MPIU_INT, gDegree.data(), g->nvAll.data(), g->nvDispl.data(), MPIU_INT, 0, comm));
  PetscCallMPI(MPI_Gatherv(localAdj.data(), neLocal, MPIU_INT, g->adjncy.data(), neAll.data(), neDispl.data(), MPIU_INT, 0, comm));
  g->xadj.assign(static_cast<size_t>(nvTotal) + 1, 0);
  for (PetscInt v = 0; v < nvTotal; ++v) g->xadj[v + 1] = g->xadj[v] + gDegree[v];
  PetscFunctionReturn(0);
}

// Serial METIS k-way on the gathered graph (rank 0): the owner rank of every cell; {status, edge cut}.
void MetisParts(const GatheredGraph &g, PetscMPIInt size, PetscInt seed, std::vector<PetscInt> *part, PetscInt status[2])
{
  const PetscInt nvTotal = (PetscInt)g.xadj.size() - 1, neTotal = (PetscInt)g.adjncy.size();
  const bool     fits    = nvTotal <= static_cast<PetscInt>(std::numeric_limits<idx_t>::max()) && neTotal <= static_cast<PetscInt>(std::numeric_limits<idx_t>::max());
  if (!fits) {
    status[0] = METIS_ERROR_INPUT;
    return;
  }
  std::vector<idx_t> xadj(g.xadj.begin(), g.xadj.end()), adjncy(g.adjncy.begin(), g.adjncy.end());
  std::vector<idx_t> metisPart(static_cast<size_t>(nvTotal), 0);
  idx_t              nvtxs = static_cast<idx_t>(nvTotal), ncon = 1, nparts = static_cast<idx_t>(size), edgecut = 0;
  idx_t              options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  options[METIS_OPTION_SEED]      = static_cast<idx_t>(seed);
  options[METIS_OPTION_CONTIG]    = 0;
  status[0] = METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.data(), nullptr, nullptr, nullptr, &nparts, nullptr, nullptr, options, &edgecut, metisPart.data());
  status[1] = static_cast<PetscInt>(edgecut);
  for (PetscInt v = 0; v < nvTotal; ++v) (*part)[v] = static_cast<PetscInt>(metisPart[v]);
}

// Whole bodies per rank (rank 0): the connected components of the cell dual graph (the bodies of a
// contact scene share no face) assigned to ranks, the largest first to the least loaded rank (with as
// many bodies as ranks: one body each). No edge is cut, so the stiffness has no coupling between ranks
// (ElasticFOM then factors each rank's block alone). Returns the component count; fewer components than
// ranks leave ranks without cells: refused by the caller.
PetscInt BodyParts(const GatheredGraph &g, PetscMPIInt size, std::vector<PetscInt> *part)
{
  const PetscInt        nvTotal = (PetscInt)g.xadj.size() - 1;
  std::vector<PetscInt> comp(static_cast<size_t>(nvTotal), -1), stack, count;
  PetscInt              ncomp = 0;
  for (PetscInt s = 0; s < nvTotal; ++s) {
    if (comp[s] >= 0) continue;
    comp[s] = ncomp;
    count.push_back(0);
    stack.assign(1, s);
    while (!stack.empty()) {
      const PetscInt v = stack.back();
      stack.pop_back();
      ++count[ncomp];
      for (PetscInt k = g.xadj[v]; k < g.xadj[v + 1]; ++k)
        if (comp[g.adjncy[k]] < 0) {
          comp[g.adjncy[k]] = ncomp;
          stack.push_back(g.adjncy[k]);
        }
    }
    ++ncomp;
  }
  std::vector<PetscInt> order(static_cast<size_t>(ncomp)), owner(static_cast<size_t>(ncomp), 0), load(static_cast<size_t>(size), 0);
  for (PetscInt c = 0; c < ncomp; ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(), [&](PetscInt a, PetscInt b) { return count[a] > count[b]; });
  if (ncomp == size) // one body per rank, in the order of the mesh
    for (PetscInt c = 0; c < ncomp; ++c) owner[c] = c;
  else
    for (PetscInt c : order) {
      const PetscInt r = (PetscInt)(std::min_element(load.begin(), load.end()) - load.begin());
      owner[c]         = r;
      load[r] += count[c];
    }
  for (PetscInt v = 0; v < nvTotal; ++v) (*part)[v] = owner[comp[v]];
  return ncomp;
}

// Scatter the owner ranks computed on rank 0 and hand each rank's cells, grouped by target rank, to
// the shell partitioner.
PetscErrorCode SetShellPartition(DM dm, const GatheredGraph &g, const std::vector<PetscInt> &gPart, PetscPartitioner part)
{
  MPI_Comm    comm;
  PetscMPIInt size, nvLocal;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectGetComm((PetscObject)dm, &comm));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscMPIIntCast(g.nv, &nvLocal));
  const PetscInt        nv = g.nv;
  std::vector<PetscInt> localPart(static_cast<size_t>(nv));
  PetscCallMPI(MPI_Scatterv(gPart.data(), g.nvAll.data(), g.nvDispl.data(), MPIU_INT, localPart.data(), nvLocal, MPIU_INT, 0, comm));

  // Group the local vertices by target rank (stable: increasing local index within a rank).
  std::vector<PetscInt> sizes(static_cast<size_t>(size), 0), start(static_cast<size_t>(size), 0), points(static_cast<size_t>(nv));
  for (PetscInt v = 0; v < nv; ++v) {
    PetscCheck(localPart[v] >= 0 && localPart[v] < size, PETSC_COMM_SELF, PETSC_ERR_LIB, "invalid part %" PetscInt_FMT, localPart[v]);
    ++sizes[localPart[v]];
  }
  for (PetscMPIInt r = 1; r < size; ++r) start[r] = start[r - 1] + sizes[r - 1];
  for (PetscInt v = 0; v < nv; ++v) points[start[localPart[v]]++] = v;
  PetscCall(PetscPartitionerShellSetPartition(part, size, sizes.data(), points.data()));
  PetscFunctionReturn(0);
}

// Partition the cells of dm into comm size parts with METIS ("metis"), by whole bodies ("bodies"), or by
// bodies when the mesh has at least as many as ranks and METIS otherwise ("auto"), and load the result
// into the shell partitioner `part`; *used: "metis" or "bodies".
PetscErrorCode SetOwnShellPartition(DM dm, const char *method, PetscInt seed, PetscPartitioner part, const char **used)
{
  MPI_Comm      comm;
  PetscMPIInt   size, rank;
  GatheredGraph g;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectGetComm((PetscObject)dm, &comm));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(GatherDualGraph(dm, &g));
  const PetscInt        nvTotal = (PetscInt)g.xadj.size() - 1;
  const bool            automatic = !std::strcmp(method, "auto");
  bool                  bodies    = automatic || !std::strcmp(method, "bodies");
  std::vector<PetscInt> gPart(static_cast<size_t>(nvTotal), 0);
  PetscInt              status[3] = {METIS_OK, 0, 0}; // {METIS status or component count, edge cut, 1: by bodies}
  if (rank == 0 && size > 1 && nvTotal > 0) {
    if (bodies) status[0] = BodyParts(g, size, &gPart);
    // auto: METIS when there are fewer bodies than ranks
    if (automatic && status[0] < size) {
      status[0] = METIS_OK;
      bodies    = false;
    }
    if (!bodies) MetisParts(g, size, seed, &gPart, status);
    status[2] = bodies;
  }
  // broadcast so that a failure errors out collectively
  PetscCallMPI(MPI_Bcast(status, 3, MPIU_INT, 0, comm));
  bodies = status[2];
  *used  = bodies ? "bodies" : "metis";
  if (bodies)
    PetscCheck(status[0] >= size, comm, PETSC_ERR_ARG_OUTOFRANGE, "-mesh_partitioner bodies gives each rank whole bodies (connected parts of the mesh), but the mesh has %" PetscInt_FMT " bodies for %d ranks: run on at most %" PetscInt_FMT " ranks or use -mesh_partitioner metis", status[0], size, status[0]);
  else
    PetscCheck(status[0] == METIS_OK, comm, PETSC_ERR_LIB, "METIS_PartGraphKway failed with status %" PetscInt_FMT " (graph: %" PetscInt_FMT " vertices)", status[0], nvTotal);
  if (rank == 0) {
    std::vector<PetscInt> partSizes(static_cast<size_t>(size), 0);
    std::string           sizesStr;
    for (PetscInt v = 0; v < nvTotal; ++v) ++partSizes[gPart[v]];
    for (PetscInt n : partSizes) sizesStr += " " + std::to_string(n);
    if (bodies) PetscCall(PetscInfo(part, "Partition of %" PetscInt_FMT " cells by bodies (%" PetscInt_FMT " bodies, %d parts): part sizes%s\n", nvTotal, status[0], size, sizesStr.c_str()));
    else PetscCall(PetscInfo(part, "METIS k-way partition of %" PetscInt_FMT " cells into %d parts (seed %" PetscInt_FMT "): edge cut %" PetscInt_FMT ", part sizes%s\n", nvTotal, size, seed, status[1], sizesStr.c_str()));
  }
  PetscCall(SetShellPartition(dm, g, gPart, part));
  PetscFunctionReturn(0);
}

} // namespace

PetscErrorCode DistributeMesh(DM *dm)
{
  MPI_Comm         comm;
  PetscMPIInt      size;
  const char      *prefix       = nullptr;
  const char      *defaultName  = "auto";
  char             partName[256] = "auto";
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
  PetscCall(PetscOptionsString("-mesh_partitioner", "Mesh partitioner: auto (bodies when the mesh has at least as many bodies as ranks, else metis), metis (serial METIS via a shell partitioner), bodies (whole bodies per rank) or a PetscPartitioner type",
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
  const char *used = partName;
  if (!std::strcmp(partName, "metis") || !std::strcmp(partName, "bodies") || !std::strcmp(partName, "auto")) {
    PetscCall(PetscPartitionerSetType(part, PETSCPARTITIONERSHELL));
    PetscCall(SetOwnShellPartition(*dm, partName, seed, part, &used));
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
  PetscContainer c;
  PetscCall(PetscContainerCreate(PETSC_COMM_SELF, &c));
  PetscCall(PetscContainerSetPointer(c, (void *)kPartitionNames[!std::strcmp(used, "metis") ? 1 : !std::strcmp(used, "bodies") ? 2 : 3]));
  PetscCall(PetscObjectCompose((PetscObject)*dm, "rbc_partition", (PetscObject)c));
  PetscCall(PetscContainerDestroy(&c));
  PetscCall(PetscLogEventEnd(g_mesh_distrib_event, *dm, 0, 0, 0));
  PetscFunctionReturn(0);
}

const char *MeshPartitionUsed(DM dm)
{
  PetscObject c    = nullptr;
  void       *name = nullptr;
  if (dm && !PetscObjectQuery((PetscObject)dm, "rbc_partition", &c) && c && !PetscContainerGetPointer((PetscContainer)c, &name) && name) return (const char *)name;
  return kPartitionNames[0];
}

} // namespace rbc
