// src/fom/elastic_fom.cpp: assembly, factorization and solve of the elastic full-order model.
#include "rbcontact/fom.hpp"
#include "rbcontact/mesh.hpp"

namespace rbc {

static PetscLogEvent FOM_Assembly = 0, FOM_Factor = 0, FOM_Solve = 0;

static PetscErrorCode RegisterEvents()
{
  PetscFunctionBeginUser;
  if (!FOM_Assembly) {
    PetscCall(PetscLogEventRegister("RBCFomAssembly", KSP_CLASSID, &FOM_Assembly));
    PetscCall(PetscLogEventRegister("RBCFomFactor", KSP_CLASSID, &FOM_Factor));
    PetscCall(PetscLogEventRegister("RBCFomSolve", KSP_CLASSID, &FOM_Solve));
  }
  PetscFunctionReturn(0);
}

ElasticFOM::~ElasticFOM()
{
  (void)KSPDestroy(&ksp);
  (void)MatDestroy(&A);
  (void)VecDestroy(&f);
  (void)VecDestroy(&u);
  (void)DMDestroy(&dm);
}

PetscErrorCode ElasticFOM::Create(MPI_Comm comm, const SceneSpec &sc)
{
  DM dmNew;

  PetscFunctionBeginUser;
  PetscCall(MeshLoad(comm, sc, &dmNew));
  PetscCall(CreateOnDM(dmNew, sc));
  PetscCall(DMDestroy(&dmNew));
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::CreateOnDM(DM dmIn, const SceneSpec &sc)
{
  PC pc;

  PetscFunctionBeginUser;
  PetscCall(RegisterEvents());
  scene = sc;
  dm    = dmIn;
  PetscCall(PetscObjectReference((PetscObject)dm));
  PetscCall(elas.Setup(dm, scene));
  PetscCall(KSPCreate(PetscObjectComm((PetscObject)dm), &ksp));
  PetscCall(KSPSetOptionsPrefix(ksp, "fom_"));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscCall(KSPSetTolerances(ksp, 1e-12, 1e-50, PETSC_DEFAULT, 10000));
  PetscCall(KSPSetFromOptions(ksp));
  PetscFunctionReturn(0);
}

PetscInt ElasticFOM::GlobalSize() const
{
  PetscInt n = 0;
  if (f) (void)VecGetSize(f, &n);
  return n;
}

PetscErrorCode ElasticFOM::AssembleAndFactor()
{
  PetscLogDouble t0, t1;
  PC             pc;
  PetscBool      isgamg;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscCall(PetscLogEventBegin(FOM_Assembly, 0, 0, 0, 0));
  PetscCall(elas.Assemble(&A, &f));
  PetscCall(PetscLogEventEnd(FOM_Assembly, 0, 0, 0, 0));
  PetscCall(PetscTime(&t1));
  times.assembly += t1 - t0;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCGAMG, &isgamg));
  if (isgamg) {
    MatNullSpace nsp;
    PetscCall(elas.NearNullSpace(&nsp));
    PetscCall(MatSetNearNullSpace(A, nsp));
    PetscCall(MatNullSpaceDestroy(&nsp));
  }
  PetscCall(KSPSetOperators(ksp, A, A));
  PetscCall(PetscLogEventBegin(FOM_Factor, 0, 0, 0, 0));
  PetscCall(KSPSetUp(ksp));
  PetscCall(PetscLogEventEnd(FOM_Factor, 0, 0, 0, 0));
  PetscCall(PetscTime(&t0));
  times.factorization += t0 - t1;
  if (!u) PetscCall(VecDuplicate(f, &u));
  PetscCall(PetscObjectSetName((PetscObject)u, "displacement"));
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::ApplyInverse(Vec rhs, Vec x)
{
  KSPConvergedReason reason;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(FOM_Solve, 0, 0, 0, 0));
  PetscCall(KSPSolve(ksp, rhs, x));
  PetscCall(PetscLogEventEnd(FOM_Solve, 0, 0, 0, 0));
  PetscCall(KSPGetConvergedReason(ksp, &reason));
  PetscCheck(reason > 0, PetscObjectComm((PetscObject)ksp), PETSC_ERR_NOT_CONVERGED, "The elastic solve (KSP prefix fom_) did not converge: %s. A singular stiffness usually means a body without enough Dirichlet conditions (-bc_dirichlet)", KSPConvergedReasons[reason]);
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::SolveElastic()
{
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscCall(ApplyInverse(f, u));
  PetscCall(PetscTime(&t1));
  times.solve += t1 - t0;
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::FillReport(Report *rep)
{
  PetscMPIInt size;
  PetscReal   energy;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)dm), &size));
  PetscCall(elas.Energy(u, &energy));
  rep->root["scene"]   = scene.name;
  rep->root["ndofs"]   = (long long)GlobalSize();
  rep->root["nranks"]  = (int)size;
  rep->root["degree"]  = (long long)elas.degree;
  rep->root["dim"]     = (long long)elas.dim;
  rep->root["energy"]  = (double)energy;
  JsonValue &t         = rep->root["time_s"];
  t["assembly"]        = (double)times.assembly;
  t["factorization"]   = (double)times.factorization;
  t["contact"]         = (double)times.contact;
  t["solve"]           = (double)times.solve;
  t["total"]           = (double)times.total;
  PetscFunctionReturn(0);
}

} // namespace rbc
