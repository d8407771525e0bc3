// tests/test_reference_config.cpp: the reference-configuration FOM (reference mesh + map h(mu) +
// affine decomposition) against (1) a direct assembly at mu on the same reference mesh (A, f to 1e-12)
// and (2) a FOM on a mesh whose nodes were moved by h(mu) with no map (u, lambda, contact force to
// 1e-10). The scene comes from the options (-options_file runs/<scene>.opts); parameter values from
// -test_mu a,b,... (one parameter: one value per case; p parameters: p values per case).
#include "rbcontact/fom.hpp"
#include "rbcontact/kacanov.hpp"
#include "rbcontact/mesh.hpp"
#include <cmath>

#include "test_check.hpp"

using namespace rbc;

using rbctest::Check;
using rbctest::failures;

// Moves the DM's vertices by the body maps at mu (every vertex belongs to the cells of one body).
static PetscErrorCode MoveNodes(DM dm, const Elasticity &elas, const GeometryMap &map, const std::vector<PetscReal> &mu)
{
  Vec          cl;
  PetscSection cs;
  DM           cdm;
  PetscInt     cStart, cEnd, dim;
  PetscScalar *x;

  PetscFunctionBeginUser;
  PetscCall(DMGetDimension(dm, &dim));
  PetscCall(DMGetCoordinateDM(dm, &cdm));
  PetscCall(DMGetLocalSection(cdm, &cs));
  PetscCall(DMGetCoordinatesLocal(dm, &cl));
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  PetscInt pStart, pEnd;
  PetscCall(PetscSectionGetChart(cs, &pStart, &pEnd));
  std::vector<char> moved(pEnd - pStart, 0);
  Vec               cnew;
  PetscCall(VecDuplicate(cl, &cnew));
  PetscCall(VecCopy(cl, cnew));
  PetscCall(VecGetArray(cnew, &x));
  for (PetscInt c = cStart; c < cEnd; ++c) {
    const Affine a = map.Evaluate(elas.CellBody()[c - cStart], mu);
    PetscInt    *closure = NULL, ncl;
    PetscCall(DMPlexGetTransitiveClosure(dm, c, PETSC_TRUE, &ncl, &closure));
    for (PetscInt k = 0; k < ncl; ++k) {
      const PetscInt p = closure[2 * k];
      PetscInt       dof, off;
      if (p < pStart || p >= pEnd) continue;
      PetscCall(PetscSectionGetDof(cs, p, &dof));
      if (!dof || moved[p - pStart]) continue;
      PetscCall(PetscSectionGetOffset(cs, p, &off));
      PetscReal xr[3], y[3];
      for (PetscInt d = 0; d < dim; ++d) xr[d] = PetscRealPart(x[off + d]);
      a.Apply(dim, xr, y);
      for (PetscInt d = 0; d < dim; ++d) x[off + d] = y[d];
      moved[p - pStart] = 1;
    }
    PetscCall(DMPlexRestoreTransitiveClosure(dm, c, PETSC_TRUE, &ncl, &closure));
  }
  PetscCall(VecRestoreArray(cnew, &x));
  PetscCall(DMSetCoordinatesLocal(dm, cnew));
  {
    Vec cg;
    PetscCall(DMGetCoordinates(dm, &cg)); // refreshes the global coordinates from the local ones
    (void)cg;
  }
  PetscCall(VecDestroy(&cnew));
  PetscFunctionReturn(0);
}

static PetscErrorCode RelDiff(Vec a, Vec b, PetscReal *rel)
{
  Vec       d;
  PetscReal na, nd;

  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(a, &d));
  PetscCall(VecWAXPY(d, -1.0, b, a));
  PetscCall(VecNorm(d, NORM_INFINITY, &nd));
  PetscCall(VecNorm(a, NORM_INFINITY, &na));
  *rel = na > 0 ? nd / na : nd;
  PetscCall(VecDestroy(&d));
  PetscFunctionReturn(0);
}

