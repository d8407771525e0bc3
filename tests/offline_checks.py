#!/usr/bin/python3
"""Checks of the offline snapshot stage, run by ctest (tests/offline.cmake).

  ring        the seed's set-up: ring_on_block, 21 training radii, on 1 rank and on 2 ranks with 2
              subcommunicators: identical snapshot files (u, lambda, contact data).
  half_disks  2 parameters (lower radius, imposed displacement) on a 5 x 5 grid, 2 ranks.
  resume      a run killed (SIGKILL) after a few snapshots, resumed with -snapshots_restart: only the
              missing ones are solved and the file equals a clean run's; the same command again without
              -snapshots_restart refused (it replaced the finished snapshots).
  concurrent  two jobs on one snapshot file: replacing the file another job writes is refused (HDF5's lock),
              and a writer whose file was replaced under it stops with an error.
  mismatch    a snapshot file from another scene / parameter box is refused with a clear error.
  early_options  the bases' options (-pod_*, -dual_*) refused before the first snapshot.
  greedy      -train_type greedy on ring_on_block: the same picks on 1 and 2 ranks, each round's first pick
              the largest indicator, the separation, the snapshot file holding exactly the picks, a
              resumed run continuing where the budget stopped, the ROM validated against the targets.
  snapshots_from  -snapshots_from: a training set extended by new points copies the done snapshots of older files
              (the rows bit for bit), solves only the new points (equal to a clean run's), on 1 and 2 ranks; a missing
              file, another scene's file and a file without the sensitivities this run stores are refused by name.
  sensitivities  -snapshots_sensitivities on half_disks: du/dmu against central differences of FOM solutions,
              the dense, saddle and CG solves, 1 and 2 ranks, the POD and dual basis enriched (on a 3 x 3 grid: the best
              approximation of u, the ROM's u and lambda errors smaller), a file without them and a bad step refused.
  initial_guess  -snapshots_initial_guess nearest (half_disks on the dense dual path, with and without sensitivities;
              sphere_block3d on the saddle path with GAMG): the snapshots of the zero start to the Kacanov tolerance, in
              fewer Kacanov iterations, on 1 rank and on 2 (two groups, each from its own); a bad value refused.
  disk_full   a full disk (a small tmpfs; skipped, exit 77, where it cannot be mounted): the ROM pair's and the snapshot
              file's writes refused with "No space left on device" naming the file, the previous pair kept, nothing left.
"""
import argparse
import atexit
import json
import os
import signal
import shutil
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

FAILED = []
os.environ["HDF5_USE_FILE_LOCKING"] = "FALSE"  # read while another process writes


def workdir(prefix):
    """A temporary directory, removed when the script exits (pass or fail)."""
    d = tempfile.mkdtemp(prefix=prefix)
    atexit.register(shutil.rmtree, d, True)
    return d


def check(cond, msg):
    print(("  ok    " if cond else "  FAIL  ") + msg)
    if not cond:
        FAILED.append(msg)


def cmd(args, np_, opts, extra):
    return ["mpirun", "-n", str(np_), args.exe, "offline", "-options_file", opts, "-offline_stop", "snapshots"] + extra


