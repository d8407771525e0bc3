#!/usr/bin/python3
"""error_estimate.py: benchmark (not a test) of the online error estimate (offline -estimate, docs/error_estimate.md),
the targets of the error-estimate issue.

One offline run per case with -estimate (the bases to the tighter -estimate_pod_tol / -estimate_dual_tol, the answer
with the sizes -pod_tol / -dual_tol choose, the calibration on 20 FOM solves), then `rbcontact validate` on 100 random
test parameters (ring_on_block seed 7, half_disks seed 11; --test-size). For u (energy norm), lambda (slave-mass
weighted l2) and the online contact force: the effectivity estimate / true error (min, 5 %, median, 95 %, max), the
share of the test parameters where the estimate is >= the error (target >= 95 %) and where it is within [1, 20] times
it (target >= 90 %), the largest true error; the online median with and without the estimate (target <= 2x) and the
answer's sizes. --cubature answer|enriched|both: the cubature's fit (-estimate_cubature).

It is a benchmark: it exits 0 unless a run fails. Timings depend on the machine's load.
Usage: /usr/bin/python3 bench/error_estimate.py [--np 2] [--exe build/bin/rbcontact] [--cases ring_on_block half_disks]
           [--cubature enriched] [--test-size 100] [--repeat 20] [--keep] [--json out.json] [--extra-offline "..."]
"""
import argparse
import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASES = {"ring_on_block": ("runs/ring_on_block.opts", "7"), "half_disks": ("runs/half_disks.opts", "11")}


def run(args, np_, cmd):
    full = (["mpirun", "-n", str(np_)] if np_ > 1 else []) + [args.exe] + cmd
    p = subprocess.run(full, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.stderr.write(p.stdout[-3000:])
        sys.exit("error_estimate.py: error: command failed (exit %d): %s" % (p.returncode, " ".join(full)))
    return p.stdout


def load(path):
    with open(path) as f:
        return json.load(f)


def quantile(v, q):
    s = sorted(v)
    return s[min(len(s) - 1, max(0, int(round(q * (len(s) - 1)))))]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--np", type=int, default=2)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build/bin/rbcontact"))
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--cubature", default="enriched", choices=["answer", "enriched", "both"])
    ap.add_argument("--test-size", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=20, help="-validate_repeat (online timing)")
    ap.add_argument("--extra-offline", default="")
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--json", default="")
    args = ap.parse_args()
    if not os.path.exists(args.exe):
        sys.exit("error_estimate.py: %s does not exist (build first)" % args.exe)
    work = tempfile.mkdtemp(prefix="rbc_bench_est_")
    fits = ["answer", "enriched"] if args.cubature == "both" else [args.cubature]
    rows = []
    for name in args.cases:
        opts, seed = CASES[name]
        for fit in fits:
            d = os.path.join(work, "%s_%s" % (name, fit))
            os.makedirs(d)
            run(args, args.np, ["offline", "-options_file", opts, "-rom", d + "/rom.h5", "-estimate", "-estimate_cubature", fit, "-report", d + "/off.json"]
                + shlex.split(args.extra_offline))
            run(args, args.np, ["validate", "-options_file", opts, "-rom", d + "/rom.h5", "-test_type", "random", "-test_size", str(args.test_size),
                                "-test_seed", seed, "-validate_repeat", str(args.repeat), "-report", d + "/val.json"])
            off, val = load(d + "/off.json"), load(d + "/val.json")
            rows.append((name, fit, off, val))
    print("\nTable 1: the online error estimate on %d random test parameters (%d ranks; effectivity = estimate / true error)\n" % (args.test_size, args.np))
    print("| case | cubature | N, R (stored) | Mc | quantity | max error | eff. min | 5 % | median | 95 % | max | >= 1 | in [1, 20] | targets |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    out = []
    for name, fit, off, val in rows:
        ro, e = off["rom"], val["estimate"]
        for q in ("u", "lambda", "force"):
            b = e[q]
            eff = b["effectivity"]
            miss = [] if b["share_above_1"] >= 0.95 and b["share_within_20"] >= 0.9 else ["missed"]
            print("| %s | %s | %d, %d (%d, %d) | %d | %s | %.2e | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f %% | %.0f %% | %s |" % (
                name, fit, ro["N_in_use"], ro["R_in_use"], ro["N"], ro["R"], ro["Mc"], q, max(b["rel_err"]), min(eff), quantile(eff, 0.05), quantile(eff, 0.5),
                quantile(eff, 0.95), max(eff), 100 * b["share_above_1"], 100 * b["share_within_20"], "met" if not miss else "missed"))
        out.append({"case": name, "cubature": fit, "offline": {"rom": ro, "estimate": off["estimate"]}, "estimate": {q: {k: e[q][k] for k in e[q] if not isinstance(e[q][k], list)} for q in ("u", "lambda", "force")},
                    "online_time_s": val["online_time_s"]})
    print("\nTable 2: online time (median over the test parameters of the median of %d solves)\n" % args.repeat)
    print("| case | cubature | answer alone | with the estimate | ratio (target <= 2) | calibration: scale (u, lambda, force) | floor | FOM solves offline (training + calibration) |")
    print("|---|---|---|---|---|---|---|---|")
    for name, fit, off, val in rows:
        t, c = val["online_time_s"], off["estimate"]
        print("| %s | %s | %.1f us | %.1f us | %.2f | %s | %s | %d + %d |" % (name, fit, 1e6 * t["median_without_estimate"], 1e6 * t["median"], t["estimate_cost_ratio"],
                                                                   ", ".join("%.3g" % x for x in c["scale"]), ", ".join("%.2e" % x for x in c["floor"]),
                                                                   off["ntrain"],
                                                                   c["calibration_points"]))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    if args.keep:
        print("kept: " + work)
    else:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
