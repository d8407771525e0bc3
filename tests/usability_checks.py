#!/usr/bin/python3
"""Checks of what a PETSc user meets driving rbcontact from outside, run by ctest (tests/usability.cmake).

Subcommands (exit 0 = pass; a failure prints what was seen):
  provenance  every report and HDF5 file says where it came from: version, git commit (equal to the
              source tree's when it is a git checkout), PETSc/SLEPc versions, options, date, ranks
  failure     a failed run still writes its -report: converged false and the error naming the file or
              option at fault, replacing an older report of the same name
  help        `rbcontact fom -help` lists the scene, boundary, parameter, map and output options
  rename      the boundary options out of PETSc's -bc_ namespace: the old spelling gives the same run
              with one deprecation warning per option; both spellings at once are refused
  gamg        the README's iterative elastic solver (-fom_ksp_type cg -fom_pc_type gamg) on a contact
              scene: the direct solver's contact force to 1e-6, also with a TAO contact QP (its own prefix
              fom_qp_); the former -fom_tao_* spelling warns once and gives the same run
  paraview    the XDMF files ParaView opens: every HDF dataset an .xmf names exists with the dimensions and
              the number type / precision the .xmf says (the FOM output, the reconstructed ROM fields, the
              offline basis view); the contact grid's points are the slave vertices; the basis view's POD
              modes, supremizers and dual vectors are those of the basis file (the same norms and entries)
  rank_files  an options file that only rank 0 can see (node-local, here: another working directory per rank)
              is read by PETSc on rank 0 as usual (the check on every rank stopped rank 1 and hung the run);
              one that rank 0 cannot see is refused on every rank, with the report, no hang
  stale       the temporary file of an output a killed job left (<target>.tmp.<pid>, its process gone) is
              named in a warning with its size before the work, and never removed; one of a process that
              still runs is not named; the output is written as usual
"""
import argparse
import atexit
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import h5py

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FAILED = []


def check(cond, msg):
    print(("  ok    " if cond else "  FAIL  ") + msg)
    if not cond:
        FAILED.append(msg)


def workdir():
    d = tempfile.mkdtemp(prefix="rbc_usability_")
    atexit.register(shutil.rmtree, d, True)
    return d


