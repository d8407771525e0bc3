#!/usr/bin/python3
"""share/refine_training.py: where a tensor-grid training set is too coarse for the multipliers, from its own
snapshots (docs/greedy_training.md "Refining a grid by its sensitivities").

Reads a snapshot file written with -snapshots_sensitivities on a tensor grid (-train_type grid). In every grid cell it
predicts the multipliers at the cell's centre from each of its 2^P corners by a first-order Taylor step
(lambda_a + sum_i dlambda/dmu_i (c_i - a_i), clipped at 0) and ranks the cell by how much these predictions disagree:
max over corner pairs ||pred_a - pred_b||_2 / ||mean pred||_2. Where the multipliers are nearly linear over the cell
the predictions agree; where the active set moves fast or the pressure bends they do not. No FOM solve and no test
data are used. Prints the table of cells and writes the centres of the k largest to a sample file (one point per
line, the -train_type file format); with --with-grid the file also lists the grid's own points first, so that
`offline -train_type file -train_file F -snapshots_from OLD.h5` solves only the new centres.

  /usr/bin/python3 share/refine_training.py snap.h5 --count 8 --out refine.txt [--with-grid]
"""
import argparse
import itertools
import os
import sys

import h5py
import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("snapshots", help="snapshot file of a tensor grid, written with -snapshots_sensitivities")
    ap.add_argument("--count", type=int, default=8, help="number of cell centres to add (default 8)")
    ap.add_argument("--out", required=True, help="sample file to write (one point per line)")
    ap.add_argument("--with-grid", action="store_true", help="list the grid's own points first")
    a = ap.parse_args()
    if a.count < 1:
        sys.exit("refine_training.py: --count %d must be >= 1" % a.count)
    try:
        f = h5py.File(a.snapshots, "r")
    except OSError as e:
        sys.exit("refine_training.py: cannot open the snapshot file '%s': %s" % (a.snapshots, e))
    with f:
        if "snapshots/extra/sensitivity_lambda" not in f:
            sys.exit("refine_training.py: '%s' has no /snapshots/extra/sensitivity_lambda (run the offline stage with -snapshots_sensitivities)" % a.snapshots)
        done = np.array(f["snapshots/done"]).astype(bool)
        mu = np.array(f["snapshots/mu"])
        lam = np.array(f["snapshots/lambda"])
        sens = np.array(f["snapshots/extra/sensitivity_lambda"])
        lo, hi = np.array(f["params/min"]), np.array(f["params/max"])
        train = np.array(f["train/points"])
    if not done.all():
        sys.exit("refine_training.py: '%s' has %d of %d snapshots not done: finish the training set first" % (a.snapshots, int((~done).sum()), len(done)))
    n, P = mu.shape
    R = lam.shape[1]
    sens = sens.reshape(n, P, R)  # stored scaled by the parameter's range: d lambda / d mu_i * (max_i - min_i)
    axes = [np.unique(mu[:, i]) for i in range(P)]
    if int(np.prod([len(x) for x in axes])) != n or min(len(x) for x in axes) < 2:
        sys.exit("refine_training.py: the %d training points of '%s' are not a tensor grid with >= 2 values per parameter" % (n, a.snapshots))
    where = {tuple(np.round(m, 12)): k for k, m in enumerate(mu)}
    cells = []
    for cell in itertools.product(*[range(len(x) - 1) for x in axes]):
        c = np.array([(axes[i][cell[i]] + axes[i][cell[i] + 1]) / 2 for i in range(P)])
        preds = []
        for corner in itertools.product((0, 1), repeat=P):
            k = where[tuple(np.round([axes[i][cell[i] + corner[i]] for i in range(P)], 12))]
            t = (c - mu[k]) / (hi - lo)
            preds.append(np.maximum(lam[k] + t @ sens[k], 0.0))
        preds = np.array(preds)
        scale = max(np.linalg.norm(preds.mean(axis=0)), 1e-300)
        ind = max(np.linalg.norm(preds[p] - preds[q]) for p in range(len(preds)) for q in range(p + 1, len(preds))) / scale
        cells.append((ind, c))
    cells.sort(key=lambda x: -x[0])
    k = min(a.count, len(cells))
    print("cell centre%s  disagreement of the corners' predictions" % ("" if P == 1 else "s"))
    for j, (ind, c) in enumerate(cells):
        print("  %s  %.4f%s" % (" ".join("%.6g" % x for x in c), ind, "  <- added" if j < k else ""))
    pts = ([list(p) for p in train] if a.with_grid else []) + [list(c) for _, c in cells[:k]]
    tmp = a.out + ".tmp"
    with open(tmp, "w") as o:
        o.write("# %s: %d cell centres of largest multiplier disagreement (share/refine_training.py)%s\n"
                % (a.snapshots, k, ", after the %d grid points" % n if a.with_grid else ""))
        for p in pts:
            o.write(" ".join(repr(float(x)) for x in p) + "\n")

    os.replace(tmp, a.out)
    print("wrote %d points to %s" % (len(pts), a.out))


if __name__ == "__main__":
    main()
