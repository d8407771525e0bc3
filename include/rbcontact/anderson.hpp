// rbcontact/anderson.hpp: Anderson mixing (Walker & Ni 2011, "type II", mixing parameter 1) for a
// small dense fixed-point iteration x = G(x): the reduced Kacanov loop (-rom_kacanov_anderson m).
// Given x_k and g_k = G(x_k), the next input is g_k - dG gamma with gamma the least-squares
// minimizer of ||f_k - dF gamma|| over the last m differences of f = g - x and of g. Safeguard: the
// history restarts when ||f|| grows. Serial, no PETSc objects.
#pragma once
#include <petscsys.h>
#include <vector>

namespace rbc {

class AndersonMixing {
public:
  // n unknowns, depth m >= 1 (history columns). Clears the history.
  void Setup(PetscInt n, PetscInt m);
  void Reset() { cols_ = 0, have_ = false; }
  // out = next input from x and g = G(x) (out may alias neither). Returns the history columns used.
  PetscInt Mix(const PetscReal *x, const PetscReal *g, PetscReal *out);

private:
  PetscInt               n_ = 0, m_ = 0, cols_ = 0;
  bool                   have_ = false;
  PetscReal              fnPrev_ = 0;
  std::vector<PetscReal> f_, fPrev_, gPrev_, dF_, dG_, q_, r_, gamma_; // dF_, dG_: n x m, newest column last
  std::vector<char>      keep_; // history column used in the least-squares fit
};

} // namespace rbc
