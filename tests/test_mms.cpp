// tests/test_mms.cpp -- owns the manufactured-solution convergence test of the elastic FOM
// (rbc::ElasticFOM, rbc::Elasticity): 2D plane strain on meshes/unit_square.geo and 3D on
// meshes/block3d.geo, Lagrange P1 and P2, Dirichlet data = the exact solution on the whole
// boundary, body force derived by hand from the exact solution (SceneSpec::bodyForceF0).
// For each case the L2 error (DMComputeL2Diff) is measured on 3 gmsh refinements and the
// observed rate over the last two refinements must reach P1 >= 1.8, P2 >= 2.7, with the mesh
// size measured from the global vertex count N as h ~ N^(-1/dim). Prints a table; exits 1 on
// failure. Options: -mms_cases 2p1,2p2,3p1,3p2 (subset to run), -mms_clscale3d a,b,c.
#include "rbcontact/fom.hpp"
#include "rbcontact/mesh.hpp"

#include <petscsf.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using rbc::GlobalPointCount;

// ---------------------------------------------------------------------------------------------
// Exact solution: a product of shifted sines per component (smooth, not a polynomial, so P2 is
// not exact; non-zero on the boundary, so the Dirichlet data are non-homogeneous):
//
//     u_c(x) = A_c * prod_{d < dim} s_cd(x_d),     s_cd(t) = sin(k_cd t + th_cd)
//
// Derivatives:  s'_cd = k_cd cos(k_cd t + th_cd),  s''_cd = -k_cd^2 s_cd,
//     d_i d_i u_c = A_c s''_ci prod_{d != i} s_cd,
//     d_i d_j u_c = A_c s'_ci s'_cj prod_{d != i, j} s_cd            (i != j).
//
// Hooke's law (plane strain in 2D): sigma = L tr(eps) I + 2 G eps, eps = (grad u + grad u^T)/2,
// so with constant L, G:
//     (div sigma)_c = sum_d d_d sigma_cd = G sum_d d_d d_d u_c + (L + G) sum_d d_c d_d u_d.
// Strong form -div sigma = b. The PetscDS residual is  int f0 . v + f1 : grad v  with
// f1 = sigma (f1_stress in src/fem/elasticity.cpp), hence  f0 = -b = div sigma(u_exact):
//
//     f0_c = G * sum_d H[c][d][d] + (L + G) * sum_d H[d][c][d],     H[c][i][j] = d_i d_j u_c.
//
// E.g. in 2D, c = 0:  f0_0 = G (u_0,xx + u_0,yy) + (L + G) (u_0,xx + u_1,xy).
// ---------------------------------------------------------------------------------------------
struct Manufactured {
  PetscInt  dim = 2;
  PetscReal L = 0, G = 0; // Lamé coefficients of the solve (set per case)
  PetscReal A[3]     = {1.0, 0.8, 0.6};
  PetscReal k[3][3]  = {{1.3, 2.1, 1.2}, {2.2, 1.1, 0.9}, {1.4, 0.7, 1.6}};
  PetscReal th[3][3] = {{0.4, 0.7, 0.1}, {1.0, 0.2, 0.5}, {0.3, 0.9, 1.2}};
};
Manufactured g_mms; // the pointwise functions have no context argument (f0) -> file-static state

PetscReal S(PetscInt c, PetscInt d, PetscReal t, PetscInt der)
{
  const PetscReal kk = g_mms.k[c][d], a = kk * t + g_mms.th[c][d];
  switch (der) {
  case 0: return std::sin(a);
  case 1: return kk * std::cos(a);
  default: return -kk * kk * std::sin(a);
  }
}

// d_i d_j u_c at x
PetscReal Hess(PetscInt c, PetscInt i, PetscInt j, const PetscReal x[])
{
  PetscReal v = g_mms.A[c];
  for (PetscInt d = 0; d < g_mms.dim; ++d) {
    const PetscInt der = (d == i) + (d == j);
    v *= S(c, d, x[d], der);
  }
  return v;
}

PetscErrorCode ExactU(PetscInt dim, PetscReal t, const PetscReal x[], PetscInt Nc, PetscScalar *u, void *ctx)
{
  for (PetscInt c = 0; c < Nc; ++c) {
    PetscReal v = g_mms.A[c];
    for (PetscInt d = 0; d < dim; ++d) v *= S(c, d, x[d], 0);
    u[c] = v;
  }
  return 0;
}

