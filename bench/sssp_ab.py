#!/usr/bin/env python3
"""Two builds' full maps against scikit-image in the same rounds (an engine change vs main).

sssp_rounds.py times one build against skimage; an engine change measured in one run and main
in another meets a different machine (these VMs' speed moves 2-10x with the other jobs). Here
every round times build A and build B (order swapped every round, so a trend in the load falls
on both) with the same bench_engine call as sssp_rounds.py (median of 3 maps after a warm-up),
then skimage's full_total; it prints per-round times, the per-round ratios to skimage, B/A, and
the medians. Terminal costs of both builds must agree with skimage's within 0.5 %.

  /usr/bin/python3 bench/sssp_ab.py --a MAIN_BUILD --b BUILD --data DIR [--sizes 256] [--rounds 3] [--threads 1]
"""
import argparse
import json
import os
import statistics
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sssp_rounds import ours, skimage_full  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--a", required=True, help="reference build dir (bench_engine inside)")
    ap.add_argument("--b", required=True, help="changed build dir")
    ap.add_argument("--data", required=True)
    ap.add_argument("--sizes", nargs="+", type=int, default=[256])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", nargs="+", type=int, default=[1], help="0 = automatic")
    a = ap.parse_args()
    ok = True
    med = statistics.median
    for n in a.sizes:
        cost_path = os.path.join(a.data, f"vessels_{n}_cost.npy")
        meta_path = os.path.join(a.data, f"vessels_{n}.json")
        cost = np.load(cost_path)
        meta = json.load(open(meta_path))
        root, terms = tuple(meta["root"]), meta["terminals"]
        rows = {(w, th): [] for w in "ab" for th in a.threads}
        sk = []
        for r in range(a.rounds):
            load = open("/proc/loadavg").read().split()[0]
            order = "ab" if r % 2 == 0 else "ba"
            got = {}
            for th in a.threads:
                for w in order:
                    t, c, used = ours(a.a if w == "a" else a.b, cost_path, meta_path, th)
                    got[(w, th)] = (t, c, used)
            ts, cs = skimage_full(cost, root, terms)
            sk.append(ts)
            line = f"vessels_{n} round {r + 1} (load {load}, order {order}): skimage {ts:.2f} s"
            for th in a.threads:
                for w in "ab":
                    t, c, used = got[(w, th)]
                    rel = max(abs(x - y) / max(abs(y), 1e-300) for x, y in zip(c, cs))
                    if rel > 0.005 or len(c) != len(cs):
                        ok = False
                        line += " MISMATCH"
                    rows[(w, th)].append(t)
                    line += f", {w} {th or 'auto'}t {t:.2f} s ({used} used) = {ts / t:.1f}x"
                line += f", b/a {got[('b', th)][0] / got[('a', th)][0]:.3f}"
            print(line, flush=True)
        for th in a.threads:
            ra = [s / t for s, t in zip(sk, rows[("a", th)])]
            rb = [s / t for s, t in zip(sk, rows[("b", th)])]
            q = [tb / ta for ta, tb in zip(rows[("a", th)], rows[("b", th)])]
            print(f"RATIO vessels_{n} threads {th or 'auto'}: a {med(ra):.1f}x ({min(ra):.1f}-{max(ra):.1f}), "
                  f"b {med(rb):.1f}x ({min(rb):.1f}-{max(rb):.1f}); b/a time {med(q):.3f} ({min(q):.3f}-{max(q):.3f}); "
                  f"medians skimage {med(sk):.2f} s, a {med(rows[('a', th)]):.2f} s, b {med(rows[('b', th)]):.2f} s")
    return 0 if ok else 3


if __name__ == "__main__":
    sys.exit(main())
