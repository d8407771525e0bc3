#!/usr/bin/python3
"""hdf5_corruption.py: measurement (not a test) of what the ROM file reader does with damaged HDF5 metadata, in
the file format rbcontact writes (HDF5 1.8: checksummed object headers, src/io/h5util.hpp MemoryFile) and in HDF5's
earliest format (h5py's default and older rbcontact files; the same ROM file rewritten by h5py).

For each format: --n random single-byte changes of the file's metadata (every byte outside the datasets' raw data),
each file read by `rbcontact online -rom F -mu 1.02` (one process, no mpirun); one table row per outcome: accepted
with the same contact force, accepted with a different force (a silently wrong answer), refused (and whether the
message says corrupt or checksum), crashed (a signal), hung (--timeout). docs/bad_input.md holds the figures.

Usage: bench/hdf5_corruption.py [--exe build/bin/rbcontact] [--n 600] [--seed 7] [--timeout 20]
"""
import argparse
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np


def rewrite_earliest(src, dst):
    with h5py.File(src, "r") as fi, h5py.File(dst, "w", libver="earliest") as fo:
        for k, v in fi.attrs.items():
            fo.attrs[k] = v

        def copy(name, obj):
            g = fo.require_group(name) if isinstance(obj, h5py.Group) else fo.create_dataset(name, data=obj[()], dtype=obj.dtype)
            for k, v in obj.attrs.items():
                g.attrs[k] = v
        fi.visititems(copy)


def online(exe, rom, report, timeout):
    if os.path.exists(report):
        os.remove(report)
    return subprocess.run([exe, "online", "-rom", rom, "-mu", "1.02", "-report", report], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=timeout)


def flips(exe, src, n, seed, timeout, d):
    raw = []
    with h5py.File(src, "r") as f:
        def v(name, o):
            if isinstance(o, h5py.Dataset) and o.id.get_offset() is not None:
                raw.append((o.id.get_offset(), o.id.get_offset() + o.id.get_storage_size()))
        f.visititems(v)
    data = open(src, "rb").read()
    meta = np.ones(len(data), bool)
    for a, b in raw:
        meta[a:b] = False
    idx = np.nonzero(meta)[0]
    p = online(exe, src, d + "/ref.json", timeout)
    if p.returncode != 0:
        sys.exit("the undamaged file is refused:\n" + p.stdout[-2000:])
    fref = json.load(open(d + "/ref.json"))["outputs"]["contact_force"]
    rng, counts = random.Random(seed), {}
    for _ in range(n):
        i = int(idx[rng.randrange(len(idx))])
        b = bytearray(data)
        b[i] = (b[i] + rng.randrange(1, 256)) % 256
        open(d + "/x.h5", "wb").write(b)
        try:
            p = online(exe, d + "/x.h5", d + "/x.json", timeout)
            out = p.stdout
            if p.returncode == 0:
                key = "accepted, same force" if json.load(open(d + "/x.json"))["outputs"]["contact_force"] == fref else "accepted, DIFFERENT force"
            elif p.returncode < 0 or p.returncode >= 128 or "SEGV" in out:
                key = "crashed (exit %d)" % p.returncode
            else:
                key = "refused, says corrupt or checksum" if ("corrupt" in out or "checksum" in out) else "refused, other message"
        except subprocess.TimeoutExpired:
            key = "hung (%g s)" % timeout
        counts[key] = counts.get(key, 0) + 1
    return len(data), len(idx), counts


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--exe", default="build/bin/rbcontact")
    ap.add_argument("--n", type=int, default=600)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--timeout", type=float, default=20)
    a = ap.parse_args()
    exe = os.path.abspath(a.exe)
    d = tempfile.mkdtemp(prefix="rbc_h5corrupt_")
    try:
        env_ok = subprocess.run([exe, "offline", "-options_file", "runs/ring_on_block.opts", "-train_size", "5", "-offline_probe", "0", "-rom", d + "/native.h5"],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if env_ok.returncode != 0:
            sys.exit("offline failed:\n" + env_ok.stdout[-2000:])
        rewrite_earliest(d + "/native.h5", d + "/earliest.h5")
        print("| file format | file bytes | metadata bytes | outcome | changes |")
        print("|---|---|---|---|---|")
        for name, f in (("HDF5 1.8 (rbcontact's)", d + "/native.h5"), ("earliest (h5py's default)", d + "/earliest.h5")):
            size, nmeta, counts = flips(exe, f, a.n, a.seed, a.timeout, d)
            for k, v in sorted(counts.items()):
                print("| %s | %d | %d | %s | %d of %d |" % (name, size, nmeta, k, v, a.n))
    finally:
        shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    main()
