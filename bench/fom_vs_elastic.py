#!/usr/bin/python3
"""fom_vs_elastic.py: benchmark (not a test) of the contact FOM against one plain elastic solve.

For each mesh refinement K (-mesh_refine K) of a scene (default ring_on_block), runs
  rbcontact fom -options_file runs/<scene>.opts -mesh_refine K -report ...            (contact)
  rbcontact fom -options_file runs/<scene>.opts -mesh_refine K -contact 0 -report ... (elastic)
--repeat times each (under `mpirun -n NP` when --np > 1), reads the reports' time_s and prints

  ndofs, R (ncontact), Kacanov iterations,
  contact FOM time:  core = assembly + factorization + contact + solve, and total
  elastic time:      core = assembly + factorization + solve,           and total
  ratio contact / elastic (core and total), and PASS/FAIL against the target ratio (<= 2).

Each time is the minimum over the --repeat runs (taken per measure). `total` is the wall time of
the whole fom stage (mesh loading and distribution, contact set-up, solve; not the output), so it
contains the same fixed costs in both runs. Before the timed runs, one untimed elastic run per
refinement fills the mesh cache (gmsh is not timed); --no-warmup skips it.

The column `bg cpu` is the CPU time other processes used during the kept runs (from /proc/stat
minus this script's children), in % of all cores: above 10 % a warning says the times are inflated.

It is a benchmark: it always exits 0 unless a run fails or the options are wrong. Results depend
on the machine; see bench/README.md for measured tables.

Usage (from anywhere; paths are relative to the repository root unless absolute):
  /usr/bin/python3 bench/fom_vs_elastic.py [--np 1] [--exe build/bin/rbcontact] [--refine 0 1 2]
      [--repeat 3] [--scene ring_on_block] [--target 2] [--mesh-cache-dir DIR] [--json out.json]
      [--wait-idle SECONDS]
      [-- extra rbcontact options for both runs, e.g. -contact_compliance solves]
"""
import argparse
import datetime
import json
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    sys.stderr.write("fom_vs_elastic.py: error: %s\n" % msg)
    sys.exit(2)


def cpu_busy_seconds():
    """Busy CPU time of the whole machine so far (all cores, seconds), from /proc/stat; None if unknown."""
    try:
        with open("/proc/stat") as fh:
            f = fh.readline().split()
        ticks = [int(v) for v in f[1:9]]  # user nice system idle iowait irq softirq steal
        busy = ticks[0] + ticks[1] + ticks[2] + ticks[5] + ticks[6] + ticks[7]
        return busy / float(os.sysconf("SC_CLK_TCK"))
    except (OSError, ValueError, IndexError):
        return None


def wait_idle(max_wait, threshold=0.10):
    """Waits (at most max_wait seconds) until the machine's CPU use over one second is below
    threshold (fraction of all cores). Returns the seconds waited."""
    if max_wait <= 0 or cpu_busy_seconds() is None:
        return 0.0
    t0, said = time.time(), False
    ncores = os.cpu_count() or 1
    while time.time() - t0 < max_wait:
        b0, w0 = cpu_busy_seconds(), time.time()
        time.sleep(1.0)
        share = (cpu_busy_seconds() - b0) / ((time.time() - w0) * ncores)
        if share < threshold:
            break
        if not said:
            print("  waiting for an idle machine (CPU use %.0f%%, --wait-idle %g s)" % (100 * share, max_wait),
                  flush=True)
            said = True
    return time.time() - t0


def children_cpu_seconds():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_fom(cmd_prefix, exe, scene_opts, refine, contact, extra, report, env, verbose):
    """Runs one fom stage; returns (report dict, background CPU share during the run or None).

    The background share is the CPU time that other processes used on the machine during the run,
    as a fraction of (wall time x cores): 0 on an idle machine, 1 when the other processes kept
    every core busy. It tells whether a time can be trusted."""
    cmd = list(cmd_prefix) + [exe, "fom", "-options_file", scene_opts, "-mesh_refine", str(refine)]
    if not contact:
        cmd += ["-contact", "0"]
    cmd += list(extra) + ["-report", report]
    if verbose:
        print("+ " + " ".join(cmd), flush=True)
    if os.path.exists(report):
        os.remove(report)
    b0, c0, t0 = cpu_busy_seconds(), children_cpu_seconds(), time.time()
    p = subprocess.run(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True)
    b1, c1, t1 = cpu_busy_seconds(), children_cpu_seconds(), time.time()
    if p.returncode != 0 or not os.path.isfile(report):
        sys.stderr.write(p.stdout)
        fail("run failed (exit code %d): %s" % (p.returncode, " ".join(cmd)))
    bg = None
    if b0 is not None and b1 is not None and t1 > t0:
        bg = max(0.0, ((b1 - b0) - (c1 - c0)) / ((t1 - t0) * (os.cpu_count() or 1)))
    with open(report) as fh:
        return json.load(fh), bg


def core_time(rep, contact):
    t = rep["time_s"]
    keys = ("assembly", "factorization", "contact", "solve") if contact else ("assembly", "factorization", "solve")
    return sum(float(t[k]) for k in keys)


