"""rbcontact: reduced-basis models of frictionless contact, online from Python.

A ROM file written by ``rbcontact offline`` answers new parameters in microseconds::

    import numpy as np, rbcontact
    rom = rbcontact.ReducedModel("rom.h5")            # opens the file (PETSc starts on first use)
    s = rom.solve([1.02])                             # one parameter point: s.v, s.lambda_hat, s.contact_force
    radii = np.linspace(0.95, 1.15, 100)
    forces = rom.contact_forces(radii)                # the contact force at 100 radii, one NumPy array

PETSc options (``-rom_*``, docs/online.md) go through ``rbcontact.initialize([...])`` before the first model.
Errors (a missing or mismatched file, a parameter outside its box, a solve that does not converge) raise
RuntimeError with the message of the command-line stages. docs/python.md.
"""
from ._rbcontact import ReducedModel, Solution, initialize, finalize

__all__ = ["ReducedModel", "Solution", "initialize", "finalize"]
