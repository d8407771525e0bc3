// src/offline/offline_rom.cpp: the last offline step: from the snapshots and the bases, the online data
// of the ROM file (docs/eim.md, docs/rom_file.md): reduced affine terms A^_q = V'A_qV, f^_q = V'f_q;
// the full contact patch on the support of the dual basis and P = W' Psi; snapshots of the contact map
// kappa and the gap gamma at the training solutions and at the iterates of the reduced Kacanov loop
// with exact contact terms; their EIM (or their exact constant form when they do not vary); the patch
// restricted to the facets around the EIM points; warm starts. Every rank of the group computes the
// same (deterministic) data; world rank 0 writes it.
#include "rbcontact/options_files.hpp"
#include "rbcontact/offline_rom.hpp"
#include "rbcontact/kacanov.hpp"
#include "rbcontact/rom_fields.hpp"
#include "rbcontact/eim.hpp"
#include "rbcontact/empirical_cubature.hpp"
#include "rbcontact/contact_states.hpp"
#include "rbcontact/eim_selection.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/training_set.hpp"
#include <slepcbv.h>
#include <algorithm>
#include <cmath>
#include <functional>
#include <set>

namespace rbc {

// OFF_Hyper: the hyper-reduction of the contact terms (the contact states, the cubature fit and/or the EIM, the patch
// self-check; it was named RBCEIM until 2026-12-03 though it also timed the cubature)
static PetscLogEvent OFF_Hyper = 0, OFF_Affine = 0;

// Position of p in list, appended if absent.
static PetscInt Intern(std::vector<PetscInt> *list, PetscInt p)
{
  auto it = std::find(list->begin(), list->end(), p);
  if (it != list->end()) return (PetscInt)(it - list->begin());
  list->push_back(p);
  return (PetscInt)list->size() - 1;
}

// Is every snapshot (n entries; the m held on this rank, by S(j)) equal to the first one of all, ref (to round-off)?
// The spread max |S_j - ref| / max |S| over the snapshots of every rank.
static PetscErrorCode Constant(MPI_Comm comm, const std::function<const PetscReal *(PetscInt)> &S, const PetscReal *ref, size_t n, PetscInt m, PetscReal *spread, bool *constant)
{
  PetscReal md[2] = {0, 0}; // max |S|, max |S - ref|
  PetscFunctionBeginUser;
  for (size_t i = 0; i < n; ++i) md[0] = std::max(md[0], std::abs(ref[i]));
  for (PetscInt j = 0; j < m; ++j) {
    const PetscReal *x = S(j);
    for (size_t i = 0; i < n; ++i) {
      md[0] = std::max(md[0], std::abs(x[i]));
      md[1] = std::max(md[1], std::abs(x[i] - ref[i]));
    }
  }
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, md, 2, MPIU_REAL, MPIU_MAX, comm));
  *spread   = md[0] > 0 ? md[1] / md[0] : 0;
  *constant = *spread <= 1e-13;
  PetscFunctionReturn(0);
}

// x summed over the ranks, the same bits on every rank (reduced on rank 0, then broadcast: an all-reduce may round
// differently on different ranks, and every rank must take the same cubature steps); in pieces below MPI's int counts.
static PetscErrorCode SumOnEveryRank(MPI_Comm comm, PetscReal *x, size_t n)
{
  PetscMPIInt rank;
  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  const size_t piece = (size_t)1 << 26;
  for (size_t i0 = 0; i0 < n; i0 += piece) {
    const PetscMPIInt c = (PetscMPIInt)std::min(piece, n - i0);
    PetscCallMPI(MPI_Reduce(rank == 0 ? MPI_IN_PLACE : x + i0, x + i0, c, MPIU_REAL, MPIU_SUM, 0, comm));
    PetscCallMPI(MPI_Bcast(x + i0, c, MPIU_REAL, 0, comm));
  }
  PetscFunctionReturn(0);
}

// The points' hit master facets of every rank's states (union).
static PetscErrorCode UniteHits(MPI_Comm comm, std::vector<std::set<PetscInt>> *hits)
{
  PetscMPIInt size;
  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  std::vector<PetscInt> mine; // (point, facet) pairs
  for (size_t p = 0; p < hits->size(); ++p)
    for (PetscInt f : (*hits)[p]) mine.insert(mine.end(), {(PetscInt)p, f});
  PetscMPIInt              n = (PetscMPIInt)mine.size();
  std::vector<PetscMPIInt> counts(size), displs(size + 1, 0);
  PetscCallMPI(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm));
  for (PetscMPIInt r = 0; r < size; ++r) displs[r + 1] = displs[r] + counts[r];
  std::vector<PetscInt> all(displs[size]);
  PetscCallMPI(MPI_Allgatherv(mine.data(), n, MPIU_INT, all.data(), counts.data(), displs.data(), MPIU_INT, comm));
  for (size_t i = 0; i < all.size(); i += 2) (*hits)[all[i]].insert(all[i + 1]);
  PetscFunctionReturn(0);
}

// The per-state values of every rank, in rank order (the states are split in contiguous blocks).
static PetscErrorCode GatherStates(MPI_Comm comm, std::vector<PetscReal> *v)
{
  PetscMPIInt size;
  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscMPIInt              n = (PetscMPIInt)v->size();
  std::vector<PetscMPIInt> counts(size), displs(size + 1, 0);
  PetscCallMPI(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm));
  for (PetscMPIInt r = 0; r < size; ++r) displs[r + 1] = displs[r] + counts[r];
  std::vector<PetscReal> all(displs[size]);
  PetscCallMPI(MPI_Allgatherv(v->data(), n, MPIU_REAL, all.data(), counts.data(), displs.data(), MPIU_REAL, comm));
  *v = std::move(all);
  PetscFunctionReturn(0);
}

PetscErrorCode HyperChoiceFromOptions(MPI_Comm comm, HyperChoice *h)
{
  char            buf[64] = "ecsw";
  CubatureOptions co;

  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, NULL, "Hyper-reduction of the contact terms (offline)", "HyperChoiceFromOptions");
  PetscCall(PetscOptionsString("-rom_hyper", "methods to build: ecsw, eim, ecsw,eim or eim,ecsw (the first is the online default)", "", buf, buf, sizeof buf, NULL));
  PetscOptionsEnd();
  const std::string s(buf);
  if (s == "ecsw") *h = {false, true, true};
  else if (s == "eim") *h = {true, false, false};
  else if (s == "ecsw,eim") *h = {true, true, true};
  else if (s == "eim,ecsw") *h = {true, true, false};
  else SETERRQ(comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "-rom_hyper: unknown value '%s' (ecsw, eim, ecsw,eim or eim,ecsw: the first is the online default)", buf);
  PetscCall(CubatureOptionsFromOptions(comm, "ecsw_", &co));
  PetscFunctionReturn(0);
}

