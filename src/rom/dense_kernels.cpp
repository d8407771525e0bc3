// src/rom/dense_kernels.cpp: CombineRows and SumOfOuterProducts (dense_kernels.hpp). A portable
// version of each and, on x86-64 with GCC or clang, an AVX2+FMA version written with intrinsics
// (the auto-vectorizer shuffled the wrong dimension), chosen once from __builtin_cpu_supports. The
// blocked sum keeps a 4 x 4 block of K in registers over all points; the plain rank-1 update loop
// reloaded and stored K at every point. Results differ from the portable ones by rounding (FMA);
// RBC_KERNELS_PORTABLE=1 in the environment selects the portable ones.
#include "dense_kernels.hpp"
#include <cstdlib>
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define RBC_KERNEL_DISPATCH 1
#endif

namespace rbc {

namespace {

void OuterPortable(PetscInt M, PetscInt rp, PetscInt nc, const PetscReal *W, const PetscReal *X, PetscReal *K)
{
  for (PetscInt c = 0; c < nc; ++c)
    for (PetscInt i0 = 0; i0 < rp; i0 += 4) {
      PetscReal        acc[4] = {0, 0, 0, 0};
      const PetscReal *x      = X + (size_t)c * M;
      for (PetscInt p = 0; p < M; ++p) {
        const PetscReal *w = W + (size_t)p * rp + i0;
        for (int i = 0; i < 4; ++i) acc[i] += w[i] * x[p];
      }
      for (int i = 0; i < 4; ++i) K[(size_t)c * rp + i0 + i] = acc[i];
    }
}

void CombinePortable(PetscInt nt, const PetscReal *coef, const PetscReal *const *rows, PetscInt n, PetscReal *out)
{
  for (PetscInt k = 0; k < n; ++k) out[k] = 0;
  for (PetscInt j = 0; j < nt; ++j) {
    const PetscReal *t = rows[j];
    const PetscReal  a = coef[j];
    for (PetscInt k = 0; k < n; ++k) out[k] += a * t[k];
  }
}

#ifdef RBC_KERNEL_DISPATCH
__attribute__((target("avx2,fma"))) void OuterAvx2(PetscInt M, PetscInt rp, PetscInt nc, const PetscReal *W, const PetscReal *X, PetscReal *K)
{
  PetscInt c0 = 0;
  for (; c0 + 4 <= nc; c0 += 4) {
    const PetscReal *x0 = X + (size_t)c0 * M, *x1 = x0 + M, *x2 = x1 + M, *x3 = x2 + M;
    for (PetscInt i0 = 0; i0 < rp; i0 += 4) {
      __m256d a0 = _mm256_setzero_pd(), a1 = a0, a2 = a0, a3 = a0;
      for (PetscInt p = 0; p < M; ++p) {
        const __m256d w = _mm256_loadu_pd(W + (size_t)p * rp + i0);
        a0              = _mm256_fmadd_pd(w, _mm256_broadcast_sd(x0 + p), a0);
        a1              = _mm256_fmadd_pd(w, _mm256_broadcast_sd(x1 + p), a1);
        a2              = _mm256_fmadd_pd(w, _mm256_broadcast_sd(x2 + p), a2);
        a3              = _mm256_fmadd_pd(w, _mm256_broadcast_sd(x3 + p), a3);
      }
      _mm256_storeu_pd(K + (size_t)c0 * rp + i0, a0);
      _mm256_storeu_pd(K + (size_t)(c0 + 1) * rp + i0, a1);
      _mm256_storeu_pd(K + (size_t)(c0 + 2) * rp + i0, a2);
      _mm256_storeu_pd(K + (size_t)(c0 + 3) * rp + i0, a3);
    }
  }
  for (; c0 < nc; ++c0) {
    const PetscReal *x = X + (size_t)c0 * M;
    for (PetscInt i0 = 0; i0 < rp; i0 += 4) {
      __m256d a = _mm256_setzero_pd();
      for (PetscInt p = 0; p < M; ++p) a = _mm256_fmadd_pd(_mm256_loadu_pd(W + (size_t)p * rp + i0), _mm256_broadcast_sd(x + p), a);
      _mm256_storeu_pd(K + (size_t)c0 * rp + i0, a);
    }
  }
}

__attribute__((target("avx2,fma"))) void CombineAvx2(PetscInt nt, const PetscReal *coef, const PetscReal *const *rows, PetscInt n, PetscReal *out)
{
  PetscInt k = 0;
  for (; k + 4 <= n; k += 4) {
    __m256d a = _mm256_setzero_pd();
    for (PetscInt j = 0; j < nt; ++j) a = _mm256_fmadd_pd(_mm256_broadcast_sd(coef + j), _mm256_loadu_pd(rows[j] + k), a);
    _mm256_storeu_pd(out + k, a);
  }
  for (; k < n; ++k) {
    PetscReal s = 0;
    for (PetscInt j = 0; j < nt; ++j) s += coef[j] * rows[j][k];
    out[k] = s;
  }
}

bool HaveAvx2()
{
  static const bool have = [] {
    __builtin_cpu_init();
    // RBC_KERNELS_PORTABLE=1 forces the portable kernels (tests, comparisons)
    const char *portable = std::getenv("RBC_KERNELS_PORTABLE");
    if (portable && portable[0] && portable[0] != '0') return false;
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return have;
}
#endif

} // namespace

void CombineRows(PetscInt nt, const PetscReal *coef, const PetscReal *const *rows, PetscInt n, PetscReal *out)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return CombineAvx2(nt, coef, rows, n, out);
#endif
  CombinePortable(nt, coef, rows, n, out);
}

void SumOfOuterProducts(PetscInt M, PetscInt rp, PetscInt nc, const PetscReal *W, const PetscReal *X, PetscReal *K)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return OuterAvx2(M, rp, nc, W, X, K);
#endif
  OuterPortable(M, rp, nc, W, X, K);
}

} // namespace rbc
