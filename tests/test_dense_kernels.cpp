// tests/test_dense_kernels.cpp: the online contact kernels (src/rom/dense_kernels.cpp) against plain
// loops, serial: SumOfOuterProducts for sizes around the 4 x 4 and 12 x 4 blocking (rows 1..18 padded,
// columns 1..21, 0..202 points), CombineRows for 0..12 terms of length 1..61 (the output held in 1..12
// register blocks, and beyond), and ScatterRows (the patch-dof accumulation, rows 1..60: the point's row in
// 1..12 register blocks, and beyond) with repeated target rows, 0..8 terms per point; RightSolveT (through the
// residual X L' - D) and LowerGram of the reduced QP's set-up, n 1..60; RowDots (U = uD + theta v). The dispatched version (AVX2+FMA
// where the CPU has it) must agree with the plain sums to rounding (1e-13 relative to the sum of |terms|). The single-precision
// dof sum (SumOfOuterProductsSingle, ScatterRowsSingle: 1..15 blocks of 8 rows) and the float row combination
// (CombineRowsSingle) and dots (RowDotsSingle) within the float accumulation bound.
// The sums of outer products each by the BLAS's gemm and by the built-in kernels (SetGemmBlas), and from point-major
// rows (SumOfOuterProductsRows*, the points' sum of the cubature); PointSumSingle (the same sum with kappa's rows formed
// from theta's, fused with AVX-512).
#include "../src/rom/dense_kernels.hpp"
#include <cmath>
#include <random>
#include <vector>

using namespace rbc;