def run(args, np_, opts, extra, expect_ok=True):
    c = cmd(args, np_, opts, extra)
    p = subprocess.run(c, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if expect_ok and p.returncode != 0:
        print(p.stdout[-4000:])
        sys.exit("command failed (exit %d): %s" % (p.returncode, " ".join(c)))
    return p


def report(path):
    with open(path) as f:
        return json.load(f)


def arrays(path):
    with h5py.File(path, "r") as f:
        out = {k: np.array(f["snapshots/" + k]) for k in ("u", "lambda", "mu", "done", "kacanov_iterations")}
        if "snapshots/extra" in f:
            for k in f["snapshots/extra"]:
                out["extra/" + k] = np.array(f["snapshots/extra/" + k])
    return out


def compare(a, b, tol, what):
    for k in ("u", "lambda", "mu", "extra/contact_gap"):
        if k not in a:
            continue
        scale = max(np.max(np.abs(a[k])), 1e-300)
        d = np.max(np.abs(a[k] - b[k])) / scale
        check(d <= tol, "%s: %s max rel. difference %.1e <= %g" % (what, k, d, tol))
    check(np.array_equal(a["done"], b["done"]), "%s: same done flags" % what)


def ring(args):
    d = workdir("rbc_off_")
    base = ["-train_type", "grid", "-train_size", "21"]
    run(args, 1, "runs/ring_on_block.opts", base + ["-snapshots", d + "/s1.h5", "-report", d + "/r1.json"])
    run(args, 2, "runs/ring_on_block.opts", base + ["-snapshots", d + "/s2.h5", "-report", d + "/r2.json", "-snapshots_subcomm", "2", "-snapshots_monitor"])
    r1, r2 = report(d + "/r1.json"), report(d + "/r2.json")
    for r, n in ((r1, 1), (r2, 2)):
        print("  np %d: %d solves, Kacanov its %s, snapshots %.2f s, total %.2f s, subcomms %d"
              % (n, r["fom_solves"], r["kacanov_iterations"], r["time_s"]["snapshots"], r["time_s"]["total"], r["subcomms"]))
        check(r["ntrain"] == 21 and r["fom_solves"] == 21 and r["resumed"] == 0, "np %d: 21 training radii solved" % n)
        check(r["kacanov_iterations"]["max"] <= 15, "np %d: at most 15 Kacanov iterations" % n)
        check(r["affine_terms"]["A"] == 1 and r["affine_terms"]["f"] == 1, "np %d: affine terms A 1, f 1 (2D dilation leaves the stiffness unchanged)" % n)
    check(r2["subcomms"] == 2 and r2["nranks"] == 2, "np 2 ran with 2 subcommunicators")
    a1, a2 = arrays(d + "/s1.h5"), arrays(d + "/s2.h5")
    check(np.all(a1["done"] == 1), "all 21 snapshots done")
    mu = a1["mu"][:, 0]
    check(np.allclose(mu, 0.95 + 0.01 * np.arange(21), rtol=0, atol=1e-14), "training radii 0.95, 0.96, ..., 1.15")
    compare(a1, a2, 1e-10, "np1 vs np2 (2 subcomms)")
    check(np.all(a1["lambda"] >= 0), "multipliers >= 0")
    # format 2: no dense contact matrices (the offline stage reassembles them from u; docs/snapshot_file.md)
    with h5py.File(d + "/s1.h5", "r") as f:
        version = int(f.attrs["format_version"])
    check(version == 2 and "extra/contact_K" not in a1 and "extra/contact_dofs" not in a1 and "extra/contact_gap" in a1,
          "format_version %d, extras %s: no contact_K / contact_dofs" % (version, sorted(k for k in a1 if k.startswith("extra/"))))


def half_disks(args):
    d = workdir("rbc_off_")
    run(args, 2, "runs/half_disks.opts", ["-train_type", "grid", "-train_size", "5", "-snapshots", d + "/s.h5", "-report", d + "/r.json"])
    r = report(d + "/r.json")
    print("  half_disks: %d solves, Kacanov its %s, snapshots %.2f s, affine terms %s" % (r["fom_solves"], r["kacanov_iterations"], r["time_s"]["snapshots"], {k: r["affine_terms"][k] for k in ("A", "f")}))
    check(r["ntrain"] == 25 and r["nparams"] == 2 and r["fom_solves"] == 25, "5 x 5 grid of (radius, displacement) solved")
    a = arrays(d + "/s.h5")
    check(np.all(a["done"] == 1), "all 25 snapshots done")
    check(len(np.unique(a["mu"][:, 0])) == 5 and len(np.unique(a["mu"][:, 1])) == 5, "5 radii x 5 displacements")
    check(r["affine_terms"]["f"] == 1, "f has one term (the lifting, scaled by the displacement)")
    check(np.all(a["lambda"] >= 0) and np.all(np.max(a["lambda"], axis=1) > 0), "every snapshot is in contact, multipliers >= 0")


def resume(args):
    d = workdir("rbc_off_")
    base = ["-train_type", "grid", "-train_size", "21"]
    run(args, 1, "runs/ring_on_block.opts", base + ["-snapshots", d + "/clean.h5"])
    path = d + "/killed.h5"
    # the job is the executable itself (singleton MPI), so that SIGKILL reaches the process that writes
    c = cmd(args, 1, "runs/ring_on_block.opts", base + ["-snapshots", path])[3:]
    p = subprocess.Popen(c, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ndone, t0 = 0, time.time()
    while time.time() - t0 < 120 and p.poll() is None:
        try:
            with h5py.File(path, "r") as f:
                ndone = int(np.sum(np.array(f["snapshots/done"])))
        except Exception:
            ndone = 0
        if ndone >= 5:
            p.send_signal(signal.SIGKILL)
            break
        time.sleep(0.05)
    p.wait()
    check(ndone >= 5 and ndone < 21, "run killed (SIGKILL) with %d of 21 snapshots done" % ndone)
    with h5py.File(path, "r") as f:
        kept = int(np.sum(np.array(f["snapshots/done"])))
    check(kept >= ndone, "the killed file is readable and keeps its %d finished snapshots" % kept)
    # the killed job resubmitted with its own command (-offline_stop snapshots, no -snapshots_restart): until 2026-11-29
    # the file was replaced and every finished snapshot solved again, without a word; now refused, the file untouched
    p = run(args, 1, "runs/ring_on_block.opts", base + ["-snapshots", path], expect_ok=False)
    with h5py.File(path, "r") as f:
        still = int(np.sum(np.array(f["snapshots/done"])))
    check(p.returncode != 0 and ("holds %d finished snapshots (of 21): resume it with -snapshots_restart" % kept) in p.stdout and "-snapshots_restart 0" in p.stdout and still == kept,
          "the same command again: refused, naming -snapshots_restart and -snapshots_restart 0; the %d snapshots kept" % still)
    run(args, 2, "runs/ring_on_block.opts", base + ["-snapshots", path, "-snapshots_restart", "-report", d + "/r.json"])
    r = report(d + "/r.json")
    check(r["resumed"] == kept and r["fom_solves"] == 21 - kept, "restart solved only the missing %d (resumed %d)" % (r["fom_solves"], r["resumed"]))
    compare(arrays(d + "/clean.h5"), arrays(path), 1e-10, "resumed vs clean run")
    leftovers = [f for f in os.listdir(d) if ".tmp." in f]
    check(not leftovers, "no temporary files left (%s)" % leftovers)


def concurrent(args):
    """Two jobs given the same snapshot file (found by an audit, 2026-11-29): a job creating the file replaced it under
    one that was writing it, which went on writing into the unlinked file and ended with exit 0, its snapshots lost.
    HDF5's file lock is on for the jobs here (this script turns it off for its own reads)."""
    d = workdir("rbc_off_")
    env = dict(os.environ)
    env.pop("HDF5_USE_FILE_LOCKING", None)
    path = d + "/busy.h5"
    base = ["-train_type", "grid", "-train_size", "400", "-snapshots", path]

    def start():
        c = cmd(args, 1, "runs/ring_on_block.opts", base)[3:]  # singleton MPI: the process that writes
        p = subprocess.Popen(c, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
        t0, n = time.time(), 0
        while time.time() - t0 < 120 and p.poll() is None and n < 1:
            try:
                with h5py.File(path, "r") as f:
                    n = int(np.sum(np.array(f["snapshots/done"])))
            except Exception:
                n = 0
            time.sleep(0.05)
        return p, n

    # a second job asked to replace the file (-snapshots_restart 0) while the first writes it: refused
    a, n = start()
    c = cmd(args, 1, "runs/ring_on_block.opts", ["-train_type", "grid", "-train_size", "3", "-snapshots", path, "-snapshots_restart", "0"])
    b = subprocess.run(c, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    running = a.poll() is None
    a.kill()
    a.wait()
    with h5py.File(path, "r") as f:
        ntrain = len(f["train/points"])
    check(n >= 1 and running and b.returncode != 0 and "another job is writing it (HDF5's file lock): not replaced under that job" in b.stdout and ntrain == 400,
          "a job replacing the file another job writes: refused (exit %d), the writer's file kept (%d training points)" % (b.returncode, ntrain))
    # the file replaced under the writer by another process (a rename): the writer stops at its next snapshot
    os.remove(path)
    a, n = start()
    shutil.copy(path, d + "/copy.h5")
    os.replace(d + "/copy.h5", path)
    try:
        out, _ = a.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        a.kill()
        out, _ = a.communicate()
    check(n >= 1 and a.returncode != 0 and "was replaced or removed while this run was writing it" in out,
          "the file replaced under the writer: it stops with an error naming that (exit %s)" % a.returncode)


def mismatch(args):
    d = workdir("rbc_off_")
    run(args, 1, "runs/ring_on_block.opts", ["-train_type", "grid", "-train_size", "3", "-snapshots", d + "/s.h5"])
    cases = [("another scene", "runs/half_disks.opts", ["-train_type", "grid", "-train_size", "3"]),
             ("another parameter box", "runs/ring_on_block.opts", ["-train_type", "grid", "-train_size", "3", "-mu_max", "1.1"]),
             ("another mesh", "runs/ring_on_block.opts", ["-train_type", "grid", "-train_size", "3", "-mesh_refine", "1"]),
             # (not in the scene hash until 2026-11-29: the resumed file mixed two contact quadratures)
             ("another contact quadrature", "runs/ring_on_block.opts", ["-train_type", "grid", "-train_size", "3", "-contact_quadrature_subdivisions", "8"])]
    for what, opts, extra in cases:
        p = run(args, 1, opts, extra + ["-snapshots", d + "/s.h5", "-snapshots_restart"], expect_ok=False)
        msg = [l for l in p.stdout.splitlines() if "error" in l.lower()][:1]
        print("  %s -> exit %d: %s" % (what, p.returncode, msg[0] if msg else p.stdout[-300:]))
        check(p.returncode != 0 and "s.h5" in p.stdout and "differs" in p.stdout, "%s: refused, the message names the file and the field that differs" % what)
        check("Segmentation" not in p.stdout and "SEGV" not in p.stdout, "%s: no crash" % what)
    with h5py.File(d + "/s.h5", "r") as f:
        check(int(np.sum(np.array(f["snapshots/done"]))) == 3, "the refused file is untouched")
    # dualbasis on an unfinished snapshot file: said (it was used without a word)
    shutil.copy(d + "/s.h5", d + "/s2.h5")
    with h5py.File(d + "/s2.h5", "r+") as f:
        f["snapshots/done"][1] = 0
    p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/s2.h5"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode == 0 and "holds 2 of its 3 snapshots (an unfinished run)" in p.stdout, "dualbasis on an unfinished snapshot file: a warning naming the count")
    def bases_from_tampered(name, ds, row, val):
        """The bases step on a copy of s.h5 whose done row `row` of /snapshots/<ds> has `val` in its middle entry."""
        bad = d + "/%s.h5" % name
        shutil.copy(d + "/s.h5", bad)
        with h5py.File(bad, "r+") as f:
            x = np.array(f["snapshots/" + ds][row])
            if x.ndim == 0:  # a 1D dataset (/snapshots/seconds): the row's one value
                x = val
            else:
                x[len(x) // 2] = val
            f["snapshots/" + ds][row] = x
        return subprocess.run(["mpirun", "-n", "1", args.exe, "offline", "-options_file", "runs/ring_on_block.opts", "-train_type", "grid", "-train_size", "3",
                               "-offline_stop", "bases", "-snapshots", bad, "-rom", d + "/never.h5"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)

    # a finished row holding a NaN (or inf): the bases step names the file, the dataset and the row
    # (a huge finite value, 1e300: the POD said "the snapshots are all zero", validate printed "max rel err u -nan", exit 0)
    for ds, row, val, word in (("u", 1, np.nan, "non-finite"), ("lambda", 2, np.inf, "non-finite"), ("u", 2, 1e300, "huge (>= 1e150)")):
        p = bases_from_tampered("bad_" + ds, ds, row, val)
        msg = [l for l in p.stdout.splitlines() if "error" in l.lower()][:1]
        print("  %s row of %s -> exit %d: %s" % (word, ds, p.returncode, msg[0] if msg else p.stdout[-300:]))
        check(p.returncode != 0 and ("bad_%s.h5" % ds) in p.stdout and ("row %d " % row) in p.stdout and ("/snapshots/" + ds) in p.stdout and word in p.stdout,
              "%s value in a done row of /snapshots/%s: refused naming the file, the row and the dataset" % (word, ds))
        check(not os.path.exists(d + "/never.h5"), "no ROM written from the corrupt %s row" % ds)
    # a finished row whose parameter is not its training point, or with a negative multiplier (resumed without a word
    # before 2026-11-29; the negative one failed later in the dual basis without naming the file)
    for ds, row, val, words in (("mu", 0, 1.1, "is not training point 1"), ("lambda", 1, -5.0, "negative multiplier")):
        p = bases_from_tampered("odd_" + ds, ds, row, val)
        check(p.returncode != 0 and ("odd_%s.h5" % ds) in p.stdout and ("row %d " % row) in p.stdout and words in p.stdout and not os.path.exists(d + "/never.h5"),
              "a done row of /snapshots/%s with %s: refused naming the file and the row, no ROM" % (ds, words))
    # the provenance of a done row: a NaN solve time (validate's FOM time and speedup from -test_snapshots turned NaN)
    # and a negative or infinite KKT residual were accepted before 2026-12-01; a NaN residual means "not given"
    for ds, row, val, words in (("seconds", 1, np.nan, "a solve time is a finite number"), ("kkt", 2, -1.0, "a KKT residual is a norm"),
                                ("kkt", 0, np.inf, "a KKT residual is a norm")):
        p = bases_from_tampered("prov_" + ds, ds, row, val)
        check(p.returncode != 0 and ("prov_%s.h5" % ds) in p.stdout and ("row %d " % row) in p.stdout and ("/snapshots/" + ds) in p.stdout and words in p.stdout
              and not os.path.exists(d + "/never.h5"), "%s in a done row of /snapshots/%s: refused naming the file, the row and the dataset, no ROM" % (val, ds))
    p = bases_from_tampered("prov_kkt_nan", "kkt", 1, np.nan)
    check(p.returncode == 0, "a NaN KKT residual (not given) is accepted")
    # a header declaring 1e12 training points of no parameter (review of 2026-12-04): every dataset it names is empty,
    # so the stored-size guard passed, and 1e12 empty points were allocated (std::bad_alloc, blamed on "a size option")
    shutil.copy(d + "/s.h5", d + "/huge.h5")
    with h5py.File(d + "/huge.h5", "r+") as f:
        f.attrs["ntrain"], f.attrs["nparams"] = np.int64(10 ** 12), np.int64(0)
        for ds, shape in (("params/names", (0,)), ("params/min", (0,)), ("params/max", (0,)), ("train/points", (10 ** 12, 0))):
            dt = f[ds].dtype
            del f[ds]
            f.create_dataset(ds, shape=shape, dtype=dt)
    p = subprocess.run(["mpirun", "-n", "1", args.exe, "offline", "-options_file", "runs/ring_on_block.opts", "-train_type", "grid", "-train_size", "3",
                        "-offline_stop", "bases", "-snapshots", d + "/huge.h5", "-snapshots_restart", "-rom", d + "/never.h5"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "huge.h5" in p.stdout and "attributes ntrain 1000000000000" in p.stdout and "out of memory" not in p.stdout,
          "a snapshot file declaring 1e12 training points of no parameter: refused naming the file and the attribute (exit %d)" % p.returncode)
    # datasets of zero rows store nothing, so the stored-size guard passed any other extent (audit of 2026-12-04): an
    # extra of 0 x 2^50 (-snapshots_sensitivities asked for a row of 2^50 values: std::bad_alloc, exit 134) and a header
    # ndofs of 2^31 - 1 over an empty /snapshots/u (rows sized from the header before the dataset was seen)
    shutil.copy(d + "/s.h5", d + "/zero_extra.h5")
    with h5py.File(d + "/zero_extra.h5", "r+") as f:
        f.create_dataset("snapshots/extra/sensitivity_u", shape=(0, 2 ** 50), dtype="f8")
    p = subprocess.run(["mpirun", "-n", "1", args.exe, "offline", "-options_file", "runs/ring_on_block.opts", "-train_type", "grid", "-train_size", "3", "-snapshots_sensitivities",
                        "-offline_stop", "bases", "-snapshots", d + "/zero_extra.h5", "-snapshots_restart", "-rom", d + "/never.h5"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "zero_extra.h5" in p.stdout and "/snapshots/extra/sensitivity_u has shape 0 x 1125899906842624, expected ntrain (3)" in p.stdout and "bad_alloc" not in p.stdout,
          "an extra dataset of 0 x 2^50: refused naming the file and the dataset (exit %d)" % p.returncode)
    shutil.copy(d + "/s.h5", d + "/zero_u.h5")
    with h5py.File(d + "/zero_u.h5", "r+") as f:
        f.attrs["ndofs"] = np.int64(2 ** 31 - 1)
        del f["snapshots/u"]
        f.create_dataset("snapshots/u", shape=(0, 2 ** 31 - 1), dtype="f8")
    p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/zero_u.h5"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "zero_u.h5" in p.stdout and "/snapshots/u has shape 0 x 2147483647, expected 3 x 2147483647" in p.stdout,
          "an empty /snapshots/u under a header ndofs of 2^31 - 1: refused naming the file and the dataset's shape (exit %d)" % p.returncode)
    # the options text in the dataset /options (written when it is too long for an attribute): read as one fixed-length
    # string; a dataset of 64 of them was read 64 x its size into a buffer of one (a heap overflow, review of 2026-12-04)
    with h5py.File(d + "/s.h5", "r") as f:
        text = f.attrs["options"]
        text = text.decode() if isinstance(text, bytes) else str(text)
    for name, data in (("opt_one", np.array(text.encode(), dtype="S%d" % (len(text) + 1))),
                       ("opt_many", np.array([text.encode()] * 64, dtype="S%d" % (len(text) + 1))),
                       ("opt_vlen", np.array([text], dtype=h5py.string_dtype()))):
        shutil.copy(d + "/s.h5", d + "/%s.h5" % name)
        with h5py.File(d + "/%s.h5" % name, "r+") as f:
            f.attrs["options"] = np.bytes_(b"@/options")
            f["options"] = data
        p = subprocess.run(["mpirun", "-n", "1", args.exe, "offline", "-options_file", "runs/ring_on_block.opts", "-train_type", "grid", "-train_size", "3",
                            "-offline_stop", "bases", "-snapshots", d + "/%s.h5" % name, "-snapshots_restart", "-rom", d + "/never.h5"],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if name == "opt_one":
            check(p.returncode == 0, "the options text in a dataset /options (one fixed-length string): read, the bases built")
        else:
            check(p.returncode != 0 and "%s.h5" % name in p.stdout and "dataset /options is not one fixed-length string" in p.stdout and "SEGV" not in p.stdout,
                  "a dataset /options of %s: refused naming the file and the dataset (exit %d)" % ("64 strings" if name == "opt_many" else "a variable-length string", p.returncode))


def early_options(args):
    """The bases' options refused before any snapshot is solved (hours on a real scene): until 2026-11-29 -pod_tol,
    -pod_n, -pod_inner, -dual_type and -dual_tol were refused only after the last snapshot, and -dual_tol 1 with
    -dual_tol_relative gave "supremizers: 0 supremizers for 0 dual vectors"."""
    d = workdir("rbc_off_")
    cases = [(["-pod_tol", "2"], "-pod_tol 2. must lie in [0, 1)"), (["-pod_n", "0"], "-pod_n 0 must be >= 1"),
             (["-pod_inner", "bogus"], "Unknown option bogus for -pod_inner"), (["-dual_type", "bogus"], "Unknown option bogus for -dual_type"),
             (["-dual_tol", "1"], "-dual_tol 1. with -dual_tol_relative must be < 1"), (["-pod_method", "svd"], "-pod_method svd computes the l2 POD only"),
             # refused after the snapshots (and, for the estimate's, after the ROM was written) until 2026-12-01
             (["-pod_n", "6"], "-pod_n 6 must lie in [1, 5] (the number of snapshots)"), (["-estimate", "-estimate_safety", "0.5"], "-estimate_safety 0.5 out of range [1, 100]"),
             (["-estimate", "-estimate_calibration_size", "-1"], "-estimate_calibration_size -1 out of range"),
             (["-eim_quadrature_subdivisions", "0"], "-eim_quadrature_subdivisions 0 out of range [1, 64]"), (["-eim_patch_rings", "-1"], "-eim_patch_rings -1 out of range [0, 20]"),
             (["-eim_patch_rings"], "option -eim_patch_rings is given without a value"),
             (["-dual_tol_relative", "0", "-dual_tol", "inf"], "-dual_tol inf. must be a finite number >= 0"),
             (["-estimate", "-estimate_pod_tol", "0.5"], "-estimate_pod_tol 0.5 must lie in [0, -pod_tol")]
    for extra, words in cases:
        c = ["mpirun", "-n", "2", args.exe, "offline", "-options_file", "runs/ring_on_block.opts", "-train_size", "5", "-snapshots_monitor", "-rom", d + "/r.h5"] + extra
        p = subprocess.run(c, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        check(p.returncode != 0 and words in p.stdout and "  snapshot " not in p.stdout and not os.path.exists(d + "/r.snapshots.h5"),
              "%s: refused before any snapshot, naming it (%s)" % (" ".join(extra), words))
    # a file solved without sensitivities, resumed with them: refused before the remaining snapshots (was after them)
    run(args, 1, "runs/ring_on_block.opts", ["-train_size", "3", "-snapshots", d + "/s3.h5"])
    with h5py.File(d + "/s3.h5", "r+") as f:  # one snapshot left to solve
        f["snapshots/done"][2] = 0
    p = run(args, 1, "runs/ring_on_block.opts", ["-train_size", "3", "-snapshots", d + "/s3.h5", "-snapshots_restart", "-snapshots_sensitivities", "-snapshots_monitor"], expect_ok=False)
    check(p.returncode != 0 and "2 of the 2 finished snapshots of" in p.stdout and "solved without sensitivities" in p.stdout and "  snapshot " not in p.stdout,
          "-snapshots_sensitivities on a file solved without them: refused before any snapshot")
    # a file whose sensitivity dataset exists but one done row was solved without them (a run resumed without the
    # option writes no sensitivity row: zeros): refused before the remaining snapshots, naming the training point
    # (was refused by the bases step only, after them)
    run(args, 1, "runs/ring_on_block.opts", ["-train_size", "3", "-snapshots", d + "/p3.h5", "-snapshots_sensitivities", "-offline_stop", "snapshots"])
    with h5py.File(d + "/p3.h5", "r+") as f:
        f["snapshots/extra/sensitivity_u"][1] = 0.0  # training point 2: as if solved without the option
        f["snapshots/done"][2] = 0  # one snapshot left to solve
    p = run(args, 2, "runs/ring_on_block.opts", ["-train_size", "3", "-snapshots", d + "/p3.h5", "-snapshots_restart", "-snapshots_sensitivities", "-snapshots_monitor"], expect_ok=False)
    check(p.returncode != 0 and "1 of the 2 finished snapshots of" in p.stdout and "(training points 2)" in p.stdout and "  snapshot " not in p.stdout,
          "-snapshots_sensitivities on a file where one done row lacks them: refused before any snapshot, naming the point (2 ranks)")


def bases_warnings(args):
    """What the bases step builds badly, said (audit of 2026-12-01; each exit 0 without a word before): a dual basis
    missing its tolerance, a training set of 1 or 2 points, an absolute -dual_tol that keeps no vector (refused by
    name, it blamed -rom_R), dualbasis on a snapshot file's dataset (read transposed), plot_fields.py on a basis view
    (drawn as a deformed solution)."""
    d = workdir("rbc_off_")

    def run(args, np_, opts, extra, expect_ok=True):  # the whole offline stage (the module's run stops after the snapshots)
        c = ["mpirun", "-n", str(np_), args.exe, "offline", "-options_file", opts] + extra
        p = subprocess.run(c, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if expect_ok and p.returncode != 0:
            print(p.stdout[-4000:])
            sys.exit("command failed (exit %d): %s" % (p.returncode, " ".join(c)))
        return p
    p = run(args, 1, "runs/ring_on_block.opts", ["-train_size", "7", "-dual_max_r", "1", "-rom", d + "/maxr1.h5", "-report", d + "/maxr1.json"])
    check("warning: the dual basis misses its tolerance" in p.stdout and "(-dual_max_r stopped the greedy)" in p.stdout and report(d + "/maxr1.json")["dual"]["tol_reached"] is False,
          "offline -dual_max_r 1: the missed tolerance warned with its reason")
    p = run(args, 1, "runs/ring_on_block.opts", ["-train_size", "7", "-rom", d + "/ok.h5", "-offline_basis_output", d + "/view.h5"])
    check("misses its tolerance" not in p.stdout and "too coarse" not in p.stdout, "offline with the shipped options: neither warning")
    for n in ("1", "2"):
        p = run(args, 1, "runs/ring_on_block.opts", ["-train_size", n, "-rom", d + "/t%s.h5" % n])
        check("the training set is too coarse" in p.stdout, "offline -train_size %s: the too-coarse warning" % n)
    p = run(args, 2, "runs/ring_on_block.opts", ["-train_size", "5", "-rom", d + "/tol10.h5", "-snapshots_restart", "0", "-dual_tol_relative", "0", "-dual_tol", "10"], expect_ok=False)
    check(p.returncode != 0 and "the dual basis is empty: the tolerance 10" in p.stdout and "-dual_tol" in p.stdout and "supremizers" not in p.stdout,
          "an absolute -dual_tol above every snapshot: refused naming -dual_tol (2 ranks)")
    p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/ok.snapshots.h5:/snapshots/lambda"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "names a dataset in the rbcontact snapshot file" in p.stdout, "dualbasis on s.h5:/snapshots/lambda: refused, naming the file form")
    p = subprocess.run(["/usr/bin/python3", "share/plot_fields.py", d + "/view.h5", "-o", d + "/view.png"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "is a basis view" in p.stdout and not os.path.exists(d + "/view.png"), "plot_fields.py on a basis view: refused, no picture")


def bases(args):
    """POD + the four dual types on the seed's set-up; 1 vs 2 ranks; nonnegativity; orthonormality."""
    d = workdir("rbc_off_")
    base = ["-train_type", "grid", "-train_size", "21", "-snapshots", d + "/s.h5", "-pod_tol", "1e-8", "-dual_tol", "1e-3", "-dual_tol_relative"]
    table = []
    for t in ("cpg", "mcpg", "angle", "nmf"):
        extra = ["-dual_type", t, "-pod_supremizers", "0"] + (["-dual_r", "8"] if t == "nmf" else [])
        reps = {}
        for np_ in (1, 2):
            rom = "%s/rom_%s_np%d.h5" % (d, t, np_)
            run(args, np_, "runs/ring_on_block.opts", base + extra + ["-offline_stop", "bases", "-rom", rom, "-report", "%s/%s_np%d.json" % (d, t, np_)])
            reps[np_] = (report("%s/%s_np%d.json" % (d, t, np_)), rom)
        (r1, rom1), (r2, rom2) = reps[1], reps[2]
        dd = r1["dual"]
        cond = [c for c in (dd["gram_cond"] or []) if c is not None]
        table.append((t, dd["r"], dd["train_max_err"], dd["train_max_rel_err"], cond[-1] if len(cond) == len(dd["gram_cond"] or [0]) else float("inf"), r1["nnls"]["retries"]))
        if t in ("cpg", "mcpg"):
            check(dd["history"][-1] <= dd["tol_abs"] * (1 + 1e-12) or dd["r"] == 21,
                  "%s stops at the tolerance: largest projection error %.3e <= %.3e (1e-3 x largest snapshot norm), R = %d" % (t, dd["history"][-1], dd["tol_abs"], dd["r"]))
        check(r1["pod"]["orthonormality_error"] <= 1e-10, "%s: POD modes orthonormal in the energy inner product (%.1e)" % (t, r1["pod"]["orthonormality_error"]))
        with h5py.File(rom1, "r") as f1, h5py.File(rom2, "r") as f2:
            W1, W2 = np.array(f1["dual/basis"]), np.array(f2["dual/basis"])
            V1, V2 = np.array(f1["pod/modes"]), np.array(f2["pod/modes"])
            s1, s2 = np.array(f1["pod/singular_values"]), np.array(f2["pod/singular_values"])
        check(W1.min() >= 0, "%s: every dual basis vector is nonnegative (min entry %.3e)" % (t, W1.min()))
        check(W1.shape == W2.shape and np.max(np.abs(W1 - W2)) <= 1e-10 * np.max(np.abs(W1)), "%s: dual basis identical on 1 and 2 ranks" % t)
        check(np.max(np.abs(s1 - s2)) <= 1e-10 * s1[0], "%s: POD singular values identical on 1 and 2 ranks" % t)
        if V1.shape == V2.shape:
            sg = np.sign(np.sum(V1 * V2, axis=1))[:, None]
            dv = np.max(np.abs(V1 - sg * V2)) / np.max(np.abs(V1))
        else:
            dv = float("inf")
        check(dv <= 1e-8, "%s: POD modes identical up to sign on 1 and 2 ranks (%.1e)" % (t, dv))
    # supremizer enrichment: N = POD modes + one supremizer per dual vector, still orthonormal
    run(args, 1, "runs/ring_on_block.opts", base + ["-dual_type", "mcpg", "-pod_supremizers", "-offline_stop", "bases", "-rom", d + "/rom_sup.h5", "-report", d + "/sup.json"])
    rs, rp = report(d + "/sup.json"), report(d + "/mcpg_np1.json")
    check(rs["pod"]["supremizers"] == rs["dual"]["r"] and rs["pod"]["n"] == rp["pod"]["n"] + rs["dual"]["r"],
          "supremizers: N = %d POD modes + %d supremizers" % (rp["pod"]["n"], rs["pod"]["supremizers"]))
    check(rs["pod"]["orthonormality_error"] <= 1e-10, "enriched primal basis orthonormal in the energy inner product (%.1e)" % rs["pod"]["orthonormality_error"])
    print("  ring_on_block, 21 radii: dual type | R | max err | max rel err | cond(Gram) | NNLS retries")
    for row in table:
        print("    %-6s %3d  %.3e  %.3e  %.2e  %d" % row)


def dualbasis_import(args):
    """`dualbasis` on a multiplier matrix written by another code (HDF5 dataset and the transposed layout)."""
    d = workdir("rbc_off_")
    x = np.linspace(-1, 1, 120)
    cols = []
    for k in range(15):
        a, c = 0.3 + 0.02 * k, 0.01 * (k - 7)
        cols.append(np.sqrt(np.maximum(0.0, 1 - ((x - c) / a) ** 2)) * (1 + 0.1 * k))
    L = np.array(cols).T  # rows = multipliers, columns = snapshots
    with h5py.File(d + "/ext.h5", "w") as f:
        f["lambda"] = L
    c = [args.exe, "dualbasis", "-snapshots", d + "/ext.h5:/lambda", "-dual_type", "cpg", "-dual_tol", "1e-3", "-dual_tol_relative", "-report", d + "/r.json", "-dual_out", d + "/w.h5"]
    p = subprocess.run(c, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print("  " + p.stdout.strip().splitlines()[-1] if p.stdout.strip() else "  (no output)")
    check(p.returncode == 0, "dualbasis ran on an imported HDF5 dataset (exit %d)" % p.returncode)
    if p.returncode != 0:
        print(p.stdout[-3000:])
        return
    r = report(d + "/r.json")
    check(r["R_fom"] == 120 and r["m"] == 15, "read 120 multipliers x 15 snapshots")
    check(r["dual"]["history"][-1] <= r["dual"]["tol_abs"] * (1 + 1e-12), "cpg stops at 1e-3 x the largest snapshot norm (%.2e <= %.2e, R = %d)" % (r["dual"]["history"][-1], r["dual"]["tol_abs"], r["dual"]["r"]))
    with h5py.File(d + "/w.h5", "r") as f:
        W = np.array(f["dual/basis"])
    check(W.min() >= 0 and W.shape == (r["dual"]["r"], 120), "basis written, nonnegative, %s" % (W.shape,))
    bad = L.copy()
    bad[3, 2] = -1.0
    with h5py.File(d + "/neg.h5", "w") as f:
        f["lambda"] = bad
    p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/neg.h5:/lambda"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "negative" in p.stdout, "negative multipliers are refused with a clear error")
    # a NaN or an inf among the imported values (review of 2026-12-04: a NaN went into the dual basis, an inf hid every
    # negative entry)
    for v in (np.nan, np.inf):
        bad = L.copy()
        bad[5, 4] = v
        with h5py.File(d + "/nf.h5", "w") as f:
            f["lambda"] = bad
        p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/nf.h5:/lambda", "-dual_out", d + "/wnf.h5"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        check(p.returncode != 0 and "non-finite value" in p.stdout and "nf.h5" in p.stdout and "snapshot 4, entry 5" in p.stdout and not os.path.exists(d + "/wnf.h5"),
              "an imported %s is refused naming the file, the snapshot and the entry, no basis written" % v)
    # a dataset of zero rows and 2^40 columns stores nothing (audit of 2026-12-04: 2^40 empty snapshot columns were
    # allocated, std::bad_alloc)
    with h5py.File(d + "/empty.h5", "w") as f:
        f.create_dataset("lambda", shape=(0, 2 ** 40), dtype="f8")
    p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/empty.h5:/lambda"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "empty.h5" in p.stdout and "has shape 0 x 1099511627776: it holds no snapshots" in p.stdout, "a dataset of 0 x 2^40: refused naming it (exit %d)" % p.returncode)
    # a virtual dataset (it reads other files; unmapped, its fill value for any shape) and external raw storage: refused
    with h5py.File(d + "/virt.h5", "w") as f:
        layout = h5py.VirtualLayout(shape=L.shape, dtype="f8")
        layout[:, :] = h5py.VirtualSource(d + "/ext.h5", "lambda", shape=L.shape)
        f.create_virtual_dataset("lambda", layout)
        L.astype("f8").tofile(d + "/raw.bin")
        f.create_dataset("ext", shape=L.shape, dtype="f8", external=[(d + "/raw.bin", 0, L.nbytes)])
    for ds, words in (("lambda", "is a virtual dataset"), ("ext", "has external storage")):
        p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/virt.h5:/" + ds], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        check(p.returncode != 0 and "virt.h5" in p.stdout and words in p.stdout, "a dataset that %s: refused naming it (exit %d)" % (words, p.returncode))
    p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/ext.h5:/nosuch"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "nosuch" in p.stdout, "a missing dataset is an error naming it")
    # a tolerance the basis misses is said (exit 0 and no word before, audit 2026-11-29): the report's dual.tol_reached
    check(r["dual"]["tol_reached"] is True, "cpg at 1e-3: dual.tol_reached true")
    p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/ext.h5:/lambda", "-dual_type", "nmf", "-dual_r", "3", "-dual_tol", "1e-6", "-report", d + "/n.json"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode == 0 and "warning: the basis misses its tolerance" in p.stdout and "nmf has the fixed rank -dual_r" in p.stdout and report(d + "/n.json")["dual"]["tol_reached"] is False,
          "nmf (rank 3) with -dual_tol 1e-6: a warning naming why, dual.tol_reached false")
    # multipliers whose squares overflow or underflow (r = 0 and exit 0 before), or all zero: refused
    for scale, words in ((1e160, "outside [1e-150, 1e150]"), (1e-200, "outside [1e-150, 1e150]"), (0.0, "every multiplier snapshot is zero")):
        with h5py.File(d + "/s.h5", "w") as f:
            f["lambda"] = L * scale
        p = subprocess.run([args.exe, "dualbasis", "-snapshots", d + "/s.h5:/lambda"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        check(p.returncode != 0 and words in p.stdout, "multipliers scaled by %g: refused (%s)" % (scale, words))


def greedy(args):
    d = workdir("rbc_off_")
    base = ["-options_file", "runs/ring_on_block.opts", "-train_type", "greedy", "-greedy_candidates_size", "60", "-greedy_tol", "1e-12"]

    def off(np_, tag, budget, extra=()):
        c = ["mpirun", "-n", str(np_), args.exe, "offline"] + base + ["-greedy_max_solves", str(budget), "-rom", "%s/%s.h5" % (d, tag), "-report", "%s/%s.json" % (d, tag)] + list(extra)
        p = subprocess.run(c, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if p.returncode != 0:
            print(p.stdout[-4000:])
            sys.exit("command failed (exit %d): %s" % (p.returncode, " ".join(c)))
        return report("%s/%s.json" % (d, tag))

    # the default batch (2) on 1 rank, given on 2: the same picks (the default was the number of groups of ranks, 1 here)
    r1, r2 = off(1, "g1", 6, ["-greedy_monitor"]), off(2, "g2", 6, ["-greedy_batch", "2"])
    g1, g2 = r1["greedy"], r2["greedy"]
    check(g1["batch"] == 2 and g2["batch"] == 2, "-greedy_batch: 2 by default on 1 rank (%d), as given on 2 (%d)" % (g1["batch"], g2["batch"]))
    for rd in g1["rounds"]:
        print("  round %d: %d solves, N %d, R %d, max indicator %.3e (residual %.3e, penetration %.3e), picked %s"
              % (rd["round"], rd["solves"], rd["N"], rd["R"], rd["max_indicator"], rd["max_residual"], rd["max_penetration"], rd["picked"]))
    check(g1["training_set_size"] == 6 and g1["stop"] == "max_solves" and g1["initial"] == 2 and g1["candidates"] == 60,
          "6 FOM solves: the 2 ends of the radius box, then 2 picks a round among 60 candidates (stop: %s)" % g1["stop"])
    check(g1["training_indices"] == g2["training_indices"], "np 1 and np 2 pick the same parameters %s" % g1["training_indices"])
    check(abs(g1["rounds"][-1]["max_indicator"] - g2["rounds"][-1]["max_indicator"]) <= 1e-6 * g1["rounds"][-1]["max_indicator"],
          "np 1 and np 2: the same last max indicator (%.6e, %.6e)" % (g1["rounds"][-1]["max_indicator"], g2["rounds"][-1]["max_indicator"]))
    with h5py.File(d + "/g1.snapshots.h5", "r") as f:
        pool = np.array(f["train/points"])
        done = np.nonzero(np.array(f["snapshots/done"]))[0].tolist()
    check(len(pool) == 62 and done == sorted(int(i) for i in g1["training_indices"]), "the snapshot file's pool has 62 points, its done rows are exactly the 6 picks")
    ok_arg, ok_sep, ok_res = True, True, True
    for rd in g1["rounds"]:
        if rd["picked"]:
            ok_arg = ok_arg and np.allclose(pool[int(rd["picked"][0])], rd["argmax"], rtol=0, atol=1e-15)
            p = [pool[int(i)][0] for i in rd["picked"]]
            ok_sep = ok_sep and all(abs(a - b) / 0.2 >= g1["separation"] for i, a in enumerate(p) for b in p[:i])
        ok_res = ok_res and rd["max_indicator"] == rd["max_residual"]
    check(ok_arg, "every round's first pick is the candidate of largest indicator")
    check(ok_sep, "the picks of a round lie at least -greedy_separation (%.3f of the box) apart" % g1["separation"])
    check(ok_res and g1["indicator"] == "residual", "the default criterion is the residual")
    check(g1["rounds"][-1]["max_indicator"] < g1["rounds"][0]["max_indicator"], "the max indicator falls: %.2e after the initial set, %.2e before the last picks" % (g1["rounds"][0]["max_indicator"], g1["rounds"][-1]["max_indicator"]))
    # a budget reached, then raised on the same files: the run resumes with the snapshots done
    off(1, "g3", 4)
    r3 = off(1, "g3", 6)
    check(r3["resumed"] == 4 and r3["fom_solves"] == 2, "budget 4 then 6 on the same file: 4 resumed, 2 solved (%d, %d)" % (r3["resumed"], r3["fom_solves"]))
    check(r3["greedy"]["training_indices"] == g1["training_indices"], "the resumed run ends with the same picks as the straight one")
    # a run killed inside a round (its first pick written, the second not): the resumed run finishes that round's picks
    # before it builds the next model. Before, the model of the partial round picked other parameters (a different ROM,
    # exit 0; found by an audit with real kills, 2026-11-29). The kill is made exact by clearing the last pick's done flag
    # in a copy of the straight run's snapshot file, which keeps the round's picks (dataset /snapshots/pending).
    last = [int(i) for i in g1["rounds"][-1]["picked"]]
    shutil.copy(d + "/g1.snapshots.h5", d + "/g4.snapshots.h5")
    with h5py.File(d + "/g4.snapshots.h5", "r+") as f:
        pending = np.nonzero(np.array(f["snapshots/pending"]))[0].tolist()
        f["snapshots/done"][last[1]] = 0
    check(pending == sorted(last), "the snapshot file keeps the last round's picks %s (/snapshots/pending %s)" % (last, pending))
    r4 = off(1, "g4", 6)
    check(r4["resumed"] == 5 and r4["fom_solves"] == 1 and r4["greedy"]["training_indices"] == g1["training_indices"]
          and r4["greedy"]["rounds"][0].get("resumed_picks") == [last[1]],
          "killed inside a round: the resumed run solves the round's missing pick %d first and ends with the straight run's picks (%s)" % (last[1], r4["greedy"]["training_indices"]))
    with h5py.File(d + "/g1.h5", "r") as a, h5py.File(d + "/g4.h5", "r") as b:
        names = []
        a["online"].visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        diff = [n for n in names if n not in b["online"] or not np.array_equal(np.array(a["online"][n]), np.array(b["online"][n]))]
    check(len(names) > 10 and not diff, "killed inside a round: the resumed ROM's %d /online datasets equal the straight run's (differ: %s)" % (len(names), diff[:5]))
    # the ROM the greedy built, validated on the test set of the ROM-accuracy targets
    p = subprocess.run(["mpirun", "-n", "2", args.exe, "validate", "-options_file", "runs/ring_on_block.opts", "-rom", d + "/g2.h5", "-report", d + "/v.json"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode == 0, "validate runs on the greedy ROM")
    if p.returncode == 0:
        t = report(d + "/v.json")["test"]
        print("  validate, 6 FOM solves: max rel err u %.2e, lambda %.2e, force %.2e" % (t["max_rel_err_u"], t["max_rel_err_lambda"], t["max_rel_err_force"]))
        check(t["max_rel_err_u"] <= 1e-4 and t["max_rel_err_lambda"] <= 1e-2 and t["max_rel_err_force"] <= 1e-3, "the 6-solve greedy ROM meets u <= 1e-4, lambda <= 1e-2, force <= 1e-3 on 20 random radii")
    # the greedy's snapshot file as a test set: refused as such (the advice to finish it was refused by its restart)
    p = subprocess.run(["mpirun", "-n", "2", args.exe, "validate", "-options_file", "runs/ring_on_block.opts", "-rom", d + "/g2.h5", "-test_snapshots", d + "/g2.snapshots.h5"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "was written by a greedy training (-train_type greedy): it holds the 6 points the greedy solved among its" in p.stdout and "candidates, not a test set" in p.stdout,
          "validate -test_snapshots <the greedy's snapshot file>: refused as a greedy training's file (exit %d)" % p.returncode)
    # -greedy_indicator estimate (docs/error_estimate.md): the rounds with an enrichment ranked by the online estimate's
    # raw u change, the others by the residual
    re_ = off(2, "ge", 8, ["-estimate", "-greedy_indicator", "estimate", "-estimate_calibration_size", "4"])
    ge = re_["greedy"]
    est_rounds = [rd for rd in ge["rounds"] if rd["indicator"] == "estimate"]
    for rd in ge["rounds"]:
        print("  estimate greedy round %d: %d solves, indicator %s, max %.3e" % (rd["round"], rd["solves"], rd["indicator"], rd["max_indicator"]))
    check(ge["indicator"] == "estimate" and ge["estimate_rounds"] == len(est_rounds) >= 1 and ge["training_set_size"] == 8
          and all(rd["max_indicator"] == rd["max_estimate_u"] > 0 for rd in est_rounds) and all("max_residual" in rd for rd in ge["rounds"] if rd["indicator"] == "residual"),
          "-greedy_indicator estimate: %d of %d rounds ranked by the estimate's u change, the others by the residual" % (len(est_rounds), len(ge["rounds"])))
    # refused: a greedy run that stops before the ROM, an unknown criterion, the estimate without its enrichment
    for extra, needle in ((["-offline_stop", "snapshots", "-snapshots", d + "/x.h5"], "-train_type greedy builds the reduced model"),
                          (["-greedy_indicator", "bogus"], "bogus"), (["-greedy_indicator", "estimate"], "needs -estimate")):
        c = ["mpirun", "-n", "1", args.exe, "offline"] + base + ["-rom", d + "/never.h5"] + extra
        p = subprocess.run(c, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        check(p.returncode != 0 and needle in p.stdout, "refused with a message naming '%s'" % needle)


def snapshots_from(args):
    d = workdir("rbc_off_")
    opts = "runs/ring_on_block.opts"

    def points(name, radii):
        with open(d + "/" + name, "w") as f:
            f.write("# radii\n" + "".join("%r\n" % r for r in radii))
        return ["-train_type", "file", "-train_file", d + "/" + name]

    run(args, 1, opts, ["-train_type", "grid", "-train_size", "3", "-snapshots", d + "/a.h5"])          # 0.95, 1.05, 1.15
    run(args, 1, opts, points("b.txt", [1.0, 1.12]) + ["-snapshots", d + "/b.h5"])                      # 1.12: not in the new set
    ext = points("ext.txt", [0.95, 1.0, 1.05, 1.1, 1.15])
    run(args, 1, opts, ext + ["-snapshots", d + "/clean.h5"])
    a, clean = arrays(d + "/a.h5"), arrays(d + "/clean.h5")
    for np_ in (1, 2):
        out = d + "/ext%d.h5" % np_
        run(args, np_, opts, ext + ["-snapshots", out, "-snapshots_from", d + "/a.h5," + d + "/b.h5", "-report", d + "/r%d.json" % np_, "-snapshots_monitor"])
        r, e = report(d + "/r%d.json" % np_), arrays(out)
        print("  np %d: imported %d, solved %d, resumed %d" % (np_, r["imported"], r["fom_solves"], r["resumed"]))
        check(r["imported"] == 4 and r["fom_solves"] == 1 and r["resumed"] == 0, "np %d: 4 snapshots imported (3 of a.h5, 1.0 of b.h5), only 1.1 solved" % np_)
        check(np.all(e["done"] == 1), "np %d: every point of the extended set done" % np_)
        same = all(np.array_equal(e[k][[0, 2, 4]], a[k]) for k in ("u", "lambda", "mu", "extra/contact_gap", "kacanov_iterations"))
        check(same, "np %d: the rows copied from a.h5 are bit for bit its rows" % np_)
        compare(clean, e, 1e-10, "np %d: extended file vs a clean run of the 5 points" % np_)
    # share/refine_training.py: the k cells of a grid with sensitivities whose corners' predictions disagree most,
    # their centres appended to the grid; offline solves only those
    run(args, 2, "runs/half_disks.opts", ["-train_type", "grid", "-train_size", "3", "-snapshots_sensitivities", "-snapshots", d + "/hs.h5"])
    rt = [sys.executable, "share/refine_training.py", d + "/hs.h5", "--count", "2", "--out", d + "/rt.txt", "--with-grid"]
    p = subprocess.run(rt, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print("\n".join("  " + l for l in p.stdout.splitlines()))
    pts = np.loadtxt(d + "/rt.txt", ndmin=2)
    hs = arrays(d + "/hs.h5")
    ax = [np.unique(hs["mu"][:, i]) for i in range(2)]
    mids = [(ax[i][:-1] + ax[i][1:]) / 2 for i in range(2)]
    centres = pts[9:]
    check(p.returncode == 0 and len(pts) == 11 and np.allclose(pts[:9], hs["mu"], rtol=0, atol=0), "refine_training.py: the 9 grid points, then 2 more")
    check(all(np.min(np.abs(mids[i] - c[i])) < 1e-12 for c in centres for i in range(2)) and len({tuple(c) for c in centres}) == 2,
          "refine_training.py: the 2 added points are distinct cell centres %s" % centres.tolist())
    run(args, 2, "runs/half_disks.opts", ["-train_type", "file", "-train_file", d + "/rt.txt", "-snapshots_sensitivities", "-snapshots", d + "/hs11.h5",
                                          "-snapshots_from", d + "/hs.h5", "-report", d + "/rt.json"])
    r = report(d + "/rt.json")
    check(r["imported"] == 9 and r["fom_solves"] == 2, "the refined set: 9 imported, the 2 centres solved (imported %d, solved %d)" % (r["imported"], r["fom_solves"]))
    p = subprocess.run(rt[:2] + [d + "/a.h5"] + rt[3:], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "a.h5" in p.stdout and "sensitivity_lambda" in p.stdout, "refine_training.py on a file without sensitivities: refused by name (%s)" % p.stdout.strip()[-160:])
    # bad input: each refused naming the file, nothing written
    bad = [("a missing file", ["-snapshots_from", d + "/none.h5"], "none.h5", "no such file"),
           ("another scene's file", None, "hd.h5", "differs"),
           ("a file without the sensitivities", ["-snapshots_from", d + "/a.h5", "-snapshots_sensitivities"], "a.h5", "sensitivity_u")]
    run(args, 1, "runs/half_disks.opts", ["-train_type", "grid", "-train_size", "2", "-snapshots", d + "/hd.h5"])
    for what, extra, name, word in bad:
        extra = extra or ["-snapshots_from", d + "/hd.h5"]
        p = run(args, 1, opts, ext + ["-snapshots", d + "/never.h5"] + extra, expect_ok=False)
        msg = [l for l in p.stdout.splitlines() if name in l][:1]
        print("  %s -> exit %d: %s" % (what, p.returncode, msg[0] if msg else p.stdout[-300:]))
        check(p.returncode != 0 and msg and word in p.stdout and "-snapshots_from" in p.stdout, "%s: refused, the message names the file and says why" % what)
        check("Segmentation" not in p.stdout and "SEGV" not in p.stdout, "%s: no crash" % what)
        if word in ("no such file", "differs"):  # the headers are checked before the snapshot file is opened (SnapshotFile::CheckImport)
            check(not os.path.exists(d + "/never.h5"), "%s: refused before the snapshot file was created" % what)
        else:
            with h5py.File(d + "/never.h5", "r") as f:
                check(int(np.sum(np.array(f["snapshots/done"]))) == 0, "%s: no snapshot written" % what)


def sensitivities(args):
    d = workdir("rbc_off_")
    # a point and its neighbours 1e-3 of each parameter's range away (the active set is the same at all five)
    w = np.array([0.6, 0.06])
    mu0 = np.array([0.9, 0.1])
    pts = [mu0] + [mu0 + sg * 1e-3 * w[i] * np.eye(2)[i] for i in range(2) for sg in (1, -1)]
    np.savetxt(d + "/fd.txt", np.array(pts), fmt="%.17g")
    base = ["-train_type", "file", "-train_file", d + "/fd.txt", "-snapshots_sensitivities"]
    run(args, 1, "runs/half_disks.opts", base + ["-snapshots", d + "/dense.h5", "-report", d + "/dense.json"])
    run(args, 1, "runs/half_disks.opts", base + ["-snapshots", d + "/cg.h5", "-report", d + "/cg.json", "-fom_dual_matrix", "shell"])
    run(args, 2, "runs/half_disks.opts", base + ["-snapshots", d + "/np2.h5", "-snapshots_subcomm", "1"])
    run(args, 2, "runs/half_disks.opts", base + ["-snapshots", d + "/saddle.h5", "-report", d + "/saddle.json", "-snapshots_subcomm", "1", "-fom_dual_matrix", "saddle"])
    rd, rc, rs = (report(d + "/%s.json" % k)["sensitivities"] for k in ("dense", "cg", "saddle"))
    print("  dense: %s\n  cg: %s\n  saddle: %s" % (rd, rc, rs))
    check(rd["enabled"] and rd["method"] == "dense" and rc["method"] == "cg" and rc["cg_iterations_max"] > 0 and rs["method"] == "saddle",
          "the dense dual path factors S_AA, the shell path runs CG, the saddle path solves its saddle point")
    a, c, n2, sd = arrays(d + "/dense.h5"), arrays(d + "/cg.h5"), arrays(d + "/np2.h5"), arrays(d + "/saddle.h5")
    nd, R = a["u"].shape[1], a["lambda"].shape[1]
    su, sl = a["extra/sensitivity_u"], a["extra/sensitivity_lambda"]
    check(su.shape == (5, 2 * nd) and sl.shape == (5, 2 * R), "the file holds du/dmu (2 x %d) and dlambda/dmu (2 x %d) per snapshot" % (nd, R))
    for other, what in ((c, "CG on the Schur complement"), (n2, "2 ranks"), (sd, "the saddle point, 2 ranks")):
        for k in ("extra/sensitivity_u", "extra/sensitivity_lambda"):
            e = np.max(np.abs(other[k] - a[k])) / np.max(np.abs(a[k]))
            check(e <= 1e-6, "%s: %s equal to the dense 1-rank one within 1e-6 (%.1e)" % (what, k, e))
    # against central differences of the FOM solutions (the derivative scaled by the range)
    U, M = a["u"], a["mu"]
    for i, name in ((1, "displacement"), (0, "radius")):
        fd = (U[1 + 2 * i] - U[2 + 2 * i]) / (M[1 + 2 * i, i] - M[2 + 2 * i, i]) * w[i]
        s = su[0, i * nd:(i + 1) * nd]
        rel = np.linalg.norm(s - fd) / np.linalg.norm(fd)
        cos = s @ fd / np.linalg.norm(s) / np.linalg.norm(fd)
        print("  d u / d %s: |sens| %.4e, |central difference| %.4e, rel. difference %.2e, cosine %.5f" % (name, np.linalg.norm(s), np.linalg.norm(fd), rel, cos))
        if name == "displacement":
            check(rel <= 1e-2, "du/d displacement = the FOM's central difference within 1e-2 (%.1e)" % rel)
        else:  # the frozen-geometry tangent: the geometric stiffness of the sliding contact is left out (docs/greedy_training.md)
            check(rel <= 0.3 and cos >= 0.97, "du/d radius: the frozen-geometry tangent within 0.3 of the central difference (%.2f), cosine >= 0.97 (%.4f)" % (rel, cos))
    L = a["lambda"]
    fdl = (L[3] - L[4]) / (M[3, 1] - M[4, 1]) * w[1]
    el = np.linalg.norm(sl[0, R:] - fdl) / np.linalg.norm(fdl)
    check(el <= 2e-2, "dlambda/d displacement = the FOM's central difference within 2e-2 (%.1e)" % el)
    # the bases: a 3 x 3 grid with and without, best approximation of u on the 20 test points
    val = {}
    for tag, extra in (("plain", []), ("sens", ["-snapshots_sensitivities"])):
        rom = "%s/%s.h5" % (d, tag)
        for stage, more in (("offline", ["-train_size", "3", "-rom", rom, "-report", "%s/%s_off.json" % (d, tag)]),
                            ("validate", ["-rom", rom, "-report", "%s/%s_val.json" % (d, tag)])):
            c_ = ["mpirun", "-n", "2", args.exe, stage, "-options_file", "runs/half_disks.opts"] + extra + more
            p = subprocess.run(c_, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            if p.returncode != 0:
                print(p.stdout[-4000:])
                sys.exit("command failed (exit %d): %s" % (p.returncode, " ".join(c_)))
        val[tag] = (report("%s/%s_off.json" % (d, tag)), report("%s/%s_val.json" % (d, tag)))
    (op, vp), (os_, vs) = val["plain"], val["sens"]
    bp, bs = vp["test_best_approximation"]["max_rel_err_u"], vs["test_best_approximation"]["max_rel_err_u"]
    print("  3 x 3 grid: N %d / %d, R %d / %d; best approximation of u %.2e / %.2e; ROM u %.2e / %.2e, lambda %.2e / %.2e (plain / with sensitivities)"
          % (vp["rom"]["N"], vs["rom"]["N"], vp["rom"]["R"], vs["rom"]["R"], bp, bs, vp["test"]["max_rel_err_u"], vs["test"]["max_rel_err_u"], vp["test"]["max_rel_err_lambda"], vs["test"]["max_rel_err_lambda"]))
    check(os_["pod"]["sensitivity_vectors"] == 18 and os_["dual"]["predicted_columns"] == 36 and op["pod"]["sensitivity_vectors"] == 0,
          "the POD saw 9 snapshots + 18 derivatives, the dual greedy 9 + 36 predicted multipliers")
    check(bs <= 0.8 * bp, "the derivatives in the POD: best approximation of u %.2e <= 0.8 x the plain grid's %.2e" % (bs, bp))
    check(vs["test"]["max_rel_err_u"] <= 0.8 * vp["test"]["max_rel_err_u"] and vs["test"]["max_rel_err_lambda"] <= 0.5 * vp["test"]["max_rel_err_lambda"],
          "and the reduced model's errors fall with them: u by 0.8x at least, lambda by 0.5x (the predicted multipliers in the dual basis)")
    # refused: the option on a file solved without it; a step out of range
    run(args, 1, "runs/half_disks.opts", ["-train_size", "2", "-snapshots", d + "/old.h5"])
    c_ = ["mpirun", "-n", "1", args.exe, "offline", "-options_file", "runs/half_disks.opts", "-train_size", "2", "-snapshots", d + "/old.h5", "-rom", d + "/x.h5", "-snapshots_sensitivities"]
    p = subprocess.run(c_, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "old.h5" in p.stdout and "solved without sensitivities" in p.stdout, "a snapshot file solved without the option is refused, naming the file")
    c_ = ["mpirun", "-n", "1", args.exe, "offline", "-options_file", "runs/half_disks.opts", "-train_size", "2", "-snapshots", d + "/bad.h5", "-rom", d + "/y.h5", "-snapshots_sensitivities", "-dual_sensitivity_step", "2"]
    p = subprocess.run(c_, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    check(p.returncode != 0 and "-dual_sensitivity_step 2" in p.stdout, "-dual_sensitivity_step 2 is refused, naming the option")


def initial_guess(args):
    d = workdir("rbc_off_")
    # the Kacanov loop stops at a relative change of 1e-8 (u and lambda, -kacanov_rtol_*): two starts of the same
    # contraction land within about that of each other; 1e-7 leaves a factor 10 (measured: 6e-14 on half_disks, whose
    # Newton steps converge quadratically, 1e-9 on the 3D saddle path)
    cases = (("half_disks + sensitivities", "runs/half_disks.opts", ["-train_size", "4", "-snapshots_sensitivities"]),
             ("half_disks", "runs/half_disks.opts", ["-train_size", "4"]),
             ("sphere_block3d, saddle + GAMG, + sensitivities", "runs/sphere_block3d.opts",
              ["-train_size", "3", "-snapshots_sensitivities", "-fom_dual_matrix", "saddle", "-fom_saddle_solver", "gamg"]))
    for i, (what, opts, extra) in enumerate(cases):
        its = {}
        for tag, np_, guess in (("zero", 1, "zero"), ("nearest", 1, "nearest"), ("nearest_np2", 2, "nearest")):
            f = "%s/c%d_%s" % (d, i, tag)
            run(args, np_, opts, extra + ["-snapshots", f + ".h5", "-snapshots_initial_guess", guess, "-report", f + ".json"])
            r = report(f + ".json")
            check(r["initial_guess"] == guess and r["fom_solves"] == r["ntrain"], "%s, %s on %d rank(s): report initial_guess %s, %d solves"
                  % (what, guess, np_, r["initial_guess"], r["fom_solves"]))
            its[tag] = arrays(f + ".h5")
        z = its["zero"]
        for tag in ("nearest", "nearest_np2"):
            compare(z, its[tag], 1e-7, "%s, %s against the zero start" % (what, tag))
            a, b = int(np.sum(z["kacanov_iterations"])), int(np.sum(its[tag]["kacanov_iterations"]))
            check(b < a, "%s, %s: %d Kacanov iterations over the grid < %d from zero" % (what, tag, b, a))
    p = run(args, 1, "runs/half_disks.opts", ["-train_size", "2", "-snapshots", d + "/bad.h5", "-snapshots_initial_guess", "previous"], expect_ok=False)
    check(p.returncode != 0 and "-snapshots_initial_guess previous" in p.stdout and not os.path.exists(d + "/bad.h5"),
          "-snapshots_initial_guess previous is refused, naming the option, before any snapshot file")


def disk_full(args):
    """A full disk (a 4 MB tmpfs mounted for the test; skipped, exit 77, where it cannot be mounted): the ROM pair's and
    the snapshot file's writes fail with a message naming the file and "No space left on device"; the previous ROM and
    basis file stay as they were (also when the basis file was already replaced: put back) with no temporary or
    .previous file left (a failure before the replacement left both .previous links: rename() of two links of one file
    does nothing); no segmentation fault at the exit (HDF5's shutdown crashed on a file it had failed to flush); a
    snapshot file without room is said before the first solve. 1 and 2 ranks."""
    d = workdir("rbc_off_full_")
    m = d + "/small"
    os.makedirs(m)
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", m], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode != 0:
        print("  SKIP  a small file system cannot be mounted here (mount -t tmpfs needs root): not run")
        sys.exit(77)
    atexit.register(subprocess.run, ["umount", "-l", m])  # (atexit runs it before the removal of d, registered first)
    ring = "runs/ring_on_block.opts"

    def offline(np_, extra):
        return subprocess.run(["mpirun", "-n", str(np_), args.exe, "offline", "-options_file", ring] + extra, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)

    def sha(path):
        import hashlib
        with open(path, "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()

    def fill_to(free):
        """A file of zeros leaving `free` bytes of the tmpfs free (its blocks: 4 kB)."""
        if os.path.exists(m + "/fill"):
            os.remove(m + "/fill")
        st = os.statvfs(m)
        n = st.f_bavail * st.f_frsize - free
        with open(m + "/fill", "wb") as f:
            f.write(b"\0" * max(n, 0))
            f.flush()
            os.fsync(f.fileno())

    # the snapshots outside the small file system (the bases and ROM from them: fast); the sizes of the new pair
    for n in (3, 4):
        p = offline(1, ["-train_size", str(n), "-snapshots", "%s/s%d.h5" % (d, n), "-rom", "%s/ref%d.h5" % (d, n)])
        check(p.returncode == 0, "the reference run with %d training radii" % n)
    B, R = os.path.getsize(d + "/ref4.basis.h5"), os.path.getsize(d + "/ref4.h5")
    p = offline(1, ["-train_size", "3", "-snapshots", d + "/s3.h5", "-snapshots_restart", "-rom", m + "/rom.h5"])
    before = {q: sha(q) for q in (m + "/rom.h5", m + "/rom.basis.h5")}
    new = ["-train_size", "4", "-snapshots", d + "/s4.h5", "-snapshots_restart", "-rom", m + "/rom.h5", "-report", d + "/r.json"]
    for np_ in (1, 2):
        for what, free, fname in (("while writing the basis file", B // 2, "rom.basis.h5"), ("while writing the ROM file, the basis file replaced", B + R // 2, "rom.h5")):
            fill_to(free)
            p = offline(np_, new)
            after = {q: sha(q) for q in before}
            left = sorted(f for f in os.listdir(m) if ".tmp" in f or ".previous" in f)
            err = [l for l in p.stdout.splitlines() if "rbcontact error" in l][:1]
            check(0 < p.returncode < 128 and "No space left on device" in p.stdout and ("ROM file '%s/%s'" % (m, fname)) in p.stdout and after == before and not left,
                  "disk full %s, %d rank(s): exit %d (an error, not a signal), the message names %s and the full disk; the previous pair unchanged (%s), nothing left (%s)"
                  % (what, np_, p.returncode, fname, after == before, left))
            if err and len(err[0]) > 400:
                check(False, "the message is short (%d characters): %s" % (len(err[0]), err[0][:400]))
            os.remove(m + "/fill")
            q = subprocess.run(["mpirun", "-n", "1", args.exe, "online", "-rom", m + "/rom.h5", "-mu", "1.02"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            check(q.returncode == 0, "... the previous pair still answers online")
    # the snapshot file: written whole at its creation (its rows' space included), so a disk without room for it is said
    # before the first FOM solve, and no file is left; with room, the same command runs
    S = os.path.getsize(d + "/s4.h5")
    for np_ in (1, 2):
        snap = "%s/snap_np%d.h5" % (m, np_)
        fill_to(S // 2)
        p = offline(np_, ["-train_size", "4", "-snapshots", snap, "-offline_stop", "snapshots", "-snapshots_subcomm", "1", "-snapshots_monitor"])
        left = sorted(f for f in os.listdir(m) if ".tmp" in f or f == os.path.basename(snap))
        check(0 < p.returncode < 128 and "No space left on device" in p.stdout and ("Snapshot file '%s'" % snap) in p.stdout and "  snapshot " not in p.stdout and not left,
              "disk full for the snapshot file (%d of %d bytes free), %d rank(s): exit %d, the message names the file and the full disk, before any "
              "solve; nothing left (%s)" % (S // 2, S, np_, p.returncode, left))
        os.remove(m + "/fill")
        p = offline(np_, ["-train_size", "4", "-snapshots", snap, "-offline_stop", "snapshots", "-snapshots_subcomm", "1", "-report", d + "/res.json"])
        check(p.returncode == 0 and report(d + "/res.json")["fom_solves"] == 4, "... with room, the same command solves the 4 snapshots")
        os.remove(snap)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("check", choices=["ring", "half_disks", "resume", "concurrent", "mismatch", "early_options", "bases_warnings", "bases", "dualbasis_import", "greedy", "snapshots_from", "sensitivities", "initial_guess", "disk_full"])
    ap.add_argument("--exe", required=True)
    args = ap.parse_args()
    globals()[args.check](args)
    if FAILED:
        print("%d check(s) failed" % len(FAILED))
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
