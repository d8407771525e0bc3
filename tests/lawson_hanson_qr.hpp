// tests/lawson_hanson_qr.hpp: a test-only reference NNLS, independent of src/reduction/nnls.cpp:
// Lawson and Hanson's active-set algorithm (Solving Least Squares Problems, 1974, ch. 23) whose
// least-squares subproblems are solved by this file's own Householder QR of the passive columns of Q
// (no LAPACK, no normal equations H = Q^T Q, no TAO). Exact up to rounding even for nearly collinear
// columns. Header-only, plain C++.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

namespace lhref {

// min ||A z - b|| with A (m x p, column-major, p <= m) by Householder QR; false if rank deficient.
inline bool HouseholderLeastSquares(std::vector<double> A, int m, int p, std::vector<double> b, std::vector<double> *z)
{
  if (p > m) return false;
  double scale = 0;
  for (double v : A) scale = std::max(scale, std::abs(v));
  std::vector<double> diag(p);
  for (int k = 0; k < p; ++k) {
    double *col = &A[(size_t)k * m];
    double  nrm = 0;
    for (int i = k; i < m; ++i) nrm += col[i] * col[i];
    nrm = std::sqrt(nrm);
    if (nrm == 0) return false;
    const double alpha = col[k] > 0 ? -nrm : nrm; // H col = alpha e_k
    // v = col[k:m] - alpha e_k, H = I - 2 v v^T / v^T v
    std::vector<double> v(col + k, col + m);
    v[0] -= alpha;
    double vv = 0;
    for (double x : v) vv += x * x;
    diag[k] = alpha;
    if (vv > 0) {
      for (int j = k + 1; j < p; ++j) {
        double *cj = &A[(size_t)j * m], s = 0;
        for (int i = k; i < m; ++i) s += v[i - k] * cj[i];
        s *= 2 / vv;
        for (int i = k; i < m; ++i) cj[i] -= s * v[i - k];
      }
      double s = 0;
      for (int i = k; i < m; ++i) s += v[i - k] * b[i];
      s *= 2 / vv;
      for (int i = k; i < m; ++i) b[i] -= s * v[i - k];
    }
  }
  double dmax = 0;
  for (double d : diag) dmax = std::max(dmax, std::abs(d));
  for (double d : diag)
    if (!(std::abs(d) > 1e-12 * std::max(dmax, scale))) return false;
  z->assign(p, 0.0);
  for (int k = p - 1; k >= 0; --k) { // R z = (Q^T b)[0:p]; R's off-diagonal part is A[k, j>k]
    double s = b[k];
    for (int j = k + 1; j < p; ++j) s -= A[k + (size_t)j * m] * (*z)[j];
    (*z)[k] = s / diag[k];
  }
  return true;
}

// min ||Q x - b||, x >= 0 (Q m x n column-major). Returns the number of outer iterations.
inline int NNLS(const std::vector<double> &Q, int m, int n, const std::vector<double> &b, std::vector<double> *x)
{
  std::vector<char>   passive(n, 0), rejected(n, 0);
  std::vector<double> r(m), z;
  x->assign(n, 0.0);
  double qmax = 0, bn = 0;
  for (double v : Q) qmax = std::max(qmax, std::abs(v));
  for (double v : b) bn += v * v;
  bn = std::sqrt(bn);
  if (qmax == 0 || bn == 0) return 0;
  auto solveP = [&](std::vector<int> *P) {
    P->clear();
    for (int j = 0; j < n; ++j) if (passive[j]) P->push_back(j);
    std::vector<double> A((size_t)m * P->size());
    for (size_t k = 0; k < P->size(); ++k) std::copy(&Q[(size_t)(*P)[k] * m], &Q[(size_t)(*P)[k] * m] + m, &A[k * m]);
    return HouseholderLeastSquares(A, m, (int)P->size(), b, &z);
  };
  int it = 0;
  for (; it < 3 * n + 30; ++it) {
    r = b;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < m; ++i) r[i] -= Q[i + (size_t)j * m] * (*x)[j];
    int    jmax = -1;
    double wmax = 1e-15 * m * qmax * bn; // entering test above rounding level
    for (int j = 0; j < n; ++j) {
      if (passive[j] || rejected[j]) continue;
      double w = 0;
      for (int i = 0; i < m; ++i) w += Q[i + (size_t)j * m] * r[i];
      if (w > wmax) { wmax = w; jmax = j; }
    }
    if (jmax < 0) break;
    passive[jmax] = 1;
    std::vector<int> P;
    bool             ok = solveP(&P);
    const size_t     kj = std::find(P.begin(), P.end(), jmax) - P.begin();
    if (!ok || z[kj] <= 0) { passive[jmax] = 0; rejected[jmax] = 1; continue; }
    std::fill(rejected.begin(), rejected.end(), 0);
    bool solved = true;
    while (true) {
      bool pos = true;
      for (double v : z) if (v <= 0) pos = false;
      if (pos) break;
      double alpha = 2;
      size_t kb    = 0;
      for (size_t k = 0; k < P.size(); ++k)
        if (z[k] <= 0) {
          const double a = (*x)[P[k]] / ((*x)[P[k]] - z[k]);
          if (a < alpha) { alpha = a; kb = k; }
        }
      for (size_t k = 0; k < P.size(); ++k) {
        (*x)[P[k]] += alpha * (z[k] - (*x)[P[k]]);
        if (k == kb || (*x)[P[k]] <= 0) { (*x)[P[k]] = 0; passive[P[k]] = 0; }
      }
      if (!solveP(&P)) { solved = false; break; }
    }
    if (solved)
      for (size_t k = 0; k < P.size(); ++k) (*x)[P[k]] = z[k];
  }
  for (int j = 0; j < n; ++j) if (!passive[j]) (*x)[j] = 0;
  return it;
}

} // namespace lhref
