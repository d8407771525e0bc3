// bench/bench_outer_products.cpp: micro benchmark (not a test) of the cubature's sum of outer products
// K^ = Pw' kappa (src/rom/dense_kernels.cpp) at the sizes of the 3D reduced models: the built-in AVX2 kernel and the
// BLAS's gemm, in double and in single precision, on random data, one thread. Prints one table (ms per sum, the
// GFLOP/s of the double ones). Usage: OPENBLAS_NUM_THREADS=1 build/bin/rbc_bench_outer_products [-reps 50]
// [-sizes M,rp,N[:M,rp,N...]] (docs/online.md "The BLAS for the cubature's sums").
#include "../src/rom/dense_kernels.hpp"
#include <chrono>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace rbc;

int main(int argc, char **argv)
{
  PetscInt  reps = 50;
  char      sizes[256] = "2738,136,190:1280,56,82:546,32,44";
  PetscBool set;

  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-reps", &reps, NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-sizes", sizes, sizeof sizes, &set));
  PetscCheck(reps >= 1, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-reps %" PetscInt_FMT " must be >= 1", reps);
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "| Mc x rp x N | built-in double | dgemm | built-in single | sgemm | GFLOP/s built-in / dgemm |\n|---|---|---|---|---|---|\n"));
  std::stringstream list(sizes);
  std::string       item;
  while (std::getline(list, item, ':')) {
    long M = 0, rp = 0, N = 0;
    PetscCheck(std::sscanf(item.c_str(), "%ld,%ld,%ld", &M, &rp, &N) == 3 && M > 0 && rp > 0 && N > 0 && rp % 8 == 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "-sizes: '%s' is not M,rp,N with rp a multiple of 8", item.c_str());
    std::mt19937                           gen(1);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double>                    W((size_t)M * rp), X((size_t)M * N), K((size_t)rp * N);
    for (auto &x : W) x = u(gen);
    for (auto &x : X) x = u(gen);
    std::vector<float> Wf(W.begin(), W.end()), Xf(X.begin(), X.end());
    auto time = [&](auto f) { // ms per call, after one warm-up call
      f();
      const auto t0 = std::chrono::steady_clock::now();
      for (PetscInt i = 0; i < reps; ++i) f();
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / reps * 1e3;
    };
    double t[4];
    for (int k = 0; k < 4; ++k) {
      SetGemmBlas(k % 2 == 1);
      t[k] = k < 2 ? time([&] { SumOfOuterProductsRows(M, rp, N, W.data(), X.data(), N, K.data()); }) : time([&] { SumOfOuterProductsRowsSingle(M, rp, N, Wf.data(), Xf.data(), N, K.data()); });
    }
    const double gf = 2.0 * M * rp * N * 1e-6;
    PetscCall(PetscPrintf(PETSC_COMM_SELF, "| %ld x %ld x %ld | %.3f | %.3f | %.3f | %.3f | %.1f / %.1f |\n", M, rp, N, t[0], t[1], t[2], t[3], gf / t[0], gf / t[1]));
  }
  PetscCall(PetscFinalize());
  return 0;
}
