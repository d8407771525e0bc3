// rbcontact/fom.hpp: the full-order model of a scene: mesh, elasticity, the factored stiffness
// (KSP prefix fom_, default MUMPS Cholesky, reused for every solve of the same parameter) and
// the solution. Contact (contact.hpp, kacanov.hpp) builds on the factored operator held here.
#pragma once
#include <petscksp.h>
#include <memory>
#include "rbcontact/affine_decomposition.hpp"
#include "rbcontact/elasticity.hpp"
#include "rbcontact/geometry_map.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/scene.hpp"

namespace rbc {

struct FomTimes {
  PetscLogDouble assembly = 0, factorization = 0, contact = 0, solve = 0, total = 0;
};

class ElasticFOM {
public:
  ElasticFOM() = default;
  ElasticFOM(const ElasticFOM &) = delete;
  ElasticFOM &operator=(const ElasticFOM &) = delete;
  ~ElasticFOM();

  // Loads the mesh of the scene and sets up the discretization.
  PetscErrorCode Create(MPI_Comm comm, const SceneSpec &scene);
  // Sets up on an existing DM (tests, manufactured solutions); takes a reference.
  PetscErrorCode CreateOnDM(DM dm, const SceneSpec &scene);
  // Builds the affine decomposition of A(mu), f(mu) (then AssembleAndFactor sums its terms).
  PetscErrorCode SetupAffine();
  // The parameter of the next assembly: physical state of the discretization at mu.
  PetscErrorCode SetMu(const std::vector<PetscReal> &mu);
  // Assembles A(mu) and f(mu) (affine sums if SetupAffine was called, else directly) and factors A.
  PetscErrorCode AssembleAndFactor();
  // The contact dofs D of the dense dual solve (KacanovSolver::ShareFactor sets them). On 1 rank with the
  // default direct solver (preonly + Cholesky + MUMPS) and -contact_compliance auto|schur, A is then
  // factored once with MUMPS and its Schur complement on D: the compliance reads that Schur complement
  // and every solve uses the same factor (one factorization per parameter; docs/fom_speed.md). The same on
  // several ranks when A has no coupling between them (-mesh_partitioner bodies): each rank factors its
  // own block with the Schur complement on its dofs of D (SchurIsLocal).
  void SetSchurDofs(const std::vector<PetscInt> &D) { schurDofs_ = D; }
  // Factorless: AssembleAndFactor only assembles, and A is factored on the first ApplyInverse (the contact
  // solve on the saddle point, -fom_dual_matrix saddle, factors its own matrix and never needs A's factor; what
  // asks for A^{-1} then is the offline stage's supremizers). iterative (-fom_saddle_solver gamg: memory linear in
  // the dofs): that solve is CG + GAMG to rtol 1e-10 as well, unless -fom_ksp_type or -fom_pc_type choose (a MUMPS
  // factor of A at 5.4e5 3D dofs outgrew the machine, docs/rom3d.md). The solver in use: ElasticSolverName().
  PetscErrorCode SetFactorless(bool on, bool iterative = false);
  std::string    ElasticSolverName() const; // "<ksp type>+<pc type>" of the elastic solves A^{-1}
  const std::vector<PetscInt> &SchurDofs() const { return schurDofs_; }
  // The Schur complement S_A = A_DD - A_DI A_II^{-1} A_ID of the last factorization (a sequential
  // dense copy), or null when A was factored by the KSP alone (or this rank holds no dof of D).
  Mat SchurComplement() const { return schurS_; }
  // True (on every rank) when each rank factored its own block: SchurComplement() is then the block of
  // this rank's dofs of D (those in its ownership range, in order) and (A^{-1})_DD is block diagonal.
  bool SchurIsLocal() const { return schurFactor_ && schurLocal_; }
  // u = A^{-1} rhs with the factored operator.
  PetscErrorCode ApplyInverse(Vec rhs, Vec x);
  // Plain elastic solve u = A^{-1} f.
  PetscErrorCode SolveElastic();
  // Writes displacement (vertex field), von Mises (cell field) to HDF5 and an XDMF beside it; the
  // named vectors of `contact` (multipliers, slave coordinates x, y(, z), normals normal_x, ...) go to the
  // group /contact, and the XDMF gets a second grid "contact" (the slave vertices as points, every contact
  // vector an attribute, the normal_* a vector) when the coordinates are among them. `fields`: more named
  // global vectors of dm (POD modes, ...), written and described like the displacement.
  PetscErrorCode WriteOutput(const std::string &h5file, const std::vector<Vec> &contact = {}, const std::vector<Vec> &fields = {});
  // Fills ndofs, nranks, energy, time_s.
  PetscErrorCode FillReport(Report *rep);
  PetscInt GlobalSize() const;
  // Checks the factorization after KSPSetUp (diagnosis, one retry on a MUMPS workspace shortage).
  PetscErrorCode CheckFactorization();
  // A clear error for a body with no Dirichlet value in some component (it floats: its translation in
  // that direction is a null mode of A; frictionless contact cannot hold it). Collective.
  PetscErrorCode CheckBodiesHeld() const;
  // Bodies that share mesh vertices are glued there (contact acts between the contact surfaces only): a warning.
  PetscErrorCode CheckBodiesApart();
  // A warning: printed once (rank 0 of the mesh's communicator) and kept for the report (key warnings).
  PetscErrorCode Warn(const std::string &msg);
  std::vector<std::string> warnings;

