// src/io/output.cpp: HDF5 output of the FOM fields (PetscViewerHDF5, VIZ layout) written to a temp
// file and renamed, plus an XDMF index so that ParaView opens it.
#include "rbcontact/provenance.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/mesh.hpp"
#include <petscviewerhdf5.h>
#include <cstdio>
#include <sstream>
#include <unistd.h>

namespace rbc {

PetscErrorCode WriteXdmf(MPI_Comm comm, const std::string &h5file, PetscInt dim, PetscInt nverts, PetscInt ncells, PetscInt nvpc, const std::vector<XdmfAttribute> &attrs)
{
  std::ostringstream x;
  const std::string  base = h5file.substr(h5file.find_last_of('/') == std::string::npos ? 0 : h5file.find_last_of('/') + 1);
  const char        *topo = dim == 2 ? (nvpc == 3 ? "Triangle" : "Quadrilateral") : (nvpc == 4 ? "Tetrahedron" : "Hexahedron");

  PetscFunctionBeginUser;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"2.0\">\n <Domain>\n  <Grid Name=\"mesh\" GridType=\"Uniform\">\n";
  x << "   <Topology TopologyType=\"" << topo << "\" NumberOfElements=\"" << ncells << "\">\n";
  x << "    <DataItem Dimensions=\"" << ncells << " " << nvpc << "\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">" << base << ":/viz/topology/cells</DataItem>\n   </Topology>\n";
  x << "   <Geometry GeometryType=\"" << (dim == 2 ? "XY" : "XYZ") << "\">\n";
  x << "    <DataItem Dimensions=\"" << nverts << " " << dim << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << base << ":/geometry/vertices</DataItem>\n   </Geometry>\n";
  for (const auto &at : attrs) {
    const PetscInt n = at.cell ? ncells : nverts;
    x << "   <Attribute Name=\"" << at.name << "\" AttributeType=\"" << (at.ncomp == 1 ? "Scalar" : "Vector") << "\" Center=\"" << (at.cell ? "Cell" : "Node") << "\">\n";
    if (at.ncomp == 2) {
      // ParaView wants 3-component vectors: pad with a zero z
      x << "    <DataItem ItemType=\"Function\" Function=\"JOIN($0, $1, 0*$0)\" Dimensions=\"" << n << " 3\">\n";
      for (int c = 0; c < 2; ++c) {
        x << "     <DataItem ItemType=\"HyperSlab\" Dimensions=\"" << n << " 1\" Type=\"HyperSlab\">\n";
        x << "      <DataItem Dimensions=\"3 2\" Format=\"XML\">0 " << c << " 1 1 " << n << " 1</DataItem>\n";
        x << "      <DataItem Dimensions=\"" << n << " 2\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << base << ":" << at.dataset << "</DataItem>\n     </DataItem>\n";
      }
      x << "    </DataItem>\n";
    } else {
      x << "    <DataItem Dimensions=\"" << n << (at.ncomp > 1 ? " " + std::to_string((long long)at.ncomp) : std::string()) << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << base << ":" << at.dataset << "</DataItem>\n";
    }
    x << "   </Attribute>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  std::string xdmf = h5file;
  if (xdmf.size() > 3 && xdmf.substr(xdmf.size() - 3) == ".h5") xdmf = xdmf.substr(0, xdmf.size() - 3);
  PetscCall(WriteFileAtomic(comm, xdmf + ".xmf", x.str()));
  PetscFunctionReturn(0);
}

PetscErrorCode ElasticFOM::WriteOutput(const std::string &h5file, const std::vector<Vec> &contact)
{
  MPI_Comm    comm = PetscObjectComm((PetscObject)dm);
  PetscViewer v;
  Vec         vm;
  PetscMPIInt rank;
  std::string tmp;
  PetscInt    nverts, ncells;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  {
    long pid = (long)getpid();
    PetscCallMPI(MPI_Bcast(&pid, 1, MPI_LONG, 0, comm));
    tmp = h5file + ".tmp." + std::to_string(pid);
  }
  PetscCall(elas.VonMises(u, &vm));
  // The mesh is the reference one: write it in the physical configuration at mu (x = h_b(mu)(xr) on
  // the vertices of body b), then restore the reference coordinates.
  Vec xref = nullptr;
  if (!map.IsIdentity() && !mu.empty()) {
    Vec          xl, xphys;
    PetscScalar *a;
    PetscInt     cStart, cEnd, vStart, vEnd;
    PetscCall(DMGetCoordinatesLocal(dm, &xl));
    PetscCall(VecDuplicate(xl, &xref));
    PetscCall(VecCopy(xl, xref));
    PetscCall(VecDuplicate(xl, &xphys));
    PetscCall(VecCopy(xl, xphys));
    PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
    PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
    std::vector<PetscInt> vbody(vEnd - vStart, -1);
    for (PetscInt c = cStart; c < cEnd; ++c) {
      PetscInt *cl = NULL, ncl;
      PetscCall(DMPlexGetTransitiveClosure(dm, c, PETSC_TRUE, &ncl, &cl));
      for (PetscInt i = 0; i < ncl; ++i)
        if (cl[2 * i] >= vStart && cl[2 * i] < vEnd) vbody[cl[2 * i] - vStart] = elas.CellBody()[c - cStart];
      PetscCall(DMPlexRestoreTransitiveClosure(dm, c, PETSC_TRUE, &ncl, &cl));
    }
    PetscCall(VecGetArray(xphys, &a));
    const PetscInt d = elas.dim;
    for (PetscInt vtx = vStart; vtx < vEnd; ++vtx) {
      PetscReal x[3] = {0, 0, 0}, y[3];
      for (PetscInt k = 0; k < d; ++k) x[k] = PetscRealPart(a[(vtx - vStart) * d + k]);
      map.Evaluate(vbody[vtx - vStart], mu).Apply(d, x, y);
      for (PetscInt k = 0; k < d; ++k) a[(vtx - vStart) * d + k] = y[k];
    }
    PetscCall(VecRestoreArray(xphys, &a));
    PetscCall(DMSetCoordinatesLocal(dm, xphys));
    PetscCall(VecDestroy(&xphys));
  }
  PetscCall(PetscViewerHDF5Open(comm, tmp.c_str(), FILE_MODE_WRITE, &v));
  PetscCall(PetscViewerPushFormat(v, PETSC_VIEWER_HDF5_VIZ));
  PetscCall(DMView(dm, v));
  if (xref) {
    PetscCall(DMSetCoordinatesLocal(dm, xref));
    PetscCall(VecDestroy(&xref));
  }
  PetscCall(VecView(u, v));
  PetscCall(VecView(vm, v));
  PetscCall(PetscViewerPopFormat(v));
  if (!contact.empty()) {
    PetscCall(PetscViewerHDF5PushGroup(v, "/contact"));
    for (Vec c : contact) PetscCall(VecView(c, v));
    PetscCall(PetscViewerHDF5PopGroup(v));
  }
  {
    Provenance prov;
    PetscCall(GetProvenance(comm, &prov));
    for (const auto &a : ProvenanceAttributes(prov)) PetscCall(PetscViewerHDF5WriteAttribute(v, "/", a.first.c_str(), PETSC_STRING, a.second.c_str()));
  }
  PetscCall(PetscViewerDestroy(&v));
  PetscCall(VecDestroy(&vm));
  if (rank == 0) PetscCheck(std::rename(tmp.c_str(), h5file.c_str()) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Cannot move '%s' to '%s' (-fom_output)", tmp.c_str(), h5file.c_str());
  PetscCallMPI(MPI_Barrier(comm));

  // Sizes for the XDMF: count owned vertices and cells.
  PetscCall(GlobalPointCount(dm, false, &nverts));
  PetscCall(GlobalPointCount(dm, true, &ncells));
  // PETSc's VIZ layout names datasets <vector name>_<field name>.
  std::vector<XdmfAttribute> attrs = {{"displacement", "/vertex_fields/displacement_displacement", elas.dim, false}, {"von_mises", "/cell_fields/von_mises_von_mises", 1, true}};
  PetscCall(WriteXdmf(comm, h5file, elas.dim, nverts, ncells, elas.dim + 1, attrs));
  PetscFunctionReturn(0);
}

} // namespace rbc
