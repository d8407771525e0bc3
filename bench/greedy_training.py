#!/usr/bin/python3
"""greedy_training.py: benchmark (not a test) of the training sets of a scene: which set reaches the ROM
accuracy targets (u <= 1e-4, lambda <= 1e-2, force <= 1e-3, max relative errors on the validate stage's
test set) and how many FOM solves it cost.

For each uniform grid of --grids (k: k x k for a two-parameter scene, k for one parameter; AxB: A points along
the first parameter and B along the second, a rectangular grid; --grids-up-to M adds every A x B grid with A, B >= 2
and A B <= M (and >= --grids-from), so that "the best uniform grid" is not only a square one) and each budget
of --budgets of the greedy training (offline -train_type greedy -greedy_max_solves B, one snapshot file
grown budget after budget: the same picks as separate runs), one offline run with the scene's options
(runs/<scene>.opts) and one `rbcontact validate`. Columns: training set, FOM solves, N, R, Mc, max relative
errors u / lambda / force, the greedy's last max indicator, online median, offline time, targets met.

It is a benchmark: it exits 0 unless a run fails (a validate that fails because the reduced model does not converge
at a test point makes a row "failed", which misses). Timings depend on the machine's load.
Usage: /usr/bin/python3 bench/greedy_training.py [--np 2] [--scene half_disks] [--grids 5 6 4x3 ...] [--grids-up-to M [--grids-from m]]
           [--budgets 12 16 20 24 32 40] [--extra="-greedy_candidates_size 1000"] [--test-seeds 7 3] [--json out.json]
(--extra takes its value after "=" when it starts with a dash.) --test-seeds validates every model on more test
sets too; "met" then means met on all of them.
"""
import argparse
import json
import os
import shlex
import shutil
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rom_accuracy  # noqa: E402  (its run and load: one way to run a stage and read its report)
from rom_accuracy import load  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TEST = {"half_disks": ["-test_seed", "11"], "ring_on_block": ["-test_seed", "7"]}


def run(args, cmd):
    return rom_accuracy.run(args, args.np, cmd)


