// src/fem/elasticity.cpp: PetscFE elasticity on a mapped reference mesh: the per-cell auxiliary P0
// field carries the effective tensor, the Lamé coefficients, G^-1 and the body-force scale; constant
// body force / tractions from the scene (scaled through the constants); essential values by lifting.
#include "rbcontact/elasticity.hpp"
#include "rbcontact/mesh.hpp"
#include <algorithm>
#include <cmath>

namespace rbc {

#define RBC_POINTWISE_ARGS \
  PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, const PetscReal x[], PetscInt numConstants, const PetscScalar constants[]

// Constants layout: [0, 3) body force; [3 + 3k, 6 + 3k) traction of natural boundary k.
static const PetscInt kMaxTractions = 8;

// Aux layout (see Elasticity::AuxSize): L, G, G^-1 (dim x dim), body-force scale, then the tensor T.
#define RBC_D4 (dim * dim * dim * dim)
#define RBC_AUX_L 0
#define RBC_AUX_G 1
#define RBC_AUX_GINV 2
#define RBC_AUX_BF (2 + dim * dim)
#define RBC_AUX_M (3 + dim * dim)
#define RBC_AUX_T (4 + dim * dim)

static void f0_body_force(RBC_POINTWISE_ARGS, PetscScalar f0[])
{
  const PetscScalar scale = a[RBC_AUX_BF];
  for (PetscInt d = 0; d < dim; ++d) f0[d] = -constants[d] * scale;
}

// Reference-configuration stress: f1[c][a] = sum_{e,b} T[c][a][e][b] du_e/dxr_b
static void f1_stress(RBC_POINTWISE_ARGS, PetscScalar f1[])
{
  for (PetscInt ca = 0; ca < dim * dim; ++ca) {
    PetscScalar s = 0;
    for (PetscInt eb = 0; eb < dim * dim; ++eb) s += a[RBC_AUX_T + ca * dim * dim + eb] * u_x[eb];
    f1[ca] = s;
  }
}

// Mass term of the H1 inner product (coefficient zero in the physical state).
static void g0_mass(PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, PetscReal u_tShift, const PetscReal x[], PetscInt numConstants, const PetscScalar constants[], PetscScalar g0[])
{
  for (PetscInt c = 0; c < dim; ++c) g0[c * dim + c] += a[RBC_AUX_M];
}

static void g3_stiffness(PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, PetscReal u_tShift, const PetscReal x[], PetscInt numConstants, const PetscScalar constants[], PetscScalar g3[])
{
  // PetscDS layout g3[test comp c][trial comp e][test deriv a][trial deriv b]; T is [c][a][e][b]
  for (PetscInt c = 0; c < dim; ++c)
    for (PetscInt aa = 0; aa < dim; ++aa)
      for (PetscInt e = 0; e < dim; ++e)
        for (PetscInt b = 0; b < dim; ++b) g3[((c * dim + e) * dim + aa) * dim + b] += a[RBC_AUX_T + ((c * dim + aa) * dim + e) * dim + b];
}

// Energy density in the reference configuration: 1/2 grad u : T : grad u (includes |det G|).
static void EnergyDensity(PetscInt dim, const PetscScalar u_x[], const PetscScalar a[], PetscScalar *w)
{
  PetscScalar e = 0;
  for (PetscInt ca = 0; ca < dim * dim; ++ca)
    for (PetscInt eb = 0; eb < dim * dim; ++eb) e += u_x[ca] * a[RBC_AUX_T + ca * dim * dim + eb] * u_x[eb];
  *w = 0.5 * e;
}

static void obj_energy(RBC_POINTWISE_ARGS, PetscScalar obj[]) { EnergyDensity(dim, u_x, a, &obj[0]); }

static void obj_von_mises(RBC_POINTWISE_ARGS, PetscScalar obj[])
{
  obj[0] = rbc::VonMisesStress(dim, u_x, PetscRealPart(a[RBC_AUX_L]), PetscRealPart(a[RBC_AUX_G]), a + RBC_AUX_GINV);
}

template <int K>
static void f0_traction(PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, const PetscReal x[], const PetscReal n[], PetscInt numConstants, const PetscScalar constants[], PetscScalar f0[])
{
  for (PetscInt d = 0; d < dim; ++d) f0[d] = -constants[3 + 3 * K + d]; // scaled in ApplyConstants
}

using BdF = void (*)(PetscInt, PetscInt, PetscInt, const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], PetscReal, const PetscReal[], const PetscReal[], PetscInt, const PetscScalar[], PetscScalar[]);
static const BdF kTractionFns[kMaxTractions] = {f0_traction<0>, f0_traction<1>, f0_traction<2>, f0_traction<3>, f0_traction<4>, f0_traction<5>, f0_traction<6>, f0_traction<7>};

static PetscErrorCode ConstantBC(PetscInt dim, PetscReal t, const PetscReal x[], PetscInt Nc, PetscScalar *u, void *ctx)
{
  const DirichletSpec *bc = static_cast<const DirichletSpec *>(ctx);
  for (PetscInt c = 0; c < Nc; ++c) u[c] = c < (PetscInt)bc->values.size() ? bc->scale * bc->values[c] : 0.0;
  return 0;
}

Elasticity::~Elasticity()
{
  (void)MatNullSpaceDestroy(&nearNull_);
  (void)VecDestroy(&bcLocal_);
  (void)SNESDestroy(&snes_);
  (void)VecDestroy(&aux_);
  (void)DMDestroy(&dmAux_);
  (void)DMDestroy(&dmCell);
  (void)DMDestroy(&dm);
}

