#!/usr/bin/env python3
"""How often the online point sum reads a row of theta that is not in a cache of the given size, for the
cubature points in the file's order, in slave facet order (what ReducedModel::OrderCubaturePoints makes of
them when the file is read) and along a Morton curve of their reference positions (docs/online.md "The
cubature points in slave facet order"). A least-recently-used cache of whole rows; each point reads the rows
of its slave facet's nodes and of its first stored master candidate's (the facet it projected onto at the
training states). Usage: bench/cubature_row_reuse.py ROM.h5 [--rows 300 1100 4000]"""
import argparse
import collections

import h5py
import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("rom")
    ap.add_argument("--rows", type=int, nargs="+", default=[300, 1100, 4000], help="cache sizes in rows of theta")
    a = ap.parse_args()
    with h5py.File(a.rom, "r") as f:
        g = f["online/contact"]
        dim = int(g["meta"][0])
        S, Mf, P = g["slave"][:], g["master"][:], g["points"][:]
        cs, cc = g["cand_start"][:].astype(int), g["cand"][:].astype(int)
        cpts = f["online/ecsw/points"][:].astype(int)
        N = int(g["meta"][1])

    def nodes(rec):
        return [int(x) for x in rec[19:19 + int(rec[2])]]

    rows, X = [], []
    for p in cpts:
        sf = int(P[p, 0])
        r = [n * dim + d for n in nodes(S[sf]) for d in range(dim)]
        if cs[p] < cs[p + 1] and cc[cs[p]] >= 0:
            r += [n * dim + d for n in nodes(Mf[cc[cs[p]]]) for d in range(dim)]
        rows.append(r)
        X.append(P[p, 1:1 + dim] @ S[sf, 4:4 + 9].reshape(3, 3)[:dim, :dim])
    X = np.array(X)

    def misses(order, cap):
        c, miss, tot = collections.OrderedDict(), 0, 0
        for p in order:
            for r in rows[p]:
                tot += 1
                if r in c:
                    c.move_to_end(r)
                else:
                    miss += 1
                    c[r] = True
                    if len(c) > cap:
                        c.popitem(last=False)
        return miss / tot

    q = ((X - X.min(0)) / (np.ptp(X, 0) + 1e-30) * 1023).astype(np.int64)
    morton = [sum(((int(v[d]) >> b) & 1) << (dim * b + d) for b in range(10) for d in range(dim)) for v in q]
    orders = {"file": np.arange(len(cpts)), "slave facet": np.lexsort((cpts, P[cpts, 0])), "Morton": np.argsort(morton, kind="stable")}
    reads, distinct = sum(len(r) for r in rows), len({x for r in rows for x in r})
    print("%s: Mc %d, %d row reads (%.1f a point), %d distinct rows (the compulsory misses %.1f %%), %d bytes a float row (N %d, padded to 8)"
          % (a.rom, len(cpts), reads, reads / len(cpts), distinct, 100.0 * distinct / reads, 4 * (-(-N // 8) * 8), N))
    print("| cache (rows) | " + " | ".join(orders) + " |")
    print("|---|" + "---|" * len(orders))
    for cap in a.rows:
        print("| %d | " % cap + " | ".join("%.1f %%" % (100 * misses(o, cap)) for o in orders.values()) + " |")


if __name__ == "__main__":
    main()
