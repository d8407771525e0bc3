// src/rom/dense_kernels.cpp: CombineRows, SumOfOuterProducts, ScatterRows (and their single-precision variants for
// -rom_ecsw_precision single), RowDots, and the reduced QP's
// RightSolveT, RightMulLT and LowerGram (dense_kernels.hpp). A portable version of each and, on x86-64 with GCC or
// clang, an AVX2+FMA version (intrinsics for the contact kernels, where the auto-vectorizer shuffled the
// wrong dimension; the QP's loops compiled for AVX2), chosen once from __builtin_cpu_supports. The
// blocked sum keeps a 4 x 4 (12 x 4) block of K in registers over all points; the plain rank-1 update loop
// reloaded and stored K at every point. ScatterRows holds a point's row of W, CombineRows the output row in
// registers (up to 12 blocks of 4, WithRegisterBlocks). Results differ from the portable ones by rounding (FMA);
// RBC_KERNELS_PORTABLE=1 in the environment selects the portable ones. With AVX-512F, PointSumSingle fuses the
// single-precision points' sum with kappa's row combination (chunks of points, K held in registers tile by tile).
#include "dense_kernels.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cstdlib>
#include <type_traits>
#include <utility>
#include <vector>
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define RBC_KERNEL_DISPATCH 1
#endif

// sgemm and sgemv with PETSc's BLAS name mangling (petscblaslapack.h declares those of PetscScalar only)
#if defined(PETSC_BLASLAPACK_CAPS)
#define RBC_SGEMM PETSC_PASTE2(SGEMM, PETSC_BLASLAPACK_SUFFIX_)
#define RBC_SGEMV PETSC_PASTE2(SGEMV, PETSC_BLASLAPACK_SUFFIX_)
#else
#define RBC_SGEMM PETSC_PASTE2(sgemm, PETSC_BLASLAPACK_SUFFIX_)
#define RBC_SGEMV PETSC_PASTE2(sgemv, PETSC_BLASLAPACK_SUFFIX_)
#endif
extern "C" void RBC_SGEMV(const char *, const PetscBLASInt *, const PetscBLASInt *, const float *, const float *, const PetscBLASInt *, const float *, const PetscBLASInt *, const float *, float *, const PetscBLASInt *);
extern "C" void RBC_SGEMM(const char *, const char *, const PetscBLASInt *, const PetscBLASInt *, const PetscBLASInt *, const float *, const float *, const PetscBLASInt *, const float *, const PetscBLASInt *, const float *, float *, const PetscBLASInt *);

