#!/usr/bin/python3
"""fom_speed.py: benchmark (not a test) of the full-order model's speed; prints the tables of bench/README.md.

Tables (each time the minimum over --repeat runs of `rbcontact fom ... -report`, meshing cached by an
untimed warm-up run):
  1. half_disks at mu = (1.0, 0.09): P2 refine 0 and 1, P1 refine 2. Total time (mesh read to
     solution) and its parts, Kacanov iterations, contact force, and the force of the same mesh with the
     reference settings (--reference: PetscFE assembly, TAO BQPIP from zero, no Anderson mixing, two
     factorizations) with their relative difference.
  2. Contact FOM against one loaded elastic solve of the same mesh and matrix (-contact 0 with the slave
     surface clamped: the same dofs but the slave's, a strained body, not a rigid translation), for
     ring_on_block and half_disks at refine 0, 1, 2: total and ratio.
  3. Kacanov iterations: plain (fixed point, no mixing), fixed point with Anderson 3, Newton (the default).
  4. 1 and 2 ranks for half_disks P2 refine 1 (2 ranks: the default partition, whole bodies per rank, and METIS).
  5. `rbcontact dualbasis -dual_type cpg` on a 400 x 120 Hertz-like snapshot matrix (relative tolerance
     1e-3, l-infinity): time per NNLS (the RBCNNLS event of -log_view) with the default warm-started
     active-set method and with -nnls_method tao (BQPIP + polish), and whether picks and history agree.
  6. The offline snapshot stage of ring_on_block (21 radii) at refine 0, 1, 2 on 1 and 2 ranks
     (-offline_stop snapshots; time_s.snapshots of the report): efficiency T1 / (2 T2).

Usage: /usr/bin/python3 bench/fom_speed.py [--exe build/bin/rbcontact] [--repeat 3] [--tables 1 2 3 4]
       [--json out.json]   (tables 1-4 take ~6 min, table 5 ~30 s on the 2-core VM)
It exits 0 unless a run fails. Results depend on the machine (bench/README.md has measured tables).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REFERENCE = ["-fem_assembly", "petscfe", "-fom_qp_tao_type", "bqpip", "-kacanov_type", "fixed_point", "-kacanov_anderson", "0", "-contact_compliance", "redundant"]
SLAVE_CLAMP = {"ring_on_block": ["-dirichlet", "ring_top,block_bottom,slave", "-dirichlet_slave_u", "0,0"],
               "half_disks": ["-dirichlet", "upper_top,lower_bottom,slave", "-dirichlet_slave_u", "0,0"]}


def run(args, np_, scene, extra):
    out = tempfile.mkdtemp(prefix="rbc_fomspeed_")
    rep = os.path.join(out, "r.json")
    cmd = [args.exe, "fom", "-options_file", os.path.join(ROOT, "runs", scene + ".opts")] + extra + ["-report", rep]
    if np_ > 1:
        cmd = ["mpirun", "-n", str(np_)] + cmd
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    if args.verbose:
        print("  $", " ".join(cmd))
    p = subprocess.run(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        print(p.stdout[-3000:])
        sys.exit("fom_speed.py: run failed (exit %d): %s" % (p.returncode, " ".join(cmd)))
    with open(rep) as f:
        return json.load(f)


def best(args, np_, scene, extra):
    """Minimum over --repeat runs of every time_s entry; the other keys from the last run."""
    reps = [run(args, np_, scene, extra) for _ in range(args.repeat)]
    r = dict(reps[-1])
    r["time_s"] = {k: min(x["time_s"][k] for x in reps) for k in reps[-1]["time_s"]}
    return r


def table1(args, rows):
    print("\n## 1. half_disks, mu = (1.0, 0.09), 1 rank (times: min of %d runs, s)\n" % args.repeat)
    print("| case | ndofs | R | Kacanov | total | assembly | factorization | contact | solve | force | force (reference settings) | rel diff |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for deg, ref in ((2, 0), (2, 1), (1, 2)):
        extra = ["-fem_degree", str(deg), "-mesh_refine", str(ref)]
        run(args, 1, "half_disks", extra + ["-contact", "0"])  # warm-up: meshing cached
        r = best(args, 1, "half_disks", extra)
        q = run(args, 1, "half_disks", extra + REFERENCE)
        t = r["time_s"]
        d = abs(r["contact_force"] - q["contact_force"]) / abs(q["contact_force"])
        print("| P%d refine %d | %d | %d | %d | %.2f | %.2f | %.2f | %.2f | %.2f | %.10f | %.10f | %.1e |"
              % (deg, ref, r["ndofs"], r["ncontact"], r["kacanov_iterations"], t["total"], t["assembly"], t["factorization"],
                 t["contact"], t["solve"], r["contact_force"], q["contact_force"], d))
        rows.append({"table": 1, "case": "P%d refine %d" % (deg, ref), "report": r, "reference_force": q["contact_force"]})


def table2(args, rows):
    print("\n## 2. Contact FOM against one loaded elastic solve of the same mesh (1 rank, P1, min of %d runs, s)\n" % args.repeat)
    print("| scene | refine | ndofs | R | Kacanov | contact total | elastic total | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in ("ring_on_block", "half_disks"):
        for ref in (0, 1, 2):
            extra = ["-mesh_refine", str(ref)]
            el = SLAVE_CLAMP[scene] + ["-contact", "0"]
            run(args, 1, scene, extra + el)  # warm-up
            e = best(args, 1, scene, extra + el)
            c = best(args, 1, scene, extra)
            ratio = c["time_s"]["total"] / e["time_s"]["total"]
            print("| %s | %d | %d | %d | %d | %.3f | %.3f | %.2f |" % (scene, ref, c["ndofs"], c["ncontact"], c["kacanov_iterations"],
                                                                     c["time_s"]["total"], e["time_s"]["total"], ratio))
            rows.append({"table": 2, "scene": scene, "refine": ref, "contact": c, "elastic": e, "ratio": ratio})


def table3(args, rows):
    print("\n## 3. Kacanov iterations (tolerances -kacanov_rtol_primal/dual 1e-8)\n")
    print("| scene | next input | iterations | force | rel diff to plain |")
    print("|---|---|---|---|---|")
    for scene in ("half_disks", "ring_on_block", "hertz"):
        plain = None
        for name, opts in (("plain (fixed point, no mixing)", ["-kacanov_type", "fixed_point", "-kacanov_anderson", "0"]),
                           ("fixed point, Anderson 3", ["-kacanov_type", "fixed_point", "-kacanov_anderson", "3"]),
                           ("Newton (default)", ["-kacanov_type", "newton"])):
            r = run(args, 1, scene, opts)
            plain = plain if plain is not None else r["contact_force"]
            print("| %s | %s | %d | %.12f | %.1e |" % (scene, name, r["kacanov_iterations"], r["contact_force"], abs(r["contact_force"] - plain) / plain))
            rows.append({"table": 3, "scene": scene, "type": name, "iterations": r["kacanov_iterations"]})


def table4(args, rows):
    print("\n## 4. Ranks: half_disks P2 refine 1 (min of %d runs, s)\n" % args.repeat)
    print("| ranks | partition | compliance | total | assembly | factorization | contact | solve | force |")
    print("|---|---|---|---|---|---|---|---|---|")
    extra = ["-fem_degree", "2", "-mesh_refine", "1"]
    for np_, part in ((1, []), (2, []), (2, ["-mesh_partitioner", "metis"])):
        r = best(args, np_, "half_disks", extra + part)
        t = r["time_s"]
        print("| %d | %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.12f |" % (np_, r.get("partition", "?"), r.get("compliance", "?"), t["total"], t["assembly"], t["factorization"], t["contact"], t["solve"], r["contact_force"]))
        rows.append({"table": 4, "ranks": np_, "partition": r.get("partition"), "report": r})


def hertz_matrix(path, R=400, m=120, seed=3):
    """Hertz-like pressure profiles p(x) = (1 + a) sqrt(1 - ((x - c) / a)^2)_+ on R nodes of [-1, 1]."""
    import h5py
    import numpy as np
    x = np.linspace(-1, 1, R)
    rng = np.random.default_rng(seed)
    cols = []
    for _ in range(m):
        a, c = 0.1 + 0.4 * rng.random(), -0.4 + 0.8 * rng.random()
        cols.append(np.sqrt(np.clip(1 - ((x - c) / a) ** 2, 0, None)) * (1 + a))
    with h5py.File(path, "w") as f:
        f["L"] = np.array(cols).T


def table5(args, rows):
    print("\n## 5. Cone-projected greedy (dualbasis -dual_type cpg), 400 x 120 Hertz-like snapshots\n")
    print("| NNLS method | NNLS solves | time per NNLS (ms) | dualbasis total (s) | r | same picks and history as tao |")
    print("|---|---|---|---|---|---|")
    out = tempfile.mkdtemp(prefix="rbc_fomspeed_")
    h5 = os.path.join(out, "hertz400x120.h5")
    hertz_matrix(h5)
    res = {}
    for meth in ("activeset", "tao"):
        rep, log = os.path.join(out, meth + ".json"), os.path.join(out, meth + ".log")
        cmd = [args.exe, "dualbasis", "-snapshots", h5 + ":/L", "-dual_type", "cpg", "-dual_tol", "1e-3", "-dual_tol_relative",
               "-nnls_method", meth, "-report", rep, "-log_view", ":" + log]
        p = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if p.returncode != 0:
            print(p.stdout[-3000:])
            sys.exit("fom_speed.py: run failed: %s" % " ".join(cmd))
        count, secs = 0, 0.0
        with open(log) as f:
            for line in f:
                if line.startswith("RBCNNLS"):
                    w = line.split()
                    count, secs = int(w[1]), float(w[3])
        with open(rep) as f:
            d = json.load(f)
        res[meth] = (d, count, secs)
    t = res["tao"][0]["dual"]
    for meth in ("activeset", "tao"):
        d, count, secs = res[meth]
        du = d["dual"]
        same = du["selected"] == t["selected"] and all(abs(x - y) <= 1e-10 * abs(y) or abs(x - y) <= 1e-14 for x, y in zip(du["history"], t["history"]))
        print("| %s | %d | %.3f | %.2f | %d | %s |" % (meth + (" (default, warm-started)" if meth == "activeset" else ""), count, 1e3 * secs / max(count, 1),
                                                     d.get("time_s", {}).get("total", float("nan")) if isinstance(d.get("time_s"), dict) else float("nan"), du["r"], "yes" if same else "NO"))
        rows.append({"table": 5, "method": meth, "nnls": count, "seconds": secs, "same": same})


def table6(args, rows):
    print("\n## 6. Offline snapshot stage, ring_on_block, 21 radii (min of %d runs, s)\n" % args.repeat)
    print("| refine | ndofs | 1 rank | 2 ranks | efficiency |")
    print("|---|---|---|---|---|")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for ref in (0, 1, 2):
        t = {}
        for np_ in (1, 2):
            best_t = None
            for _ in range(args.repeat):
                out = tempfile.mkdtemp(prefix="rbc_fomspeed_")
                rep, snap = os.path.join(out, "r.json"), os.path.join(out, "s.h5")
                cmd = ["mpirun", "-n", str(np_), args.exe, "offline", "-options_file", os.path.join(ROOT, "runs", "ring_on_block.opts"),
                       "-mesh_refine", str(ref), "-offline_stop", "snapshots", "-snapshots", snap, "-report", rep]
                p = subprocess.run(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                if p.returncode != 0:
                    print(p.stdout[-3000:])
                    sys.exit("fom_speed.py: run failed: %s" % " ".join(cmd))
                with open(rep) as f:
                    v = json.load(f)["time_s"]["snapshots"]
                best_t = v if best_t is None else min(best_t, v)
            t[np_] = best_t
        nd = run(args, 1, "ring_on_block", ["-mesh_refine", str(ref), "-contact", "0"])["ndofs"]
        eff = t[1] / (2 * t[2])
        print("| %d | %d | %.2f | %.2f | %.2f |" % (ref, nd, t[1], t[2], eff))
        rows.append({"table": 6, "refine": ref, "t1": t[1], "t2": t[2], "efficiency": eff})


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "bin", "rbcontact"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tables", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6])
    ap.add_argument("--json")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args()
    if not os.path.exists(args.exe):
        sys.exit("fom_speed.py: %s not found (build first)" % args.exe)
    rows = []
    for t in args.tables:
        {1: table1, 2: table2, 3: table3, 4: table4, 5: table5, 6: table6}[t](args, rows)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
