// src/fem/geometry_map.cpp: affine building blocks of the reference-configuration map and their
// setup from options.
#include "rbcontact/geometry_map.hpp"
#include <cmath>
#include <sstream>

namespace rbc {

Affine Affine::Then(const Affine &n) const
{
  Affine r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      r.G[3 * i + j] = 0;
      for (int k = 0; k < 3; ++k) r.G[3 * i + j] += n.G[3 * i + k] * G[3 * k + j];
    }
    r.t[i] = n.t[i];
    for (int k = 0; k < 3; ++k) r.t[i] += n.G[3 * i + k] * t[k];
  }
  return r;
}

void Affine::Apply(PetscInt dim, const PetscReal x[], PetscReal y[]) const
{
  for (PetscInt i = 0; i < dim; ++i) {
    y[i] = t[i];
    for (PetscInt k = 0; k < dim; ++k) y[i] += G[3 * i + k] * x[k];
  }
}

PetscReal Affine::Det(PetscInt dim) const
{
  if (dim == 2) return G[0] * G[4] - G[1] * G[3];
  return G[0] * (G[4] * G[8] - G[5] * G[7]) - G[1] * (G[3] * G[8] - G[5] * G[6]) + G[2] * (G[3] * G[7] - G[4] * G[6]);
}

bool Affine::IsIdentity() const
{
  const Affine id;
  for (int i = 0; i < 9; ++i) if (G[i] != id.G[i]) return false;
  for (int i = 0; i < 3; ++i) if (t[i] != 0) return false;
  return true;
}

Affine Dilation::Evaluate(const std::vector<PetscReal> &mu) const
{
  const PetscReal s = mu[p_] / ref_;
  Affine          a;
  for (int i = 0; i < 3; ++i) {
    a.G[4 * i] = s;
    a.t[i]     = (1 - s) * c_[i];
  }
  return a;
}
std::string Dilation::Describe() const
{
  std::ostringstream o;
  o << "dilation by mu[" << p_ << "]/" << ref_ << " about (" << c_[0] << ", " << c_[1] << ", " << c_[2] << ")";
  return o.str();
}

Affine Stretch::Evaluate(const std::vector<PetscReal> &mu) const
{
  const PetscReal s = mu[p_] / ref_;
  Affine          a;
  a.G[4 * axis_] = s;
  a.t[axis_]     = (1 - s) * c_;
  return a;
}
std::string Stretch::Describe() const
{
  std::ostringstream o;
  o << "stretch of axis " << axis_ << " by mu[" << p_ << "]/" << ref_ << " about " << c_;
  return o.str();
}

Affine Translation::Evaluate(const std::vector<PetscReal> &mu) const
{
  Affine a;
  for (int i = 0; i < 3; ++i) a.t[i] = (mu[p_] - ref_) * d_[i];
  return a;
}
std::string Translation::Describe() const
{
  std::ostringstream o;
  o << "translation by (mu[" << p_ << "] - " << ref_ << ") (" << d_[0] << ", " << d_[1] << ", " << d_[2] << ")";
  return o.str();
}

std::array<PetscReal, 7> Dilation::Record() const { return {0, (PetscReal)p_, ref_, c_[0], c_[1], c_[2], 0}; }
std::array<PetscReal, 7> Stretch::Record() const { return {1, (PetscReal)p_, ref_, c_, 0, 0, (PetscReal)axis_}; }
std::array<PetscReal, 7> Translation::Record() const { return {2, (PetscReal)p_, ref_, d_[0], d_[1], d_[2], 0}; }

std::unique_ptr<AffineBlock> AffineBlockFromRecord(const std::array<PetscReal, 7> &r)
{
  const PetscInt p = (PetscInt)r[1];
  switch ((int)r[0]) {
  case 0: return std::make_unique<Dilation>(p, r[2], std::array<PetscReal, 3>{r[3], r[4], r[5]});
  case 1: return std::make_unique<Stretch>(p, r[2], (PetscInt)r[6], r[3]);
  case 2: return std::make_unique<Translation>(p, r[2], std::array<PetscReal, 3>{r[3], r[4], r[5]});
  default: return nullptr;
  }
}

