// tests/test_vonmises.cpp -- owns the uniform-strain patch test of the elastic FOM's von Mises
// stress (rbc::Elasticity::VonMises) and of its HDF5/XDMF output (rbc::ElasticFOM::WriteOutput).
// An affine displacement u = B x (B constant, with shear) is imposed on the whole boundary; the
// discrete solution reproduces it exactly (P1 and P2), so every cell's von Mises stress must equal
// the analytic value computed here (plane strain in 2D) to 1e-10 relative. The output file of
// each case is then reopened: the .h5 must hold /geometry/vertices, /viz/topology/cells,
// /vertex_fields/displacement_displacement and /cell_fields/von_mises_von_mises with the right
// sizes, the written von Mises values and u = B x at the written vertices, and the .xmf must
// exist and name them.
// Options: -out_dir DIR (where the output files go, default "."). Exits 1 on failure.
#include "rbcontact/fom.hpp"
#include "rbcontact/mesh.hpp"

#include <hdf5.h>
#include <petscsf.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using rbc::GlobalPointCount;

// Displacement gradient B (u = B x): stretches, shear and (3D) out-of-plane terms.
const PetscReal kB[3][3] = {{2.0e-3, 1.5e-3, 0.4e-3}, {-0.5e-3, -1.0e-3, 0.7e-3}, {0.3e-3, -0.6e-3, 0.8e-3}};

PetscErrorCode AffineU(PetscInt dim, PetscReal t, const PetscReal x[], PetscInt Nc, PetscScalar *u, void *ctx)
{
  for (PetscInt c = 0; c < Nc; ++c) {
    u[c] = 0;
    for (PetscInt d = 0; d < dim; ++d) u[c] += kB[c][d] * x[d];
  }
  return 0;
}

// Analytic von Mises stress of u = B x: sigma = L tr(eps) I + 2 G eps (3x3; in 2D plane strain
// eps_zz = 0, so sigma_zz = L tr(eps)), von Mises = sqrt(3/2 dev(sigma) : dev(sigma)).
PetscReal AnalyticVonMises(PetscInt dim, PetscReal E, PetscReal nu)
{
  const PetscReal L = E * nu / ((1 + nu) * (1 - 2 * nu)), G = E / (2 * (1 + nu));
  PetscReal       eps[3][3] = {{0}}, sig[3][3], tr = 0;
  for (PetscInt i = 0; i < dim; ++i)
    for (PetscInt j = 0; j < dim; ++j) eps[i][j] = 0.5 * (kB[i][j] + kB[j][i]);
  for (int i = 0; i < 3; ++i) tr += eps[i][i];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) sig[i][j] = 2 * G * eps[i][j] + (i == j ? L * tr : 0.0);
  const PetscReal p = (sig[0][0] + sig[1][1] + sig[2][2]) / 3;
  PetscReal       dd = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const PetscReal s = sig[i][j] - (i == j ? p : 0.0);
      dd += s * s;
    }
  return std::sqrt(1.5 * dd);
}

struct Case {
  std::string              id, mesh;
  PetscInt                 dim, degree;
  PetscReal                E, nu, clscale;
  std::vector<std::string> boundary;
};

