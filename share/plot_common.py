"""plot_common.py: what the plotting scripts of share/ have in common (not a script of its own): the error exit
that names the calling script, and the check that numpy, matplotlib (with its headless backend) and, when asked,
h5py are there, with a message saying how to get them. The scripts import it from their own directory (share/,
or scripts/ of an installed tree), so it must stay beside them.
"""
import os
import sys


def fail(msg):
    sys.stderr.write("%s: error: %s\n" % (os.path.basename(sys.argv[0]), msg))
    sys.exit(1)


def require_plotting(h5py=True):
    """Select matplotlib's Agg backend; exit with a clear message if a package is missing."""
    try:
        import numpy  # noqa: F401
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot  # noqa: F401
        if h5py:
            import h5py as _h5py  # noqa: F401
    except ImportError as e:  # pragma: no cover
        fail("%s (interpreter %s). Run with /usr/bin/python3 after share/setup.sh "
             "(python3-numpy%s python3-matplotlib)" % (e, sys.executable, " python3-h5py" if h5py else ""))