void f0_mms(PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, const PetscReal x[], PetscInt numConstants, const PetscScalar constants[], PetscScalar f0[])
{
  const PetscReal L = g_mms.L, G = g_mms.G;
  for (PetscInt c = 0; c < dim; ++c) {
    PetscReal lap = 0, graddiv = 0;
    for (PetscInt d = 0; d < dim; ++d) {
      lap += Hess(c, d, d, x);
      graddiv += Hess(d, c, d, x);
    }
    f0[c] = G * lap + (L + G) * graddiv;
  }
}

// Global number of points of a depth stratum (0: vertices) or height stratum (cells) of a possibly
// distributed DMPlex: local points minus the ghosts (leaves of the point SF).
struct Case {
  std::string              id, mesh;
  PetscInt                 dim, degree;
  PetscReal                E, nu, minRate;
  std::vector<PetscReal>   clscales;
  std::vector<std::string> boundary; // Dirichlet labels covering the whole boundary
};

PetscErrorCode RunCase(MPI_Comm comm, const Case &cs, bool *ok)
{
  std::vector<PetscReal> errs, hs, hcs;
  std::vector<PetscInt>  nverts, ncells, ndofs;

  PetscFunctionBeginUser;
  g_mms.dim = cs.dim;
  // Lamé coefficients computed here (independently of rbc::LameFromYoung).
  g_mms.L = cs.E * cs.nu / ((1 + cs.nu) * (1 - 2 * cs.nu));
  g_mms.G = cs.E / (2 * (1 + cs.nu));
  for (PetscReal cl : cs.clscales) {
    rbc::SceneSpec sc;
    sc.name         = "mms_" + cs.id;
    sc.mesh.file    = cs.mesh;
    sc.mesh.clscale = cl;
    const char *cache = std::getenv("RBC_MESH_CACHE");
    sc.mesh.cacheDir  = cache ? cache : "meshcache";
    sc.bodies.push_back({"all", cs.E, cs.nu});
    for (const auto &b : cs.boundary) {
      rbc::DirichletSpec bc;
      bc.label = b;
      bc.fn    = ExactU;
      sc.dirichlet.push_back(bc);
    }
    sc.bodyForceF0 = f0_mms;
    sc.degree      = cs.degree;

    rbc::ElasticFOM fom;
    PetscCall(fom.Create(comm, sc));
    PetscCall(fom.AssembleAndFactor());
    PetscCall(fom.SolveElastic());
    PetscErrorCode (*fns[1])(PetscInt, PetscReal, const PetscReal[], PetscInt, PetscScalar *, void *) = {ExactU};
    PetscReal err;
    PetscCall(DMComputeL2Diff(fom.dm, 0.0, fns, NULL, fom.u, &err));
    PetscInt nv, nc;
    PetscCall(GlobalPointCount(fom.dm, false, &nv));
    PetscCall(GlobalPointCount(fom.dm, true, &nc));
    PetscCheck(std::isfinite(err), comm, PETSC_ERR_FP, "case %s: L2 error is not finite", cs.id.c_str());
    errs.push_back(err);
    nverts.push_back(nv);
    ncells.push_back(nc);
    hcs.push_back(std::pow((PetscReal)nc, -1.0 / cs.dim));
    ndofs.push_back(fom.GlobalSize());
    hs.push_back(std::pow((PetscReal)nv, -1.0 / cs.dim));
  }
  PetscCall(PetscPrintf(comm, "case %s: %" PetscInt_FMT "D P%" PetscInt_FMT ", E %g nu %g, mesh %s\n", cs.id.c_str(), cs.dim, cs.degree, (double)cs.E, (double)cs.nu, cs.mesh.c_str()));
  // rate: from h = N_vertices^(-1/dim) (asserted); rate_c: from h = N_cells^(-1/dim) (information
  // only: on coarse meshes the boundary vertices inflate N and so the vertex-based rate).
  PetscCall(PetscPrintf(comm, "  %8s %9s %9s %9s %11s %13s %7s %7s\n", "clscale", "vertices", "cells", "dofs", "h=N^-1/d", "L2 error", "rate", "rate_c"));
  PetscReal lastRate = 0;
  for (size_t i = 0; i < errs.size(); ++i) {
    char rate[32] = "-", ratec[32] = "-";
    if (i > 0) {
      lastRate = std::log(errs[i - 1] / errs[i]) / std::log(hs[i - 1] / hs[i]);
      std::snprintf(rate, sizeof rate, "%.3f", (double)lastRate);
      std::snprintf(ratec, sizeof ratec, "%.3f", (double)(std::log(errs[i - 1] / errs[i]) / std::log(hcs[i - 1] / hcs[i])));
    }
    PetscCall(PetscPrintf(comm, "  %8.4g %9" PetscInt_FMT " %9" PetscInt_FMT " %9" PetscInt_FMT " %11.4e %13.6e %7s %7s\n", (double)cs.clscales[i], nverts[i], ncells[i], ndofs[i], (double)hs[i], (double)errs[i], rate, ratec));
  }
  *ok = std::isfinite(lastRate) && lastRate >= cs.minRate && errs.size() >= 3;
  PetscCall(PetscPrintf(comm, "  rate over the last two refinements %.3f, required >= %.2f: %s\n", (double)lastRate, (double)cs.minRate, *ok ? "ok" : "FAILED"));
  PetscFunctionReturn(0);
}

