// src/contact/compliance.cpp: G = (A^{-1})_{DD} by a MUMPS Schur complement (serial, or per rank when
// A has no coupling between ranks), by MUMPS's
// selected entries of the inverse on the parallel factor, or by back-solves with unit right-hand sides.
#include "rbcontact/compliance.hpp"
#include <petscblaslapack.h>
#include <cstring>

namespace rbc {

static PetscLogEvent CMP_Compute = 0;

// G = S_A^{-1} from the Schur complement S_A = A_DD - A_DI A_II^{-1} A_ID (SPD: Cholesky inverse).
static PetscErrorCode InverseOfSchur(Mat S, std::vector<PetscReal> *G)
{
  const PetscScalar *s;
  PetscInt           lda, n;

  PetscFunctionBeginUser;
  PetscCall(MatGetSize(S, &n, NULL));
  // (no free contact dof: LAPACK said "parameter number 4 had an illegal value" and the message "not SPD")
  PetscCheck(n > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "Contact compliance: the contact surfaces have no free degree of freedom: Dirichlet conditions fix all of them (does -dirichlet list the slave or master surface?)");
  const PetscBLASInt nb = (PetscBLASInt)n;
  PetscCall(MatDenseGetLDA(S, &lda));
  PetscCall(MatDenseGetArrayRead(S, &s));
  G->assign((size_t)n * n, 0.0);
  for (PetscInt j = 0; j < n; ++j)
    for (PetscInt i = 0; i < n; ++i) (*G)[i + (size_t)j * n] = PetscRealPart(s[i + j * lda]);
  PetscCall(MatDenseRestoreArrayRead(S, &s));
  PetscBLASInt linfo = 0;
  LAPACKpotrf_("L", &nb, G->data(), &nb, &linfo);
  PetscCheck(!linfo, PETSC_COMM_SELF, PETSC_ERR_MAT_CH_ZRPVT, "Contact compliance: Schur complement on the contact dofs is not SPD (LAPACK potrf info %d)", (int)linfo);
  LAPACKpotri_("L", &nb, G->data(), &nb, &linfo);
  PetscCheck(!linfo, PETSC_COMM_SELF, PETSC_ERR_LIB, "Contact compliance: LAPACK potri info %d", (int)linfo);
  for (PetscInt j = 0; j < n; ++j)
    for (PetscInt i = 0; i < j; ++i) (*G)[i + (size_t)j * n] = (*G)[j + (size_t)i * n];
  PetscFunctionReturn(0);
}

// G = blockdiag(G_r) from each rank's Schur complement on its dofs of D (A without coupling between ranks:
// (A^{-1})_DD is block diagonal; the ranks' dofs of D are consecutive in D, rank by rank).
static PetscErrorCode ComplianceFromLocalSchur(ElasticFOM &fom, const std::vector<PetscInt> &D, std::vector<PetscReal> *G)
{
  MPI_Comm               comm = PetscObjectComm((PetscObject)fom.A);
  PetscMPIInt            size;
  std::vector<PetscReal> Gr;
  PetscInt               nr = 0;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (fom.SchurComplement()) {
    PetscCall(InverseOfSchur(fom.SchurComplement(), &Gr));
    PetscCall(MatGetSize(fom.SchurComplement(), &nr, NULL));
  }
  std::vector<PetscMPIInt> counts(size), cdispl(size), sizes(size);
  PetscMPIInt              nrm = (PetscMPIInt)nr, cnt = (PetscMPIInt)(nr * nr);
  PetscCallMPI(MPI_Allgather(&nrm, 1, MPI_INT, sizes.data(), 1, MPI_INT, comm));
  size_t total = 0, nD = 0;
  for (PetscMPIInt r = 0; r < size; ++r) {
    counts[r] = sizes[r] * sizes[r];
    cdispl[r] = (PetscMPIInt)total;
    total += (size_t)counts[r];
    nD += (size_t)sizes[r];
  }
  PetscCheck(nD == D.size(), comm, PETSC_ERR_PLIB, "compliance: the ranks' Schur complements cover %zu of the %zu contact dofs", nD, D.size());
  std::vector<PetscReal> blocks(total);
  PetscCallMPI(MPI_Allgatherv(Gr.data(), cnt, MPIU_REAL, blocks.data(), counts.data(), cdispl.data(), MPIU_REAL, comm));
  const size_t n = D.size();
  G->assign(n * n, 0.0);
  size_t off = 0;
  for (PetscMPIInt r = 0; r < size; ++r) {
    const size_t m = (size_t)sizes[r];
    for (size_t j = 0; j < m; ++j)
      for (size_t i = 0; i < m; ++i) (*G)[(off + i) + (off + j) * n] = blocks[cdispl[r] + i + j * m];
    off += m;
  }
  PetscFunctionReturn(0);
}

// A (sequential, global numbering) -> G = (A^{-1})_{DD} through a MUMPS factorization with the Schur
// complement on D.
static PetscErrorCode ComplianceBySchur(Mat Aseq, const std::vector<PetscInt> &D, std::vector<PetscReal> *G)
{
  Mat                  F, S;
  IS                   is;
  MatFactorInfo        info;
  MatFactorSchurStatus status;

  PetscFunctionBeginUser;
  PetscCall(ISCreateGeneral(PETSC_COMM_SELF, (PetscInt)D.size(), D.data(), PETSC_COPY_VALUES, &is));
  PetscCall(MatGetFactor(Aseq, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &F));
  PetscCall(MatFactorSetSchurIS(F, is));
  PetscCall(MatFactorInfoInitialize(&info));
  PetscCall(MatCholeskyFactorSymbolic(F, Aseq, NULL, &info));
  PetscCall(MatCholeskyFactorNumeric(F, Aseq, &info));
  PetscCall(MatFactorCreateSchurComplement(F, &S, &status));
  PetscCall(InverseOfSchur(S, G));
  PetscCall(MatDestroy(&S));
  PetscCall(MatDestroy(&F));
  PetscCall(ISDestroy(&is));
  PetscFunctionReturn(0);
}

// The MUMPS factor of the FOM's KSP (preonly or not, Cholesky or LU), or null when A is not factored by MUMPS.
static PetscErrorCode MumpsFactorOf(ElasticFOM &fom, Mat *F)
{
  PC            pc;
  PetscBool     chol, lu, mumps = PETSC_FALSE;
  MatSolverType st = NULL;

  PetscFunctionBeginUser;
  *F = nullptr;
  PetscCall(KSPGetPC(fom.ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCCHOLESKY, &chol));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCLU, &lu));
  if (!chol && !lu) PetscFunctionReturn(0);
  PetscCall(PCFactorGetMatSolverType(pc, &st));
  if (st) PetscCall(PetscStrcmp(st, MATSOLVERMUMPS, &mumps));
  if (mumps) PetscCall(PCFactorGetMatrix(pc, F));
  PetscFunctionReturn(0);
}

