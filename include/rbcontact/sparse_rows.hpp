// rbcontact/sparse_rows.hpp: SparseRows, a sparse matrix by rows (CSR) held whole on a rank: the contact matrix on
// the contact dofs, gathered by the Kacanov solver's dense dual path (kacanov.hpp, GatherRowsOnDofs) and read back
// from a snapshot file (snapshot_file.hpp).
#pragma once
#include <petscsys.h>
#include <vector>

namespace rbc {

// A sparse matrix by rows (CSR).
struct SparseRows {
  PetscInt               rows = 0, cols = 0;
  std::vector<PetscInt>  ptr{0}, col; // row i: entries [ptr[i], ptr[i + 1])
  std::vector<PetscReal> val;
};

} // namespace rbc
