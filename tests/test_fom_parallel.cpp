// tests/test_fom_parallel.cpp -- owns the parallel-consistency test of the elastic FOM: the
// scene given by the options (e.g. -options_file runs/ring_on_block.opts -contact 0 with the slave
// curve clamped) is solved on PETSC_COMM_WORLD (distributed with -mesh_partitioner, solved with the
// fom_ KSP from the options) and, in the same program, on PETSC_COMM_SELF on rank 0 with the default
// direct solver (MUMPS Cholesky, forced). The energies 0.5 a(u, u) (ElasticFOM::FillReport's
// "energy") must agree to -energy_rtol (default 1e-10); the energy must be positive and finite,
// on more than one rank every rank must own cells, and with -mesh_partitioner metis the FOM mesh
// must have the cells per rank of a direct rbc::DistributeMesh of the same file.
// Options: the scene options, -mesh_partitioner, -fem_degree, -fom_ksp_*/-fom_pc_*,
// -energy_rtol <tol>. Prints a table; exits 1 on failure.
#include "rbcontact/fom.hpp"
#include "rbcontact/mesh.hpp"
#include "rbcontact/partition.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

PetscErrorCode Describe(KSP ksp, std::string *s)
{
  KSPType   kt;
  PCType    pt;
  PC        pc;
  PetscInt  its;
  MatSolverType st = NULL;

  PetscFunctionBeginUser;
  PetscCall(KSPGetType(ksp, &kt));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCGetType(pc, &pt));
  PetscCall(KSPGetIterationNumber(ksp, &its));
  PetscBool isfactor;
  PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &isfactor, PCCHOLESKY, PCLU, ""));
  if (isfactor) PetscCall(PCFactorGetMatSolverType(pc, &st));
  *s = std::string(kt) + "/" + pt + (st ? std::string("(") + st + ")" : std::string()) + ", " + std::to_string((long long)its) + " its";
  PetscFunctionReturn(0);
}