PetscErrorCode Run(MPI_Comm comm, int *failures)
{
  char        buf[256] = "2p1,2p2,3p1,3p2";
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-mms_cases", buf, sizeof buf, NULL));
  // 3D refinements. P2 stops at clscale 0.7 (~4000 tets): PETSc 3.18's PetscFE element-matrix
  // loop costs ~3 ms per P2 tetrahedron (27 quadrature points), 0.5 would take ~30 s alone.
  // -mms_clscale3d a,b,c overrides both.
  PetscReal cl3p1[3] = {2.0, 1.0, 0.5}, cl3p2[3] = {2.0, 1.0, 0.7};
  PetscInt  ncl3     = 3;
  PetscBool set3;
  PetscCall(PetscOptionsGetRealArray(NULL, NULL, "-mms_clscale3d", cl3p1, &ncl3, &set3));
  if (set3) {
    PetscCheck(ncl3 == 3, comm, PETSC_ERR_USER_INPUT, "-mms_clscale3d needs 3 values");
    for (int i = 0; i < 3; ++i) cl3p2[i] = cl3p1[i];
  }
  const std::vector<std::string> wanted = rbc::SplitList(buf);
  PetscCallMPI(MPI_Comm_size(comm, &size));
  const std::vector<std::string> sq = {"boundary"}, cube = {"bottom", "top", "sides"};
  // Two materials (E, nu) so that L/G differ between cases.
  const std::vector<Case> cases = {
    {"2p1", "meshes/unit_square.geo", 2, 1, 100.0, 0.30, 1.8, {1.0, 0.5, 0.25}, sq},
    {"2p2", "meshes/unit_square.geo", 2, 2, 3.5, 0.42, 2.7, {1.0, 0.5, 0.25}, sq},
    {"3p1", "meshes/block3d.geo", 3, 1, 100.0, 0.30, 1.8, {cl3p1[0], cl3p1[1], cl3p1[2]}, cube},
    {"3p2", "meshes/block3d.geo", 3, 2, 3.5, 0.42, 2.7, {cl3p2[0], cl3p2[1], cl3p2[2]}, cube},
  };
  PetscCall(PetscPrintf(comm, "test_mms: manufactured solutions, %d rank(s)\n", size));
  *failures = 0;
  for (const auto &cs : cases) {
    bool run = false;
    for (const auto &w : wanted) run = run || w == cs.id;
    if (!run) continue;
    bool ok = false;
    PetscCall(RunCase(comm, cs, &ok));
    if (!ok) ++*failures;
  }
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  int failures = 0;

  PetscCall(PetscInitialize(&argc, &argv, NULL, "manufactured-solution convergence test of the elastic FOM\n"));
  PetscCall(Run(PETSC_COMM_WORLD, &failures));
  if (failures) PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_mms: FAILED (%d case(s) below the required rate)\n", failures));
  else PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_mms: all cases passed\n"));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
