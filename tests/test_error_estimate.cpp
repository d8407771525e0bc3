// tests/test_error_estimate.cpp: the calibration of the online error estimate (CalibrateEstimate,
// error_estimate.hpp) on synthetic data: a raw estimate proportional to the error gives that factor and no floor;
// a raw estimate with no information gives the floor max(err); every calibration point covered (effectivity >= 1);
// the fit is the best scale against a brute-force search; points without an error skipped; no data: scale 1, floor 0.
#include <petscsys.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include "rbcontact/error_estimate.hpp"

using rbc::CalibrateEstimate;

static int failures = 0;

static void Check(bool ok, const char *what, double value, double bound)
{
  if (!ok) ++failures;
  std::printf("  %-6s %-84s %10.3e (bound %.1e)\n", ok ? "ok" : "FAILED", what, value, bound);
}

// the 90 % quantile of the effectivities of (a, b) (the fit's objective)
static double Quantile90(const std::vector<double> &raw, const std::vector<double> &err, double a, double b)
{
  std::vector<double> eff;
  for (size_t k = 0; k < err.size(); ++k)
    if (err[k] > 0) eff.push_back((a * raw[k] + b) / err[k]);
  std::sort(eff.begin(), eff.end());
  return eff[std::min(eff.size() - 1, (size_t)std::ceil(0.9 * eff.size()) - 1)];
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  std::mt19937_64                        gen(3);
  std::uniform_real_distribution<double> U(0, 1);
  {
    std::vector<double> err(20), raw(20);
    for (int k = 0; k < 20; ++k) {
      err[k] = std::pow(10.0, -6 + 3 * U(gen));
      raw[k] = err[k] / 3.7;
    }
    const auto c = CalibrateEstimate(raw, err);
    Check(std::abs(c.scale - 3.7) <= 1e-9 * 3.7, "raw = err / 3.7: scale 3.7", std::abs(c.scale - 3.7), 1e-9 * 3.7);
    Check(c.floor <= 1e-15, "raw = err / 3.7: no floor", c.floor, 1e-15);
    Check(std::abs(c.minEffectivity - 1) <= 1e-9 && std::abs(c.maxEffectivity - 1) <= 1e-9, "raw = err / 3.7: effectivity 1 at every point", std::max(std::abs(c.minEffectivity - 1), std::abs(c.maxEffectivity - 1)), 1e-9);
  }
  {
    std::vector<double> err(30), raw(30);
    for (int k = 0; k < 30; ++k) {
      err[k] = 1e-4 * (1 + U(gen));
      raw[k] = 1e-9 * U(gen); // no information: the floor carries the estimate
    }
    const auto c = CalibrateEstimate(raw, err);
    const double emax = *std::max_element(err.begin(), err.end());
    Check(c.floor <= emax && c.floor >= emax - c.scale * 1e-9, "uninformative raw: the floor is max err", std::abs(c.floor - emax) / emax, c.scale * 1e-9 / emax);
    Check(c.minEffectivity >= 1 - 1e-12, "uninformative raw: every point covered", c.minEffectivity, 1);
  }
  {
    // a noisy proportional estimate: every point covered, and no scale of a fine brute-force search does better
    std::vector<double> err(25), raw(25);
    for (int k = 0; k < 25; ++k) {
      err[k] = std::pow(10.0, -5 + 2 * U(gen));
      raw[k] = err[k] * std::exp(1.5 * (U(gen) - 0.5));
    }
    const auto c = CalibrateEstimate(raw, err);
    double     cover = 1e300;
    for (int k = 0; k < 25; ++k) cover = std::min(cover, (c.scale * raw[k] + c.floor) / err[k]);
    Check(cover >= 1 - 1e-12, "noisy raw: every calibration point covered", cover, 1);
    double best = 1e300;
    for (int i = 0; i <= 20000; ++i) {
      const double a = 1e-2 * std::pow(1e6, i / 20000.0);
      double       b = 0;
      for (int k = 0; k < 25; ++k) b = std::max(b, err[k] - a * raw[k]);
      best = std::min(best, Quantile90(raw, err, a, b));
    }
    const double q = Quantile90(raw, err, c.scale, c.floor);
    Check(q <= best * (1 + 1e-3), "noisy raw: 90 % quantile of the effectivities no worse than a brute-force search", q / best - 1, 1e-3);
  }
  {
    const auto c = CalibrateEstimate({1e-3, 2e-3, 5e-4}, {0, -1, 0});
    Check(c.points == 0 && c.scale == 1 && c.floor == 0, "no point with an error: scale 1, floor 0", (double)c.points, 0);
    const auto d = CalibrateEstimate({1e-3, 1e-3}, {0, 2e-3});
    Check(d.points == 1 && std::abs(d.scale * 1e-3 + d.floor - 2e-3) <= 1e-15, "a zero error is skipped, the other point fitted exactly", std::abs(d.scale * 1e-3 + d.floor - 2e-3), 1e-15);
  }
  std::printf("%s\n", failures ? "FAILED" : "all checks passed");
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
