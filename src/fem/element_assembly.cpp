// src/fem/element_assembly.cpp: element-by-element assembly of linear elasticity on affine simplices
// (the tables, the preallocated pattern, A, the Dirichlet lifting, the energy, the cell von Mises stress).
// See element_assembly.hpp.
#include "rbcontact/element_assembly.hpp"
#include <petscds.h>
#include <algorithm>
#include <cmath>

namespace rbc {

static PetscLogEvent EA_Setup = 0, EA_Matrix = 0, EA_Lifting = 0, EA_Energy = 0, EA_VonMises = 0;

void PullBackTensor(PetscInt dim, const PetscReal *T, const PetscReal *M, PetscReal scale, PetscReal *out)
{
  const PetscInt d = dim;
  for (PetscInt c = 0; c < d; ++c)
    for (PetscInt al = 0; al < d; ++al)
      for (PetscInt e = 0; e < d; ++e)
        for (PetscInt be = 0; be < d; ++be) {
          PetscReal s = 0;
          for (PetscInt a = 0; a < d; ++a)
            for (PetscInt b = 0; b < d; ++b) s += T[((c * d + a) * d + e) * d + b] * M[al * d + a] * M[be * d + b];
          out[((c * d + al) * d + e) * d + be] = scale * s;
        }
}

PetscReal VonMisesStress(PetscInt dim, const PetscReal *gr, PetscReal L, PetscReal G, const PetscReal *Ginv)
{
  PetscReal s[3][3] = {{0}}, tr = 0, gx[9];
  for (PetscInt c = 0; c < dim; ++c)
    for (PetscInt d = 0; d < dim; ++d) {
      gx[c * dim + d] = 0;
      for (PetscInt k = 0; k < dim; ++k) gx[c * dim + d] += gr[c * dim + k] * Ginv[k * dim + d];
    }
  for (PetscInt d = 0; d < dim; ++d) tr += gx[d * dim + d];
  for (PetscInt c = 0; c < dim; ++c)
    for (PetscInt d = 0; d < dim; ++d) s[c][d] = G * (gx[c * dim + d] + gx[d * dim + c]) + (c == d ? L * tr : 0);
  if (dim == 2) s[2][2] = L * tr; // plane strain
  const PetscReal j2 = 0.5 * ((s[0][0] - s[1][1]) * (s[0][0] - s[1][1]) + (s[1][1] - s[2][2]) * (s[1][1] - s[2][2]) + (s[2][2] - s[0][0]) * (s[2][2] - s[0][0])) + 3 * (s[0][1] * s[0][1] + s[1][2] * s[1][2] + s[0][2] * s[0][2]);
  return std::sqrt(j2);
}

ElementAssembler::~ElementAssembler()
{
  (void)MatDestroy(&pattern_);
  (void)DMDestroy(&dm_);
}

PetscErrorCode ElementAssembler::Setup(DM dm)
{
  PetscSection    lsec, gsec;
  PetscDS         ds;
  PetscFE         fe;
  PetscQuadrature q;
  PetscTabulation tab;
  PetscInt        qdim, qNc, nq, Nc;
  const PetscReal *qpoints, *qweights;

  PetscFunctionBeginUser;
  if (!EA_Setup) {
    PetscCall(PetscLogEventRegister("RBCElemSetup", DM_CLASSID, &EA_Setup));
    PetscCall(PetscLogEventRegister("RBCElemMatrix", DM_CLASSID, &EA_Matrix));
    PetscCall(PetscLogEventRegister("RBCElemLifting", DM_CLASSID, &EA_Lifting));
    PetscCall(PetscLogEventRegister("RBCElemEnergy", DM_CLASSID, &EA_Energy));
    PetscCall(PetscLogEventRegister("RBCElemVonMises", DM_CLASSID, &EA_VonMises));
  }
  PetscCall(PetscLogEventBegin(EA_Setup, 0, 0, 0, 0));
  PetscCall(MatDestroy(&pattern_));
  PetscCall(DMDestroy(&dm_));
  dm_ = dm;
  PetscCall(PetscObjectReference((PetscObject)dm_));
  PetscCall(DMGetDimension(dm, &dim_));
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart_, &cEnd_));
  PetscCall(DMGetLocalSection(dm, &lsec));
  PetscCall(DMGetGlobalSection(dm, &gsec));
  PetscCall(DMGetDS(dm, &ds));
  PetscCall(PetscDSGetDiscretization(ds, 0, (PetscObject *)&fe));
  PetscCall(PetscFEGetDimension(fe, &nb_));
  PetscCall(PetscFEGetNumComponents(fe, &Nc));
  PetscCheck(Nc == dim_, PetscObjectComm((PetscObject)dm), PETSC_ERR_PLIB, "Element assembly: the field has %" PetscInt_FMT " components in %" PetscInt_FMT "D", Nc, dim_);

  // Reference integrals from PetscFE's own tabulation (its basis order; its quadrature integrates the
  // degree-2k products exactly: Gauss-Jacobi with k+1 points per direction).
  PetscCall(PetscFEGetQuadrature(fe, &q));
  PetscCall(PetscQuadratureGetData(q, &qdim, &qNc, &nq, &qpoints, &qweights));
  PetscCall(PetscFEGetCellTabulation(fe, 1, &tab));
  const PetscReal *B = tab->T[0], *D = tab->T[1]; // B[(q nb + i) Nc + c], D[((q nb + i) Nc + c) dim + a]
  const PetscInt   d = dim_, nb = nb_;
  comp_.assign(nb, -1);
  for (PetscInt i = 0; i < nb; ++i) {
    PetscReal best = 0;
    for (PetscInt c = 0; c < Nc; ++c) {
      PetscReal s = 0;
      for (PetscInt p = 0; p < nq; ++p) {
        s += std::abs(B[(p * nb + i) * Nc + c]);
        for (PetscInt a = 0; a < d; ++a) s += std::abs(D[((p * nb + i) * Nc + c) * d + a]);
      }
      if (s > best) { best = s; comp_[i] = c; }
    }
    for (PetscInt c = 0; c < Nc; ++c) // a vector Lagrange basis function has one nonzero component
      if (c != comp_[i])
        for (PetscInt p = 0; p < nq; ++p) PetscCheck(B[(p * nb + i) * Nc + c] == 0.0, PETSC_COMM_SELF, PETSC_ERR_SUP, "Element assembly: basis function %" PetscInt_FMT " has several components", i);
  }
  gradInt_.assign((size_t)nb * nb * d * d, 0.0);
  massInt_.assign((size_t)nb * nb, 0.0);
  for (PetscInt p = 0; p < nq; ++p)
    for (PetscInt i = 0; i < nb; ++i)
      for (PetscInt j = 0; j < nb; ++j) {
        const PetscReal *gi = &D[((p * nb + i) * Nc + comp_[i]) * d], *gj = &D[((p * nb + j) * Nc + comp_[j]) * d];
        PetscReal       *g  = &gradInt_[((size_t)i * nb + j) * d * d];
        for (PetscInt a = 0; a < d; ++a)
          for (PetscInt b = 0; b < d; ++b) g[a * d + b] += qweights[p] * gi[a] * gj[b];
        if (comp_[i] == comp_[j]) massInt_[(size_t)i * nb + j] += qweights[p] * B[(p * nb + i) * Nc + comp_[i]] * B[(p * nb + j) * Nc + comp_[j]];
      }
  qWeight_.assign(qweights, qweights + nq);
  qDer_.assign((size_t)nq * nb * d, 0.0);
  for (PetscInt p = 0; p < nq; ++p)
    for (PetscInt i = 0; i < nb; ++i)
      for (PetscInt a = 0; a < d; ++a) qDer_[((size_t)p * nb + i) * d + a] = D[((p * nb + i) * Nc + comp_[i]) * d + a];

  // Per-cell tables: closure indices (global as DMPlexMatSetClosure uses them: constrained dofs
  // negative; local: offsets in the local vector, closure order) and the affine geometry.
  const PetscInt ncell = cEnd_ - cStart_;
  gidx_.assign((size_t)ncell * nb, -1);
  lidx_.assign((size_t)ncell * nb, -1);
  invJ_.assign((size_t)ncell * d * d, 0.0);
  detJ_.assign(ncell, 0.0);
  liftCells_.clear();
  for (PetscInt c = cStart_; c < cEnd_; ++c) {
    PetscInt  n, *idx = NULL;
    PetscReal v0[3], J[9], iJ[9], dJ;
    PetscCall(DMPlexGetClosureIndices(dm, lsec, gsec, c, PETSC_TRUE, &n, &idx, NULL, NULL));
    PetscCheck(n == nb, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Element assembly: cell %" PetscInt_FMT " has %" PetscInt_FMT " closure dofs, the element %" PetscInt_FMT, c, n, nb);
    bool lift = false;
    for (PetscInt k = 0; k < nb; ++k) {
      gidx_[(size_t)(c - cStart_) * nb + k] = idx[k];
      lift = lift || idx[k] < 0;
    }
    PetscCall(DMPlexRestoreClosureIndices(dm, lsec, gsec, c, PETSC_TRUE, &n, &idx, NULL, NULL));
    if (lift) liftCells_.push_back(c);
    PetscInt *pts = NULL, npts, k = 0;
    PetscCall(DMPlexGetTransitiveClosure(dm, c, PETSC_TRUE, &npts, &pts));
    for (PetscInt t = 0; t < npts; ++t) {
      PetscInt dof, off;
      PetscCall(PetscSectionGetDof(lsec, pts[2 * t], &dof));
      PetscCall(PetscSectionGetOffset(lsec, pts[2 * t], &off));
      for (PetscInt e = 0; e < dof && k < nb; ++e) lidx_[(size_t)(c - cStart_) * nb + k++] = off + e;
    }
    PetscCall(DMPlexRestoreTransitiveClosure(dm, c, PETSC_TRUE, &npts, &pts));
    PetscCheck(k == nb, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Element assembly: cell %" PetscInt_FMT " has %" PetscInt_FMT " local closure dofs, the element %" PetscInt_FMT, c, k, nb);
    PetscCall(DMPlexComputeCellGeometryAffineFEM(dm, c, v0, J, iJ, &dJ));
    for (PetscInt e = 0; e < d * d; ++e) invJ_[(size_t)(c - cStart_) * d * d + e] = iJ[e];
    detJ_[c - cStart_] = std::abs(dJ);
  }
  PetscCall(CreatePattern());
  PetscCall(PetscLogEventEnd(EA_Setup, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

// The nonzero pattern from the closure tables, kept with zero values and duplicated by every assembly.
// Each rank lists, for every row its cells touch, the columns of those cells (deduplicated through a
// marker on the local-vector index); the lists of rows owned by another rank (points on the partition
// boundary) go to their owner, which merges them: the exact pattern, set in one call from its CSR.
PetscErrorCode ElementAssembler::CreatePattern()
{
  PetscInt    nloc, N, rstart, nlv;
  PetscMPIInt size;
  Vec         g, l;
  MPI_Comm    comm = PetscObjectComm((PetscObject)dm_);

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(DMGetGlobalVector(dm_, &g));
  PetscCall(VecGetLocalSize(g, &nloc));
  PetscCall(VecGetSize(g, &N));
  PetscCall(VecGetOwnershipRange(g, &rstart, NULL));
  PetscCall(DMRestoreGlobalVector(dm_, &g));
  PetscCall(DMGetLocalVector(dm_, &l));
  PetscCall(VecGetLocalSize(l, &nlv));
  PetscCall(DMRestoreLocalVector(dm_, &l));
  const PetscInt ncell = cEnd_ - cStart_, nb = nb_;
  // global row of every local-vector entry (-1: constrained or untouched) and the cells around it
  std::vector<PetscInt> rowOf(nlv, -1), start(nlv + 1, 0), cells((size_t)ncell * nb);
  for (size_t k = 0; k < lidx_.size(); ++k) {
    rowOf[lidx_[k]] = gidx_[k];
    ++start[lidx_[k] + 1];
  }
  for (PetscInt i = 0; i < nlv; ++i) start[i + 1] += start[i];
  {
    std::vector<PetscInt> fill(start.begin(), start.end() - 1);
    for (PetscInt c = 0; c < ncell; ++c)
      for (PetscInt k = 0; k < nb; ++k) cells[fill[lidx_[(size_t)c * nb + k]]++] = c;
  }
  // columns of every touched row, owned rows in ownedCols (by local row), the others packed per owner
  std::vector<PetscInt>              ranges(size + 1, 0);
  PetscCallMPI(MPI_Allgather(&rstart, 1, MPIU_INT, ranges.data(), 1, MPIU_INT, comm));
  ranges[size] = N;
  std::vector<std::vector<PetscInt>> ownedCols(nloc), sendTo(size);
  std::vector<PetscInt>              mark(nlv, -1), cols;
  for (PetscInt i = 0; i < nlv; ++i) {
    if (rowOf[i] < 0) continue;
    cols.clear();
    for (PetscInt t = start[i]; t < start[i + 1]; ++t) {
      const PetscInt c = cells[t];
      for (PetscInt k = 0; k < nb; ++k) {
        const PetscInt li = lidx_[(size_t)c * nb + k], gi = gidx_[(size_t)c * nb + k];
        if (gi < 0 || mark[li] == i) continue;
        mark[li] = i;
        cols.push_back(gi);
      }
    }
    const PetscInt r = rowOf[i];
    if (r >= rstart && r < rstart + nloc) ownedCols[r - rstart].insert(ownedCols[r - rstart].end(), cols.begin(), cols.end());
    else {
      const PetscMPIInt q = (PetscMPIInt)(std::upper_bound(ranges.begin(), ranges.end(), r) - ranges.begin() - 1);
      auto             &buf = sendTo[q];
      buf.push_back(r);
      buf.push_back((PetscInt)cols.size());
      buf.insert(buf.end(), cols.begin(), cols.end());
    }
  }
  if (size > 1) {
    std::vector<int> scount(size), rcount(size), sdispl(size + 1, 0), rdispl(size + 1, 0);
    for (int q = 0; q < size; ++q) scount[q] = (int)sendTo[q].size();
    PetscCallMPI(MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, comm));
    for (int q = 0; q < size; ++q) {
      sdispl[q + 1] = sdispl[q] + scount[q];
      rdispl[q + 1] = rdispl[q] + rcount[q];
    }
    std::vector<PetscInt> sbuf(sdispl[size]), rbuf(rdispl[size]);
    for (int q = 0; q < size; ++q) std::copy(sendTo[q].begin(), sendTo[q].end(), sbuf.begin() + sdispl[q]);
    PetscCallMPI(MPI_Alltoallv(sbuf.data(), scount.data(), sdispl.data(), MPIU_INT, rbuf.data(), rcount.data(), rdispl.data(), MPIU_INT, comm));
    for (size_t t = 0; t < rbuf.size();) {
      const PetscInt r = rbuf[t], n = rbuf[t + 1];
      PetscCheck(r >= rstart && r < rstart + nloc, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Element assembly: row %" PetscInt_FMT " sent to a rank that does not own it", r);
      ownedCols[r - rstart].insert(ownedCols[r - rstart].end(), rbuf.begin() + t + 2, rbuf.begin() + t + 2 + n);
      t += 2 + n;
    }
  }
  std::vector<PetscInt> rowStart(nloc + 1, 0), colIdx; // CSR of the owned rows, global column indices
  for (PetscInt r = 0; r < nloc; ++r) {
    auto &c = ownedCols[r];
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    rowStart[r + 1] = rowStart[r] + (PetscInt)c.size();
  }
  colIdx.reserve(rowStart[nloc]);
  for (auto &c : ownedCols) {
    colIdx.insert(colIdx.end(), c.begin(), c.end());
    std::vector<PetscInt>().swap(c);
  }
  // the structure (and zero values) in one call; the call that does not match the type is ignored
  PetscCall(MatCreate(comm, &pattern_));
  PetscCall(MatSetType(pattern_, MATAIJ));
  PetscCall(MatSetSizes(pattern_, nloc, nloc, N, N));
  PetscCall(MatSeqAIJSetPreallocationCSR(pattern_, rowStart.data(), colIdx.data(), NULL));
  PetscCall(MatMPIAIJSetPreallocationCSR(pattern_, rowStart.data(), colIdx.data(), NULL));
  PetscCall(MatSetOption(pattern_, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE));
  PetscCall(MatSetDM(pattern_, dm_));
  PetscFunctionReturn(0);
}

// Ke[i nb + j] = |det J| sum_{alpha,beta} T'[ci alpha cj beta] int dphi_i/dxi_alpha dphi_j/dxi_beta
//              + m |det J| int phi_i phi_j,  T'[c alpha e beta] = sum_{a,b} T[c a e b] invJ[alpha a] invJ[beta b].
void ElementAssembler::ElementMatrix(const Coefficients &k, PetscInt c, PetscReal *Ke) const
{
  const PetscInt   d = dim_, nb = nb_, body = (*k.cellBody)[c - cStart_];
  const PetscReal *T = k.tensor[body], *iJ = &invJ_[(size_t)(c - cStart_) * d * d], J = detJ_[c - cStart_];
  PetscReal        Tp[81];
  PullBackTensor(d, T, iJ, J, Tp);
  const PetscReal m = k.mass[body] * J;
  for (PetscInt i = 0; i < nb; ++i)
    for (PetscInt j = 0; j < nb; ++j) {
      const PetscReal *g  = &gradInt_[((size_t)i * nb + j) * d * d];
      const PetscReal *tp = &Tp[((comp_[i] * d) * d + comp_[j]) * d];
      PetscReal        s  = 0;
      for (PetscInt al = 0; al < d; ++al)
        for (PetscInt be = 0; be < d; ++be) s += tp[al * d * d + be] * g[al * d + be];
      if (m != 0) s += m * massInt_[(size_t)i * nb + j];
      Ke[i * nb + j] = s;
    }
}

PetscErrorCode ElementAssembler::AssembleMatrix(const Coefficients &k, Mat *A) const
{
  std::vector<PetscScalar> Ke((size_t)nb_ * nb_);

  PetscFunctionBeginUser;
  PetscCheck(Ready(), PETSC_COMM_SELF, PETSC_ERR_ORDER, "ElementAssembler: Setup() first");
  PetscCall(PetscLogEventBegin(EA_Matrix, 0, 0, 0, 0));
  if (!*A) PetscCall(MatDuplicate(pattern_, MAT_DO_NOT_COPY_VALUES, A));
  else PetscCall(MatZeroEntries(*A));
  for (PetscInt c = cStart_; c < cEnd_; ++c) {
    ElementMatrix(k, c, Ke.data());
    const PetscInt *ix = &gidx_[(size_t)(c - cStart_) * nb_];
    PetscCall(MatSetValues(*A, nb_, ix, nb_, ix, Ke.data(), ADD_VALUES));
  }
  PetscCall(MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscLogEventEnd(EA_Matrix, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode ElementAssembler::AddLifting(const Coefficients &k, Vec uloc, Vec f) const
{
  std::vector<PetscScalar> Ke((size_t)nb_ * nb_), r(nb_);
  const PetscScalar       *u;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(EA_Lifting, 0, 0, 0, 0));
  PetscCall(VecSetOption(f, VEC_IGNORE_NEGATIVE_INDICES, PETSC_TRUE)); // the constrained rows
  PetscCall(VecGetArrayRead(uloc, &u));
  for (PetscInt c : liftCells_) {
    const PetscInt *ix = &gidx_[(size_t)(c - cStart_) * nb_], *lx = &lidx_[(size_t)(c - cStart_) * nb_];
    ElementMatrix(k, c, Ke.data());
    for (PetscInt i = 0; i < nb_; ++i) {
      PetscScalar s = 0;
      if (ix[i] >= 0)
        for (PetscInt j = 0; j < nb_; ++j)
          if (ix[j] < 0) s -= Ke[i * nb_ + j] * u[lx[j]];
      r[i] = s;
    }
    PetscCall(VecSetValues(f, nb_, ix, r.data(), ADD_VALUES));
  }
  PetscCall(VecRestoreArrayRead(uloc, &u));
  PetscCall(VecAssemblyBegin(f));
  PetscCall(VecAssemblyEnd(f));
  PetscCall(PetscLogEventEnd(EA_Lifting, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode ElementAssembler::Energy(const Coefficients &k, Vec uloc, PetscReal *energy) const
{
  std::vector<PetscScalar> Ke((size_t)nb_ * nb_);
  const PetscScalar       *u;
  PetscReal                e = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(EA_Energy, 0, 0, 0, 0));
  PetscCall(VecGetArrayRead(uloc, &u));
  for (PetscInt c = cStart_; c < cEnd_; ++c) {
    const PetscInt *lx = &lidx_[(size_t)(c - cStart_) * nb_];
    ElementMatrix(k, c, Ke.data());
    for (PetscInt i = 0; i < nb_; ++i) {
      PetscScalar s = 0;
      for (PetscInt j = 0; j < nb_; ++j) s += Ke[i * nb_ + j] * u[lx[j]];
      e += PetscRealPart(u[lx[i]] * s);
    }
  }
  PetscCall(VecRestoreArrayRead(uloc, &u));
  e *= 0.5;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &e, 1, MPIU_REAL, MPIU_SUM, PetscObjectComm((PetscObject)dm_)));
  *energy = e;
  PetscCall(PetscLogEventEnd(EA_Energy, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

PetscErrorCode ElementAssembler::VonMises(const Coefficients &k, Vec uloc, std::vector<PetscReal> *vm) const
{
  const PetscScalar *u;
  const PetscInt     d = dim_, nb = nb_, nq = (PetscInt)qWeight_.size();

  PetscFunctionBeginUser;
  PetscCheck(Ready(), PETSC_COMM_SELF, PETSC_ERR_ORDER, "ElementAssembler: Setup() first");
  PetscCheck(k.lame.size() == k.tensor.size(), PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "ElementAssembler::VonMises: %zu bodies with Lame data, %zu with tensors", k.lame.size(), k.tensor.size());
  PetscCall(PetscLogEventBegin(EA_VonMises, 0, 0, 0, 0));
  PetscReal wsum = 0;
  for (PetscInt p = 0; p < nq; ++p) wsum += qWeight_[p];
  vm->assign(cEnd_ - cStart_, 0.0);
  PetscCall(VecGetArrayRead(uloc, &u));
  for (PetscInt c = cStart_; c < cEnd_; ++c) {
    const PetscInt  *lx = &lidx_[(size_t)(c - cStart_) * nb];
    const PetscReal *iJ = &invJ_[(size_t)(c - cStart_) * d * d], *lame = k.lame[(*k.cellBody)[c - cStart_]];
    const PetscReal  L = lame[0], G = lame[1], *Ginv = lame + 2;
    PetscReal        mean = 0;
    for (PetscInt p = 0; p < nq; ++p) {
      PetscReal gr[9] = {0}; // grad_xr u [c][b]
      for (PetscInt i = 0; i < nb; ++i) {
        const PetscReal *D = &qDer_[((size_t)p * nb + i) * d], ui = PetscRealPart(u[lx[i]]);
        for (PetscInt b = 0; b < d; ++b) {
          PetscReal db = 0;
          for (PetscInt a = 0; a < d; ++a) db += D[a] * iJ[a * d + b];
          gr[comp_[i] * d + b] += ui * db;
        }
      }
      mean += qWeight_[p] * VonMisesStress(d, gr, L, G, Ginv);
    }
    (*vm)[c - cStart_] = mean / wsum; // |det J| is constant on the cell: it cancels
  }
  PetscCall(VecRestoreArrayRead(uloc, &u));
  PetscCall(PetscLogEventEnd(EA_VonMises, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

} // namespace rbc
