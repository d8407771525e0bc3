// src/rom/dense_kernels.hpp: the two small dense kernels the online contact terms spend their time in
// (docs/online.md, "Where the online time goes"), register-blocked and compiled twice: for the
// baseline x86-64 and for AVX2+FMA, chosen once at run time from the CPU (no -march needed).
// Internal to the library.
#pragma once
#include <petscsys.h>

namespace rbc {

// out[0:n) = sum_j coef[j] * rows[j][0:n)   (nt terms)
void CombineRows(PetscInt nt, const PetscReal *coef, const PetscReal *const *rows, PetscInt n, PetscReal *out);

// Sum of outer products over M points: K(:, c) = sum_p W(p, :) X(c, p) for c < nc, with W (M x rp,
// point-major, rp a multiple of 4, padding zero) and X (nc x M, row-major); K is rp x nc, column-major.
void SumOfOuterProducts(PetscInt M, PetscInt rp, PetscInt nc, const PetscReal *W, const PetscReal *X, PetscReal *K);

// rp for r rows: r rounded up to the kernel's block (4).
inline PetscInt PaddedRows(PetscInt r) { return (r + 3) / 4 * 4; }

} // namespace rbc
