#!/usr/bin/python3
"""plot_speed_error.py: speed against error of a reduced model, from the sweep table of
`rbcontact validate ... -validate_sweep -validate_sweep_output <stem>`.

Reads <stem>.json:
  {"rows": [{"N", "R", "Mk", "Mg",            sizes of the truncated ROM
             "online_median_s",               median time of one online solve [s]
             "max_rel_err_u",                 max over the test set, energy norm of A(mu)
             "max_rel_err_lambda",            max over the test set, l2 weighted by the slave mass
             "max_rel_err_force", "failed"}, ...],
   "fom_median_s": t, "scene": name, "ndofs": n}
(JSON has no NaN: errors of rows with failed ROM solves are null) and draws, log-log, the max
relative error over the test set against the time per solve, one series for u and one for lambda,
each point labelled N,R,Mk,Mg; the FOM's median time as a vertical dashed line (the FOM is exact to
the solver tolerance); a top axis with the speedup over the FOM; optional target error lines.
Rows with failed solves are drawn as crosses at the top of the plot.

Several tables (e.g. the ECSW and the EIM ROM, or two meshes) go into one picture, one colour pair each.

Usage: /usr/bin/python3 share/plot_speed_error.py results/ring_on_block/sweep.json [more.json ...] -o speed_error.png \
           [--title ring_on_block] [--targets 1e-3,1e-2] [--dpi 150]
Run it with Debian's /usr/bin/python3 (python3-matplotlib, python3-numpy).
"""
import argparse
import json
import math
import os
import sys


from plot_common import fail, require_plotting

require_plotting(h5py=False)
import numpy as np
import matplotlib
import matplotlib.pyplot as plt
import matplotlib.transforms as mtransforms
import matplotlib.ticker as mticker

SIZES = ("N", "R", "Mk", "Mg")
VALUES = ("online_median_s", "max_rel_err_u", "max_rel_err_lambda")


def number(path, i, row, key, integer=False):
    """row[key] as a float (None -> nan); a clear error naming the file, the row and the key."""
    if key not in row:
        fail("'%s': row %d lacks \"%s\" (it has: %s)" % (path, i, key, ", ".join(sorted(row.keys())) or "nothing"))
    v = row[key]
    if v is None:
        if integer:
            fail("'%s': row %d: \"%s\" is null" % (path, i, key))
        return float("nan")
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        fail("'%s': row %d: \"%s\" is %r, expected a number" % (path, i, key, v))
    if integer and v != int(v):
        fail("'%s': row %d: \"%s\" is %r, expected an integer" % (path, i, key, v))
    return float(v)


def read_table(path):
    if not os.path.isfile(path):
        fail("file '%s' not found (write it with: rbcontact validate ... -validate_sweep "
             "-validate_sweep_output <stem>, which writes <stem>.json)" % path)
    try:
        with open(path) as fh:
            t = json.load(fh)
    except (OSError, UnicodeDecodeError, ValueError) as e:
        fail("cannot read '%s' as JSON: %s" % (path, e))
    if not isinstance(t, dict):
        fail("'%s' is not a sweep table (expected a JSON object with \"rows\")" % path)
    if "rows" not in t:
        hint = ""
        if "sweep_files" in t:
            hint = " This looks like a validate report: give the sweep table it names, %s." % t["sweep_files"]
        elif t.get("stage") == "validate":
            hint = " This looks like a validate report of a run without -validate_sweep."
        fail("'%s' has no \"rows\" (it has: %s).%s" % (path, ", ".join(sorted(t.keys())) or "nothing", hint))
    rows = t["rows"]
    if not isinstance(rows, list) or not rows:
        fail("'%s': \"rows\" is %s, expected a non-empty list of rows" % (path, "empty" if rows == [] else repr(type(rows).__name__)))
    out = []
    for i, row in enumerate(rows):
        if not isinstance(row, dict):
            fail("'%s': row %d is not an object" % (path, i))
        r = {k: int(number(path, i, row, k, integer=True)) for k in SIZES}
        r.update({k: number(path, i, row, k) for k in VALUES})
        r["failed"] = int(number(path, i, row, "failed", integer=True)) if "failed" in row else 0
        r["first_failure"] = row.get("first_failure", "")
        out.append(r)
    fom = t.get("fom_median_s")
    if fom is not None and (isinstance(fom, bool) or not isinstance(fom, (int, float))):
        fail("'%s': \"fom_median_s\" is %r, expected a number" % (path, fom))
    fom = float(fom) if fom is not None else float("nan")
    tol = t.get("fom_tolerance", 1e-8)
    if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not tol > 0:
        fail("'%s': \"fom_tolerance\" is %r, expected a positive number" % (path, tol))
    mc = t.get("Mc")
    return out, (fom, float(tol)), t.get("scene"), t.get("ndofs"), t.get("hyper"), int(mc) if isinstance(mc, (int, float)) else None


