// src/rom/warm_start.cpp: the weights of the online warm start (include/rbcontact/warm_start.hpp).
#include "rbcontact/warm_start.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace rbc {

std::vector<std::pair<size_t, PetscReal>> WarmStartWeights(const std::vector<PetscReal> &mus, const std::vector<PetscReal> &width, const std::vector<PetscReal> &mu)
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
  // the 2 np + 1 nearest (ties by index: deterministic), affine least squares through them: the fit's
  // value at mu is c' y with c = X z, G z = e_0, G = X'X, X = [1, scaled(k, :)] (the intercept is the value at mu)
  const size_t        k = std::min(nw, 2 * np + 1), m = np + 1;
  std::vector<size_t> order(nw);
  std::iota(order.begin(), order.end(), 0);
  std::partial_sort(order.begin(), order.begin() + k, order.end(), [&](size_t a, size_t b) { return d[a] < d[b] || (d[a] == d[b] && a < b); });
  std::vector<PetscReal> X(k * m), G(m * m, 0.0), z(m, 0.0);
  for (size_t j = 0; j < k; ++j) {
    X[j * m] = 1;
    for (size_t i = 0; i < np; ++i) X[j * m + i + 1] = scaled(order[j], i);
    for (size_t a = 0; a < m; ++a)
      for (size_t b = 0; b < m; ++b) G[a * m + b] += X[j * m + a] * X[j * m + b];
  }
  // Cholesky of the Gram matrix; a pivot^2 below 1e-10 of its largest diagonal entry: the points do not
  // determine an affine fit (collinear), use the nearest
  PetscReal gmax = 0;
  for (size_t a = 0; a < m; ++a) gmax = std::max(gmax, G[a * m + a]);
  PetscBLASInt n = (PetscBLASInt)m, one = 1, info = 0;
  LAPACKpotrf_("L", &n, G.data(), &n, &info);
  for (size_t a = 0; info == 0 && a < m; ++a)
    if (!(G[a * m + a] * G[a * m + a] > 1e-10 * gmax)) info = 1;
  if (info != 0) return {{nearest, 1.0}};
  z[0] = 1;
  LAPACKpotrs_("L", &n, &one, G.data(), &n, z.data(), &n, &info);
  if (info != 0) return {{nearest, 1.0}};
  std::vector<std::pair<size_t, PetscReal>> w;
  for (size_t j = 0; j < k; ++j) {
    PetscReal c = 0;
    for (size_t a = 0; a < m; ++a) c += X[j * m + a] * z[a];
    w.emplace_back(order[j], c);
  }
  return w;
}

} // namespace rbc
