// tests/test_two_bodies.cpp -- owns the test that two disconnected bodies in one DMPlex are two
// independent elastic problems: meshes/flat_punch.geo (punch on base, touching along y = 0 with
// separate nodes; no contact) is solved as one two-body scene with different E, nu per body,
// imposed displacement, tractions and a body force. Then, for each body, a genuinely separate
// one-body DMPlex is cut out of the same mesh with DMPlexFilter (cell label of the body; labels
// of the body's boundaries transferred through the subpoint map) and solved with that body's data
// only. Checks, for P1 and P2:
//   * the one-body mesh has exactly the body's vertices (coordinates matched one to one);
//   * the two-body solution equals the one-body solution at every vertex of the body to 1e-10
//     (relative to the body's max |u|, max norm);
//   * the two-body energy equals the sum of the one-body energies to 1e-10 (relative);
//   * each body is loaded (max |u| > 1e-4, energy > 0).
// Prints a table; exits 1 on failure.
#include "rbcontact/fom.hpp"
#include "rbcontact/mesh.hpp"

#include <petscsf.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace {

struct BodyData {
  std::string              name;
  PetscReal                E, nu;
  std::vector<std::string> dirichlet;                                     // labels of this body
  std::vector<std::vector<PetscReal>> dirichletU;
  std::vector<std::pair<std::string, std::vector<PetscReal>>> tractions;  // labels of this body
};

// Body data: the punch pushed down and sideways at its top with a lateral traction on its right
// side; the base clamped at its bottom, with a traction on its top ("master"). Body force on both.
const std::vector<BodyData> kBodies = {
  {"punch", 100.0, 0.30, {"punch_top"}, {{0.02, -0.05}}, {{"punch_right", {-1.5, 0.5}}}},
  {"base", 7.0, 0.20, {"base_bottom"}, {{0.0, 0.0}}, {{"master", {0.5, -2.0}}}},
};
const std::vector<PetscReal> kBodyForce = {0.3, -1.0};

rbc::SceneSpec MakeScene(const std::vector<BodyData> &bodies, PetscInt degree)
{
  rbc::SceneSpec sc;
  sc.name           = "two_bodies";
  sc.mesh.file      = "meshes/flat_punch.geo";
  const char *cache = std::getenv("RBC_MESH_CACHE");
  sc.mesh.cacheDir  = cache ? cache : "meshcache";
  sc.degree         = degree;
  sc.bodyForce      = kBodyForce;
  for (const auto &b : bodies) {
    sc.bodies.push_back({b.name, b.E, b.nu});
    for (size_t i = 0; i < b.dirichlet.size(); ++i) {
      rbc::DirichletSpec bc;
      bc.label  = b.dirichlet[i];
      bc.values = b.dirichletU[i];
      sc.dirichlet.push_back(bc);
    }
    for (const auto &t : b.tractions) sc.tractions.push_back({t.first, t.second});
  }
  return sc;
}

// The value of a label (gmsh physical tag), the same on all ranks.
PetscErrorCode LabelValue(DM dm, const char *name, PetscInt *value)
{
  DMLabel         label;
  IS              is;
  PetscInt        n;
  const PetscInt *vals;

  PetscFunctionBeginUser;
  PetscCall(DMGetLabel(dm, name, &label));
  PetscCheck(label, PetscObjectComm((PetscObject)dm), PETSC_ERR_ARG_WRONG, "no label %s", name);
  PetscCall(DMLabelGetValueIS(label, &is));
  PetscCall(ISGetLocalSize(is, &n));
  PetscCall(ISGetIndices(is, &vals));
  *value = n ? vals[0] : -1;
  PetscCall(ISRestoreIndices(is, &vals));
  PetscCall(ISDestroy(&is));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, value, 1, MPIU_INT, MPI_MAX, PetscObjectComm((PetscObject)dm)));
  PetscFunctionReturn(0);
}