def run(args, np_, cmd, expect_ok=True, timeout=None):
    full = (["mpirun", "-n", str(np_)] if np_ > 1 else []) + [args.exe] + cmd
    # errors="replace": PETSc 3.18's -help prints the default of -dm_plex_boundary_label from uninitialized
    # memory ("<now 3\x0fh\xd7...>"), not always valid UTF-8
    try:
        p = subprocess.run(full, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace", stdin=subprocess.DEVNULL, timeout=timeout)
    except subprocess.TimeoutExpired:
        subprocess.run(["pkill", "-f", args.exe + " " + cmd[0]])
        sys.exit("command hung (killed after %g s): %s" % (timeout, " ".join(full)))
    if expect_ok and p.returncode != 0:
        print(p.stdout[-3000:])
        sys.exit("command failed (exit %d): %s" % (p.returncode, " ".join(full)))
    return p


def load(path):
    with open(path) as f:
        return json.load(f)


def attr(f, name):
    v = f.attrs[name]
    return v.decode() if isinstance(v, bytes) else str(v)


def source_commit():
    """The checkout's commit as the build records it (short, -dirty when tracked files differ), or None."""
    if not os.path.isdir(os.path.join(ROOT, ".git")) or shutil.which("git") is None:
        return None
    c = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short=12", "HEAD"], stdout=subprocess.PIPE, text=True)
    return c.stdout.strip() if c.returncode == 0 else None


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        return re.search(r"project\(rbcontact VERSION ([0-9.]+)", f.read()).group(1)


def check_provenance(p, np_, what, option="-mesh_file"):
    keys = ("version", "commit", "petsc", "slepc", "date", "nranks", "options")
    check(all(k in p for k in keys), "%s: provenance has %s (%s)" % (what, ", ".join(keys), sorted(p)))
    check(p.get("version") == project_version(), "%s: version %s = CMakeLists.txt's %s" % (what, p.get("version"), project_version()))
    c = source_commit()
    if c is not None:
        check(p.get("commit", "").split("-dirty")[0] == c, "%s: commit %s = the checkout's %s (if not: the binary is older than the checkout, rebuild)" % (what, p.get("commit"), c))
    else:
        check(p.get("commit") not in (None, ""), "%s: commit given (%s; not a git checkout)" % (what, p.get("commit")))
    check("3.18" in p.get("petsc", "") and "3.18" in p.get("slepc", ""), "%s: PETSc/SLEPc versions '%s', '%s'" % (what, p.get("petsc"), p.get("slepc")))
    check(p.get("nranks") == np_, "%s: nranks %s = %d" % (what, p.get("nranks"), np_))
    check(option in p.get("options", ""), "%s: the options are recorded (%s among them)" % (what, option))
    check(re.match(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$", p.get("date", "")) is not None, "%s: date %s (ISO 8601, UTC)" % (what, p.get("date")))


def provenance(args):
    d = workdir()
    run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-report", d + "/fom.json", "-fom_output", d + "/fom.h5"])
    r = load(d + "/fom.json")
    check_provenance(r.get("provenance", {}), args.np, "fom report")
    with h5py.File(d + "/fom.h5", "r") as f:
        check(attr(f, "code_commit") == r["provenance"]["commit"] and attr(f, "code_version") == r["provenance"]["version"],
              "fom fields file: code_commit %s, code_version %s as in the report" % (attr(f, "code_commit"), attr(f, "code_version")))
        check("PETSc" in attr(f, "petsc_version") or "Petsc" in attr(f, "petsc_version"), "fom fields file: petsc_version")
    run(args, args.np, ["offline", "-options_file", "runs/ring_on_block.opts", "-train_size", "5", "-rom", d + "/rom.h5", "-snapshots", d + "/snap.h5",
                        "-report", d + "/off.json"])
    o = load(d + "/off.json")
    check_provenance(o.get("provenance", {}), args.np, "offline report")
    for name in ("rom.h5", "snap.h5"):
        with h5py.File(os.path.join(d, name), "r") as f:
            check(attr(f, "code_commit") == o["provenance"]["commit"] and attr(f, "code_version") == project_version() and attr(f, "created") != "",
                  "%s: code_commit %s, code_version %s, created %s" % (name, attr(f, "code_commit"), attr(f, "code_version"), attr(f, "created")))
    run(args, args.np, ["online", "-rom", d + "/rom.h5", "-mu", "1.02", "-report", d + "/on.json"])
    check_provenance(load(d + "/on.json").get("provenance", {}), args.np, "online report", "-rom")


def failure(args):
    d = workdir()
    rep = d + "/fail.json"
    with open(rep, "w") as f:
        f.write('{"stale": true}\n')
    cases = [(["-mesh_file", "nope.msh"], r"Mesh file 'nope\.msh' not found", "missing mesh"),
             (["-kacanov_max_it", "2"], r"Kacanov iterations did not converge in 2 iterations", "Kacanov not converged"),
             (["-contact_quadrature", "bogus"], r"-contact_quadrature: unknown value 'bogus'", "unknown option value")]
    # a failure on one rank only (-rbc_test_fail_rank, a test hook of src/apps/main.cpp): before, the other rank waited
    # in the stage's first collective and the failed one in MPI_Finalize, for ever; now the failed rank waits
    # -rbc_error_wait seconds for the others, then aborts the run after writing the report
    one_rank = [(["-rbc_test_fail_rank", str(r), "-rbc_error_wait", "2"], r"-rbc_test_fail_rank %d: an error raised on this rank only" % r,
                 "failure on rank %d alone" % r) for r in range(args.np)] if args.np > 1 else []
    # a C++ exception out of a stage (std::bad_alloc of a size beyond memory): said, reported, MPI_Abort (src/apps/main.cpp)
    cases.append((["-rbc_test_fail_rank", str(args.np - 1), "-rbc_test_fail_throw"], r"C\+\+ exception: -rbc_test_fail_rank with -rbc_test_fail_throw", "C++ exception"))
    for extra, pattern, what in cases + one_rank:
        t0 = time.time()
        p = run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-report", rep, "-rbc_error_wait", "60"] + extra, expect_ok=False, timeout=120)
        alone = "-rbc_test_fail_rank" in extra and "-rbc_test_fail_throw" not in extra
        check(p.returncode != 0, "%s: exit %d (non-zero)" % (what, p.returncode))
        # a collective failure ends without the wait (60 s here) and without the abort
        check(("did not reach this failure within 2 s" in p.stdout) == alone and (alone or time.time() - t0 < 50),
              "%s: %s in %.1f s" % (what, "aborted after the wait" if alone else "ended without waiting", time.time() - t0))
        if "-rbc_test_fail_throw" in extra:  # (Open MPI's MPI_ABORT banner is not always printed: the time says it)
            check(time.time() - t0 < 60, "%s: the run ended (MPI_Abort: the other ranks waited in a collective) in %.1f s" % (what, time.time() - t0))
        r = load(rep)
        check(r.get("converged") is False and r.get("stage") == "fom" and "stale" not in r, "%s: report says converged false, stage fom (keys %s)" % (what, sorted(r)))
        check(re.search(pattern, r.get("error", "")) is not None, "%s: report error '%s' matches '%s'" % (what, r.get("error", "")[:160], pattern))
        check("commit" in r.get("provenance", {}), "%s: report has the provenance" % what)
        check(not [x for x in os.listdir(d) if ".tmp." in x], "%s: no temporary file left" % what)


def help_(args):
    # without a stage: --help prints the usage and --version the version, exit 0 (both were "error: the first argument
    # must be a stage word", exit 1, until 2026-12-02); no argument or another option stays an error
    for w in ("--help", "-help", "-h", "help"):
        p = run(args, 1, [w], expect_ok=False)
        check(p.returncode == 0 and "Usage: rbcontact <stage>" in p.stdout and "error:" not in p.stdout, "rbcontact %s: the usage, exit %d (0)" % (w, p.returncode))
    p = run(args, 1, ["--version"], expect_ok=False)
    c = source_commit()
    check(p.returncode == 0 and p.stdout.startswith("rbcontact %s (commit " % project_version()) and "3.18" in p.stdout and (c is None or c in p.stdout),
          "rbcontact --version: version, commit and PETSc/SLEPc, exit %d (%s)" % (p.returncode, p.stdout.strip()))
    for w in ([], ["-x"]):
        p = run(args, 1, w, expect_ok=False)
        check(p.returncode == 1 and "the first argument must be a stage word" in p.stdout, "rbcontact %s: an error, exit %d (1)" % (" ".join(w) or "(nothing)", p.returncode))
    p = run(args, 1, ["fom", "-options_file", "runs/ring_on_block.opts", "-help"])
    for opt in ("-mesh_file", "-mesh_refine", "-bodies", "-body_E", "-dirichlet", "-dirichlet_ring_top_u", "-mu_names", "-mu", "-map_ring",
                "-contact_slave", "-contact_quadrature", "-report", "-fom_output", "-kacanov_max_it", "-fom_ksp_type",
                "-fom_kkt_view", "-fom_qp_polish", "-fom_qp_tao_type"):  # (the last three missing until 2026-12-02)
        check(re.search(r"^\s+%s[ :<]" % re.escape(opt), p.stdout, re.M) is not None, "fom -help lists %s" % opt)
    check("rbcontact: warning" not in p.stdout, "the shipped scene: no rbcontact warning (deprecated or unused option)")
    m = re.search(r"^\s+-mu <([-0-9.e+]+)", p.stdout, re.M)
    check(m is not None and 0.95 <= float(m.group(1)) <= 1.1, "fom -help shows the default of -mu inside the box [0.95, 1.1] (%s)" % (m.group(1) if m else None))
    # a stage's -help without its input: the options read before it, a note naming the input, exit 0 and no error
    # (it stopped at the first missing input with exit 95); the report is not written
    for stage, needs, listed in (("fom", "-mesh_file", ("-mesh_file", "-bodies", "-mu_names", "-dirichlet")), ("offline", "-mesh_file", ("-train_type", "-snapshots", "-mesh_file")),
                                 ("online", "-rom", ("-rom", "-online_repeat")), ("probe", "-rom", ("-rom",)), ("validate", "-rom", ("-rom", "-validate_repeat", "-validate_sweep")),
                                 ("dualbasis", "-snapshots", ("-snapshots", "-dual_out"))):
        p = run(args, 1, [stage, "-help"], expect_ok=False)
        check(p.returncode == 0 and "rbcontact error" not in p.stdout, "%s -help without %s: exit %d (0), no error" % (stage, needs, p.returncode))
        check(("the stage needs %s, where it stops" % needs) in p.stdout, "%s -help: the note names %s" % (stage, needs))
        for opt in listed:
            check(re.search(r"^\s+%s[ :<]" % re.escape(opt), p.stdout, re.M) is not None, "%s -help without %s lists %s" % (stage, needs, opt))
    # its -report says so (an earlier run's report is not left in place)
    hd = workdir()
    with open(hd + "/old.json", "w") as f:
        f.write('{"stage": "fom", "converged": true}')
    p = run(args, 1, ["fom", "-help", "-report", hd + "/old.json"], expect_ok=False)
    hr = load(hd + "/old.json")
    check(p.returncode == 0 and hr.get("converged") is False and "-help: stopped before -mesh_file (nothing was run)" in hr.get("error", ""),
          "fom -help -report without a mesh: the report replaced, saying nothing was run (%s)" % hr.get("error"))
    # without -help the missing input is still an error
    p = run(args, 1, ["online"], expect_ok=False)
    check(p.returncode != 0 and "online: give the ROM file with -rom" in p.stdout, "online without -rom and without -help: an error (exit %d)" % p.returncode)
    # the offline, online and validate stages list their own options and the reduced model's (the offline
    # run writes the small ROM the others open)
    d = workdir()
    rom = os.path.join(d, "rom.h5")
    p = run(args, 1, ["offline", "-options_file", "runs/ring_on_block.opts", "-train_size", "5", "-rom", rom, "-help"])
    for opt in ("-rom", "-rom_basis", "-snapshots", "-snapshots_restart", "-snapshots_monitor", "-snapshots_subcomm", "-offline_stop", "-train_type",
                "-train_size", "-report", "-pod_inner", "-pod_tol", "-pod_supremizers", "-pod_supremizers_infsup", "-dual_type", "-dual_tol",
                "-dual_mass_weighted", "-rom_hyper", "-ecsw_tol", "-ecsw_fit", "-ecsw_fit_force", "-eim_quadrature_subdivisions", "-eim_patch_rings",
                "-eim_select", "-eim_select_slack", "-eim_kappa_tol", "-rom_kacanov_max_it", "-offline_basis_output", "-snapshots_sensitivities",
                "-dual_sensitivity_step", "-ecsw_distribute_states", "-dual_select_size", "-dual_select_snapshots", "-dual_select_slack", "-dual_select_R",
                "-snapshots_initial_guess"):
        check(re.search(r"^\s+%s[ :<]" % re.escape(opt), p.stdout, re.M) is not None, "offline -help lists %s" % opt)
    check("rbcontact: warning" not in p.stdout, "offline with the shipped scene: no rbcontact warning (unused option)")
    p = run(args, 1, ["online", "-rom", rom, "-help"])
    for opt in ("-rom", "-mu", "-report", "-online_repeat", "-rom_reconstruct", "-rom_hyper", "-rom_N", "-rom_R", "-rom_kkt_tol", "-rom_warm_start",
                "-rom_ecsw_sum", "-rom_ecsw_precision", "-rom_kacanov_rtol_primal", "-rom_qp_type"):
        check(re.search(r"^\s+%s[ :<]" % re.escape(opt), p.stdout, re.M) is not None, "online -help lists %s" % opt)
    p = run(args, 1, ["validate", "-options_file", "runs/ring_on_block.opts", "-rom", rom, "-test_size", "1", "-validate_repeat", "1", "-help"])
    for opt in ("-rom", "-report", "-validate_repeat", "-validate_sweep", "-validate_sweep_fractions", "-validate_sweep_output", "-test_type", "-test_size",
                "-rom_hyper", "-test_snapshots", "-validate_sweep_R"):
        check(re.search(r"^\s+%s[ :<]" % re.escape(opt), p.stdout, re.M) is not None, "validate -help lists %s" % opt)
    # the sweep's options without -validate_sweep: said (nothing read them, without a word before)
    p = run(args, 1, ["validate", "-options_file", "runs/ring_on_block.opts", "-rom", rom, "-test_size", "1", "-validate_repeat", "1", "-validate_sweep_R", "3", "-validate_sweep_fractions", "0.5"])
    for o in ("-validate_sweep_R", "-validate_sweep_fractions"):
        check(("warning: %s has no effect without -validate_sweep" % o) in p.stdout, "validate %s without -validate_sweep: a warning" % o)
    check("-validate_sweep_output has no effect" not in p.stdout, "validate: no warning for a sweep option not given")
    p = run(args, 1, ["dualbasis", "-snapshots", d + "/rom.snapshots.h5", "-help"])
    for opt in ("-snapshots", "-report", "-dual_out", "-dual_type", "-dual_tol"):
        check(re.search(r"^\s+%s[ :<]" % re.escape(opt), p.stdout, re.M) is not None, "dualbasis -help lists %s" % opt)


def rename(args):
    d = workdir()
    with open(os.path.join(ROOT, "runs/ring_on_block.opts")) as f:
        text = f.read()
    old = re.sub(r"^-dirichlet_(\w+)_u\b", r"-bc_\1_u", text, flags=re.M)
    old = re.sub(r"^-dirichlet\b", "-bc_dirichlet", old, flags=re.M)
    check(old != text and "-bc_ring_top_u" in old, "an options file in the old spelling (-bc_dirichlet, -bc_<name>_u)")
    with open(d + "/old.opts", "w") as f:
        f.write(old)
    # the old file refers to meshes/ relative to the source tree: run from there
    a = run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-report", d + "/new.json"])
    b = run(args, args.np, ["fom", "-options_file", d + "/old.opts", "-report", d + "/old.json"])
    rn, ro = load(d + "/new.json"), load(d + "/old.json")
    check(rn["contact_force"] == ro["contact_force"] and rn["energy"] == ro["energy"], "old spelling: same force %.12g / %.12g and energy" % (rn["contact_force"], ro["contact_force"]))
    for opt in ("-bc_dirichlet", "-bc_ring_top_u", "-bc_block_bottom_u"):
        check(b.stdout.count("option %s is deprecated" % opt) == 1, "one deprecation warning for %s" % opt)
    check("deprecated" not in a.stdout and "was not used" not in b.stdout, "new spelling: no warning; old spelling: no unused-option warning")
    p = run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-bc_ring_top_u", "0,-0.05"], expect_ok=False)
    check(p.returncode != 0 and "-dirichlet_ring_top_u and its deprecated spelling -bc_ring_top_u are both given" in p.stdout,
          "both spellings: refused, naming both (exit %d)" % p.returncode)


def rank_files(args):
    # mpirun's MPMD form gives each rank its own working directory: runs/ring_on_block.opts exists for the rank started in
    # the source tree only
    d = workdir()
    exe = os.path.abspath(args.exe)

    def mpmd(first_here, rep):
        here = ["-n", "1", "--wdir", ROOT, exe, "fom", "-options_file", "runs/ring_on_block.opts", "-report", rep]
        away = ["-n", "1", "--wdir", d, exe, "fom", "-options_file", "runs/ring_on_block.opts", "-report", rep]
        c = ["mpirun"] + (here + [":"] + away if first_here else away + [":"] + here)
        t0 = time.time()
        try:
            p = subprocess.run(c, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace", stdin=subprocess.DEVNULL, timeout=120)
        except subprocess.TimeoutExpired:
            subprocess.run(["pkill", "-f", exe + " fom"])
            check(False, "rank 0 %s the options file: the run hung (killed after 120 s)" % ("sees" if first_here else "does not see"))
            return None, 0
        return p, time.time() - t0

    ref = d + "/ref.json"
    run(args, 2, ["fom", "-options_file", "runs/ring_on_block.opts", "-report", ref])
    p, t = mpmd(True, d + "/a.json")
    if p is not None:
        r = load(d + "/a.json") if os.path.exists(d + "/a.json") else {}
        check(p.returncode == 0 and r.get("converged") is True and r.get("nranks") == 2, "only rank 0 sees the options file: the run works on 2 ranks (exit %d, %.1f s)" % (p.returncode, t))
        e0 = load(ref)["energy"]
        check(abs(r.get("energy", 0) - e0) <= 1e-10 * abs(e0), "... the energy of the ordinary run (%.12g / %.12g)" % (r.get("energy", float("nan")), e0))
    p, t = mpmd(False, d + "/b.json")
    if p is not None:
        r = load(d + "/b.json") if os.path.exists(d + "/b.json") else {}
        check(p.returncode != 0 and "options file runs/ring_on_block.opts (-options_file): No such file or directory" in p.stdout and t < 60,
              "rank 0 does not see the options file: refused on every rank, naming it (exit %d, %.1f s)" % (p.returncode, t))
        check(r.get("converged") is False and "No such file" in r.get("error", ""), "... the failure report written (%s)" % r.get("error"))
    # the Python module (built beside the executable): rbcontact.initialize with an options file rank 1 cannot see
    pydir = os.path.join(os.path.dirname(os.path.dirname(exe)), "python")
    rom = d + "/rom.h5"
    if os.path.isdir(os.path.join(pydir, "rbcontact")):
        run(args, 1, ["offline", "-options_file", "runs/ring_on_block.opts", "-train_size", "5", "-rom", rom])
        script = d + "/init.py"
        with open(script, "w") as f:
            f.write("import sys\nsys.path.insert(0, %r)\nimport rbcontact\nrbcontact.initialize(['-options_file', 'runs/ring_on_block.opts'])\n"
                    "print('force %%.15g' %% rbcontact.ReducedModel(%r).solve([1.02]).contact_force)\n" % (pydir, rom))
        py = ["-n", "1", "--wdir", ROOT, "/usr/bin/python3", script]
        c = ["mpirun"] + py + [":"] + py[:2] + ["--wdir", d] + py[4:]
        try:
            p = subprocess.run(c, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace", stdin=subprocess.DEVNULL, timeout=120)
            forces = re.findall(r"^force (\S+)", p.stdout, re.M)
            check(p.returncode == 0 and len(forces) == 2 and forces[0] == forces[1], "Python: rbcontact.initialize with an options file only rank 0 sees works on 2 ranks (exit %d, %s)" % (p.returncode, forces))
        except subprocess.TimeoutExpired:
            subprocess.run(["pkill", "-f", script])
            check(False, "Python: rbcontact.initialize with an options file only rank 0 sees: hung (killed after 120 s)")


def stale(args):
    # what a job killed while writing leaves beside its output: <target>.tmp.<pid>, never reused (the next job's pid
    # differs); a snapshot file's is as large as the file. The dead pid: a process run here, killed and reaped.
    d = workdir()
    k = subprocess.Popen(["sleep", "60"])
    k.kill()
    k.wait()
    dead, live = k.pid, os.getpid()
    rep, out = d + "/fom.json", d + "/u.h5"
    planted = {rep + ".tmp.%d" % dead: 3 << 20, out + ".tmp.%d" % dead: 1 << 10, rep + ".tmp.%d" % live: 10}
    for path, size in planted.items():
        with open(path, "wb") as f:
            f.write(b"\0" * size)
    p = run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-report", rep, "-fom_output", out])
    warned = [l for l in p.stdout.splitlines() if "is a temporary file of this output left by a job that no longer runs" in l]
    check(len(warned) == 2, "two warnings, one per stale temporary file (%d: %s)" % (len(warned), warned))
    check(any("-report %s: '%s.tmp.%d' (3.0 MB)" % (rep, rep, dead) in l for l in warned), "-report: the dead job's file named with its size")
    check(any("-fom_output %s: '%s.tmp.%d' (0.0 MB)" % (out, out, dead) in l for l in warned), "-fom_output: the dead job's file named")
    check(not any(".tmp.%d" % live in l for l in warned), "the file of a process that runs (pid %d) is not named" % live)
    check(all(os.path.getsize(x) == n for x, n in planted.items()), "every planted file is still there, untouched (named, never removed)")
    check(load(rep).get("converged") is True and os.path.exists(out), "the run wrote its report and its output as usual")
    left = sorted(x for x in os.listdir(d) if ".tmp." in x and os.path.join(d, x) not in planted)
    check(not left, "the run left no temporary file of its own (%s)" % left)


def run_force(args, d, extra):
    run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-report", d + "/rf.json"] + extra)
    return load(d + "/rf.json")["contact_force"]


def gamg(args):
    d = workdir()
    run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-report", d + "/direct.json"])
    run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-fom_ksp_type", "cg", "-fom_pc_type", "gamg", "-report", d + "/gamg.json"])
    a, b = load(d + "/direct.json"), load(d + "/gamg.json")
    rel = abs(a["contact_force"] - b["contact_force"]) / abs(a["contact_force"])
    check(b["converged"] and rel <= 1e-6, "cg + gamg: contact force %.12g against the direct %.12g (rel %.1e <= 1e-6)" % (b["contact_force"], a["contact_force"], rel))
    # with a TAO contact QP as well: its inner KSP has its own prefix (fom_qp_), the elastic solver's options do not reach it
    run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-fom_qp_tao_type", "bqpip", "-fom_ksp_type", "cg", "-fom_pc_type", "gamg", "-report", d + "/gamg_tao.json"])
    c = load(d + "/gamg_tao.json")
    rel = abs(a["contact_force"] - c["contact_force"]) / abs(a["contact_force"])
    check(c["converged"] and rel <= 1e-6, "cg + gamg with the TAO QP (-fom_qp_tao_type bqpip): contact force %.12g (rel %.1e <= 1e-6)" % (c["contact_force"], rel))
    # the former spelling -fom_tao_type: the same run, one deprecation warning, no "not used" warning
    p = run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-fom_tao_type", "bqpip", "-report", d + "/old.json"])
    o = load(d + "/old.json")
    check(p.stdout.count("option -fom_tao_type is deprecated") == 1 and "was not used" not in p.stdout and o["contact_force"] == run_force(args, d, ["-fom_qp_tao_type", "bqpip"]),
          "-fom_tao_type bqpip: one deprecation warning, the same force as -fom_qp_tao_type bqpip")


def check_xdmf(xmf):
    """Every HDF DataItem of xmf against its dataset: exists, dimensions, number type and precision."""
    import xml.etree.ElementTree as ET
    base = os.path.dirname(xmf)
    bad, n = [], 0
    for item in ET.parse(xmf).iter("DataItem"):
        if item.get("Format") != "HDF":
            continue
        n += 1
        fname, ds = item.text.strip().split(":", 1)
        with h5py.File(os.path.join(base, fname), "r") as f:
            if ds not in f:
                bad.append("%s: no dataset %s" % (fname, ds))
                continue
            d = f[ds]
            dims = tuple(int(x) for x in item.get("Dimensions").split())
            kind = {"i": "Int", "u": "UInt", "f": "Float"}[d.dtype.kind]
            if dims != d.shape or kind != item.get("NumberType") or str(d.dtype.itemsize) != item.get("Precision"):
                bad.append("%s: .xmf says %s %s%s, the file holds %s %s%d" % (ds, dims, item.get("NumberType"), item.get("Precision"), d.shape, kind, d.dtype.itemsize))
    check(n > 0 and not bad, "%s: %d HDF data items match their datasets%s" % (os.path.basename(xmf), n, (": " + "; ".join(bad[:4])) if bad else ""))
    return ET.parse(xmf)


def paraview(args):
    import numpy as np
    d = workdir()
    run(args, args.np, ["fom", "-options_file", "runs/ring_on_block.opts", "-fom_output", d + "/fom.h5"])
    tree = check_xdmf(d + "/fom.xmf")
    grids = [g.get("Name") for g in tree.iter("Grid")]
    names = [a.get("Name") for g in tree.iter("Grid") if g.get("Name") == "contact" for a in g.iter("Attribute")]
    check(grids == ["mesh", "contact"] and {"lambda", "weight", "normal"} <= set(names), "fom.xmf: grids %s, contact attributes %s" % (grids, names))
    with h5py.File(d + "/fom.h5", "r") as f:
        pts, x, y = f["/contact/points"][()], f["/contact/x"][()], f["/contact/y"][()]
    check(pts.shape == (len(x), 3) and np.array_equal(pts[:, 0], x) and np.array_equal(pts[:, 1], y) and not pts[:, 2].any(),
          "the contact grid's %d points are the slave vertices (x, y, 0)" % len(x))
    rom = d + "/rom.h5"
    run(args, args.np, ["offline", "-options_file", "runs/ring_on_block.opts", "-train_size", "7", "-rom", rom, "-offline_basis_output", d + "/basis_view.h5", "-report", d + "/off.json"])
    off = load(d + "/off.json")
    bv = off.get("basis_view", {})
    check(bv.get("xdmf") == d + "/basis_view.xmf" and os.path.exists(bv.get("xdmf", "")), "offline -offline_basis_output: report key basis_view %s" % bv)
    tree = check_xdmf(d + "/basis_view.xmf")
    mesh_attrs = [a.get("Name") for g in tree.iter("Grid") if g.get("Name") == "mesh" for a in g.iter("Attribute")]
    contact_attrs = [a.get("Name") for g in tree.iter("Grid") if g.get("Name") == "contact" for a in g.iter("Attribute")]
    npod, nsup, r = bv.get("pod_modes", 0), bv.get("supremizers", 0), bv.get("dual", 0)
    want_mesh = ["pod_mode_%d" % k for k in range(npod)] + ["supremizer_%d" % k for k in range(nsup)]
    want_dual = ["dual_%d" % k for k in range(r)]
    check(npod + nsup == off["rom"]["N"] and r == off["rom"]["R"] and set(want_mesh) <= set(mesh_attrs) and set(want_dual) <= set(contact_attrs),
          "basis view: %d POD modes + %d supremizers (N %d) on the mesh, %d dual vectors (R %d) on the contact grid" % (npod, nsup, off["rom"]["N"], r, off["rom"]["R"]))
    with h5py.File(d + "/basis_view.h5", "r") as v, h5py.File(d + "/rom.basis.h5", "r") as b:
        modes, W = b["/pod/modes"][()], b["/dual/basis"][()]
        # the view holds each mode on the mesh vertices (P1): the free dofs' entries in another order, and zero
        # at the Dirichlet-constrained dofs (not the scene's boundary values: a mode is homogeneous)
        def vs_mode(k, nm):
            a = np.sort(np.ravel(v["/vertex_fields/%s_displacement" % nm][()]))
            return abs(a - np.sort(np.concatenate([modes[k], np.zeros(a.size - modes[k].size)]))).max()
        worst = max(vs_mode(k, nm) for k, nm in enumerate(want_mesh))
        dworst = max(abs(np.sort(v["/contact/dual_%d" % k][()]) - np.sort(W[k])).max() for k in range(r))
        dmin = min(v["/contact/dual_%d" % k][()].min() for k in range(r))
    check(worst <= 1e-14 * abs(modes).max() and dworst <= 1e-14 * abs(W).max() and dmin >= 0,
          "basis view entries = the basis file's (modes %.1e, dual %.1e), dual vectors nonnegative (min %.2g)" % (worst, dworst, dmin))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=["provenance", "failure", "help", "rename", "gamg", "paraview", "stale", "rank_files"])
    ap.add_argument("--exe", default=os.path.join(ROOT, "build/bin/rbcontact"))
    ap.add_argument("--np", type=int, default=1)
    args = ap.parse_args()
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    {"provenance": provenance, "failure": failure, "help": help_, "rename": rename, "gamg": gamg, "paraview": paraview, "stale": stale, "rank_files": rank_files}[args.what](args)
    if FAILED:
        print("%d check(s) failed" % len(FAILED))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
