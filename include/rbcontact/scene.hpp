// rbcontact/scene.hpp: a scene = one configured problem (mesh, bodies, boundary conditions, loads,
// contact pair). Owns the option parsing of the scene's options file and the checks of its values.
// The option names are documented in docs/options.md.
#pragma once
#include <petscsys.h>
#include <string>
#include <vector>

namespace rbc {

struct BodySpec {
  std::string name;   // physical name of the body's cells in the mesh ("all": every cell)
  PetscReal   E  = 1; // Young's modulus (> 0)
  PetscReal   nu = 0; // Poisson ratio (-1 < nu < 0.5)
  PetscInt    paramE = -1, paramNu = -1; // -param_E_<body> NAME: E (nu) equals that parameter
};

// Pointwise vector function of the position (PETSc's projection signature).
using PointFn = PetscErrorCode (*)(PetscInt dim, PetscReal t, const PetscReal x[], PetscInt Nc, PetscScalar u[], void *ctx);

struct DirichletSpec {
  std::string            label;  // physical name of the boundary
  std::vector<PetscInt>  comps;  // constrained components (all if empty)
  std::vector<PetscReal> values; // imposed displacement, one per space component
  PointFn                fn    = nullptr; // C++ API: a function instead of constant values
  void                  *fnCtx = nullptr;
  PetscInt               param = -1;  // -param_bc_<label> NAME: values scale by mu_NAME / default
  PetscReal              scale = 1.0; // current scale (set by Elasticity::SetMu)
};

struct TractionSpec {
  std::string            label;
  std::vector<PetscReal> traction; // one per space component
  PetscInt               param = -1; // -param_t_<label> NAME: traction scales by mu_NAME / default
};

struct MeshSpec {
  std::string                                   file;        // .geo (generated with gmsh) or .msh
  PetscReal                                     clscale = 1; // gmsh -clscale, times 2^-refine
  std::vector<std::pair<std::string, PetscReal>> geoNumbers; // gmsh -setnumber NAME VALUE
  std::string                                   cacheDir;    // where generated .msh files go
};

// A scene parameter with its box; geometry parameters set a gmsh constant of the .geo (the mesh is
// generated at that value; the reference-configuration map of the next stage replaces this).
struct ParamSpec {
  std::string name;
  PetscReal   min = 0, max = 0, value = 0, def = 0; // box, current value, default (reference)
  std::string geoName; // gmsh constant (-mu_geo_set), empty if not a geometry parameter
};

struct SceneSpec {
  std::string                name = "unnamed";
  MeshSpec                   mesh;
  std::vector<BodySpec>      bodies;
  std::vector<DirichletSpec> dirichlet;
  std::vector<TractionSpec>  tractions;
  std::vector<PetscReal>     bodyForce; // empty: none
  // C++ API: a pointwise residual term f0 replacing the constant body force (manufactured solutions).
  void (*bodyForceF0)(PetscInt, PetscInt, PetscInt, const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], PetscReal, const PetscReal[], PetscInt, const PetscScalar[], PetscScalar[]) = nullptr;
  PetscInt                   degree = 1; // Lagrange degree of the displacement (1 or 2)
  std::vector<ParamSpec>     params; // -mu_names, -mu_min, -mu_max, -mu_default, -mu_geo_set, -mu
  // Contact pair: slave and master physical names.
  PetscBool   contact = PETSC_FALSE;
  std::string slave, master;
};

// Reads the scene from the options database (-mesh_file, -bodies, -body_E, ...). Checks ranges:
// E > 0, -1 < nu < 0.5, degree in {1, 2}; errors name the option and the value.
PetscErrorCode SceneSpecFromOptions(MPI_Comm comm, SceneSpec *scene);

// Lamé coefficients of a body: L = E nu / ((1 + nu)(1 - 2 nu)), G = E / (2 (1 + nu)).
void LameFromYoung(PetscReal E, PetscReal nu, PetscReal *L, PetscReal *G);

// The names of the options in PETSc's database, as given (with the leading '-'), and lowered (without it).
PetscErrorCode OptionNames(std::vector<std::string> *given, std::vector<std::string> *lowered);

// Splits "a,b,c" (no empty items).
std::vector<std::string> SplitList(const std::string &s, char sep = ',');
// The shortest decimal that reads back to x (1.1500000001, not 1.15 or 1.1500000000999999).
std::string ShortestReal(double x);
// "parameter 'radius' = 1.1500000001 is outside its box [0.95, 1.15]" (shortest round-trip digits)
std::string OutOfBoxMessage(const ParamSpec &p, PetscReal value);

} // namespace rbc
