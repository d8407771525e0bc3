// tests/test_element_assembly.cpp: the element-by-element assembly (src/fem/element_assembly.cpp, the
// default) against PetscFE's residual and Jacobian (-fem_assembly petscfe) on the same mesh: the
// stiffness A, the right-hand side f (loads and Dirichlet lifting), the H1 inner-product matrix, the
// energy 1/2 a(U, U) and the cell von Mises stresses of a random field, each to 1e-12 relative, at every -test_mu point (the
// geometric maps give anisotropic effective tensors). The scene comes from the options
// (-options_file runs/<scene>.opts plus overrides); exits 1 on a mismatch.
#include "rbcontact/elasticity.hpp"
#include "rbcontact/geometry_map.hpp"
#include "rbcontact/mesh.hpp"
#include <cmath>

using namespace rbc;

static int failures = 0;

static PetscErrorCode Check(MPI_Comm comm, const char *what, PetscReal diff, PetscReal ref, PetscReal tol)
{
  PetscFunctionBeginUser;
  const PetscReal rel = ref > 0 ? diff / ref : diff;
  const bool      ok  = std::isfinite(rel) && rel <= tol && ref > 0;
  PetscCall(PetscPrintf(comm, "  %-4s %-44s rel diff %.2e (norm %.3e, bound %.0e)\n", ok ? "ok" : "FAIL", what, (double)rel, (double)ref, (double)tol));
  if (!ok) ++failures;
  PetscFunctionReturn(0);
}

static PetscErrorCode CompareMats(MPI_Comm comm, const char *what, Mat Afe, Mat Ael)
{
  Mat       D;
  PetscReal nd, na;

  PetscFunctionBeginUser;
  PetscCall(MatDuplicate(Afe, MAT_COPY_VALUES, &D));
  PetscCall(MatAXPY(D, -1.0, Ael, DIFFERENT_NONZERO_PATTERN));
  PetscCall(MatNorm(D, NORM_FROBENIUS, &nd));
  PetscCall(MatNorm(Afe, NORM_FROBENIUS, &na));
  PetscCall(MatDestroy(&D));
  PetscCall(Check(comm, what, nd, na, 1e-12));
  PetscFunctionReturn(0);
}

static PetscErrorCode CompareVecs(MPI_Comm comm, const char *what, Vec a, Vec b)
{
  Vec       d;
  PetscReal nd, na;

  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(a, &d));
  PetscCall(VecWAXPY(d, -1.0, b, a));
  PetscCall(VecNorm(d, NORM_2, &nd));
  PetscCall(VecNorm(a, NORM_2, &na));
  PetscCall(VecDestroy(&d));
  PetscCall(Check(comm, what, nd, na, 1e-12));
  PetscFunctionReturn(0);
}