// Rank 0: checks the datasets of the written HDF5 file with the HDF5 C API. Appends failures.
void CheckH5(const std::string &h5, PetscInt dim, PetscInt nverts, PetscInt ncells, PetscReal vmExact, std::vector<std::string> *fails, std::string *summary)
{
  H5E_auto2_t func;
  void       *data;
  H5Eget_auto2(H5E_DEFAULT, &func, &data);
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL); // we report missing datasets ourselves
  hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) {
    fails->push_back("cannot open '" + h5 + "' with HDF5");
    H5Eset_auto2(H5E_DEFAULT, func, data);
    return;
  }
  struct Expect {
    const char *path;
    hsize_t     rows, cols; // cols 0: any (1-D or n x 1)
  };
  const Expect expects[] = {{"/geometry/vertices", (hsize_t)nverts, (hsize_t)dim},
                            {"/viz/topology/cells", (hsize_t)ncells, (hsize_t)(dim + 1)},
                            {"/vertex_fields/displacement_displacement", (hsize_t)nverts, (hsize_t)dim},
                            {"/cell_fields/von_mises_von_mises", (hsize_t)ncells, 0}};
  std::ostringstream sum;
  for (const auto &e : expects) {
    if (H5Lexists(f, e.path, H5P_DEFAULT) <= 0) {
      // H5Lexists needs the intermediate groups: check the group first
      fails->push_back(std::string("dataset ") + e.path + " missing in " + h5);
      continue;
    }
    hid_t d = H5Dopen2(f, e.path, H5P_DEFAULT);
    if (d < 0) {
      fails->push_back(std::string("cannot open dataset ") + e.path);
      continue;
    }
    hid_t   sp = H5Dget_space(d);
    hsize_t dims[4] = {0, 0, 0, 0};
    int     nd      = H5Sget_simple_extent_ndims(sp);
    if (nd > 0 && nd <= 4) H5Sget_simple_extent_dims(sp, dims, NULL);
    const hsize_t rows = nd >= 1 ? dims[0] : 0, cols = nd >= 2 ? dims[1] : 1;
    sum << "    " << e.path << " [" << rows << " x " << cols << "]\n";
    if (rows != e.rows || (e.cols && cols != e.cols) || (!e.cols && cols != 1)) {
      std::ostringstream m;
      m << "dataset " << e.path << " has shape " << rows << " x " << cols << ", expected " << e.rows << " x " << (e.cols ? e.cols : 1);
      fails->push_back(m.str());
    } else if (!e.cols) {
      // the written von Mises values
      std::vector<double> v(rows);
      if (H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0) fails->push_back(std::string("cannot read ") + e.path);
      double worst = 0;
      for (double x : v) worst = std::max(worst, std::fabs(x - vmExact) / vmExact);
      sum << "      max rel. deviation of the written von Mises from the analytic value: " << worst << "\n";
      if (!(worst <= 1e-10)) fails->push_back("written von Mises values deviate from the analytic value (" + std::to_string(worst) + ")");
    }
    H5Sclose(sp);
    H5Dclose(d);
  }
  // The written vertex displacement must be u = B x at the written vertex coordinates.
  if (fails->empty()) {
    std::vector<double> X((size_t)nverts * dim), U((size_t)nverts * dim);
    hid_t dx = H5Dopen2(f, "/geometry/vertices", H5P_DEFAULT), du = H5Dopen2(f, "/vertex_fields/displacement_displacement", H5P_DEFAULT);
    if (H5Dread(dx, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, X.data()) < 0 || H5Dread(du, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, U.data()) < 0) fails->push_back("cannot read the vertices / displacement datasets");
    H5Dclose(dx);
    H5Dclose(du);
    double worst = 0, umax = 0;
    for (PetscInt v = 0; v < nverts; ++v) {
      PetscScalar ue[3];
      AffineU(dim, 0, &X[(size_t)v * dim], dim, ue, NULL);
      for (PetscInt c = 0; c < dim; ++c) {
        worst = std::max(worst, std::fabs(U[(size_t)v * dim + c] - ue[c]));
        umax  = std::max(umax, std::fabs(ue[c]));
      }
    }
    sum << "      max |u_written - B x| / max |B x| over the written vertices: " << worst / umax << "\n";
    if (!(worst <= 1e-10 * umax)) fails->push_back("written displacement differs from the affine solution (" + std::to_string(worst / umax) + ")");
  }
  H5Fclose(f);
  H5Eset_auto2(H5E_DEFAULT, func, data);
  *summary = sum.str();
}

