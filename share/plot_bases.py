#!/usr/bin/python3
"""Basis diagnostics from rbcontact reports: POD singular value decay (from an `offline
-offline_stop bases` report) and the dual training projection error against R for several dual
types (from `dualbasis` or offline reports, one per type), on one figure (PNG).

  share/plot_bases.py --pod offline.json --dual cpg.json mcpg.json angle.json nmf.json -o bases.png

For the greedy types the curve is the report's dual.history (largest training projection error after
each step); for nmf, whose history is the objective per iteration, the point (r, train_max_err) is
drawn (run nmf for several -dual_r to get a curve; each report adds a point).
"""
import argparse
import json
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit("plot_bases.py: cannot read report '%s': %s" % (path, e))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pod", help="report with pod.singular_values")
    ap.add_argument("--dual", nargs="*", default=[], help="reports with a dual block (one per type or per r)")
    ap.add_argument("-o", "--output", required=True)
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    if a.pod:
        r = load(a.pod)
        if "pod" not in r:
            sys.exit("plot_bases.py: '%s' has no pod block (run offline -offline_stop bases)" % a.pod)
        s = r["pod"]["singular_values"]
        axes[0].semilogy(range(1, len(s) + 1), [max(x / s[0], 1e-17) for x in s], "o-", ms=3)
        # pod.n counts the supremizers too (the whole primal size): the POD's own modes are n - supremizers (the line
        # stood past the singular values before 2026-12-01)
        npod = r["pod"]["n"] - r["pod"].get("supremizers", 0)
        axes[0].axvline(npod, color="gray", ls="--", lw=0.8, label="N_pod = %d (%s)" % (npod, r["pod"]["inner"]))
        axes[0].legend()
    axes[0].set_xlabel("index")
    axes[0].set_ylabel("singular value / first")
    axes[0].set_title("POD of the displacements")
    axes[0].grid(True, which="both", alpha=0.3)
    nmf = []
    for p in a.dual:
        d = load(p).get("dual")
        if d is None:
            sys.exit("plot_bases.py: '%s' has no dual block" % p)
        if d["type"] == "nmf":
            nmf.append((d["r"], d["train_max_rel_err"]))
        else:
            h = d["history"]
            lab = d["type"] + (" (onto the span)" if d["type"] == "angle" else "")
            axes[1].semilogy(range(1, len(h) + 1), [max(x, 1e-17) for x in h], "o-", ms=3, label=lab)
    if nmf:
        nmf.sort()
        axes[1].semilogy([x for x, _ in nmf], [max(y, 1e-17) for _, y in nmf], "s--", ms=4, label="nmf (rel.)")
    axes[1].set_xlabel("R (dual basis size)")
    axes[1].set_ylabel("largest training projection error")
    axes[1].set_title("dual bases")
    axes[1].grid(True, which="both", alpha=0.3)
    if a.dual:
        axes[1].legend()
    if a.title:
        fig.suptitle(a.title)
    fig.tight_layout()
    fig.savefig(a.output, dpi=120)
    print("wrote", a.output)


if __name__ == "__main__":
    main()