// Gives the submesh the label `name` of the parent mesh through the subpoint map (unless
// DMPlexFilter already carried it over).
PetscErrorCode TransferLabel(DM dm, DM sub, const std::string &name)
{
  DMLabel         label, subLabel;
  PetscBool       has;
  IS              spIS;
  const PetscInt *sp;
  PetscInt        pStart, pEnd;

  PetscFunctionBeginUser;
  PetscCall(DMHasLabel(sub, name.c_str(), &has));
  if (has) PetscFunctionReturn(0);
  PetscCall(DMGetLabel(dm, name.c_str(), &label));
  PetscCall(DMCreateLabel(sub, name.c_str()));
  PetscCall(DMGetLabel(sub, name.c_str(), &subLabel));
  PetscCall(DMPlexGetSubpointIS(sub, &spIS));
  PetscCall(DMPlexGetChart(sub, &pStart, &pEnd));
  if (pEnd > pStart) {
    PetscCall(ISGetIndices(spIS, &sp));
    for (PetscInt p = pStart; p < pEnd; ++p) {
      PetscInt v;
      PetscCall(DMLabelGetValue(label, sp[p - pStart], &v));
      if (v >= 0) PetscCall(DMLabelSetValue(subLabel, p, v));
    }
    PetscCall(ISRestoreIndices(spIS, &sp));
  }
  PetscFunctionReturn(0);
}

// Owned vertices of the cells whose body index is `body` (all cells if body < 0): coordinates
// and the vertex dofs of the full solution field (Dirichlet values included), gathered on rank 0
// as rows (x_0..x_{dim-1}, u_0..u_{dim-1}).
PetscErrorCode GatherVertexValues(rbc::ElasticFOM &fom, PetscInt body, std::vector<PetscReal> *rows)
{
  DM                 dm = fom.dm, cdm;
  MPI_Comm           comm = PetscObjectComm((PetscObject)dm);
  PetscInt           dim = fom.elas.dim, cStart, cEnd, vStart, vEnd, nleaves;
  PetscSF            sf;
  const PetscInt    *leaves;
  Vec                uloc, coords;
  const PetscScalar *ua, *ca;
  PetscMPIInt        rank, size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
  std::vector<char> mark(vEnd - vStart, 0);
  for (PetscInt c = cStart; c < cEnd; ++c) {
    if (body >= 0 && fom.elas.CellBody()[c - cStart] != body) continue;
    PetscInt *cl = NULL, ncl;
    PetscCall(DMPlexGetTransitiveClosure(dm, c, PETSC_TRUE, &ncl, &cl));
    for (PetscInt i = 0; i < 2 * ncl; i += 2)
      if (cl[i] >= vStart && cl[i] < vEnd) mark[cl[i] - vStart] = 1;
    PetscCall(DMPlexRestoreTransitiveClosure(dm, c, PETSC_TRUE, &ncl, &cl));
  }
  PetscCall(DMGetPointSF(dm, &sf));
  PetscCall(PetscSFGetGraph(sf, NULL, &nleaves, &leaves, NULL));
  for (PetscInt l = 0; l < PetscMax(nleaves, 0); ++l) {
    const PetscInt p = leaves ? leaves[l] : l;
    if (p >= vStart && p < vEnd) mark[p - vStart] = 0; // ghost: its owner reports it
  }
  PetscCall(DMGetLocalVector(dm, &uloc));
  PetscCall(fom.elas.GlobalToLocalWithBC(fom.u, uloc));
  PetscCall(DMGetCoordinatesLocal(dm, &coords));
  PetscCall(DMGetCoordinateDM(dm, &cdm));
  PetscCall(VecGetArrayRead(uloc, &ua));
  PetscCall(VecGetArrayRead(coords, &ca));
  std::vector<PetscReal> mine;
  for (PetscInt v = vStart; v < vEnd; ++v) {
    if (!mark[v - vStart]) continue;
    const PetscScalar *x, *u;
    PetscCall(DMPlexPointLocalRead(cdm, v, ca, &x));
    PetscCall(DMPlexPointLocalRead(dm, v, ua, &u));
    for (PetscInt d = 0; d < dim; ++d) mine.push_back(PetscRealPart(x[d]));
    for (PetscInt d = 0; d < dim; ++d) mine.push_back(PetscRealPart(u[d]));
  }
  PetscCall(VecRestoreArrayRead(coords, &ca));
  PetscCall(VecRestoreArrayRead(uloc, &ua));
  PetscCall(DMRestoreLocalVector(dm, &uloc));
  int              n = (int)mine.size();
  std::vector<int> counts(size), displs(size);
  PetscCallMPI(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm));
  int total = 0;
  for (int r = 0; r < size; ++r) {
    displs[r] = total;
    total += counts[r];
  }
  rows->assign(rank == 0 ? total : 0, 0.0);
  PetscCallMPI(MPI_Gatherv(mine.data(), n, MPIU_REAL, rows->data(), counts.data(), displs.data(), MPIU_REAL, 0, comm));
  PetscFunctionReturn(0);
}