PetscErrorCode ContactPatchOptions(MPI_Comm comm, PetscInt *nsub, PetscInt *rings)
{
  PetscInt n = 4, r = 2;

  PetscFunctionBeginUser;
  PetscCall(CheckValuesGiven(comm, "eim_", {"quadrature_subdivisions", "patch_rings"})); // (given without a value: the default, without a word)
  PetscOptionsBegin(comm, "eim_", "The contact patch of the hyper-reduction (offline)", "ContactPatchOptions");
  PetscCall(PetscOptionsInt("-quadrature_subdivisions", "pieces per slave facet of the candidate points (each with the contact Gauss rule)", "", n, &n, NULL));
  PetscCall(PetscOptionsInt("-patch_rings", "rings of master facets around those the points projected onto, kept online", "", r, &r, NULL));
  PetscOptionsEnd();
  PetscCheck(n >= 1 && n <= 64, comm, PETSC_ERR_ARG_OUTOFRANGE, "-eim_quadrature_subdivisions %" PetscInt_FMT " out of range [1, 64]", n);
  PetscCheck(r >= 0 && r <= 20, comm, PETSC_ERR_ARG_OUTOFRANGE, "-eim_patch_rings %" PetscInt_FMT " out of range [0, 20]", r);
  if (nsub) *nsub = n;
  if (rings) *rings = r;
  PetscFunctionReturn(0);
}

PetscErrorCode BuildExactReducedModel(MPI_Comm world, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, BV V, const std::vector<double> &modes, PetscInt Npod, PetscInt nsup, const DualBasisResult &dual, ReducedModel *rm, std::shared_ptr<ContactPatch> *fullOut, std::vector<PetscReal> *Pout, PetscInt *nsubOut)
{
  PetscFunctionBeginUser;
  if (!OFF_Affine) PetscCall(PetscLogEventRegister("RBCReducedAffine", DM_CLASSID, &OFF_Affine));
  PetscCheck(fom.scene.contact, world, PETSC_ERR_SUP, "offline: the online ROM needs a contact scene (-contact_slave, -contact_master); use -offline_stop bases for the bases only");
  PetscCheck(fom.useAffine, world, PETSC_ERR_SUP, "offline: the scene has no affine decomposition (see the fom report's affine_terms)");
  const PetscInt N = Npod + nsup, R = dual.W.cols, Rfom = dual.W.rows;
  // --- reduced affine terms
  PetscCall(PetscLogEventBegin(OFF_Affine, 0, 0, 0, 0));
  rm->dim   = fom.elas.dim;
  rm->Nfull = N;
  rm->Npod  = Npod;
  rm->nsup  = nsup;
  rm->Rfull = R;
  PetscCall(rm->par.FromFOM(fom.elas, fom.map, fom.affine));
  rm->Aq.assign(fom.affine.Aq.size() * N * N, 0.0);
  rm->fq.assign(fom.affine.fq.size() * N, 0.0);
  {
    // explicit products (the BV carries the POD inner product: its BVDot would include it)
    std::vector<Vec> cols(N);
    Vec              Av;
    for (PetscInt i = 0; i < N; ++i) {
      Vec c;
      PetscCall(BVGetColumn(V, i, &c));
      PetscCall(VecDuplicate(c, &cols[i]));
      PetscCall(VecCopy(c, cols[i]));
      PetscCall(BVRestoreColumn(V, i, &c));
    }
    PetscCall(VecDuplicate(cols[0], &Av));
    std::vector<PetscScalar> dots(N);
    for (size_t q = 0; q < fom.affine.Aq.size(); ++q)
      for (PetscInt j = 0; j < N; ++j) {
        PetscCall(MatMult(fom.affine.Aq[q], cols[j], Av));
        PetscCall(VecMDot(Av, N, cols.data(), dots.data()));
        for (PetscInt i = 0; i < N; ++i) rm->Aq[(q * N + i) * N + j] = PetscRealPart(dots[i]);
      }
    for (size_t q = 0; q < fom.affine.Aq.size(); ++q) // exact symmetry
      for (PetscInt i = 0; i < N; ++i)
        for (PetscInt j = 0; j < i; ++j) {
          const PetscReal a = 0.5 * (rm->Aq[(q * N + i) * N + j] + rm->Aq[(q * N + j) * N + i]);
          rm->Aq[(q * N + i) * N + j] = rm->Aq[(q * N + j) * N + i] = a;
        }
    for (size_t q = 0; q < fom.affine.fq.size(); ++q) {
      PetscCall(VecMDot(fom.affine.fq[q], N, cols.data(), dots.data()));
      for (PetscInt i = 0; i < N; ++i) rm->fq[q * N + i] = PetscRealPart(dots[i]);
    }
    PetscCall(VecDestroy(&Av));
    for (auto &c : cols) PetscCall(VecDestroy(&c));
  }
  PetscCall(PetscLogEventEnd(OFF_Affine, 0, 0, 0, 0));

  // --- the full contact patch on the support of the dual basis (Dirichlet values at the default mu)
  PetscInt &nsub = *nsubOut;
  PetscCall(ContactPatchOptions(world, &nsub, NULL));
  std::vector<double> Wt((size_t)R * Rfom);
  for (PetscInt k = 0; k < R; ++k)
    for (PetscInt i = 0; i < Rfom; ++i) Wt[(size_t)k * Rfom + i] = dual.W(i, k);
  std::shared_ptr<ContactPatch> &full = *fullOut;
  std::vector<PetscReal>        &P    = *Pout;
  PetscCall(BuildFullContact(fom, cmap, order, modes, N, Wt, R, nsub, &full, &P));
  {
    bool bcParam = false, uDnonzero = false;
    for (const auto &d : fom.scene.dirichlet) bcParam = bcParam || d.param >= 0;
    for (PetscReal v : full->uD) uDnonzero = uDnonzero || v != 0;
    PetscCheck(!(bcParam && uDnonzero), world, PETSC_ERR_SUP, "offline: a parametrized Dirichlet condition (-param_bc_*) acts on the contact surfaces; the reduced contact map does not support it yet");
  }
  rm->dualGram.assign((size_t)R * R, 0.0);
  for (PetscInt a = 0; a < R; ++a)
    for (PetscInt b = 0; b < R; ++b)
      for (PetscInt i = 0; i < Rfom; ++i) rm->dualGram[(size_t)a * R + b] += dual.W(i, a) * dual.W(i, b);
  rm->SetExactContact(full, P);
  rm->SetContactMode(ReducedModel::ContactMode::Exact);
  PetscCall(rm->SetFromOptions()); // rom_kacanov_*, rom_qp_* (the truncation options are not for this step)
  PetscCall(rm->Truncate(-1, -1, -1, -1));
  PetscFunctionReturn(0);
}

