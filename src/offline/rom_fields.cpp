// src/offline/rom_fields.cpp: full-order fields of reduced solutions (validation, -rom_reconstruct).
#include "rbcontact/rom_fields.hpp"
#include "rbcontact/kacanov.hpp"
#include "rbcontact/rom_file.hpp"
#include "rbcontact/options_files.hpp"
#include <cstring>
#include <cmath>
#include <filesystem>
#include <sstream>
#include "rbcontact/mesh.hpp"

namespace rbc {

// Everything that defines the problem (not the run): the snapshot file's scene hash.
std::string SceneFingerprint(const SceneSpec &s, const GeometryMap &map)
{
  std::ostringstream o;
  o.precision(17);
  o << "scene " << s.name << "|mesh " << s.mesh.file << " " << s.mesh.clscale;
  for (const auto &g : s.mesh.geoNumbers) o << " " << g.first << "=" << g.second;
  o << "|degree " << s.degree;
  for (const auto &b : s.bodies) o << "|body " << b.name << " " << b.E << " " << b.nu << " " << b.paramE << " " << b.paramNu;
  for (const auto &d : s.dirichlet) {
    o << "|dirichlet " << d.label << " " << d.param;
    for (auto v : d.values) o << " " << v;
    for (auto c : d.comps) o << " c" << c;
  }
  for (const auto &t : s.tractions) {
    o << "|traction " << t.label << " " << t.param;
    for (auto v : t.traction) o << " " << v;
  }
  for (auto v : s.bodyForce) o << "|bf " << v;
  o << "|contact " << s.contact << " " << s.slave << " " << s.master;
  for (const auto &p : s.params) o << "|param " << p.name << " " << p.min << " " << p.max << " " << p.def;
  o << "|map " << map.Describe(s);
  { // the multiplier functions change the problem; always in the hash (files of the standard default differ)
    char mult[64] = "dual";
    (void)PetscOptionsGetString(NULL, NULL, "-contact_multiplier", mult, sizeof mult, NULL);
    o << "|multiplier " << mult;
  }
  // (the options that change the discrete problem; only when given, so that the files of the defaults keep their hash.
  // -contact_quadrature_subdivisions was missing until 2026-11-29: a resumed file mixed two composite rules)
  for (const char *opt : {"-contact_quadrature", "-contact_quadrature_points", "-contact_quadrature_subdivisions", "-contact_normal"}) {
    char      v[256] = "";
    PetscBool set;
    if (!PetscOptionsGetString(NULL, NULL, opt, v, sizeof v, &set) && set) o << "|" << opt << " " << v;
  }
  return o.str();
}

std::string SceneHashHex(const SceneSpec &s, const GeometryMap &map)
{
  std::ostringstream hs;
  hs << std::hex << Fnv1a(SceneFingerprint(s, map));
  return hs.str();
}

PetscErrorCode CheckRomScene(MPI_Comm comm, const std::string &romPath, const SceneSpec &scene, const GeometryMap &map)
{
  std::string stored, romScene;
  PetscFunctionBeginUser;
  PetscCall(RomReadAttr(romPath, "scene", &romScene));
  PetscCheck(scene.name == romScene, comm, PETSC_ERR_USER_INPUT, "the scene of the options is '%s', the ROM %s was built for '%s' (give -options_file runs/%s.opts)", scene.name.c_str(), romPath.c_str(), romScene.c_str(), romScene.c_str());
  PetscCall(RomReadAttr(romPath, "scene_hash", &stored));
  const std::string now = SceneHashHex(scene, map);
  PetscCheck(stored == now, comm, PETSC_ERR_USER_INPUT, "the ROM %s was built for another configuration of scene '%s' (scene hash %s; the options now give %s): materials, loads, boundary conditions, parameters, maps, mesh or contact options differ. Rebuild it with offline, or run with the options it was built with (stored in its attribute 'options')", romPath.c_str(), scene.name.c_str(), stored.c_str(), now.c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode CheckSceneOptions(MPI_Comm comm, const std::string &stage, const std::string &romPath)
{
  // (-contact_normal, -contact_multiplier, -contact_quadrature* were "not used (misspelled?)" until 2026-12-02: they enter the scene hash)
  static const char *const sceneFamilies[] = {"-scene", "-bodies", "-body_", "-mesh_file", "-mesh_refine", "-mesh_clscale", "-mesh_geo_set", "-dirichlet", "-traction", "-contact_slave",
                                              "-contact_master", "-contact_normal", "-contact_multiplier", "-contact_quadrature", "-mu_names", "-mu_min", "-mu_max", "-mu_default", "-mu_geo_set", "-map_", "-fem_degree", "-param_"};
  std::string first;
  char        sceneName[256] = "";
  PetscBool   hasScene       = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-scene", sceneName, sizeof sceneName, &hasScene));
  for (const auto &o : OptionsInUse())
    for (const char *f : sceneFamilies)
      if (first.empty() && o.first.compare(0, std::strlen(f), f) == 0) first = o.first;
  if (first.empty()) PetscFunctionReturn(0);
  PetscCheck(hasScene, comm, PETSC_ERR_USER_INPUT, "%s: option %s is a scene option, but %s solves the ROM %s as it was built (its scene's options are stored in it); give the whole scene (-options_file runs/<scene>.opts) to have them checked against the ROM, or leave them out", stage.c_str(), first.c_str(), stage.c_str(), romPath.c_str());
  // the scene's name first: another scene's options file was blamed on -mu ("the scene has 1 parameters") before
  std::string romScene;
  PetscCall(RomReadAttr(romPath, "scene", &romScene));
  PetscCheck(romScene == sceneName, comm, PETSC_ERR_USER_INPUT, "the scene of the options is '%s', the ROM %s was built for '%s' (give -options_file runs/%s.opts)", sceneName, romPath.c_str(), romScene.c_str(), romScene.c_str());
  SceneSpec   scene;
  GeometryMap map;
  PetscCall(SceneSpecFromOptions(comm, &scene));
  PetscCall(map.SetFromOptions(comm, scene));
  PetscCall(CheckRomScene(comm, romPath, scene, map));
  PetscFunctionReturn(0);
}

PetscErrorCode RomBases::Read(MPI_Comm comm, const ReducedModel &model, const std::string &romPath, PetscInt nd, PetscInt nmult)
{
  std::vector<unsigned long long> dims;
  char                            buf[PETSC_MAX_PATH_LEN] = "";
  PetscBool                       set;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-rom_basis", buf, sizeof buf, &set));
  if (set) {
    path = buf;
    std::error_code ec;
    PetscCheck(std::filesystem::exists(path, ec), comm, PETSC_ERR_FILE_OPEN, "basis file %s (-rom_basis): does not exist", path.c_str());
  } else {
    // stored relative to the ROM file's directory (files of before 2026-11-22: relative to the
    // offline run's working directory, the fallback)
    std::string stored;
    PetscCall(RomReadAttr(romPath, "basis_file", &stored));
    const std::filesystem::path p(stored), beside = std::filesystem::path(romPath).parent_path() / p;
    std::error_code             ec;
    path = p.is_relative() && std::filesystem::exists(beside, ec) ? beside.string() : stored;
    // a ROM moved without its basis file was "ROM file 'rom.basis.h5': does not exist"
    PetscCheck(std::filesystem::exists(path, ec), comm, PETSC_ERR_FILE_OPEN, "the basis file of the ROM %s (its attribute basis_file '%s') is neither beside it (%s) nor %s: give it with -rom_basis <file>", romPath.c_str(), stored.c_str(), beside.string().c_str(),
               p.is_relative() ? "relative to the working directory" : "at that path");
  }
  { // the pair written by one offline run (files of before 2026-11-23 have no rom_id on either: not checked)
    std::string idRom, idBasis;
    PetscErrorCode e1, e2;
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    e1 = RomReadAttr(romPath, "rom_id", &idRom);
    e2 = RomReadAttr(path, "rom_id", &idBasis);
    PetscCall(PetscPopErrorHandler());
    // (a basis file without one was accepted beside a ROM with one: another run's basis, lambda error 0.19 for 0.007)
    PetscCheck(e1 || !e2, comm, PETSC_ERR_FILE_UNEXPECTED, "basis file %s has no rom_id, the ROM %s has one (%s): both are written by one offline run, so this basis file is not the ROM's (or it is damaged); rerun offline (or give the right file with -rom_basis)", path.c_str(), romPath.c_str(), idRom.c_str());
    PetscCheck(e1 || idRom == idBasis, comm, PETSC_ERR_FILE_UNEXPECTED, "basis file %s (rom_id %s) was not written by the offline run of the ROM %s (rom_id %s): a mismatched or half-replaced pair; rerun offline (or give the right file with -rom_basis)", path.c_str(), idBasis.c_str(), romPath.c_str(), idRom.c_str());
  }
  PetscCall(RomReadDataset(path, "/pod/modes", &dims, &modes));
  PetscCheck(dims.size() == 2 && (PetscInt)dims[0] == model.Nfull && (PetscInt)dims[1] == nd, comm, PETSC_ERR_FILE_UNEXPECTED, "basis file %s: /pod/modes is %llu x %llu, the ROM %s has N = %" PetscInt_FMT " and the scene %" PetscInt_FMT " dofs (another scene or mesh?)", path.c_str(), dims.size() > 0 ? dims[0] : 0ULL, dims.size() > 1 ? dims[1] : 0ULL, romPath.c_str(), model.Nfull, nd);
  N     = model.Nfull;
  ndofs = nd;
  PetscCall(RomReadDataset(path, "/dual/basis", &dims, &W));
  PetscCheck(dims.size() == 2 && (PetscInt)dims[0] == model.Rfull, comm, PETSC_ERR_FILE_UNEXPECTED, "basis file %s: /dual/basis has %llu vectors, the ROM R = %" PetscInt_FMT, path.c_str(), dims.empty() ? 0ULL : dims[0], model.Rfull);
  PetscCheck((PetscInt)dims[1] == nmult, comm, PETSC_ERR_FILE_UNEXPECTED, "basis file %s: /dual/basis has vectors of length %llu, the scene has %" PetscInt_FMT " contact multipliers (another scene or mesh?)", path.c_str(), dims[1], nmult);
  r = (PetscInt)dims[0];
  R = (PetscInt)dims[1];
  PetscCall(RomCheckValues("basis file " + path, "/pod/modes", modes));
  PetscCall(RomCheckValues("basis file " + path, "/dual/basis", W));
  PetscFunctionReturn(0);
}

PetscErrorCode RomBases::Displacement(const ReducedModel &model, const CanonicalOrder &order, const std::vector<PetscReal> &v, Vec u) const
{
  PetscInt     lo, hi;
  PetscScalar *a;

  PetscFunctionBeginUser;
  const auto &cols = model.Columns();
  PetscCall(VecGetOwnershipRange(u, &lo, &hi));
  PetscCall(VecGetArray(u, &a));
  for (PetscInt i = lo; i < hi; ++i) {
    const PetscInt c = order.CanonicalDof(i);
    PetscReal      s = 0;
    for (size_t n = 0; n < cols.size(); ++n) s += v[n] * modes[(size_t)cols[n] * ndofs + c];
    a[i - lo] = s;
  }
  PetscCall(VecRestoreArray(u, &a));
  PetscFunctionReturn(0);
}

void RomBases::Multipliers(const ReducedModel &model, const std::vector<PetscReal> &lhat, std::vector<PetscReal> *lambda) const
{
  lambda->assign(R, 0.0);
  for (PetscInt k = 0; k < model.R(); ++k)
    for (PetscInt i = 0; i < R; ++i) (*lambda)[i] += lhat[k] * W[(size_t)k * R + i];
}

PetscErrorCode AssembleReferenceContact(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, ContactSystem *sys)
{
  Vec zero, uloc;

  PetscFunctionBeginUser;
  PetscCall(fom.SetMu(ParamValues(fom.scene)));
  cmap.SetGeometry(&fom.map, fom.mu);
  PetscCall(DMGetGlobalVector(fom.dm, &zero));
  PetscCall(VecSet(zero, 0.0));
  PetscCall(DMGetLocalVector(fom.dm, &uloc));
  PetscCall(fom.elas.GlobalToLocalWithBC(zero, uloc));
  PetscCall(DMRestoreGlobalVector(fom.dm, &zero));
  PetscCall(cmap.Assemble(fom.elas, uloc, sys));
  PetscCall(DMRestoreLocalVector(fom.dm, &uloc));
  if (order.NumMultipliers() != cmap.NumMultipliers()) PetscCall(order.BuildMultipliers(sys->coordRef, fom.elas.dim));
  PetscFunctionReturn(0);
}

std::vector<PetscReal> SlaveMassGram(const DenseMatrix &W, const std::vector<PetscReal> &w)
{
  const PetscInt         r = W.cols;
  std::vector<PetscReal> G((size_t)r * r, 0.0);
  for (PetscInt i = 0; i < r; ++i)
    for (PetscInt j = 0; j < r; ++j) {
      PetscReal g = 0;
      for (PetscInt k = 0; k < W.rows; ++k) g += W(k, i) * w[k] * W(k, j);
      G[(size_t)i * r + j] = g;
    }
  return G;
}

PetscErrorCode ReferenceSlaveMass(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, std::vector<PetscReal> *w)
{
  ContactSystem          sys;
  std::vector<PetscReal> wg;

  PetscFunctionBeginUser;
  PetscCall(AssembleReferenceContact(fom, cmap, order, &sys));
  PetscCall(GatherVec(sys.weight, &wg));
  w->assign(wg.size(), 0.0);
  for (size_t g = 0; g < wg.size(); ++g) (*w)[order.CanonicalMultiplier((PetscInt)g)] = wg[g];
  PetscFunctionReturn(0);
}

PetscErrorCode BuildFullContact(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const std::vector<double> &modes, PetscInt N, const std::vector<double> &Wt, PetscInt r, PetscInt nsub, std::shared_ptr<ContactPatch> *full, std::vector<PetscReal> *P)
{
  ContactSystem sys;

  PetscFunctionBeginUser;
  PetscCall(AssembleReferenceContact(fom, cmap, order, &sys));
  const PetscInt    Rfom = cmap.NumMultipliers();
  std::vector<char> support(Rfom, 0);
  for (PetscInt k = 0; k < r; ++k)
    for (PetscInt i = 0; i < Rfom; ++i)
      if (Wt[(size_t)k * Rfom + i] > 0) support[i] = 1;
  *full = std::make_shared<ContactPatch>();
  PetscCall((*full)->BuildFull(PetscObjectComm((PetscObject)fom.dm), cmap, order, modes, N, support, nsub));
  const PetscInt Q = (*full)->NumPoints();
  P->assign((size_t)r * Q, 0.0);
  for (PetscInt p = 0; p < Q; ++p)
    for (PetscInt k = 0; k < fom.elas.dim; ++k) {
      const PetscInt  row = (*full)->points[p].row[k];
      const PetscReal b   = MultiplierShape(cmap.multiplier, fom.elas.dim, (*full)->points[p].b, k);
      if (row < 0 || b == 0) continue;
      for (PetscInt q = 0; q < r; ++q) (*P)[(size_t)q * Q + p] += b * Wt[(size_t)q * Rfom + row];
    }
  PetscFunctionReturn(0);
}

PetscErrorCode CanonicalToMultipliers(const CanonicalOrder &order, const std::vector<PetscReal> &lambda, Vec v)
{
  PetscInt     lo, hi;
  PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(VecGetOwnershipRange(v, &lo, &hi));
  PetscCall(VecGetArray(v, &a));
  for (PetscInt i = lo; i < hi; ++i) a[i - lo] = lambda[order.CanonicalMultiplier(i)];
  PetscCall(VecRestoreArray(v, &a));
  PetscFunctionReturn(0);
}

// The scene's FOM at mu for the ROM at romPath (checked to be the ROM's scene), the canonical order, the
// bases, and the contact system at displacement fom.u (the multiplier layout, weights, normals, points).
static PetscErrorCode SceneOfRom(MPI_Comm comm, const SceneSpec &scene, const ReducedModel &model, const std::vector<PetscReal> &mu, const char *what, ElasticFOM *fom, CanonicalOrder *order, RomBases *bases, ContactMap *cmap)
{
  std::string romScene;

  PetscFunctionBeginUser;
  PetscCall(RomReadAttr(model.file, "scene", &romScene));
  PetscCheck(scene.name == romScene, comm, PETSC_ERR_USER_INPUT, "%s: the scene of the options is '%s', the ROM %s was built for '%s' (give -options_file runs/%s.opts)", what, scene.name.c_str(), model.file.c_str(), romScene.c_str(), romScene.c_str());
  PetscCall(fom->Create(comm, scene));
  PetscCall(CheckRomScene(comm, model.file, scene, fom->map));
  PetscCall(fom->SetupAffine());
  PetscCall(fom->SetMu(mu));
  PetscCall(order->BuildDofs(fom->elas));
  if (!fom->u) {
    PetscCall(DMCreateGlobalVector(fom->dm, &fom->u));
    PetscCall(PetscObjectSetName((PetscObject)fom->u, "displacement"));
  }
  PetscCheck(scene.contact, comm, PETSC_ERR_SUP, "%s: the scene has no contact pair (-contact_slave, -contact_master)", what);
  PetscCall(cmap->Setup(fom->elas, scene.slave, scene.master));
  PetscCall(bases->Read(comm, model, model.file, order->NumDofs(), cmap->NumMultipliers()));
  cmap->SetGeometry(&fom->map, mu);
  PetscFunctionReturn(0);
}

static PetscErrorCode ContactAt(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, ContactSystem *sys)
{
  Vec uloc;

  PetscFunctionBeginUser;
  PetscCall(DMGetLocalVector(fom.dm, &uloc));
  PetscCall(fom.elas.GlobalToLocalWithBC(fom.u, uloc));
  PetscCall(cmap.Assemble(fom.elas, uloc, sys));
  PetscCall(DMRestoreLocalVector(fom.dm, &uloc));
  PetscCall(order.BuildMultipliers(sys->coordRef, fom.elas.dim));
  PetscFunctionReturn(0);
}

// The contact vectors of the output: the named ones first, then weight, slave points and normals.
static PetscErrorCode ContactOutputs(const ContactSystem &sys, PetscInt dim, std::vector<Vec> *cv)
{
  const char *names[] = {"x", "y", "z"}, *nn[] = {"normal_x", "normal_y", "normal_z"};

  PetscFunctionBeginUser;
  PetscCall(PetscObjectSetName((PetscObject)sys.weight, "weight"));
  cv->push_back(sys.weight);
  for (PetscInt d = 0; d < dim; ++d) {
    PetscCall(PetscObjectSetName((PetscObject)sys.coord[d], names[d]));
    PetscCall(PetscObjectSetName((PetscObject)sys.normal[d], nn[d]));
    cv->push_back(sys.coord[d]);
    cv->push_back(sys.normal[d]);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode ReconstructFields(MPI_Comm comm, const ReducedModel &model, const ReducedSolution &sol, const std::vector<PetscReal> &mu, const std::string &path, Report *rep)
{
  SceneSpec      scene;
  ElasticFOM     fom;
  ContactMap     cmap;
  CanonicalOrder order;
  RomBases       bases;
  ContactSystem  sys;

  PetscFunctionBeginUser;
  { // without the scene, SceneSpecFromOptions blamed -mu ("the scene declares no parameters") or the mesh
    PetscBool hasMesh = PETSC_FALSE;
    PetscCall(PetscOptionsHasName(NULL, NULL, "-mesh_file", &hasMesh));
    PetscCheck(hasMesh, comm, PETSC_ERR_USER_INPUT, "-rom_reconstruct %s writes the fields on the scene's mesh: give the scene's options the ROM was built with (-options_file runs/<scene>.opts; the ROM file holds no mesh)", path.c_str());
  }
  PetscCall(SceneSpecFromOptions(comm, &scene));
  PetscCall(SceneOfRom(comm, scene, model, mu, "-rom_reconstruct", &fom, &order, &bases, &cmap));
  PetscCall(bases.Displacement(model, order, sol.v, fom.u));
  PetscCall(ContactAt(fom, cmap, order, &sys)); // at the reconstructed displacement
  std::vector<PetscReal> lam;
  bases.Multipliers(model, sol.lambda, &lam);
  Vec lambda;
  PetscCall(VecDuplicate(sys.g, &lambda));
  PetscCall(CanonicalToMultipliers(order, lam, lambda));
  ContactSummary cs;
  PetscCall(SummarizeContact(sys, lambda, fom.elas.dim, &cs));
  rep->root["contact_force"] = (double)cs.force;
  rep->root["max_pressure"]  = (double)cs.maxPressure;
  rep->root["contact_halfwidth_moment"] = (double)cs.halfwidthMoment; // 2D the half-width, 3D the radius, by the pressure's moments (as fom's)
  rep->root["nactive"]       = (long long)cs.nactive;
  PetscReal energy;
  PetscCall(fom.elas.Energy(fom.u, &energy));
  rep->root["energy"] = (double)energy;
  PetscCall(PetscObjectSetName((PetscObject)lambda, "lambda"));
  std::vector<Vec> cv = {lambda};
  PetscCall(ContactOutputs(sys, fom.elas.dim, &cv));
  PetscCall(fom.WriteOutput(path, cv));
  PetscCall(VecDestroy(&lambda));
  PetscFunctionReturn(0);
}

PetscErrorCode WriteBasisView(MPI_Comm comm, const SceneSpec &scene, const std::string &romPath, const std::string &path, Report *rep)
{
  ReducedModel   model;
  ElasticFOM     fom;
  ContactMap     cmap;
  CanonicalOrder order;
  RomBases       bases;
  ContactSystem  sys;
  std::vector<Vec> fields, dual;

  PetscFunctionBeginUser;
  PetscCall(CheckOutputPath(comm, path, "-offline_basis_output"));
  PetscCall(model.Open(romPath));
  std::vector<PetscReal> mu;
  for (const auto &p : model.par.params) mu.push_back(p.def);
  PetscCall(SceneOfRom(comm, scene, model, mu, "-offline_basis_output", &fom, &order, &bases, &cmap));
  PetscCall(VecZeroEntries(fom.u));
  PetscCall(ContactAt(fom, cmap, order, &sys)); // the reference configuration at the default parameters
  PetscInt lo, hi;
  PetscCall(VecGetOwnershipRange(fom.u, &lo, &hi));
  for (PetscInt n = 0; n < bases.N; ++n) { // POD modes, then supremizers (unit energy norm)
    Vec          f;
    PetscScalar *a;
    PetscCall(VecDuplicate(fom.u, &f));
    PetscCall(VecGetArray(f, &a));
    for (PetscInt i = lo; i < hi; ++i) a[i - lo] = bases.modes[(size_t)n * bases.ndofs + order.CanonicalDof(i)];
    PetscCall(VecRestoreArray(f, &a));
    const std::string name = n < model.Npod ? "pod_mode_" + std::to_string((long long)n) : "supremizer_" + std::to_string((long long)(n - model.Npod));
    PetscCall(PetscObjectSetName((PetscObject)f, name.c_str()));
    fields.push_back(f);
  }
  for (PetscInt k = 0; k < bases.r; ++k) { // the nonnegative dual basis: nodal multiplier coefficients
    Vec l;
    PetscCall(VecDuplicate(sys.g, &l));
    PetscCall(CanonicalToMultipliers(order, std::vector<PetscReal>(bases.W.begin() + (size_t)k * bases.R, bases.W.begin() + (size_t)(k + 1) * bases.R), l));
    PetscCall(PetscObjectSetName((PetscObject)l, ("dual_" + std::to_string((long long)k)).c_str()));
    dual.push_back(l);
  }
  std::vector<Vec> cv = dual;
  PetscCall(ContactOutputs(sys, fom.elas.dim, &cv));
  PetscCall(fom.WriteOutput(path, cv, fields));
  for (Vec &f : fields) PetscCall(VecDestroy(&f));
  for (Vec &l : dual) PetscCall(VecDestroy(&l));

  rep->root["basis_view"]["file"]        = path;
  rep->root["basis_view"]["xdmf"]        = XdmfPath(path);
  rep->root["basis_view"]["pod_modes"]   = (long long)model.Npod;
  rep->root["basis_view"]["supremizers"] = (long long)(bases.N - model.Npod);
  rep->root["basis_view"]["dual"]        = (long long)bases.r;
  PetscFunctionReturn(0);
}

} // namespace rbc