// G = (A^{-1})_{DD} as MUMPS's selected entries of the inverse (ICNTL(30), sparse right-hand sides
// e_j, j in D, only the D entries of each column computed) on the factor the KSP already holds: no
// second factorization, and the work is the pruned solves of the parallel factor. The pattern lives on
// rank 0 (the PETSc interface's layout); G is broadcast. The solve controls it changes (ICNTL 20, 21, 30)
// are restored for the ordinary solves that follow.
static PetscErrorCode ComplianceByInverseEntries(ElasticFOM &fom, Mat F, const std::vector<PetscInt> &D, std::vector<PetscReal> *G)
{
  MPI_Comm       comm = PetscObjectComm((PetscObject)fom.A);
  PetscMPIInt    rank;
  const PetscInt n = (PetscInt)D.size();
  PetscInt       M, icntl21, icntl30;
  Mat            Bt, B;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(MatGetSize(fom.A, &M, NULL));
  // Bt = pattern of (A^{-1})_{DD}^T: row D[j] (the right-hand side e_{D[j]}) holds the columns D, the
  // other rows are empty (MUMPS wants as many right-hand sides as unknowns); all on rank 0
  std::vector<PetscInt> nnz(rank ? 0 : M, 0);
  if (!rank)
    for (PetscInt j = 0; j < n; ++j) nnz[D[j]] = n;
  PetscCall(MatCreate(comm, &Bt));
  PetscCall(MatSetSizes(Bt, rank ? 0 : M, rank ? 0 : M, M, M));
  PetscCall(MatSetType(Bt, MATAIJ));
  PetscCall(MatSeqAIJSetPreallocation(Bt, 0, nnz.data()));
  PetscCall(MatMPIAIJSetPreallocation(Bt, 0, nnz.data(), 0, NULL));
  if (!rank) {
    std::vector<PetscScalar> zero(n, 0.0);
    for (PetscInt j = 0; j < n; ++j) PetscCall(MatSetValues(Bt, 1, &D[j], n, D.data(), zero.data(), INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(Bt, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(Bt, MAT_FINAL_ASSEMBLY));
  PetscCall(MatMumpsGetIcntl(F, 21, &icntl21));
  PetscCall(MatMumpsGetIcntl(F, 30, &icntl30));
  PetscCall(MatCreateTranspose(Bt, &B));
  PetscCall(MatMumpsGetInverse(F, B));
  PetscCall(MatDestroy(&B));
  PetscCall(MatMumpsSetIcntl(F, 21, icntl21));
  PetscCall(MatMumpsSetIcntl(F, 30, icntl30));
  G->assign((size_t)n * n, 0.0);
  if (!rank) {
    Mat                Bl = Bt;
    PetscBool          mpi;
    const PetscScalar *a;
    PetscCall(PetscObjectTypeCompare((PetscObject)Bt, MATMPIAIJ, &mpi));
    if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(Bt, &Bl, NULL, NULL));
    PetscCall(MatSeqAIJGetArrayRead(Bl, &a)); // row D[j] holds (A^{-1})_{D[i], D[j]} in the order of D (sorted), rows in order
    for (size_t k = 0; k < (size_t)n * n; ++k) (*G)[k] = PetscRealPart(a[k]);
    PetscCall(MatSeqAIJRestoreArrayRead(Bl, &a));
  }
  PetscCall(MatDestroy(&Bt));
  PetscCallMPI(MPI_Bcast(G->data(), (PetscMPIInt)((size_t)n * n), MPIU_REAL, 0, comm));
  for (PetscInt j = 0; j < n; ++j) // symmetric up to rounding
    for (PetscInt i = 0; i < j; ++i) {
      const PetscReal m = 0.5 * ((*G)[i + (size_t)j * n] + (*G)[j + (size_t)i * n]);
      (*G)[i + (size_t)j * n] = (*G)[j + (size_t)i * n] = m;
    }
  PetscFunctionReturn(0);
}

static PetscErrorCode ComplianceBySolves(ElasticFOM &fom, const std::vector<PetscInt> &D, std::vector<PetscReal> *G)
{
  Vec                e, x, xall;
  VecScatter         sc;
  IS                 isD;
  const PetscInt     n = (PetscInt)D.size();
  PetscInt           lo, hi;

  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(fom.f, &e));
  PetscCall(VecDuplicate(fom.f, &x));
  PetscCall(VecGetOwnershipRange(e, &lo, &hi));
  PetscCall(ISCreateGeneral(PETSC_COMM_SELF, n, D.data(), PETSC_COPY_VALUES, &isD));
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, n, &xall));
  PetscCall(VecScatterCreate(x, isD, xall, NULL, &sc));
  G->assign((size_t)n * n, 0.0);
  for (PetscInt j = 0; j < n; ++j) {
    PetscCall(VecSet(e, 0.0));
    if (D[j] >= lo && D[j] < hi) PetscCall(VecSetValue(e, D[j], 1.0, INSERT_VALUES));
    PetscCall(VecAssemblyBegin(e));
    PetscCall(VecAssemblyEnd(e));
    PetscCall(fom.ApplyInverse(e, x));
    PetscCall(VecScatterBegin(sc, x, xall, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(sc, x, xall, INSERT_VALUES, SCATTER_FORWARD));
    const PetscScalar *a;
    PetscCall(VecGetArrayRead(xall, &a));
    for (PetscInt i = 0; i < n; ++i) (*G)[i + (size_t)j * n] = PetscRealPart(a[i]);
    PetscCall(VecRestoreArrayRead(xall, &a));
  }
  // Symmetrize (the factor is symmetric up to rounding)
  for (PetscInt j = 0; j < n; ++j)
    for (PetscInt i = 0; i < j; ++i) {
      const PetscReal m = 0.5 * ((*G)[i + (size_t)j * n] + (*G)[j + (size_t)i * n]);
      (*G)[i + (size_t)j * n] = (*G)[j + (size_t)i * n] = m;
    }
  PetscCall(VecScatterDestroy(&sc));
  PetscCall(ISDestroy(&isD));
  PetscCall(VecDestroy(&xall));
  PetscCall(VecDestroy(&e));
  PetscCall(VecDestroy(&x));
  PetscFunctionReturn(0);
}

