// src/fem/affine_decomposition.cpp: automatic affine decomposition of A(mu) and f(mu) by sampling the
// coefficient functions of the effective tensors and loads, dropping zeros and merging proportional
// ones; assembly of the mu-independent terms with PetscFE.
#include "rbcontact/affine_decomposition.hpp"
#include <algorithm>
#include <cmath>
#include <sstream>

namespace rbc {

PetscReal Coefficient::Evaluate(const Elasticity &elas, const GeometryMap *map, const std::vector<PetscReal> &mu) const
{
  PetscReal v = scale;
  if (tensorBody >= 0) {
    PetscReal              E, nu;
    std::vector<PetscReal> aux;
    elas.Material(tensorBody, mu, &E, &nu);
    elas.PhysicalAux(E, nu, map ? map->Evaluate(tensorBody, mu) : Affine(), &aux);
    v *= aux[tensorEntry];
  }
  if (detBody >= 0) v *= std::abs((map ? map->Evaluate(detBody, mu) : Affine()).Det(elas.dim));
  if (surfBody >= 0) v *= std::pow((map ? map->Evaluate(surfBody, mu) : Affine()).G[0], (PetscReal)(elas.dim - 1));
  if (param >= 0) v *= mu[param] / elas.scene.params[param].def;
  return v;
}

std::string Coefficient::Describe(const SceneSpec &scene) const
{
  std::ostringstream o;
  o << scale;
  if (tensorBody >= 0) o << " * T_" << scene.bodies[tensorBody].name << "[" << tensorEntry << "](mu)";
  if (detBody >= 0) o << " * |det G_" << scene.bodies[detBody].name << "(mu)|";
  if (surfBody >= 0) o << " * s_" << scene.bodies[surfBody].name << "(mu)^(d-1)";
  if (param >= 0) o << " * " << scene.params[param].name << "/" << scene.params[param].def;
  return o.str();
}

AffineDecomposition::~AffineDecomposition()
{
  for (auto &A : Aq) (void)MatDestroy(&A);
  for (auto &f : fq) (void)VecDestroy(&f);
}

// Deterministic sample points in the box: centre, corners (p <= 4), then a low-discrepancy fill.
static std::vector<std::vector<PetscReal>> SamplePoints(const std::vector<ParamSpec> &params, PetscInt n)
{
  std::vector<std::vector<PetscReal>> pts;
  const size_t                        p = params.size();
  std::vector<PetscReal>              c(p);
  for (size_t i = 0; i < p; ++i) c[i] = params[i].def;
  pts.push_back(c);
  if (p <= 4)
    for (unsigned m = 0; m < (1u << p); ++m) {
      std::vector<PetscReal> x(p);
      for (size_t i = 0; i < p; ++i) x[i] = (m >> i) & 1 ? params[i].max : params[i].min;
      pts.push_back(x);
    }
  const PetscReal primes[] = {2, 3, 5, 7, 11, 13, 17, 19};
  for (PetscInt k = 1; (PetscInt)pts.size() < n; ++k) {
    std::vector<PetscReal> x(p);
    for (size_t i = 0; i < p; ++i) {
      // van der Corput in base primes[i % 8]
      PetscReal f = 1, r = 0;
      for (PetscInt q = k; q > 0; q /= (PetscInt)primes[i % 8]) { f /= primes[i % 8]; r += f * (q % (PetscInt)primes[i % 8]); }
      x[i] = params[i].min + r * (params[i].max - params[i].min);
    }
    pts.push_back(x);
  }
  return pts;
}

// Groups sample vectors by proportionality. Returns group ids (-1: zero) and, per group, whether it
// is constant. ratio[i] = v_i / v_rep(group) (at the representative's largest sample).
static void GroupProportional(const std::vector<std::vector<PetscReal>> &v, std::vector<PetscInt> *gid, std::vector<PetscInt> *rep, std::vector<PetscReal> *ratio, std::vector<bool> *constant)
{
  PetscReal vmax = 0;
  for (const auto &x : v) for (PetscReal y : x) vmax = std::max(vmax, std::abs(y));
  const size_t n = v.size();
  gid->assign(n, -1);
  ratio->assign(n, 0.0);
  rep->clear();
  constant->clear();
  auto normalized = [](const std::vector<PetscReal> &x) {
    size_t k = 0;
    for (size_t i = 0; i < x.size(); ++i) if (std::abs(x[i]) > std::abs(x[k])) k = i;
    std::vector<PetscReal> y(x.size());
    for (size_t i = 0; i < x.size(); ++i) y[i] = x[i] / x[k];
    return y;
  };
  std::vector<std::vector<PetscReal>> nv(n);
  for (size_t i = 0; i < n; ++i) {
    PetscReal m = 0;
    for (PetscReal y : v[i]) m = std::max(m, std::abs(y));
    if (m <= 1e-13 * vmax || m == 0) continue; // identically zero (to round-off)
    nv[i] = normalized(v[i]);
    PetscInt g = -1;
    for (size_t r = 0; r < rep->size() && g < 0; ++r) {
      const auto &w = nv[(*rep)[r]];
      bool        same = true;
      for (size_t k = 0; k < w.size() && same; ++k) same = std::abs(w[k] - nv[i][k]) <= 1e-11;
      if (same) g = (PetscInt)r;
    }
    if (g < 0) {
      g = (PetscInt)rep->size();
      rep->push_back((PetscInt)i);
      bool c = true;
      for (PetscReal y : nv[i]) c = c && std::abs(y - 1.0) <= 1e-11;
      constant->push_back(c);
    }
    (*gid)[i] = g;
    const auto &r = v[(*rep)[g]];
    size_t      k = 0;
    for (size_t j = 0; j < r.size(); ++j) if (std::abs(r[j]) > std::abs(r[k])) k = j;
    (*ratio)[i] = v[i][k] / r[k];
  }
}

PetscErrorCode AffineDecomposition::Build(Elasticity &elas, const GeometryMap *map)
{
  const SceneSpec &scene = elas.scene;
  const PetscInt   dim   = elas.dim, d4 = dim * dim * dim * dim, t0 = elas.AuxTensorOffset();
  const size_t     nb    = scene.bodies.size();
  PetscInt         nsamples = 12;

  PetscFunctionBeginUser;
  elas_ = &elas;
  map_  = map;
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-affine_samples", &nsamples, NULL));
  PetscCheck(nsamples >= 2, PetscObjectComm((PetscObject)elas.dm), PETSC_ERR_ARG_OUTOFRANGE, "-affine_samples %" PetscInt_FMT " must be >= 2", nsamples);
  const auto samples = SamplePoints(scene.params, scene.params.empty() ? 1 : nsamples);

  // --- A: one atomic coefficient per (body, tensor entry)
  std::vector<Coefficient>            atoms;
  std::vector<std::vector<PetscReal>> vals;
  for (size_t b = 0; b < nb; ++b)
    for (PetscInt e = 0; e < d4; ++e) {
      Coefficient c;
      c.tensorBody  = (PetscInt)b;
      c.tensorEntry = t0 + e;
      std::vector<PetscReal> v;
      for (const auto &mu : samples) v.push_back(c.Evaluate(elas, map, mu));
      atoms.push_back(c);
      vals.push_back(v);
    }
  std::vector<PetscInt>  gid, rep;
  std::vector<PetscReal> ratio;
  std::vector<bool>      constant;
  GroupProportional(vals, &gid, &rep, &ratio, &constant);
  std::vector<std::vector<std::vector<PetscReal>>> groupAux(rep.size(), std::vector<std::vector<PetscReal>>(nb, std::vector<PetscReal>(elas.AuxSize(), 0.0)));
  std::vector<std::vector<bool>>                   groupBodies(rep.size(), std::vector<bool>(nb, false));
  for (size_t i = 0; i < atoms.size(); ++i) {
    const PetscInt g = gid[i];
    if (g < 0) continue;
    // constant group: weights are the values themselves (theta = 1)
    groupAux[g][atoms[i].tensorBody][atoms[i].tensorEntry] = constant[g] ? vals[i][0] : ratio[i];
    groupBodies[g][atoms[i].tensorBody] = true;
  }
  for (size_t g = 0; g < rep.size(); ++g) {
    Coefficient c = constant[g] ? Coefficient() : atoms[rep[g]];
    std::ostringstream why;
    why << (constant[g] ? "constant" : "varies with mu") << ": stiffness of ";
    bool first = true;
    for (size_t b = 0; b < nb; ++b)
      if (groupBodies[g][b]) { why << (first ? "" : ", ") << scene.bodies[b].name; first = false; }
    if (!constant[g]) why << "; theta = " << c.Describe(scene);
    Mat A = nullptr;
    PetscCall(elas.SetBodyAux(groupAux[g]));
    PetscCall(elas.AssembleMatrix(&A));
    Aq.push_back(A);
    thetaA.push_back(c);
    whyA.push_back(why.str());
  }

  // --- f: lifting (per A term x Dirichlet load factor), body forces (per body), tractions
  std::vector<Coefficient> fatoms;
  std::vector<Vec>         fvecs;
  std::vector<std::string> fwhy;
  const size_t             nd = scene.dirichlet.size(), nt = scene.tractions.size();
  std::vector<PetscInt>    dparams;
  for (const auto &bc : scene.dirichlet) if (std::find(dparams.begin(), dparams.end(), bc.param) == dparams.end()) dparams.push_back(bc.param);
  const std::vector<std::vector<PetscReal>> zeroAux(nb, std::vector<PetscReal>(elas.AuxSize(), 0.0));
  for (size_t g = 0; g < Aq.size(); ++g)
    for (PetscInt dp : dparams) {
      std::vector<PetscReal> ds(nd, 0.0), ts(nt, 0.0);
      for (size_t k = 0; k < nd; ++k) ds[k] = scene.dirichlet[k].param == dp ? 1.0 : 0.0;
      PetscCall(elas.SetBodyAux(groupAux[g]));
      PetscCall(elas.SetLoadScales(ds, 0.0, ts));
      Vec f = nullptr;
      PetscCall(elas.AssembleRhs(&f));
      PetscReal nrm;
      PetscCall(VecNorm(f, NORM_INFINITY, &nrm));
      if (nrm == 0) { PetscCall(VecDestroy(&f)); continue; } // homogeneous Dirichlet data: no lifting
      Coefficient c = thetaA[g];
      c.param       = dp;
      fatoms.push_back(c);
      fvecs.push_back(f);
      fwhy.push_back("Dirichlet lifting of A term " + std::to_string(g) + (dp >= 0 ? " scaled by " + scene.params[dp].name : std::string()));
    }
  if (!scene.bodyForce.empty() && !scene.bodyForceF0)
    for (size_t b = 0; b < nb; ++b) {
      std::vector<std::vector<PetscReal>> aux = zeroAux;
      aux[b][elas.AuxBodyForceIndex()] = 1.0; // body-force scale on body b only
      PetscCall(elas.SetBodyAux(aux));
      PetscCall(elas.SetLoadScales(std::vector<PetscReal>(nd, 0.0), 1.0, std::vector<PetscReal>(nt, 0.0)));
      Vec f = nullptr;
      PetscCall(elas.AssembleRhs(&f));
      Coefficient c;
      c.detBody = (PetscInt)b;
      fatoms.push_back(c);
      fvecs.push_back(f);
      fwhy.push_back("body force on " + scene.bodies[b].name + " (scales with |det G|)");
    }
  for (size_t k = 0; k < nt; ++k) {
    std::vector<PetscReal> ts(nt, 0.0);
    ts[k] = 1.0;
    PetscCall(elas.SetBodyAux(zeroAux));
    PetscCall(elas.SetLoadScales(std::vector<PetscReal>(nd, 0.0), 0.0, ts));
    Vec f = nullptr;
    PetscCall(elas.AssembleRhs(&f));
    Coefficient c;
    const PetscInt ob = elas.TractionBody()[k];
    if (ob >= 0 && map && !map->bodies[ob].blocks.empty()) c.surfBody = ob;
    c.param = scene.tractions[k].param;
    fatoms.push_back(c);
    fvecs.push_back(f);
    fwhy.push_back("traction on " + scene.tractions[k].label);
  }
  // merge proportional f coefficients
  std::vector<std::vector<PetscReal>> fvals;
  for (const auto &c : fatoms) {
    std::vector<PetscReal> v;
    for (const auto &mu : samples) v.push_back(c.Evaluate(elas, map, mu));
    fvals.push_back(v);
  }
  std::vector<PetscInt>  fg, frep;
  std::vector<PetscReal> fratio;
  std::vector<bool>      fconst;
  GroupProportional(fvals, &fg, &frep, &fratio, &fconst);
  for (size_t g = 0; g < frep.size(); ++g) {
    Vec         f = nullptr;
    std::string why;
    for (size_t i = 0; i < fatoms.size(); ++i) {
      if (fg[i] != (PetscInt)g) continue;
      if (!f) {
        PetscCall(VecDuplicate(fvecs[i], &f));
        PetscCall(VecSet(f, 0.0));
      }
      PetscCall(VecAXPY(f, fconst[g] ? fvals[i][0] : fratio[i], fvecs[i]));
      why += (why.empty() ? "" : " + ") + fwhy[i];
    }
    fq.push_back(f);
    thetaF.push_back(fconst[g] ? Coefficient() : fatoms[frep[g]]);
    whyF.push_back(std::string(fconst[g] ? "constant: " : "varies with mu: ") + why);
  }
  for (auto &v : fvecs) PetscCall(VecDestroy(&v));
  // restore the physical state
  PetscCall(elas.SetMu(ParamValues(scene)));
  PetscFunctionReturn(0);
}

std::vector<PetscReal> AffineDecomposition::ThetaA(const std::vector<PetscReal> &mu) const
{
  std::vector<PetscReal> t;
  for (const auto &c : thetaA) t.push_back(c.Evaluate(*elas_, map_, mu));
  return t;
}

std::vector<PetscReal> AffineDecomposition::ThetaF(const std::vector<PetscReal> &mu) const
{
  std::vector<PetscReal> t;
  for (const auto &c : thetaF) t.push_back(c.Evaluate(*elas_, map_, mu));
  return t;
}

PetscErrorCode AffineDecomposition::Residual(const std::vector<PetscReal> &mu, Vec u, Vec t, Vec r) const
{
  PetscFunctionBeginUser;
  const std::vector<PetscReal> ta = ThetaA(mu), tf = ThetaF(mu);
  PetscCall(VecSet(r, 0.0));
  for (size_t q = 0; q < ta.size(); ++q) {
    PetscCall(MatMult(Aq[q], u, t));
    PetscCall(VecAXPY(r, ta[q], t));
  }
  for (size_t q = 0; q < tf.size(); ++q) PetscCall(VecAXPY(r, -tf[q], fq[q]));
  PetscFunctionReturn(0);
}

PetscErrorCode AffineDecomposition::Assemble(const std::vector<PetscReal> &mu, Mat *A, Vec *f) const
{
  PetscFunctionBeginUser;
  const auto ta = ThetaA(mu), tf = ThetaF(mu);
  if (!*A) {
    PetscCall(MatDuplicate(Aq[0], MAT_DO_NOT_COPY_VALUES, A));
    PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(*A, MAT_SPD, PETSC_TRUE));
  }
  PetscCall(MatZeroEntries(*A));
  for (size_t q = 0; q < Aq.size(); ++q) PetscCall(MatAXPY(*A, ta[q], Aq[q], SAME_NONZERO_PATTERN));
  if (!*f) PetscCall(DMCreateGlobalVector(elas_->dm, f)); // carries the DM (output, BC insertion)
  PetscCall(VecSet(*f, 0.0));
  for (size_t q = 0; q < fq.size(); ++q) PetscCall(VecAXPY(*f, tf[q], fq[q]));
  PetscFunctionReturn(0);
}

void AffineDecomposition::Describe(JsonValue *out) const
{
  (*out)["A"] = (long long)Aq.size();
  (*out)["f"] = (long long)fq.size();
  JsonValue a = JsonValue::Array(), f = JsonValue::Array();
  for (const auto &w : whyA) a.Push(JsonValue::String(w));
  for (const auto &w : whyF) f.Push(JsonValue::String(w));
  (*out)["A_terms"] = a;
  (*out)["f_terms"] = f;
}

} // namespace rbc