// The lambda fit's metric (CubatureLambdaMetric) at the training solutions of the exact-contact ROM (rm's warm-start
// table): per solution, the exact reduced constraint, A^(mu_j) and the slave-mass Gram of W (CubatureLambdaWeights);
// kappa_s v_j from the states' terms and theta v_j (one value per patch dof), not from the Q x N blocks; withForce: the
// forces' part too (C_j per solution, their mean metric's factor). dropped: the solutions in contact whose metric did
// not factor.
static PetscErrorCode LambdaFitMetric(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const DualBasisResult &dual, ContactPatch *full, const ContactStates &cs, ReducedModel *rm, bool withForce, CubatureLambdaMetric *metric, PetscInt *dropped)
{
  const PetscInt N = rm->N(), R = rm->R(), nt = (PetscInt)(rm->warmL.size() / std::max<PetscInt>(R, 1));
  std::vector<PetscReal> wc, Kj((size_t)R * N), gj(R), Aj, fj;
  std::vector<std::vector<PetscReal>> C(nt);

  PetscFunctionBeginUser;
  PetscCheck(N == full->N && R == dual.W.cols, PetscObjectComm((PetscObject)fom.dm), PETSC_ERR_PLIB, "offline: the exact reduced model's sizes differ from the bases'");
  PetscCall(ReferenceSlaveMass(fom, cmap, order, &wc));
  const std::vector<PetscReal>    M    = SlaveMassGram(dual.W, wc);
  const size_t                    npar = rm->warmMu.size() / std::max<PetscInt>(nt, 1);
  const ReducedModel::ContactMode mode = rm->Mode();
  rm->SetContactMode(ReducedModel::ContactMode::Exact);
  metric->T.assign(nt, {});
  *dropped = 0;
  for (PetscInt j = 0; j < nt; ++j) {
    const std::vector<PetscReal> mu(rm->warmMu.begin() + j * npar, rm->warmMu.begin() + (j + 1) * npar);
    full->SetGeometry(&fom.map, mu);
    (void)rm->ContactTerms(mu, &rm->warmV[(size_t)j * N], Kj.data(), gj.data());
    rm->Operators(mu, &Aj, &fj);
    const PetscReal *lam = &rm->warmL[(size_t)j * R];
    if (CubatureLambdaWeights(R, N, Aj.data(), Kj.data(), lam, M, &metric->T[j], withForce ? &C[j] : nullptr) == 0 && std::any_of(lam, lam + R, [](PetscReal l) { return l > 0; })) ++*dropped;
  }
  rm->SetContactMode(mode);
  if (withForce) metric->forceRank = CubatureLambdaForceFactor(N, C, &metric->forceFactor);
  const size_t rows = full->theta.size() / std::max<PetscInt>(N, 1);
  auto         tv   = std::make_shared<std::vector<PetscReal>>((size_t)nt * rows, 0.0);
  for (PetscInt j = 0; j < nt; ++j)
    for (size_t i = 0; i < rows; ++i) {
      PetscReal t = 0;
      for (PetscInt n = 0; n < N; ++n) t += full->theta[i * N + n] * rm->warmV[(size_t)j * N + n];
      (*tv)[(size_t)j * rows + i] = t;
    }
  metric->kappaTimes = [&cs, tv, rows](PetscInt s, PetscInt j, PetscReal *y) { cs.KappaTimes(s, &(*tv)[(size_t)j * rows], y); };
  PetscFunctionReturn(0);
}

