// src/fem/elasticity.cpp: PetscFE elasticity with per-cell Lamé coefficients (auxiliary P0 field),
// constant body force / tractions from the scene, essential boundary values by lifting.
#include "rbcontact/elasticity.hpp"
#include "rbcontact/mesh.hpp"
#include <cmath>

namespace rbc {

#define RBC_POINTWISE_ARGS \
  PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, const PetscReal x[], PetscInt numConstants, const PetscScalar constants[]

// Constants layout: [0, 3) body force; [3 + 3k, 6 + 3k) traction of natural boundary k.
static const PetscInt kMaxTractions = 8;

static void f0_body_force(RBC_POINTWISE_ARGS, PetscScalar f0[])
{
  for (PetscInt d = 0; d < dim; ++d) f0[d] = -constants[d];
}

// sigma(u) = L tr(eps) I + 2 G eps, aux a = (L, G)
static void f1_stress(RBC_POINTWISE_ARGS, PetscScalar f1[])
{
  const PetscScalar L = a[0], G = a[1];
  PetscScalar       tr = 0;
  for (PetscInt d = 0; d < dim; ++d) tr += u_x[d * dim + d];
  for (PetscInt c = 0; c < dim; ++c) {
    for (PetscInt d = 0; d < dim; ++d) f1[c * dim + d] = G * (u_x[c * dim + d] + u_x[d * dim + c]);
    f1[c * dim + c] += L * tr;
  }
}

static void g3_stiffness(PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, PetscReal u_tShift, const PetscReal x[], PetscInt numConstants, const PetscScalar constants[], PetscScalar g3[])
{
  const PetscScalar L = a[0], G = a[1];
  for (PetscInt c = 0; c < dim; ++c) {
    for (PetscInt d = 0; d < dim; ++d) {
      g3[((c * dim + c) * dim + d) * dim + d] += G;
      g3[((c * dim + d) * dim + d) * dim + c] += G;
      g3[((c * dim + d) * dim + c) * dim + d] += L;
    }
  }
}

static void EnergyDensity(PetscInt dim, const PetscScalar u_x[], const PetscScalar a[], PetscScalar *w)
{
  const PetscScalar L = a[0], G = a[1];
  PetscScalar       tr = 0, ee = 0;
  for (PetscInt d = 0; d < dim; ++d) tr += u_x[d * dim + d];
  for (PetscInt c = 0; c < dim; ++c)
    for (PetscInt d = 0; d < dim; ++d) {
      const PetscScalar e = 0.5 * (u_x[c * dim + d] + u_x[d * dim + c]);
      ee += e * e;
    }
  *w = 0.5 * L * tr * tr + G * ee;
}

static void obj_energy(RBC_POINTWISE_ARGS, PetscScalar obj[]) { EnergyDensity(dim, u_x, a, &obj[0]); }

static void obj_von_mises(RBC_POINTWISE_ARGS, PetscScalar obj[])
{
  const PetscScalar L = a[0], G = a[1];
  PetscScalar       s[3][3] = {{0}}, tr = 0;
  for (PetscInt d = 0; d < dim; ++d) tr += u_x[d * dim + d];
  for (PetscInt c = 0; c < dim; ++c)
    for (PetscInt d = 0; d < dim; ++d) s[c][d] = G * (u_x[c * dim + d] + u_x[d * dim + c]) + (c == d ? L * tr : 0);
  if (dim == 2) s[2][2] = L * tr; // plane strain
  const PetscScalar j2 = 0.5 * ((s[0][0] - s[1][1]) * (s[0][0] - s[1][1]) + (s[1][1] - s[2][2]) * (s[1][1] - s[2][2]) + (s[2][2] - s[0][0]) * (s[2][2] - s[0][0])) + 3 * (s[0][1] * s[0][1] + s[1][2] * s[1][2] + s[0][2] * s[0][2]);
  obj[0] = PetscSqrtReal(PetscRealPart(j2));
}

template <int K>
static void f0_traction(PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, const PetscReal x[], const PetscReal n[], PetscInt numConstants, const PetscScalar constants[], PetscScalar f0[])
{
  for (PetscInt d = 0; d < dim; ++d) f0[d] = -constants[3 + 3 * K + d];
}

using BdF = void (*)(PetscInt, PetscInt, PetscInt, const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], const PetscInt[], const PetscInt[], const PetscScalar[], const PetscScalar[], const PetscScalar[], PetscReal, const PetscReal[], const PetscReal[], PetscInt, const PetscScalar[], PetscScalar[]);
static const BdF kTractionFns[kMaxTractions] = {f0_traction<0>, f0_traction<1>, f0_traction<2>, f0_traction<3>, f0_traction<4>, f0_traction<5>, f0_traction<6>, f0_traction<7>};