namespace rbc {

namespace {

#if defined(__GNUC__) || defined(__clang__)
#define RBC_INLINE inline __attribute__((always_inline))
#else
#define RBC_INLINE inline
#endif

// X = D L^{-T} (D, X: r x n column-major, leading dimension r; L lower n x n): column k of X is
// (D(:,k) - sum_{m<k} L(k,m) X(:,m)) / L(k,k), four columns m at a time. About 2x faster than the
// reference BLAS trsm for n <= 60 (same operations, another summation order).
RBC_INLINE void RightSolveTBody(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *D, PetscReal *X)
{
  for (PetscInt k = 0; k < n; ++k) {
    PetscReal *x = &X[(size_t)k * r];
    std::copy_n(&D[(size_t)k * r], r, x); // (memcpy from a null pointer is undefined even for 0 bytes: UBSan)
    PetscInt m = 0;
    for (; m + 4 <= k; m += 4) {
      const PetscReal  l0 = L[k + m * n], l1 = L[k + (m + 1) * n], l2 = L[k + (m + 2) * n], l3 = L[k + (m + 3) * n];
      const PetscReal *x0 = &X[(size_t)m * r], *x1 = x0 + r, *x2 = x1 + r, *x3 = x2 + r;
      for (PetscInt i = 0; i < r; ++i) x[i] -= l0 * x0[i] + l1 * x1[i] + l2 * x2[i] + l3 * x3[i];
    }
    for (; m < k; ++m) {
      const PetscReal  lm = L[k + m * n], *xm = &X[(size_t)m * r];
      for (PetscInt i = 0; i < r; ++i) x[i] -= lm * xm[i];
    }
    const PetscReal inv = 1.0 / L[k + k * n];
    for (PetscInt i = 0; i < r; ++i) x[i] *= inv;
  }
}

// D = G L' (G, D: r x n column-major, leading dimension r; L lower n x n): column j of D is
// sum_{k<=j} L(j,k) G(:,k), four columns k at a time (RightSolveT's product, undone).
RBC_INLINE void RightMulLTBody(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *G, PetscReal *D)
{
  for (PetscInt j = 0; j < n; ++j) {
    PetscReal *d = &D[(size_t)j * r];
    std::fill(d, d + r, 0.0);
    PetscInt k = 0;
    for (; k + 4 <= j + 1; k += 4) {
      const PetscReal  l0 = L[j + k * n], l1 = L[j + (k + 1) * n], l2 = L[j + (k + 2) * n], l3 = L[j + (k + 3) * n];
      const PetscReal *g0 = &G[(size_t)k * r], *g1 = g0 + r, *g2 = g1 + r, *g3 = g2 + r;
      for (PetscInt i = 0; i < r; ++i) d[i] += l0 * g0[i] + l1 * g1[i] + l2 * g2[i] + l3 * g3[i];
    }
    for (; k <= j; ++k) {
      const PetscReal  lk = L[j + k * n], *gk = &G[(size_t)k * r];
      for (PetscInt i = 0; i < r; ++i) d[i] += lk * gk[i];
    }
  }
}

// Lower triangle of S = X X' (X r x n, S r x r, both leading dimension r): rank-4 updates with
// contiguous columns. About 1.7x faster than the reference BLAS syrk for n <= 60.
RBC_INLINE void LowerGramBody(PetscInt r, PetscInt n, const PetscReal *X, PetscReal *S)
{
  for (PetscInt j = 0; j < r; ++j)
    for (PetscInt i = j; i < r; ++i) S[i + j * r] = 0;
  PetscInt k = 0;
  for (; k + 4 <= n; k += 4) {
    const PetscReal *x0 = &X[(size_t)k * r], *x1 = x0 + r, *x2 = x1 + r, *x3 = x2 + r;
    for (PetscInt j = 0; j < r; ++j) {
      const PetscReal a0 = x0[j], a1 = x1[j], a2 = x2[j], a3 = x3[j];
      PetscReal      *sj = &S[(size_t)j * r];
      for (PetscInt i = j; i < r; ++i) sj[i] += a0 * x0[i] + a1 * x1[i] + a2 * x2[i] + a3 * x3[i];
    }
  }
  for (; k < n; ++k) {
    const PetscReal *x = &X[(size_t)k * r];
    for (PetscInt j = 0; j < r; ++j) {
      const PetscReal a = x[j];
      PetscReal      *sj = &S[(size_t)j * r];
      for (PetscInt i = j; i < r; ++i) sj[i] += a * x[i];
    }
  }
}

void RightSolveTPortable(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *D, PetscReal *X) { RightSolveTBody(r, n, L, D, X); }
void LowerGramPortable(PetscInt r, PetscInt n, const PetscReal *X, PetscReal *S) { LowerGramBody(r, n, X, S); }
void RightMulLTPortable(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *G, PetscReal *D) { RightMulLTBody(r, n, L, G, D); }

// T = double (K in place) or float (-rom_ecsw_precision single: the sum in float, K in double); rows in blocks of
// 32 bytes (4 doubles, 8 floats)
template <class T>
void OuterPortable(PetscInt M, PetscInt rp, PetscInt nc, const T *W, const T *X, PetscReal *K)
{
  constexpr int B = 32 / sizeof(T);
  for (PetscInt c = 0; c < nc; ++c)
    for (PetscInt i0 = 0; i0 < rp; i0 += B) {
      T        acc[B] = {};
      const T *x      = X + (size_t)c * M;
      for (PetscInt p = 0; p < M; ++p) {
        const T *w = W + (size_t)p * rp + i0;
        for (int i = 0; i < B; ++i) acc[i] += w[i] * x[p];
      }
      for (int i = 0; i < B; ++i) K[(size_t)c * rp + i0 + i] = acc[i];
    }
}

void ScatterPortable(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const PetscReal *W, const PetscReal *gamma, PetscReal *Q, PetscReal *g)
{
  for (PetscInt p = 0; p < M; ++p) {
    const PetscReal *w = W + (size_t)p * rp;
    for (PetscInt t = 0; t < nt[p]; ++t) {
      const PetscReal cf = coef[(size_t)p * maxTerms + t];
      PetscReal      *q  = Q + (size_t)rowIdx[(size_t)p * maxTerms + t] * rp;
      for (PetscInt i = 0; i < rp; ++i) q[i] += cf * w[i];
    }
    for (PetscInt i = 0; i < rp; ++i) g[i] += gamma[p] * w[i];
  }
}

// Single precision (-rom_ecsw_precision single): the dof sum's accumulation in float
void ScatterPortableF(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const float *W, float *Q)
{
  for (PetscInt p = 0; p < M; ++p) {
    const float *w = W + (size_t)p * rp;
    for (PetscInt t = 0; t < nt[p]; ++t) {
      const float cf = (float)coef[(size_t)p * maxTerms + t];
      float      *q  = Q + (size_t)rowIdx[(size_t)p * maxTerms + t] * rp;
      for (PetscInt i = 0; i < rp; ++i) q[i] += cf * w[i];
    }
  }
}

void RowDotsPortable(PetscInt rows, PetscInt n, const PetscReal *A, const PetscReal *v, const PetscReal *b, PetscReal *out)
{
  for (PetscInt r = 0; r < rows; ++r) {
    const PetscReal *a = A + (size_t)r * n;
    PetscReal        s = b[r];
    for (PetscInt k = 0; k < n; ++k) s += a[k] * v[k];
    out[r] = s;
  }
}

void RowDotsPortableF(PetscInt rows, PetscInt n, const float *A, const float *v, const PetscReal *b, PetscReal *out)
{
  for (PetscInt r = 0; r < rows; ++r) {
    const float *a = A + (size_t)r * n;
    float        s = 0;
    for (PetscInt k = 0; k < n; ++k) s += a[k] * v[k];
    out[r] = b[r] + s;
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

void CombinePortableF(PetscInt nt, const PetscReal *coef, const float *const *rows, PetscInt n, float *out)
{
  for (PetscInt k = 0; k < n; ++k) out[k] = 0;
  for (PetscInt j = 0; j < nt; ++j) {
    const float *t = rows[j];
    const float  a = (float)coef[j];
    for (PetscInt k = 0; k < n; ++k) out[k] += a * t[k];
  }
}

#ifdef RBC_KERNEL_DISPATCH
// One AVX2 register of T: 4 doubles or 8 floats (stored to K in double)
template <class T>
struct Avx2Reg;
template <>
struct Avx2Reg<double> {
  using V = __m256d;
  static constexpr int width = 4;
  __attribute__((target("avx2,fma"))) static RBC_INLINE V Zero() { return _mm256_setzero_pd(); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE V Load(const double *w) { return _mm256_loadu_pd(w); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE V Bcast(const double *x) { return _mm256_broadcast_sd(x); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE V Fma(V a, V b, V c) { return _mm256_fmadd_pd(a, b, c); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE void Store(PetscReal *k, V a) { _mm256_storeu_pd(k, a); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE void StoreSame(double *k, V a) { _mm256_storeu_pd(k, a); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE double HSum(V a)
  {
    const __m128d h = _mm_add_pd(_mm256_castpd256_pd128(a), _mm256_extractf128_pd(a, 1));
    return _mm_cvtsd_f64(_mm_add_sd(h, _mm_unpackhi_pd(h, h)));
  }
};
template <>
struct Avx2Reg<float> {
  using V = __m256;
  static constexpr int width = 8;
  __attribute__((target("avx2,fma"))) static RBC_INLINE V Zero() { return _mm256_setzero_ps(); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE V Load(const float *w) { return _mm256_loadu_ps(w); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE V Bcast(const float *x) { return _mm256_broadcast_ss(x); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE V Fma(V a, V b, V c) { return _mm256_fmadd_ps(a, b, c); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE void Store(PetscReal *k, V a) // 8 floats to 8 doubles
  {
    _mm256_storeu_pd(k, _mm256_cvtps_pd(_mm256_castps256_ps128(a)));
    _mm256_storeu_pd(k + 4, _mm256_cvtps_pd(_mm256_extractf128_ps(a, 1)));
  }
  __attribute__((target("avx2,fma"))) static RBC_INLINE void StoreSame(float *k, V a) { _mm256_storeu_ps(k, a); }
  __attribute__((target("avx2,fma"))) static RBC_INLINE float HSum(V a)
  {
    __m128 h = _mm_add_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
    h        = _mm_add_ps(h, _mm_movehl_ps(h, h));
    return _mm_cvtss_f32(_mm_add_ss(h, _mm_shuffle_ps(h, h, 1)));
  }
};

// 3 registers of rows x 4 columns in 12 registers: 3 loads and 4 broadcasts per 12 FMAs (the 1 x 4 block below
// needs 1 load and 4 broadcasts per 4); 12 rows in double, 24 in float
template <class T>
__attribute__((target("avx2,fma"))) void OuterAvx2(PetscInt M, PetscInt rp, PetscInt nc, const T *W, const T *X, PetscReal *K)
{
  using R         = Avx2Reg<T>;
  using V         = typename R::V;
  constexpr int w = R::width;
  PetscInt      c0 = 0;
  for (; c0 + 4 <= nc; c0 += 4) {
    const T *x0 = X + (size_t)c0 * M, *x1 = x0 + M, *x2 = x1 + M, *x3 = x2 + M;
    PetscInt i0 = 0;
    for (; i0 + 3 * w <= rp; i0 += 3 * w) {
      V a[3][4];
      for (int b = 0; b < 3; ++b)
        for (int j = 0; j < 4; ++j) a[b][j] = R::Zero();
      for (PetscInt p = 0; p < M; ++p) {
        const T *wp = W + (size_t)p * rp + i0;
        const V  w0 = R::Load(wp), w1 = R::Load(wp + w), w2 = R::Load(wp + 2 * w);
        const V  xs[4] = {R::Bcast(x0 + p), R::Bcast(x1 + p), R::Bcast(x2 + p), R::Bcast(x3 + p)};
        for (int j = 0; j < 4; ++j) {
          a[0][j] = R::Fma(w0, xs[j], a[0][j]);
          a[1][j] = R::Fma(w1, xs[j], a[1][j]);
          a[2][j] = R::Fma(w2, xs[j], a[2][j]);
        }
      }
      for (int j = 0; j < 4; ++j)
        for (int b = 0; b < 3; ++b) R::Store(K + (size_t)(c0 + j) * rp + i0 + w * b, a[b][j]);
    }
    for (; i0 < rp; i0 += w) {
      V a0 = R::Zero(), a1 = a0, a2 = a0, a3 = a0;
      for (PetscInt p = 0; p < M; ++p) {
        const V v = R::Load(W + (size_t)p * rp + i0);
        a0        = R::Fma(v, R::Bcast(x0 + p), a0);
        a1        = R::Fma(v, R::Bcast(x1 + p), a1);
        a2        = R::Fma(v, R::Bcast(x2 + p), a2);
        a3        = R::Fma(v, R::Bcast(x3 + p), a3);
      }
      R::Store(K + (size_t)c0 * rp + i0, a0);
      R::Store(K + (size_t)(c0 + 1) * rp + i0, a1);
      R::Store(K + (size_t)(c0 + 2) * rp + i0, a2);
      R::Store(K + (size_t)(c0 + 3) * rp + i0, a3);
    }
  }
  for (; c0 < nc; ++c0) {
    const T *x = X + (size_t)c0 * M;
    for (PetscInt i0 = 0; i0 < rp; i0 += w) {
      V a = R::Zero();
      for (PetscInt p = 0; p < M; ++p) a = R::Fma(R::Load(W + (size_t)p * rp + i0), R::Bcast(x + p), a);
      R::Store(K + (size_t)c0 * rp + i0, a);
    }
  }
}

// Calls f(std::integral_constant<int, B>()) for the block count nb when 1 <= nb <= 12 (the kernels that hold
// B blocks of 4 in registers are instantiated for those); false otherwise
template <int B = 1, class F>
bool WithRegisterBlocks(PetscInt nb, F &&f)
{
  if constexpr (B > 12) return false;
  else {
    if (nb == B) {
      f(std::integral_constant<int, B>());
      return true;
    }
    return WithRegisterBlocks<B + 1>(nb, std::forward<F>(f));
  }
}

// One point's W row held in NB registers over its terms (each term: load, FMA, store of Q's row)
template <int NB>
__attribute__((target("avx2,fma"))) void ScatterAvx2Fixed(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const PetscReal *W, const PetscReal *gamma, PetscReal *Q, PetscReal *g)
{
  __m256d gs[NB];
  for (int b = 0; b < NB; ++b) gs[b] = _mm256_loadu_pd(g + 4 * b);
  for (PetscInt p = 0; p < M; ++p) {
    const PetscReal *w = W + (size_t)p * rp;
    __m256d          wr[NB];
    for (int b = 0; b < NB; ++b) wr[b] = _mm256_loadu_pd(w + 4 * b);
    const PetscInt  *ri = rowIdx + (size_t)p * maxTerms;
    const PetscReal *cp = coef + (size_t)p * maxTerms;
    for (PetscInt t = 0; t < nt[p]; ++t) {
      const __m256d cf = _mm256_broadcast_sd(cp + t);
      PetscReal    *q  = Q + (size_t)ri[t] * rp;
      for (int b = 0; b < NB; ++b) _mm256_storeu_pd(q + 4 * b, _mm256_fmadd_pd(cf, wr[b], _mm256_loadu_pd(q + 4 * b)));
    }
    const __m256d gp = _mm256_broadcast_sd(gamma + p);
    for (int b = 0; b < NB; ++b) gs[b] = _mm256_fmadd_pd(gp, wr[b], gs[b]);
  }
  for (int b = 0; b < NB; ++b) _mm256_storeu_pd(g + 4 * b, gs[b]);
}

__attribute__((target("avx2,fma"))) void ScatterAvx2(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const PetscReal *W, const PetscReal *gamma, PetscReal *Q, PetscReal *g)
{
  // up to 12 blocks (48 rows) in registers: the rest of the 16 hold the term's coefficient and Q
  if (WithRegisterBlocks(rp / 4, [&](auto nb) { ScatterAvx2Fixed<decltype(nb)::value>(M, rp, nt, maxTerms, rowIdx, coef, W, gamma, Q, g); })) return;
  for (PetscInt p = 0; p < M; ++p) {
    const PetscReal *w = W + (size_t)p * rp;
    for (PetscInt t = 0; t < nt[p]; ++t) {
      const __m256d cf = _mm256_broadcast_sd(coef + (size_t)p * maxTerms + t);
      PetscReal    *q  = Q + (size_t)rowIdx[(size_t)p * maxTerms + t] * rp;
      for (PetscInt i = 0; i < rp; i += 4) _mm256_storeu_pd(q + i, _mm256_fmadd_pd(cf, _mm256_loadu_pd(w + i), _mm256_loadu_pd(q + i)));
    }
    const __m256d gp = _mm256_broadcast_sd(gamma + p);
    for (PetscInt i = 0; i < rp; i += 4) _mm256_storeu_pd(g + i, _mm256_fmadd_pd(gp, _mm256_loadu_pd(w + i), _mm256_loadu_pd(g + i)));
  }
}

// The single-precision accumulation: the point's row of W in NB registers of 8 floats over its terms
template <int NB>
__attribute__((target("avx2,fma"))) void ScatterAvx2FFixed(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const float *W, float *Q)
{
  for (PetscInt p = 0; p < M; ++p) {
    const float *w = W + (size_t)p * rp;
    __m256       wr[NB];
    for (int b = 0; b < NB; ++b) wr[b] = _mm256_loadu_ps(w + 8 * b);
    const PetscInt  *ri = rowIdx + (size_t)p * maxTerms;
    const PetscReal *cp = coef + (size_t)p * maxTerms;
    for (PetscInt t = 0; t < nt[p]; ++t) {
      const __m256 cf = _mm256_set1_ps((float)cp[t]);
      float       *q  = Q + (size_t)ri[t] * rp;
      for (int b = 0; b < NB; ++b) _mm256_storeu_ps(q + 8 * b, _mm256_fmadd_ps(cf, wr[b], _mm256_loadu_ps(q + 8 * b)));
    }
  }
}

__attribute__((target("avx2,fma"))) void ScatterAvx2F(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const float *W, float *Q)
{
  if (WithRegisterBlocks(rp / 8, [&](auto nb) { ScatterAvx2FFixed<decltype(nb)::value>(M, rp, nt, maxTerms, rowIdx, coef, W, Q); })) return;
  ScatterPortableF(M, rp, nt, maxTerms, rowIdx, coef, W, Q);
}

// out[r] = b[r] + A(r, :) v with the dots in T (double: b added before the tail, as always; float: after it, the float
// dot then added in double)
template <class T>
__attribute__((target("avx2,fma"))) void RowDotsAvx2T(PetscInt rows, PetscInt n, const T *A, const T *v, const PetscReal *b, PetscReal *out)
{
  using R = Avx2Reg<T>;
  for (PetscInt r = 0; r < rows; ++r) {
    const T      *a   = A + (size_t)r * n;
    typename R::V acc = R::Zero();
    PetscInt      k   = 0;
    for (; k + R::width <= n; k += R::width) acc = R::Fma(R::Load(a + k), R::Load(v + k), acc);
    if constexpr (std::is_same<T, double>::value) {
      PetscReal s = b[r] + R::HSum(acc);
      for (; k < n; ++k) s += a[k] * v[k];
      out[r] = s;
    } else {
      float s = R::HSum(acc);
      for (; k < n; ++k) s += a[k] * v[k];
      out[r] = b[r] + s;
    }
  }
}

// out[k0, k0 + NB w) (w = 4 doubles or 8 floats) held in NB registers over the terms: per term one broadcast and NB
// load-FMAs (double: kappa's rows; float: the single points' sum, the coefficients rounded to float)
template <class T, int NB>
__attribute__((target("avx2,fma"))) void CombineAvx2Fixed(PetscInt nt, const PetscReal *coef, const T *const *rows, PetscInt k0, T *out)
{
  using R = Avx2Reg<T>;
  typename R::V acc[NB];
  for (int b = 0; b < NB; ++b) acc[b] = R::Zero();
  for (PetscInt j = 0; j < nt; ++j) {
    const T             c  = (T)coef[j];
    const typename R::V cf = R::Bcast(&c);
    const T            *t  = rows[j] + k0;
    for (int b = 0; b < NB; ++b) acc[b] = R::Fma(cf, R::Load(t + R::width * b), acc[b]);
  }
  for (int b = 0; b < NB; ++b) R::StoreSame(out + k0 + R::width * b, acc[b]);
}

__attribute__((target("avx2,fma"))) void CombineAvx2(PetscInt nt, const PetscReal *coef, const PetscReal *const *rows, PetscInt n, PetscReal *out)
{
  PetscInt k = 0;
  // the first up to 48 entries with the output in registers (12 blocks), the rest block by block
  const PetscInt nb = std::min<PetscInt>(n / 4, 12);
  WithRegisterBlocks(nb, [&](auto b) { CombineAvx2Fixed<double, decltype(b)::value>(nt, coef, rows, 0, out); });
  k = 4 * nb;
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

__attribute__((target("avx2,fma"))) void CombineAvx2F(PetscInt nt, const PetscReal *coef, const float *const *rows, PetscInt n, float *out)
{
  PetscInt k = 0;
  // passes of up to 12 blocks of 8 in registers, then the tail entry by entry
  for (PetscInt nb; (nb = std::min<PetscInt>((n - k) / 8, 12)) > 0; k += 8 * nb) WithRegisterBlocks(nb, [&](auto b) { CombineAvx2Fixed<float, decltype(b)::value>(nt, coef, rows, k, out); });
  for (; k < n; ++k) {
    float s = 0;
    for (PetscInt j = 0; j < nt; ++j) s += (float)coef[j] * rows[j][k];
    out[k] = s;
  }
}

// The same loops vectorized 4-wide with FMA by the compiler (the inner loops run over the r rows, contiguous)
__attribute__((target("avx2,fma"))) void RightSolveTAvx2(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *D, PetscReal *X) { RightSolveTBody(r, n, L, D, X); }
__attribute__((target("avx2,fma"))) void LowerGramAvx2(PetscInt r, PetscInt n, const PetscReal *X, PetscReal *S) { LowerGramBody(r, n, X, S); }
__attribute__((target("avx2,fma"))) void RightMulLTAvx2(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *G, PetscReal *D) { RightMulLTBody(r, n, L, G, D); }

bool HaveAvx2();

// The points' sum in single precision fused with kappa's row combination, AVX-512 (PointSumSingle): the points in
// chunks of kPointChunk, each chunk's rows x_p combined into a block that stays in L2, then added to a float K (rp x nc,
// column-major) tile by tile: a tile of IB x 16 rows and NC columns held in IB NC registers over the chunk's points
// (per point IB loads of W's row, NC broadcasts, IB NC FMAs). The rows past rp are masked off (W and K are never read
// or written there). The BLAS's sgemm of the same sum ran Haswell's AVX2 kernel on this VM's CPU (OpenBLAS 0.3.21 does
// not know it) and read the M x ldx rows of kappa back from memory (docs/online.md "The fused points' sum").
constexpr PetscInt kPointChunk = 64;

template <int IB, int NC>
__attribute__((target("avx512f"))) void PointTileAvx512(PetscInt np, PetscInt rp, PetscInt i0, const __mmask16 *mask, const float *W, const float *X, PetscInt ldx, PetscInt c0, float *K)
{
  __m512 acc[NC][IB];
#pragma GCC unroll 16
  for (int j = 0; j < NC; ++j)
#pragma GCC unroll 4
    for (int b = 0; b < IB; ++b) acc[j][b] = _mm512_maskz_loadu_ps(mask[b], K + (size_t)(c0 + j) * rp + i0 + 16 * b);
  for (PetscInt p = 0; p < np; ++p) {
    const float *w = W + (size_t)p * rp + i0;
    const float *x = X + (size_t)p * ldx + c0;
    // every load before the FMAs: __m512 may alias float, so a load between them would keep acc in memory
    __m512 wv[IB], xb[NC];
#pragma GCC unroll 4
    for (int b = 0; b < IB; ++b) wv[b] = _mm512_maskz_loadu_ps(mask[b], w + 16 * b);
#pragma GCC unroll 16
    for (int j = 0; j < NC; ++j) xb[j] = _mm512_set1_ps(x[j]);
#pragma GCC unroll 16
    for (int j = 0; j < NC; ++j)
#pragma GCC unroll 4
      for (int b = 0; b < IB; ++b) acc[j][b] = _mm512_fmadd_ps(wv[b], xb[j], acc[j][b]);
  }
#pragma GCC unroll 16
  for (int j = 0; j < NC; ++j)
#pragma GCC unroll 4
    for (int b = 0; b < IB; ++b) _mm512_mask_storeu_ps(K + (size_t)(c0 + j) * rp + i0 + 16 * b, mask[b], acc[j][b]);
}

// out[k0, k0 + 16 NB) = sum_j cf[j] rows[j][k0, ...) in float, held in NB registers over the terms (the last one
// masked by last); NB fixed so that the registers are not kept in memory (__m512 may alias float)
template <int NB>
__attribute__((target("avx512f"))) void CombineAvx512Fixed(PetscInt nt, const float *cf, const float *const *rows, PetscInt k0, __mmask16 last, float *out)
{
  __m512 acc[NB];
#pragma GCC unroll 16
  for (int b = 0; b < NB; ++b) acc[b] = _mm512_setzero_ps();
  for (PetscInt j = 0; j < nt; ++j) {
    const float *t = rows[j] + k0;
    __m512       v[NB];
#pragma GCC unroll 16
    for (int b = 0; b < NB; ++b) v[b] = _mm512_maskz_loadu_ps(b == NB - 1 ? last : (__mmask16)0xFFFF, t + 16 * b);
    const __m512 c = _mm512_set1_ps(cf[j]);
#pragma GCC unroll 16
    for (int b = 0; b < NB; ++b) acc[b] = _mm512_fmadd_ps(c, v[b], acc[b]);
  }
#pragma GCC unroll 16
  for (int b = 0; b < NB; ++b) _mm512_mask_storeu_ps(out + k0 + 16 * b, b == NB - 1 ? last : (__mmask16)0xFFFF, acc[b]);
}

// out[0:n) = sum_j coef[j] rows[j][0:n) in float: passes of up to 12 registers of 16 entries
__attribute__((target("avx512f"))) void CombineAvx512F(PetscInt nt, const PetscReal *coef, const float *const *rows, PetscInt n, float *out)
{
  float cf[64]; // >= ContactPatch::MaxTerms
  for (PetscInt j = 0; j < nt; ++j) cf[j] = (float)coef[j];
  for (PetscInt k0 = 0; k0 < n; k0 += 16 * 12) {
    const PetscInt  nb   = std::min<PetscInt>(12, (n - k0 + 15) / 16), left = n - k0 - 16 * (nb - 1);
    const __mmask16 last = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1);
    WithRegisterBlocks(nb, [&](auto b) { CombineAvx512Fixed<decltype(b)::value>(nt, cf, rows, k0, last, out); });
  }
}

// Calls f(std::integral_constant<int, C>()) for 1 <= nc <= 8 (the column counts of PointTileAvx512's tiles)
template <int C = 1, class F>
void WithTileColumns(PetscInt nc, F &&f)
{
  if constexpr (C <= 8) {
    if (nc == C) f(std::integral_constant<int, C>());
    else WithTileColumns<C + 1>(nc, std::forward<F>(f));
  }
}

__attribute__((target("avx512f"))) void PointSumAvx512(PetscInt M, PetscInt rp, PetscInt nc, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const float *theta, PetscInt ldt, const float *W, PetscReal *K)
{
  constexpr int IB = 2; // tiles of 32 rows x 8 columns: 16 accumulators, 2 W registers, 8 broadcasts
  thread_local std::vector<float> Kf, X;
  Kf.assign((size_t)rp * nc, 0.0f);
  X.resize((size_t)kPointChunk * ldt);
  const float *rows[64];
  for (PetscInt p0 = 0; p0 < M; p0 += kPointChunk) {
    const PetscInt np = std::min(kPointChunk, M - p0);
    for (PetscInt q = 0; q < np; ++q) {
      const PetscInt  p  = p0 + q;
      const PetscInt *ri = rowIdx + (size_t)p * maxTerms;
      for (PetscInt t = 0; t < nt[p]; ++t) rows[t] = theta + (size_t)ri[t] * ldt;
      CombineAvx512F(nt[p], coef + (size_t)p * maxTerms, rows, nc, X.data() + (size_t)q * ldt);
    }
    for (PetscInt c0 = 0; c0 < nc; c0 += 8)
      for (PetscInt i0 = 0; i0 < rp; i0 += 16 * IB) {
        __mmask16 m[IB];
        for (int b = 0; b < IB; ++b) {
          const PetscInt left = rp - i0 - 16 * b;
          m[b]                = left >= 16 ? (__mmask16)0xFFFF : left > 0 ? (__mmask16)((1u << left) - 1) : (__mmask16)0;
        }
        const float *Wc = W + (size_t)p0 * rp;
        // a last tile of at most 16 rows in one register (the second would be all masked: FMAs for nothing)
        if (rp - i0 <= 16) WithTileColumns(std::min<PetscInt>(8, nc - c0), [&](auto C) { PointTileAvx512<1, decltype(C)::value>(np, rp, i0, m, Wc, X.data(), ldt, c0, Kf.data()); });
        else WithTileColumns(std::min<PetscInt>(8, nc - c0), [&](auto C) { PointTileAvx512<IB, decltype(C)::value>(np, rp, i0, m, Wc, X.data(), ldt, c0, Kf.data()); });
      }
  }
  std::copy(Kf.begin(), Kf.end(), K);
}

bool HaveAvx512()
{
  static const bool have = [] {
    __builtin_cpu_init();
    return HaveAvx2() && __builtin_cpu_supports("avx512f");
  }();
  return have;
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

void CombineRowsSingle(PetscInt nt, const PetscReal *coef, const float *const *rows, PetscInt n, float *out)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return CombineAvx2F(nt, coef, rows, n, out);
#endif
  CombinePortableF(nt, coef, rows, n, out);
}

namespace {
thread_local bool gemmBlas = true; // per thread: each ReducedModel sets its own before its sums

// K (rp x nc, column-major, double) = W' X by the BLAS: W is M x rp point-major (a column-major rp x M), X either
// nc x M row-major (transX false: a column-major M x nc, leading dimension ldx) or M x nc row-major (transX true:
// a column-major nc x M). Single precision through a float result, converted.
template <class T>
void Gemm(bool transX, PetscInt M, PetscInt rp, PetscInt nc, const T *W, const T *X, PetscInt ldx, PetscReal *K)
{
  if (rp <= 0 || nc <= 0) return;
  if (M <= 0) {
    std::fill(K, K + (size_t)rp * nc, 0.0);
    return;
  }
  const PetscBLASInt m = (PetscBLASInt)rp, n = (PetscBLASInt)nc, k = (PetscBLASInt)M, ld = (PetscBLASInt)ldx;
  const PetscBLASInt inc = transX ? ld : 1, one1 = 1; // one column (g^): gemv, which does not pack W as gemm does
  const T            one = 1, zero = 0;
  if constexpr (std::is_same<T, double>::value) {
    if (nc == 1) BLASgemv_("N", &m, &k, &one, W, &m, X, &inc, &zero, K, &one1);
    else BLASgemm_("N", transX ? "T" : "N", &m, &n, &k, &one, W, &m, X, &ld, &zero, K, &m);
  } else {
    thread_local std::vector<float> Kf;
    Kf.resize((size_t)rp * nc);
    if (nc == 1) RBC_SGEMV("N", &m, &k, &one, W, &m, X, &inc, &zero, Kf.data(), &one1);
    else RBC_SGEMM("N", transX ? "T" : "N", &m, &n, &k, &one, W, &m, X, &ld, &zero, Kf.data(), &m);
    std::copy(Kf.begin(), Kf.end(), K);
  }
}

// The built-in kernels' sum of a point-major X: transposed into a scratch array first
template <class T>
void OuterRowsBuiltin(PetscInt M, PetscInt rp, PetscInt nc, const T *W, const T *X, PetscInt ldx, PetscReal *K)
{
  thread_local std::vector<T> Xt;
  Xt.resize((size_t)nc * M);
  for (PetscInt c = 0; c < nc; ++c)
    for (PetscInt p = 0; p < M; ++p) Xt[(size_t)c * M + p] = X[(size_t)p * ldx + c];
  if constexpr (std::is_same<T, double>::value) SumOfOuterProducts(M, rp, nc, W, Xt.data(), K);
  else SumOfOuterProductsSingle(M, rp, nc, W, Xt.data(), K);
}
} // namespace

void SetGemmBlas(bool blas) { gemmBlas = blas; }
bool GemmBlas() { return gemmBlas; }

void SumOfOuterProductsRows(PetscInt M, PetscInt rp, PetscInt nc, const PetscReal *W, const PetscReal *X, PetscInt ldx, PetscReal *K)
{
  if (gemmBlas) Gemm<double>(true, M, rp, nc, W, X, ldx, K);
  else OuterRowsBuiltin<double>(M, rp, nc, W, X, ldx, K);
}

void SumOfOuterProductsRowsSingle(PetscInt M, PetscInt rp, PetscInt nc, const float *W, const float *X, PetscInt ldx, PetscReal *K)
{
  if (gemmBlas) Gemm<float>(true, M, rp, nc, W, X, ldx, K);
  else OuterRowsBuiltin<float>(M, rp, nc, W, X, ldx, K);
}

void SumOfOuterProducts(PetscInt M, PetscInt rp, PetscInt nc, const PetscReal *W, const PetscReal *X, PetscReal *K)
{
  if (gemmBlas) return Gemm<double>(false, M, rp, nc, W, X, std::max<PetscInt>(M, 1), K);
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return OuterAvx2<double>(M, rp, nc, W, X, K);
#endif
  OuterPortable<double>(M, rp, nc, W, X, K);
}

void ScatterRows(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const PetscReal *W, const PetscReal *gamma, PetscReal *Q, PetscReal *g)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return ScatterAvx2(M, rp, nt, maxTerms, rowIdx, coef, W, gamma, Q, g);
#endif
  ScatterPortable(M, rp, nt, maxTerms, rowIdx, coef, W, gamma, Q, g);
}

void RightSolveT(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *D, PetscReal *X)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return RightSolveTAvx2(r, n, L, D, X);
#endif
  RightSolveTPortable(r, n, L, D, X);
}

void RightMulLT(PetscInt r, PetscInt n, const PetscReal *L, const PetscReal *G, PetscReal *D)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return RightMulLTAvx2(r, n, L, G, D);
#endif
  RightMulLTPortable(r, n, L, G, D);
}

void LowerGram(PetscInt r, PetscInt n, const PetscReal *X, PetscReal *S)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return LowerGramAvx2(r, n, X, S);
#endif
  LowerGramPortable(r, n, X, S);
}

void SumOfOuterProductsSingle(PetscInt M, PetscInt rp, PetscInt nc, const float *W, const float *X, PetscReal *K)
{
  if (gemmBlas) return Gemm<float>(false, M, rp, nc, W, X, std::max<PetscInt>(M, 1), K);
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return OuterAvx2<float>(M, rp, nc, W, X, K);
#endif
  OuterPortable<float>(M, rp, nc, W, X, K);
}

void ScatterRowsSingle(PetscInt M, PetscInt rp, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const float *W, float *Q)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return ScatterAvx2F(M, rp, nt, maxTerms, rowIdx, coef, W, Q);
#endif
  ScatterPortableF(M, rp, nt, maxTerms, rowIdx, coef, W, Q);
}

void RowDots(PetscInt rows, PetscInt n, const PetscReal *A, const PetscReal *v, const PetscReal *b, PetscReal *out)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return RowDotsAvx2T<double>(rows, n, A, v, b, out);
#endif
  RowDotsPortable(rows, n, A, v, b, out);
}

void RowDotsSingle(PetscInt rows, PetscInt n, const float *A, const float *v, const PetscReal *b, PetscReal *out)
{
#ifdef RBC_KERNEL_DISPATCH
  if (HaveAvx2()) return RowDotsAvx2T<float>(rows, n, A, v, b, out);
#endif
  RowDotsPortableF(rows, n, A, v, b, out);
}

bool PointSumFusedAvailable()
{
#ifdef RBC_KERNEL_DISPATCH
  return HaveAvx512();
#else
  return false;
#endif
}

void PointSumSingle(bool fused, PetscInt M, PetscInt rp, PetscInt nc, const PetscInt *nt, PetscInt maxTerms, const PetscInt *rowIdx, const PetscReal *coef, const float *theta, PetscInt ldt, const float *W, float *X, PetscReal *K)
{
#ifdef RBC_KERNEL_DISPATCH
  if (fused && HaveAvx512()) return PointSumAvx512(M, rp, nc, nt, maxTerms, rowIdx, coef, theta, ldt, W, K);
#endif
  const float *rows[64];
  for (PetscInt p = 0; p < M; ++p) {
    const PetscInt *ri = rowIdx + (size_t)p * maxTerms;
    for (PetscInt t = 0; t < nt[p]; ++t) rows[t] = theta + (size_t)ri[t] * ldt;
    CombineRowsSingle(nt[p], coef + (size_t)p * maxTerms, rows, ldt, X + (size_t)p * ldt);
  }
  SumOfOuterProductsRowsSingle(M, rp, nc, W, X, ldt, K);
}

} // namespace rbc
