// src/rom/warm_start.cpp: the weights of the online warm start (include/rbcontact/warm_start.hpp).
#include "rbcontact/warm_start.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace rbc {

namespace {

// Least-squares fit by the m monomials of degree <= deg in the scaled offsets (1, x_i, and x_i x_j for
// i <= j) over the k nearest training parameters (order: sorted by distance, ties by index). The fit's value at mu
// is its intercept c' y with c = X z, G z = e_0, G = X'X. Empty when the points do not determine the fit
// (a pivot^2 of the Cholesky factor of G below 1e-10 of G's largest diagonal entry).
template <class Scaled>
std::vector<std::pair<size_t, PetscReal>> FitOver(const std::vector<size_t> &order, size_t np, Scaled scaled, int deg, size_t k)
{
  const size_t m = deg >= 2 ? (np + 1) * (np + 2) / 2 : np + 1;
  if (k < m || k > order.size()) return {};
  std::vector<PetscReal> X(k * m), G(m * m, 0.0), z(m, 0.0);
  for (size_t j = 0; j < k; ++j) {
    PetscReal *x = &X[j * m];
    size_t     c = 0;
    x[c++]       = 1;
    for (size_t i = 0; i < np; ++i) x[c++] = scaled(order[j], i);
    if (deg >= 2)
      for (size_t i = 0; i < np; ++i)
        for (size_t l = i; l < np; ++l) x[c++] = scaled(order[j], i) * scaled(order[j], l);
    for (size_t a = 0; a < m; ++a)
      for (size_t b = 0; b < m; ++b) G[a * m + b] += x[a] * x[b];
  }
  PetscReal gmax = 0;
  for (size_t a = 0; a < m; ++a) gmax = std::max(gmax, G[a * m + a]);
  PetscBLASInt n = (PetscBLASInt)m, one = 1, info = 0;
  LAPACKpotrf_("L", &n, G.data(), &n, &info);
  for (size_t a = 0; info == 0 && a < m; ++a)
    if (!(G[a * m + a] * G[a * m + a] > 1e-10 * gmax)) info = 1;
  if (info != 0) return {};
  z[0] = 1;
  LAPACKpotrs_("L", &n, &one, G.data(), &n, z.data(), &n, &info);
  if (info != 0) return {};
  std::vector<std::pair<size_t, PetscReal>> w;
  for (size_t j = 0; j < k; ++j) {
    PetscReal c = 0;
    for (size_t a = 0; a < m; ++a) c += X[j * m + a] * z[a];
    w.emplace_back(order[j], c);
  }
  return w;
}

// The fit over the 2 m - 1 nearest (2 np + 1 for the affine fit); a quadratic one, when those do not
// determine it (nearest points on too few grid lines), over 3 m and then 5 m nearest.
template <class Scaled>
std::vector<std::pair<size_t, PetscReal>> PolynomialFit(const std::vector<size_t> &order, size_t np, Scaled scaled, int deg)
{
  const size_t nw = order.size(), m = deg >= 2 ? (np + 1) * (np + 2) / 2 : np + 1;
  for (size_t k : {2 * m - 1, 3 * m, 5 * m}) {
    auto w = FitOver(order, np, scaled, deg, std::min(k, nw));
    if (!w.empty() || deg < 2 || k >= nw) return w;
  }
  return {};
}

} // namespace

std::vector<std::pair<size_t, PetscReal>> WarmStartWeights(const std::vector<PetscReal> &mus, const std::vector<PetscReal> &width, const std::vector<PetscReal> &mu, int degree)
{
  const size_t np = mu.size(), nw = np ? mus.size() / np : 0;
  if (nw == 0) return {};
  auto scaled = [&](size_t k, size_t i) { return (mus[k * np + i] - mu[i]) / std::max<PetscReal>(width[i], 1e-300); };
  std::vector<PetscReal> d(nw, 0.0);
  for (size_t k = 0; k < nw; ++k)
    for (size_t i = 0; i < np; ++i) d[k] += scaled(k, i) * scaled(k, i);
  const size_t nearest = (size_t)(std::min_element(d.begin(), d.end()) - d.begin());
  if (np == 1) {
    size_t lo = nw, hi = nw;
    for (size_t k = 0; k < nw; ++k) {
      if (mus[k] <= mu[0] && (lo == nw || mus[k] > mus[lo])) lo = k;
      if (mus[k] >= mu[0] && (hi == nw || mus[k] < mus[hi])) hi = k;
    }
    if (lo == nw || hi == nw || !(mus[hi] > mus[lo])) return {{nearest, 1.0}};
    const PetscReal t = (mu[0] - mus[lo]) / (mus[hi] - mus[lo]);
    return {{lo, 1 - t}, {hi, t}};
  }
  // a quadratic, else an affine least-squares fit over the nearest training parameters, evaluated at mu;
  // the nearest sorted once (at most 5 m of the quadratic fit are used)
  const size_t        ks = std::min(nw, 5 * ((np + 1) * (np + 2) / 2));
  std::vector<size_t> order(nw);
  std::iota(order.begin(), order.end(), 0);
  std::partial_sort(order.begin(), order.begin() + ks, order.end(), [&](size_t a, size_t b) { return d[a] < d[b] || (d[a] == d[b] && a < b); });
  order.resize(ks);
  if (degree >= 2) {
    auto w = PolynomialFit(order, np, scaled, 2);
    if (!w.empty()) return w;
  }
  auto w = PolynomialFit(order, np, scaled, 1);
  if (!w.empty()) return w;
  return {{nearest, 1.0}};
}

} // namespace rbc
