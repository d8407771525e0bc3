// src/fom/scene.cpp: parses a scene from the options database and checks its values.
#include "rbcontact/scene.hpp"
#include "rbcontact/options_files.hpp"
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace rbc {

std::vector<std::string> SplitList(const std::string &s, char sep)
{
  std::vector<std::string> out;
  std::stringstream        ss(s);
  std::string              item;
  while (std::getline(ss, item, sep)) {
    const auto b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    if (b != std::string::npos) out.push_back(item.substr(b, e - b + 1));
  }
  return out;
}

void LameFromYoung(PetscReal E, PetscReal nu, PetscReal *L, PetscReal *G)
{
  *L = E * nu / ((1 + nu) * (1 - 2 * nu));
  *G = E / (2 * (1 + nu));
}

// The scene's options are read inside one options block (SceneSpecFromOptions), so that `-help` lists
// each with its meaning and current value (PETSc's PetscOptionsString etc. need the block's object,
// PetscOptionsObject, in scope).
static const char kMan[] = "README.md: Options";

// A gmsh variable name, as -mesh_geo_set and -mu_geo_set give it to gmsh -setnumber (it went to a shell command line
// unquoted: a name could run any command).
// The first name of a list that appears twice ("" when none).
static std::string Repeated(const std::vector<std::string> &names)
{
  for (size_t i = 0; i < names.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (names[i] == names[j]) return names[i];
  return "";
}

static bool GeoIdentifier(const std::string &n)
{
  if (n.empty() || std::isdigit((unsigned char)n[0])) return false;
  for (char c : n)
    if (!std::isalnum((unsigned char)c) && c != '_') return false;
  return true;
}

static PetscErrorCode GetString(PetscOptionItems *PetscOptionsObject, const char *name, const char *text, std::string *value, PetscBool *set)
{
  char      buf[PETSC_MAX_PATH_LEN];
  PetscBool flg;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(buf, value->c_str(), sizeof buf));
  PetscCall(PetscOptionsString(name, text, kMan, buf, buf, sizeof buf, &flg));
  if (flg) *value = buf;
  if (set) *set = flg;
  PetscFunctionReturn(0);
}

// shown: the default -help prints (its first value; else 0)
static PetscErrorCode GetRealArray(PetscOptionItems *PetscOptionsObject, const char *name, const char *text, std::vector<PetscReal> *v, PetscBool *set, const std::vector<PetscReal> &shown = {})
{
  PetscReal buf[65] = {0}; // -help prints buf[0] of an unset option; one more than taken: PETSc drops values beyond the buffer silently
  PetscInt  n = 65;
  PetscBool flg;

  PetscFunctionBeginUser;
  for (size_t i = 0; i < shown.size() && i < 64; ++i) buf[i] = shown[i];
  PetscCall(PetscOptionsRealArray(name, text, kMan, buf, &n, &flg));
  PetscCheck(!flg || n <= 64, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "option %s takes at most 64 values, more were given", name);
  // every rank reads the same options: a local error on each (no collective, no hang)
  PetscBool has = PETSC_FALSE;
  PetscCall(PetscOptionsHasName(NULL, NULL, name, &has));
  PetscCheck(!has || (flg && n > 0), PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "option %s is given without a value", name);
  for (PetscInt i = 0; flg && i < n; ++i)
    PetscCheck(std::isfinite(buf[i]), PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "option %s: value %" PetscInt_FMT " of the list is not a finite number (inf or nan)", name, i + 1);
  if (flg) v->assign(buf, buf + n);
  if (set) *set = flg;
  PetscFunctionReturn(0);
}

static PetscErrorCode GetIntArray(PetscOptionItems *PetscOptionsObject, const char *name, const char *text, std::vector<PetscInt> *v, PetscBool *set)
{
  PetscInt  buf[65] = {0}; // one more than taken: PETSc drops values beyond the buffer silently
  PetscInt  n = 65;
  PetscBool flg;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsIntArray(name, text, kMan, buf, &n, &flg));
  PetscCheck(!flg || n <= 64, PETSC_COMM_SELF, PETSC_ERR_ARG_SIZ, "option %s takes at most 64 values, more were given", name);
  if (flg) v->assign(buf, buf + n);
  if (set) *set = flg;
  PetscFunctionReturn(0);
}

