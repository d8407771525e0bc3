// src/rom/anderson.cpp: Anderson mixing of a small fixed-point iteration (include/rbcontact/anderson.hpp).
#include "rbcontact/anderson.hpp"
#include <cmath>

namespace rbc {

void AndersonMixing::Setup(PetscInt n, PetscInt m)
{
  n_ = n;
  m_ = m;
  f_.assign(n, 0.0);
  fPrev_.assign(n, 0.0);
  gPrev_.assign(n, 0.0);
  dF_.assign((size_t)n * m, 0.0);
  dG_.assign((size_t)n * m, 0.0);
  q_.assign((size_t)n * m, 0.0);
  r_.assign((size_t)m * m, 0.0);
  gamma_.assign(m, 0.0);
  keep_.reserve(m);
  Reset();
}

PetscInt AndersonMixing::Mix(const PetscReal *x, const PetscReal *g, PetscReal *out)
{
  PetscReal fn = 0;
  for (PetscInt i = 0; i < n_; ++i) {
    f_[i] = g[i] - x[i];
    fn += f_[i] * f_[i];
  }
  fn = std::sqrt(fn);
  if (have_ && fn > fnPrev_) cols_ = 0; // the residual grew: restart from the plain step
  else if (have_) {
    if (cols_ == m_) { // drop the oldest column
      for (PetscInt j = 1; j < m_; ++j)
        for (PetscInt i = 0; i < n_; ++i) {
          dF_[(size_t)(j - 1) * n_ + i] = dF_[(size_t)j * n_ + i];
          dG_[(size_t)(j - 1) * n_ + i] = dG_[(size_t)j * n_ + i];
        }
      --cols_;
    }
    for (PetscInt i = 0; i < n_; ++i) {
      dF_[(size_t)cols_ * n_ + i] = f_[i] - fPrev_[i];
      dG_[(size_t)cols_ * n_ + i] = g[i] - gPrev_[i];
    }
    ++cols_;
  }
  for (PetscInt i = 0; i < n_; ++i) {
    fPrev_[i] = f_[i];
    gPrev_[i] = g[i];
    out[i]    = g[i];
  }
  fnPrev_ = fn;
  have_   = true;
  // least squares min ||f - dF gamma|| by modified Gram-Schmidt; a column (numerically) in the span
  // of the previous ones is skipped (gamma_j = 0)
  PetscInt   used = 0;
  std::vector<char> &keep = keep_;
  keep.assign(cols_, 0);
  for (PetscInt j = 0; j < cols_; ++j) {
    PetscReal *q = &q_[(size_t)j * n_], n0 = 0, nn = 0;
    for (PetscInt i = 0; i < n_; ++i) {
      q[i] = dF_[(size_t)j * n_ + i];
      n0 += q[i] * q[i];
    }
    for (PetscInt k = 0; k < j; ++k) {
      r_[k + (size_t)m_ * j] = 0;
      if (!keep[k]) continue;
      const PetscReal *qk = &q_[(size_t)k * n_];
      PetscReal        s  = 0;
      for (PetscInt i = 0; i < n_; ++i) s += qk[i] * q[i];
      r_[k + (size_t)m_ * j] = s;
      for (PetscInt i = 0; i < n_; ++i) q[i] -= s * qk[i];
    }
    for (PetscInt i = 0; i < n_; ++i) nn += q[i] * q[i];
    nn = std::sqrt(nn);
    if (!(nn > 1e-10 * std::sqrt(n0)) || nn == 0) continue;
    for (PetscInt i = 0; i < n_; ++i) q[i] /= nn;
    r_[j + (size_t)m_ * j] = nn;
    keep[j]                = 1;
    ++used;
  }
  if (!used) return 0;
  // gamma = R^{-1} Q' f over the kept columns
  for (PetscInt j = cols_ - 1; j >= 0; --j) {
    gamma_[j] = 0;
    if (!keep[j]) continue;
    const PetscReal *q = &q_[(size_t)j * n_];
    PetscReal        s = 0;
    for (PetscInt i = 0; i < n_; ++i) s += q[i] * f_[i];
    for (PetscInt k = j + 1; k < cols_; ++k)
      if (keep[k]) s -= r_[j + (size_t)m_ * k] * gamma_[k];
    gamma_[j] = s / r_[j + (size_t)m_ * j];
  }
  for (PetscInt j = 0; j < cols_; ++j)
    if (keep[j])
      for (PetscInt i = 0; i < n_; ++i) out[i] -= gamma_[j] * dG_[(size_t)j * n_ + i];
  return used;
}

} // namespace rbc