PetscErrorCode Elasticity::SetupMaterials()
{
  PetscInt cStart, cEnd;
  PetscFE  fe, feAux;
  PetscDS  ds;

  PetscFunctionBeginUser;
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  cellBody_.assign(cEnd - cStart, -1);
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec &body = scene.bodies[b];
    if (body.name == "all") {
      for (auto &cb : cellBody_) if (cb < 0) cb = (PetscInt)b;
      continue;
    }
    DMLabel label;
    PetscCall(DMGetLabel(dm, body.name.c_str(), &label));
    if (!label) continue; // checked globally when the mesh was loaded
    for (PetscInt c = cStart; c < cEnd; ++c) {
      PetscInt v;
      PetscCall(DMLabelGetValue(label, c, &v));
      if (v >= 0) cellBody_[c - cStart] = (PetscInt)b;
    }
  }
  PetscInt missing = 0;
  for (auto cb : cellBody_) if (cb < 0) ++missing;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &missing, 1, MPIU_INT, MPI_SUM, PetscObjectComm((PetscObject)dm)));
  PetscCheck(!missing, PetscObjectComm((PetscObject)dm), PETSC_ERR_USER_INPUT, "%" PetscInt_FMT " cells belong to no body of -bodies (mesh '%s'): name every body, or use -bodies all", missing, scene.mesh.file.c_str());

  PetscCall(DMClone(dm, &dmAux_));
  PetscCall(DMGetDS(dm, &ds));
  PetscCall(PetscDSGetDiscretization(ds, 0, (PetscObject *)&fe));
  PetscCall(PetscFECreateLagrange(PETSC_COMM_SELF, dim, AuxSize(), PETSC_TRUE, 0, PETSC_DETERMINE, &feAux));
  PetscCall(PetscFECopyQuadrature(fe, feAux));
  PetscCall(DMSetField(dmAux_, 0, NULL, (PetscObject)feAux));
  PetscCall(DMCreateDS(dmAux_));
  PetscCall(PetscFEDestroy(&feAux));
  PetscCall(DMCreateLocalVector(dmAux_, &aux_));
  PetscCall(DMSetAuxiliaryVec(dm, NULL, 0, 0, aux_));
  PetscFunctionReturn(0);
}

void Elasticity::Material(PetscInt b, const std::vector<PetscReal> &mu, PetscReal *E, PetscReal *nu) const
{
  const BodySpec &body = scene.bodies[b];
  *E                   = body.paramE >= 0 && body.paramE < (PetscInt)mu.size() ? mu[body.paramE] : body.E;
  *nu                  = body.paramNu >= 0 && body.paramNu < (PetscInt)mu.size() ? mu[body.paramNu] : body.nu;
}

void Elasticity::PhysicalAux(PetscReal E, PetscReal nu, const Affine &a, std::vector<PetscReal> *aux) const
{
  PetscReal L, G;
  LameFromYoung(E, nu, &L, &G);
  aux->assign(AuxSize(), 0.0);
  // G^-1 of the dim x dim block
  PetscReal Gi[9] = {0};
  const PetscReal det = a.Det(dim);
  if (dim == 2) {
    Gi[0] = a.G[4] / det; Gi[1] = -a.G[1] / det; Gi[2] = -a.G[3] / det; Gi[3] = a.G[0] / det;
  } else {
    const auto &m = a.G;
    Gi[0] = (m[4] * m[8] - m[5] * m[7]) / det; Gi[1] = (m[2] * m[7] - m[1] * m[8]) / det; Gi[2] = (m[1] * m[5] - m[2] * m[4]) / det;
    Gi[3] = (m[5] * m[6] - m[3] * m[8]) / det; Gi[4] = (m[0] * m[8] - m[2] * m[6]) / det; Gi[5] = (m[2] * m[3] - m[0] * m[5]) / det;
    Gi[6] = (m[3] * m[7] - m[4] * m[6]) / det; Gi[7] = (m[1] * m[6] - m[0] * m[7]) / det; Gi[8] = (m[0] * m[4] - m[1] * m[3]) / det;
  }
  // T[c][a][e][b] = |det G| sum_{d,f} C[c][d][e][f] Gi[a][d] Gi[b][f], C = L d_cd d_ef + G (d_ce d_df + d_cf d_de)
  const PetscReal J = std::abs(det);
  PetscReal       C[81];
  for (PetscInt c = 0; c < dim; ++c)
    for (PetscInt d = 0; d < dim; ++d)
      for (PetscInt e = 0; e < dim; ++e)
        for (PetscInt f = 0; f < dim; ++f) C[((c * dim + d) * dim + e) * dim + f] = L * (c == d) * (e == f) + G * ((c == e) * (d == f) + (c == f) * (d == e));
  PullBackTensor(dim, C, Gi, J, aux->data() + AuxTensorOffset());
  (*aux)[0] = L;
  (*aux)[1] = G;
  for (PetscInt k = 0; k < dim * dim; ++k) (*aux)[2 + k] = Gi[k];
  (*aux)[AuxBodyForceIndex()] = J; // body force scale
}