PetscErrorCode OfflineReducedModel(MPI_Comm world, ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const std::vector<Snapshot> &snaps, BV V, const std::vector<double> &modes, PetscInt Npod, PetscInt nsup, const DualBasisResult &dual, RomWriter *w, Report *rep, PetscInt nDefault, PetscInt rDefault, PetscReal ecswTol)
{
  PetscLogDouble t0, t1, t2;
  PetscMPIInt    wrank;
  ReducedModel   rm;

  PetscFunctionBeginUser;
  if (!OFF_Hyper) PetscCall(PetscLogEventRegister("RBCHyperReduction", DM_CLASSID, &OFF_Hyper));
  PetscCallMPI(MPI_Comm_rank(world, &wrank));
  const PetscInt N = Npod + nsup, R = dual.W.cols, m = (PetscInt)snaps.size();
  PetscCall(PetscTime(&t0));

  PetscInt                      nsub;
  std::shared_ptr<ContactPatch> full;
  std::vector<PetscReal>        P;
  PetscCall(BuildExactReducedModel(world, fom, cmap, order, V, modes, Npod, nsup, dual, &rm, &full, &P, &nsub));
  PetscCall(PetscLogEventBegin(OFF_Hyper, 0, 0, 0, 0));
  const PetscInt Q = full->NumPoints();
  rm.warmStart      = PETSC_FALSE;
  rm.loop.monitor   = PETSC_FALSE;
  rm.recordIterates = true;

  // --- snapshots of kappa (Q x N per evaluation) and gamma (Q): training solutions and the iterates
  // of the reduced Kacanov loop with the exact reduced contact terms. First the reduced solves (they list the
  // states), then the evaluations, kept by the points' terms (ContactStates: kappa's Q x N x states doubles were
  // the offline stage's largest object in 3D, 2.9 GB at 41k dofs, docs/rom3d.md).
  struct State {
    std::vector<PetscReal> mu, v; // v empty: the FOM training solution j
    PetscInt               j = -1;
  };
  std::vector<State>                states;
  std::vector<PetscReal>            kap((size_t)Q * N), gam(Q), U;
  std::vector<PetscInt>             all(Q), hit(Q);
  std::vector<std::set<PetscInt>>   hits(Q);
  PetscInt                          nRomIts = 0, maxRomIts = 0;
  PetscReal                         uDep = 0;
  for (PetscInt p = 0; p < Q; ++p) all[p] = p;
  auto addIterates = [&](const std::vector<PetscReal> &mu, const ReducedSolution &sol) {
    nRomIts += sol.iterations;
    maxRomIts = std::max(maxRomIts, sol.iterations);
    for (PetscInt it = 0; it < sol.iterations; ++it) states.push_back({mu, std::vector<PetscReal>(&sol.iterates[(size_t)it * N], &sol.iterates[(size_t)(it + 1) * N]), -1});
  };
  PetscInt nDuplicate = 0;
  for (PetscInt j = 0; j < m; ++j) {
    const auto &mu = snaps[j].mu;
    // A training parameter listed again adds nothing: its reduced solve would warm-start from its own
    // earlier copy and add other Kacanov iterates, so the cubature would depend on the repetition
    // (tests/hard_cases.py repeated_training). Its states and warm-start entry are taken once.
    bool repeated = false;
    for (PetscInt k = 0; k < j && !repeated; ++k) repeated = snaps[k].mu == mu;
    if (repeated) {
      ++nDuplicate;
      continue;
    }
    states.push_back({mu, {}, j});
    full->SetGeometry(&fom.map, mu);
    ReducedSolution sol;
    PetscCall(rm.Solve(mu, &sol));
    PetscCheck(sol.converged, world, PETSC_ERR_NOT_CONVERGED, "offline: the reduced model with exact contact terms fails at training parameter %" PetscInt_FMT ": %s", j, sol.message.c_str());
    addIterates(mu, sol);
    rm.warmMu.insert(rm.warmMu.end(), mu.begin(), mu.end());
    rm.warmV.insert(rm.warmV.end(), sol.v.begin(), sol.v.end());
    rm.warmL.insert(rm.warmL.end(), sol.lambda.begin(), sol.lambda.end());
  }
  // optional extra parameters for the EIM only (-eim_train_type ...): no FOM solve, the reduced loop
  // with exact contact terms is cheap, and its iterates widen what the EIM is trained on
  PetscBool extraSet = PETSC_FALSE;
  PetscInt  nExtra   = 0;
  PetscCall(PetscOptionsHasName(NULL, NULL, "-eim_train_type", &extraSet));
  if (extraSet) {
    ParameterSet extra;
    PetscCall(ParameterSetFromOptions(world, fom.scene.params, "eim_train_", &extra));
    for (const auto &mu : extra.points) {
      full->SetGeometry(&fom.map, mu);
      ReducedSolution sol;
      PetscCall(rm.Solve(mu, &sol));
      PetscCheck(sol.converged, world, PETSC_ERR_NOT_CONVERGED, "offline: the reduced model with exact contact terms fails at an -eim_train_ parameter: %s", sol.message.c_str());
      addIterates(mu, sol);
      states.push_back({mu, sol.v, -1});
      ++nExtra;
    }
  }
  // the contact evaluations of the states: split over the ranks in contiguous blocks when only the cubature needs
  // them (its Gram matrix is a sum over the states: each rank adds its own, SumOnEveryRank), whole on every rank when
  // the EIM's greedy needs every snapshot (docs/hyper_reduction.md, "Memory")
  HyperChoice hyper;
  PetscCall(HyperChoiceFromOptions(world, &hyper));
  PetscMPIInt wsize;
  PetscBool   spread = PETSC_TRUE;
  PetscCallMPI(MPI_Comm_size(world, &wsize));
  PetscOptionsBegin(world, "ecsw_", "Empirical cubature (offline)", "OfflineReducedModel");
  PetscCall(PetscOptionsBool("-distribute_states", "split the contact states' evaluations over the ranks (without the EIM)", "", spread, &spread, NULL));
  PetscOptionsEnd();
  const bool   distribute = spread && wsize > 1 && !hyper.eim;
  const size_t msAll = states.size(), k0 = distribute ? msAll * wrank / wsize : 0, k1 = distribute ? msAll * (wrank + 1) / wsize : msAll;
  ContactStates cs(*full, (PetscInt)(k1 - k0));
  // the first state (a training solution) on every rank: the reference of the constant-term test and of kappa's
  // dependence on u
  PetscCheck(!states.empty(), world, PETSC_ERR_PLIB, "offline: no contact state to fit the hyper-reduction on");
  std::vector<PetscReal> kap0((size_t)Q * N), gam0(Q);
  {
    const State &st = states[0];
    full->SetGeometry(&fom.map, st.mu);
    if (st.j >= 0) { // does kappa depend on the displacement? (compare with u = 0)
      std::vector<PetscReal> g0(Q), Z;
      full->NodalFromCanonical(std::vector<PetscReal>(snaps[st.j].u.size(), 0.0), &Z);
      full->SetNodal(Z);
      (void)full->Evaluate(all.data(), Q, kap.data(), g0.data(), nullptr);
      full->NodalFromCanonical(snaps[st.j].u, &U);
      full->SetNodal(U);
    } else full->SetReduced(st.v.data());
    (void)full->Evaluate(all.data(), Q, kap0.data(), gam0.data(), nullptr);
    PetscReal sc = 0;
    for (size_t i = 0; st.j >= 0 && i < kap0.size(); ++i) {
      uDep = std::max(uDep, std::abs(kap[i] - kap0[i]));
      sc   = std::max(sc, std::abs(kap0[i]));
    }
    uDep = sc > 0 ? uDep / sc : 0;
  }
  for (size_t k = k0; k < k1; ++k) {
    const State &st = states[k];
    if (k == k0 || st.mu != states[k - 1].mu) full->SetGeometry(&fom.map, st.mu);
    if (st.j >= 0) {
      full->NodalFromCanonical(snaps[st.j].u, &U);
      full->SetNodal(U);
    } else full->SetReduced(st.v.data());
    cs.Append(&hit);
    for (PetscInt p = 0; p < Q; ++p) hits[p].insert(hit[p]);
  }
  const std::vector<PetscReal> &Sg = cs.Gamma(), &Sw = cs.ForceWeights();
  const KappaBlocks             Sk = [&cs](PetscInt s) { return cs.Kappa(s); };
  if (distribute) PetscCall(UniteHits(world, &hits));
  const PetscInt ms = (PetscInt)(k1 - k0); // the states held here (msAll: of every rank)
  PetscCall(PetscTime(&t1));

  // --- EIM of kappa and gamma (or their exact constant form)
  EIMOptions ok, og;
  ok.name = "kappa";
  og.name = "gap";
  PetscCall(EIMOptionsFromOptions(world, "eim_kappa_", &ok));
  PetscCall(EIMOptionsFromOptions(world, "eim_gap_", &og));
  if (wrank != 0) ok.monitor = og.monitor = false; // every rank runs the same greedy: one prints
  EIMResult  ek, eg;
  PetscReal  spreadK, spreadG;
  bool       constK, constG;
  PetscCall(Constant(world, Sk, kap0.data(), (size_t)Q * N, ms, &spreadK, &constK));
  PetscCall(Constant(world, [&](PetscInt j) { return &Sg[(size_t)j * Q]; }, gam0.data(), Q, ms, &spreadG, &constG));
  rm.kappaConst = constK;
  rm.gapConst   = constG;
  if (rm.kappaConst && rm.gapConst) hyper = {true, false, false}; // exact constant terms: nothing to hyper-reduce
  const bool eimKappa = hyper.eim && !rm.kappaConst, eimGap = hyper.eim && !rm.gapConst;
  std::vector<PetscInt> keep; // restricted patch points
  auto keepPoint = [&](PetscInt p) { return Intern(&keep, p); };
  if (rm.kappaConst) {
    rm.kConstant.assign((size_t)N * R, 0.0);
    for (PetscInt n = 0; n < N; ++n)
      for (PetscInt r = 0; r < R; ++r) {
        PetscReal s = 0;
        for (PetscInt p = 0; p < Q; ++p) s += P[(size_t)r * Q + p] * kap0[(size_t)p * N + n];
        rm.kConstant[(size_t)n * R + r] = s;
      }
  } else if (eimKappa) {
    std::vector<PetscReal> Skd; // the EIM's greedy on every snapshot, whole (not distributed)
    Skd.reserve((size_t)ms * Q * N);
    for (PetscInt j = 0; j < ms; ++j) {
      const PetscReal *k = Sk(j); // formed once (every call forms the block again)
      Skd.insert(Skd.end(), k, k + (size_t)Q * N);
    }
    PetscCall(EIMGreedy(Skd, Q * N, ms, ok, &ek));
    rm.MkFull = ek.M;
    rm.kB     = ek.B;
    rm.kC.assign((size_t)ek.M * N * R, 0.0);
    for (PetscInt j = 0; j < ek.M; ++j) {
      rm.kPoint.push_back(keepPoint(ek.points[j] / N));
      rm.kMode.push_back(ek.points[j] % N);
      for (PetscInt n = 0; n < N; ++n)
        for (PetscInt r = 0; r < R; ++r) {
          PetscReal s = 0;
          for (PetscInt p = 0; p < Q; ++p) s += P[(size_t)r * Q + p] * ek.Q[(size_t)j * Q * N + (size_t)p * N + n];
          rm.kC[((size_t)j * N + n) * R + r] = s;
        }
    }
  }
  if (rm.gapConst) {
    rm.gConstant.assign(R, 0.0);
    for (PetscInt r = 0; r < R; ++r)
      for (PetscInt p = 0; p < Q; ++p) rm.gConstant[r] += P[(size_t)r * Q + p] * gam0[p];
  } else if (eimGap) {
    PetscCall(EIMGreedy(Sg, Q, ms, og, &eg));
    rm.MgFull = eg.M;
    rm.gB     = eg.B;
    rm.gC.assign((size_t)eg.M * R, 0.0);
    for (PetscInt j = 0; j < eg.M; ++j) {
      rm.gPoint.push_back(keepPoint(eg.points[j]));
      for (PetscInt r = 0; r < R; ++r) {
        PetscReal s = 0;
        for (PetscInt p = 0; p < Q; ++p) s += P[(size_t)r * Q + p] * eg.Q[(size_t)j * Q + p];
        rm.gC[(size_t)j * R + r] = s;
      }
    }
  }
  // --- the local data: slave facets of the points, master facets they projected onto (+ 2 rings)
  PetscInt rings;
  PetscCall(ContactPatchOptions(world, NULL, &rings));
  std::vector<std::vector<PetscInt>> hitv(Q);
  for (PetscInt p = 0; p < Q; ++p) hitv[p].assign(hits[p].begin(), hits[p].end());
  full->Restrict(keep, hitv, rings, &rm.patch);
  // --- the default EIM sizes: the smallest whose error on held-out parameters (against the reduced
  // model with exact contact terms) is within -eim_select_slack of the best (docs/eim.md)
  PetscBool    select = PETSC_TRUE, keepAll = PETSC_FALSE;
  PetscReal    slack  = 0.1;
  EIMSelection esel;
  std::vector<std::vector<PetscReal>> held;
  PetscOptionsBegin(world, "eim_", "EIM sizes (offline)", "OfflineReducedModel");
  PetscCall(PetscOptionsBool("-select", "choose the EIM sizes on held-out parameters", "", select, &select, NULL));
  PetscCall(PetscOptionsReal("-select_slack", "the smallest sizes within this relative slack of the best held-out error", "", slack, &slack, NULL));
  PetscCall(PetscOptionsBool("-select_keep_all", "keep every EIM term in the file (not only those in use)", "", keepAll, &keepAll, NULL));
  PetscOptionsEnd();
  if (!eimKappa && !eimGap) select = PETSC_FALSE; // no EIM term to size
  if (select) {
    PetscBool heldSet = PETSC_FALSE;
    PetscCall(PetscOptionsHasName(NULL, NULL, "-eim_heldout_type", &heldSet));
    if (heldSet) {
      ParameterSet hs;
      PetscCall(ParameterSetFromOptions(world, fom.scene.params, "eim_heldout_", &hs));
      held = hs.points;
    } else {
      std::vector<std::vector<PetscReal>> train;
      for (const auto &s : snaps) train.push_back(s.mu);
      held = HeldOutParameters(fom.scene.params, train, 20, 1);
    }
    rm.warmStart      = PETSC_TRUE;
    rm.recordIterates = false;
    PetscCall(SelectEIMSizes(world, rm, held, slack, &esel));
    if (!keepAll) { // keep only the terms in use, and the local data of their points
      std::vector<PetscInt> keep2, kP, gP;
      auto                  at = [&](PetscInt p) { return Intern(&keep2, p); };
      const PetscInt mk = rm.kappaConst ? 0 : esel.Mk, mg = rm.gapConst ? 0 : esel.Mg;
      for (PetscInt j = 0; j < mk; ++j) kP.push_back(at(keep[rm.kPoint[j]]));
      for (PetscInt j = 0; j < mg; ++j) gP.push_back(at(keep[rm.gPoint[j]]));
      std::vector<PetscReal> kB((size_t)mk * mk), gB((size_t)mg * mg);
      for (PetscInt j = 0; j < mk; ++j)
        for (PetscInt i = 0; i < mk; ++i) kB[i + (size_t)mk * j] = rm.kB[i + (size_t)rm.MkFull * j];
      for (PetscInt j = 0; j < mg; ++j)
        for (PetscInt i = 0; i < mg; ++i) gB[i + (size_t)mg * j] = rm.gB[i + (size_t)rm.MgFull * j];
      rm.kB = kB;
      rm.gB = gB;
      rm.kC.resize((size_t)mk * N * R); // C_j blocks are contiguous in j
      rm.gC.resize((size_t)mg * R);
      rm.kMode.resize(mk);
      rm.kPoint = kP;
      rm.gPoint = gP;
      if (!rm.kappaConst) rm.MkFull = mk;
      if (!rm.gapConst) rm.MgFull = mg;
      rm.MkDefault = rm.MgDefault = -1;
      keep = keep2;
      full->Restrict(keep, hitv, rings, &rm.patch);
    }
  }
  // --- the empirical cubature (ECSW) of the exact reduced terms on the same states (docs/hyper_reduction.md)
  CubatureOptions co;
  CubatureResult  cr;
  std::vector<PetscReal> errK, errG;
  CubatureHierarchy      hier;
  PetscInt               metricDropped = 0; // -ecsw_fit lambda: training solutions in contact whose metric failed
  PetscInt               metricForceRank = 0; // -ecsw_fit lambda: the rank of its force metric (0: left out)
  if (hyper.ecsw) {
    PetscCall(CubatureOptionsFromOptions(world, "ecsw_", &co));
    if (ecswTol > 0) co.tol = ecswTol;
    if (wrank != 0) co.monitor = false;
    // with the error estimate's enrichment (offline -estimate) the points are fitted to every stored basis function
    // (-estimate_cubature enriched, the default: the tighter estimate) or to the answer's sizes only (answer: the
    // answer's cost as without -estimate); the enrichment's terms are evaluated at the same points (docs/error_estimate.md)
    PetscBool fitAll = PETSC_FALSE;
    if (nDefault > 0 || rDefault > 0) {
      const char *fits[] = {"answer", "enriched"};
      PetscInt    f      = 1;
      PetscOptionsBegin(world, "estimate_", "Online error estimate: cubature (offline)", "OfflineReducedModel");
      PetscCall(PetscOptionsEList("-cubature", "the cubature's fit: the answer's sizes or every stored basis function", "", fits, 2, fits[f], &f, NULL));
      PetscOptionsEnd();
      fitAll = f == 1 ? PETSC_TRUE : PETSC_FALSE;
    }
    const PetscInt nt = (PetscInt)(rm.warmL.size() / R);
    // the lambda fit's metric at the training solutions (docs/hyper_reduction.md "The lambda fit")
    CubatureLambdaMetric metric;
    if (co.fit == CubatureFit::Lambda) {
      PetscCheck(!((nDefault > 0 || rDefault > 0) && !fitAll), world, PETSC_ERR_SUP, "offline: -ecsw_fit lambda fits every stored basis function; it does not combine with -estimate_cubature answer");
      PetscCall(LambdaFitMetric(fom, cmap, order, dual, full.get(), cs, &rm, co.lambdaForce, &metric, &metricDropped));
      metricForceRank = metric.forceRank;
    }
    const CubatureLambdaMetric *pm = co.fit == CubatureFit::Lambda ? &metric : nullptr;
    CubatureGramFunction gram;
    CubatureScalings     scalings; // the action fit's per-state scalings, formed by the first call (hierarchical: many calls)
    std::vector<PetscReal> PA, LA, VA, blockA;
    KappaBlocks            SkA;
    if ((nDefault > 0 || rDefault > 0) && !fitAll) {
      const PetscInt        rA = rDefault > 0 ? rDefault : R, nA = nDefault > 0 ? nDefault : Npod;
      const std::vector<PetscInt> cols = ReducedColumns(Npod, nsup, nA, rA);
      const PetscInt         Na = (PetscInt)cols.size();
      PA.assign(P.begin(), P.begin() + (size_t)rA * Q);
      LA.resize((size_t)nt * rA);
      VA.resize((size_t)nt * Na);
      SkA = [&, cols, Na](PetscInt s) { // the answer's columns of a state's kappa block
        const PetscReal *k = Sk(s);
        blockA.resize((size_t)Q * Na);
        for (size_t p = 0; p < (size_t)Q; ++p)
          for (PetscInt c = 0; c < Na; ++c) blockA[p * Na + c] = k[p * N + cols[c]];
        return (const PetscReal *)blockA.data();
      };
      for (PetscInt j = 0; j < nt; ++j) {
        for (PetscInt i = 0; i < rA; ++i) LA[(size_t)j * rA + i] = rm.warmL[(size_t)j * R + i];
        for (PetscInt c = 0; c < Na; ++c) VA[(size_t)j * Na + c] = rm.warmV[(size_t)j * N + cols[c]];
      }
      if (co.fit == CubatureFit::Action) gram = [&, rA, Na](CubatureCandidates *c, std::vector<PetscReal> *Hc) { CubatureActionGram(PA, rA, Q, Na, SkA, Sg, ms, LA, VA, nt, Hc, co.fitForce ? Sw : std::vector<PetscReal>(), full->dim, 0, c, &scalings); };
      else gram = [&, rA, Na](CubatureCandidates *c, std::vector<PetscReal> *Hc) { CubatureGram(PA, rA, Q, Na, SkA, Sg, ms, Hc, c); };
    } else if (co.fit != CubatureFit::Terms) gram = [&](CubatureCandidates *c, std::vector<PetscReal> *Hc) { CubatureActionGram(P, R, Q, N, Sk, Sg, ms, rm.warmL, rm.warmV, nt, Hc, co.fitForce ? Sw : std::vector<PetscReal>(), full->dim, 0, c, &scalings, pm); };
    else gram = [&](CubatureCandidates *c, std::vector<PetscReal> *Hc) { CubatureGram(P, R, Q, N, Sk, Sg, ms, Hc, c); };
    if (distribute) // this rank's states' share of the Gram system, summed over the ranks
      gram = [&world, local = gram](CubatureCandidates *c, std::vector<PetscReal> *Hc) {
        local(c, Hc);
        PetscCallAbort(world, SumOnEveryRank(world, Hc->data(), Hc->size()));
        if (c) {
          PetscCallAbort(world, SumOnEveryRank(world, c->b.data(), c->b.size()));
          PetscCallAbort(world, SumOnEveryRank(world, &c->c, 1));
          PetscCallAbort(world, SumOnEveryRank(world, &c->cOwn, 1));
        }
      };
    PetscCall(HierarchicalCubature(world, Q, co, gram, &cr, &hier, distribute)); // gram: collective when distributed, else local
    PetscCheck(cr.residual <= co.tol, world, PETSC_ERR_NOT_CONVERGED, "offline: the empirical cubature reaches a relative residual %g > -ecsw_tol %g with %zu points (-ecsw_max_points %" PetscInt_FMT "): raise -ecsw_max_points or -ecsw_tol", (double)cr.residual, (double)co.tol, cr.points.size(), co.maxPoints);
    rm.cPoint.clear();
    rm.cPw.assign((size_t)R * cr.points.size(), 0.0);
    const PetscInt M = (PetscInt)cr.points.size();
    for (PetscInt j = 0; j < M; ++j) {
      rm.cPoint.push_back(keepPoint(cr.points[j]));
      for (PetscInt r = 0; r < R; ++r) rm.cPw[(size_t)r * M + j] = cr.weights[j] * P[(size_t)r * Q + cr.points[j]];
    }
    full->Restrict(keep, hitv, rings, &rm.patch);
    rm.OrderCubaturePoints();
    CubatureStateErrors(P, R, Q, N, Sk, Sg, ms, cr, &errK, &errG); // the fit on every training state
    if (distribute) {
      PetscCall(GatherStates(world, &errK));
      PetscCall(GatherStates(world, &errG));
    }
  }
  rm.hyperDefault = hyper.ecsw && (hyper.ecswFirst || !hyper.eim) ? ReducedModel::ContactMode::Cubature : ReducedModel::ContactMode::EIM;
  rm.SetContactMode(rm.hyperDefault);
  PetscCall(rm.Truncate(-1, -1, -1, -1)); // the sizes in use (report)
  // self-check: the restricted patch reproduces the full one at its points on every stored evaluation
  // state of the last training parameter
  PetscReal patchDiff = 0;
  if (!keep.empty()) {
    const PetscInt         nk = (PetscInt)keep.size();
    std::vector<PetscInt>  idx(nk);
    std::vector<PetscReal> k1((size_t)nk * N), g1(nk);
    for (PetscInt i = 0; i < nk; ++i) idx[i] = i;
    // the last training solution (repeated parameters have no entry of their own)
    const size_t                 nw = rm.warmV.size() / N, npar = snaps[m - 1].mu.size();
    const std::vector<PetscReal> mu(rm.warmMu.end() - npar, rm.warmMu.end());
    full->SetGeometry(&fom.map, mu);
    rm.patch.SetGeometry(&fom.map, mu);
    full->SetReduced(&rm.warmV[(nw - 1) * N]);
    rm.patch.SetReduced(&rm.warmV[(nw - 1) * N]);
    (void)full->Evaluate(keep.data(), nk, kap.data(), gam.data(), nullptr);
    const PetscInt outside = rm.patch.Evaluate(idx.data(), nk, k1.data(), g1.data(), nullptr);
    for (PetscInt i = 0; i < nk; ++i) {
      patchDiff = std::max(patchDiff, std::abs(g1[i] - gam[i]));
      for (PetscInt n = 0; n < N; ++n) patchDiff = std::max(patchDiff, std::abs(k1[(size_t)i * N + n] - kap[(size_t)i * N + n]));
    }
    PetscCheck(patchDiff <= 1e-12 && outside == 0, world, PETSC_ERR_PLIB, "offline: the local contact data differs from the full contact map by %g (%" PetscInt_FMT " projections outside): increase -eim_patch_rings", (double)patchDiff, outside);
  }
  PetscCall(PetscLogEventEnd(OFF_Hyper, 0, 0, 0, 0));
  PetscCall(PetscTime(&t2));
  // outputs of interest on the slave surface (max pressure, contact half-width; surface_outputs.hpp): the dual
  // basis on the slave vertices and the slave facets; their weights checked against the FOM's at the default
  PetscReal surfaceWeightDiff = -1;
  {
    std::vector<SurfaceFacet> facets;
    PetscCall(cmap.Slave().Gather(PetscObjectComm((PetscObject)fom.dm), &facets));
    const PetscInt        Rfom = dual.W.rows;
    std::vector<PetscInt> canon(Rfom);
    for (PetscInt g = 0; g < Rfom; ++g) canon[g] = order.CanonicalMultiplier(g);
    rm.surface.Build(fom.elas.dim, facets, canon, Rfom, R, dual.W.a);
    std::vector<PetscReal> wc, ws, xs;
    PetscCall(ReferenceSlaveMass(fom, cmap, order, &wc));
    rm.surface.Weights(fom.map, ParamValues(fom.scene), &ws, &xs);
    PetscReal dmax = 0, wmax = 0;
    for (PetscInt i = 0; i < Rfom; ++i) {
      dmax = std::max(dmax, std::abs(ws[i] - wc[i]));
      wmax = std::max(wmax, std::abs(wc[i]));
    }
    surfaceWeightDiff = wmax > 0 ? dmax / wmax : dmax;
    // a multiplier space whose int psi_i is not |facet| / vertices (not ours today): no surface outputs rather than wrong ones
    if (!(surfaceWeightDiff <= 1e-10)) rm.surface = SurfaceOutputs();
    // the error estimate's enrichment (offline -estimate, docs/error_estimate.md): the answer's sizes and the
    // lambda norm of validate's error (the slave mass weights of the reference configuration) on the dual basis
    if (nDefault > 0 || rDefault > 0) {
      rm.NDefault = nDefault > 0 ? nDefault : Npod;
      rm.RDefault = rDefault > 0 ? rDefault : R;
      rm.massGram = SlaveMassGram(dual.W, wc);
      PetscCall(rm.Truncate(-1, -1, -1, -1)); // the answer's sizes (report)
    }
  }
  if (wrank == 0) {
    WriteReducedModel(rm, w);
    w->Dataset("/online/eim_quadrature", {1}, {(double)nsub}); // the contact quadrature of kappa, gamma (validation)
  }

  // --- report
  JsonValue &e = rep->root["eim"];
  e["quadrature_points"]    = (long long)Q;
  e["quadrature_subdivisions"] = (long long)nsub;
  e["snapshots"]            = (long long)msAll;
  e["extra_parameters"]     = (long long)nExtra;
  e["repeated_training_parameters"] = (long long)nDuplicate; // taken once for the contact states and warm starts
  e["rom_kacanov_iterations"]["total"] = (long long)nRomIts;
  e["rom_kacanov_iterations"]["max"]   = (long long)maxRomIts;
  JsonValue &k = e["kappa"];
  k["kind"]            = rm.kappaConst ? "constant: independent of mu and u, stored exactly (no EIM)" : eimKappa ? "eim" : "none (-rom_hyper without eim)";
  k["M"]               = (long long)(rm.kappaConst ? 0 : ek.M); // the greedy's size (rom.Mk: in use)
  k["depends_on_u"]    = uDep > 1e-13;
  k["u_sensitivity"]   = (double)uDep;
  k["snapshot_spread"] = (double)spreadK;
  if (eimKappa) {
    k["history"] = ek.history;
    k["tol_abs"] = (double)ek.tolAbs;
    k["scale"]   = (double)ek.scale;
  }
  JsonValue &g = e["gap"];
  g["kind"]            = rm.gapConst ? "constant: independent of mu and u, stored exactly (no EIM)" : eimGap ? "eim" : "none (-rom_hyper without eim)";
  g["M"]               = (long long)(rm.gapConst ? 0 : eg.M);
  g["snapshot_spread"] = (double)spreadG;
  if (eimGap) {
    g["history"] = eg.history;
    g["tol_abs"] = (double)eg.tolAbs;
    g["scale"]   = (double)eg.scale;
  }
  if (hyper.ecsw) {
    JsonValue &c = rep->root["ecsw"];
    c["M"]            = (long long)cr.points.size();
    c["tol"]          = (double)co.tol;
    c["fit"]          = co.fit == CubatureFit::Lambda ? "lambda" : co.fit == CubatureFit::Action ? "action" : "terms";
    c["fit_force"]    = co.fit != CubatureFit::Terms && co.fitForce;
    if (co.fit == CubatureFit::Lambda) {
      c["lambda_metric_dropped"] = (long long)metricDropped;
      c["lambda_force_rank"]     = (long long)metricForceRank;
    }
    c["residual"]     = (double)cr.residual;
    c["quadrature_points"] = (long long)Q;
    c["groups"]       = (long long)hier.groups;     // > 1: the hierarchical fit (-ecsw_group_points)
    c["candidates"]   = (long long)hier.candidates; // the final fit's candidate points (Q with one group)
    if (hier.groups > 1) {
      c["group_tol"]       = (double)hier.groupTol;
      c["group_residuals"] = hier.groupResiduals;
    }
    c["history"]      = cr.history;
    c["iterations"]   = (long long)cr.iterations;
    c["eliminated"]   = (long long)cr.eliminated; // points removed after the fit (-ecsw_eliminate)
    c["M_without_elimination"] = (long long)cr.plainPoints; // the fit stopped on first reaching -ecsw_tol
    c["eliminate"]    = co.eliminate;
    c["eliminate_from"] = (double)co.eliminateFrom;
    JsonValue &ft = c["fit_time_s"]; // the final fit's seconds (the union's in the hierarchical fit): to tol, on to
    ft["fit"]        = (double)cr.timeFit; // eliminate_from x tol, the elimination
    ft["longer_fit"] = (double)cr.timeLonger;
    ft["eliminate"]  = (double)cr.timeEliminate;
    c["weights"]      = cr.weights;
    c["states"]       = (long long)msAll;
    c["states_distributed"] = distribute; // the states' evaluations split over the ranks (-ecsw_distribute_states)
    c["states_per_rank_max"] = (long long)(distribute ? (msAll + wsize - 1) / wsize : msAll);
    c["states_bytes"]        = (double)cs.Bytes();               // rank 0's store of its states (ContactStates)
    c["states_dense_bytes"]  = (double)ms * Q * (N + 1 + full->dim) * sizeof(PetscReal); // the same as Q x (N + 1 + dim) x states arrays
    c["train_err_K"]  = errK;
    c["train_err_g"]  = errG;
    c["train_max_err_K"] = errK.empty() ? 0.0 : (double)*std::max_element(errK.begin(), errK.end());
    c["train_max_err_g"] = errG.empty() ? 0.0 : (double)*std::max_element(errG.begin(), errG.end());
  }
  JsonValue &se = e["select"];
  se["enabled"] = (bool)select;
  if (select) {
    se["heldout"]    = (long long)esel.heldout;
    se["Mk"]         = (long long)esel.Mk;
    se["Mg"]         = (long long)esel.Mg;
    se["slack"]      = (double)slack;
    se["max_err"]    = (double)esel.err;
    se["err_kappa"]  = esel.errKappa;
    se["err_gap"]    = esel.errGap;
    se["kept_all"]   = (bool)keepAll;
  }
  JsonValue &pt = e["patch"];
  pt["points"]           = (long long)rm.patch.NumPoints();
  pt["slave_facets"]     = (long long)rm.patch.slave.size();
  pt["master_facets"]    = (long long)rm.patch.master.size();
  pt["nodes"]            = (long long)rm.patch.nnode;
  pt["rings"]            = (long long)rings;
  pt["check_max_diff"]   = (double)patchDiff;
  JsonValue &ro = rep->root["rom"];
  ro["N"]    = (long long)N;
  ro["Npod"] = (long long)Npod;
  ro["supremizers"] = (long long)nsup;
  ro["R"]    = (long long)R;
  ro["Mk"]   = (long long)rm.Mk(); // the sizes in use by default
  ro["Mg"]   = (long long)rm.Mg();
  ro["hyper"] = rm.hyperDefault == ReducedModel::ContactMode::Cubature ? "ecsw" : "eim";
  ro["hyper_stored"] = std::string(hyper.ecsw ? "ecsw" : "") + (hyper.ecsw && hyper.eim ? "," : "") + (hyper.eim ? "eim" : "");
  ro["Mc"] = (long long)rm.Mc();
  ro["Mk_stored"] = (long long)rm.MkFull;
  ro["N_in_use"]  = (long long)rm.N(); // the answer's sizes: N, R minus the error estimate's enrichment (offline -estimate)
  ro["R_in_use"]  = (long long)rm.R();
  ro["estimate_enrichment"] = rm.HasEnrichment();
  ro["Mg_stored"] = (long long)rm.MgFull;
  ro["surface_outputs"] = !rm.surface.Empty();                 // max pressure, contact half-width online
  ro["surface_weight_check"] = (double)surfaceWeightDiff;      // max rel diff of int psi_i: facets vs the FOM
  ro["affine_A"] = (long long)rm.par.NumA();
  ro["affine_f"] = (long long)rm.par.NumF();
  ro["kacanov_rtol_primal"] = (double)rm.loop.rtolPrimal; // stored in the file: the online default (/online/kacanov_rtol)
  ro["kacanov_rtol_dual"]   = (double)rm.loop.rtolDual;
  ro["ecsw_sum"]            = rm.EcswSumsByDofs() ? "dofs" : "points";                  // the online sum (-rom_ecsw_sum auto: by flops)
  ro["gemm"]                = rm.GemmName();                                            // who sums its outer products (-rom_gemm)
  ro["ecsw_precision"]      = rm.EcswSingle() ? "single" : "double";                    // ... and its arithmetic in effect
  ro["ecsw_precision_stored"] = rm.ecswSingle ? "single" : "double";                    // /online/ecsw_precision
  rep->root["time_s"]["eim_snapshots"] = (double)(t1 - t0);
  rep->root["time_s"]["eim"]           = (double)(t2 - t1);
  rep->root["time_s"]["hyper_snapshots"] = (double)(t1 - t0); // the same two phases under names that fit the
  rep->root["time_s"]["hyper"]           = (double)(t2 - t1); // cubature too (eim_* kept: a stable report key)
  PetscFunctionReturn(0);
}

} // namespace rbc