def one(args, work, label, train_opts, rom):
    opts = ["-options_file", "runs/%s.opts" % args.scene] + shlex.split(args.extra)
    t0 = time.time()
    run(args, ["offline"] + opts + train_opts + ["-rom", rom, "-report", os.path.join(work, "off.json")])
    t_off = time.time() - t0
    # the scene's test set, then every --test-seeds one (20 points each): the errors are the maxima over them
    sets = [TEST.get(args.scene, [])] + [["-test_seed", str(sd)] for sd in args.test_seeds]
    tests, vals = [], []
    for i, ts in enumerate(sets):
        vj = os.path.join(work, "val%d.json" % i)
        try:
            run(args, ["validate"] + opts + ts + ["-rom", rom, "-report", vj])
        except SystemExit:  # the reduced model failed at a test parameter (validate refuses): a row that missed, with the reason
            off = load(os.path.join(work, "off.json"))
            g = off.get("greedy", {})
            why = load(vj).get("error", "validate failed") if os.path.exists(vj) else "validate failed"
            return dict(set=label, solves=g.get("training_set_size", off["ntrain"]), failed=why.splitlines()[0][:160], met=False)
        vals.append(load(vj))
        tests.append(vals[-1]["test"])
    off, val = load(os.path.join(work, "off.json")), vals[0]
    g = off.get("greedy", {})
    solves = g.get("training_set_size", off["ntrain"])
    row = dict(set=label, solves=solves, N=val["rom"]["N"], R=val["rom"]["R"], Mc=val["rom"].get("Mc", 0),
               u=max(t["max_rel_err_u"] for t in tests), lam=max(t["max_rel_err_lambda"] for t in tests),
               force=max(t["max_rel_err_force"] for t in tests), u_per_set=[t["max_rel_err_u"] for t in tests],
               indicator=(g["rounds"][-1]["max_indicator"] if g.get("rounds") else None),
               online_us=1e6 * val["online_time_s"]["median"], offline_s=t_off)
    row["met"] = row["u"] <= 1e-4 and row["lam"] <= 1e-2 and row["force"] <= 1e-3
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--np", type=int, default=2)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "bin", "rbcontact"))
    ap.add_argument("--scene", default="half_disks")
    ap.add_argument("--grids", nargs="*", default=["5", "6", "7", "8", "9"], help="k (k x k) or AxB (a rectangular grid)")
    ap.add_argument("--grids-up-to", type=int, default=0, help="also every A x B grid, A, B >= 2, with A B <= this many FOM solves")
    ap.add_argument("--grids-from", type=int, default=0, help="with --grids-up-to: only the grids of at least this many FOM solves")
    ap.add_argument("--budgets", type=int, nargs="*", default=[12, 16, 20, 24, 32, 40])
    ap.add_argument("--extra", default="", help="options added to every offline and validate run")
    ap.add_argument("--test-seeds", type=int, nargs="*", default=[],
                    help="more test sets (seeds of 20 random points) besides the scene's: the table's errors are the maxima over all, "
                         "the column 'u per test set' lists each (a set whose error sits at a target shows it)")
    ap.add_argument("--json", default="")
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rbc_greedy_")
    rows = []
    try:
        grids = [tuple(int(c) for c in g.lower().split("x")) if "x" in g.lower() else (int(g), int(g)) for g in args.grids]
        grids += [(a, b) for a in range(2, args.grids_up_to // 2 + 1) for b in range(2, args.grids_up_to // a + 1) if a * b >= args.grids_from]
        for a, b in sorted(set(grids), key=lambda g: (g[0] * g[1], g)):
            rom = os.path.join(work, "grid%dx%d.h5" % (a, b))
            # one count for a square grid (k for a one-parameter scene), else one per parameter
            size = str(a) if a == b else "%d,%d" % (a, b)
            rows.append(one(args, work, "grid %d" % a if a == b else "grid %d x %d" % (a, b), ["-train_type", "grid", "-train_size", size], rom))
            print(rows[-1], flush=True)
        rom = os.path.join(work, "greedy.h5")  # one snapshot file, grown budget after budget
        for b in sorted(args.budgets):
            rows.append(one(args, work, "greedy %d" % b, ["-train_type", "greedy", "-greedy_tol", "1e-12", "-greedy_max_solves", str(b)], rom))
            print(rows[-1], flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    print("\n%s, %d ranks: training sets against the targets (u <= 1e-4, lambda <= 1e-2, force <= 1e-3)" % (args.scene, args.np))
    many = len(args.test_seeds) > 0
    print("| training set | FOM solves | N | R | Mc | u | lambda | force |%s last max indicator | online median | offline | targets |" % (" u per test set |" if many else ""))
    print("|---|---|---|---|---|---|---|---|---|---|---|---|" + ("---|" if many else ""))
    for r in rows:
        if "failed" in r:
            print("| %s | %d | failed: %s |" % (r["set"], r["solves"], r["failed"]))
            continue
        ind = "%.2e" % r["indicator"] if r["indicator"] is not None else "-"
        per = " %s |" % " / ".join("%.2e" % x for x in r["u_per_set"]) if many else ""
        print("| %s | %d | %d | %d | %d | %.2e | %.2e | %.2e |%s %s | %.0f us | %.1f s | %s |" % (
            r["set"], r["solves"], r["N"], r["R"], r["Mc"], r["u"], r["lam"], r["force"], per, ind, r["online_us"], r["offline_s"], "met" if r["met"] else "missed"))
    met = [r for r in rows if r["met"]]
    for kind in ("grid", "greedy"):
        best = min((r for r in met if r["set"].startswith(kind)), key=lambda r: r["solves"], default=None)
        print("fewest FOM solves reaching the targets, %s: %s" % (kind, "%s (%d solves)" % (best["set"], best["solves"]) if best else "none of those run"))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
