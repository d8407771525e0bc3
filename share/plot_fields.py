#!/usr/bin/python3
"""plot_fields.py: picture of a FOM solution written by `rbcontact fom -fom_output f.h5`.

Reads the HDF5 file in PETSc's VIZ layout:
  /geometry/vertices                        (nv x dim)  vertex coordinates
  /viz/topology/cells                       (nc x nvpc) cells, global vertex ids
  /vertex_fields/displacement_displacement  (nv x dim)  displacement
  /cell_fields/von_mises_von_mises          (nc)        cell von Mises stress
(other /vertex_fields/*, /cell_fields/*, /fields/* datasets are ignored) and renders the
deformed mesh (x + scale * u) coloured by von Mises, with the mesh edges, to a PNG.
2D (triangles): matplotlib tripcolor. 3D (tetrahedra): the boundary faces of the deformed
mesh in a 3D view (a message says so).

Usage: /usr/bin/python3 share/plot_fields.py results/ring_on_block/fom.h5 -o fom.png \
           [--scale 1] [--title ring_on_block] [--dpi 150] [--no-edges]
Run it with Debian's /usr/bin/python3 (python3-matplotlib, python3-h5py, python3-numpy).
"""
import argparse
import os
import sys

DATASETS = {
    "vertices": "/geometry/vertices",
    "cells": "/viz/topology/cells",
    "displacement": "/vertex_fields/displacement_displacement",
    "von_mises": "/cell_fields/von_mises_von_mises",
}


from plot_common import fail, require_plotting

require_plotting()
import numpy as np
import h5py
import matplotlib
import matplotlib.pyplot as plt
import matplotlib.tri as mtri


def read_fields(path):
    if not os.path.isfile(path):
        fail("file '%s' not found (write it with: rbcontact fom ... -fom_output %s)" % (path, path))
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        fail("cannot open '%s' as HDF5: %s" % (path, e))
    with f:
        names = []
        f.visititems(lambda name, obj: names.append("/" + name) if isinstance(obj, h5py.Dataset) else None)
        if any("/pod_mode_" in n or "/supremizer_" in n for n in names):  # (drawn as a deformed FOM solution before 2026-12-01)
            fail("'%s' is a basis view (offline -offline_basis_output: pod_mode_* and supremizer_* fields), not a FOM solution: "
                 "open it in ParaView (its .xmf), or plot the output of rbcontact fom -fom_output" % path)
        missing = [d for d in DATASETS.values() if d not in f]
        if missing:
            have = []
            f.visititems(lambda name, obj: have.append("/" + name) if isinstance(obj, h5py.Dataset) else None)
            fail("'%s' lacks dataset(s) %s (expected the PETSc VIZ layout of `rbcontact fom -fom_output`); "
                 "it has: %s" % (path, ", ".join(missing), ", ".join(have) or "nothing"))
        data = {k: np.asarray(f[d][...]) for k, d in DATASETS.items()}
    x, cells, u, vm = data["vertices"], data["cells"].astype(np.int64), data["displacement"], data["von_mises"].ravel()
    if x.ndim != 2 or x.shape[1] not in (2, 3):
        fail("%s has shape %s, expected (nv, 2|3)" % (DATASETS["vertices"], x.shape))
    if u.shape != x.shape:
        fail("%s has shape %s, but the vertices have shape %s" % (DATASETS["displacement"], u.shape, x.shape))
    if cells.ndim != 2 or vm.shape[0] != cells.shape[0]:
        fail("%s (%s) and %s (%s) disagree" % (DATASETS["cells"], cells.shape, DATASETS["von_mises"], vm.shape))
    if cells.size and (cells.min() < 0 or cells.max() >= x.shape[0]):
        fail("%s refers to vertices outside [0, %d)" % (DATASETS["cells"], x.shape[0]))
    return x, cells, u, vm


def plot_2d(ax, xd, cells, vm, edges, cmap):
    if cells.shape[1] != 3:
        fail("2D plotting supports triangles only (cells have %d vertices)" % cells.shape[1])
    tri = mtri.Triangulation(xd[:, 0], xd[:, 1], cells)
    pc = ax.tripcolor(tri, facecolors=vm, cmap=cmap, edgecolors="none")
    if edges:
        ax.triplot(tri, color="k", linewidth=0.1, alpha=0.35)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    return pc