PetscErrorCode Run(MPI_Comm comm, bool *ok)
{
  PetscMPIInt size, rank;
  char        part[64] = "metis";
  PetscReal   tol      = 1e-10;
  rbc::SceneSpec scene;

  PetscFunctionBeginUser;
  *ok = true;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-mesh_partitioner", part, sizeof part, NULL));
  PetscCall(PetscOptionsGetReal(NULL, NULL, "-energy_rtol", &tol, NULL));
  PetscCall(rbc::SceneSpecFromOptions(comm, &scene));
  PetscCheck(!scene.contact, comm, PETSC_ERR_USER_INPUT, "test_fom_parallel solves the elastic FOM only: pass -contact 0");

  // Parallel solve (the fom_ KSP as configured by the options).
  rbc::ElasticFOM par;
  rbc::Report     repPar;
  PetscLogDouble  t0, t1, t2;
  PetscCall(PetscTime(&t0));
  PetscCall(par.Create(comm, scene));
  PetscCall(par.AssembleAndFactor());
  PetscCall(par.SolveElastic());
  PetscCall(par.FillReport(&repPar));
  PetscCall(PetscTime(&t1));
  const PetscReal ePar = repPar.root["energy"].AsNumber();
  std::string     descPar;
  PetscCall(Describe(par.ksp, &descPar));
  PetscInt cStart, cEnd;
  PetscCall(DMPlexGetHeightStratum(par.dm, 0, &cStart, &cEnd));
  std::vector<PetscInt> cellsPerRank(size);
  PetscInt              myCells = cEnd - cStart;
  PetscCallMPI(MPI_Allgather(&myCells, 1, MPIU_INT, cellsPerRank.data(), 1, MPIU_INT, comm));

  // The FOM's mesh must carry the -mesh_partitioner partition: distribute the same .msh directly
  // with rbc::DistributeMesh and compare the cells per rank (metis only: it is deterministic;
  // PT-Scotch is not, run to run). MeshLoad used to distribute a second time in DMSetFromOptions.
  std::vector<PetscInt> directCells(size);
  {
    std::string msh;
    DM          dmd;
    PetscCall(rbc::MeshGenerate(comm, scene.mesh, &msh));
    PetscCall(DMPlexCreateFromFile(comm, msh.c_str(), "direct", PETSC_TRUE, &dmd));
    PetscCall(rbc::DistributeMesh(&dmd));
    PetscInt s, e;
    PetscCall(DMPlexGetHeightStratum(dmd, 0, &s, &e));
    PetscInt n = e - s;
    PetscCallMPI(MPI_Allgather(&n, 1, MPIU_INT, directCells.data(), 1, MPIU_INT, comm));
    PetscCall(DMDestroy(&dmd));
  }

  // Serial reference on rank 0: same scene, PETSC_COMM_SELF, MUMPS Cholesky whatever the options.
  PetscReal eSer = 0;
  PetscInt  nSer = 0;
  char      descSer[256] = "";
  if (rank == 0) {
    rbc::ElasticFOM ser;
    rbc::Report     repSer;
    PC              pc;
    PetscCall(ser.Create(PETSC_COMM_SELF, scene));
    PetscCall(KSPSetType(ser.ksp, KSPPREONLY));
    PetscCall(KSPGetPC(ser.ksp, &pc));
    PetscCall(PCSetType(pc, PCCHOLESKY));
    PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    PetscCall(ser.AssembleAndFactor());
    PetscCall(ser.SolveElastic());
    PetscCall(ser.FillReport(&repSer));
    eSer = repSer.root["energy"].AsNumber();
    nSer = ser.GlobalSize();
    std::string d;
    PetscCall(Describe(ser.ksp, &d));
    std::snprintf(descSer, sizeof descSer, "%s", d.c_str());
  }
  PetscCall(PetscTime(&t2));
  PetscCallMPI(MPI_Bcast(&eSer, 1, MPIU_REAL, 0, comm));
  PetscCallMPI(MPI_Bcast(&nSer, 1, MPIU_INT, 0, comm));
  PetscCallMPI(MPI_Bcast(descSer, sizeof descSer, MPI_CHAR, 0, comm));

  const PetscReal rel = PetscAbsReal(ePar - eSer) / PetscAbsReal(eSer);
  std::string     cells, direct;
  for (PetscInt c : cellsPerRank) cells += (cells.empty() ? "" : "/") + std::to_string((long long)c);
  for (PetscInt c : directCells) direct += (direct.empty() ? "" : "/") + std::to_string((long long)c);
  PetscCall(PetscPrintf(comm, "test_fom_parallel: scene %s, P%" PetscInt_FMT ", %d rank(s), partitioner %s, cells per rank %s\n", scene.name.c_str(), scene.degree, size, part, cells.c_str()));
  PetscCall(PetscPrintf(comm, "  %-9s %8s %-34s %22s %8s\n", "solve", "dofs", "solver", "energy 0.5 a(u,u)", "time s"));
  PetscCall(PetscPrintf(comm, "  %-9s %8" PetscInt_FMT " %-34s %22.15e %8.3f\n", "parallel", par.GlobalSize(), descPar.c_str(), (double)ePar, (double)(t1 - t0)));
  PetscCall(PetscPrintf(comm, "  %-9s %8" PetscInt_FMT " %-34s %22.15e %8.3f\n", "serial", nSer, descSer, (double)eSer, (double)(t2 - t1)));
  PetscCall(PetscPrintf(comm, "  relative energy difference %.3e (tol %.1e)\n", (double)rel, (double)tol));
  PetscCall(PetscPrintf(comm, "  cells per rank: FOM mesh %s, direct rbc::DistributeMesh %s\n", cells.c_str(), direct.c_str()));
  if (!std::strcmp(part, "metis") && cellsPerRank != directCells) {
    *ok = false;
    PetscCall(PetscPrintf(comm, "FAILED: the FOM mesh is not distributed as -mesh_partitioner metis partitions it (%s vs %s)\n", cells.c_str(), direct.c_str()));
  }

  if (!(std::isfinite(ePar) && ePar > 0 && eSer > 0)) {
    *ok = false;
    PetscCall(PetscPrintf(comm, "FAILED: energies must be positive and finite (a stressed scene)\n"));
  }
  if (!(rel <= tol)) {
    *ok = false;
    PetscCall(PetscPrintf(comm, "FAILED: parallel energy %.15e differs from the serial one %.15e by %.3e > %.1e\n", (double)ePar, (double)eSer, (double)rel, (double)tol));
  }
  if (par.GlobalSize() != nSer) {
    *ok = false;
    PetscCall(PetscPrintf(comm, "FAILED: %" PetscInt_FMT " parallel dofs vs %" PetscInt_FMT " serial dofs\n", par.GlobalSize(), nSer));
  }
  for (PetscInt c : cellsPerRank)
    if (size > 1 && c <= 0) {
      *ok = false;
      PetscCall(PetscPrintf(comm, "FAILED: a rank owns no cells (%s)\n", cells.c_str()));
      break;
    }
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  bool ok = false;

  PetscCall(PetscInitialize(&argc, &argv, NULL, "parallel vs serial energy of the elastic FOM\n"));
  PetscCall(Run(PETSC_COMM_WORLD, &ok));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_fom_parallel: %s\n", ok ? "passed" : "FAILED"));
  PetscCall(PetscFinalize());
  return ok ? 0 : 1;
}
