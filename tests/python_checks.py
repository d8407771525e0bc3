#!/usr/bin/python3
"""Checks of the Python module (python/module.cpp), run by ctest (tests/python.cmake):
  - a ROM of ring_on_block (offline on 2 ranks) opened from Python: its parameter box, N, R, hyper;
  - 100 radii through ReducedModel.contact_forces: every force equals the `rbcontact online` report's
    outputs.contact_force at 5 of them (the same code: relative difference <= 1e-12), and the FOM's at one
    radius to 1e-3 (an independent reference);
  - solve(): error_u, error_lambda, error_force (nan without offline -estimate, the online report's with it);
  - solve(): converged, reduced coordinates of the report's sizes, force vector whose norm is contact_force;
  - bad input raises RuntimeError naming the cause: a missing ROM file (its path), a radius outside the box
    (the parameter), an array of the wrong shape; nan_on_failure keeps going past no failure here;
  - the offline and validate stages from Python (rbcontact.offline / validate, the library's RunOffline and
    RunValidation): the same ROM (forces to 1e-12) and the same validation errors as the command line with
    the same options, the report returned and written, a bad option value raising with the option named;
  - bad keywords and words refused naming the option, the earlier report replaced by the failure: integers beyond 32 bits
    (also initialize()'s), empty list entries and values, NUL characters, a missing options file; a misspelled
    initialize() option warned about; the GIL released during a call, calls from several threads serialized.
Usage: python_checks.py --exe build/bin/rbcontact --pythonpath build/python
"""
import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time

failures = 0


def check(cond, msg):
    global failures
    print("  %-4s %s" % ("ok" if cond else "FAIL", msg), flush=True)
    if not cond:
        failures += 1