  SceneSpec  scene;
  GeometryMap map;          // h(mu) per body (-map_<body> ...)
  Elasticity elas;
  AffineDecomposition affine;
  bool                useAffine = false;
  std::vector<PetscReal> mu; // current parameter
  DM         dm  = nullptr;
  Mat        A   = nullptr;
  Vec        f   = nullptr;
  Vec        u   = nullptr;
  KSP        ksp = nullptr;
  FomTimes   times;

private:
  PetscErrorCode FactorWithSchur(bool *done);
  PetscErrorCode Factor();
  bool                  factorless_ = false, factorPending_ = false;
  bool                  residualChecked_ = false; // the first solve after a factorization checks ||A x - rhs||
  std::vector<PetscInt> schurDofs_;
  Mat                   schurFactor_ = nullptr, schurS_ = nullptr; // MUMPS factor with the Schur on D, S copy
  Mat                   factored_    = nullptr;                    // the matrix schurFactor_ factors (A, or its diagonal block)
  bool                  schurLocal_  = false;                      // each rank factors its own block
  PetscInt              schurRank_   = 0;                          // this rank's dofs of D in the factor's Schur set
  Vec                   bLocal_ = nullptr, xLocal_ = nullptr;      // sequential views of the local parts (schurLocal_)
};

// One attribute of an XDMF grid: display name, HDF5 dataset path, components, node or cell centred.
struct XdmfAttribute {
  std::string name, dataset;
  PetscInt    ncomp = 1;
  bool        cell  = false;
};
// Writes <h5file without .h5>.xmf describing the mesh (/geometry/vertices, /viz/topology/cells: PetscInt,
// its precision sizeof(PetscInt)) and the attributes of an HDF5 file in PETSc's VIZ layout; with npoints > 0
// also the grid "contact": npoints points at /contact/points (npoints x 3) with the attributes pattrs.
// The XDMF file written beside an HDF5 file: <h5file without .h5>.xmf.
std::string    XdmfPath(const std::string &h5file);
PetscErrorCode WriteXdmf(MPI_Comm comm, const std::string &h5file, PetscInt dim, PetscInt nverts, PetscInt ncells, PetscInt nvpc, const std::vector<XdmfAttribute> &attrs, PetscInt npoints = 0, const std::vector<XdmfAttribute> &pattrs = {});

} // namespace rbc
