// tests/test_reduced_contact.cpp: an independent check of the reduced model's contact evaluator
// (ContactPatch) and of its parametrization (ReducedParametrization) against the full-order code, on
// the scene of the options (-options_file runs/ring_on_block.opts), on any number of ranks:
//   1. the full patch's pointwise kappa, gamma summed with the multiplier shape functions psi equal the
//      FOM contact map assembled with the same composite quadrature (K times three fixed "modes", g);
//   2. a restricted patch (Restrict) reproduces the full patch at its points (and, with no rings and a
//      master shifted tangentially, flags the projections that left it);
//   3. ReducedParametrization::FromFOM gives the FOM's affine coefficients, survives a ROM-file
//      roundtrip, and CheckBox rejects a parameter outside the box;
//   4. a patch serialized to a ROM file and read back evaluates bitwise identically;
//   and the offline store of contact states by their terms (ContactStates) gives Evaluate's values bit for bit, also
//   after SetGeometry has moved between parameters (the facets of an unmoved body kept).
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact_states.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/kacanov.hpp"
#include "rbcontact/reduced_contact.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/rom_file.hpp"
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "test_check.hpp"

using namespace rbc;


// ok must be the same on every rank (all data compared here is replicated); reduced anyway.
using rbctest::Check;
using rbctest::failures;

// rank 0's vector on every rank
static PetscErrorCode Bcast(MPI_Comm comm, std::vector<PetscReal> *v)
{
  long long n = (long long)v->size();

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm));
  v->resize((size_t)n);
  if (n) PetscCallMPI(MPI_Bcast(v->data(), (int)n, MPIU_REAL, 0, comm));
  PetscFunctionReturn(0);
}

// canonical-order array -> distributed global dof vector x
static PetscErrorCode CanonicalToVec(const CanonicalOrder &order, const PetscReal *c, Vec x)
{
  PetscInt     lo, hi;
  PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(VecGetOwnershipRange(x, &lo, &hi));
  PetscCall(VecGetArray(x, &a));
  for (PetscInt g = lo; g < hi; ++g) a[g - lo] = c[order.CanonicalDof(g)];
  PetscCall(VecRestoreArray(x, &a));
  PetscFunctionReturn(0);
}

static PetscReal MaxAbs(const std::vector<PetscReal> &a)
{
  PetscReal m = 0;
  for (PetscReal x : a) m = std::max(m, std::abs(x));
  return m;
}

