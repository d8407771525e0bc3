// include/rbcontact/rom_fields.hpp: full-order fields of a reduced solution on the scene's mesh: the primal and
// dual bases read from the ROM's basis file, the displacement u = sum_n v_n theta_n and the
// multipliers lambda = sum_r lambda_r xi_r (canonical order), and -rom_reconstruct's output file.
#pragma once
#include <memory>
#include "rbcontact/canonical_order.hpp"
#include "rbcontact/contact.hpp"
#include "rbcontact/dual_basis.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/reduced_model.hpp"
#include "rbcontact/report.hpp"

namespace rbc {

class RomBases {
public:
  // The basis file named by the ROM (attribute basis_file; -rom_basis overrides); checks its sizes
  // against the model, ndofs (the scene's free dofs) and nmult (its multipliers), and that every value is finite.
  PetscErrorCode Read(MPI_Comm comm, const ReducedModel &model, const std::string &romPath, PetscInt ndofs, PetscInt nmult);
  // u (global vector of order's DM) from the active reduced coordinates v of model.
  PetscErrorCode Displacement(const ReducedModel &model, const CanonicalOrder &order, const std::vector<PetscReal> &v, Vec u) const;
  // lambda in canonical multiplier order from the active reduced multipliers.
  void Multipliers(const ReducedModel &model, const std::vector<PetscReal> &lhat, std::vector<PetscReal> *lambda) const;
  std::string            path;
  PetscInt               N = 0, ndofs = 0, r = 0, R = 0;
  std::vector<double>    modes, W; // N x ndofs, r x R (row-major, canonical)
};

// Everything that defines the problem (not the run): scene, mesh, materials, loads, parameters, maps,
// contact options (the multiplier functions always). Its FNV-1a hash (hex) is the files' scene_hash.
std::string SceneFingerprint(const SceneSpec &s, const GeometryMap &map);
std::string SceneHashHex(const SceneSpec &s, const GeometryMap &map);
// The ROM at romPath belongs to this scene as configured now (name and scene_hash); else a clear error.
PetscErrorCode CheckRomScene(MPI_Comm comm, const std::string &romPath, const SceneSpec &scene, const GeometryMap &map);
// Scene options given to a stage that solves a ROM as it was built (online without -rom_reconstruct, probe): an options
// file of a scene, -body_E 200,100 were ignored without a word (the ROM's own answer). With -scene they are checked
// against the ROM (its scene name first, then CheckRomScene); without it, a scene option is refused by name.
PetscErrorCode CheckSceneOptions(MPI_Comm comm, const std::string &stage, const std::string &romPath);

// The contact system at the default parameter and u = 0 (Dirichlet values lifted); numbers order's
// multipliers if needed. Its weight is the slave mass int psi_i of the reference configuration.
PetscErrorCode AssembleReferenceContact(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, ContactSystem *sys);
// Its weights int psi_i (the slave mass) on every rank, in canonical multiplier order. Collective on fom.
PetscErrorCode ReferenceSlaveMass(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, std::vector<PetscReal> *w);
// W' diag(w) W (r x r, row-major) for the dual basis W (R_fom x r) and that slave mass w: the norm of validate's lambda
// error on the reduced multipliers (the error estimate's, ReducedModel::massGram).
std::vector<PetscReal> SlaveMassGram(const DenseMatrix &W, const std::vector<PetscReal> &w);
// The full contact patch (ContactPatch::BuildFull) on the support of the dual basis Wt (r x R_fom,
// row-major, canonical) with the primal basis modes (N x ndofs, canonical), nsub composite pieces, and
// P = W' Psi (r x Q, row-major). The surfaces are assembled at the default parameter with u = 0 (they
// then carry the Dirichlet values); numbers order's multipliers if not done yet. Collective on fom.
PetscErrorCode BuildFullContact(ElasticFOM &fom, ContactMap &cmap, CanonicalOrder &order, const std::vector<double> &modes, PetscInt N, const std::vector<double> &Wt, PetscInt r, PetscInt nsub, std::shared_ptr<ContactPatch> *full, std::vector<PetscReal> *P);
// lambda (canonical multiplier order) into the distributed multiplier vector v (rows of K).
PetscErrorCode CanonicalToMultipliers(const CanonicalOrder &order, const std::vector<PetscReal> &lambda, Vec v);

// -rom_reconstruct: the scene from the options (must match the ROM's), fields at mu written to path.
PetscErrorCode ReconstructFields(MPI_Comm comm, const ReducedModel &model, const ReducedSolution &sol, const std::vector<PetscReal> &mu, const std::string &path, Report *rep);

// -offline_basis_output: the bases of the ROM at romPath on the scene's mesh for ParaView (path + its .xmf): the
// POD modes and supremizers as vertex fields pod_mode_k, supremizer_k (the displacement is zero), and the dual
// basis vectors dual_k with the slave weights and normals on the grid "contact" (the slave vertices at the
// default parameters). Report key basis_view {file, xdmf, pod_modes, supremizers, dual}.
PetscErrorCode WriteBasisView(MPI_Comm comm, const SceneSpec &scene, const std::string &romPath, const std::string &path, Report *rep);

} // namespace rbc
