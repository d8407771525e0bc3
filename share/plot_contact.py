#!/usr/bin/python3
"""plot_contact.py: contact pressure along the slave surface of a contact FOM solution.

Reads the /contact group that `rbcontact fom -fom_output f.h5` writes when contact is on:
  /contact/lambda    (R)  nodal contact pressure of each slave vertex (coefficient of the hat
                          function psi_i; lambda >= 0, > 0 on the active nodes)
  /contact/weight    (R)  int psi_i over the slave surface (resultant = sum lambda_i weight_i n_i)
  /contact/x, /contact/y  the slave vertices' undeformed positions at the run's mu (the geometric map applied)
and plots lambda against the position along the slave surface (x by default, sorted), markers +
line, with the active nodes (lambda > --active-tol) highlighted. 3D slave surfaces (/contact/z present):
by default against r, the distance to the pressure centroid in the plane normal to the resultant (a
point contact's profile), with a second panel showing the pressure on that plane.

Hertz overlay: --hertz-a A --hertz-p0 P0, or --report r.json (a `rbcontact fom` report of a run
with -hertz_radius: takes hertz.a_exact and hertz.p0_exact; explicit --hertz-a/--hertz-p0 win),
draws p0 sqrt(1 - (x - xc)^2 / a^2) for |x - xc| <= a, with xc the pressure centroid
sum(lambda w x) / sum(lambda w).

Usage: /usr/bin/python3 share/plot_contact.py results/ring_on_block/fom.h5 -o pressure.png \
           [--title ring_on_block] [--report fom.json | --hertz-a A --hertz-p0 P0] [--coord x|y]
Run it with Debian's /usr/bin/python3 (python3-matplotlib, python3-h5py, python3-numpy).
"""
import argparse
import json
import os
import sys


from plot_common import fail, require_plotting

require_plotting()
import numpy as np
import h5py
import matplotlib.pyplot as plt


def read_contact(path, coord):
    if not os.path.isfile(path):
        fail("file '%s' not found (write it with: rbcontact fom ... -fom_output %s)" % (path, path))
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        fail("cannot open '%s' as HDF5: %s" % (path, e))
    with f:
        if "contact" not in f or not isinstance(f["contact"], h5py.Group):
            fail("'%s' has no /contact group: it was written by a run without contact "
                 "(-contact 0, or a scene without -contact_slave/-contact_master). "
                 "Run `rbcontact fom` with contact to get the contact pressure." % path)
        g = f["contact"]
        need = ["lambda", "weight"] + ([coord] if coord != "r" else ["x", "y", "z"])
        missing = ["/contact/" + n for n in need if n not in g]
        if missing:
            fail("'%s' lacks %s (it has: %s)" % (path, ", ".join(missing),
                                                 ", ".join("/contact/" + k for k in g.keys()) or "nothing"))
        data = {n: np.asarray(g[n][...], dtype=float).ravel() for n in need}
        dim = sum(1 for c in ("x", "y", "z") if c in g)
        # the master normals (files of rbcontact fom have them): the resultant is sum lambda_i w_i n_i
        normals = [np.asarray(g["normal_" + c][...], dtype=float).ravel() for c in ("x", "y", "z")[:dim] if "normal_" + c in g]
    lam, w = data["lambda"], data["weight"]
    s = data[coord] if coord != "r" else np.stack([data["x"], data["y"], data["z"]], axis=1)
    data["normals"] = normals if len(normals) == dim and dim > 0 else None
    if not (lam.shape == w.shape == s.shape[:1]):
        fail("/contact datasets disagree in size: lambda %s, weight %s, %s %s" % (lam.shape, w.shape, coord, s.shape))
    if lam.size == 0:
        fail("'%s': the slave surface has no vertices (/contact/lambda is empty)" % path)
    return lam, w, s, dim, data["normals"]


def radial(X, lam, w, normals):
    """3D: the slave vertices in the plane normal to the resultant (in-plane coordinates e1, e2 about the
    pressure centroid) and their distance r to the centroid."""
    n = np.array([float((lam * w * c).sum()) for c in normals]) if normals is not None else np.zeros(3)
    if not np.linalg.norm(n) > 0:
        n = np.array([0.0, 0.0, 1.0])
    n = n / np.linalg.norm(n)
    e1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    m = lam * w
    c = (m[:, None] * X).sum(axis=0) / m.sum() if m.sum() > 0 else X.mean(axis=0)
    p1, p2 = (X - c) @ e1, (X - c) @ e2
    return np.hypot(p1, p2), p1, p2