static PetscReal MaxDiff(const std::vector<PetscReal> &a, const std::vector<PetscReal> &b)
{
  if (a.size() != b.size()) return INFINITY;
  PetscReal m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

static bool Bitwise(const std::vector<PetscReal> &a, const std::vector<PetscReal> &b)
{
  return a.size() == b.size() && (a.empty() || !std::memcmp(a.data(), b.data(), a.size() * sizeof(PetscReal)));
}

// deterministic pseudo-random number in [-1, 1] of an index (splitmix64)
static PetscReal Hash01(std::uint64_t x)
{
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  x ^= x >> 31;
  return 2.0 * (PetscReal)(x >> 11) / (PetscReal)(1ULL << 53) - 1.0;
}

// Evaluates all points idx of a patch.
struct Eval {
  std::vector<PetscReal> kappa, gamma;
  std::vector<PetscInt>  hit;
  PetscInt               outside = 0;
};
static void EvaluatePatch(const ContactPatch &P, const std::vector<PetscInt> &idx, Eval *e)
{
  const PetscInt n = (PetscInt)idx.size();
  e->kappa.assign((size_t)n * P.N, 0.0);
  e->gamma.assign(n, 0.0);
  e->hit.assign(n, -1);
  e->outside = P.Evaluate(idx.data(), n, e->kappa.data(), e->gamma.data(), e->hit.data());
}

static std::vector<PetscInt> Iota(PetscInt n)
{
  std::vector<PetscInt> v(n);
  for (PetscInt i = 0; i < n; ++i) v[i] = i;
  return v;
}

// kappa/gamma of two evaluations: max |diff| relative to the largest value of the first.
static void RelDiffs(const Eval &a, const Eval &b, PetscReal *dk, PetscReal *dg)
{
  const PetscReal sk = MaxAbs(a.kappa), sg = MaxAbs(a.gamma);
  *dk = MaxDiff(a.kappa, b.kappa) / (sk > 0 ? sk : 1.0);
  *dg = MaxDiff(a.gamma, b.gamma) / (sg > 0 ? sg : 1.0);
}

static PetscErrorCode Run()
{
  MPI_Comm    comm = PETSC_COMM_WORLD;
  PetscMPIInt rank, size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  // the fixed composite rule the reduced model uses: 4 pieces x the Gauss rule per slave facet
  const PetscInt nsub = 4;
  PetscCall(PetscOptionsSetValue(NULL, "-contact_quadrature", "composite"));
  PetscCall(PetscOptionsSetValue(NULL, "-contact_quadrature_subdivisions", "4"));

  SceneSpec scene;
  PetscCall(SceneSpecFromOptions(comm, &scene));
  PetscCheck(scene.contact && scene.params.size() == 1, comm, PETSC_ERR_USER_INPUT, "test_reduced_contact needs a contact scene with one parameter (runs/ring_on_block.opts)");
  ElasticFOM fom;
  PetscCall(fom.Create(comm, scene));
  PetscCall(fom.SetupAffine());
  const PetscInt dim = fom.elas.dim;
  ContactMap     map;
  KacanovSolver  kac;
  PetscCall(map.Setup(fom.elas, scene.slave, scene.master));
  PetscCall(kac.SetFromOptions(comm));
  PetscCheck(map.quadrature == ContactQuadrature::Composite && map.nsub == nsub, comm, PETSC_ERR_PLIB, "the contact map did not take -contact_quadrature composite");

  const std::vector<PetscReal> mu = {1.07};
  PetscCall(fom.SetMu(mu));
  PetscCall(fom.AssembleAndFactor());
  map.SetGeometry(&fom.map, mu);
  PetscCall(kac.Solve(fom, map));
  PetscCall(PetscPrintf(comm, "scene %s on %d rank(s), mu = %g: Kacanov %" PetscInt_FMT " iterations, R = %" PetscInt_FMT ", %" PetscInt_FMT " dofs\n", scene.name.c_str(), size, (double)mu[0], kac.iterations, map.NumMultipliers(), fom.GlobalSize()));

  CanonicalOrder order;
  PetscCall(order.BuildDofs(fom.elas));
  PetscCall(order.BuildMultipliers(kac.sys.coordRef, dim));
  const PetscInt ndofs = order.NumDofs(), R = order.NumMultipliers();
  std::vector<PetscReal> ucan;
  PetscCall(order.DofsToCanonical(fom.u, &ucan));
  PetscCall(Bcast(comm, &ucan));

  // the modes (N x ndofs, canonical order): u; 1 on the even canonical dofs (x components: a rigid
  // translation of both bodies' free nodes); a small deterministic pseudo-random field
  const PetscInt         N = 3;
  std::vector<PetscReal> modes((size_t)N * ndofs);
  for (PetscInt c = 0; c < ndofs; ++c) {
    modes[c]             = ucan[c];
    modes[ndofs + c]     = c % 2 == 0 ? 1.0 : 0.0;
    modes[2 * ndofs + c] = 1e-3 * Hash01((std::uint64_t)c);
  }

  // FOM contact map at u (composite rule); the surfaces now carry the Dirichlet values of u's field
  ContactSystem sys;
  {
    Vec uloc;
    PetscCall(DMGetLocalVector(fom.dm, &uloc));
    PetscCall(fom.elas.GlobalToLocalWithBC(fom.u, uloc));
    PetscCall(map.Assemble(fom.elas, uloc, &sys));
    PetscCall(DMRestoreLocalVector(fom.dm, &uloc));
  }
  ContactPatch full;
  PetscCall(full.BuildFull(comm, map, order, modes, N, std::vector<char>(), nsub));
  const PetscInt Q = full.NumPoints();
  PetscCall(PetscPrintf(comm, "full patch: %" PetscInt_FMT " points, %zu slave / %zu master facets, %" PetscInt_FMT " nodes, %" PetscInt_FMT " master vertices\n", Q, full.slave.size(), full.master.size(), full.nnode, full.nvertex));

  // ---------------------------------------------------------------- 1. patch = FOM contact map
  PetscCall(PetscPrintf(comm, "1. full patch (psi-summed) = FOM contact map, composite rule nsub = %" PetscInt_FMT "\n", nsub));
  {
    // the canonical <-> PETSc dof map used for the modes reproduces u exactly
    Vec       x;
    PetscReal d;
    PetscCall(VecDuplicate(fom.u, &x));
    PetscCall(CanonicalToVec(order, ucan.data(), x));
    PetscCall(VecAXPY(x, -1.0, fom.u));
    PetscCall(VecNorm(x, NORM_INFINITY, &d));
    PetscCall(VecDestroy(&x));
    PetscCall(Check(comm, d == 0.0, "canonical u mapped back = fom.u (max |diff|)", d, 0.0));
  }
  full.SetGeometry(&fom.map, mu);
  std::vector<PetscReal> Unod;
  full.NodalFromCanonical(ucan, &Unod);
  full.SetNodal(Unod);
  const std::vector<PetscInt> all = Iota(Q);
  Eval                        e0;
  EvaluatePatch(full, all, &e0);
  // psi sums: (KV)_{i n} = sum_p psi_k kappa(p, n), g_i = sum_p psi_k gamma(p) (canonical multiplier rows)
  std::vector<PetscReal> KVp((size_t)R * N, 0.0), gp(R, 0.0); // KVp: R x N row-major
  PetscInt               badRows = 0;
  std::vector<char>      seen(R, 0);
  for (PetscInt p = 0; p < Q; ++p)
    for (PetscInt k = 0; k < dim; ++k) {
      const PetscInt  i = full.points[p].row[k];
      const PetscReal b = MultiplierShape(map.multiplier, dim, full.points[p].b, k); // psi_k (dual or standard)
      if (i < 0 || i >= R) {
        ++badRows;
        continue;
      }
      seen[i] = 1;
      for (PetscInt n = 0; n < N; ++n) KVp[(size_t)i * N + n] += b * e0.kappa[(size_t)p * N + n];
      gp[i] += b * e0.gamma[p];
    }
  PetscInt unseen = 0;
  for (char s : seen) unseen += !s;
  PetscCall(Check(comm, badRows == 0 && unseen == 0, "every point row valid and every multiplier row covered (bad + missing)", (double)(badRows + unseen), 0));
  // FOM: K times the modes in PETSc order, g; gathered in canonical multiplier order
  std::vector<PetscReal> KVf((size_t)R * N, 0.0), gf;
  {
    Vec x, y;
    PetscCall(VecDuplicate(fom.u, &x));
    PetscCall(VecDuplicate(sys.g, &y));
    for (PetscInt n = 0; n < N; ++n) {
      std::vector<PetscReal> yc;
      PetscCall(CanonicalToVec(order, &modes[(size_t)n * ndofs], x));
      PetscCall(MatMult(sys.K, x, y));
      PetscCall(order.MultipliersToCanonical(y, &yc));
      PetscCall(Bcast(comm, &yc));
      PetscCheck((PetscInt)yc.size() == R, comm, PETSC_ERR_PLIB, "K V column has %zu entries, R = %" PetscInt_FMT, yc.size(), R);
      for (PetscInt i = 0; i < R; ++i) KVf[(size_t)i * N + n] = yc[i];
    }
    PetscCall(VecDestroy(&x));
    PetscCall(VecDestroy(&y));
    PetscCall(order.MultipliersToCanonical(sys.g, &gf));
    PetscCall(Bcast(comm, &gf));
  }
  {
    const PetscReal sK = MaxAbs(KVf), sg = MaxAbs(gf), dK = MaxDiff(KVp, KVf), dg = MaxDiff(gp, gf);
    for (PetscInt n = 0; n < N; ++n) {
      PetscReal mx = 0, df = 0;
      for (PetscInt i = 0; i < R; ++i) {
        mx = std::max(mx, std::abs(KVf[(size_t)i * N + n]));
        df = std::max(df, std::abs(KVf[(size_t)i * N + n] - KVp[(size_t)i * N + n]));
      }
      PetscCall(PetscPrintf(comm, "     mode %" PetscInt_FMT ": max |K v_n| %.6e, max |diff| %.3e\n", n, (double)mx, (double)df));
    }
    PetscCall(PetscPrintf(comm, "     max |K V| %.6e, max |g| %.6e\n", (double)sK, (double)sg));
    PetscCall(Check(comm, sK > 0 && dK <= 1e-12 * sK, "sum_p psi kappa = K V (max |diff| / max |K V|)", sK > 0 ? dK / sK : dK, 1e-12));
    PetscCall(Check(comm, sg > 0 && dg <= 1e-12 * sg, "sum_p psi gamma = g (max |diff| / max |g|)", sg > 0 ? dg / sg : dg, 1e-12));
  }

  // ---------------------------------------------------------------- 2. Restrict
  PetscCall(PetscPrintf(comm, "2. restricted patch = full patch at its points\n"));
  std::vector<std::vector<PetscInt>> hits(Q);
  for (PetscInt p = 0; p < Q; ++p) hits[p] = {e0.hit[p]};
  // two point sets: every 7th point from the middle of the slave (a few neighbouring slave facets: the
  // restricted master is a strict subset, renumbered) and 10 points spread over the whole slave
  std::vector<PetscInt> keep, spread;
  for (PetscInt j = 0; j < 10; ++j) {
    keep.push_back(Q / 2 - 35 + 7 * j);
    spread.push_back(3 + j * 7 * (Q / 70));
  }
  for (PetscInt p : keep) PetscCheck(p >= 0 && p < Q, comm, PETSC_ERR_PLIB, "too few patch points (%" PetscInt_FMT ")", Q);
  for (PetscInt p : spread) PetscCheck(p >= 0 && p < Q, comm, PETSC_ERR_PLIB, "too few patch points (%" PetscInt_FMT ")", Q);
  const PetscInt  nk   = (PetscInt)keep.size();
  const PetscReal v[3] = {1.0, 0.3, -0.2};
  ContactPatch    local, localSpread;
  full.Restrict(keep, hits, 2, &local);
  full.Restrict(spread, hits, 2, &localSpread);
  full.SetGeometry(&fom.map, mu);
  full.SetReduced(v);
  for (auto &set : {std::make_pair("every 7th", std::make_pair(&keep, &local)), std::make_pair("spread", std::make_pair(&spread, &localSpread))}) {
    const std::vector<PetscInt> &pts = *set.second.first;
    ContactPatch                &L   = *set.second.second;
    PetscCall(PetscPrintf(comm, "     %s: points %" PetscInt_FMT "..%" PetscInt_FMT ", rings 2: %zu slave / %zu master facets (%d searchable), %" PetscInt_FMT " nodes\n", set.first, pts.front(), pts.back(), L.slave.size(), L.master.size(), (int)std::count(L.searchable.begin(), L.searchable.end(), 1), L.nnode));
    L.SetGeometry(&fom.map, mu);
    L.SetReduced(v);
    Eval ef, el;
    EvaluatePatch(full, pts, &ef);
    EvaluatePatch(L, Iota((PetscInt)pts.size()), &el);
    PetscReal dk, dg;
    RelDiffs(ef, el, &dk, &dg);
    char what[128];
    std::snprintf(what, sizeof what, "%s: restricted kappa = full kappa at v = (1, 0.3, -0.2) (rel.)", set.first);
    PetscCall(Check(comm, dk <= 1e-14, what, dk, 1e-14));
    std::snprintf(what, sizeof what, "%s: restricted gamma = full gamma at v = (1, 0.3, -0.2) (rel.)", set.first);
    PetscCall(Check(comm, dg <= 1e-14, what, dg, 1e-14));
    std::snprintf(what, sizeof what, "%s: restricted patch out-of-range projections", set.first);
    PetscCall(Check(comm, el.outside == 0, what, (double)el.outside, 0));
    std::snprintf(what, sizeof what, "%s: restricted kappa not identically zero (max |kappa|)", set.first);
    PetscCall(Check(comm, MaxAbs(el.kappa) > 0, what, MaxAbs(el.kappa), 0));
  }
  PetscCall(Check(comm, local.master.size() < full.master.size(), "every 7th: restricted master is a strict subset (facets)", (double)local.master.size(), (double)full.master.size()));
  // no rings and the master shifted tangentially by about 3 master facets: the projections leave the
  // single candidate facet; the evaluator must flag them (or still be exact)
  {
    const PetscReal        shift = 0.1;
    std::vector<PetscReal> w = ucan;
    std::vector<char>      done(ndofs, 0);
    for (const auto &F : full.master)
      for (PetscInt a = 0; a < F.nnodes; ++a) {
        const PetscInt c = full.canon[F.dof[a * dim + 0]];
        if (c >= 0 && !done[c]) {
          w[c] += shift;
          done[c] = 1;
        }
      }
    ContactPatch local0;
    full.Restrict(keep, hits, 0, &local0);
    std::vector<PetscReal> Uf, U0, U2;
    full.NodalFromCanonical(w, &Uf);
    local0.NodalFromCanonical(w, &U0);
    local.NodalFromCanonical(w, &U2);
    local0.SetGeometry(&fom.map, mu);
    full.SetNodal(Uf);
    local0.SetNodal(U0);
    local.SetNodal(U2);
    Eval ff, f0, f2;
    EvaluatePatch(full, keep, &ff);
    EvaluatePatch(local0, Iota(nk), &f0);
    EvaluatePatch(local, Iota(nk), &f2);
    PetscReal dk0, dg0, dk2, dg2;
    RelDiffs(ff, f0, &dk0, &dg0);
    RelDiffs(ff, f2, &dk2, &dg2);
    PetscInt moved = 0;
    for (PetscInt i = 0; i < nk; ++i) moved += ff.hit[i] != e0.hit[keep[i]];
    PetscCall(PetscPrintf(comm, "     master shifted by %g in x: %" PetscInt_FMT "/%" PetscInt_FMT " points project onto another facet than at u\n", (double)shift, moved, nk));
    PetscCall(PetscPrintf(comm, "     rings 0: out of range %" PetscInt_FMT ", rel. diff kappa %.3e gamma %.3e\n", f0.outside, (double)dk0, (double)dg0));
    PetscCall(PetscPrintf(comm, "     rings 2: out of range %" PetscInt_FMT ", rel. diff kappa %.3e gamma %.3e (information)\n", f2.outside, (double)dk2, (double)dg2));
    const bool exact0 = dk0 <= 1e-14 && dg0 <= 1e-14;
    PetscCall(Check(comm, f0.outside > 0 || exact0, "rings 0, shifted master: flagged out of range, or exact (count)", (double)f0.outside, 0));
  }

  // the offline stage's store of contact states by their terms (ContactStates): each state's kappa block, gamma,
  // w n2 and hits bit for bit those of Evaluate at that state (two states: v at mu, 2 v at 1.01 mu)
  {
    const PetscReal              v2[3] = {2.0, 0.6, -0.4};
    const std::vector<PetscReal> mu2   = {mu[0] * 1.01};
    const std::vector<PetscInt>  all   = Iota(Q);
    ContactStates                cs(full, 2);
    std::vector<PetscInt>        hs;
    bool                         same = true;
    std::vector<Eval>            ref(2);
    std::vector<std::vector<PetscReal>> wref(2, std::vector<PetscReal>((size_t)Q * dim));
    for (int s = 0; s < 2; ++s) {
      full.SetGeometry(&fom.map, s ? mu2 : mu);
      full.SetReduced(s ? v2 : v);
      EvaluatePatch(full, all, &ref[s]);
      (void)full.Evaluate(all.data(), Q, nullptr, nullptr, nullptr, wref[s].data());
      cs.Append(&hs);
      same = same && hs == ref[s].hit;
    }
    for (int s = 0; s < 2 && same; ++s) {
      same = std::memcmp(cs.Kappa(s), ref[s].kappa.data(), (size_t)Q * N * sizeof(PetscReal)) == 0;
      same = same && std::memcmp(&cs.Gamma()[(size_t)s * Q], ref[s].gamma.data(), (size_t)Q * sizeof(PetscReal)) == 0;
      same = same && std::memcmp(&cs.ForceWeights()[(size_t)s * Q * dim], wref[s].data(), (size_t)Q * dim * sizeof(PetscReal)) == 0;
    }
    PetscCall(Check(comm, cs.Size() == 2 && same, "ContactStates: kappa blocks, gamma, w n2, hits of 2 states bit for bit those of Evaluate", same ? 0.0 : 1.0, 0));
    // SetGeometry keeps the facets of a body whose map did not change (the block's) and maps the others again: back at
    // mu after mu2, the evaluation is bit for bit the first one at mu
    Eval back;
    full.SetGeometry(&fom.map, mu);
    full.SetReduced(v);
    EvaluatePatch(full, all, &back);
    const bool again = Bitwise(back.kappa, ref[0].kappa) && Bitwise(back.gamma, ref[0].gamma) && back.hit == ref[0].hit;
    PetscCall(Check(comm, again, "SetGeometry at mu, 1.01 mu, then mu again: kappa, gamma, hits bit for bit those of the first visit", again ? 0.0 : 1.0, 0));
    { // non-finite reduced coordinates (a diverged iterate, a corrupt file): no closest facet is found; the point's gap
      // is NaN (which the reduced QP refuses) and its facet a valid index, never -1 (this read master[-1] and crashed)
      std::vector<PetscReal> vnan(3, std::numeric_limits<PetscReal>::quiet_NaN()); // v has 3 entries
      Eval                   bad;
      full.SetReduced(vnan.data());
      EvaluatePatch(full, all, &bad);
      bool nanGap = true, validHit = true;
      for (size_t p = 0; p < bad.gamma.size(); ++p) {
        nanGap   = nanGap && std::isnan(bad.gamma[p]);
        validHit = validHit && bad.hit[p] >= 0 && bad.hit[p] < (PetscInt)full.master.size();
      }
      PetscCall(Check(comm, nanGap && validHit, "NaN reduced coordinates: every point's gap NaN, its facet a valid index (no crash)", nanGap && validHit ? 0.0 : 1.0, 0));
      full.SetReduced(v);
    }
    // every facet's coordinates are its body's map at the last parameter applied to its reference ones (mu2, mu, mu2)
    bool mapped = true;
    for (const auto &m : {mu2, mu, mu2}) {
      full.SetGeometry(&fom.map, m);
      for (const auto *fs : {&full.slave, &full.master})
        for (const auto &F : *fs) {
          const Affine a = fom.map.Evaluate(F.body, m);
          for (PetscInt k = 0; k < F.nv; ++k) {
            PetscReal y[3];
            a.Apply(dim, &F.Xref[k * dim], y);
            for (PetscInt d = 0; d < dim; ++d) mapped = mapped && y[d] == F.X[k * dim + d];
          }
        }
    }
    PetscCall(Check(comm, mapped, "SetGeometry at 1.01 mu, mu, 1.01 mu: every facet's coordinates its body's map at that parameter", mapped ? 0.0 : 1.0, 0));
  }

  // ---------------------------------------------------------------- 3. parametrization
  PetscCall(PetscPrintf(comm, "3. reduced parametrization = FOM affine coefficients, ROM-file roundtrip, box check\n"));
  long long tag = rank == 0 ? (long long)getpid() : 0;
  PetscCallMPI(MPI_Bcast(&tag, 1, MPI_LONG_LONG, 0, comm));
  const std::string parFile   = "/tmp/rbc_test_reduced_contact_" + std::to_string(tag) + "_np" + std::to_string(size) + "_par.h5";
  const std::string patchFile = "/tmp/rbc_test_reduced_contact_" + std::to_string(tag) + "_np" + std::to_string(size) + "_patch.h5";
  {
    ReducedParametrization par, par2;
    PetscCall(par.FromFOM(fom.elas, fom.map, fom.affine));
    RomWriter w;
    par.Write(&w);
    PetscCall(w.Write(comm, parFile));
    PetscCall(par2.Read(parFile));
    PetscCall(PetscPrintf(comm, "     %" PetscInt_FMT " A terms, %" PetscInt_FMT " f terms (FOM %zu, %zu)\n", par.NumA(), par.NumF(), fom.affine.thetaA.size(), fom.affine.thetaF.size()));
    PetscCall(Check(comm, par.NumA() == (PetscInt)fom.affine.Aq.size() && par.NumF() == (PetscInt)fom.affine.fq.size() && par2.NumA() == par.NumA() && par2.NumF() == par.NumF(), "term counts (FromFOM, read back) = FOM", (double)(par2.NumA() + par2.NumF()), 0));
    for (PetscReal m : {0.95, 1.0, 1.15}) {
      const std::vector<PetscReal> mm = {m};
      std::vector<PetscReal>       ta, tf, ta2, tf2;
      const std::vector<PetscReal> fa = fom.affine.ThetaA(mm), ff = fom.affine.ThetaF(mm);
      par.ThetaA(mm, &ta);
      par.ThetaF(mm, &tf);
      par2.ThetaA(mm, &ta2);
      par2.ThetaF(mm, &tf2);
      PetscCall(PetscPrintf(comm, "     mu = %.2f: thetaA[0] %.17g, thetaF[0] %.17g (FOM %.17g, %.17g)\n", (double)m, ta.empty() ? 0.0 : (double)ta[0], tf.empty() ? 0.0 : (double)tf[0], fa.empty() ? 0.0 : (double)fa[0], ff.empty() ? 0.0 : (double)ff[0]));
      const PetscReal sa = std::max(MaxAbs(fa), (PetscReal)1e-300), sf = std::max(MaxAbs(ff), (PetscReal)1e-300);
      const PetscReal da = std::max(MaxDiff(ta, fa), MaxDiff(ta2, fa)) / sa, df = std::max(MaxDiff(tf, ff), MaxDiff(tf2, ff)) / sf;
      char what[128];
      std::snprintf(what, sizeof what, "mu = %.2f: thetaA (FromFOM, read back) = FOM (rel.)", (double)m);
      PetscCall(Check(comm, da <= 1e-14, what, da, 1e-14));
      std::snprintf(what, sizeof what, "mu = %.2f: thetaF (FromFOM, read back) = FOM (rel.)", (double)m);
      PetscCall(Check(comm, df <= 1e-14, what, df, 1e-14));
      PetscReal dmap = 0; // the geometric map read back
      for (PetscInt b = 0; b < (PetscInt)scene.bodies.size(); ++b) {
        const Affine a1 = fom.map.Evaluate(b, mm), a2 = par2.map.Evaluate(b, mm);
        for (int i = 0; i < 9; ++i) dmap = std::max(dmap, std::abs(a1.G[i] - a2.G[i]));
        for (int i = 0; i < 3; ++i) dmap = std::max(dmap, std::abs(a1.t[i] - a2.t[i]));
      }
      std::snprintf(what, sizeof what, "mu = %.2f: geometric map read back = FOM map (max |diff|)", (double)m);
      PetscCall(Check(comm, dmap <= 1e-15, what, dmap, 1e-15));
    }
    PetscReal dbox = 0;
    bool      same = par2.params.size() == scene.params.size() && par2.dim == dim && par2.bodies.size() == scene.bodies.size();
    for (size_t i = 0; same && i < scene.params.size(); ++i) {
      same = same && par2.params[i].name == scene.params[i].name;
      dbox = std::max({dbox, std::abs(par2.params[i].min - scene.params[i].min), std::abs(par2.params[i].max - scene.params[i].max), std::abs(par2.params[i].def - scene.params[i].def)});
    }
    for (size_t b = 0; same && b < scene.bodies.size(); ++b) same = par2.bodies[b].E == scene.bodies[b].E && par2.bodies[b].nu == scene.bodies[b].nu;
    PetscCall(PetscPrintf(comm, "     box read back: %s in [%g, %g], default %g\n", par2.params.empty() ? "?" : par2.params[0].name.c_str(), par2.params.empty() ? 0.0 : (double)par2.params[0].min, par2.params.empty() ? 0.0 : (double)par2.params[0].max, par2.params.empty() ? 0.0 : (double)par2.params[0].def));
    PetscCall(Check(comm, same && dbox == 0, "box, names, dim, materials read back = scene (max |diff| of the box)", dbox, 0));
    // The scene's coefficients are constant (a 2D dilation leaves the effective tensor unchanged):
    // synthetic coefficients of every kind that do vary with mu, evaluated by the parametrization
    // (its parameter-only Elasticity and the serialized map, read back) against Coefficient::Evaluate
    // with the FOM's Elasticity and map.
    {
      ReducedParametrization syn, syn2;
      PetscCall(syn.FromFOM(fom.elas, fom.map, fom.affine));
      syn.thetaA.clear();
      syn.thetaF.clear();
      for (PetscInt b = 0; b < (PetscInt)scene.bodies.size(); ++b) {
        for (PetscInt entry : {(PetscInt)0, (PetscInt)1, (PetscInt)2, (PetscInt)5, fom.elas.AuxTensorOffset(), fom.elas.AuxTensorOffset() + 3, fom.elas.AuxSize() - 1}) {
          Coefficient c;
          c.tensorBody  = b;
          c.tensorEntry = entry;
          c.scale       = 0.5 + entry;
          syn.thetaA.push_back(c);
        }
        Coefficient d, f, all;
        d.detBody  = b;
        f.surfBody = b;
        all.tensorBody = b, all.tensorEntry = 2, all.detBody = b, all.surfBody = b, all.param = 0, all.scale = -3.25;
        syn.thetaA.push_back(d);
        syn.thetaF.push_back(f);
        syn.thetaF.push_back(all);
      }
      Coefficient pm;
      pm.param = 0;
      pm.scale = 2;
      syn.thetaF.push_back(pm);
      RomWriter w2;
      syn.Write(&w2);
      PetscCall(w2.Write(comm, parFile));
      PetscCall(syn2.Read(parFile));
      PetscReal dmax = 0, spread = 0;
      std::vector<PetscReal> first;
      for (PetscReal m : {0.95, 1.0, 1.07, 1.15}) {
        const std::vector<PetscReal> mm = {m};
        std::vector<PetscReal>       ref, t1, t2, a, f2;
        for (const auto &c : syn.thetaA) ref.push_back(c.Evaluate(fom.elas, &fom.map, mm));
        for (const auto &c : syn.thetaF) ref.push_back(c.Evaluate(fom.elas, &fom.map, mm));
        syn.ThetaA(mm, &t1);
        syn.ThetaF(mm, &a);
        t1.insert(t1.end(), a.begin(), a.end());
        syn2.ThetaA(mm, &t2);
        syn2.ThetaF(mm, &f2);
        t2.insert(t2.end(), f2.begin(), f2.end());
        for (size_t i = 0; i < ref.size(); ++i) {
          const PetscReal sc = std::max(std::abs(ref[i]), (PetscReal)1e-300);
          dmax = std::max({dmax, i < t1.size() ? std::abs(t1[i] - ref[i]) / sc : (PetscReal)INFINITY, i < t2.size() ? std::abs(t2[i] - ref[i]) / sc : (PetscReal)INFINITY});
        }
        if (first.empty()) first = ref;
        else
          for (size_t i = 0; i < ref.size(); ++i) spread = std::max(spread, std::abs(ref[i] - first[i]) / std::max(std::abs(first[i]), (PetscReal)1e-300));
      }
      PetscCall(PetscPrintf(comm, "     synthetic coefficients: %zu A, %zu F; largest relative variation over mu %.3e\n", syn.thetaA.size(), syn.thetaF.size(), (double)spread));
      PetscCall(Check(comm, spread > 0.1, "synthetic coefficients vary with mu (max rel. variation)", spread, 0.1));
      PetscCall(Check(comm, dmax <= 1e-14, "synthetic thetas (FromFOM, read back) = Coefficient::Evaluate (rel.)", dmax, 1e-14));
    }
    // CheckBox: inside accepted, outside (and a wrong size) rejected with an error
    PetscErrorCode eIn = 0, eOut, eOut2, eSize;
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    for (PetscReal m : {0.95, 1.0, 1.07, 1.15}) eIn = eIn ? eIn : par2.CheckBox(comm, {m});
    eOut  = par.CheckBox(comm, {1.2});
    eOut2 = par2.CheckBox(comm, {1.2});
    eSize = par2.CheckBox(comm, {1.0, 1.0});
    PetscCall(PetscPopErrorHandler());
    PetscCall(PetscPrintf(comm, "     CheckBox error codes: inside %d, mu = 1.2 %d (read back %d), two values %d\n", (int)eIn, (int)eOut, (int)eOut2, (int)eSize));
    PetscCall(Check(comm, eIn == 0, "CheckBox accepts 0.95, 1.0, 1.07, 1.15 (error code)", (double)eIn, 0));
    PetscCall(Check(comm, eOut != 0 && eOut2 != 0, "CheckBox rejects mu = 1.2 (error code; 0 = accepted)", (double)std::min(eOut, eOut2), 0));
    PetscCall(Check(comm, eSize != 0, "CheckBox rejects a wrong number of parameters (error code)", (double)eSize, 0));
  }

  // ---------------------------------------------------------------- 4. patch serialization
  PetscCall(PetscPrintf(comm, "4. serialized patches (full, restricted) evaluate bitwise identically\n"));
  {
    RomWriter w;
    for (const auto &pp : {std::make_pair(std::string("/full"), &full), std::make_pair(std::string("/local"), &local)}) {
      std::vector<std::pair<std::string, std::pair<std::vector<unsigned long long>, std::vector<double>>>> items;
      pp.second->Serialize(&items);
      for (auto &it : items) w.Dataset(pp.first + "/" + it.first, it.second.first, it.second.second);
    }
    PetscCall(w.Write(comm, patchFile));
    ContactPatch full2, local2;
    PetscCall(full2.Deserialize(patchFile, "/full"));
    PetscCall(local2.Deserialize(patchFile, "/local"));
    struct Pair {
      const char   *name;
      ContactPatch *a, *b;
    } pairs[2] = {{"full", &full, &full2}, {"restricted", &local, &local2}};
    for (auto &pr : pairs) {
      pr.a->SetGeometry(&fom.map, mu);
      pr.b->SetGeometry(&fom.map, mu);
      pr.a->SetReduced(v);
      pr.b->SetReduced(v);
      const std::vector<PetscInt> idx = Iota(pr.a->NumPoints());
      Eval                        ea, eb;
      EvaluatePatch(*pr.a, idx, &ea);
      EvaluatePatch(*pr.b, idx, &eb);
      const bool same = pr.b->NumPoints() == pr.a->NumPoints() && Bitwise(ea.kappa, eb.kappa) && Bitwise(ea.gamma, eb.gamma) && ea.hit == eb.hit && ea.outside == eb.outside;
      PetscReal  dk, dg;
      RelDiffs(ea, eb, &dk, &dg);
      char what[128];
      std::snprintf(what, sizeof what, "%s patch (%" PetscInt_FMT " points) read back: bitwise (max rel. diff)", pr.name, pr.b->NumPoints());
      PetscCall(Check(comm, same, what, std::max(dk, dg), 0));
    }
  }
  PetscCallMPI(MPI_Barrier(comm));
  if (rank == 0) {
    std::remove(parFile.c_str());
    std::remove(patchFile.c_str());
  }
  PetscCall(PetscPrintf(comm, "%s (%d failure(s))\n", failures ? "reduced_contact test FAILED" : "reduced_contact test passed", failures));
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCall(Run()); // every PETSc object is destroyed before PetscFinalize
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
