#!/usr/bin/python3
"""plot_bodies3d.py: a 3D picture of the deformed bodies of a 3D contact FOM solution and of the contact
pressure on the slave surface.

Reads what `rbcontact fom -fom_output f.h5` writes for a 3D scene (tetrahedra):
  /geometry/vertices (nv x 3), /viz/topology/cells (nc x 4), /vertex_fields/displacement_displacement (nv x 3),
  /cell_fields/von_mises_von_mises (nc, optional), /contact/lambda and /contact/points (slave vertices).
Left: the bodies cut by the plane y = y_cut (the cells whose centroid has y >= y_cut; default the middle of the
box) near the contact (--window), their boundary faces at the displaced positions (displacement times --scale) coloured by the cell's von
Mises stress, so that the contact zone is seen in section. Right: the slave surface's vertices at their
displaced positions, coloured by the nodal contact pressure lambda (a triangulation of their projection on the
plane normal to the resultant).
It prints the area of the whole undeformed boundary (a check of the face extraction: every face of exactly one
cell) and whether that surface is closed (every edge on two faces).

Usage: /usr/bin/python3 share/plot_bodies3d.py results/hertz3d/fom.h5 -o bodies.png [--title hertz3d]
           [--scale 5] [--y-cut 0] [--window 1]
Run it with Debian's /usr/bin/python3 (python3-matplotlib, python3-h5py, python3-numpy).
"""
import argparse


from plot_common import fail, require_plotting

require_plotting()
import numpy as np
import h5py
import matplotlib.pyplot as plt
from matplotlib import cm, colors
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from matplotlib.tri import Triangulation


def read(path):
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        fail("cannot open '%s': %s" % (path, e))
    with f:
        need = ("geometry/vertices", "viz/topology/cells", "vertex_fields/displacement_displacement")
        for n in need:
            if n not in f:
                fail("'%s' has no /%s (not a `rbcontact fom -fom_output` file?)" % (path, n))
        X = np.asarray(f["geometry/vertices"][...], dtype=float)
        C = np.asarray(f["viz/topology/cells"][...], dtype=np.int64)
        U = np.asarray(f["vertex_fields/displacement_displacement"][...], dtype=float)
        vm = np.asarray(f["cell_fields/von_mises_von_mises"][...], dtype=float) if "cell_fields/von_mises_von_mises" in f else None
        lam = np.asarray(f["contact/lambda"][...], dtype=float) if "contact/lambda" in f else None
        pts = np.asarray(f["contact/points"][...], dtype=float) if "contact/points" in f else None
        nrm = [np.asarray(f["contact/normal_" + c][...], dtype=float) for c in "xyz" if "contact/normal_" + c in f]
        w = np.asarray(f["contact/weight"][...], dtype=float) if "contact/weight" in f else None
    if X.ndim != 2 or X.shape[1] != 3 or C.ndim != 2 or C.shape[1] != 4:
        fail("'%s' is not a 3D tetrahedral mesh (vertices %s, cells %s)" % (path, X.shape, C.shape))
    if U.shape != X.shape:
        fail("'%s': displacement %s for %s vertices" % (path, U.shape, X.shape))
    if C.min() < 0 or C.max() >= len(X):
        fail("'%s': a cell refers to vertex %d of %d" % (path, C.max() if C.max() >= len(X) else C.min(), len(X)))
    return X, C, U, vm, lam, pts, nrm, w