PetscErrorCode Elasticity::SetBodyAux(const std::vector<std::vector<PetscReal>> &perBody)
{
  PetscInt     cStart, cEnd;
  PetscScalar *arr;

  PetscFunctionBeginUser;
  bodyAux_ = perBody;
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  PetscCall(VecGetArray(aux_, &arr));
  for (PetscInt c = cStart; c < cEnd; ++c) {
    PetscScalar *p;
    PetscCall(DMPlexPointLocalRef(dmAux_, c, arr, &p));
    const auto &v = perBody[cellBody_[c - cStart]];
    for (PetscInt k = 0; k < AuxSize(); ++k) p[k] = v[k];
  }
  PetscCall(VecRestoreArray(aux_, &arr));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::ApplyConstants(PetscReal bodyForceScale, const std::vector<PetscReal> &tractionScale)
{
  PetscDS ds;

  PetscFunctionBeginUser;
  std::vector<PetscScalar> constants(3 + 3 * kMaxTractions, 0.0);
  for (size_t d = 0; d < scene.bodyForce.size(); ++d) constants[d] = scene.bodyForce[d] * (bodyForceScale != 0 ? 1.0 : 0.0);
  for (size_t k = 0; k < scene.tractions.size(); ++k)
    for (PetscInt d = 0; d < dim; ++d) constants[3 + 3 * k + d] = scene.tractions[k].traction[d] * tractionScale[k];
  PetscCall(DMGetDS(dm, &ds));
  PetscCall(PetscDSSetConstants(ds, (PetscInt)constants.size(), constants.data()));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::SetLoadScales(const std::vector<PetscReal> &dirichlet, PetscReal bodyForce, const std::vector<PetscReal> &traction)
{
  PetscFunctionBeginUser;
  size_t k = 0;
  for (auto &bc : bcs_) bc.scale = dirichlet[k++];
  bcValid_ = false;
  PetscCall(ApplyConstants(bodyForce, traction));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::SetMu(const std::vector<PetscReal> &mu)
{
  MPI_Comm comm = PetscObjectComm((PetscObject)dm);

  PetscFunctionBeginUser;
  std::vector<std::vector<PetscReal>> perBody(scene.bodies.size());
  std::vector<Affine>                 maps(scene.bodies.size());
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    PetscReal E, nu;
    Material((PetscInt)b, mu, &E, &nu);
    PetscCheck(E > 0 && nu > -1 && nu < 0.5, comm, PETSC_ERR_ARG_OUTOFRANGE, "Body '%s' at this parameter: E = %g, nu = %g out of range", scene.bodies[b].name.c_str(), (double)E, (double)nu);
    maps[b] = map_ ? map_->Evaluate((PetscInt)b, mu) : Affine();
    PetscCheck(maps[b].Det(dim) > 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "The geometric map of body '%s' is not orientation preserving at this parameter (det %g)", scene.bodies[b].name.c_str(), (double)maps[b].Det(dim));
    PhysicalAux(E, nu, maps[b], &perBody[b]);
  }
  PetscCall(SetBodyAux(perBody));
  std::vector<PetscReal> dsc, tsc;
  for (const auto &bc : scene.dirichlet) dsc.push_back(bc.param >= 0 ? mu[bc.param] / scene.params[bc.param].def : 1.0);
  for (size_t k = 0; k < scene.tractions.size(); ++k) {
    const TractionSpec &t = scene.tractions[k];
    // the surface measure of a mapped boundary: s^(dim-1) under G = s I (conformal maps only)
    PetscReal      s = 1.0;
    const PetscInt b = tractionBody_[k];
    if (b >= 0 && !(map_ ? map_->bodies[b].blocks.empty() : true)) {
      const Affine &a   = maps[b];
      const bool    conf = std::abs(a.G[1]) + std::abs(a.G[3]) + std::abs(a.G[2]) + std::abs(a.G[5]) + std::abs(a.G[6]) + std::abs(a.G[7]) < 1e-14 && std::abs(a.G[0] - a.G[4]) <= 1e-14 * std::abs(a.G[0]) && (dim == 2 || std::abs(a.G[0] - a.G[8]) <= 1e-14 * std::abs(a.G[0]));
      PetscCheck(conf, comm, PETSC_ERR_SUP, "-traction %s: tractions on a body with a non-conformal map (stretch) are not supported", t.label.c_str());
      s = std::pow(a.G[0], (PetscReal)(dim - 1));
    }
    tsc.push_back(s * (t.param >= 0 ? mu[t.param] / scene.params[t.param].def : 1.0));
  }
  PetscCall(SetLoadScales(dsc, 1.0, tsc));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::Setup(DM dmIn, const SceneSpec &sceneIn)
{
  PetscFE  fe;
  PetscDS  ds;
  PetscInt cStart;
  MPI_Comm comm = PetscObjectComm((PetscObject)dmIn);

  PetscFunctionBeginUser;
  PetscCall(MatNullSpaceDestroy(&nearNull_)); // of an earlier mesh
  dm = dmIn;
  scene = sceneIn;
  PetscCall(PetscObjectReference((PetscObject)dm));
  PetscCall(DMGetDimension(dm, &dim));
  degree = scene.degree;
  {
    const char *types[] = {"element", "petscfe"};
    PetscInt    t       = elementAssembly_ ? 0 : 1;
    PetscOptionsBegin(comm, "fem_", "Finite-element assembly", "Elasticity");
    PetscCall(PetscOptionsEList("-assembly", "Assembly of A, the lifting, the energy and the von Mises output: element (cell tables and exact reference integrals, a cached pattern) or petscfe (PetscFE residual and Jacobian, the reference)", NULL, types, 2, types[t], &t, NULL));
    PetscOptionsEnd();
    elementAssembly_ = t == 0;
  }
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, NULL));
  {
    // every cell, on every rank (the first one's type alone let a mesh of tetrahedra and hexahedra through, to errors
    // of the contact surface or the assembly that named no mesh; and the check was rank-local)
    const DMPolytopeType simplex = dim == 3 ? DM_POLYTOPE_TETRAHEDRON : DM_POLYTOPE_TRIANGLE;
    PetscInt             cEnd, bad[2] = {0, -1}; // count, the first such cell's type
    PetscCall(DMPlexGetHeightStratum(dm, 0, NULL, &cEnd));
    for (PetscInt c = cStart; c < cEnd; ++c) {
      DMPolytopeType ct;
      PetscCall(DMPlexGetCellType(dm, c, &ct));
      if (ct != simplex && bad[0]++ == 0) bad[1] = (PetscInt)ct;
    }
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad[0], 1, MPIU_INT, MPI_SUM, comm));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad[1], 1, MPIU_INT, MPI_MAX, comm));
    PetscCheck(bad[0] == 0, comm, PETSC_ERR_SUP, "Mesh '%s': only simplex cells (triangles, tetrahedra) are supported; %" PetscInt_FMT " of its cells are not (the first of type %s)", scene.mesh.file.c_str(), bad[0], bad[1] >= 0 ? DMPolytopeTypes[bad[1]] : "other");
  }
  PetscCall(PetscFECreateLagrange(comm, dim, dim, PETSC_TRUE, degree, PETSC_DETERMINE, &fe));
  PetscCall(PetscObjectSetName((PetscObject)fe, "displacement"));
  PetscCall(DMSetField(dm, 0, NULL, (PetscObject)fe));
  PetscCall(DMCreateDS(dm));
  PetscCall(PetscFEDestroy(&fe));
  PetscCall(DMGetDS(dm, &ds));
  PetscCall(PetscDSSetResidual(ds, 0, (scene.bodyForceF0 ? scene.bodyForceF0 : (!scene.bodyForce.empty() ? f0_body_force : NULL)), f1_stress));
  PetscCall(PetscDSSetJacobian(ds, 0, 0, g0_mass, NULL, NULL, g3_stiffness));

  // Constants: body force and tractions
  PetscCheck((PetscInt)scene.tractions.size() <= kMaxTractions, comm, PETSC_ERR_SUP, "-traction: at most %" PetscInt_FMT " traction boundaries", kMaxTractions);
  std::vector<PetscScalar> constants(3 + 3 * kMaxTractions, 0.0);
  PetscCheck(scene.bodyForce.empty() || (PetscInt)scene.bodyForce.size() == dim, comm, PETSC_ERR_USER_INPUT, "-body_force has %zu components, the mesh is %" PetscInt_FMT "D", scene.bodyForce.size(), dim);
  for (size_t d = 0; d < scene.bodyForce.size(); ++d) constants[d] = scene.bodyForce[d];
  for (size_t k = 0; k < scene.tractions.size(); ++k) {
    const TractionSpec &tr = scene.tractions[k];
    PetscCheck((PetscInt)tr.traction.size() == dim, comm, PETSC_ERR_USER_INPUT, "-traction_%s_t has %zu components, the mesh is %" PetscInt_FMT "D", tr.label.c_str(), tr.traction.size(), dim);
    for (PetscInt d = 0; d < dim; ++d) constants[3 + 3 * k + d] = tr.traction[d];
    DMLabel       label;
    PetscInt      bd;
    PetscWeakForm wf;
    IS            valueIS;
    PetscInt      nv = 0;
    const PetscInt *vals = NULL;
    PetscCall(DMGetLabel(dm, tr.label.c_str(), &label));
    PetscCall(MeshCheckLabel(dm, tr.label, "-traction", scene.mesh.file));
    PetscCall(DMLabelGetValueIS(label, &valueIS));
    PetscCall(ISGetLocalSize(valueIS, &nv));
    PetscCall(ISGetIndices(valueIS, &vals));
    std::vector<PetscInt> values(vals, vals + nv);
    PetscCall(ISRestoreIndices(valueIS, &vals));
    PetscCall(ISDestroy(&valueIS));
    // Label values are the gmsh physical tags: the same on every rank that holds the boundary.
    PetscInt v = values.empty() ? -1 : values[0];
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPIU_INT, MPI_MAX, comm));
    PetscCall(DMAddBoundary(dm, DM_BC_NATURAL, tr.label.c_str(), label, 1, &v, 0, 0, NULL, NULL, NULL, NULL, &bd));
    PetscCall(PetscDSGetBoundary(ds, bd, &wf, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL));
    PetscCall(PetscWeakFormSetIndexBdResidual(wf, label, v, 0, 0, 0, kTractionFns[k], 0, NULL));
  }
  PetscCall(PetscDSSetConstants(ds, (PetscInt)constants.size(), constants.data()));

  // Essential boundaries
  bcs_.assign(scene.dirichlet.begin(), scene.dirichlet.end());
  bcValue_.clear();
  for (auto &bc : bcs_) {
    DMLabel label;
    PetscCall(MeshCheckLabel(dm, bc.label, "-dirichlet", scene.mesh.file));
    PetscCall(DMGetLabel(dm, bc.label.c_str(), &label));
    if (!bc.fn) PetscCheck(!bc.values.empty(), comm, PETSC_ERR_USER_INPUT, "-dirichlet_%s_u is not given: -dirichlet lists the label '%s', give its %" PetscInt_FMT " displacement components (e.g. -dirichlet_%s_u 0,0)", bc.label.c_str(), bc.label.c_str(), dim, bc.label.c_str());
    if (!bc.fn) PetscCheck((PetscInt)bc.values.size() == dim, comm, PETSC_ERR_USER_INPUT, "-dirichlet_%s_u has %zu components, the mesh is %" PetscInt_FMT "D (give all components; -dirichlet_%s_comps selects the constrained ones)", bc.label.c_str(), bc.values.size(), dim, bc.label.c_str());
    for (PetscInt c : bc.comps) PetscCheck(c < dim, comm, PETSC_ERR_ARG_OUTOFRANGE, "-dirichlet_%s_comps: component %" PetscInt_FMT " >= dimension %" PetscInt_FMT, bc.label.c_str(), c, dim);
    IS              valueIS;
    PetscInt        nv = 0;
    const PetscInt *vals = NULL;
    PetscCall(DMLabelGetValueIS(label, &valueIS));
    PetscCall(ISGetLocalSize(valueIS, &nv));
    PetscCall(ISGetIndices(valueIS, &vals));
    PetscInt v = nv ? vals[0] : -1;
    PetscCall(ISRestoreIndices(valueIS, &vals));
    PetscCall(ISDestroy(&valueIS));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPIU_INT, MPI_MAX, comm));
    bcValue_.push_back(v);
    PetscCall(DMAddBoundary(dm, DM_BC_ESSENTIAL, bc.label.c_str(), label, 1, &v, 0, (PetscInt)bc.comps.size(), bc.comps.empty() ? NULL : bc.comps.data(), (void (*)(void))(bc.fn ? bc.fn : ConstantBC), NULL, bc.fn ? bc.fnCtx : (void *)&bc, NULL));
  }
  PetscCall(SetupMaterials());
  // The body owning each traction boundary (the cell next to its facets)
  tractionBody_.assign(scene.tractions.size(), -1);
  for (size_t k = 0; k < scene.tractions.size(); ++k) {
    DMLabel  label;
    PetscInt fStart, fEnd, cStart, owner = -1;
    PetscCall(DMGetLabel(dm, scene.tractions[k].label.c_str(), &label));
    PetscCall(DMPlexGetHeightStratum(dm, 1, &fStart, &fEnd));
    PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, NULL));
    for (PetscInt f = fStart; f < fEnd && owner < 0; ++f) {
      PetscInt v, ns;
      const PetscInt *supp;
      PetscCall(DMLabelGetValue(label, f, &v));
      if (v < 0) continue;
      PetscCall(DMPlexGetSupportSize(dm, f, &ns));
      PetscCall(DMPlexGetSupport(dm, f, &supp));
      if (ns > 0) owner = cellBody_[supp[0] - cStart];
    }
    PetscCallMPI(MPI_Allreduce(&owner, &tractionBody_[k], 1, MPIU_INT, MPI_MAX, comm));
  }
  PetscCall(SetMu(ParamValues(scene)));

  // P0 scalar DM for cell fields
  {
    PetscFE fe0;
    PetscCall(DMClone(dm, &dmCell));
    PetscCall(PetscFECreateLagrange(PETSC_COMM_SELF, dim, 1, PETSC_TRUE, 0, PETSC_DETERMINE, &fe0));
    PetscCall(PetscObjectSetName((PetscObject)fe0, "von_mises"));
    PetscCall(DMSetField(dmCell, 0, NULL, (PetscObject)fe0));
    PetscCall(DMCreateDS(dmCell));
    PetscCall(PetscFEDestroy(&fe0));
  }

  PetscCall(SNESCreate(comm, &snes_));
  PetscCall(SNESSetDM(snes_, dm));
  PetscCall(DMPlexSetSNESLocalFEM(dm, NULL, NULL, NULL));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::EnsureElements() const
{
  PetscFunctionBeginUser;
  if (!elem_.Ready()) PetscCall(elem_.Setup(dm));
  PetscFunctionReturn(0);
}

