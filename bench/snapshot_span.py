#!/usr/bin/python3
"""snapshot_span.py: benchmark (not a test) of what a training set's snapshots can represent, independent of the
reduced model built from them: the relative l2 best approximation of FOM test solutions by the span of
  u        the training solutions,
  +sens    and their computed sensitivities (-snapshots_sensitivities: the frozen-geometry tangent),
  +fd1     or their first derivatives by forward differences of FOM solutions (step --step of the range),
  +fd2     and their second derivatives (d11, d22, d12) by the same differences,
each set's vectors (derivatives scaled by the range, squared for the second) truncated by an SVD at 3e-6 of the
largest singular value (the POD's -pod_tol 1e-11). Training sets: the greedy's first --budget picks
(-train_type greedy -snapshots_sensitivities), its first --budget-small picks, and the k x k grids of --grids.
The second derivatives cost 5 more FOM solves a point here; the table says what an exact second-order
sensitivity (linear solves with the factor the solve holds) would add to the span. Two-parameter scenes only.

Usage: /usr/bin/python3 bench/snapshot_span.py [--np 2] [--scene half_disks] [--budget 8] [--budget-small 6]
           [--grids 2 3 4] [--step 1e-2] [--test-seeds 11 7] [--keep]
It exits 0 unless a run fails. Written 2026-11-26 for issue #16 (docs/greedy_training.md "Second derivatives").
"""
import argparse
import os
import shutil
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rom_accuracy  # noqa: E402  (its run: one way to run a stage)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STENCIL = [(0, 0), (1, 0), (2, 0), (0, 1), (0, 2), (1, 1)]  # forward differences, turned inward at the box's edges


def solved(path):
    with h5py.File(path, "r") as f:
        s = f["snapshots"]
        done = s["done"][:] > 0
        ex = s["extra"]
        return (s["mu"][:][done], s["u"][:][done],
                ex["sensitivity_u"][:][done] if "sensitivity_u" in ex else None)


def best_errors(V, tests, tol=3e-6):
    U, S, _ = np.linalg.svd(V.T, full_matrices=False)
    U = U[:, :int(np.sum(S > tol * S[0]))]
    return U.shape[1], [max(np.linalg.norm(t - U @ (U.T @ t)) / np.linalg.norm(t) for t in T) for T in tests]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--np", type=int, default=2)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "bin", "rbcontact"))
    ap.add_argument("--scene", default="half_disks")
    ap.add_argument("--budget", type=int, default=8)
    ap.add_argument("--budget-small", type=int, default=6)
    ap.add_argument("--grids", type=int, nargs="*", default=[2, 3, 4])
    ap.add_argument("--step", type=float, default=1e-2)
    ap.add_argument("--test-seeds", type=int, nargs="*", default=[11, 7])
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rbc_span_")
    opts = ["-options_file", "runs/%s.opts" % args.scene]
    run = lambda cmd: rom_accuracy.run(args, args.np, cmd)  # noqa: E731
    try:
        g = os.path.join(work, "greedy.h5")
        run(["offline"] + opts + ["-train_type", "greedy", "-greedy_tol", "1e-12", "-greedy_max_solves", str(args.budget),
                                  "-snapshots_sensitivities", "-snapshots", g, "-rom", os.path.join(work, "g.h5")])
        picks = solved(g)[0]
        with h5py.File(g, "r") as f:
            lo, hi = f["params/min"][:], f["params/max"][:]
        assert len(lo) == 2, "two-parameter scenes only"
        sets = [("greedy %d" % args.budget, picks), ("greedy %d" % args.budget_small, picks[:args.budget_small])]
        for k in args.grids:
            a, b = np.linspace(lo[0], hi[0], k), np.linspace(lo[1], hi[1], k)
            sets.append(("grid %d x %d" % (k, k), np.array([[x, y] for x in a for y in b])))
        tests = []
        for sd in args.test_seeds:
            t = os.path.join(work, "test%d.h5" % sd)
            run(["offline"] + opts + ["-offline_stop", "snapshots", "-train_type", "random", "-train_size", "20",
                                      "-train_seed", str(sd), "-snapshots", t])
            tests.append(solved(t)[1])
        h, rng = args.step, hi - lo
        print("%s, test sets of seeds %s (20 points each), stencil step %g of the range" % (args.scene, args.test_seeds, h))
        print("| training set | FOM solves | vectors | span | " + " | ".join("max err seed %d" % s for s in args.test_seeds) + " |")
        print("|---|---|---|---|" + "---|" * len(args.test_seeds))
        for i, (label, P) in enumerate(sets):
            pts = []
            for p in P:
                sg = np.where(p + 2 * h * rng <= hi + 1e-12, 1.0, -1.0)
                pts += [p + h * rng * np.array([a * sg[0], b * sg[1]]) for a, b in STENCIL]
            pf, sf = os.path.join(work, "set%d.txt" % i), os.path.join(work, "set%d.h5" % i)
            np.savetxt(pf, np.array(pts), fmt="%.15g", delimiter=",")
            run(["offline"] + opts + ["-offline_stop", "snapshots", "-train_type", "file", "-train_file", pf,
                                      "-snapshots_sensitivities", "-snapshots", sf])
            _, u, su = solved(sf)
            n = len(P)
            u, su = u.reshape(n, len(STENCIL), -1), su.reshape(n, len(STENCIL), 2, -1)
            base, sens = u[:, 0], su[:, 0].reshape(2 * n, -1)
            d1, d2 = (u[:, 1] - u[:, 0]) / h, (u[:, 3] - u[:, 0]) / h
            d11 = (u[:, 2] - 2 * u[:, 1] + u[:, 0]) / h ** 2
            d22 = (u[:, 4] - 2 * u[:, 3] + u[:, 0]) / h ** 2
            d12 = (u[:, 5] - u[:, 1] - u[:, 3] + u[:, 0]) / h ** 2
            for lab, V in [("u", base), ("u + sens", np.vstack([base, sens])), ("u + fd1", np.vstack([base, d1, d2])),
                           ("u + sens + fd2", np.vstack([base, sens, d11, d22, d12])),
                           ("u + fd1 + fd2", np.vstack([base, d1, d2, d11, d22, d12]))]:
                k, e = best_errors(V, tests)
                print("| %s | %d | %s | %d | %s |" % (label, n, lab, k, " | ".join("%.2e" % x for x in e)), flush=True)
    finally:
        if args.keep:
            print("kept " + work)
        else:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