def run(exe, np_, args):
    cmd = (["mpiexec", "-n", str(np_)] if np_ > 1 else []) + [exe] + args
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.stdout.write(p.stdout[-3000:])
        sys.exit("python_checks.py: error: command failed (exit %d): %s" % (p.returncode, " ".join(cmd)))
    return p.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--exe", required=True)
    ap.add_argument("--pythonpath", required=True)
    args = ap.parse_args()
    sys.path.insert(0, args.pythonpath)
    import numpy as np
    import rbcontact

    d = tempfile.mkdtemp(prefix="rbc_python_")
    try:
        rom = os.path.join(d, "rom.h5")
        run(args.exe, 2, ["offline", "-options_file", "runs/ring_on_block.opts", "-rom", rom, "-report", d + "/off.json"])
        # (mpiexec before the first model initializes MPI in this process)
        rome = os.path.join(d, "rom_e.h5")
        run(args.exe, 2, ["offline", "-options_file", "runs/ring_on_block.opts", "-rom", rome, "-estimate", "-report", d + "/off_e.json"])
        # a small 3D model (2 x 2 grid) and its online report at one parameter, for the 3D outputs below
        rom3 = os.path.join(d, "rom3.h5")
        run(args.exe, 2, ["offline", "-options_file", "runs/sphere_block3d.opts", "-train_size", "2", "-rom", rom3, "-report", d + "/off3.json"])
        run(args.exe, 1, ["online", "-rom", rom3, "-mu", "1.1,0.045", "-online_repeat", "1", "-report", d + "/on3.json"])
        exe_version = subprocess.run([args.exe, "--version"], stdout=subprocess.PIPE, text=True).stdout.strip()
        check(rbcontact.version_line == exe_version and exe_version.startswith("rbcontact " + rbcontact.__version__ + " (commit "),
              "rbcontact.__version__ %s and version_line as `rbcontact --version` (%s)" % (rbcontact.__version__, rbcontact.version_line))
        m = rbcontact.ReducedModel(rom)
        (name, lo, hi), = m.parameters
        check(name == "radius" and abs(lo - 0.95) < 1e-14 and abs(hi - 1.15) < 1e-14, "parameter box from the file: %s in [%g, %g]" % (name, lo, hi))
        off = json.load(open(d + "/off.json"))
        check(m.N == off["rom"]["N"] and m.R == off["rom"]["R"] and m.hyper == "ecsw", "sizes N %d R %d and hyper-reduction %s as the offline report" % (m.N, m.R, m.hyper))

        radii = np.linspace(lo, hi, 100)
        forces = m.contact_forces(radii)
        check(forces.shape == (100,) and np.all(np.isfinite(forces)) and np.all(forces > 0), "contact_forces: 100 finite positive forces (%.4f .. %.4f)" % (forces.min(), forces.max()))
        worst = 0.0
        for k in (0, 17, 50, 83, 99):
            rep = d + "/on%d.json" % k
            run(args.exe, 1, ["online", "-rom", rom, "-mu", repr(float(radii[k])), "-report", rep])
            f = json.load(open(rep))["outputs"]["contact_force"]
            worst = max(worst, abs(forces[k] - f) / f)
        check(worst <= 1e-12, "the same forces as `rbcontact online` at 5 radii (max rel diff %.1e <= 1e-12)" % worst)
        r = 1.02
        run(args.exe, 1, ["fom", "-options_file", "runs/ring_on_block.opts", "-mu", str(r), "-report", d + "/fom.json"])
        ff = json.load(open(d + "/fom.json"))["contact_force"]
        s = m.solve([r])
        check(s.converged and s.iterations >= 1 and s.v.shape == (m.N,) and s.lambda_hat.shape == (m.R,) and s.message == "", "solve([%g]): converged in %d iterations, v (%d), lambda_hat (%d)" % (r, s.iterations, m.N, m.R))
        check(s.force.shape == (2,) and abs(np.linalg.norm(s.force) - s.contact_force) <= 1e-14 * s.contact_force, "force vector %s, its norm = contact_force" % s.force)
        check(abs(s.contact_force - ff) <= 1e-3 * ff, "contact force %.8f vs the FOM's %.8f (rel %.1e <= 1e-3)" % (s.contact_force, ff, abs(s.contact_force - ff) / ff))
        fj = json.load(open(d + "/fom.json"))
        pm, hw = fj["max_pressure"], fj["contact_halfwidth_moment"]
        check(abs(s.max_pressure - pm) <= 1e-2 * pm and abs(s.contact_halfwidth - hw) <= 1e-2 * hw and s.contact_length == 2 * s.contact_halfwidth,
              "max pressure %.6f and half-width %.6f vs the FOM's %.6f, %.6f (rel %.1e, %.1e <= 1e-2)" % (s.max_pressure, s.contact_halfwidth, pm, hw, abs(s.max_pressure - pm) / pm, abs(s.contact_halfwidth - hw) / hw))
        check(np.isnan(s.contact_radius), "2D: contact_radius (3D) is nan")
        s3, o3 = rbcontact.ReducedModel(rom3).solve([1.1, 0.045]), json.load(open(d + "/on3.json"))["outputs"]
        check(s3.converged and abs(s3.contact_radius - o3["contact_radius"]) <= 1e-12 * o3["contact_radius"] and np.isnan(s3.contact_halfwidth) and np.isnan(s3.contact_length),
              "3D: contact_radius %.12g = the online report's %.12g; half-width and length nan" % (s3.contact_radius, o3["contact_radius"]))
        check(np.array_equal(m.contact_forces(np.array([[r]])), np.array([s.contact_force])), "contact_forces on an (n, 1) array = solve")
        # the online error estimate (docs/error_estimate.md): nan without it in the file, the online report's with it
        check(np.isnan(s.error_u) and np.isnan(s.error_lambda) and np.isnan(s.error_force), "a ROM without -estimate: error_u, error_lambda, error_force are nan")
        se = rbcontact.ReducedModel(rome).solve([r])
        run(args.exe, 1, ["online", "-rom", rome, "-mu", repr(r), "-report", d + "/on_e.json"])
        ee = json.load(open(d + "/on_e.json"))["error_estimate"]
        check(ee["available"] and all(abs(getattr(se, "error_" + k) - ee[k]) <= 1e-12 * ee[k] for k in ("u", "lambda", "force")),
              "offline -estimate: solve() gives the online report's error estimate (u %.2e, lambda %.2e, force %.2e)" % (se.error_u, se.error_lambda, se.error_force))

        def raises(f, words, what):
            try:
                f()
            except RuntimeError as e:
                msg = str(e)
                check(all(w in msg for w in words), "%s: RuntimeError naming %s (%s)" % (what, ", ".join(words), msg.splitlines()[0][:150]))
                return
            check(False, "%s: no exception" % what)

        missing = os.path.join(d, "nonexistent.h5")
        raises(lambda: rbcontact.ReducedModel(missing), [missing], "a missing ROM file")
        # a pathlib.Path (a TypeError) and a name with a NUL character (cut there: the file before it opened; audit J)
        import pathlib
        check(rbcontact.ReducedModel(pathlib.Path(rom)).solve([1.02]).contact_force == m.solve([1.02]).contact_force, "ReducedModel(pathlib.Path): the same model")
        raises(lambda: rbcontact.ReducedModel(rom + "\0garbage"), ["holds a NUL character"], "a ROM file name with a NUL character")
        raises(lambda: m.solve([1.3]), ["solve: parameter 'radius' = 1.3 is outside its box"], "a radius outside the box (named as solve's, not -mu's)")
        raises(lambda: m.contact_forces(np.array([1.0, 1.2])), ["contact_forces: row 1", "radius"], "a radius outside the box in contact_forces (the row named, not -mu)")
        raises(lambda: m.contact_forces(np.zeros((3, 2))), ["(n, 1)"], "an array of the wrong shape")
        raises(lambda: rbcontact.initialize(["-rom_kacanov_monitor"]), ["already initialized"], "options after the first model")
        # a complex array was cast to its real part without a word (pybind11's forcecast)
        try:
            m.contact_forces(np.array([1.0 + 0.5j]))
            check(False, "a complex array in contact_forces: no exception")
        except TypeError as e:
            check("dtype complex128" in str(e), "a complex array in contact_forces: TypeError naming its dtype (%s)" % str(e)[:120])
        check(np.array_equal(m.contact_forces([1.02, 1.05]), m.contact_forces(np.array([[1.02], [1.05]]))), "contact_forces on a list = on an (n, 1) array")
        # solve() took a complex value's real part and a bool as 1.0; a copy that cannot be allocated crashed the
        # interpreter (audit of 2026-12-01)
        for bad, what in (([1.02 + 0.5j], "a complex value in solve"), (np.array([1.02 + 0.5j]), "a complex array in solve"), ([True], "a bool in solve"),
                          (np.array([[True]]), "a bool array in contact_forces")):
            try:
                (m.contact_forces if "contact_forces" in what else m.solve)(bad)
                check(False, "%s: no exception" % what)
            except TypeError as e:
                check("expected real parameter values, got dtype" in str(e), "%s: TypeError naming its dtype (%s)" % (what, str(e)[:100]))
        check(m.solve(np.array([1.02])).contact_force == m.solve([1.02]).contact_force == m.solve((1.02,)).contact_force, "solve on an array, a list, a tuple: one answer")
        try:
            m.contact_forces(np.broadcast_to(np.array([1.02]), (10 ** 13, 1)))
            check(False, "a broadcast view of 1e13 rows: no exception")
        except MemoryError as e:
            check("cannot make a contiguous float64 copy" in str(e), "a broadcast view of 1e13 rows in contact_forces: MemoryError, no crash (%s)" % str(e)[:100])
        def fresh(code):  # in a fresh interpreter (initialize() comes before the first model)
            p = subprocess.run([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace",
                               env=dict(os.environ, PYTHONPATH=args.pythonpath))
            return p.returncode, p.stdout

        # options before the first model: they reach the reduced model; a misspelled one is warned about once (the first
        # model reads them), the others not; a NUL character refused before PETSc starts (it cut the word: '2\0x' read as 2)
        rc, out = fresh("import warnings, rbcontact\n"
                        "try:\n    rbcontact.initialize(['-rom_R', '2\\0x'])\nexcept RuntimeError as e:\n    print('NUL:', e)\n"
                        "with warnings.catch_warnings(record=True) as w:\n    warnings.simplefilter('always')\n"
                        "    rbcontact.initialize(['-rom_kacanov_monitor', '-rom_R', '2', '-rom_kacanov_monitr'])\n"
                        "    m = rbcontact.ReducedModel(%r); m2 = rbcontact.ReducedModel(%r)\n"
                        "print('WARN', [str(x.message) for x in w])\n"
                        "s = m.solve([1.02]); print('R', m.R, 'lambda_hat', len(s.lambda_hat), 'converged', s.converged)" % (rom, rom))
        check(rc == 0 and "R 2 lambda_hat 2 converged True" in out and "ROM Kacanov" in out,
              "initialize(options) before the first model: -rom_R 2 and the Kacanov monitor take effect (exit %d)" % rc)
        warned = [l for l in out.splitlines() if l.startswith("WARN ")]
        check(len(warned) == 1 and warned[0].count("was not used") == 1 and "rbcontact.initialize: option -rom_kacanov_monitr was not used" in warned[0],
              "initialize() with a misspelled option: one UserWarning naming it, at the first model only (%s)" % (warned[0][:120] if warned else out[-300:]))
        check("NUL: rbcontact.initialize: option -rom_R '2\\0x': a NUL character in the value" in out, "initialize() with a NUL character: refused naming the option")
        # a daemon thread inside solve when the interpreter exits: a clean exit (pybind11's GIL guard took the GIL back in
        # a destructor, and the thread's forced unwind there was std::terminate: SIGABRT, exit 134; audit J)
        codes = [fresh("import rbcontact, threading, time\nm = rbcontact.ReducedModel(%r)\n"
                       "def bg():\n    while True: m.solve([1.02])\n"
                       "threading.Thread(target=bg, daemon=True).start(); time.sleep(0.2); print('main done')" % rom)[0] for _ in range(3)]
        check(codes == [0, 0, 0], "a daemon thread solving while the interpreter exits: exit codes %s (0)" % codes)
        # integer options beyond 32 bits (PETSc casts them: -rom_N 4294967297 ran with N 1), as the executable refuses them
        rc, out = fresh("import rbcontact; rbcontact.initialize(['-rom_N', '4294967297'])\n"
                        "try:\n    rbcontact.ReducedModel(%r); print('accepted')\nexcept RuntimeError as e:\n    print('refused:', e)" % rom)
        check(rc == 0 and "refused: Input string 4294967297 is out of the range of a 32-bit integer (option -rom_N 4294967297)" in out,
              "initialize(['-rom_N', '4294967297']): the model refuses it, naming the option (%s)" % out.strip().splitlines()[-1][:110])
        # ... unless PETSc was loaded before the module (petsc4py first): then a RuntimeWarning says the check is off
        lib = re.search(r"=> (\S*libpetsc\S*)", subprocess.run(["ldd", glob.glob(os.path.join(args.pythonpath, "rbcontact", "_rbcontact*.so"))[0]],
                                                                stdout=subprocess.PIPE, text=True).stdout)
        rc, out = fresh("import ctypes, warnings; ctypes.CDLL(%r, mode=ctypes.RTLD_GLOBAL); warnings.simplefilter('always')\n"
                        "import rbcontact; m = rbcontact.ReducedModel(%r); print('opened')" % (lib.group(1) if lib else "libpetsc.so", rom))
        check(rc == 0 and "RuntimeWarning: rbcontact: PETSc was loaded before this module" in out and "opened" in out,
              "PETSc loaded before the module: a RuntimeWarning that integer options are not range-checked (exit %d)" % rc)
        check(np.allclose(m.contact_forces(radii[:3], nan_on_failure=True), forces[:3], rtol=0, atol=0), "nan_on_failure: the same forces where every solve converges")
        # contact projections at the edge of the stored data (a half_disks ROM of 2 x 2 points): the command line warns, and
        # so do solve() and contact_forces(), with Solution.out_of_range (silent before; audit J)
        run(args.exe, 1, ["offline", "-options_file", "runs/half_disks.opts", "-train_size", "2,2", "-offline_probe", "0", "-rom", d + "/hd22.h5"])
        import warnings
        hd = rbcontact.ReducedModel(d + "/hd22.h5")
        edge = [0.86064982349869057, 0.063233953393474707]
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            se = hd.solve(edge)
            hd.contact_forces(np.array([edge, edge]))
        msgs = [str(x.message) for x in w if issubclass(x.category, RuntimeWarning)]
        check(se.converged and se.out_of_range > 0 and len(msgs) == 2 and "fell at the edge of the stored contact data" in msgs[0] and "at 2 row(s)" in msgs[1],
              "projections at the edge of the stored data: out_of_range %d and a RuntimeWarning from solve() and contact_forces() (%s)" % (se.out_of_range, [x[:60] for x in msgs]))
        cli = run(args.exe, 1, ["online", "-rom", d + "/hd22.h5", "-mu", "%.17g,%.17g" % tuple(edge)])
        check("%d contact projections fell at the edge" % se.out_of_range in cli, "the command line's online counts the same %d projections" % se.out_of_range)
        del hd

        # the offline and validate stages from Python, against the command line with the same options
        pyrom, clirom = d + "/py5.h5", d + "/cli5.h5"
        rep = rbcontact.offline(options_file="runs/ring_on_block.opts", rom=pyrom, train_size=5, report=d + "/pyoff.json")
        run(args.exe, 1, ["offline", "-options_file", "runs/ring_on_block.opts", "-rom", clirom, "-train_size", "5"])
        written = json.load(open(d + "/pyoff.json"))
        check(rep["stage"] == "offline" and rep["fom_solves"] == 5 and rep["rom"]["N"] == written["rom"]["N"] and os.path.exists(pyrom),
              "rbcontact.offline: 5 FOM solves, the report returned and written, %s exists" % os.path.basename(pyrom))
        fp = rbcontact.ReducedModel(pyrom).contact_forces(radii[::20])
        fc = rbcontact.ReducedModel(clirom).contact_forces(radii[::20])
        dmax = float(np.max(np.abs(fp - fc) / fc))
        check(dmax <= 1e-12, "the Python-built ROM answers as the command line's (max rel diff %.1e <= 1e-12 at 5 radii)" % dmax)
        val = rbcontact.validate("-options_file", "runs/ring_on_block.opts", rom=pyrom, test_size=3, validate_repeat=1)
        run(args.exe, 1, ["validate", "-options_file", "runs/ring_on_block.opts", "-rom", pyrom, "-test_size", "3", "-validate_repeat", "1", "-report", d + "/cliv.json"])
        cv = json.load(open(d + "/cliv.json"))
        eu, ec = val["test"]["rel_err_u"], cv["test"]["rel_err_u"]
        check(val["test"]["n"] == 3 and max(abs(a - b) for a, b in zip(eu, ec)) <= 1e-10 * max(ec) and max(eu) < 1e-3,
              "rbcontact.validate: 3 test radii, u errors %s equal to the command line's" % ", ".join("%.2e" % x for x in eu))
        raises(lambda: rbcontact.offline(options_file="runs/ring_on_block.opts", rom=d + "/bad.h5", offline_stop="bogus"), ["-offline_stop", "bogus"], "an unknown -offline_stop from Python")
        # the probe from Python: the offline report's (same file, sample and seed) and the command line's
        pr = rbcontact.probe(rom=pyrom)["probe"]
        run(args.exe, 1, ["probe", "-rom", pyrom, "-report", d + "/clip.json"])
        cp = json.load(open(d + "/clip.json"))["probe"]
        check(pr["size"] == 1000 and pr["failed"] == 0 and pr == {**cp, "time_s": pr["time_s"]} and rep["probe"]["kacanov_iterations"] == pr["kacanov_iterations"],
              "rbcontact.probe: 1000 parameters, none failed, the command line's report and the offline stage's iterations")
        raises(lambda: rbcontact.probe(rom=pyrom, probe_size=0), ["-probe_size"], "-probe_size 0 from Python")
        # keywords: False turns an option off, an options file never overrides the keywords given with it (whatever their
        # order), a misspelled keyword is warned about (it ran the file's 21 points without a word)
        import warnings
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r5 = rbcontact.offline(train_size=5, rom=d + "/kw.h5", offline_probe=False, trian_size=3, options_file="runs/ring_on_block.opts")
        said = [str(w.message) for w in caught if "trian_size" in str(w.message)]
        check(r5["ntrain"] == 5 and "probe" not in r5, "keywords before options_file= win over the file (5 training points), offline_probe=False turns the probe off")
        check(len(said) == 1 and "was not used by the offline stage" in said[0] and any("trian_size" in w for w in r5.get("warnings", [])),
              "a misspelled keyword (trian_size): a UserWarning and the report's warnings")
        # an options file that includes itself (crashed the interpreter); a failed call replaces an earlier report
        with open(d + "/self.opts", "w") as f:
            f.write("-options_file %s/self.opts\n" % d)
        raises(lambda: rbcontact.validate(options_file=d + "/self.opts", rom=pyrom), ["includes itself"], "an options file that includes itself, from Python")
        with open(d + "/old.json", "w") as f:
            f.write('{"stage": "old", "converged": true}')
        raises(lambda: rbcontact.validate(options_file="runs/ring_on_block.opts", rom=missing, report=d + "/old.json"), ["nonexistent.h5"], "validate of a missing ROM from Python")
        check(json.load(open(d + "/old.json"))["converged"] is False, "the failed call replaced the earlier report with its failure")
        # a call failing before the stage (a missing options file) replaces it too, as the command line does; and so does a
        # failure after a call whose report was refused (the library's mark of that refusal outlived its call)
        def mkold():
            with open(d + "/old.json", "w") as f:
                f.write('{"stage": "old", "converged": true}')
        mkold()
        raises(lambda: rbcontact.validate(options_file=d + "/nosuch.opts", rom=pyrom, report=d + "/old.json"), ["nosuch.opts", "No such file"], "a missing options file from Python")
        old = json.load(open(d + "/old.json"))
        check(old.get("converged") is False and old.get("stage") == "validate" and "nosuch.opts" in old.get("error", ""), "a missing options file: the earlier report replaced by the failure naming it")
        os.mkdir(d + "/adir")
        raises(lambda: rbcontact.validate(options_file="runs/ring_on_block.opts", rom=pyrom, report=d + "/adir"), ["-report", "directory"], "a report onto a directory")
        mkold()
        raises(lambda: rbcontact.validate(options_file="runs/ring_on_block.opts", rom=missing, report=d + "/old.json"), ["nonexistent.h5"], "validate of a missing ROM after a refused report")
        check(json.load(open(d + "/old.json")).get("converged") is False, "after a call whose report was refused, a failed call still replaces its report")
        # integer keywords beyond 32 bits (they wrapped: probe_size=2**32+1 ran 1 point), words too
        raises(lambda: rbcontact.probe(rom=pyrom, probe_size=2 ** 32 + 1), ["out of the range of a 32-bit integer", "-probe_size 4294967297"], "probe_size=2**32+1")
        raises(lambda: rbcontact.validate("-validate_repeat", str(2 ** 40), options_file="runs/ring_on_block.opts", rom=pyrom, test_size=2),
               ["32-bit", "-validate_repeat 1099511627776"], "the word -validate_repeat 2**40")
        # empty list entries (lost without a word: [0.5, '', 1] read as 0.5,1), empty values (the option a flag), NUL
        # characters (the value cut there: rom='x.h5\0y' opened x.h5): refused naming the keyword, the report replaced
        for kw, words in (({"validate_sweep_fractions": [0.5, "", 1]}, ["-validate_sweep_fractions 0.5,,1", "empty entry"]),
                          ({"validate_sweep_fractions": [0.5, ""]}, ["-validate_sweep_fractions 0.5,", "empty entry"]),
                          ({"validate_sweep_fractions": "1,,2"}, ["-validate_sweep_fractions 1,,2", "empty entry"]),
                          ({"validate_sweep_fractions": []}, ["-validate_sweep_fractions", "empty value"]),
                          ({"test_seed": ""}, ["-test_seed", "empty value"]),
                          ({"rom": pyrom + "\0x"}, ["option -rom", "\\0x", "NUL character"])):
            mkold()
            raises(lambda: rbcontact.validate(options_file="runs/ring_on_block.opts", **dict({"rom": pyrom, "validate_sweep": True, "validate_sweep_output": d + "/sweep", "report": d + "/old.json"}, **kw)),
                   words, "validate(%s)" % ", ".join("%s=%r" % x for x in kw.items()))
            check(json.load(open(d + "/old.json")).get("converged") is False, "  ... and the earlier report replaced by the failure")
        with open(d + "/list.opts", "w") as f:
            f.write("-options_file runs/ring_on_block.opts\n-validate_sweep_fractions 0.25,,1\n")
        raises(lambda: rbcontact.validate(options_file=d + "/list.opts", rom=pyrom, validate_sweep=True, validate_sweep_output=d + "/sweep"), ["-validate_sweep_fractions 0.25,,1", "empty entry"],
               "an empty list entry in an options file")
        # the GIL is released during a call: another thread runs meanwhile (it waited for the stage's end); calls from
        # several threads run one after the other, each with its own options and the same answers as alone
        ticks, done = [0], threading.Event()
        def ticker():
            while not done.is_set():
                ticks[0] += 1
                time.sleep(0.001)
        tt = threading.Thread(target=ticker)
        tt.start()
        t0 = time.time()
        p1 = rbcontact.probe(rom=pyrom, probe_size=20000)["probe"]
        elapsed = time.time() - t0
        done.set()
        tt.join()
        check(ticks[0] >= 10 and p1["failed"] == 0, "another Python thread runs during a stage: %d ticks of 1 ms in its %.2f s" % (ticks[0], elapsed))
        results = {}
        def work(name, f):
            try:
                results[name] = f()
            except Exception as e:
                results[name] = e
        jobs = [threading.Thread(target=work, args=("forces%d" % k, lambda: m.contact_forces(radii))) for k in range(2)]
        jobs += [threading.Thread(target=work, args=("probe%d" % k, lambda k=k: rbcontact.probe(rom=pyrom, probe_size=200 + k)["probe"])) for k in range(2)]
        for j in jobs:
            j.start()
        for j in jobs:
            j.join()
        alone = [rbcontact.probe(rom=pyrom, probe_size=200 + k)["probe"] for k in range(2)]
        same = [isinstance(results["forces%d" % k], np.ndarray) and np.array_equal(results["forces%d" % k], forces) for k in range(2)]
        same += [isinstance(results["probe%d" % k], dict) and results["probe%d" % k]["size"] == 200 + k and dict(results["probe%d" % k], time_s=0) == dict(alone[k], time_s=0)
                 for k in range(2)]
        check(all(same), "4 threads (2 contact_forces, 2 probes of their own sizes): the answers of the calls alone (%s)" % same)
        del m
        # after finalize() PETSc cannot start again (MPI cannot): an exception, not an abort of the interpreter
        rbcontact.finalize()
        raises(lambda: rbcontact.ReducedModel(pyrom), ["finalized"], "a model opened after rbcontact.finalize()")
    finally:
        shutil.rmtree(d, ignore_errors=True)
    print("%d passed, %d failed" % (0 if failures else 1, 1 if failures else 0))
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