// The boundary options were -bc_<...> until 2026-11-25, in PETSc's own namespace (PetscDS reads
// -bc_<boundary name> as the label values of a boundary of that name): the new name is read, the old
// one still works for one release with a deprecation warning; both at once is an error.
static PetscErrorCode Renamed(MPI_Comm comm, const std::string &now, const std::string &old, std::string *use)
{
  PetscBool hasNew = PETSC_FALSE, hasOld = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsHasName(NULL, NULL, now.c_str(), &hasNew));
  PetscCall(PetscOptionsHasName(NULL, NULL, old.c_str(), &hasOld));
  PetscCheck(!(hasNew && hasOld), comm, PETSC_ERR_USER_INPUT, "%s and its deprecated spelling %s are both given: keep %s", now.c_str(), old.c_str(), now.c_str());
  *use = now;
  if (hasOld) {
    PetscCall(PetscPrintf(comm, "rbcontact: warning: option %s is deprecated (PETSc's -bc_ namespace): use %s\n", old.c_str(), now.c_str()));
    *use = old;
  }
  PetscFunctionReturn(0);
}

PetscErrorCode OptionNames(std::vector<std::string> *given, std::vector<std::string> *lowered)
{
  char *all = NULL;

  PetscFunctionBeginUser;
  given->clear();
  lowered->clear();
  PetscCall(PetscOptionsGetAll(NULL, &all));
  std::istringstream in(all ? all : "");
  PetscCall(PetscFree(all));
  // "-name value -flag ...": a name is a word of '-' and a letter (a value like -0.1 is not)
  for (std::string tok; in >> tok;) {
    if (tok.size() < 2 || tok[0] != '-' || !std::isalpha((unsigned char)tok[1])) continue;
    std::string low = tok.substr(1);
    for (auto &c : low) c = (char)std::tolower((unsigned char)c);
    given->push_back(tok);
    lowered->push_back(low);
  }
  PetscFunctionReturn(0);
}

