// src/io/output.cpp: HDF5 output of the FOM fields (PetscViewerHDF5, VIZ layout) written to a temp
// file and renamed, plus an XDMF index so that ParaView opens it.
#include "rbcontact/report.hpp"
#include "rbcontact/provenance.hpp"
#include "rbcontact/fom.hpp"
#include "rbcontact/mesh.hpp"
#include <petscviewerhdf5.h>
#include <cstdio>
#include <sstream>
#include <unistd.h>

namespace rbc {

// One attribute over n points (or cells) of the file base: 2-component vectors padded with a zero z
// (ParaView wants 3), a "JOIN" of the datasets when the components are stored apart (dataset "a|b|c").
static void XdmfAttributeText(std::ostringstream &x, const std::string &base, const XdmfAttribute &at, PetscInt n)
{
  const bool split = at.dataset.find('|') != std::string::npos;
  x << "   <Attribute Name=\"" << at.name << "\" AttributeType=\"" << (at.ncomp == 1 ? "Scalar" : "Vector") << "\" Center=\"" << (at.cell ? "Cell" : "Node") << "\">\n";
  auto item = [&](const std::string &ds, PetscInt ncomp) { x << "      <DataItem Dimensions=\"" << n << (ncomp > 1 ? " " + std::to_string((long long)ncomp) : std::string()) << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << base << ":" << ds << "</DataItem>\n"; };
  if (split) {
    std::vector<std::string> parts;
    for (size_t a = 0, b; a <= at.dataset.size(); a = b + 1) {
      b = at.dataset.find('|', a);
      if (b == std::string::npos) b = at.dataset.size();
      parts.push_back(at.dataset.substr(a, b - a));
    }
    x << "    <DataItem ItemType=\"Function\" Function=\"JOIN($0, $1, " << (parts.size() > 2 ? "$2" : "0*$0") << ")\" Dimensions=\"" << n << " 3\">\n";
    for (const auto &p : parts) item(p, 1);
    x << "    </DataItem>\n";
  } else if (at.ncomp == 2) {
    x << "    <DataItem ItemType=\"Function\" Function=\"JOIN($0, $1, 0*$0)\" Dimensions=\"" << n << " 3\">\n";
    for (int c = 0; c < 2; ++c) {
      x << "     <DataItem ItemType=\"HyperSlab\" Dimensions=\"" << n << " 1\" Type=\"HyperSlab\">\n";
      x << "      <DataItem Dimensions=\"3 2\" Format=\"XML\">0 " << c << " 1 1 " << n << " 1</DataItem>\n";
      item(at.dataset, 2);
      x << "     </DataItem>\n";
    }
    x << "    </DataItem>\n";
  } else item(at.dataset, at.ncomp);
  x << "   </Attribute>\n";
}

PetscErrorCode WriteXdmf(MPI_Comm comm, const std::string &h5file, PetscInt dim, PetscInt nverts, PetscInt ncells, PetscInt nvpc, const std::vector<XdmfAttribute> &attrs, PetscInt npoints, const std::vector<XdmfAttribute> &pattrs)
{
  std::ostringstream x;
  const std::string  base = h5file.substr(h5file.find_last_of('/') == std::string::npos ? 0 : h5file.find_last_of('/') + 1);
  const char        *topo = dim == 2 ? (nvpc == 3 ? "Triangle" : "Quadrilateral") : (nvpc == 4 ? "Tetrahedron" : "Hexahedron");

  PetscFunctionBeginUser;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"2.0\">\n <Domain>\n  <Grid Name=\"mesh\" GridType=\"Uniform\">\n";
  x << "   <Topology TopologyType=\"" << topo << "\" NumberOfElements=\"" << ncells << "\">\n";
  // the cells are PetscInt (int32 unless PETSc uses 64-bit indices): the precision says which
  x << "    <DataItem Dimensions=\"" << ncells << " " << nvpc << "\" NumberType=\"Int\" Precision=\"" << sizeof(PetscInt) << "\" Format=\"HDF\">" << base << ":/viz/topology/cells</DataItem>\n   </Topology>\n";
  x << "   <Geometry GeometryType=\"" << (dim == 2 ? "XY" : "XYZ") << "\">\n";
  x << "    <DataItem Dimensions=\"" << nverts << " " << dim << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << base << ":/geometry/vertices</DataItem>\n   </Geometry>\n";
  for (const auto &at : attrs) XdmfAttributeText(x, base, at, at.cell ? ncells : nverts);
  x << "  </Grid>\n";
  if (npoints > 0) {
    x << "  <Grid Name=\"contact\" GridType=\"Uniform\">\n";
    x << "   <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << npoints << "\" NodesPerElement=\"1\"/>\n";
    x << "   <Geometry GeometryType=\"XYZ\">\n";
    x << "    <DataItem Dimensions=\"" << npoints << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << base << ":/contact/points</DataItem>\n   </Geometry>\n";
    for (const auto &at : pattrs) XdmfAttributeText(x, base, at, npoints);
    x << "  </Grid>\n";
  }
  x << " </Domain>\n</Xdmf>\n";
  PetscCall(WriteFileAtomic(comm, XdmfPath(h5file), x.str()));
  PetscFunctionReturn(0);
}

std::string XdmfPath(const std::string &h5file)
{
  const bool h5 = h5file.size() > 3 && h5file.compare(h5file.size() - 3, 3, ".h5") == 0;
  return (h5 ? h5file.substr(0, h5file.size() - 3) : h5file) + ".xmf";
}

PetscErrorCode ElasticFOM::WriteOutput(const std::string &h5file, const std::vector<Vec> &contact, const std::vector<Vec> &fields)
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
    tmp = TemporaryPath(h5file, pid);
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
  // the extra fields through a clone of the DM with the same discretization and no boundary conditions:
  // PETSc's VIZ viewer inserts the DM's Dirichlet values (right for the displacement, wrong for a POD mode,
  // which is zero there); the clone has the same local layout
  if (!fields.empty()) {
    DM          dmv;
    PetscObject fe;
    PetscCall(DMClone(dm, &dmv));
    PetscCall(DMGetField(dm, 0, NULL, &fe));
    PetscCall(DMSetField(dmv, 0, NULL, fe));
    PetscCall(DMCreateDS(dmv));
    for (Vec f : fields) {
      Vec         loc, lv;
      const char *name;
      PetscCall(DMGetLocalVector(dm, &loc));
      PetscCall(VecZeroEntries(loc));
      PetscCall(DMGlobalToLocal(dm, f, INSERT_VALUES, loc));
      PetscCall(DMGetLocalVector(dmv, &lv));
      PetscCall(VecCopy(loc, lv));
      PetscCall(PetscObjectGetName((PetscObject)f, &name));
      PetscCall(PetscObjectSetName((PetscObject)lv, name));
      PetscCall(VecView(lv, v));
      PetscCall(DMRestoreLocalVector(dmv, &lv));
      PetscCall(DMRestoreLocalVector(dm, &loc));
    }
    PetscCall(DMDestroy(&dmv));
  }
  PetscCall(PetscViewerPopFormat(v));
  // the contact vectors, and the slave points (x, y(, z) joined, z = 0 in 2D) for the XDMF's contact grid
  PetscInt                   npoints = 0;
  std::vector<XdmfAttribute> pattrs;
  if (!contact.empty()) {
    PetscCall(PetscViewerHDF5PushGroup(v, "/contact"));
    Vec         xyz[3] = {nullptr, nullptr, nullptr};
    std::string nx[3];
    for (Vec c : contact) {
      const char *name;
      PetscCall(VecView(c, v));
      PetscCall(PetscObjectGetName((PetscObject)c, &name));
      const std::string n = name;
      if (n == "x" || n == "y" || n == "z") xyz[n[0] - 'x'] = c;
      else if (n.compare(0, 7, "normal_") == 0) nx[n[7] - 'x'] = "/contact/" + n;
      else pattrs.push_back({n, "/contact/" + n, 1, false});
    }
    if (xyz[0] && xyz[1]) {
      Vec                pts;
      PetscInt           nloc;
      PetscScalar       *p;
      const PetscScalar *c[3] = {nullptr, nullptr, nullptr};
      PetscCall(VecGetLocalSize(xyz[0], &nloc));
      PetscCall(VecGetSize(xyz[0], &npoints));
      PetscCall(VecCreateMPI(comm, 3 * nloc, PETSC_DETERMINE, &pts));
      PetscCall(VecSetBlockSize(pts, 3));
      PetscCall(PetscObjectSetName((PetscObject)pts, "points"));
      PetscCall(VecGetArray(pts, &p));
      for (int d = 0; d < 3; ++d)
        if (xyz[d]) PetscCall(VecGetArrayRead(xyz[d], &c[d]));
      for (PetscInt i = 0; i < nloc; ++i)
        for (int d = 0; d < 3; ++d) p[3 * i + d] = c[d] ? c[d][i] : 0.0;
      for (int d = 0; d < 3; ++d)
        if (xyz[d]) PetscCall(VecRestoreArrayRead(xyz[d], &c[d]));
      PetscCall(VecRestoreArray(pts, &p));
      PetscCall(VecView(pts, v));
      PetscCall(VecDestroy(&pts));
      if (!nx[0].empty() && !nx[1].empty()) pattrs.push_back({"normal", nx[0] + "|" + nx[1] + (nx[2].empty() ? "" : "|" + nx[2]), 3, false});
    }
    PetscCall(PetscViewerHDF5PopGroup(v));
  }
  {
    Provenance prov;
    PetscCall(GetProvenance(comm, &prov));
    for (const auto &a : ProvenanceAttributes(prov)) PetscCall(PetscViewerHDF5WriteAttribute(v, "/", a.first.c_str(), PETSC_STRING, a.second.c_str()));
  }
  PetscCall(PetscViewerDestroy(&v));
  PetscCall(VecDestroy(&vm));
  if (rank == 0) PetscCheck(std::rename(tmp.c_str(), OutputTarget(h5file).c_str()) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Cannot move '%s' to '%s' (-fom_output)", tmp.c_str(), h5file.c_str());
  PetscCallMPI(MPI_Barrier(comm));

  // Sizes for the XDMF: count owned vertices and cells.
  PetscCall(GlobalPointCount(dm, false, &nverts));
  PetscCall(GlobalPointCount(dm, true, &ncells));
  // PETSc's VIZ layout names datasets <vector name>_<field name>.
  std::vector<XdmfAttribute> attrs = {{"displacement", "/vertex_fields/displacement_displacement", elas.dim, false}, {"von_mises", "/cell_fields/von_mises_von_mises", 1, true}};
  for (Vec f : fields) {
    const char *name;
    PetscCall(PetscObjectGetName((PetscObject)f, &name));
    attrs.push_back({name, std::string("/vertex_fields/") + name + "_displacement", elas.dim, false});
  }
  PetscCall(WriteXdmf(comm, h5file, elas.dim, nverts, ncells, elas.dim + 1, attrs, npoints, pattrs));
  PetscFunctionReturn(0);
}

} // namespace rbc
