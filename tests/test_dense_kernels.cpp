// tests/test_dense_kernels.cpp: the online contact kernels (src/rom/dense_kernels.cpp) against plain
// loops, serial: SumOfOuterProducts for sizes around the 4 x 4 blocking (rows 1..18 padded, columns
// 1..21, 0..202 points) and CombineRows for 0..12 terms of length 1..23. The dispatched version (AVX2+FMA
// where the CPU has it) must agree with the plain sums to rounding (1e-13 relative to the sum of |terms|).
#include "../src/rom/dense_kernels.hpp"
#include <cmath>
#include <random>
#include <vector>

using namespace rbc;

int main(int argc, char **argv)
{
  int          failures = 0, checks = 0;
  double       worst    = 0;
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(-1, 1);

  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  for (PetscInt M : {0, 1, 7, 202})
    for (PetscInt r : {1, 3, 4, 5, 18})
      for (PetscInt nc : {1, 3, 4, 5, 21}) {
        const PetscInt      rp = PaddedRows(r);
        std::vector<double> W((size_t)M * rp, 0.0), X((size_t)nc * M), K((size_t)rp * nc, -7.0);
        for (PetscInt p = 0; p < M; ++p)
          for (PetscInt i = 0; i < r; ++i) W[(size_t)p * rp + i] = u(gen);
        for (auto &x : X) x = u(gen);
        SumOfOuterProducts(M, rp, nc, W.data(), X.data(), K.data());
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
              PetscCall(PetscPrintf(PETSC_COMM_SELF, "FAIL SumOfOuterProducts M %d r %d nc %d entry (%d, %d): %g vs %g\n", (int)M, (int)r, (int)nc, (int)i, (int)c, K[(size_t)c * rp + i], s));
            }
          }
      }
  for (PetscInt nt = 0; nt <= 12; ++nt)
    for (PetscInt n = 1; n <= 23; ++n) {
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
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "%s: %d entries checked, worst relative difference %.2e (bound 1e-13)\n", failures ? "FAIL" : "ok", checks, worst));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