std::string ShortestReal(double x)
{
  char buf[40];
  for (int prec = 6; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*g", prec, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

std::string OutOfBoxMessage(const ParamSpec &p, PetscReal value)
{
  return "parameter '" + p.name + "' = " + ShortestReal(value) + " is outside its box [" + ShortestReal(p.min) + ", " + ShortestReal(p.max) + "]";
}

PetscErrorCode SceneSpecFromOptions(MPI_Comm comm, SceneSpec *scene)
{
  std::string s;
  PetscBool   flg;
  PetscInt    refine = 0;

  PetscFunctionBeginUser;
  // the numeric and list options of the scene (the contact map's and the solver's: ContactMap::Setup, KacanovSolver): given without a value, PETSc kept the default
  // without a word (a trailing -fem_degree cancelled a file's -fem_degree 2: another discretization, exit 0)
  PetscCall(CheckValuesGiven(comm, {"-fem_degree", "-mesh_refine", "-mesh_clscale", "-mesh_partitioner", "-mesh_metis_seed", "-mesh_file", "-scene", "-contact_slave", "-contact_master"}));
  bool meshGiven = false;
  PetscOptionsBegin(comm, NULL, "Scene: mesh, parameters, bodies, boundary conditions, contact pair (README.md: Options)", "rbcontact");
  PetscCall(GetString(PetscOptionsObject, "-scene", "Scene name (reports, file headers)", &scene->name, NULL));
  PetscCall(GetString(PetscOptionsObject, "-mesh_file", "gmsh mesh: .geo (meshed and cached) or .msh; relative to the working directory, then the installed share/rbcontact", &scene->mesh.file, &flg));
  meshGiven = flg; // checked after the block (-help lists the whole block first)
  PetscCall(PetscOptionsReal("-mesh_clscale", "gmsh characteristic length factor (.geo)", kMan, scene->mesh.clscale, &scene->mesh.clscale, NULL));
  PetscCall(PetscOptionsInt("-mesh_refine", "Halve the mesh size this many times (.geo: -mesh_clscale x 0.5^n)", kMan, refine, &refine, NULL));
  PetscCheck(scene->mesh.clscale > 0 && std::isfinite(scene->mesh.clscale), comm, PETSC_ERR_ARG_OUTOFRANGE, "-mesh_clscale %g must be a finite number > 0", (double)scene->mesh.clscale); // (inf crashed gmsh)
  PetscCheck(refine >= 0 && refine <= 8, comm, PETSC_ERR_ARG_OUTOFRANGE, "-mesh_refine %" PetscInt_FMT " out of range [0, 8]", refine);
  scene->mesh.clscale *= std::pow(0.5, (double)refine);
  if (const char *env = std::getenv("RBC_MESH_CACHE")) scene->mesh.cacheDir = env;
  PetscCall(GetString(PetscOptionsObject, "-mesh_cache_dir", "Where meshed .geo files are cached (default: $RBC_MESH_CACHE, else ./meshcache)", &scene->mesh.cacheDir, NULL));
  if (scene->mesh.cacheDir.empty()) scene->mesh.cacheDir = "meshcache";
  s.clear();
  PetscCall(GetString(PetscOptionsObject, "-mesh_geo_set", "NAME=VALUE,... : gmsh constants of the .geo", &s, &flg));
  for (const auto &kv : SplitList(s)) {
    const auto eq = kv.find('=');
    PetscCheck(eq != std::string::npos, comm, PETSC_ERR_USER_INPUT, "-mesh_geo_set: item '%s' is not NAME=VALUE", kv.c_str());
    char     *end;
    const std::string val = kv.substr(eq + 1);
    double    x           = std::strtod(val.c_str(), &end);
    PetscCheck(end != val.c_str() && *end == 0, comm, PETSC_ERR_USER_INPUT, "-mesh_geo_set: value '%s' of '%s' is not a number", val.c_str(), kv.substr(0, eq).c_str());
    // (nan and inf went to gmsh: 3 slave nodes, force 0.904 for 0.4996, exit 0)
    PetscCheck(std::isfinite(x), comm, PETSC_ERR_USER_INPUT, "-mesh_geo_set: value '%s' of '%s' is not a finite number", val.c_str(), kv.substr(0, eq).c_str());
    PetscCheck(GeoIdentifier(kv.substr(0, eq)), comm, PETSC_ERR_USER_INPUT, "-mesh_geo_set: '%s' is not a gmsh variable name (letters, digits and _, not starting with a digit)", kv.substr(0, eq).c_str());
    scene->mesh.geoNumbers.emplace_back(kv.substr(0, eq), x);
  }

  // Parameters: names, boxes, defaults, the gmsh constant each one sets, and the values (-mu)
  s.clear();
  PetscCall(GetString(PetscOptionsObject, "-mu_names", "Parameter names, comma separated", &s, NULL));
  const std::vector<std::string> pnames = SplitList(s);
  // (a repeated name: one of the -mu values was dropped without a word)
  PetscCheck(Repeated(pnames).empty(), comm, PETSC_ERR_USER_INPUT, "-mu_names: the parameter name '%s' appears twice", Repeated(pnames).c_str());
  if (!pnames.empty()) {
    std::vector<PetscReal> lo, hi, def, val;
    PetscCall(GetRealArray(PetscOptionsObject, "-mu_min", "Parameter box: lower bounds, one per parameter", &lo, NULL));
    PetscCall(GetRealArray(PetscOptionsObject, "-mu_max", "Parameter box: upper bounds", &hi, NULL));
    PetscCall(GetRealArray(PetscOptionsObject, "-mu_default", "Default parameter values (the reference configuration)", &def, NULL));
    std::vector<PetscReal> shown = def; // -help: the default values (-mu <0.> lay outside most boxes)
    if (shown.empty() && lo.size() == hi.size())
      for (size_t i = 0; i < lo.size(); ++i) shown.push_back(0.5 * (lo[i] + hi[i]));
    PetscCall(GetRealArray(PetscOptionsObject, "-mu", "Parameter values of this run (fom, online), inside the box; default -mu_default", &val, &flg, shown));
    s.clear();
    PetscCall(GetString(PetscOptionsObject, "-mu_geo_set", "gmsh constant set by each parameter ('-' for none), comma separated", &s, NULL));
    const std::vector<std::string> geo = SplitList(s);
    const size_t np = pnames.size();
    PetscCheck(lo.size() == np && hi.size() == np, comm, PETSC_ERR_USER_INPUT, "-mu_min and -mu_max need one value per parameter of -mu_names (%zu)", np);
    PetscCheck(def.empty() || def.size() == np, comm, PETSC_ERR_USER_INPUT, "-mu_default needs one value per parameter (%zu)", np);
    std::string plist;
    for (const auto &n : pnames) plist += (plist.empty() ? "" : ", ") + n;
    PetscCheck(!flg || val.size() == np, comm, PETSC_ERR_USER_INPUT, "-mu has %zu values; the scene has %zu parameters (%s, in this order)", val.size(), np, plist.c_str());
    for (size_t i = 0; i < np; ++i) {
      ParamSpec p;
      p.name  = pnames[i];
      p.min   = lo[i];
      p.max   = hi[i];
      p.def   = def.empty() ? 0.5 * (lo[i] + hi[i]) : def[i];
      p.value = flg ? val[i] : p.def;
      PetscCheck(lo[i] <= hi[i], comm, PETSC_ERR_ARG_OUTOFRANGE, "-mu_min %g > -mu_max %g for parameter '%s'", (double)lo[i], (double)hi[i], p.name.c_str());
      PetscCheck(p.def >= lo[i] && p.def <= hi[i], comm, PETSC_ERR_ARG_OUTOFRANGE, "-mu_default: %s", OutOfBoxMessage(p, p.def).c_str()); // (was blamed on -mu)
      PetscCheck(p.value >= lo[i] && p.value <= hi[i], comm, PETSC_ERR_ARG_OUTOFRANGE, "-mu: %s", OutOfBoxMessage(p, p.value).c_str());
      if (i < geo.size() && geo[i] != "-") p.geoName = geo[i];
      PetscCheck(p.geoName.empty() || GeoIdentifier(p.geoName), comm, PETSC_ERR_USER_INPUT, "-mu_geo_set: '%s' is not a gmsh variable name (letters, digits and _, not starting with a digit)", p.geoName.c_str());
      if (!p.geoName.empty()) scene->mesh.geoNumbers.emplace_back(p.geoName, p.value);
      scene->params.push_back(p);
    }
  } else {
    PetscCall(PetscOptionsHasName(NULL, NULL, "-mu", &flg));
    PetscCheck(!flg, comm, PETSC_ERR_USER_INPUT, "-mu given but the scene declares no parameters (-mu_names)");
  }

  // Bodies and materials
  s.clear();
  PetscCall(GetString(PetscOptionsObject, "-bodies", "Body names = physical surface (volume) groups of the mesh, comma separated", &s, NULL));
  std::vector<std::string> names = SplitList(s);
  if (names.empty()) names.push_back("all");
  // (a repeated body: its cells went to the last entry, and the first was said to float)
  PetscCheck(Repeated(names).empty(), comm, PETSC_ERR_USER_INPUT, "-bodies: the body '%s' appears twice", Repeated(names).c_str());
  std::vector<PetscReal> E, nu;
  PetscCall(GetRealArray(PetscOptionsObject, "-body_E", "Young's modulus: one value, or one per body", &E, NULL));
  PetscCall(GetRealArray(PetscOptionsObject, "-body_nu", "Poisson ratio: one value, or one per body", &nu, NULL));
  if (E.empty()) E.push_back(1.0);
  if (nu.empty()) nu.push_back(0.3);
  PetscCheck(E.size() == 1 || E.size() == names.size(), comm, PETSC_ERR_USER_INPUT, "-body_E has %zu values for %zu bodies (give one, or one per body of -bodies)", E.size(), names.size());
  PetscCheck(nu.size() == 1 || nu.size() == names.size(), comm, PETSC_ERR_USER_INPUT, "-body_nu has %zu values for %zu bodies (give one, or one per body of -bodies)", nu.size(), names.size());
  scene->bodies.clear();
  for (size_t b = 0; b < names.size(); ++b) {
    BodySpec body;
    body.name = names[b];
    body.E    = E.size() == 1 ? E[0] : E[b];
    body.nu   = nu.size() == 1 ? nu[0] : nu[b];
    PetscCheck(body.E > 0 && std::isfinite(body.E), comm, PETSC_ERR_ARG_OUTOFRANGE, "-body_E: Young's modulus %g of body '%s' must be > 0", (double)body.E, body.name.c_str());
    PetscCheck(body.nu > -1 && body.nu < 0.5, comm, PETSC_ERR_ARG_OUTOFRANGE, "-body_nu: Poisson ratio %g of body '%s' must lie in (-1, 0.5)", (double)body.nu, body.name.c_str());
    scene->bodies.push_back(body);
  }

  // Dirichlet boundaries: -dirichlet a,b with -dirichlet_a_u ux,uy[,uz] and optional -dirichlet_a_comps 0,1
  // (before 2026-11-25: -bc_dirichlet, -bc_a_u, -bc_a_comps; still read, with a warning: Renamed)
  std::string opt;
  s.clear();
  PetscCall(Renamed(comm, "-dirichlet", "-bc_dirichlet", &opt));
  PetscCall(GetString(PetscOptionsObject, opt.c_str(), "Dirichlet boundaries = physical line (surface) groups, comma separated; each with -dirichlet_<name>_u", &s, NULL));
  scene->dirichlet.clear();
  for (const auto &name : SplitList(s)) {
    DirichletSpec bc;
    bc.label = name;
    PetscCall(Renamed(comm, "-dirichlet_" + name + "_u", "-bc_" + name + "_u", &opt));
    PetscCall(GetRealArray(PetscOptionsObject, opt.c_str(), "Imposed displacement on this boundary, all components", &bc.values, NULL));
    PetscCall(Renamed(comm, "-dirichlet_" + name + "_comps", "-bc_" + name + "_comps", &opt));
    PetscCall(GetIntArray(PetscOptionsObject, opt.c_str(), "Constrained components (default: all)", &bc.comps, NULL));
    for (PetscInt c : bc.comps) PetscCheck(c >= 0 && c < 3, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s: component %" PetscInt_FMT " out of range [0, 2]", opt.c_str(), c);
    scene->dirichlet.push_back(bc);
  }
  s.clear();
  PetscCall(Renamed(comm, "-traction", "-bc_traction", &opt));
  PetscCall(GetString(PetscOptionsObject, opt.c_str(), "Traction boundaries, comma separated; each with -traction_<name>_t", &s, NULL));
  scene->tractions.clear();
  for (const auto &name : SplitList(s)) {
    TractionSpec t;
    t.label = name;
    PetscCall(Renamed(comm, "-traction_" + name + "_t", "-bc_" + name + "_t", &opt));
    PetscCall(GetRealArray(PetscOptionsObject, opt.c_str(), "Traction vector on this boundary", &t.traction, &flg));
    PetscCheck(flg, comm, PETSC_ERR_USER_INPUT, "-traction names '%s' but -traction_%s_t (the traction vector) is missing", name.c_str(), name.c_str());
    scene->tractions.push_back(t);
  }
  PetscCall(GetRealArray(PetscOptionsObject, "-body_force", "Body force per unit volume (all bodies)", &scene->bodyForce, NULL));
  PetscCall(PetscOptionsInt("-fem_degree", "Lagrange degree of the displacement (1 or 2)", kMan, scene->degree, &scene->degree, NULL));
  PetscCheck(scene->degree == 1 || scene->degree == 2, comm, PETSC_ERR_ARG_OUTOFRANGE, "-fem_degree %" PetscInt_FMT " is not supported (1 or 2)", scene->degree);

  PetscCall(GetString(PetscOptionsObject, "-contact_slave", "Slave boundary group (its points are projected; carries the multipliers)", &scene->slave, NULL));
  PetscCall(GetString(PetscOptionsObject, "-contact_master", "Master boundary group", &scene->master, NULL));
  scene->contact = (!scene->slave.empty() || !scene->master.empty()) ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscOptionsBool("-contact", "Solve with contact (default: when a pair is given)", kMan, scene->contact, &scene->contact, NULL));

  { // the options that name a body (-map_<body>[_...], -param_E_<body>, -param_nu_<body>) must name one of -bodies:
    // a misspelled body would otherwise leave its map or parameter silently unused (the run "succeeds")
    std::vector<std::string> given, lowered;
    PetscCall(OptionNames(&given, &lowered));
    auto lower = [](std::string x) {
      for (auto &c : x) c = (char)std::tolower((unsigned char)c);
      return x;
    };
    std::string names;
    for (const auto &b : scene->bodies) names += (names.empty() ? "" : ", ") + b.name;
    for (size_t o = 0; o < given.size(); ++o) {
      const std::string &tok = given[o], &name = lowered[o];
      for (const std::string pre : {"map_", "param_e_", "param_nu_"}) {
        if (name.compare(0, pre.size(), pre) != 0) continue;
        const std::string rest = name.substr(pre.size());
        bool              ok   = false;
        for (const auto &b : scene->bodies) {
          const std::string bn = lower(b.name);
          ok = ok || rest == bn || (pre == "map_" && rest.compare(0, bn.size() + 1, bn + "_") == 0);
        }
        PetscCheck(ok, comm, PETSC_ERR_USER_INPUT, "option %s names no body of -bodies (%s): a misspelled body name?", tok.c_str(), names.c_str());
      }
    }
  }
  // Material and load parameters: -param_E_<body>, -param_nu_<body>, -param_bc_<label>, -param_t_<label>
  auto paramIndex = [&](const std::string &opt, PetscInt *idx) -> PetscErrorCode {
    char      nm[128];
    PetscBool set;
    PetscFunctionBeginUser;
    *idx = -1;
    nm[0] = 0;
    PetscCall(PetscOptionsString(opt.c_str(), "Parameter (of -mu_names) that scales this quantity", kMan, nm, nm, sizeof nm, &set));
    if (set) {
      for (size_t i = 0; i < scene->params.size(); ++i) if (scene->params[i].name == nm) *idx = (PetscInt)i;
      PetscCheck(*idx >= 0, comm, PETSC_ERR_USER_INPUT, "%s: unknown parameter '%s' (declared by -mu_names)", opt.c_str(), nm);
    }
    PetscFunctionReturn(0);
  };
  for (auto &b : scene->bodies) {
    PetscCall(paramIndex("-param_E_" + b.name, &b.paramE));
    PetscCall(paramIndex("-param_nu_" + b.name, &b.paramNu));
    if (b.paramE >= 0) PetscCheck(scene->params[b.paramE].min > 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-param_E_%s: the box of '%s' must be > 0", b.name.c_str(), scene->params[b.paramE].name.c_str());
    if (b.paramNu >= 0) PetscCheck(scene->params[b.paramNu].min > -1 && scene->params[b.paramNu].max < 0.5, comm, PETSC_ERR_ARG_OUTOFRANGE, "-param_nu_%s: the box of '%s' must lie in (-1, 0.5)", b.name.c_str(), scene->params[b.paramNu].name.c_str());
  }
  for (auto &bc : scene->dirichlet) {
    PetscCall(paramIndex("-param_bc_" + bc.label, &bc.param));
    if (bc.param >= 0) PetscCheck(scene->params[bc.param].def != 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-param_bc_%s: parameter '%s' needs a nonzero -mu_default (the scale is mu / default)", bc.label.c_str(), scene->params[bc.param].name.c_str());
  }
  for (auto &t : scene->tractions) {
    PetscCall(paramIndex("-param_t_" + t.label, &t.param));
    if (t.param >= 0) PetscCheck(scene->params[t.param].def != 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-param_t_%s: parameter '%s' needs a nonzero -mu_default", t.label.c_str(), scene->params[t.param].name.c_str());
  }
  if (scene->contact) PetscCheck(!scene->slave.empty() && !scene->master.empty(), comm, PETSC_ERR_USER_INPUT, "-contact 1 needs -contact_slave NAME and -contact_master NAME");
  PetscOptionsEnd();
  PetscCall(RequireInput(comm, meshGiven, "-mesh_file", "No mesh: give -mesh_file <file.geo|file.msh> (usually in runs/<scene>.opts via -options_file)"));
  PetscFunctionReturn(0);
}

} // namespace rbc