def parse_targets(s):
    vals = []
    for tok in s.split(","):
        tok = tok.strip()
        if not tok:
            continue
        try:
            v = float(tok)
        except ValueError:
            fail("--targets: '%s' is not a number (give e.g. --targets 1e-3,1e-2)" % tok)
        if not (v > 0 and math.isfinite(v)):
            fail("--targets: %s must be > 0 (the error axis is logarithmic)" % tok)
        vals.append((v, tok))
    return sorted(dict(vals).items())  # (value, as given), one per value


def ok(v):
    return math.isfinite(v) and v > 0


def label(r, hyper=None):
    if hyper == "ecsw":  # the cubature keeps its points under truncation: N,R only
        return "%d,%d" % (r["N"], r["R"])
    return "%d,%d,%d,%d" % tuple(r[k] for k in SIZES)


def place_labels(fig, ax, labels, avoid):
    """Annotates each (x, y, text, color) at the first of a few offsets around its point where the text
    overlaps no marker, line, other label, text or legend (else where it overlaps least)."""
    fig.canvas.draw()
    rend = fig.canvas.get_renderer()
    box = matplotlib.transforms.Bbox
    obst = [a.get_window_extent(rend) for a in avoid + ax.texts]
    for line in ax.get_lines():  # markers, and samples along the segments (straight on log-log axes)
        if line.get_transform() != ax.transData or not len(line.get_xdata()):
            continue
        d = ax.transData.transform(np.column_stack([line.get_xdata(), line.get_ydata()]))
        for p0, p1 in zip(d[:-1], d[1:]):
            for t in np.linspace(0.0, 1.0, 16):
                q = p0 + t * (p1 - p0)
                obst.append(box.from_extents(q[0] - 2, q[1] - 2, q[0] + 2, q[1] + 2))
        for q in d:
            obst.append(box.from_extents(q[0] - 6, q[1] - 6, q[0] + 6, q[1] + 6))
    frame = ax.get_window_extent(rend)
    # offsets [points] from the point, nearest first; the farther ones get a leader line
    cands = [(dx * s, dy * s, ha, va) for s in (1, 2, 3, 4)
             for dx, dy, ha, va in ((5, 4, "left", "bottom"), (5, -4, "left", "top"), (-5, 4, "right", "bottom"),
                                    (-5, -4, "right", "top"), (0, 7, "center", "bottom"), (0, -7, "center", "top"),
                                    (8, 0, "left", "center"), (-8, 0, "right", "center"))]

    def overlap(bb):
        area = 0.0
        for o in obst:
            w = min(bb.x1, o.x1) - max(bb.x0, o.x0)
            h = min(bb.y1, o.y1) - max(bb.y0, o.y0)
            if w > 0 and h > 0:
                area += w * h
        out = bb.width * bb.height - max(0.0, min(bb.x1, frame.x1) - max(bb.x0, frame.x0)) * \
            max(0.0, min(bb.y1, frame.y1) - max(bb.y0, frame.y0))
        return area + 10.0 * out

    for x, y, text, color in labels:
        best = None
        for dx, dy, ha, va in cands:
            an = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points", ha=ha, va=va, fontsize=7.5,
                             color=color, zorder=4,
                             arrowprops=dict(arrowstyle="-", color=color, lw=0.7, shrinkA=1, shrinkB=5)
                             if abs(dx) > 8 or abs(dy) > 8 else None,
                             bbox=dict(boxstyle="round,pad=0.1", facecolor="white", edgecolor="none", alpha=0.75))
            bb = an.get_window_extent(rend).expanded(1.0, 1.0)
            cost = overlap(bb)
            if best is None or cost < best[0]:
                if best is not None:
                    best[1].remove()
                best = (cost, an, bb)
            else:
                an.remove()
            if cost == 0:
                break
        obst.append(best[2])


