#!/usr/bin/python3
"""plot_contact.py: contact pressure along the slave surface of a contact FOM solution.

Reads the /contact group that `rbcontact fom -fom_output f.h5` writes when contact is on:
  /contact/lambda    (R)  nodal contact pressure of each slave vertex (coefficient of the hat
                          function psi_i; lambda >= 0, > 0 on the active nodes)
  /contact/weight    (R)  int psi_i over the slave surface (resultant = sum lambda_i weight_i n_i)
  /contact/x, /contact/y  reference coordinates of the slave vertices
and plots lambda against the position along the slave surface (x by default, sorted), markers +
line, with the active nodes (lambda > --active-tol) highlighted.

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


def fail(msg):
    sys.stderr.write("plot_contact.py: error: %s\n" % msg)
    sys.exit(1)


try:
    import numpy as np
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError as e:  # pragma: no cover
    fail("%s (interpreter %s). Run with /usr/bin/python3 after share/setup.sh "
         "(python3-numpy python3-h5py python3-matplotlib)" % (e, sys.executable))


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
        need = ["lambda", "weight", coord]
        missing = ["/contact/" + n for n in need if n not in g]
        if missing:
            fail("'%s' lacks %s (it has: %s)" % (path, ", ".join(missing),
                                                 ", ".join("/contact/" + k for k in g.keys()) or "nothing"))
        data = {n: np.asarray(g[n][...], dtype=float).ravel() for n in need}
        dim = sum(1 for c in ("x", "y", "z") if c in g)
        # the master normals (files of rbcontact fom have them): the resultant is sum lambda_i w_i n_i
        normals = [np.asarray(g["normal_" + c][...], dtype=float).ravel() for c in ("x", "y", "z")[:dim] if "normal_" + c in g]
    lam, w, s = data["lambda"], data["weight"], data[coord]
    data["normals"] = normals if len(normals) == dim and dim > 0 else None
    if not (lam.shape == w.shape == s.shape):
        fail("/contact datasets disagree in size: lambda %s, weight %s, %s %s" % (lam.shape, w.shape, coord, s.shape))
    if lam.size == 0:
        fail("'%s': the slave surface has no vertices (/contact/lambda is empty)" % path)
    return lam, w, s, dim, data["normals"]


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
    p.add_argument("--coord", choices=("x", "y"), default="x",
                   help="reference coordinate of the slave vertices used as abscissa (default x)")
    p.add_argument("--hertz-a", type=float, default=None, help="Hertz contact half-width a (overlay)")
    p.add_argument("--hertz-p0", type=float, default=None, help="Hertz peak pressure p0 (overlay)")
    p.add_argument("--report", default=None,
                   help="fom report (JSON) to take hertz.a_exact and hertz.p0_exact from (overlay)")
    p.add_argument("--active-tol", type=float, default=0.0,
                   help="nodes with lambda > this are active (default 0, as the report's nactive)")
    p.add_argument("--dpi", type=int, default=150, help="resolution (default 150)")
    a = p.parse_args(argv)

    out = a.output or (a.h5[:-3] if a.h5.endswith(".h5") else a.h5) + "_pressure.png"
    lam, w, s, dim, normals = read_contact(a.h5, a.coord)
    if dim == 3:
        print("plot_contact.py: 3D slave surface: plotting the pressure against %s only (a projection)" % a.coord)

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
    active = lam > a.active_tol
    nact = int(active.sum())
    force = float(np.hypot.reduce(force_vec)) if force_vec is not None else float((lam * w).sum())
    pmax = float(lam.max())
    mass = float((lam * w).sum())
    xc = float((lam * w * s).sum() / mass) if mass > 0 else float(s.mean())

    fig, ax = plt.subplots(figsize=(8, 4.8), layout="constrained")
    ax.plot(s, lam, "-", color="tab:blue", linewidth=1.0, zorder=2, label="FE nodal pressure $\\lambda_i$")
    ax.plot(s[~active], lam[~active], "o", markersize=3.5, markerfacecolor="white", markeredgecolor="tab:blue",
            zorder=3, label="inactive nodes (%d)" % int((~active).sum()))
    ax.plot(s[active], lam[active], "o", markersize=5, color="tab:red", zorder=4,
            label="active nodes (%d)" % nact)
    if ha is not None:
        xh = np.linspace(xc - ha, xc + ha, 401)
        ph = hp0 * np.sqrt(np.clip(1.0 - (xh - xc) ** 2 / ha ** 2, 0.0, None))
        ax.plot(xh, ph, "--", color="k", linewidth=1.2, zorder=5,
                label="Hertz $p_0\\sqrt{1-(x-x_c)^2/a^2}$, a = %.4g, $p_0$ = %.4g" % (ha, hp0))
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
    ax.set_xlabel("%s (reference position of the slave vertex)" % a.coord)
    ax.set_ylabel("contact pressure $\\lambda$")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="lower center", framealpha=0.9)
    title = a.title or os.path.basename(a.h5)
    sub = "%d slave nodes, %d active, max pressure %.4g, resultant %.4g" % (lam.size, nact, pmax, force)
    if nact:
        sub += ", active %s in [%.4g, %.4g]" % (a.coord, float(s[active].min()), float(s[active].max()))
    else:
        sub += " (no contact: all pressures are zero)"
    fig.suptitle("%s: contact pressure along the slave surface\n%s" % (title, sub), fontsize=10)

    odir = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(odir):
        fail("output directory '%s' does not exist" % odir)
    fig.savefig(out, dpi=a.dpi)
    plt.close(fig)
    print("plot_contact.py: wrote %s" % out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
