// tests/test_warm_start.cpp: the weights of the online warm start (WarmStartWeights, warm_start.hpp):
// weights sum to 1; one parameter: the bracketing linear interpolation, the nearest outside the range;
// several parameters: affine data reproduced exactly by the affine fit (degree 1) and quadratic data by
// the quadratic one (degree 2, the default online), on grid and scattered training sets with 2 and 3
// parameters; a smooth function approximated better than by the nearest point, and better with degree
// 2 than with 1; collinear training parameters fall back to the nearest one with either degree.
#include <petscsys.h>
#include <cmath>
#include <cstdio>
#include <random>
#include "rbcontact/warm_start.hpp"

using rbc::WarmStartWeights;

static int failures = 0;

static void Check(bool ok, const char *what, double value, double bound)
{
  if (!ok) ++failures;
  std::printf("  %-6s %-84s %10.3e (bound %.1e)\n", ok ? "ok" : "FAILED", what, value, bound);
}

static double Combine(const std::vector<std::pair<size_t, PetscReal>> &w, const std::vector<double> &y)
{
  double s = 0;
  for (const auto &[k, c] : w) s += c * y[k];
  return s;
}

static double WeightSumError(const std::vector<std::pair<size_t, PetscReal>> &w)
{
  double s = 0;
  for (const auto &kc : w) s += kc.second;
  return std::abs(s - 1);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  std::mt19937_64                   gen(5);
  std::mt19937_64                   gen2(6); // the test parameters of the degree-2 fit (degree 1 draws from gen as before)
  std::uniform_real_distribution<> U(0, 1);
  {
    // one parameter: 21 radii in [0.95, 1.15]
    std::vector<PetscReal> mus;
    for (int k = 0; k < 21; ++k) mus.push_back(0.95 + 0.01 * k);
    auto w = WarmStartWeights(mus, {0.2}, {1.0725});
    Check(w.size() == 2 && w[0].first == 12 && w[1].first == 13 && std::abs(w[1].second - 0.25) < 1e-12, "one parameter: the bracket 1.07, 1.08 with weights 0.75, 0.25", w.size() == 2 ? w[1].second : -1, 0.25);
    w = WarmStartWeights(mus, {0.2}, {1.2});
    Check(w.size() == 1 && w[0].first == 20 && w[0].second == 1, "one parameter outside the training range: the nearest", (double)w.size(), 1);
  }
  for (int np : {2, 3}) {
    // a grid (9 x 9, 5 x 5 x 5) and a scattered set of the same size in the box [0.7, 1.3] x [0.06, 0.12] (x [0, 1])
    const double lo[3] = {0.7, 0.06, 0}, wd[3] = {0.6, 0.06, 1};
    const int    n1    = np == 2 ? 9 : 5;
    for (int scattered : {0, 1}) {
      std::vector<PetscReal> mus;
      int                    nw = 1;
      for (int i = 0; i < np; ++i) nw *= n1;
      for (int k = 0; k < nw; ++k) {
        int kk = k;
        for (int i = 0; i < np; ++i, kk /= n1) mus.push_back(lo[i] + wd[i] * (scattered ? U(gen) : (kk % n1) / (n1 - 1.0)));
      }
      std::vector<double> yaff(nw), yq(nw), ysm(nw);
      auto                aff = [&](const PetscReal *m) { double s = 0.3; for (int i = 0; i < np; ++i) s += (i + 1.5) * m[i] / wd[i]; return s; };
      auto                quad = [&](const PetscReal *m) { double s = aff(m); for (int i = 0; i < np; ++i) for (int l = i; l < np; ++l) s += (1 + i - 0.7 * l) * m[i] * m[l] / (wd[i] * wd[l]); return s; };
      auto                sm  = [&](const PetscReal *m) { double s = 0; for (int i = 0; i < np; ++i) s += std::sin(2 * (m[i] - lo[i]) / wd[i]); return s; };
      for (int k = 0; k < nw; ++k) {
        yaff[k] = aff(&mus[(size_t)k * np]);
        yq[k]   = quad(&mus[(size_t)k * np]);
        ysm[k]  = sm(&mus[(size_t)k * np]);
      }
      double efitDeg[3] = {0, 0, 0};
      for (int deg : {1, 2}) {
        double eexact = 0, esum = 0, efit = 0, enear = 0;
        for (int t = 0; t < 200; ++t) {
          std::vector<PetscReal> mu(np);
          for (int i = 0; i < np; ++i) mu[i] = lo[i] + wd[i] * U(deg == 1 ? gen : gen2);
          const auto w = WarmStartWeights(mus, std::vector<PetscReal>(wd, wd + np), mu, deg);
          eexact       = std::max(eexact, std::abs(Combine(w, deg == 1 ? yaff : yq) - (deg == 1 ? aff(mu.data()) : quad(mu.data()))));
          esum         = std::max(esum, WeightSumError(w));
          efit         = std::max(efit, std::abs(Combine(w, ysm) - sm(mu.data())));
          size_t best = 0;
          double bd   = 1e300;
          for (int k = 0; k < nw; ++k) {
            double d = 0;
            for (int i = 0; i < np; ++i) d += std::pow((mus[(size_t)k * np + i] - mu[i]) / wd[i], 2);
            if (d < bd) { bd = d; best = (size_t)k; }
          }
          enear = std::max(enear, std::abs(ysm[best] - sm(mu.data())));
        }
        efitDeg[deg] = efit / enear;
        char what[120];
        std::snprintf(what, sizeof what, "%d parameters, %s, degree %d: %s data reproduced (max abs error, 200 random mu)", np, scattered ? "scattered" : "grid", deg, deg == 1 ? "affine" : "quadratic");
        Check(eexact <= 1e-10, what, eexact, 1e-10);
        std::snprintf(what, sizeof what, "%d parameters, %s, degree %d: weights sum to 1", np, scattered ? "scattered" : "grid", deg);
        Check(esum <= 1e-12, what, esum, 1e-12);
        std::snprintf(what, sizeof what, "%d parameters, %s, degree %d: smooth data, max error / the nearest point's", np, scattered ? "scattered" : "grid", deg);
        Check(efit <= 0.5 * enear, what, efit / enear, 0.5);
      }
      if (!scattered) { // on a grid the quadratic fit is the more accurate (scattered sets: either may win locally)
        char what[120];
        std::snprintf(what, sizeof what, "%d parameters, grid: smooth data, error of degree 2 / degree 1", np);
        Check(efitDeg[2] < efitDeg[1], what, efitDeg[2] / efitDeg[1], 1);
      }
    }
  }
  {
    // collinear training parameters in 2D: no affine fit, the nearest one
    std::vector<PetscReal> mus;
    for (int k = 0; k < 9; ++k) { mus.push_back(0.7 + 0.075 * k); mus.push_back(0.06 + 0.0075 * k); }
    for (int deg : {1, 2}) {
      const auto w = WarmStartWeights(mus, {0.6, 0.06}, {0.79, 0.09}, deg);
      Check(w.size() == 1 && w[0].first == 3 && w[0].second == 1, deg == 1 ? "collinear training parameters, degree 1: the nearest one (index 3)" : "collinear training parameters, degree 2: the nearest one (index 3)", w.empty() ? -1.0 : (double)w[0].first, 3);
    }
    Check(WarmStartWeights({}, {0.6, 0.06}, {0.79, 0.09}).empty(), "no training parameter: no weight", 0, 0);
  }
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_warm_start: %d failure(s)\n", failures));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