PetscErrorCode RunDegree(MPI_Comm comm, PetscInt degree, bool *ok)
{
  PetscMPIInt rank;
  PetscReal   energyTwo;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  const rbc::SceneSpec scTwo = MakeScene(kBodies, degree);
  rbc::ElasticFOM      two;
  PetscCall(two.Create(comm, scTwo));
  PetscCall(two.AssembleAndFactor());
  PetscCall(two.SolveElastic());
  PetscCall(two.elas.Energy(two.u, &energyTwo));
  const PetscInt dim = two.elas.dim;

  PetscCall(PetscPrintf(comm, "P%" PetscInt_FMT ": two-body scene %s, %" PetscInt_FMT " dofs, energy %.12e\n", degree, scTwo.mesh.file.c_str(), two.GlobalSize(), (double)energyTwo));
  PetscCall(PetscPrintf(comm, "  %-6s %6s %5s %9s %9s %12s %12s %11s %11s\n", "body", "E", "nu", "vertices", "dofs(1b)", "max|u|", "max|du|", "rel diff", "energy(1b)"));
  PetscReal energySum = 0;
  for (size_t b = 0; b < kBodies.size(); ++b) {
    const BodyData &body = kBodies[b];
    // One-body mesh: DMPlexFilter of the two-body (distributed) mesh by the body's cell label.
    DMLabel  cellLabel;
    PetscInt value;
    DM       sub;
    PetscCall(LabelValue(two.dm, body.name.c_str(), &value));
    PetscCall(DMGetLabel(two.dm, body.name.c_str(), &cellLabel));
    PetscCall(DMPlexFilter(two.dm, cellLabel, value, &sub));
    PetscCall(PetscObjectSetName((PetscObject)sub, body.name.c_str()));
    std::vector<std::string> labels = {body.name};
    for (const auto &l : body.dirichlet) labels.push_back(l);
    for (const auto &t : body.tractions) labels.push_back(t.first);
    for (const auto &l : labels) PetscCall(TransferLabel(two.dm, sub, l));
    rbc::SceneSpec scOne = MakeScene({body}, degree);
    scOne.name           = "one_body_" + body.name;
    rbc::ElasticFOM one;
    PetscCall(one.CreateOnDM(sub, scOne));
    PetscCall(DMDestroy(&sub));
    PetscCall(one.AssembleAndFactor());
    PetscCall(one.SolveElastic());
    PetscReal energyOne;
    PetscCall(one.elas.Energy(one.u, &energyOne));
    energySum += energyOne;

    std::vector<PetscReal> rowsTwo, rowsOne;
    PetscCall(GatherVertexValues(two, (PetscInt)b, &rowsTwo));
    PetscCall(GatherVertexValues(one, -1, &rowsOne));
    // Rank 0: match vertices by coordinates (bit-identical: the submesh copies them).
    int       good = 1;
    PetscReal umax = 0, dmax = 0;
    long long nv = 0;
    char      why[512] = "";
    if (rank == 0) {
      const size_t                                 w = 2 * dim;
      std::map<std::vector<PetscReal>, size_t>     index;
      for (size_t i = 0; i < rowsOne.size() / w; ++i) index[std::vector<PetscReal>(rowsOne.begin() + i * w, rowsOne.begin() + i * w + dim)] = i;
      nv = (long long)(rowsTwo.size() / w);
      if (index.size() != rowsOne.size() / w || rowsOne.size() != rowsTwo.size()) {
        good = 0;
        std::snprintf(why, sizeof why, "vertex sets differ: two-body mesh has %zu vertices in body %s, the one-body mesh %zu (%zu distinct)", rowsTwo.size() / w, body.name.c_str(), rowsOne.size() / w, index.size());
      }
      for (size_t i = 0; good && i < rowsTwo.size() / w; ++i) {
        auto it = index.find(std::vector<PetscReal>(rowsTwo.begin() + i * w, rowsTwo.begin() + i * w + dim));
        if (it == index.end()) {
          good = 0;
          std::snprintf(why, sizeof why, "vertex (%g, %g) of body %s has no match in the one-body mesh", (double)rowsTwo[i * w], (double)rowsTwo[i * w + 1], body.name.c_str());
          break;
        }
        for (PetscInt d = 0; d < dim; ++d) {
          const PetscReal u1 = rowsOne[it->second * w + dim + d], u2 = rowsTwo[i * w + dim + d];
          umax               = PetscMax(umax, PetscAbsReal(u1));
          dmax               = PetscMax(dmax, std::isfinite(u2) ? PetscAbsReal(u2 - u1) : PETSC_MAX_REAL);
        }
      }
    }
    PetscCallMPI(MPI_Bcast(&good, 1, MPI_INT, 0, comm));
    PetscCallMPI(MPI_Bcast(&umax, 1, MPIU_REAL, 0, comm));
    PetscCallMPI(MPI_Bcast(&dmax, 1, MPIU_REAL, 0, comm));
    PetscCallMPI(MPI_Bcast(&nv, 1, MPI_LONG_LONG, 0, comm));
    PetscCallMPI(MPI_Bcast(why, sizeof why, MPI_CHAR, 0, comm));
    const PetscReal rel = umax > 0 ? dmax / umax : PETSC_MAX_REAL;
    PetscCall(PetscPrintf(comm, "  %-6s %6g %5g %9lld %9" PetscInt_FMT " %12.5e %12.5e %11.3e %11.5e\n", body.name.c_str(), (double)body.E, (double)body.nu, nv, one.GlobalSize(), (double)umax, (double)dmax, (double)rel, (double)energyOne));
    if (!good) {
      *ok = false;
      PetscCall(PetscPrintf(comm, "  FAILED: %s\n", why));
    } else if (!(rel <= 1e-10)) {
      *ok = false;
      PetscCall(PetscPrintf(comm, "  FAILED: body %s: two-body and one-body solutions differ by %.3e (relative, max norm) > 1e-10\n", body.name.c_str(), (double)rel));
    }
    if (!(umax > 1e-4) || !(energyOne > 0)) {
      *ok = false;
      PetscCall(PetscPrintf(comm, "  FAILED: body %s is not loaded (max|u| %g, energy %g)\n", body.name.c_str(), (double)umax, (double)energyOne));
    }
  }
  const PetscReal erel = PetscAbsReal(energyTwo - energySum) / PetscAbsReal(energySum);
  PetscCall(PetscPrintf(comm, "  energy: two-body %.12e, sum of one-body %.12e, rel diff %.3e (tol 1e-10)\n", (double)energyTwo, (double)energySum, (double)erel));
  if (!(erel <= 1e-10)) {
    *ok = false;
    PetscCall(PetscPrintf(comm, "  FAILED: two-body energy differs from the sum of the one-body energies\n"));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode Run(MPI_Comm comm, bool *ok)
{
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscPrintf(comm, "test_two_bodies: %d rank(s)\n", size));
  *ok = true;
  for (PetscInt degree : {1, 2}) PetscCall(RunDegree(comm, degree, ok));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  bool ok = false;

  PetscCall(PetscInitialize(&argc, &argv, NULL, "two disconnected bodies vs one-body solves\n"));
  PetscCall(Run(PETSC_COMM_WORLD, &ok));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_two_bodies: %s\n", ok ? "all checks passed" : "FAILED"));
  PetscCall(PetscFinalize());
  return ok ? 0 : 1;
}