def verdict(ratio, target):
    return "PASS" if ratio <= target else "FAIL"


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    extra = []
    if "--" in argv:
        i = argv.index("--")
        argv, extra = argv[:i], argv[i + 1:]
    p = argparse.ArgumentParser(description="Benchmark: contact FOM time vs one plain elastic solve of the same mesh "
                                            "(rbcontact fom with and without -contact 0). Always exits 0 unless a run "
                                            "fails. Options after `--` go to both rbcontact runs.")
    p.add_argument("--np", type=int, default=1, help="MPI ranks (default 1; > 1 runs under mpirun -n NP)")
    p.add_argument("--exe", default=None,
                   help="rbcontact executable (default: <repo>/build/bin/rbcontact; a relative path is taken "
                        "from the current directory)")
    p.add_argument("--refine", type=int, nargs="+", default=[0, 1, 2], help="mesh refinements (default 0 1 2)")
    p.add_argument("--repeat", type=int, default=1, help="runs per case; the minimum time is kept (default 1)")
    p.add_argument("--scene", default="ring_on_block", help="scene: runs/<scene>.opts (default ring_on_block)")
    p.add_argument("--target", type=float, default=2.0, help="target ratio contact/elastic (default 2)")
    p.add_argument("--mesh-cache-dir", default=None,
                   help="-mesh_cache_dir for the runs (default: $RBC_MESH_CACHE, else rbcontact's default "
                        "./meshcache in the repository root)")
    p.add_argument("--mpirun", default="mpirun", help="MPI launcher (default mpirun)")
    p.add_argument("--no-warmup", dest="warmup", action="store_false",
                   help="skip the untimed warm-up run per refinement (it fills the mesh cache)")
    p.add_argument("--wait-idle", type=float, default=0.0, metavar="SECONDS",
                   help="before each timed run, wait up to SECONDS for the machine's CPU use to drop below 10%% "
                        "(on a shared machine; default 0: do not wait)")
    p.add_argument("--json", default=None, help="also write the results to this JSON file")
    p.add_argument("-v", "--verbose", action="store_true", help="print the commands")
    a = p.parse_args(argv)

    if a.np < 1:
        fail("--np %d must be >= 1" % a.np)
    if a.repeat < 1:
        fail("--repeat %d must be >= 1" % a.repeat)
    if any(r < 0 or r > 8 for r in a.refine):
        fail("--refine values must lie in [0, 8]")
    exe = os.path.abspath(a.exe) if a.exe else os.path.join(ROOT, "build", "bin", "rbcontact")
    if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
        fail("executable '%s' not found: build first (cmake -S . -B build && cmake --build build -j2) "
             "or pass --exe" % exe)
    scene_opts = os.path.join("runs", a.scene + ".opts")
    if not os.path.isfile(os.path.join(ROOT, scene_opts)):
        fail("scene options file '%s' not found in %s" % (scene_opts, ROOT))
    if a.mesh_cache_dir:
        extra = ["-mesh_cache_dir", os.path.abspath(a.mesh_cache_dir)] + extra

    env = dict(os.environ)
    cmd_prefix = []
    if a.np > 1:
        if shutil.which(a.mpirun) is None:
            fail("MPI launcher '%s' not found (--mpirun)" % a.mpirun)
        cmd_prefix = [a.mpirun, "-n", str(a.np)]
        if hasattr(os, "geteuid") and os.geteuid() == 0:  # OpenMPI refuses root without these
            env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
            env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")

    ncores = os.cpu_count()
    print("fom_vs_elastic: scene %s, np %d, refine %s, repeat %d (min kept), target ratio <= %g"
          % (a.scene, a.np, " ".join(map(str, a.refine)), a.repeat, a.target))
    print("  exe %s, %s, %s cores, %s" % (exe, platform.node(), ncores, datetime.date.today().isoformat()))
    if extra:
        print("  extra options: %s" % " ".join(extra))
    if ncores and a.np > ncores:
        print("  warning: %d ranks on %d cores (oversubscribed): times are not meaningful" % (a.np, ncores))
    sys.stdout.flush()

    rows = []
    tmp = tempfile.mkdtemp(prefix="rbc_bench_")
    try:
        for r in a.refine:
            if a.warmup:
                run_fom(cmd_prefix, exe, scene_opts, r, False, extra, os.path.join(tmp, "warm.json"), env, a.verbose)
            best = {"c_core": None, "c_total": None, "e_core": None, "e_total": None}
            bg_of = {}  # background CPU share of the run that gave each kept minimum
            c_best_rep = None
            for _ in range(a.repeat):
                wait_idle(a.wait_idle)
                rc, bgc = run_fom(cmd_prefix, exe, scene_opts, r, True, extra, os.path.join(tmp, "c.json"), env,
                                  a.verbose)
                if not rc.get("contact"):
                    fail("the contact run of scene %s reports contact = false (does the scene define "
                         "-contact_slave/-contact_master?)" % a.scene)
                wait_idle(a.wait_idle)
                re, bge = run_fom(cmd_prefix, exe, scene_opts, r, False, extra, os.path.join(tmp, "e.json"), env,
                                  a.verbose)
                cc, ct = core_time(rc, True), float(rc["time_s"]["total"])
                ec, et = core_time(re, False), float(re["time_s"]["total"])
                if best["c_core"] is None or cc < best["c_core"]:
                    best["c_core"], c_best_rep, bg_of["c_core"] = cc, rc, bgc
                for k, v, bg in (("c_total", ct, bgc), ("e_core", ec, bge), ("e_total", et, bge)):
                    if best[k] is None or v < best[k]:
                        best[k], bg_of[k] = v, bg
                if int(re["ndofs"]) != int(rc["ndofs"]):
                    fail("ndofs differ between the contact (%s) and elastic (%s) runs" % (rc["ndofs"], re["ndofs"]))
            row = {
                "refine": r,
                "ndofs": int(c_best_rep["ndofs"]),
                "R": int(c_best_rep["ncontact"]),
                "nactive": int(c_best_rep["nactive"]),
                "kacanov_iterations": int(c_best_rep["kacanov_iterations"]),
                "contact_core_s": best["c_core"],
                "contact_total_s": best["c_total"],
                "elastic_core_s": best["e_core"],
                "elastic_total_s": best["e_total"],
                "ratio_core": best["c_core"] / best["e_core"] if best["e_core"] > 0 else float("inf"),
                "ratio_total": best["c_total"] / best["e_total"] if best["e_total"] > 0 else float("inf"),
                "contact_time_s": {k: float(v) for k, v in c_best_rep["time_s"].items()},
                "background_cpu": (max(v for v in bg_of.values() if v is not None)
                                   if any(v is not None for v in bg_of.values()) else None),
            }
            row["pass_core"] = row["ratio_core"] <= a.target
            row["pass_total"] = row["ratio_total"] <= a.target
            rows.append(row)
            print("  refine %d done: ndofs %d, R %d, ratio core %.2f, total %.2f"
                  % (r, row["ndofs"], row["R"], row["ratio_core"], row["ratio_total"]), flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    # The table. core = assembly + factorization (+ contact) + solve; total = the whole fom stage.
    hdr = ("refine", "ndofs", "R", "active", "Kacanov", "FOM core", "FOM total", "elastic core", "elastic total",
           "ratio core", "ratio total", "core<=%g" % a.target, "total<=%g" % a.target, "bg cpu")
    lines = []
    for row in rows:
        lines.append((str(row["refine"]), str(row["ndofs"]), str(row["R"]), str(row["nactive"]),
                      str(row["kacanov_iterations"]),
                      "%.3f" % row["contact_core_s"], "%.3f" % row["contact_total_s"],
                      "%.3f" % row["elastic_core_s"], "%.3f" % row["elastic_total_s"],
                      "%.2f" % row["ratio_core"], "%.2f" % row["ratio_total"],
                      verdict(row["ratio_core"], a.target), verdict(row["ratio_total"], a.target),
                      "?" if row["background_cpu"] is None else "%.0f%%" % (100 * row["background_cpu"])))
    w = [max(len(h), *(len(l[i]) for l in lines)) if lines else len(h) for i, h in enumerate(hdr)]
    print()
    print("times in seconds (min over %d run%s); core = assembly + factorization [+ contact] + solve, "
          "total = whole fom stage" % (a.repeat, "s" if a.repeat > 1 else ""))
    print("  ".join(h.rjust(w[i]) for i, h in enumerate(hdr)))
    for l in lines:
        print("  ".join(c.rjust(w[i]) for i, c in enumerate(l)))
    print()
    busy = [row["refine"] for row in rows if row["background_cpu"] is not None and row["background_cpu"] > 0.1]
    print("bg cpu: CPU used by other processes during the kept runs, in % of all cores (max over them).")
    if busy:
        print("warning: other processes used > 10%% of the machine during refine %s: those times are "
              "inflated; rerun on an idle machine" % " ".join(map(str, busy)))
    print()
    print("contact FOM breakdown (the run with the smallest core time), seconds:")
    bh = ("refine", "assembly", "factorization", "contact", "solve", "total")
    print("  ".join(h.rjust(13) for h in bh))
    for row in rows:
        t = row["contact_time_s"]
        print("  ".join(s.rjust(13) for s in [str(row["refine"])] + ["%.3f" % t.get(k, float("nan")) for k in bh[1:]]))

    if a.json:
        out = {"scene": a.scene, "np": a.np, "repeat": a.repeat, "target": a.target, "exe": exe,
               "extra": extra, "host": platform.node(), "cores": ncores,
               "date": datetime.date.today().isoformat(), "rows": rows}
        with open(a.json, "w") as fh:
            json.dump(out, fh, indent=2)
        print("\nwrote %s" % a.json)
    return 0  # a benchmark: FAIL rows do not fail the run


if __name__ == "__main__":
    sys.exit(main())