def boundary_faces(cells):
    """Faces of tetrahedra that belong to one cell only: (faces (nf x 3), owning cell (nf))."""
    local = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    faces = cells[:, local].reshape(-1, 3)
    owner = np.repeat(np.arange(cells.shape[0]), 4)
    key = np.sort(faces, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    once = cnt[inv.ravel()] == 1
    return faces[once], owner[once]


def plot_3d(fig, xd, cells, vm, edges, cmap):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if cells.shape[1] != 4:
        fail("3D plotting supports tetrahedra only (cells have %d vertices)" % cells.shape[1])
    print("plot_fields.py: 3D mesh: drawing the boundary faces of the deformed mesh in a 3D view")
    faces, owner = boundary_faces(cells)
    ax = fig.add_subplot(projection="3d")
    norm = matplotlib.colors.Normalize(vmin=float(vm.min()), vmax=float(vm.max()))
    coll = Poly3DCollection(xd[faces], cmap=cmap, norm=norm,
                            edgecolors="k" if edges else "none", linewidths=0.1)
    coll.set_array(vm[owner])
    ax.add_collection3d(coll)
    lo, hi = xd.min(axis=0), xd.max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(np.maximum(hi - lo, 1e-12 * max(float((hi - lo).max()), 1.0)))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    return ax, coll


def main(argv=None):
    p = argparse.ArgumentParser(description="Render the deformed mesh of an rbcontact FOM HDF5 output, "
                                            "coloured by von Mises stress.")
    p.add_argument("h5", help="HDF5 file written by `rbcontact fom -fom_output <file.h5>`")
    p.add_argument("-o", "--output", help="PNG to write (default: <h5 without .h5>.png)")
    p.add_argument("--scale", type=float, default=1.0, help="displacement magnification (default 1)")
    p.add_argument("--title", default=None, help="scene name shown in the title (default: file name)")
    p.add_argument("--dpi", type=int, default=150, help="resolution (default 150)")
    p.add_argument("--cmap", default="viridis", help="matplotlib colormap (default viridis)")
    p.add_argument("--no-edges", dest="edges", action="store_false", help="do not draw the mesh edges")
    p.add_argument("--zero-tol", type=float, default=1e-10,
                   help="von Mises values all below this are round-off: drawn as 0 (default 1e-10)")
    a = p.parse_args(argv)

    out = a.output or (a.h5[:-3] if a.h5.endswith(".h5") else a.h5) + ".png"
    x, cells, u, vm = read_fields(a.h5)
    xd = x + a.scale * u
    dim = x.shape[1]
    title = a.title or os.path.basename(a.h5)
    umax = float(np.sqrt((u ** 2).sum(axis=1)).max()) if u.size else 0.0
    vmmax = float(np.abs(vm).max()) if vm.size else 0.0
    stress_free = vmmax <= a.zero_tol
    if stress_free:  # e.g. a rigid motion: do not colour round-off noise
        vm = np.zeros_like(vm)

    if dim == 2:  # size the figure to the deformed domain (equal aspect)
        ext = np.maximum(xd.max(axis=0) - xd.min(axis=0), 1e-12)
        fig = plt.figure(figsize=(8, float(np.clip(6.4 * ext[1] / ext[0] + 1.0, 3.0, 11.0))), layout="constrained")
    else:
        fig = plt.figure(figsize=(8, 6.5), layout="constrained")
    if dim == 2:
        ax = fig.add_subplot()
        mappable = plot_2d(ax, xd, cells, vm, a.edges, a.cmap)
        cbar = fig.colorbar(mappable, ax=ax, shrink=0.85)
    else:
        ax, mappable = plot_3d(fig, xd, cells, vm, a.edges, a.cmap)
        cbar = fig.colorbar(mappable, ax=ax, shrink=0.7)
    if stress_free:
        mappable.set_clim(0.0, a.zero_tol)
    cbar.set_label("von Mises stress")
    note = ("\nstress-free (von Mises < %g everywhere, e.g. a rigid motion)" % a.zero_tol) if stress_free else ""
    fig.suptitle("%s: deformed mesh (displacement x %g), von Mises stress\n"
                 "%d vertices, %d cells, max |u| = %.3g, max von Mises = %.3g%s"
                 % (title, a.scale, x.shape[0], cells.shape[0], umax, vmmax, note),
                 fontsize=10)
    odir = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(odir):
        fail("output directory '%s' does not exist" % odir)
    fig.savefig(out, dpi=a.dpi)
    plt.close(fig)
    print("plot_fields.py: wrote %s" % out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