def main(argv=None):
    p = argparse.ArgumentParser(description="Plot the max relative error against the online time per solve "
                                            "of the ROM truncations in rbcontact validate sweep tables.")
    p.add_argument("json", nargs="+", help="sweep table(s) <stem>.json written by `rbcontact validate -validate_sweep "
                                           "-validate_sweep_output <stem>`; several tables (for instance the EIM and the "
                                           "ECSW hyper-reduction, or two meshes) are drawn in one picture")
    p.add_argument("-o", "--output", help="PNG to write (default: <first json without .json>.png)")
    p.add_argument("--title", default=None, help="scene name shown in the title (default: the table's \"scene\")")
    p.add_argument("--targets", default=None,
                   help="comma-separated target errors drawn as horizontal lines, e.g. 1e-3,1e-2")
    p.add_argument("--dpi", type=int, default=150, help="resolution (default 150)")
    a = p.parse_args(argv)

    first = a.json[0]
    out = a.output or (first[:-5] if first.endswith(".json") else first) + ".png"
    targets = parse_targets(a.targets) if a.targets else []
    tables = []
    for path in a.json:
        rows, (fom, fom_tol), scene, ndofs, hyper, mc = read_table(path)
        tables.append(dict(path=path, rows=rows, fom=fom, fom_tol=fom_tol, scene=scene, ndofs=ndofs, hyper=hyper, mc=mc))
    multi = len(tables) > 1
    title = a.title or tables[0]["scene"] or os.path.basename(first)
    palette = [("tab:blue", "tab:orange"), ("tab:green", "tab:red"), ("tab:purple", "tab:brown"), ("tab:cyan", "tab:olive"),
               ("tab:gray", "tab:pink")]

    # two panels sharing the error axis: the reduced models (their times span a factor of a few) and the FOM
    # (5-6 decades slower): one axis across both squeezed every ROM point and its label into a corner
    fig, (ax, axf) = plt.subplots(1, 2, figsize=(10.0, 6.4), layout="constrained", sharey=True,
                                  gridspec_kw=dict(width_ratios=[4.2, 1.0], wspace=0.02))
    for x_ in (ax, axf):
        x_.set_xscale("log")
        x_.set_yscale("log")
    labels = []  # (x, y, text, color): placed once the axes are final
    xs, ys, bad_all, foms = [], [], [], []
    for ti, t in enumerate(tables):
        cu, cl = palette[ti % len(palette)]
        name = ""
        if multi or t["hyper"]:
            name = "%s%s: " % ((t["hyper"] or "").upper() + (" Mc %d" % t["mc"] if t["hyper"] == "ecsw" and t["mc"] else ""),
                               (", %s dofs" % t["ndofs"]) if multi and t["ndofs"] is not None else "")
        series = [("max_rel_err_u", "u, energy norm", "o", cu, "-"),
                  ("max_rel_err_lambda", "$\\lambda$, weighted $\\ell^2$", "s", cl, "--")]
        good = [r for r in t["rows"] if not r["failed"] and ok(r["online_median_s"])]
        bad_all += [(r, t) for r in t["rows"] if r not in good]
        ys += [r[k] for r in good for k, _, _, _, _ in series if ok(r[k])]
        xs += [r["online_median_s"] for r in t["rows"] if ok(r["online_median_s"])]
        for key, nm, marker, color, ls in series:
            # along the truncation path (sizes increasing): the cubature keeps its points under truncation,
            # so its time is not monotone in the sizes
            order = sorted((i for i, r in enumerate(good) if ok(r[key])), key=lambda i: (good[i]["N"], good[i]["R"], good[i]["Mk"], good[i]["Mg"]))
            pts = [(good[i]["online_median_s"], good[i][key], i) for i in order]
            if not pts:
                continue
            ax.plot([q[0] for q in pts], [q[1] for q in pts], ls, marker=marker, color=color, markersize=6,
                    linewidth=1.0, zorder=3, label="%smax rel. error of %s" % (name, nm))
            labels += [(xi, yi, label(good[i], t["hyper"]), color) for xi, yi, i in pts]
        if ok(t["fom"]):
            foms.append((t["fom"], t["fom_tol"], t["ndofs"]))
    if not ys and not bad_all:
        fail("%s: no row has a positive time and error to plot" % ", ".join(a.json))

    # limits: the ROM times (left) and the FOM times (right) in x, all errors and targets in y
    xlo, xhi = (min(xs), max(xs)) if xs else (1e-5, 1e-4)
    ax.set_xlim(xlo / 1.5, xhi * 1.6)
    if foms:
        flo, fhi = min(f[0] for f in foms), max(f[0] for f in foms)
        axf.set_xlim(flo / 3.0, fhi * 3.0)
    yall = ys + [tv for tv, _ in targets] + [f[1] for f in foms]
    ylo, yhi = (min(yall), max(yall)) if yall else (1e-3, 1.0)
    ylo, yhi = 10 ** math.floor(math.log10(ylo) - 0.15), 10 ** math.ceil(math.log10(yhi) + 0.15)
    ax.set_ylim(ylo, yhi)

    seen = set()
    for fom, fom_tol, ndofs in foms:
        key = ndofs if ndofs is not None else round(math.log10(fom), 2)  # one FOM per mesh (its first table's time)
        if key in seen:
            continue
        seen.add(key)
        tag = ("FOM, %s dofs" % ndofs) if (multi and ndofs is not None) else "FOM"
        axf.axvline(fom, color="k", linestyle="--", linewidth=1.0, zorder=2)
        axf.text(fom, 0.98, "%s (exact to solver tolerance) " % tag, rotation=90, ha="right", va="top",
                 fontsize=7.5, transform=mtransforms.blended_transform_factory(axf.transData, axf.transAxes),
                 bbox=dict(boxstyle="square,pad=0.05", facecolor="white", edgecolor="none", alpha=0.8))
        # the FOM as a point: its error is the solver's tolerance (Kacanov, KKT)
        axf.plot([fom], [fom_tol], marker="*", color="k", markersize=12, linestyle="none", zorder=4,
                 label="%s: median %.3g s, error ~ solver tolerance %.0e" % (tag, fom, fom_tol))
    if len(foms) == 1 or (foms and not multi):
        fom = foms[0][0]
        sec = ax.secondary_xaxis("top", functions=(lambda t: fom / np.maximum(t, 1e-300),
                                                   lambda s: fom / np.maximum(s, 1e-300)))
        sec.set_xlabel("speedup over the FOM (FOM median time / time per solve)", fontsize=9)
    for tv, tok in targets:
        for x_ in (ax, axf):
            x_.axhline(tv, color="tab:green", linestyle=":", linewidth=1.2, zorder=1)
        ax.text(0.995, tv, "target %s" % tok, ha="right", va="bottom", fontsize=8, color="tab:green",
                transform=mtransforms.blended_transform_factory(ax.transAxes, ax.transData))
    if bad_all:  # failed truncations: crosses at the top edge (there is no error to plot)
        trans = mtransforms.blended_transform_factory(ax.transData, ax.transAxes)
        for r, t in bad_all:
            if ok(r["online_median_s"]):
                ax.plot(r["online_median_s"], 0.97, "x", color="tab:red", markersize=8, mew=2, transform=trans,
                        clip_on=False, zorder=5)
                ax.annotate(label(r, t["hyper"]) + " failed", (r["online_median_s"], 0.97), xycoords=trans, xytext=(5, -3),
                            textcoords="offset points", fontsize=7, color="tab:red", va="top")
        ax.plot([], [], "x", color="tab:red", mew=2, label="truncation with failed solves (no error)")

    # the ROM panel spans less than a decade or two: ticks at 1, 2, 3, 5 x 10^k, in microseconds
    ax.xaxis.set_major_locator(mticker.LogLocator(base=10, subs=(1.0, 2.0, 3.0, 5.0)))
    ax.xaxis.set_minor_locator(mticker.LogLocator(base=10, subs=np.arange(1, 10)))
    ax.xaxis.set_major_formatter(mticker.FuncFormatter(lambda t, _: "%g" % float("%.2g" % (t * 1e6))))
    ax.xaxis.set_minor_formatter(mticker.NullFormatter())
    ax.set_xlabel("reduced model: time per online solve [$\\mu$s] (median)")
    axf.set_xlabel("full-order model [s]")
    ax.set_ylabel("max relative error over the test set")
    for x_ in (ax, axf):
        x_.grid(True, which="major", alpha=0.35)
        x_.grid(True, which="minor", alpha=0.12)
    axf.tick_params(labelleft=False)
    # legend below both panels: the plot area is for the points and their labels
    hs, ls_ = ax.get_legend_handles_labels()
    hf, lf = axf.get_legend_handles_labels()
    leg = ax.legend(hs + hf, ls_ + lf, fontsize=7.5, loc="upper center", bbox_to_anchor=(0.6, -0.11), ncol=2, frameon=False)
    place_labels(fig, ax, labels, [leg])
    nrows = sum(len(t["rows"]) for t in tables)
    sub = "point labels: N,R (ECSW: reduced primal and dual sizes) or N,R,Mk,Mg (EIM: + kappa and gap terms); %d truncations" % nrows
    if bad_all:
        sub += ", %d with failed solves" % len(bad_all)
    hidden = ["%s %s" % (label(r, t["hyper"]), "u" if k == "max_rel_err_u" else "lambda") for t in tables for r in t["rows"]
              if not r["failed"] and ok(r["online_median_s"]) for k in ("max_rel_err_u", "max_rel_err_lambda") if not ok(r[k])]
    if hidden:  # zero (exact) or missing errors have no place on a log axis
        sub += "\nnot drawn (error zero or missing): %s" % "; ".join(hidden)
    if bad_all:
        firstf = next((r["first_failure"] for r, _ in bad_all if r["first_failure"]), "")
        if firstf:
            sub += "\nfirst failure: %s" % (firstf if len(firstf) <= 110 else firstf[:107] + "...")
    nd = tables[0]["ndofs"]
    fig.suptitle("%s: ROM speed against error%s\n%s"
                 % (title, (", %s dofs" % nd) if (nd is not None and not multi) else "", sub), fontsize=9.5)

    odir = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(odir):
        fail("output directory '%s' does not exist" % odir)
    fig.savefig(out, dpi=a.dpi)
    plt.close(fig)
    print("plot_speed_error.py: wrote %s" % out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