std::vector<PetscReal> GeometryMap::Records() const
{
  std::vector<PetscReal> rec;
  for (size_t b = 0; b < bodies.size(); ++b)
    for (const auto &blk : bodies[b].blocks) {
      const auto r = blk->Record();
      rec.push_back((PetscReal)b);
      rec.insert(rec.end(), r.begin(), r.end());
    }
  return rec;
}

PetscErrorCode GeometryMap::FromRecords(PetscInt nbodies, const std::vector<PetscReal> &rec)
{
  PetscFunctionBeginUser;
  PetscCheck(rec.size() % 8 == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "geometry map: %zu values is not a multiple of 8", rec.size());
  bodies.clear();
  bodies.resize(nbodies);
  for (size_t i = 0; i < rec.size(); i += 8) {
    const PetscInt b = (PetscInt)rec[i];
    PetscCheck(b >= 0 && b < nbodies, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "geometry map: block of body %" PetscInt_FMT " (%" PetscInt_FMT " bodies)", b, nbodies);
    std::array<PetscReal, 7> r;
    for (int k = 0; k < 7; ++k) r[k] = rec[i + 1 + k];
    auto blk = AffineBlockFromRecord(r);
    PetscCheck(blk, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "geometry map: unknown block type %g", (double)r[0]);
    bodies[b].blocks.push_back(std::move(blk));
  }
  PetscFunctionReturn(0);
}

Affine BodyMap::Evaluate(const std::vector<PetscReal> &mu) const
{
  Affine a;
  for (const auto &b : blocks) a = a.Then(b->Evaluate(mu));
  return a;
}

Affine GeometryMap::Evaluate(PetscInt body, const std::vector<PetscReal> &mu) const
{
  if (body < 0 || body >= (PetscInt)bodies.size()) return Affine();
  return bodies[body].Evaluate(mu);
}

bool GeometryMap::IsIdentity() const
{
  for (const auto &b : bodies) if (!b.blocks.empty()) return false;
  return true;
}

std::string GeometryMap::Describe(const SceneSpec &scene) const
{
  std::ostringstream o;
  for (size_t b = 0; b < bodies.size(); ++b) {
    o << scene.bodies[b].name << ": ";
    if (bodies[b].blocks.empty()) o << "fixed";
    for (size_t k = 0; k < bodies[b].blocks.size(); ++k) o << (k ? " then " : "") << bodies[b].blocks[k]->Describe();
    o << (b + 1 < bodies.size() ? "; " : "");
  }
  return o.str();
}

std::vector<PetscReal> ParamValues(const SceneSpec &scene)
{
  std::vector<PetscReal> mu;
  for (const auto &p : scene.params) mu.push_back(p.value);
  return mu;
}

