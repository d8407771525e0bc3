// rbcontact/mesh.hpp: meshes of a scene. Owns the generation of .msh files from gmsh .geo sources
// (cached by content hash, written atomically), reading them into a DMPlex whose physical names
// are DMLabels, the checks of the labels a scene names, and the distribution (partition.hpp).
#pragma once
#include <petscdmplex.h>
#include <string>
#include <vector>
#include "rbcontact/scene.hpp"

namespace rbc {

// Generates (rank 0, with gmsh) or locates the .msh of spec; every rank gets the path.
PetscErrorCode MeshGenerate(MPI_Comm comm, const MeshSpec &spec, std::string *mshPath);

// Reads the scene's mesh (generating it if needed), checks that every physical name the scene uses
// exists, completes boundary labels, distributes it (-mesh_partitioner) and applies -dm_view.
PetscErrorCode MeshLoad(MPI_Comm comm, const SceneSpec &scene, DM *dm);

// Names of the DMLabels that come from gmsh physical groups (all labels but the standard ones): their union over the
// ranks of the DM, the same on every rank. Collective.
PetscErrorCode MeshPhysicalNames(DM dm, std::vector<std::string> *names);

// Checks that a label of that name exists and is non-empty somewhere; the error names the option.
PetscErrorCode MeshCheckLabel(DM dm, const std::string &name, const char *option, const std::string &file);

// Resolves a file name: as given, else relative to the source tree. Errors name the file.
PetscErrorCode ResolveDataFile(MPI_Comm comm, const std::string &file, std::string *path);

// Global number of cells (cells = true) or vertices of a distributed DMPlex (each counted once).
PetscErrorCode GlobalPointCount(DM dm, bool cells, PetscInt *n);

// 64-bit FNV-1a hash of a string (mesh cache keys, checksums).
unsigned long long Fnv1a(const std::string &s, unsigned long long h = 1469598103934665603ULL);

} // namespace rbc
