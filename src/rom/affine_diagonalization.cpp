// src/rom/affine_diagonalization.cpp: the simultaneous diagonalization of a two-term reduced stiffness
// (include/rbcontact/affine_diagonalization.hpp).
#include "rbcontact/affine_diagonalization.hpp"
#include <petscblaslapack.h>
#include <cmath>

namespace rbc {

PetscErrorCode AffineDiagonalization::Set(PetscInt N, const std::vector<PetscReal> &theta0, const PetscReal *Aq, bool *ok)
{
  const size_t qa = theta0.size(), nn = (size_t)N * N;

  PetscFunctionBeginUser;
  *ok = false;
  n_  = -1;
  t0_.clear();
  t1_.clear();
  V_.clear();
  lam_.clear();
  Vinv_.clear();
  if (N < 1 || qa < 1 || qa > 2) PetscFunctionReturn(0);
  PetscReal n2 = 0;
  for (PetscReal t : theta0) n2 += t * t;
  if (!(n2 > 0) || !std::isfinite(n2)) PetscFunctionReturn(0);
  std::vector<PetscReal> t0(qa), t1(qa, 0.0);
  for (size_t q = 0; q < qa; ++q) t0[q] = theta0[q] / n2;
  if (qa == 2) { // the unit vector orthogonal to theta(mu0)
    const PetscReal nrm = std::sqrt(n2);
    t1[0]               = -theta0[1] / nrm;
    t1[1]               = theta0[0] / nrm;
  }
  // B = A(mu0), C = sum_q t1_q A_q (zero with one term: lam = 0, V = L^{-T})
  std::vector<PetscReal> Bm(nn, 0.0), Cm(nn, 0.0), w(N);
  for (size_t q = 0; q < qa; ++q)
    for (size_t e = 0; e < nn; ++e) {
      Bm[e] += theta0[q] * Aq[q * nn + e];
      Cm[e] += t1[q] * Aq[q * nn + e];
    }
  for (PetscReal x : Bm)
    if (!std::isfinite(x)) PetscFunctionReturn(0);
  const std::vector<PetscReal> B0 = Bm; // (sygv overwrites Bm with its Cholesky factor)
  // sygv: C x = lam B x, eigenvectors in Cm normalized x' B x = 1 (workspace query first)
  PetscBLASInt itype = 1, n = (PetscBLASInt)N, lwork = -1, info = 0;
  PetscReal    wq    = 0;
  LAPACKsygv_(&itype, "V", "L", &n, Cm.data(), &n, Bm.data(), &n, w.data(), &wq, &lwork, &info);
  PetscCheck(info == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "LAPACK sygv workspace query failed (info %d)", (int)info);
  lwork = (PetscBLASInt)wq;
  std::vector<PetscReal> work(std::max<PetscBLASInt>(lwork, 1));
  LAPACKsygv_(&itype, "V", "L", &n, Cm.data(), &n, Bm.data(), &n, w.data(), work.data(), &lwork, &info);
  PetscCheck(info >= 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "LAPACK sygv: argument %d invalid", (int)-info);
  if (info > 0) PetscFunctionReturn(0); // B not positive definite (info > N) or no convergence (info <= N)
  const PetscScalar a1 = 1, b0 = 0;
  Vinv_.resize(nn);
  BLASgemm_("T", "N", &n, &n, &n, &a1, Cm.data(), &n, B0.data(), &n, &b0, Vinv_.data(), &n); // V' B
  n_   = N;
  t0_  = t0;
  t1_  = qa == 2 ? t1 : std::vector<PetscReal>();
  V_   = std::move(Cm);
  lam_ = std::move(w);
  *ok  = true;
  PetscFunctionReturn(0);
}

void AffineDiagonalization::Diagonal(const std::vector<PetscReal> &theta, PetscReal *d) const
{
  PetscReal alpha = 0, beta = 0;
  for (size_t q = 0; q < t0_.size(); ++q) alpha += theta[q] * t0_[q];
  for (size_t q = 0; q < t1_.size(); ++q) beta += theta[q] * t1_[q];
  for (PetscInt i = 0; i < n_; ++i) d[i] = alpha + beta * lam_[i];
}

} // namespace rbc