ElementAssembler::Coefficients Elasticity::ElementCoefficients() const
{
  ElementAssembler::Coefficients k;
  k.cellBody = &cellBody_;
  for (const auto &a : bodyAux_) {
    k.tensor.push_back(a.data() + AuxTensorOffset());
    k.mass.push_back(a[AuxMassIndex()]);
    k.lame.push_back(a.data()); // L, G, G^-1: the aux layout's head
  }
  return k;
}

PetscErrorCode Elasticity::AssembleMatrix(Mat *A)
{
  Vec       zero;
  const bool create = !*A;

  PetscFunctionBeginUser;
  if (elementAssembly_) {
    PetscCall(EnsureElements());
    PetscCall(elem_.AssembleMatrix(ElementCoefficients(), A));
  } else {
    if (create) PetscCall(DMCreateMatrix(dm, A));
    PetscCall(DMGetGlobalVector(dm, &zero));
    PetscCall(VecSet(zero, 0.0));
    PetscCall(SNESComputeJacobian(snes_, zero, *A, *A));
    PetscCall(DMRestoreGlobalVector(dm, &zero));
  }
  if (create) {
    PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(*A, MAT_SPD, PETSC_TRUE));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::AssembleH1(Mat *M)
{
  PetscFunctionBeginUser;
  std::vector<std::vector<PetscReal>> aux(scene.bodies.size(), std::vector<PetscReal>(AuxSize(), 0.0));
  for (auto &a : aux) {
    a[AuxMassIndex()] = 1.0;
    for (PetscInt c = 0; c < dim; ++c)
      for (PetscInt d = 0; d < dim; ++d) a[AuxTensorOffset() + ((c * dim + d) * dim + c) * dim + d] = 1.0; // grad u : grad v
  }
  PetscCall(SetBodyAux(aux));
  PetscCall(AssembleMatrix(M));
  PetscCall(SetMu(ParamValues(scene)));
  PetscFunctionReturn(0);
}

// Loads only: the PetscFE residual at u = 0 in the current state with a zero stiffness tensor (its
// Dirichlet lifting vanishes with it); nothing to integrate when the scene has no body force and no traction.
PetscErrorCode Elasticity::AssembleLoads(Vec f)
{
  Vec zero;

  PetscFunctionBeginUser;
  PetscCall(VecSet(f, 0.0));
  if (!scene.bodyForceF0 && scene.bodyForce.empty() && scene.tractions.empty()) PetscFunctionReturn(0);
  const std::vector<std::vector<PetscReal>> state = bodyAux_;
  std::vector<std::vector<PetscReal>>       loadsOnly = state;
  for (auto &a : loadsOnly) std::fill(a.begin() + AuxTensorOffset(), a.end(), 0.0);
  PetscCall(SetBodyAux(loadsOnly));
  PetscCall(DMGetGlobalVector(dm, &zero));
  PetscCall(VecSet(zero, 0.0));
  PetscCall(SNESComputeFunction(snes_, zero, f)); // F(0) = -(loads)
  PetscCall(VecScale(f, -1.0));
  PetscCall(DMRestoreGlobalVector(dm, &zero));
  PetscCall(SetBodyAux(state));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::AssembleRhs(Vec *f)
{
  Vec zero;

  PetscFunctionBeginUser;
  if (!*f) PetscCall(DMCreateGlobalVector(dm, f));
  if (elementAssembly_) {
    Vec uloc;
    PetscCall(EnsureElements());
    PetscCall(AssembleLoads(*f));
    PetscCall(DMGetGlobalVector(dm, &zero));
    PetscCall(DMGetLocalVector(dm, &uloc));
    PetscCall(VecSet(zero, 0.0));
    PetscCall(GlobalToLocalWithBC(zero, uloc)); // the Dirichlet values, zero elsewhere
    PetscCall(elem_.AddLifting(ElementCoefficients(), uloc, *f));
    PetscCall(DMRestoreLocalVector(dm, &uloc));
    PetscCall(DMRestoreGlobalVector(dm, &zero));
    PetscFunctionReturn(0);
  }
  PetscCall(DMGetGlobalVector(dm, &zero));
  PetscCall(VecSet(zero, 0.0));
  PetscCall(SNESComputeFunction(snes_, zero, *f)); // F(0) = -(loads) + A_{fc} u_D
  PetscCall(VecScale(*f, -1.0));
  PetscCall(DMRestoreGlobalVector(dm, &zero));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::Assemble(Mat *A, Vec *f)
{
  PetscFunctionBeginUser;
  PetscCall(AssembleMatrix(A));
  PetscCall(AssembleRhs(f));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::GlobalToLocalWithBC(Vec u, Vec uloc) const
{
  PetscFunctionBeginUser;
  if (!bcValid_) { // the boundary values of this state, projected once (DMPlexInsertBoundaryValues is slow)
    bool constant = elementAssembly_;
    for (const auto &bc : bcs_) constant = constant && !bc.fn;
    if (!bcLocal_) PetscCall(DMCreateLocalVector(dm, &bcLocal_));
    PetscCall(VecSet(bcLocal_, 0.0));
    if (constant) PetscCall(InsertConstantBoundaryValues(bcLocal_));
    else PetscCall(DMPlexInsertBoundaryValues(dm, PETSC_TRUE, bcLocal_, 0.0, NULL, NULL, NULL));
    bcValid_ = true;
  }
  PetscCall(VecCopy(bcLocal_, uloc)); // the global-to-local scatter leaves the constrained entries alone
  PetscCall(DMGlobalToLocal(dm, u, INSERT_VALUES, uloc));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::InsertConstantBoundaryValues(Vec uloc) const
{
  PetscSection sec;
  PetscScalar *a;
  PetscInt     dim;

  PetscFunctionBeginUser;
  PetscCall(DMGetDimension(dm, &dim));
  PetscCall(DMGetLocalSection(dm, &sec));
  PetscCall(VecGetArray(uloc, &a));
  size_t k = 0;
  for (const auto &bc : bcs_) {
    DMLabel         label;
    IS              pts = NULL;
    const PetscInt *pi  = NULL;
    PetscInt        np  = 0;
    const PetscInt  v   = bcValue_[k++];
    PetscCall(DMGetLabel(dm, bc.label.c_str(), &label));
    if (label && v >= 0) PetscCall(DMLabelGetStratumIS(label, v, &pts));
    if (!pts) continue;
    PetscCall(ISGetLocalSize(pts, &np));
    PetscCall(ISGetIndices(pts, &pi));
    for (PetscInt q = 0; q < np; ++q) {
      PetscInt *cl = NULL, ncl = 0;
      PetscCall(DMPlexGetTransitiveClosure(dm, pi[q], PETSC_TRUE, &ncl, &cl));
      for (PetscInt c = 0; c < ncl; ++c) {
        PetscInt dof, off;
        PetscCall(PetscSectionGetDof(sec, cl[2 * c], &dof));
        if (!dof) continue;
        PetscCall(PetscSectionGetOffset(sec, cl[2 * c], &off));
        for (PetscInt n = 0; n < dof / dim; ++n) // Lagrange nodes of the point, component fastest
          if (bc.comps.empty())
            for (PetscInt d = 0; d < dim; ++d) a[off + n * dim + d] = bc.scale * bc.values[d];
          else
            for (PetscInt d : bc.comps) a[off + n * dim + d] = bc.scale * bc.values[d];
      }
      PetscCall(DMPlexRestoreTransitiveClosure(dm, pi[q], PETSC_TRUE, &ncl, &cl));
    }
    PetscCall(ISRestoreIndices(pts, &pi));
    PetscCall(ISDestroy(&pts));
  }
  PetscCall(VecRestoreArray(uloc, &a));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::Energy(Vec u, PetscReal *energy) const
{
  PetscDS     ds;
  PetscScalar integral[1] = {0};

  PetscFunctionBeginUser;
  if (elementAssembly_) {
    Vec uloc;
    PetscCall(EnsureElements());
    PetscCall(DMGetLocalVector(dm, &uloc));
    PetscCall(GlobalToLocalWithBC(u, uloc));
    PetscCall(elem_.Energy(ElementCoefficients(), uloc, energy));
    PetscCall(DMRestoreLocalVector(dm, &uloc));
    PetscFunctionReturn(0);
  }
  PetscCall(DMGetDS(dm, &ds));
  PetscCall(PetscDSSetObjective(ds, 0, obj_energy));
  PetscCall(DMPlexComputeIntegralFEM(dm, u, integral, NULL));
  *energy = PetscRealPart(integral[0]);
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::VonMises(Vec u, Vec *vm) const
{
  PetscDS  ds;
  PetscInt cStart, cEnd;

  PetscFunctionBeginUser;
  PetscCall(DMCreateGlobalVector(dmCell, vm));
  PetscCall(PetscObjectSetName((PetscObject)*vm, "von_mises"));
  if (elementAssembly_) {
    // the same quadrature mean from the element tables: PETSc's cellwise integral cost 160 us a cell on
    // P1 tetrahedra (12 of the 27 s of a hertz3d FOM, 2026-11-26; docs/fom_speed.md)
    Vec                    uloc;
    PetscSection           s;
    PetscInt               rstart;
    PetscScalar           *arr;
    std::vector<PetscReal> cellVm;
    PetscCall(EnsureElements());
    PetscCall(DMGetLocalVector(dm, &uloc));
    PetscCall(GlobalToLocalWithBC(u, uloc));
    PetscCall(elem_.VonMises(ElementCoefficients(), uloc, &cellVm));
    PetscCall(DMRestoreLocalVector(dm, &uloc));
    PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
    PetscCall(DMGetGlobalSection(dmCell, &s));
    PetscCall(VecGetOwnershipRange(*vm, &rstart, NULL));
    PetscCall(VecGetArray(*vm, &arr));
    for (PetscInt c = cStart; c < cEnd; ++c) {
      PetscInt off;
      PetscCall(PetscSectionGetOffset(s, c, &off));
      if (off >= 0) arr[off - rstart] = cellVm[c - cStart];
    }
    PetscCall(VecRestoreArray(*vm, &arr));
    PetscFunctionReturn(0);
  }
  PetscCall(DMGetDS(dm, &ds));
  PetscCall(PetscDSSetObjective(ds, 0, obj_von_mises));
  PetscCall(DMPlexComputeCellwiseIntegralFEM(dm, u, *vm, NULL));
  // integral over the cell -> cell mean
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  PetscScalar *arr;
  PetscCall(VecGetArray(*vm, &arr));
  for (PetscInt c = cStart; c < cEnd; ++c) {
    PetscReal vol;
    PetscInt  off;
    PetscSection s;
    PetscCall(DMGetGlobalSection(dmCell, &s));
    PetscCall(PetscSectionGetOffset(s, c, &off));
    if (off < 0) continue;
    PetscInt rstart;
    PetscCall(VecGetOwnershipRange(*vm, &rstart, NULL));
    PetscCall(DMPlexComputeCellGeometryFVM(dm, c, &vol, NULL, NULL));
    arr[off - rstart] /= vol;
  }
  PetscCall(VecRestoreArray(*vm, &arr));
  PetscFunctionReturn(0);
}

PetscErrorCode NodalRigidBodyModes(DM dm, MatNullSpace *nsp)
{
  MPI_Comm           comm = PetscObjectComm((PetscObject)dm);
  PetscSection       ls, cs;
  Vec                cloc, loc[6], glob[6];
  const PetscScalar *ca;
  PetscInt           dim, Nc, pStart, pEnd, vStart, vEnd;
  PetscBool          supported = PETSC_TRUE;

  PetscFunctionBeginUser;
  *nsp = nullptr;
  PetscCall(DMGetDimension(dm, &dim));
  PetscCall(DMGetLocalSection(dm, &ls));
  PetscCall(PetscSectionGetFieldComponents(ls, 0, &Nc));
  const PetscInt nm = dim == 2 ? 3 : 6;
  if (Nc != dim || (dim != 2 && dim != 3)) PetscFunctionReturn(0);
  PetscCall(PetscSectionGetChart(ls, &pStart, &pEnd));
  PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
  PetscCall(DMGetCoordinatesLocal(dm, &cloc));
  PetscCall(DMGetCoordinateSection(dm, &cs));
  PetscCall(VecGetArrayRead(cloc, &ca));
  std::vector<PetscScalar *> la(nm);
  for (PetscInt m = 0; m < nm; ++m) {
    PetscCall(DMGetLocalVector(dm, &loc[m]));
    PetscCall(VecSet(loc[m], 0.0));
    PetscCall(VecGetArray(loc[m], &la[m]));
  }
  for (PetscInt p = pStart; p < pEnd && supported; ++p) {
    PetscInt ndof, off, nclos, *clos = nullptr, nv = 0;
    PetscReal x[3] = {0, 0, 0};
    PetscCall(PetscSectionGetDof(ls, p, &ndof));
    if (!ndof) continue;
    if (ndof != Nc) { supported = PETSC_FALSE; break; } // more than one node on the point (degree > 2): the projection
    PetscCall(PetscSectionGetOffset(ls, p, &off));
    // the node: the vertex, or the centroid of the point's vertices (the midpoint of a P2 edge)
    PetscCall(DMPlexGetTransitiveClosure(dm, p, PETSC_TRUE, &nclos, &clos));
    for (PetscInt k = 0; k < nclos; ++k) {
      const PetscInt q = clos[2 * k];
      if (q < vStart || q >= vEnd) continue;
      PetscInt coff, cdof;
      PetscCall(PetscSectionGetDof(cs, q, &cdof));
      PetscCall(PetscSectionGetOffset(cs, q, &coff));
      if (cdof != dim) continue;
      for (PetscInt d = 0; d < dim; ++d) x[d] += PetscRealPart(ca[coff + d]);
      ++nv;
    }
    PetscCall(DMPlexRestoreTransitiveClosure(dm, p, PETSC_TRUE, &nclos, &clos));
    if (!nv) { supported = PETSC_FALSE; break; }
    for (PetscInt d = 0; d < dim; ++d) x[d] /= nv;
    for (PetscInt d = 0; d < dim; ++d) la[d][off + d] = 1.0; // translations
    if (dim == 2) {
      la[2][off] = -x[1];
      la[2][off + 1] = x[0];
    } else { // rotations about z, x, y
      la[3][off] = -x[1]; la[3][off + 1] = x[0];
      la[4][off + 1] = -x[2]; la[4][off + 2] = x[1];
      la[5][off] = x[2]; la[5][off + 2] = -x[0];
    }
  }
  PetscCall(VecRestoreArrayRead(cloc, &ca));
  for (PetscInt m = 0; m < nm; ++m) PetscCall(VecRestoreArray(loc[m], &la[m]));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &supported, 1, MPIU_BOOL, MPI_LAND, comm));
  if (supported) {
    // the free dofs (DMLocalToGlobal drops the constrained ones, as DMProjectFunction does), orthonormalized
    for (PetscInt m = 0; m < nm; ++m) {
      PetscReal nrm;
      PetscCall(DMCreateGlobalVector(dm, &glob[m]));
      PetscCall(DMLocalToGlobal(dm, loc[m], INSERT_VALUES, glob[m]));
      for (PetscInt j = 0; j < m; ++j) {
        PetscScalar dot;
        PetscCall(VecDot(glob[m], glob[j], &dot));
        PetscCall(VecAXPY(glob[m], -dot, glob[j]));
      }
      PetscCall(VecNormalize(glob[m], &nrm));
      PetscCheck(nrm > 0, comm, PETSC_ERR_PLIB, "Rigid-body mode %" PetscInt_FMT " vanishes on the free dofs", m);
    }
    PetscCall(MatNullSpaceCreate(comm, PETSC_FALSE, nm, glob, nsp));
    for (PetscInt m = 0; m < nm; ++m) PetscCall(VecDestroy(&glob[m]));
  }
  for (PetscInt m = 0; m < nm; ++m) PetscCall(DMRestoreLocalVector(dm, &loc[m]));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::NearNullSpace(MatNullSpace *nsp) const
{
  static PetscLogEvent event = 0;

  PetscFunctionBeginUser;
  if (!nearNull_) {
    // the modes at the nodes (vertices, P2 edge midpoints); DMPlexCreateRigidBody (a projection through every
    // cell's FE geometry, 40 % of a hertz3d FOM when done twice per parameter; measured 2026-11-26) otherwise
    if (!event) PetscCall(PetscLogEventRegister("RBCNearNullSpace", DM_CLASSID, &event));
    PetscCall(PetscLogEventBegin(event, 0, 0, 0, 0));
    PetscCall(NodalRigidBodyModes(dm, &nearNull_));
    if (!nearNull_) PetscCall(DMPlexCreateRigidBody(dm, 0, &nearNull_));
    PetscCall(PetscLogEventEnd(event, 0, 0, 0, 0));
  }
  PetscCall(PetscObjectReference((PetscObject)nearNull_));
  *nsp = nearNull_;
  PetscFunctionReturn(0);
}

} // namespace rbc
