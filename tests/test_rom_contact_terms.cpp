// tests/test_rom_contact_terms.cpp: the reduced model's public ContactTerms in the cubature mode where A^ is
// diagonalized once (-rom_diagonalize_a, docs/online.md "A diagonalized once") and the points' sum runs in single
// precision: its float rows hold theta(:, cols) V, the nodal displacement comes from V^{-1} v, and the public call
// returns K^ = (K^ V) V^{-1}. Against the same model without the diagonalization (rows theta(:, cols)), at the reduced
// solution of each -mu: K^ and g^ to the float sums' noise (1e-5 of their largest entry; a wrong transform moves them
// by O(1)). Run by tests/rom_checks.py `sphere_block3d` on its ROM: test_rom_contact_terms -rom rom.h5 -mu a,b.
#include <slepcsys.h>
#include <algorithm>
#include <cmath>
#include <vector>
#include "rbcontact/reduced_model.hpp"
#include "test_check.hpp"

using rbctest::Check;

int main(int argc, char **argv)
{
  char      rom[PETSC_MAX_PATH_LEN] = "";
  PetscBool set                     = PETSC_FALSE;
  PetscReal muv[8];
  PetscInt  nmu = 8;

  PetscCall(SlepcInitialize(&argc, &argv, NULL, NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-rom", rom, sizeof rom, &set));
  PetscCheck(set, PETSC_COMM_WORLD, PETSC_ERR_USER_INPUT, "-rom <file> is required");
  PetscCall(PetscOptionsGetRealArray(NULL, NULL, "-mu", muv, &nmu, &set));
  PetscCheck(set && nmu > 0, PETSC_COMM_WORLD, PETSC_ERR_USER_INPUT, "-mu a,b is required");
  const std::vector<PetscReal> mu(muv, muv + nmu);
  PetscCall(PetscOptionsSetValue(NULL, "-rom_ecsw_sum", "points"));
  PetscCall(PetscOptionsSetValue(NULL, "-rom_ecsw_precision", "single"));
  std::vector<PetscReal> K[2], g[2], v;
  bool                   diag[2] = {false, false};
  for (int k = 0; k < 2; ++k) { // k = 0: diagonalized, 1: not
    rbc::ReducedModel m;
    PetscCall(PetscOptionsSetValue(NULL, "-rom_diagonalize_a", k == 0 ? "true" : "false"));
    PetscCall(m.Open(rom));
    PetscCall(m.SetFromOptions());
    PetscCheck(!m.EcswSumsByDofs() && m.EcswSingle(), PETSC_COMM_WORLD, PETSC_ERR_PLIB, "the points' sum in single precision was asked for");
    diag[k] = m.ADiagonalized();
    if (k == 0) { // the reduced solution at mu, where both evaluate
      rbc::ReducedSolution sol;
      PetscCall(m.Solve(mu, &sol));
      PetscCheck(sol.converged, PETSC_COMM_WORLD, PETSC_ERR_NOT_CONVERGED, "reduced solve: %s", sol.message.c_str());
      v = sol.v;
    }
    K[k].resize((size_t)m.R() * m.N());
    g[k].resize(m.R());
    (void)m.ContactTerms(mu, v.data(), K[k].data(), g[k].data());
  }
  auto relmax = [](const std::vector<PetscReal> &a, const std::vector<PetscReal> &b) {
    PetscReal d = 0, n = 0;
    for (size_t i = 0; i < a.size(); ++i) { d = std::max(d, std::abs(a[i] - b[i])); n = std::max(n, std::abs(b[i])); }
    return n > 0 ? d / n : d;
  };
  PetscCall(Check(PETSC_COMM_WORLD, diag[0] && !diag[1], "-rom_diagonalize_a true / false in effect as asked (rom.a_diagonalized)", (double)(diag[0] + 2 * diag[1]), 1));
  const double dk = relmax(K[0], K[1]), dg = relmax(g[0], g[1]);
  PetscCall(Check(PETSC_COMM_WORLD, K[0].size() == K[1].size() && dk <= 1e-5, "public ContactTerms: K^ from the V-transformed float rows vs theta's (max, relative)", dk, 1e-5));
  PetscCall(Check(PETSC_COMM_WORLD, dg <= 1e-5, "public ContactTerms: g^ (nodal displacement from V^{-1} v) vs theta v (max, relative)", dg, 1e-5));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s: %d failure(s)\n", rbctest::failures ? "FAILED" : "PASSED", rbctest::failures));
  PetscCall(SlepcFinalize());
  return rbctest::failures ? 1 : 0;
}
