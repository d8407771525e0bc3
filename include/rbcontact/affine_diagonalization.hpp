// rbcontact/affine_diagonalization.hpp: a reduced stiffness with at most two affine terms,
// A(mu) = theta_0(mu) A_0 + theta_1(mu) A_1 (one parametrized body beside a fixed one: a 3D dilation scales its body's
// stiffness; a Young's modulus parameter does the same), diagonalized once for every mu.
//
// With B = A(mu0) (symmetric positive definite) and C the term whose coefficient vector t1 is orthogonal to
// theta(mu0), the generalized symmetric eigenproblem C V = B V diag(lam), V' B V = I (LAPACK sygv) gives, for every mu,
//     V' A(mu) V = diag(d(mu)),   d_i(mu) = alpha(mu) + beta(mu) lam_i,
// alpha = <theta(mu), theta(mu0)> / |theta(mu0)|^2, beta = <theta(mu), t1>: theta(mu) = alpha theta(mu0) + beta t1 holds
// exactly with two coefficients. So A(mu)^{-1} = V diag(1/d(mu)) V', and in the coordinates z = diag(d)^{1/2} V^{-1} v
// the reduced stiffness is the identity: the online QP needs no factorization per parameter (docs/online.md,
// "A diagonalized once"). A(mu) is positive definite exactly when every d_i(mu) > 0.
#pragma once
#include <petscsys.h>
#include <vector>

namespace rbc {

class AffineDiagonalization {
public:
  // theta0 = theta(mu0) (QA = 1 or 2 entries), Aq: the QA terms (each N x N, column-major, contiguous).
  // *ok false (the object left empty) when QA is not 1 or 2, theta(mu0) is zero, or B = A(mu0) is not positive
  // definite (sygv's Cholesky fails). Errors only for LAPACK argument errors.
  PetscErrorCode Set(PetscInt N, const std::vector<PetscReal> &theta0, const PetscReal *Aq, bool *ok);
  bool           Empty() const { return n_ < 0; }
  PetscInt       N() const { return n_; }
  // d(mu) (N) from theta(mu) (QA entries)
  void Diagonal(const std::vector<PetscReal> &theta, PetscReal *d) const;
  // V (N x N, column-major): V' B V = I, V' C V = diag(lam)
  const std::vector<PetscReal> &V() const { return V_; }
  const std::vector<PetscReal> &Lambda() const { return lam_; }
  // V^{-1} = V' B (N x N, column-major): reduced coordinates v to V's, w = V^{-1} v
  const std::vector<PetscReal> &VInverse() const { return Vinv_; }

private:
  PetscInt               n_ = -1;
  std::vector<PetscReal> t0_, t1_; // theta(mu0) / |theta(mu0)|^2 and the unit vector orthogonal to it (QA = 2; else empty)
  std::vector<PetscReal> V_, lam_, Vinv_;
};

} // namespace rbc
