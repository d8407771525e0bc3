"""rbcontact: reduced-basis models of frictionless contact, online from Python.

A ROM file written by ``rbcontact offline`` answers new parameters in microseconds::

    import numpy as np, rbcontact
    rom = rbcontact.ReducedModel("rom.h5")            # opens the file (PETSc starts on first use)
    s = rom.solve([1.02])                             # one parameter point: s.v, s.lambda_hat, s.contact_force
    radii = np.linspace(0.95, 1.15, 100)
    forces = rom.contact_forces(radii)                # the contact force at 100 radii, one NumPy array

The offline and validate stages run from Python too, with their options given as keywords (or a list of
command-line words) and their JSON report returned as a dict::

    rep = rbcontact.offline(options_file="runs/ring_on_block.opts", rom="rom.h5", train_size=5)
    val = rbcontact.validate(options_file="runs/ring_on_block.opts", rom="rom.h5", test_size=5)
    val["test"]["max_rel_err_u"]
    rbcontact.probe(rom="rom.h5")["probe"]["failed"]   # the ROM at 1000 parameters of its box, no FOM

PETSc options (``-rom_*``, docs/online.md) go through ``rbcontact.initialize([...])`` before the first model
(the first model warns about those nobody read). Errors (a missing or mismatched file, a parameter outside its box,
a solve that does not converge, a bad option value: an integer beyond 32 bits, an empty list entry, a NUL character)
raise RuntimeError with the message of the command-line stages, naming the option.

Threads and Ctrl-C: every call releases the GIL while it runs, so other Python threads go on meanwhile; but PETSc's
options database and error state are global, so calls from several threads run one after the other (a mutex), never
at the same time, and other threads must not use PETSc or MPI themselves (petsc4py, mpi4py) during a call. Ctrl-C
is seen when the running call ends (a stage of minutes runs to its end, then KeyboardInterrupt). docs/python.md.
"""
import json as _json

from ._rbcontact import ReducedModel, Solution, initialize, finalize, _run_stage, __version__, version_line


def _words(args, kw):
    # an options file first, so that the keywords and words given with it override its values whatever their order
    # (PETSc lets the later of two settings win); None leaves an option out, False gives "-name 0"
    kw = dict(kw)
    words = []
    if kw.get("options_file") is not None:
        words += ["-options_file", str(kw.pop("options_file"))]
    words += [str(a) for a in args]
    for k, v in kw.items():
        if v is None:
            continue
        words.append("-" + k)
        if v is False:
            words.append("0")
        elif v is not True:
            words.append(",".join(str(x) for x in v) if isinstance(v, (list, tuple)) else str(v))
    return words


def offline(*args, **options):
    """Run the offline stage (snapshots, bases, ROM file) with these options; returns its report (dict).

    ``offline(options_file="runs/ring_on_block.opts", rom="rom.h5", train_size=5)`` is
    ``rbcontact offline -options_file runs/ring_on_block.opts -rom rom.h5 -train_size 5``; positional
    arguments are command-line words as they are. Only these options apply (not initialize()'s).
    """
    return _json.loads(_run_stage("offline", _words(args, options)))


def validate(*args, **options):
    """Run the validate stage (the ROM against the FOM on a test set); returns its report (dict)."""
    return _json.loads(_run_stage("validate", _words(args, options)))


def probe(*args, **options):
    """Solve a ROM file at many parameters of its box without the FOM (``rbcontact probe``; docs/online.md
    "Probing a model"); returns the report (dict). ``probe(rom="rom.h5", probe_size=1000)["probe"]["failed"]``
    counts the parameters where the reduced loop failed (not an exception here, unlike the command line's exit code)."""
    return _json.loads(_run_stage("probe", _words(args, options)))


__all__ = ["ReducedModel", "Solution", "initialize", "finalize", "offline", "validate", "probe", "version_line"]