static PetscErrorCode Run()
{
  MPI_Comm  comm = PETSC_COMM_WORLD;

  PetscFunctionBeginUser;
  SceneSpec scene;
  PetscCall(PetscPushErrorHandler(PetscTraceBackErrorHandler, NULL));
  PetscCall(SceneSpecFromOptions(comm, &scene));
  const size_t np = scene.params.size();
  PetscCheck(np > 0, comm, PETSC_ERR_USER_INPUT, "the scene declares no parameters");
  PetscReal vals[64];
  PetscInt  nv = 64;
  PetscBool set;
  PetscCall(PetscOptionsGetRealArray(NULL, NULL, "-test_mu", vals, &nv, &set));
  PetscCheck(set && nv % (PetscInt)np == 0, comm, PETSC_ERR_USER_INPUT, "-test_mu needs a multiple of %zu values", np);

  ElasticFOM ref;
  PetscCall(ref.Create(comm, scene));
  PetscCall(ref.SetupAffine());
  JsonValue terms;
  ref.affine.Describe(&terms);
  PetscCall(PetscPrintf(comm, "scene %s: map %s; affine terms A %lld, f %lld\n", scene.name.c_str(), ref.map.Describe(scene).c_str(), (long long)terms["A"].AsNumber(), (long long)terms["f"].AsNumber()));
  ContactMap    refMap;
  KacanovSolver refKac;
  if (scene.contact) {
    PetscCall(refKac.SetFromOptions(comm));
    PetscCall(refMap.Setup(ref.elas, scene.slave, scene.master));
  }
  for (PetscInt c = 0; c < nv / (PetscInt)np; ++c) {
    std::vector<PetscReal> mu(vals + c * np, vals + (c + 1) * np);
    PetscCall(PetscPrintf(comm, "mu =%s\n", [&] { std::string s; for (PetscReal m : mu) s += " " + std::to_string(m); return s; }().c_str()));
    // (1) affine sums vs direct assembly at mu
    PetscCall(ref.SetMu(mu));
    Mat Ad = nullptr;
    Vec fd = nullptr;
    PetscCall(ref.elas.Assemble(&Ad, &fd));
    PetscCall(ref.AssembleAndFactor());
    PetscReal nA, nD, rf;
    Mat       D;
    PetscCall(MatDuplicate(Ad, MAT_COPY_VALUES, &D));
    PetscCall(MatAXPY(D, -1.0, ref.A, SAME_NONZERO_PATTERN));
    PetscCall(MatNorm(D, NORM_FROBENIUS, &nD));
    PetscCall(MatNorm(Ad, NORM_FROBENIUS, &nA));
    PetscCall(RelDiff(fd, ref.f, &rf));
    PetscCall(Check(comm, nD / nA <= 1e-12, "affine A(mu) = direct assembly (rel. Frobenius)", nD / nA, 1e-12));
    PetscCall(Check(comm, rf <= 1e-12, "affine f(mu) = direct assembly (rel. max)", rf, 1e-12));
    PetscCall(MatDestroy(&D));
    PetscCall(MatDestroy(&Ad));
    PetscCall(VecDestroy(&fd));
    // reference-configuration solve
    ContactSummary cs1, cs2;
    if (scene.contact) {
      refMap.SetGeometry(&ref.map, mu);
      PetscCall(refKac.Solve(ref, refMap));
      PetscCall(SummarizeContact(refKac.sys, refKac.lambda, ref.elas.dim, &cs1));
    } else PetscCall(ref.SolveElastic());
    // (2) moved mesh, no map
    DM dm2;
    PetscCall(MeshLoad(comm, scene, &dm2));
    {
      ElasticFOM tmp; // body of each cell on the moved DM (same topology)
      PetscCall(tmp.CreateOnDM(dm2, scene));
      PetscCall(MoveNodes(dm2, tmp.elas, tmp.map, mu));
    }
    ElasticFOM moved;
    PetscCall(moved.CreateOnDM(dm2, scene));
    PetscCall(DMDestroy(&dm2));
    moved.map.bodies.clear(); // identity: the nodes already are where h(mu) puts them
    PetscCall(moved.SetMu(mu));
    PetscCall(moved.AssembleAndFactor());
    ContactMap    map2;
    KacanovSolver kac2;
    if (scene.contact) {
      PetscCall(kac2.SetFromOptions(comm));
      PetscCall(map2.Setup(moved.elas, scene.slave, scene.master));
      map2.SetGeometry(nullptr, mu);
      PetscCall(kac2.Solve(moved, map2));
      PetscCall(SummarizeContact(kac2.sys, kac2.lambda, moved.elas.dim, &cs2));
    } else PetscCall(moved.SolveElastic());
    PetscReal du;
    PetscCall(RelDiff(ref.u, moved.u, &du));
    PetscCall(Check(comm, du <= 1e-10, "u (reference config) = u (moved nodes)", du, 1e-10));
    if (scene.contact) {
      PetscReal dl;
      PetscCall(RelDiff(refKac.lambda, kac2.lambda, &dl));
      PetscCall(Check(comm, dl <= 1e-10, "lambda (reference config) = lambda (moved nodes)", dl, 1e-10));
      const PetscReal df = std::abs(cs1.force - cs2.force) / cs1.force;
      PetscCall(Check(comm, df <= 1e-10, "contact force (reference config) = (moved nodes)", df, 1e-10));
      PetscCall(PetscPrintf(comm, "  contact force %.12e, active %" PetscInt_FMT "/%" PetscInt_FMT "\n", (double)cs1.force, cs1.nactive, cs1.R));
    }
  }
  PetscCall(PetscPrintf(comm, "%s (%d failure(s))\n", failures ? "reference_config test FAILED" : "reference_config test passed", failures));
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCall(Run()); // every PETSc object is destroyed before PetscFinalize
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