def hertz_from_report(path):
    try:
        with open(path) as fh:
            rep = json.load(fh)
    except (OSError, ValueError) as e:
        fail("cannot read the report '%s': %s" % (path, e))
    hz = rep.get("hertz")
    if not isinstance(hz, dict) or "a_exact" not in hz or "p0_exact" not in hz:
        fail("report '%s' has no hertz.a_exact / hertz.p0_exact (run `rbcontact fom` with -hertz_radius R, "
             "as runs/hertz.opts does, or give --hertz-a and --hertz-p0)" % path)
    return float(hz["a_exact"]), float(hz["p0_exact"])


def main(argv=None):
    p = argparse.ArgumentParser(description="Plot the contact pressure along the slave surface of an rbcontact "
                                            "contact FOM HDF5 output, optionally against Hertz's profile.")
    p.add_argument("h5", help="HDF5 file written by `rbcontact fom -fom_output <file.h5>` with contact on")
    p.add_argument("-o", "--output", help="PNG to write (default: <h5 without .h5>_pressure.png)")
    p.add_argument("--title", default=None, help="scene name shown in the title (default: file name)")
    p.add_argument("--coord", choices=("x", "y", "r"), default=None,
                   help="abscissa: an undeformed coordinate (at the run's mu) of the slave vertices (x, y; default x in 2D) or, in 3D, r "
                        "(the default there): the distance to the pressure centroid in the plane normal to the "
                        "resultant, with a second panel showing the pressure on that plane")
    p.add_argument("--hertz-a", type=float, default=None, help="Hertz contact half-width a (overlay)")
    p.add_argument("--hertz-p0", type=float, default=None, help="Hertz peak pressure p0 (overlay)")
    p.add_argument("--report", default=None,
                   help="fom report (JSON) to take hertz.a_exact and hertz.p0_exact from (overlay)")
    p.add_argument("--active-tol", type=float, default=0.0,
                   help="nodes with lambda > this are active (default 0, as the report's nactive)")
    p.add_argument("--dpi", type=int, default=150, help="resolution (default 150)")
    a = p.parse_args(argv)

    out = a.output or (a.h5[:-3] if a.h5.endswith(".h5") else a.h5) + "_pressure.png"
    coord = a.coord
    if coord is None:  # r for a 3D slave surface; a file that cannot be read is reported by read_contact
        coord = "x"
        try:
            with h5py.File(a.h5, "r") as f:
                if "contact" in f and isinstance(f["contact"], h5py.Group) and "z" in f["contact"]:
                    coord = "r"
        except OSError:
            pass
    lam, w, s, dim, normals = read_contact(a.h5, coord)
    plane = None
    if coord == "r":
        if dim != 3:
            fail("--coord r is for 3D slave surfaces ('%s' is %dD)" % (a.h5, dim))
        s, p1, p2 = radial(s, lam, w, normals)
        plane = (p1, p2)
        print("plot_contact.py: 3D slave surface: the pressure against the distance r to its centroid, and on the contact plane")
    elif dim == 3:
        print("plot_contact.py: 3D slave surface: plotting the pressure against %s only (a projection)" % coord)

    ha, hp0 = None, None
    if a.report:
        ha, hp0 = hertz_from_report(a.report)
    if a.hertz_a is not None:
        ha = a.hertz_a
    if a.hertz_p0 is not None:
        hp0 = a.hertz_p0
    if (ha is None) != (hp0 is None):
        fail("the Hertz overlay needs both a and p0 (--hertz-a and --hertz-p0, or --report)")
    if ha is not None and not (ha > 0 and hp0 > 0):
        fail("Hertz overlay: a = %g and p0 = %g must be > 0" % (ha, hp0))

    # the resultant's norm |sum_i lambda_i w_i n_i| (the report's contact_force); sum lambda_i w_i without normals
    force_vec = [float((lam * w * n).sum()) for n in normals] if normals is not None else None
    order = np.argsort(s, kind="stable")
    s, lam, w = s[order], lam[order], w[order]
    if plane is not None:
        plane = (plane[0][order], plane[1][order])
    active = lam > a.active_tol
    nact = int(active.sum())
    force = float(np.hypot.reduce(force_vec)) if force_vec is not None else float((lam * w).sum())
    pmax = float(lam.max())
    mass = float((lam * w).sum())
    xc = float((lam * w * s).sum() / mass) if mass > 0 else float(s.mean())
    if plane is not None:
        xc = 0.0  # r is measured from the centroid already

    if plane is None:
        fig, ax = plt.subplots(figsize=(8, 4.8), layout="constrained")
    else:
        fig, (ax, axp) = plt.subplots(1, 2, figsize=(12, 5), layout="constrained", gridspec_kw={"width_ratios": [1.4, 1]})
    if plane is None:  # a line along the surface (in 3D, nodes at one r lie all around the centroid: markers only)
        ax.plot(s, lam, "-", color="tab:blue", linewidth=1.0, zorder=2, label="FE nodal pressure $\\lambda_i$")
    ax.plot(s[~active], lam[~active], "o", markersize=3.5, markerfacecolor="white", markeredgecolor="tab:blue",
            zorder=3, label="inactive nodes (%d)" % int((~active).sum()))
    ax.plot(s[active], lam[active], "o", markersize=5, color="tab:red", zorder=4,
            label="active nodes (%d)" % nact)
    if ha is not None:
        xh = np.linspace(xc - ha, xc + ha, 401) if plane is None else np.linspace(0.0, ha, 201)
        ph = hp0 * np.sqrt(np.clip(1.0 - (xh - xc) ** 2 / ha ** 2, 0.0, None))
        ax.plot(xh, ph, "--", color="k", linewidth=1.2, zorder=5,
                label=("Hertz $p_0\\sqrt{1-(x-x_c)^2/a^2}$" if plane is None else "Hertz $p_0\\sqrt{1-r^2/a^2}$") + ", a = %.4g, $p_0$ = %.4g" % (ha, hp0))
    if nact:
        # zoom on the contact zone (with margins), keeping some inactive nodes in view
        lo, hi = float(s[active].min()), float(s[active].max())
        if ha is not None:
            lo, hi = min(lo, xc - ha), max(hi, xc + ha)
        width = max(hi - lo, 1e-12 * max(1.0, abs(lo), abs(hi)))
        lo, hi = lo - 0.3 * width, hi + 0.3 * width
        ax.set_xlim(max(lo, float(s.min()) - 0.02 * width), min(hi, float(s.max()) + 0.02 * width))
    ax.set_ylim(bottom=0.0, top=1.12 * max(pmax, hp0 or 0.0, 1e-300))
    ax.axhline(0.0, color="0.6", linewidth=0.6, zorder=1)
    ax.set_xlabel("%s (undeformed position of the slave vertex at this mu)" % coord if plane is None else
                  "r: distance to the pressure centroid in the contact plane (undeformed positions)")
    if plane is not None:
        sc = axp.scatter(plane[0], plane[1], c=lam, s=6, cmap="viridis", vmin=0.0)
        if ha is not None:
            t = np.linspace(0, 2 * np.pi, 200)
            axp.plot(ha * np.cos(t), ha * np.sin(t), "--", color="k", linewidth=1.0, label="Hertz a")
            axp.legend(fontsize=8, loc="upper right")
        if nact:
            rmax = 1.5 * max(float(s[active].max()), ha or 0.0)
            axp.set_xlim(-rmax, rmax)
            axp.set_ylim(-rmax, rmax)
        axp.set_aspect("equal")
        axp.set_xlabel("contact plane, e1")
        axp.set_ylabel("contact plane, e2")
        axp.set_title("pressure on the slave surface (seen along the resultant)", fontsize=9)
        fig.colorbar(sc, ax=axp, label="contact pressure $\\lambda$")
    ax.set_ylabel("contact pressure $\\lambda$")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="lower center" if plane is None else "lower left", framealpha=0.9)
    title = a.title or os.path.basename(a.h5)
    sub = "%d slave nodes, %d active, max pressure %.4g, resultant %.4g" % (lam.size, nact, pmax, force)
    if nact:
        sub += ", active %s in [%.4g, %.4g]" % (coord, float(s[active].min()), float(s[active].max()))
    else:
        sub += " (no contact: all pressures are zero)"
    fig.suptitle("%s: contact pressure along the slave surface\n%s" % (title, sub), fontsize=10)

    odir = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(odir):
        fail("output directory '%s' does not exist" % odir)
    fig.savefig(out, dpi=a.dpi)
    plt.close(fig)
    print("plot_contact.py: %d slave nodes, %d active, max pressure %.12g, resultant %.12g" % (lam.size, nact, pmax, force))
    print("plot_contact.py: wrote %s" % out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