int main(int argc, char **argv)
{
  int          failures = 0, checks = 0;
  double       worst = 0, worst32 = 0;
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(-1, 1);

  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  // the sums of outer products by the BLAS's gemm and by the built-in kernels (-rom_gemm), X row-major by columns
  // (SumOfOuterProducts) and point-major with a leading dimension beyond nc (SumOfOuterProductsRows)
  for (bool blas : {true, false})
    for (bool rows : {false, true})
  for (PetscInt M : {0, 1, 7, 202})
    for (PetscInt r : {1, 3, 4, 5, 9, 12, 18})
      for (PetscInt nc : {1, 3, 4, 5, 21}) {
        const PetscInt      rp = PaddedRows(r), ldx = nc + 2;
        std::vector<double> W((size_t)M * rp, 0.0), X((size_t)nc * M), K((size_t)rp * nc, -7.0), Xr((size_t)M * ldx, 99.0);
        for (PetscInt p = 0; p < M; ++p)
          for (PetscInt i = 0; i < r; ++i) W[(size_t)p * rp + i] = u(gen);
        for (auto &x : X) x = u(gen);
        for (PetscInt p = 0; p < M; ++p)
          for (PetscInt c = 0; c < nc; ++c) Xr[(size_t)p * ldx + c] = X[(size_t)c * M + p];
        SetGemmBlas(blas);
        if (rows) SumOfOuterProductsRows(M, rp, nc, W.data(), Xr.data(), ldx, K.data());
        else SumOfOuterProducts(M, rp, nc, W.data(), X.data(), K.data());
        for (PetscInt c = 0; c < nc; ++c)
          for (PetscInt i = 0; i < rp; ++i) {
            double s = 0, a = 0;
            for (PetscInt p = 0; p < M; ++p) {
              s += W[(size_t)p * rp + i] * X[(size_t)c * M + p];
              a += std::abs(W[(size_t)p * rp + i] * X[(size_t)c * M + p]);
            }
            const double e = std::abs(K[(size_t)c * rp + i] - s) / std::max(a, 1e-300);
            worst          = std::max(worst, e);
            ++checks;
            if (!(e <= 1e-13) && !(a == 0 && K[(size_t)c * rp + i] == 0)) {
              ++failures;
              PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL SumOfOuterProducts%s (%s) M %d r %d nc %d entry (%d, %d): %g vs %g\n", rows ? "Rows" : "", blas ? "blas" : "builtin", (int)M, (int)r, (int)nc, (int)i, (int)c, K[(size_t)c * rp + i], s));
            }
          }
      }
  for (PetscInt nt = 0; nt <= 12; ++nt)
    for (PetscInt n : {1, 2, 3, 4, 5, 7, 8, 9, 12, 13, 16, 17, 20, 21, 23, 44, 47, 48, 49, 52, 61}) {
      std::vector<std::vector<double>> rows(nt, std::vector<double>(n));
      std::vector<const double *>      ptr(nt);
      std::vector<double>              coef(nt), out(n, -7.0);
      for (PetscInt j = 0; j < nt; ++j) {
        coef[j] = u(gen);
        for (auto &x : rows[j]) x = u(gen);
        ptr[j] = rows[j].data();
      }
      CombineRows(nt, coef.data(), ptr.data(), n, out.data());
      for (PetscInt k = 0; k < n; ++k) {
        double s = 0, a = 0;
        for (PetscInt j = 0; j < nt; ++j) {
          s += coef[j] * rows[j][k];
          a += std::abs(coef[j] * rows[j][k]);
        }
        const double e = a > 0 ? std::abs(out[k] - s) / a : std::abs(out[k]);
        worst          = std::max(worst, e);
        ++checks;
        if (!(e <= 1e-13)) {
          ++failures;
          PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL CombineRows nt %d n %d entry %d: %g vs %g\n", (int)nt, (int)n, (int)k, out[k], s));
        }
      }
    }
  for (PetscInt M : {0, 1, 7, 202})
    for (PetscInt r : {1, 4, 5, 12, 18, 30, 45, 48, 49, 60}) {
      const PetscInt        rp = PaddedRows(r), nd = 13, maxT = 36;
      std::vector<double>   W((size_t)M * rp, 0.0), coef((size_t)M * maxT, 99.0), gamma(M), Q((size_t)nd * rp, 0.5), g(rp, -0.25);
      std::vector<PetscInt> nt(M), row((size_t)M * maxT, -1);
      for (PetscInt p = 0; p < M; ++p) {
        for (PetscInt i = 0; i < r; ++i) W[(size_t)p * rp + i] = u(gen);
        gamma[p] = u(gen);
        nt[p]    = p % 9; // 0..8 terms, target rows repeat across points
        for (PetscInt t = 0; t < nt[p]; ++t) {
          coef[(size_t)p * maxT + t] = u(gen);
          row[(size_t)p * maxT + t]  = (p + 3 * t) % nd;
        }
      }
      std::vector<double> Qr(Q), gr(g), Qa(Q.size(), 0.0), ga(rp, 0.0);
      for (PetscInt p = 0; p < M; ++p) {
        for (PetscInt t = 0; t < nt[p]; ++t)
          for (PetscInt i = 0; i < rp; ++i) {
            const double term = coef[(size_t)p * maxT + t] * W[(size_t)p * rp + i];
            Qr[(size_t)row[(size_t)p * maxT + t] * rp + i] += term;
            Qa[(size_t)row[(size_t)p * maxT + t] * rp + i] += std::abs(term);
          }
        for (PetscInt i = 0; i < rp; ++i) {
          gr[i] += gamma[p] * W[(size_t)p * rp + i];
          ga[i] += std::abs(gamma[p] * W[(size_t)p * rp + i]);
        }
      }
      ScatterRows(M, rp, nt.data(), maxT, row.data(), coef.data(), W.data(), gamma.data(), Q.data(), g.data());
      auto check = [&](double got, double want, double a, const char *what, PetscInt i) -> PetscErrorCode {
        PetscFunctionBeginUser;
        const double e = std::abs(got - want) / (a + 1.0); // the initial values (0.5, -0.25) are part of the sum
        worst          = std::max(worst, e);
        ++checks;
        if (!(e <= 1e-13)) {
          ++failures;
          PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL ScatterRows M %d r %d %s entry %d: %g vs %g\n", (int)M, (int)r, what, (int)i, got, want));
        }
        PetscFunctionReturn(0);
      };
      for (size_t k = 0; k < Q.size(); ++k) PetscCall(check(Q[k], Qr[k], Qa[k], "Q", (PetscInt)k));
      for (PetscInt i = 0; i < rp; ++i) PetscCall(check(g[i], gr[i], ga[i], "g", i));
    }
  // the dof sum in single precision (-rom_ecsw_precision single): float inputs, float accumulation; against the
  // double sum of the same float inputs, within the accumulation bound (terms + 2) 2^-24 sum |terms| per entry
  // (a misplaced row or column is off by O(1) of the sum)
  const double uf = std::ldexp(1.0, -24);
  for (bool blas : {true, false})
    for (bool rows : {false, true})
  for (PetscInt M : {0, 1, 7, 202, 631})
    for (PetscInt r : {1, 5, 8, 9, 24, 30, 33, 44})
      for (PetscInt nc : {1, 3, 4, 5, 44}) {
        const PetscInt      rps = PaddedRows(r, 8), ldx = nc + 1;
        std::vector<float>  W((size_t)M * rps, 0.0f), X((size_t)nc * M), Xr((size_t)M * ldx, 99.0f);
        std::vector<double> K((size_t)rps * nc, -7.0);
        for (PetscInt p = 0; p < M; ++p)
          for (PetscInt i = 0; i < r; ++i) W[(size_t)p * rps + i] = (float)u(gen);
        for (auto &x : X) x = (float)u(gen);
        for (PetscInt p = 0; p < M; ++p)
          for (PetscInt c = 0; c < nc; ++c) Xr[(size_t)p * ldx + c] = X[(size_t)c * M + p];
        SetGemmBlas(blas);
        if (rows) SumOfOuterProductsRowsSingle(M, rps, nc, W.data(), Xr.data(), ldx, K.data());
        else SumOfOuterProductsSingle(M, rps, nc, W.data(), X.data(), K.data());
        for (PetscInt c = 0; c < nc; ++c)
          for (PetscInt i = 0; i < rps; ++i) {
            double s = 0, a = 0;
            for (PetscInt p = 0; p < M; ++p) {
              s += (double)W[(size_t)p * rps + i] * X[(size_t)c * M + p];
              a += std::abs((double)W[(size_t)p * rps + i] * X[(size_t)c * M + p]);
            }
            const double e = std::abs(K[(size_t)c * rps + i] - s), bound = (M + 2) * uf * a;
            worst32        = std::max(worst32, a > 0 ? e / a : e);
            ++checks;
            if (!(e <= bound)) {
              ++failures;
              PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL SumOfOuterProducts%sSingle (%s) M %d r %d nc %d entry (%d, %d): %g vs %g\n", rows ? "Rows" : "", blas ? "blas" : "builtin", (int)M, (int)r, (int)nc, (int)i, (int)c, K[(size_t)c * rps + i], s));
            }
          }
      }
  // PointSumSingle, the points' sum in single precision with kappa's rows formed on the way (fused with AVX-512:
  // chunks of 64 points, tiles of 32 rows x 8 columns, a last tile of <= 16 rows; else combination + sum): sizes
  // around the chunk and the tiles, 0..18 terms a point from 41 float rows of theta padded with zeros; against the
  // double sum of the same float inputs within the float accumulation bound (M + terms + 4) 2^-24 sum |terms|, the
  // padded rows of K exactly 0
  for (PetscInt M : {0, 1, 63, 64, 65, 202, 631})
    for (PetscInt r : {1, 8, 9, 16, 17, 31, 33, 47, 49, 162})
      for (PetscInt nc : {1, 7, 8, 9, 17, 44, 225}) {
        const PetscInt        rps = PaddedRows(r, 8), ldt = PaddedRows(nc, 8), nr = 41, maxT = 36;
        std::vector<float>    W((size_t)M * rps, 0.0f), theta((size_t)nr * ldt, 0.0f), X((size_t)M * ldt, 99.0f);
        std::vector<double>   coef((size_t)M * maxT, 99.0), K((size_t)rps * nc, -7.0);
        std::vector<PetscInt> nt(M), row((size_t)M * maxT, -1);
        for (PetscInt p = 0; p < M; ++p)
          for (PetscInt i = 0; i < r; ++i) W[(size_t)p * rps + i] = (float)u(gen);
        for (PetscInt a = 0; a < nr; ++a)
          for (PetscInt c = 0; c < nc; ++c) theta[(size_t)a * ldt + c] = (float)u(gen);
        for (PetscInt p = 0; p < M; ++p) {
          nt[p] = p % 19;
          for (PetscInt t = 0; t < nt[p]; ++t) {
            coef[(size_t)p * maxT + t] = u(gen);
            row[(size_t)p * maxT + t]  = (PetscInt)(gen() % nr);
          }
        }
        PointSumSingle(true, M, rps, nc, nt.data(), maxT, row.data(), coef.data(), theta.data(), ldt, W.data(), X.data(), K.data());
        std::vector<double> s((size_t)rps * nc, 0.0), a((size_t)rps * nc, 0.0), x(nc), xa(nc);
        for (PetscInt p = 0; p < M; ++p) {
          std::fill(x.begin(), x.end(), 0.0);
          std::fill(xa.begin(), xa.end(), 0.0);
          for (PetscInt t = 0; t < nt[p]; ++t)
            for (PetscInt c = 0; c < nc; ++c) {
              const double term = (double)(float)coef[(size_t)p * maxT + t] * theta[(size_t)row[(size_t)p * maxT + t] * ldt + c];
              x[c] += term;
              xa[c] += std::abs(term);
            }
          for (PetscInt c = 0; c < nc; ++c)
            for (PetscInt i = 0; i < rps; ++i) {
              s[(size_t)c * rps + i] += (double)W[(size_t)p * rps + i] * x[c];
              a[(size_t)c * rps + i] += std::abs((double)W[(size_t)p * rps + i]) * xa[c];
            }
        }
        for (size_t k = 0; k < K.size(); ++k) {
          const double e = std::abs(K[k] - s[k]), bound = (M + 18 + 4) * uf * a[k];
          worst32        = std::max(worst32, a[k] > 0 ? e / a[k] : e);
          ++checks;
          if (!(e <= bound)) {
            ++failures;
            PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL PointSumSingle (%s) M %d r %d nc %d entry (%d, %d): %g vs %g\n", PointSumFusedAvailable() ? "fused" : "combination + sum", (int)M, (int)r, (int)nc, (int)(k % rps), (int)(k / rps), K[k], s[k]));
          }
        }
      }
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "PointSumSingle: %s\n", PointSumFusedAvailable() ? "fused (AVX-512)" : "row combination + sum of outer products"));
  for (PetscInt M : {0, 1, 7, 202})
    for (PetscInt r : {1, 5, 8, 9, 24, 30, 45, 96, 97, 120}) {
      const PetscInt        rps = PaddedRows(r, 8), nd = 13, maxT = 36;
      std::vector<float>    W((size_t)M * rps, 0.0f), Q((size_t)nd * rps, 0.5f);
      std::vector<double>   coef((size_t)M * maxT, 99.0), Qr(Q.size(), 0.5), Qa(Q.size(), 0.5);
      std::vector<PetscInt> nt(M), row((size_t)M * maxT, -1), count(Q.size(), 1);
      for (PetscInt p = 0; p < M; ++p) {
        for (PetscInt i = 0; i < r; ++i) W[(size_t)p * rps + i] = (float)u(gen);
        nt[p] = p % 9;
        for (PetscInt t = 0; t < nt[p]; ++t) {
          coef[(size_t)p * maxT + t] = u(gen);
          row[(size_t)p * maxT + t]  = (p + 3 * t) % nd;
          for (PetscInt i = 0; i < rps; ++i) {
            const size_t k    = (size_t)row[(size_t)p * maxT + t] * rps + i;
            const double term = (double)(float)coef[(size_t)p * maxT + t] * W[(size_t)p * rps + i];
            Qr[k] += term;
            Qa[k] += std::abs(term);
            ++count[k];
          }
        }
      }
      ScatterRowsSingle(M, rps, nt.data(), maxT, row.data(), coef.data(), W.data(), Q.data());
      for (size_t k = 0; k < Q.size(); ++k) {
        const double e = std::abs(Q[k] - Qr[k]);
        worst32        = std::max(worst32, e / Qa[k]);
        ++checks;
        if (!(e <= (count[k] + 2) * uf * Qa[k])) {
          ++failures;
          PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL ScatterRowsSingle M %d r %d entry %d: %g vs %g\n", (int)M, (int)r, (int)k, (double)Q[k], Qr[k]));
        }
      }
    }
  // CombineRowsSingle (kappa's rows in float for the single points' sum): 0..18 terms (3D P1: 2 sides x 3 nodes x 3),
  // lengths around the 12 blocks of 8 held in registers, one pass and two (192: the finest 3D model's padded N), and tails
  for (PetscInt nt = 0; nt <= 18; ++nt)
    for (PetscInt n : {1, 7, 8, 9, 15, 16, 17, 95, 96, 97, 103, 104, 191, 192, 200}) {
      std::vector<std::vector<float>> rows(nt, std::vector<float>(n));
      std::vector<const float *>      ptr(nt);
      std::vector<double>             coef(nt);
      std::vector<float>              out(n + 1, -7.0f);
      for (PetscInt j = 0; j < nt; ++j) {
        coef[j] = u(gen);
        for (auto &x : rows[j]) x = (float)u(gen);
        ptr[j] = rows[j].data();
      }
      CombineRowsSingle(nt, coef.data(), ptr.data(), n, out.data());
      ++checks;
      if (out[n] != -7.0f) {
        ++failures;
        PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL CombineRowsSingle nt %d n %d: wrote past the end\n", (int)nt, (int)n));
      }
      for (PetscInt k = 0; k < n; ++k) {
        double s = 0, a = 0;
        for (PetscInt j = 0; j < nt; ++j) {
          const double term = (double)(float)coef[j] * rows[j][k];
          s += term;
          a += std::abs(term);
        }
        const double e = std::abs(out[k] - s);
        worst32        = std::max(worst32, a > 0 ? e / a : e);
        ++checks;
        if (!(e <= (nt + 2) * uf * a)) {
          ++failures;
          PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL CombineRowsSingle nt %d n %d entry %d: %g vs %g\n", (int)nt, (int)n, (int)k, (double)out[k], s));
        }
      }
    }
  // RowDots: out = b + A v
  for (PetscInt rows : {0, 1, 7})
    for (PetscInt n : {0, 1, 3, 4, 5, 13, 60}) {
      std::vector<double> A((size_t)rows * n), v(n), b(rows), out(rows, -7.0);
      for (auto &x : A) x = u(gen);
      for (auto &x : v) x = u(gen);
      for (auto &x : b) x = u(gen);
      RowDots(rows, n, A.data(), v.data(), b.data(), out.data());
      for (PetscInt r = 0; r < rows; ++r) {
        double s = b[r], a = std::abs(b[r]);
        for (PetscInt k = 0; k < n; ++k) {
          s += A[(size_t)r * n + k] * v[k];
          a += std::abs(A[(size_t)r * n + k] * v[k]);
        }
        const double e = std::abs(out[r] - s) / std::max(a, 1e-300);
        worst          = std::max(worst, e);
        ++checks;
        if (!(e <= 1e-13)) {
          ++failures;
          PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL RowDots rows %d n %d entry %d: %g vs %g\n", (int)rows, (int)n, (int)r, out[r], s));
        }
      }
    }
  // RowDotsSingle: out = b + A v with A, v in float (the dots in float, b added in double): within the float bound of
  // the dots' terms, n around the 8-wide blocks
  for (PetscInt rows : {0, 1, 7})
    for (PetscInt n : {0, 1, 7, 8, 9, 16, 17, 192, 197}) {
      std::vector<float>  A((size_t)rows * n), v(n);
      std::vector<double> b(rows), out(rows, -7.0);
      for (auto &x : A) x = (float)u(gen);
      for (auto &x : v) x = (float)u(gen);
      for (auto &x : b) x = u(gen);
      RowDotsSingle(rows, n, A.data(), v.data(), b.data(), out.data());
      for (PetscInt r = 0; r < rows; ++r) {
        double s = b[r], a = 0;
        for (PetscInt k = 0; k < n; ++k) {
          s += (double)A[(size_t)r * n + k] * v[k];
          a += std::abs((double)A[(size_t)r * n + k] * v[k]);
        }
        const double e = std::abs(out[r] - s);
        worst32        = std::max(worst32, a > 0 ? e / a : e);
        ++checks;
        if (!(e <= (n + 2) * uf * a + 1e-15 * std::abs(b[r]))) {
          ++failures;
          PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL RowDotsSingle rows %d n %d entry %d: %g vs %g\n", (int)rows, (int)n, (int)r, out[r], s));
        }
      }
    }
  // RightSolveT: X L' = D for a well-conditioned lower L (checked through the residual), LowerGram = X X'
  for (PetscInt n : {1, 3, 4, 5, 13, 60})
    for (PetscInt r : {1, 5, 12}) {
      std::vector<double> L((size_t)n * n, 0.0), D((size_t)r * n), X((size_t)r * n, -7.0), S((size_t)r * r, -7.0);
      for (PetscInt j = 0; j < n; ++j)
        for (PetscInt i = j; i < n; ++i) L[i + (size_t)j * n] = i == j ? 2 + u(gen) : 0.3 * u(gen);
      for (auto &x : D) x = u(gen);
      RightSolveT(r, n, L.data(), D.data(), X.data());
      for (PetscInt i = 0; i < r; ++i)
        for (PetscInt k = 0; k < n; ++k) { // (X L')(i, k) = sum_{m <= k} X(i, m) L(k, m)
          double s = 0, a = 0;
          for (PetscInt m = 0; m <= k; ++m) {
            s += X[i + (size_t)m * r] * L[k + (size_t)m * n];
            a += std::abs(X[i + (size_t)m * r] * L[k + (size_t)m * n]);
          }
          const double e = std::abs(s - D[i + (size_t)k * r]) / std::max(a, 1e-300);
          worst          = std::max(worst, e);
          ++checks;
          if (!(e <= 1e-13)) {
            ++failures;
            PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL RightSolveT n %d r %d entry (%d, %d): residual %g\n", (int)n, (int)r, (int)i, (int)k, s - D[i + (size_t)k * r]));
          }
        }
      LowerGram(r, n, X.data(), S.data());
      for (PetscInt j = 0; j < r; ++j)
        for (PetscInt i = j; i < r; ++i) {
          double s = 0, a = 0;
          for (PetscInt k = 0; k < n; ++k) {
            s += X[i + (size_t)k * r] * X[j + (size_t)k * r];
            a += std::abs(X[i + (size_t)k * r] * X[j + (size_t)k * r]);
          }
          const double e = std::abs(S[i + (size_t)j * r] - s) / std::max(a, 1e-300);
          worst          = std::max(worst, e);
          ++checks;
          if (!(e <= 1e-13)) {
            ++failures;
            PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL LowerGram n %d r %d entry (%d, %d): %g vs %g\n", (int)n, (int)r, (int)i, (int)j, S[i + (size_t)j * r], s));
          }
        }
    }
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "%s: %d entries checked, worst relative difference %.2e (bound 1e-13), single precision %.2e (bound (terms + 2) 2^-24)\n", failures ? "FAIL" : "ok", checks, worst, worst32));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
