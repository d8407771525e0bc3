#!/usr/bin/python3
"""hard_cases.py (bench): the whole hard-case table (tests/hard_cases.py holds the cases, their references and
verdicts; ctest -L hard_cases runs the same cases as tests) with times, as markdown for docs/hard_cases.md:
every case on 1 rank, and on 2 ranks the cases that run in parallel.

Usage: /usr/bin/python3 bench/hard_cases.py [--exe build/bin/rbcontact] [--np 1 2] [--cases c1 c2 ...] [--json out.json]
It is a benchmark: timings depend on the machine's load. It exits 1 when a case fails.
"""
import argparse
import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
import hard_cases  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--exe", default=os.path.join(ROOT, "build/bin/rbcontact"))
    ap.add_argument("--np", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--cases", nargs="+", default=list(hard_cases.CASES))
    ap.add_argument("--json", default="")
    args = ap.parse_args()
    rows = []
    for np_ in args.np:
        names = [c for c in args.cases if np_ == 1 or hard_cases.CASES[c][3]]
        ns = argparse.Namespace(exe=args.exe, np=np_, verbose=False, keep=False)
        rows += hard_cases.run_cases(names, ns)
    print("\n| case | ranks | exercises | reference | converged | KKT | accuracy | verdict | time (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        k = "-" if r["kkt"] is None else "%.1e" % r["kkt"]
        acc = r["accuracy"] + ((" [" + r["note"] + "]") if r["note"] else "")
        print("| %s | %d | %s | %s | %s | %s | %s | %s | %.1f |" % (r["case"], r["np"], r["exercises"], r["reference"], "yes" if r["converged"] else "no", k,
                                                                 acc.replace("|", "/"), r["verdict"], r["seconds"]))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    bad = ["%s (np %d)" % (r["case"], r["np"]) for r in rows if r["verdict"] != "pass"]
    print("\n%d rows, %d failed%s" % (len(rows), len(bad), (": " + ", ".join(bad)) if bad else ""))
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