PetscErrorCode RunCase(MPI_Comm comm, const Case &cs, const std::string &outDir, std::vector<std::string> *fails)
{
  PetscMPIInt rank, size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  rbc::SceneSpec sc;
  sc.name           = "vonmises_" + cs.id;
  sc.mesh.file      = cs.mesh;
  sc.mesh.clscale   = cs.clscale;
  const char *cache = std::getenv("RBC_MESH_CACHE");
  sc.mesh.cacheDir  = cache ? cache : "meshcache";
  sc.bodies.push_back({"all", cs.E, cs.nu});
  for (const auto &b : cs.boundary) {
    rbc::DirichletSpec bc;
    bc.label = b;
    bc.fn    = AffineU;
    sc.dirichlet.push_back(bc);
  }
  sc.degree = cs.degree;

  rbc::ElasticFOM fom;
  PetscCall(fom.Create(comm, sc));
  PetscCall(fom.AssembleAndFactor());
  PetscCall(fom.SolveElastic());

  // 1. Cell von Mises vs the analytic value, every owned cell.
  const PetscReal vmExact = AnalyticVonMises(cs.dim, cs.E, cs.nu);
  Vec             vm;
  PetscInt        n, ncellsVec;
  PetscCall(fom.elas.VonMises(fom.u, &vm));
  PetscCall(VecGetLocalSize(vm, &n));
  PetscCall(VecGetSize(vm, &ncellsVec));
  const PetscScalar *arr;
  PetscReal          worst = 0, vmin = PETSC_MAX_REAL, vmax = -PETSC_MAX_REAL;
  PetscCall(VecGetArrayRead(vm, &arr));
  for (PetscInt i = 0; i < n; ++i) {
    const PetscReal v = PetscRealPart(arr[i]);
    worst             = PetscMax(worst, std::isfinite(v) ? std::fabs(v - vmExact) / vmExact : PETSC_MAX_REAL);
    vmin              = PetscMin(vmin, v);
    vmax              = PetscMax(vmax, v);
  }
  PetscCall(VecRestoreArrayRead(vm, &arr));
  PetscCall(VecDestroy(&vm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPIU_REAL, MPI_MAX, comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &vmin, 1, MPIU_REAL, MPI_MIN, comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &vmax, 1, MPIU_REAL, MPI_MAX, comm));
  PetscInt nverts, ncells;
  PetscCall(GlobalPointCount(fom.dm, false, &nverts));
  PetscCall(GlobalPointCount(fom.dm, true, &ncells));
  PetscCall(PetscPrintf(comm, "case %s: %" PetscInt_FMT "D P%" PetscInt_FMT ", E %g nu %g, %" PetscInt_FMT " cells, %" PetscInt_FMT " vertices\n", cs.id.c_str(), cs.dim, cs.degree, (double)cs.E, (double)cs.nu, ncells, nverts));
  PetscCall(PetscPrintf(comm, "  von Mises analytic %.12e, cells min %.12e max %.12e, max rel. deviation %.3e (tol 1e-10)\n", (double)vmExact, (double)vmin, (double)vmax, (double)worst));
  if (!(worst <= 1e-10)) fails->push_back("case " + cs.id + ": cell von Mises deviates from the analytic plane-strain/3D value by " + std::to_string(worst));
  if (ncellsVec != ncells) fails->push_back("case " + cs.id + ": von Mises vector has " + std::to_string((long long)ncellsVec) + " entries for " + std::to_string((long long)ncells) + " cells");

  // 2. Output: .h5 + .xmf.
  const std::string base = outDir + "/test_vonmises_" + cs.id + "_np" + std::to_string(size);
  const std::string h5 = base + ".h5", xmf = base + ".xmf";
  if (rank == 0) {
    std::remove(h5.c_str());
    std::remove(xmf.c_str());
  }
  PetscCallMPI(MPI_Barrier(comm));
  PetscCall(fom.WriteOutput(h5));
  if (rank == 0) {
    std::string summary;
    const size_t nfail0 = fails->size();
    CheckH5(h5, cs.dim, nverts, ncells, vmExact, fails, &summary);
    std::ifstream     in(xmf);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string x = ss.str();
    if (!in.good() && x.empty()) fails->push_back("XDMF file '" + xmf + "' missing");
    for (const char *needle : {"/geometry/vertices", "/viz/topology/cells", "/vertex_fields/displacement_displacement", "/cell_fields/von_mises_von_mises"})
      if (x.find(needle) == std::string::npos) fails->push_back("XDMF file '" + xmf + "' does not reference " + needle);
    const std::string nelem = "NumberOfElements=\"" + std::to_string((long long)ncells) + "\"";
    if (x.find(nelem) == std::string::npos) fails->push_back("XDMF file '" + xmf + "' lacks " + nelem);
    std::printf("  output %s (+ .xmf, %zu bytes): %s\n%s", h5.c_str(), x.size(), fails->size() == nfail0 ? "ok" : "FAILED", summary.c_str());
    std::fflush(stdout);
  }
  PetscFunctionReturn(0);
}

PetscErrorCode Run(MPI_Comm comm, int *nfail)
{
  char        outDir[PETSC_MAX_PATH_LEN] = ".";
  PetscMPIInt rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-out_dir", outDir, sizeof outDir, NULL));
  const std::vector<Case> cases = {
    {"2d_p1", "meshes/unit_square.geo", 2, 1, 210.0, 0.30, 1.0, {"boundary"}},
    {"2d_p2", "meshes/unit_square.geo", 2, 2, 3.0, 0.45, 1.0, {"boundary"}},
    {"3d_p1", "meshes/block3d.geo", 3, 1, 70.0, 0.33, 1.0, {"bottom", "top", "sides"}},
  };
  PetscCall(PetscPrintf(comm, "test_vonmises: uniform-strain patch, von Mises and output\n"));
  std::vector<std::string> fails;
  for (const auto &cs : cases) PetscCall(RunCase(comm, cs, outDir, &fails));
  // Failures of the file checks are known on rank 0 only.
  int n = (int)fails.size();
  PetscCallMPI(MPI_Bcast(&n, 1, MPI_INT, 0, comm));
  if (rank == 0)
    for (const auto &f : fails) std::printf("FAILED: %s\n", f.c_str());
  std::fflush(stdout);
  *nfail = PetscMax(n, (int)fails.size());
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, nfail, 1, MPI_INT, MPI_MAX, comm));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  int nfail = 0;

  PetscCall(PetscInitialize(&argc, &argv, NULL, "von Mises patch test and FOM output test\n"));
  PetscCall(Run(PETSC_COMM_WORLD, &nfail));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_vonmises: %s\n", nfail ? "FAILED" : "all checks passed"));
  PetscCall(PetscFinalize());
  return nfail ? 1 : 0;
}