PetscErrorCode GeometryMap::SetFromOptions(MPI_Comm comm, const SceneSpec &scene)
{
  PetscFunctionBeginUser;
  bodies.clear();
  needs_.clear();
  bodies.resize(scene.bodies.size());
  PetscOptionsBegin(comm, NULL, "Geometry maps of the reference configuration, per body (docs/reference_configuration.md)", "GeometryMap");
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const std::string pre = "-map_" + scene.bodies[b].name;
    char              buf[256] = "";
    PetscBool         flg;
    PetscCall(PetscOptionsString(pre.c_str(), "Map blocks of this body: dilation, stretch, translation (comma separated)", "docs/reference_configuration.md", buf, buf, sizeof buf, &flg));
    if (!flg) continue;
    for (const auto &kind : SplitList(buf)) {
      const std::string bp = pre + "_" + kind;
      char              pname[128] = "";
      PetscCheck(kind == "dilation" || kind == "stretch" || kind == "translation", comm, PETSC_ERR_ARG_UNKNOWN_TYPE, "%s: unknown map block '%s' (dilation, stretch, translation)", pre.c_str(), kind.c_str());
      PetscCall(PetscOptionsString((bp + "_param").c_str(), "Parameter (of -mu_names) driving this block", "docs/reference_configuration.md", pname, pname, sizeof pname, &flg));
      PetscCheck(flg, comm, PETSC_ERR_USER_INPUT, "%s lists '%s' but %s_param (the driving parameter) is missing", pre.c_str(), kind.c_str(), bp.c_str());
      PetscInt p = -1;
      for (size_t i = 0; i < scene.params.size(); ++i) if (scene.params[i].name == pname) p = (PetscInt)i;
      PetscCheck(p >= 0, comm, PETSC_ERR_USER_INPUT, "%s_param: unknown parameter '%s' (declared by -mu_names)", bp.c_str(), pname);
      PetscCheck(scene.params[p].geoName.empty(), comm, PETSC_ERR_USER_INPUT, "Parameter '%s' both remeshes (-mu_geo_set) and drives %s: choose one", pname, pre.c_str());
      PetscReal ref = scene.params[p].def;
      PetscCall(PetscOptionsReal((bp + "_ref").c_str(), "Parameter value of the mesh (default: -mu_default)", "docs/reference_configuration.md", ref, &ref, NULL));
      PetscCheck(ref != 0 && std::isfinite(ref), comm, PETSC_ERR_ARG_OUTOFRANGE, "%s_ref must be a finite nonzero number", bp.c_str());
      if (kind == "dilation" || kind == "translation") {
        PetscReal v[4] = {0, 0, 0, 0}; // (room for a fourth value: PETSc drops the values beyond the buffer silently)
        PetscInt  n    = 4;
        const std::string opt = bp + (kind == "dilation" ? "_center" : "_dir");
        PetscCall(PetscOptionsRealArray(opt.c_str(), kind == "dilation" ? "Fixed point of the dilation" : "Direction of the translation", "docs/reference_configuration.md", v, &n, &flg));
        PetscCheck(flg, comm, PETSC_ERR_USER_INPUT, "%s is required", opt.c_str());
        PetscCheck(n <= 3, comm, PETSC_ERR_ARG_SIZ, "%s takes at most 3 coordinates, more were given", opt.c_str());
        for (PetscInt i = 0; i < n; ++i) PetscCheck(std::isfinite(v[i]), comm, PETSC_ERR_USER_INPUT, "%s: coordinate %" PetscInt_FMT " is not a finite number", opt.c_str(), i + 1);
        needs_.push_back({opt, n, true}); // (fewer coordinates than the mesh's dimension were padded with 0: another map, exit 0)
        const std::array<PetscReal, 3> a = {v[0], v[1], v[2]};
        if (kind == "dilation") bodies[b].blocks.push_back(std::make_unique<Dilation>(p, ref, a));
        else bodies[b].blocks.push_back(std::make_unique<Translation>(p, ref, a));
      } else if (kind == "stretch") {
        PetscInt  axis = -1;
        PetscReal c    = 0;
        PetscCall(PetscOptionsInt((bp + "_axis").c_str(), "Stretched axis (0, 1, 2)", "docs/reference_configuration.md", axis, &axis, NULL));
        PetscCall(PetscOptionsReal((bp + "_center").c_str(), "Fixed coordinate of the stretch", "docs/reference_configuration.md", c, &c, NULL));
        PetscCheck(axis >= 0 && axis < 3, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s_axis %" PetscInt_FMT " must be 0, 1 or 2", bp.c_str(), axis);
        PetscCheck(std::isfinite(c), comm, PETSC_ERR_USER_INPUT, "%s_center is not a finite number", bp.c_str());
        needs_.push_back({bp + "_axis", axis, false}); // (axis 2 of a 2D mesh: the parameter did nothing, exit 0)
        bodies[b].blocks.push_back(std::make_unique<Stretch>(p, ref, axis, c));
      }
    }
  }
  PetscOptionsEnd();
  PetscFunctionReturn(0);
}

PetscErrorCode GeometryMap::CheckDimension(MPI_Comm comm, PetscInt dim) const
{
  PetscFunctionBeginUser;
  for (const auto &n : needs_) {
    // fewer were padded with 0 (another map); more in 2D dropped the third (a translation along z did nothing), exit 0
    if (n.coordinates) PetscCheck(n.value == dim, comm, PETSC_ERR_USER_INPUT, "%s has %" PetscInt_FMT " coordinate(s); the mesh is %" PetscInt_FMT "D: give %" PetscInt_FMT, n.option.c_str(), n.value, dim, dim);
    else PetscCheck(n.value < dim, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s %" PetscInt_FMT ": the mesh is %" PetscInt_FMT "D (axes 0 to %" PetscInt_FMT ")", n.option.c_str(), n.value, dim, dim - 1);
  }
  PetscFunctionReturn(0);
}

} // namespace rbc