def boundary_faces(C):
    """Faces of exactly one cell: (faces nb x 3, the cell of each)."""
    loc = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
    F = C[:, loc].reshape(-1, 3)
    owner = np.repeat(np.arange(len(C)), 4)
    key = np.sort(F, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    one = cnt[inv.ravel()] == 1
    return F[one], owner[one]


def closed(F):
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, cnt = np.unique(e, axis=0, return_counts=True)
    return bool((cnt == 2).all())


def area(P, F):
    a, b, c = P[F[:, 0]], P[F[:, 1]], P[F[:, 2]]
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def main(argv=None):
    p = argparse.ArgumentParser(description="3D picture of the deformed bodies and of the contact pressure of a 3D rbcontact FOM output.")
    p.add_argument("h5", help="HDF5 file written by `rbcontact fom -fom_output <file.h5>` for a 3D scene")
    p.add_argument("-o", "--output", help="PNG to write (default: <h5 without .h5>_bodies.png)")
    p.add_argument("--title", default=None)
    p.add_argument("--scale", type=float, default=None, help="displacement magnification (default: 5 %% of the box size / max |u|)")
    p.add_argument("--y-cut", type=float, default=None, help="keep the cells whose centroid has y >= this (default: the middle of the box)")
    p.add_argument("--window", type=float, default=None, help="half-width of the box around the slave surface whose cells are drawn "
                                                              "(default: twice the slave surface's radius; 0: everything)")
    p.add_argument("--dpi", type=int, default=130)
    a = p.parse_args(argv)
    out = a.output or (a.h5[:-3] if a.h5.endswith(".h5") else a.h5) + "_bodies.png"

    X, C, U, vm, lam, pts, nrm, w = read(a.h5)
    F, owner = boundary_faces(C)
    A = float(area(X, F).sum())
    print("plot_bodies3d.py: %d vertices, %d cells, %d boundary faces, boundary area %.10g, closed %s"
          % (len(X), len(C), len(F), A, "yes" if closed(F) else "no"))
    box = X.max(axis=0) - X.min(axis=0)
    umax = float(np.linalg.norm(U, axis=1).max())
    scale = a.scale if a.scale is not None else (0.05 * float(box.max()) / umax if umax > 0 else 1.0)
    P = X + scale * U
    ycut = a.y_cut if a.y_cut is not None else float(0.5 * (X[:, 1].min() + X[:, 1].max()))
    cen = X[C].mean(axis=1)
    keep = cen[:, 1] >= ycut
    if pts is not None and len(pts) and a.window is None:
        half = 2.0 * float(np.linalg.norm(pts - pts.mean(axis=0), axis=1).max())
    else:
        half = a.window
    if half is not None and half > 0:  # zoom on the contact zone: the cells within a box around the slave surface
        c0 = pts.mean(axis=0) if pts is not None and len(pts) else X.mean(axis=0)
        keep &= (np.abs(cen[:, 0] - c0[0]) <= half) & (np.abs(cen[:, 2] - c0[2]) <= half) & (cen[:, 1] - c0[1] <= half)
    Fk, ok = boundary_faces(C[keep])
    cells = np.nonzero(keep)[0][ok]

    fig = plt.figure(figsize=(13, 6), layout="constrained")
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    val = vm[cells] if vm is not None else np.zeros(len(cells))
    norm = colors.Normalize(vmin=float(val.min()), vmax=float(np.percentile(val, 99.5)) if val.size else 1.0)
    pc = Poly3DCollection(P[Fk], facecolors=cm.viridis(norm(val)), edgecolors=(0, 0, 0, 0.15), linewidths=0.2)
    ax.add_collection3d(pc)
    lo, hi = P[Fk].reshape(-1, 3).min(axis=0), P[Fk].reshape(-1, 3).max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(np.maximum(hi - lo, 1e-12)))
    ax.view_init(elev=15, azim=-60)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    sm = cm.ScalarMappable(norm=norm, cmap="viridis")
    fig.colorbar(sm, ax=ax, shrink=0.6, label="von Mises stress" if vm is not None else "(no von Mises field)")
    ax.set_title("deformed bodies (displacement x %.3g), cut at y = %.3g" % (scale, ycut))

    ax2 = fig.add_subplot(1, 2, 2, projection="3d")
    if lam is not None and pts is not None and len(lam) >= 3:
        # displaced slave vertices: match /contact/points to the mesh vertices
        idx = np.array([int(np.argmin(np.linalg.norm(X - q, axis=1))) for q in pts])
        S = X[idx] + scale * U[idx]
        # triangulate in the plane normal to the resultant (the slave surface is a graph over it)
        if len(nrm) == 3 and w is not None:
            n = np.array([(lam * w * c).sum() for c in nrm])
        else:
            n = np.array([0.0, 0.0, 1.0])
        n = n / np.linalg.norm(n) if np.linalg.norm(n) > 0 else np.array([0.0, 0.0, 1.0])
        e1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(n, e1)
        tri = Triangulation(pts @ e1, pts @ e2)
        lnorm = colors.Normalize(vmin=0.0, vmax=max(float(lam.max()), 1e-300))
        face = lam[tri.triangles].mean(axis=1)
        pc2 = Poly3DCollection(S[tri.triangles], facecolors=cm.inferno(lnorm(face)), edgecolors=(0, 0, 0, 0.2), linewidths=0.2)
        ax2.add_collection3d(pc2)
        lo2, hi2 = S.min(axis=0), S.max(axis=0)
        ax2.set_xlim(lo2[0], hi2[0])
        ax2.set_ylim(lo2[1], hi2[1])
        ax2.set_zlim(lo2[2], hi2[2])
        ax2.set_box_aspect(tuple(np.maximum(hi2 - lo2, 1e-3 * float((hi2 - lo2).max()))))
        ax2.view_init(elev=-35, azim=-60)
        ax2.set_zticks([])  # the surface is nearly flat: its z ticks would pile up on one another
        fig.colorbar(cm.ScalarMappable(norm=lnorm, cmap="inferno"), ax=ax2, shrink=0.6, label="contact pressure $\\lambda$")
        ax2.set_title("contact pressure on the slave surface (max %.4g, %d active of %d vertices)" % (float(lam.max()), int((lam > 0).sum()), len(lam)))
    else:
        ax2.set_title("no contact data in this file")
    fig.suptitle(a.title or a.h5)
    try:
        fig.savefig(out, dpi=a.dpi)
    except OSError as e:
        fail("cannot write '%s': %s" % (out, e))
    print("plot_bodies3d.py: wrote %s" % out)


if __name__ == "__main__":
    main()