static PetscErrorCode Run(MPI_Comm comm)
{
  SceneSpec   scene;
  DM          dm, dm2;
  GeometryMap map;

  PetscFunctionBeginUser;
  PetscCall(SceneSpecFromOptions(comm, &scene));
  PetscCall(MeshLoad(comm, scene, &dm));
  PetscCall(DMClone(dm, &dm2)); // same topology and numbering, its own fields and sections
  PetscCall(map.SetFromOptions(comm, scene));
  {
    Elasticity fe, el;
    fe.SetGeometryMap(&map);
    el.SetGeometryMap(&map);
    PetscCall(PetscOptionsSetValue(NULL, "-fem_assembly", "petscfe"));
    PetscCall(fe.Setup(dm, scene));
    PetscCall(PetscOptionsSetValue(NULL, "-fem_assembly", "element"));
    PetscCall(el.Setup(dm2, scene));
    PetscInt nmu = 0;
    PetscReal muv[64];
    PetscInt  n = 64;
    PetscBool flg;
    PetscCall(PetscOptionsGetRealArray(NULL, NULL, "-test_mu", muv, &n, &flg));
    const size_t p = scene.params.size();
    std::vector<std::vector<PetscReal>> mus;
    mus.push_back(ParamValues(scene));
    if (flg && p > 0)
      for (PetscInt k = 0; k + (PetscInt)p <= n; k += (PetscInt)p) mus.emplace_back(muv + k, muv + k + p);
    for (const auto &mu : mus) {
      ++nmu;
      PetscCall(PetscPrintf(comm, "scene %s, P%" PetscInt_FMT ", mu =", scene.name.c_str(), el.degree));
      for (PetscReal m : mu) PetscCall(PetscPrintf(comm, " %g", (double)m));
      PetscCall(PetscPrintf(comm, "\n"));
      PetscCall(fe.SetMu(mu));
      PetscCall(el.SetMu(mu));
      Mat Afe = nullptr, Ael = nullptr;
      Vec ffe = nullptr, fel = nullptr;
      PetscCall(fe.Assemble(&Afe, &ffe));
      PetscCall(el.Assemble(&Ael, &fel));
      PetscCall(CompareMats(comm, "stiffness A", Afe, Ael));
      PetscCall(CompareVecs(comm, "right-hand side f (loads + lifting)", ffe, fel));
      // a second assembly into the existing matrix (MatZeroEntries path) gives the same A
      PetscCall(el.AssembleMatrix(&Ael));
      PetscCall(CompareMats(comm, "stiffness A, reassembled in place", Afe, Ael));
      // energy of a random field with the Dirichlet values
      Vec       u;
      PetscReal efe, eel;
      PetscRandom rnd;
      PetscCall(VecDuplicate(ffe, &u));
      PetscCall(PetscRandomCreate(comm, &rnd));
      PetscCall(PetscRandomSetSeed(rnd, 7));
      PetscCall(PetscRandomSeed(rnd));
      PetscCall(VecSetRandom(u, rnd));
      PetscCall(PetscRandomDestroy(&rnd));
      PetscCall(fe.Energy(u, &efe));
      PetscCall(el.Energy(u, &eel));
      PetscCall(Check(comm, "energy 1/2 a(U, U) of a random field", std::abs(efe - eel), std::abs(efe), 1e-12));
      {
        // cell von Mises stress of the same field: the element tables' quadrature mean against PetscFE's
        // cellwise integral divided by the cell volume (the output's cell field)
        Vec       vfe, vel;
        PetscReal nref, ndiff;
        PetscCall(fe.VonMises(u, &vfe));
        PetscCall(el.VonMises(u, &vel));
        PetscCall(VecNorm(vfe, NORM_INFINITY, &nref));
        PetscCall(VecAXPY(vel, -1.0, vfe));
        PetscCall(VecNorm(vel, NORM_INFINITY, &ndiff));
        PetscCall(Check(comm, "cell von Mises stress of a random field (max)", ndiff, nref, 1e-12));
        PetscCall(VecDestroy(&vfe));
        PetscCall(VecDestroy(&vel));
      }
      {
        // the local vector with the Dirichlet values: constant values inserted directly (element path)
        // against DMPlexInsertBoundaryValues's projection (PetscFE path); same numbering (cloned DM)
        Vec       lfe, lel;
        PetscReal dmax = 0, nref = 0;
        PetscCall(DMGetLocalVector(fe.dm, &lfe));
        PetscCall(DMGetLocalVector(el.dm, &lel));
        PetscCall(fe.GlobalToLocalWithBC(u, lfe));
        PetscCall(el.GlobalToLocalWithBC(u, lel));
        PetscCall(VecNorm(lfe, NORM_INFINITY, &nref));
        PetscCall(VecAXPY(lel, -1.0, lfe));
        PetscCall(VecNorm(lel, NORM_INFINITY, &dmax));
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &dmax, 1, MPIU_REAL, MPI_MAX, comm));
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &nref, 1, MPIU_REAL, MPI_MAX, comm));
        PetscCall(Check(comm, "local vector with the Dirichlet values: direct insertion = DMPlexInsertBoundaryValues", dmax, nref, 1e-14));
        PetscCall(DMRestoreLocalVector(fe.dm, &lfe));
        PetscCall(DMRestoreLocalVector(el.dm, &lel));
      }
      PetscCall(VecDestroy(&u));
      PetscCall(MatDestroy(&Afe));
      PetscCall(MatDestroy(&Ael));
      PetscCall(VecDestroy(&ffe));
      PetscCall(VecDestroy(&fel));
    }
    Mat Mfe = nullptr, Mel = nullptr;
    PetscCall(fe.AssembleH1(&Mfe));
    PetscCall(el.AssembleH1(&Mel));
    PetscCall(CompareMats(comm, "H1 inner product (mass + grad:grad)", Mfe, Mel));
    PetscCall(MatDestroy(&Mfe));
    PetscCall(MatDestroy(&Mel));
    {
      // the rigid-body modes at the nodes (GAMG's near null space) span what DMPlexCreateRigidBody projects
      MatNullSpace nn, np;
      PetscInt     nn_n, np_n;
      const Vec   *vn, *vp;
      PetscBool    hasc;
      PetscReal    worst = 0;
      PetscCall(NodalRigidBodyModes(el.dm, &nn));
      PetscCheck(nn, comm, PETSC_ERR_PLIB, "NodalRigidBodyModes: not supported on a P%" PetscInt_FMT " field", el.degree);
      PetscCall(DMPlexCreateRigidBody(fe.dm, 0, &np));
      PetscCall(MatNullSpaceGetVecs(nn, &hasc, &nn_n, &vn));
      PetscCall(MatNullSpaceGetVecs(np, &hasc, &np_n, &vp));
      PetscCheck(nn_n == np_n && nn_n == (el.dim == 2 ? 3 : 6), comm, PETSC_ERR_PLIB, "rigid-body modes: %" PetscInt_FMT " at the nodes, %" PetscInt_FMT " projected", nn_n, np_n);
      for (PetscInt j = 0; j < np_n; ++j) { // the part of each projected mode outside the nodal span
        Vec       r;
        PetscReal nr;
        PetscCall(VecDuplicate(vp[j], &r));
        PetscCall(VecCopy(vp[j], r));
        for (PetscInt i = 0; i < nn_n; ++i) {
          PetscScalar d;
          PetscCall(VecDot(vp[j], vn[i], &d));
          PetscCall(VecAXPY(r, -d, vn[i]));
        }
        PetscCall(VecNorm(r, NORM_2, &nr));
        worst = std::max(worst, nr);
        PetscCall(VecDestroy(&r));
      }
      PetscCall(Check(comm, "rigid-body modes at the nodes span DMPlexCreateRigidBody's", worst, 1.0, 1e-12));
      PetscCall(MatNullSpaceDestroy(&nn));
      PetscCall(MatNullSpaceDestroy(&np));
    }
    PetscCheck(nmu > 0, comm, PETSC_ERR_PLIB, "no parameter point tested");
  }
  PetscCall(DMDestroy(&dm2));
  PetscCall(DMDestroy(&dm));
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCall(Run(PETSC_COMM_WORLD));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s: %d failure(s)\n", failures ? "FAIL" : "PASS", failures));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
