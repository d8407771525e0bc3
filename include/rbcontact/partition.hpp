// rbcontact/partition.hpp -- owns the mesh-distribution entry point of rbcontact:
// choosing a graph partitioner (our own METIS call through a shell PetscPartitioner,
// or any PETSc-native partitioner type) and distributing a DMPlex in place.
#pragma once

#include <petscdmplex.h>

namespace rbc {

// Distribute the DMPlex *dm over its communicator with overlap 0, replacing *dm by the
// distributed DM (the old DM is destroyed; name and options prefix are carried over;
// labels and coordinates are migrated by DMPlexDistribute). No-op on one rank.
//
// Options (read with the DM's options prefix, if any):
//   -mesh_partitioner <auto|metis|bodies|ptscotch|simple|gather|shell|...>   default: auto
//       auto: bodies when the mesh has at least as many bodies as ranks, metis otherwise.
//       metis: serial METIS_PartGraphKway on the cell dual graph, gathered on rank 0,
//              handed to PETSc through a PETSCPARTITIONERSHELL partitioner.
//       bodies: whole bodies per rank (the connected components of the cell dual graph; one
//              each when there are as many as ranks, else the largest first to the least loaded
//              rank), through the same shell; fewer bodies than ranks is an error. No stiffness
//              coupling between ranks: ElasticFOM factors each rank's block alone.
//       anything else: PetscPartitionerSetType(part, name) (+ PetscPartitionerSetFromOptions,
//              so -petscpartitioner_* type options apply).
//   -mesh_metis_seed <int>      METIS_OPTION_SEED (default 0; partition is deterministic)
//   -mesh_partitioner_view      view the partitioner after distribution
// Collective on the DM's communicator. An unknown partitioner name is an error
// (PETSC_ERR_ARG_UNKNOWN_TYPE) on every rank count, including 1.
PetscErrorCode DistributeMesh(DM *dm);

// The partition DistributeMesh gave dm: "metis", "bodies", "petsc" (a PetscPartitioner type), or "none"
// (one rank, or a DM it did not distribute). For reports.
const char *MeshPartitionUsed(DM dm);

}  // namespace rbc
