// src/offline/contact_states.cpp: the offline hyper-reduction's contact states by their pointwise terms
// (include/rbcontact/contact_states.hpp).
#include "rbcontact/contact_states.hpp"
#include <numeric>

namespace rbc {

void ContactStates::Append(std::vector<PetscInt> *hit)
{
  const PetscInt         dim = patch_->dim, T = ContactPatch::MaxTerms;
  std::vector<PetscInt>  idx(Q_), nt(Q_), rows((size_t)Q_ * T);
  std::vector<PetscReal> coef((size_t)Q_ * T), g(Q_), wn((size_t)Q_ * dim);
  std::iota(idx.begin(), idx.end(), 0);
  hit->resize(Q_);
  (void)patch_->EvaluateCoefficients(idx.data(), Q_, nt.data(), rows.data(), coef.data(), g.data(), wn.data(), hit->data());
  base_.push_back(row_.size());
  uint32_t n = 0;
  for (PetscInt p = 0; p < Q_; ++p) {
    start_.push_back(n);
    row_.insert(row_.end(), &rows[(size_t)p * T], &rows[(size_t)p * T] + nt[p]);
    coef_.insert(coef_.end(), &coef[(size_t)p * T], &coef[(size_t)p * T] + nt[p]);
    n += (uint32_t)nt[p];
  }
  start_.push_back(n);
  if (base_.size() == 1 && expected_ > 1) { // the others like the first (a little more: the zone grows with the load)
    row_.reserve((size_t)(1.25 * n * expected_));
    coef_.reserve((size_t)(1.25 * n * expected_));
    start_.reserve((size_t)(Q_ + 1) * expected_);
    gamma_.reserve((size_t)Q_ * expected_);
    wn_.reserve((size_t)Q_ * patch_->dim * expected_);
  }
  gamma_.insert(gamma_.end(), g.begin(), g.end());
  wn_.insert(wn_.end(), wn.begin(), wn.end());
}

const PetscReal *ContactStates::Kappa(PetscInt s) const
{
  const PetscInt N = patch_->N;
  block_.resize((size_t)Q_ * N);
  const uint32_t *st = &start_[(size_t)s * (Q_ + 1)];
  const size_t    b  = base_[s];
  for (PetscInt p = 0; p < Q_; ++p) patch_->KappaRow((PetscInt)(st[p + 1] - st[p]), &row_[b + st[p]], &coef_[b + st[p]], &block_[(size_t)p * N]);
  return block_.data();
}

void ContactStates::KappaTimes(PetscInt s, const PetscReal *thetaV, PetscReal *y) const
{
  const uint32_t *st = &start_[(size_t)s * (Q_ + 1)];
  const size_t    b  = base_[s];
  for (PetscInt p = 0; p < Q_; ++p) {
    PetscReal t = 0;
    for (uint32_t k = st[p]; k < st[p + 1]; ++k) t += coef_[b + k] * thetaV[row_[b + k]];
    y[p] = t;
  }
}

size_t ContactStates::Bytes() const
{
  return base_.size() * sizeof(size_t) + start_.size() * sizeof(uint32_t) + row_.size() * sizeof(PetscInt) + (coef_.size() + gamma_.size() + wn_.size()) * sizeof(PetscReal);
}

} // namespace rbc