PetscErrorCode SurfaceCompliance::Compute(ElasticFOM &fom, const std::vector<PetscInt> &Din)
{
  MPI_Comm       comm = PetscObjectComm((PetscObject)fom.A);
  PetscMPIInt    size;
  char           m[32] = "auto";
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  if (!CMP_Compute) PetscCall(PetscLogEventRegister("RBCCompliance", MAT_CLASSID, &CMP_Compute));
  PetscCall(PetscTime(&t0));
  PetscCall(PetscLogEventBegin(CMP_Compute, 0, 0, 0, 0));
  D = Din;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-contact_compliance", m, sizeof m, NULL));
  PetscCheck(!strcmp(m, "auto") || !strcmp(m, "schur") || !strcmp(m, "inverse") || !strcmp(m, "redundant") || !strcmp(m, "solves"), comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-contact_compliance: unknown value '%s' (auto, schur, inverse, redundant or solves)", m);
  Mat F = nullptr;
  if (!strcmp(m, "inverse")) {
    PetscCall(KSPSetUp(fom.ksp));
    PetscCall(MumpsFactorOf(fom, &F));
  }
  // auto: the Schur complement (on 1 rank directly, on several ranks on a redundant sequential copy of
  // A: PETSc 3.18 has no parallel MUMPS Schur complement). One back-solve per contact dof in parallel
  // was measured 20x slower on 2 ranks (ring_on_block refine 2: 14.5 s of an 18.8 s solve); the selected
  // entries of the inverse on the parallel factor 1.5-2x slower than the redundant Schur complement
  // (half_disks P2 refine 1, 2340 contact dofs: 2.7-3.9 s against 1.8 s), but without a copy of A per rank.
  // With A uncoupled between ranks (-mesh_partitioner bodies) each rank's Schur complement gives its block.
  const bool local = fom.SchurIsLocal() && fom.SchurDofs() == D;
  if (!strcmp(m, "auto")) method = size == 1 || local ? "schur" : "redundant";
  else method = m;
  PetscCheck(method != "schur" || size == 1 || local, comm, PETSC_ERR_SUP, "-contact_compliance schur needs 1 rank or -mesh_partitioner bodies (PETSc 3.18 has no parallel MUMPS Schur complement); use inverse, redundant or solves");
  PetscCheck(method != "inverse" || F, comm, PETSC_ERR_SUP, "-contact_compliance inverse needs the FOM's stiffness factored by MUMPS (-fom_pc_type cholesky or lu, -fom_pc_factor_mat_solver_type mumps)");
  if (method == "schur" && local) {
    method = "schur per rank (the factors of the solves)";
    PetscCall(ComplianceFromLocalSchur(fom, D, &G));
  } else if (method == "schur" && fom.SchurComplement() && fom.SchurDofs() == D) {
    method = "schur (the factor of the solves)"; // one factorization per parameter
    PetscCall(InverseOfSchur(fom.SchurComplement(), &G));
  } else if (method == "schur") PetscCall(ComplianceBySchur(fom.A, D, &G));
  else if (method == "inverse") PetscCall(ComplianceByInverseEntries(fom, F, D, &G));
  else if (method == "redundant") {
    Mat Aseq;
    PetscCall(MatCreateRedundantMatrix(fom.A, size, MPI_COMM_NULL, MAT_INITIAL_MATRIX, &Aseq));
    PetscCall(MatSetOption(Aseq, MAT_SPD, PETSC_TRUE));
    PetscCall(ComplianceBySchur(Aseq, D, &G)); // every rank, same data: the same G everywhere
    PetscCall(MatDestroy(&Aseq));
  } else PetscCall(ComplianceBySolves(fom, D, &G));
  PetscCall(PetscLogEventEnd(CMP_Compute, 0, 0, 0, 0));
  PetscCall(PetscTime(&t1));
  seconds = t1 - t0;
  PetscFunctionReturn(0);
}

} // namespace rbc
