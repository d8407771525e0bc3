// src/rom/dense_kernels.hpp: the small dense kernels the online stage spends its time in (docs/online.md,
// "Where the online time goes"): the cubature's contact terms and the reduced QP's set-up, compiled twice: for the
// baseline x86-64 and for AVX2+FMA (the fused points' sum also for AVX-512F), chosen once at run time from the CPU
// (no -march needed).
// Internal to the library.
#pragma once
#include <petscsys.h>

namespace rbc {

// out[0:n) = sum_j coef[j] * rows[j][0:n)   (nt terms)
void CombineRows(PetscInt nt, const PetscReal *coef, const PetscReal *const *rows, PetscInt n, PetscReal *out);
// The same in float (coefficients rounded to float): kappa's rows for the points' sum in single precision, from a
// float copy of theta's used columns (half the bytes read, twice the entries per vector operation)
void CombineRowsSingle(PetscInt nt, const PetscReal *coef, const float *const *rows, PetscInt n, float *out);

// Sum of outer products over M points: K(:, c) = sum_p W(p, :) X(c, p) for c < nc, with W (M x rp,
// point-major, rp a multiple of 4, padding zero) and X (nc x M, row-major); K is rp x nc, column-major.
void SumOfOuterProducts(PetscInt M, PetscInt rp, PetscInt nc, const PetscReal *W, const PetscReal *X, PetscReal *K);

// The same sum with X point-major (M x nc, row-major, leading dimension ldx >= nc): the points' sum straight from
// the rows of kappa, without a transposed copy on the BLAS path. K is rp x nc, column-major.
void SumOfOuterProductsRows(PetscInt M, PetscInt rp, PetscInt nc, const PetscReal *W, const PetscReal *X, PetscInt ldx, PetscReal *K);
void SumOfOuterProductsRowsSingle(PetscInt M, PetscInt rp, PetscInt nc, const float *W, const float *X, PetscInt ldx, PetscReal *K);

// Who computes the sums of outer products (SumOfOuterProducts*): the BLAS's gemm (true, the default) or the built-in
// kernels below (-rom_gemm builtin: for a reference BLAS; docs/online.md "The BLAS for the cubature's sums").
// Per thread: a ReducedModel sets its own choice before it sums (ContactTerms, EstimateError).
void SetGemmBlas(bool blas);
bool GemmBlas();

// The patch-dof accumulation of the cubature's dof sum: for every point p < M and term t < nt[p],
// Q(rowIdx[p][t], :) += coef[p][t] W(p, :), and g += gamma[p] W(p, :) (W M x rp point-major, Q nd x rp
// row-major, g of length rp; rowIdx and coef hold maxTerms entries per point). Accumulates into Q, g.
void ScatterRows(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const PetscReal *W, const PetscReal *gamma, PetscReal *Q, PetscReal *g);

// The dof sum in single precision (-rom_ecsw_precision single, docs/online.md): the same two steps with W, Q and X
// in float (rp a multiple of 8, padding zero), the output K in double; ScatterRowsSingle leaves g to the caller.
void ScatterRowsSingle(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const float *W, float *Q);
void SumOfOuterProductsSingle(PetscInt M, PetscInt rp, PetscInt nc, const float *W, const float *X, PetscReal *K);

// The points' sum in single precision with kappa's rows formed on the way: K (rp x nc, column-major, double) =
// sum_p W(p, :)' x_p(0:nc), x_p = sum_t coef[p][t] theta(rowIdx[p][t], :) (theta in float, leading dimension ldt >= nc,
// rows padded with zeros; W M x rp point-major, rp a multiple of 8). fused and AVX-512: chunks of points, the rows
// combined into a block that stays in cache, K held in registers tile by tile (X unused); otherwise CombineRowsSingle
// into X (M x ldt) and SumOfOuterProductsRowsSingle (SetGemmBlas's choice). PointSumFusedAvailable: the CPU has AVX-512F.
void PointSumSingle(bool fused, PetscInt M, PetscInt rp, PetscInt nc, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const float *theta, PetscInt ldt, const float *W, float *X, PetscReal *K);
bool PointSumFusedAvailable();

// out[r] = b[r] + A(r, :) v for r < rows (A rows x n, row-major; b and out may be the same array): the patch's
// nodal displacement U = uD + theta v (ContactPatch::SetReduced), the cubature points' multipliers (ResultantForce).
void RowDots(PetscInt rows, PetscInt n, const PetscReal *A, const PetscReal *v, const PetscReal *b, PetscReal *out);
// The same with A and v in float, the dots summed in float and added to b in double: the patch's nodal displacement
// from the float copy of theta that the single-precision points' sum keeps (half the bytes of the double theta)
void RowDotsSingle(PetscInt rows, PetscInt n, const float *A, const float *v, const PetscReal *b, PetscReal *out);

// The reduced QP's set-up (src/rom/reduced_qp.cpp): X = D L^{-T} (D, X: r x n column-major, leading
// dimension r; L lower n x n, column-major) and the lower triangle of S = X X' (S r x r).
void RightSolveT(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *D, PetscReal *X);
void LowerGram(PetscInt r, PetscInt n, const PetscReal *X, PetscReal *S);
// D = G L' (G, D r x n, leading dimension r; L lower n x n): the reduced QP's D from D L^{-T} (ReducedQP::ResidualsFactored).
void RightMulLT(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *G, PetscReal *D);

// rp for r rows: r rounded up to the kernel's block (4 doubles; 8 floats for the single-precision dof sum).
inline PetscInt PaddedRows(PetscInt r, PetscInt block = 4) { return (r + block - 1) / block * block; }

} // namespace rbc