static PetscErrorCode ConstantBC(PetscInt dim, PetscReal t, const PetscReal x[], PetscInt Nc, PetscScalar *u, void *ctx)
{
  const DirichletSpec *bc = static_cast<const DirichletSpec *>(ctx);
  for (PetscInt c = 0; c < Nc; ++c) u[c] = c < (PetscInt)bc->values.size() ? bc->values[c] : 0.0;
  return 0;
}

Elasticity::~Elasticity()
{
  (void)SNESDestroy(&snes_);
  (void)VecDestroy(&aux_);
  (void)DMDestroy(&dmAux_);
  (void)DMDestroy(&dmCell);
  (void)DMDestroy(&dm);
}

PetscErrorCode Elasticity::SetupMaterials(const SceneSpec &scene)
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
  PetscCall(PetscFECreateLagrange(PETSC_COMM_SELF, dim, 2, PETSC_TRUE, 0, PETSC_DETERMINE, &feAux));
  PetscCall(PetscFECopyQuadrature(fe, feAux));
  PetscCall(DMSetField(dmAux_, 0, NULL, (PetscObject)feAux));
  PetscCall(DMCreateDS(dmAux_));
  PetscCall(PetscFEDestroy(&feAux));
  PetscCall(DMCreateLocalVector(dmAux_, &aux_));
  {
    PetscScalar *arr;
    PetscCall(VecGetArray(aux_, &arr));
    for (PetscInt c = cStart; c < cEnd; ++c) {
      PetscScalar   *p;
      const BodySpec &body = scene.bodies[cellBody_[c - cStart]];
      PetscReal      L, G;
      LameFromYoung(body.E, body.nu, &L, &G);
      PetscCall(DMPlexPointLocalRef(dmAux_, c, arr, &p));
      p[0] = L;
      p[1] = G;
    }
    PetscCall(VecRestoreArray(aux_, &arr));
  }
  PetscCall(DMSetAuxiliaryVec(dm, NULL, 0, 0, aux_));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::Setup(DM dmIn, const SceneSpec &scene)
{
  PetscFE  fe;
  PetscDS  ds;
  PetscInt cStart;
  MPI_Comm comm = PetscObjectComm((PetscObject)dmIn);

  PetscFunctionBeginUser;
  dm = dmIn;
  PetscCall(PetscObjectReference((PetscObject)dm));
  PetscCall(DMGetDimension(dm, &dim));
  degree = scene.degree;
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, NULL));
  {
    DMPolytopeType ct;
    PetscInt       cEnd;
    PetscCall(DMPlexGetHeightStratum(dm, 0, NULL, &cEnd));
    ct = DM_POLYTOPE_TRIANGLE;
    if (cEnd > cStart) PetscCall(DMPlexGetCellType(dm, cStart, &ct));
    PetscCheck(ct == DM_POLYTOPE_TRIANGLE || ct == DM_POLYTOPE_TETRAHEDRON, comm, PETSC_ERR_SUP, "Mesh '%s': only simplex cells (triangles, tetrahedra) are supported", scene.mesh.file.c_str());
  }
  PetscCall(PetscFECreateLagrange(comm, dim, dim, PETSC_TRUE, degree, PETSC_DETERMINE, &fe));
  PetscCall(PetscObjectSetName((PetscObject)fe, "displacement"));
  PetscCall(DMSetField(dm, 0, NULL, (PetscObject)fe));
  PetscCall(DMCreateDS(dm));
  PetscCall(PetscFEDestroy(&fe));
  PetscCall(DMGetDS(dm, &ds));
  PetscCall(PetscDSSetResidual(ds, 0, (scene.bodyForceF0 ? scene.bodyForceF0 : (!scene.bodyForce.empty() ? f0_body_force : NULL)), f1_stress));
  PetscCall(PetscDSSetJacobian(ds, 0, 0, NULL, NULL, NULL, g3_stiffness));

  // Constants: body force and tractions
  PetscCheck((PetscInt)scene.tractions.size() <= kMaxTractions, comm, PETSC_ERR_SUP, "-bc_traction: at most %" PetscInt_FMT " traction boundaries", kMaxTractions);
  std::vector<PetscScalar> constants(3 + 3 * kMaxTractions, 0.0);
  PetscCheck(scene.bodyForce.empty() || (PetscInt)scene.bodyForce.size() == dim, comm, PETSC_ERR_USER_INPUT, "-body_force has %zu components, the mesh is %" PetscInt_FMT "D", scene.bodyForce.size(), dim);
  for (size_t d = 0; d < scene.bodyForce.size(); ++d) constants[d] = scene.bodyForce[d];
  for (size_t k = 0; k < scene.tractions.size(); ++k) {
    const TractionSpec &tr = scene.tractions[k];
    PetscCheck((PetscInt)tr.traction.size() == dim, comm, PETSC_ERR_USER_INPUT, "-bc_%s_t has %zu components, the mesh is %" PetscInt_FMT "D", tr.label.c_str(), tr.traction.size(), dim);
    for (PetscInt d = 0; d < dim; ++d) constants[3 + 3 * k + d] = tr.traction[d];
    DMLabel       label;
    PetscInt      bd;
    PetscWeakForm wf;
    IS            valueIS;
    PetscInt      nv = 0;
    const PetscInt *vals = NULL;
    PetscCall(DMGetLabel(dm, tr.label.c_str(), &label));
    PetscCall(MeshCheckLabel(dm, tr.label, "-bc_traction", scene.mesh.file));
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
  for (auto &bc : bcs_) {
    DMLabel label;
    PetscCall(MeshCheckLabel(dm, bc.label, "-bc_dirichlet", scene.mesh.file));
    PetscCall(DMGetLabel(dm, bc.label.c_str(), &label));
    if (!bc.fn) PetscCheck((PetscInt)bc.values.size() == dim, comm, PETSC_ERR_USER_INPUT, "-bc_%s_u has %zu components, the mesh is %" PetscInt_FMT "D (give all components; -bc_%s_comps selects the constrained ones)", bc.label.c_str(), bc.values.size(), dim, bc.label.c_str());
    for (PetscInt c : bc.comps) PetscCheck(c < dim, comm, PETSC_ERR_ARG_OUTOFRANGE, "-bc_%s_comps: component %" PetscInt_FMT " >= dimension %" PetscInt_FMT, bc.label.c_str(), c, dim);
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
    PetscCall(DMAddBoundary(dm, DM_BC_ESSENTIAL, bc.label.c_str(), label, 1, &v, 0, (PetscInt)bc.comps.size(), bc.comps.empty() ? NULL : bc.comps.data(), (void (*)(void))(bc.fn ? bc.fn : ConstantBC), NULL, bc.fn ? bc.fnCtx : (void *)&bc, NULL));
  }
  PetscCall(SetupMaterials(scene));

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

PetscErrorCode Elasticity::Assemble(Mat *A, Vec *f)
{
  Vec zero;

  PetscFunctionBeginUser;
  if (!*A) {
    PetscCall(DMCreateMatrix(dm, A));
    PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(*A, MAT_SPD, PETSC_TRUE));
  }
  if (!*f) PetscCall(DMCreateGlobalVector(dm, f));
  PetscCall(DMGetGlobalVector(dm, &zero));
  PetscCall(VecSet(zero, 0.0));
  PetscCall(SNESComputeJacobian(snes_, zero, *A, *A));
  PetscCall(SNESComputeFunction(snes_, zero, *f)); // F(0) = -(loads) + A_{fc} u_D
  PetscCall(VecScale(*f, -1.0));
  PetscCall(DMRestoreGlobalVector(dm, &zero));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::GlobalToLocalWithBC(Vec u, Vec uloc) const
{
  PetscFunctionBeginUser;
  PetscCall(VecSet(uloc, 0.0));
  PetscCall(DMGlobalToLocal(dm, u, INSERT_VALUES, uloc));
  PetscCall(DMPlexInsertBoundaryValues(dm, PETSC_TRUE, uloc, 0.0, NULL, NULL, NULL));
  PetscFunctionReturn(0);
}

PetscErrorCode Elasticity::Energy(Vec u, PetscReal *energy) const
{
  PetscDS     ds;
  PetscScalar integral[1] = {0};

  PetscFunctionBeginUser;
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
  PetscCall(DMGetDS(dm, &ds));
  PetscCall(PetscDSSetObjective(ds, 0, obj_von_mises));
  PetscCall(DMCreateGlobalVector(dmCell, vm));
  PetscCall(PetscObjectSetName((PetscObject)*vm, "von_mises"));
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

PetscErrorCode Elasticity::NearNullSpace(MatNullSpace *nsp) const
{
  PetscFunctionBeginUser;
  PetscCall(DMPlexCreateRigidBody(dm, 0, nsp));
  PetscFunctionReturn(0);
}

} // namespace rbc
