#!/usr/bin/env python3
"""Full single-source map, scikit-image vs the project, alternated round by round.

The machines these figures come from are shared VMs whose speed changes by up to 2x within
minutes. Timing one tool and then the other (engine_vs_peers.sh) lets such a change land on one
side only. Here every round times skimage's full_total exactly as the peer script does
(MCP_Geometric construction + find_costs, perf_counter, one thread) and, right before it, the
project's full map (bench_engine --full-only: construction + runToCompletion, median of 3 after
a warm-up), once on the default threads and once forced to one. The figure to read is the
median of the per-round ratios. Terminal costs of both tools must agree within 0.5 %.

  /usr/bin/python3 bench/sssp_rounds.py --build build --data DIR [--sizes 128 256] [--rounds 5]

DIR holds the peers' inputs (make_volumes.py): vessels_N_cost.npy and vessels_N.json.
Needs Debian's python3-numpy and python3-skimage.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from skimage.graph import MCP_Geometric


def ours(build, cost_path, meta_path, threads):
    cmd = [os.path.join(build, "bench_engine"), "--npy", cost_path, "--sidecar", meta_path,
           "--repeat", "3", "--warmup", "1", "--full-only", "1", "--threads", str(threads)]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    d = json.loads(out.strip().splitlines()[-1])
    return d["timings"]["full_total"]["median_s"], d["terminal_costs"], d["threads"]


def skimage_full(cost, root, terms):
    t0 = time.perf_counter()
    cum, _ = MCP_Geometric(cost, fully_connected=True).find_costs([root])
    dt = time.perf_counter() - t0
    return dt, [float(cum[tuple(t)]) for t in terms]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--data", required=True)
    ap.add_argument("--sizes", nargs="+", type=int, default=[128, 256])
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    ok = True
    for n in a.sizes:
        cost_path = os.path.join(a.data, f"vessels_{n}_cost.npy")
        meta_path = os.path.join(a.data, f"vessels_{n}.json")
        if not (os.path.exists(cost_path) and os.path.exists(meta_path)):
            print(f"sssp_rounds: {cost_path} or {meta_path} missing (make_volumes.py writes them)", file=sys.stderr)
            return 1
        cost = np.load(cost_path)
        meta = json.load(open(meta_path))
        root, terms = tuple(meta["root"]), meta["terminals"]
        rounds = a.rounds if n < 256 else max(1, (a.rounds + 1) // 2)
        r_def, r_one, t_sk, t_def, t_one = [], [], [], [], []
        threads = 1
        for r in range(rounds):
            td, cd, threads = ours(a.build, cost_path, meta_path, 0)
            t1, c1, _ = ours(a.build, cost_path, meta_path, 1)
            ts, cs = skimage_full(cost, root, terms)
            rel = max(abs(x - y) / max(abs(y), 1e-300) for x, y in zip(cd + c1, cs + cs))
            if rel > 0.005 or len(cd) != len(cs):
                ok = False
                print(f"CHECK vessels_{n} round {r + 1}: terminal costs differ from skimage by {rel:.2e} -> MISMATCH")
            r_def.append(ts / td)
            r_one.append(ts / t1)
            t_sk.append(ts)
            t_def.append(td)
            t_one.append(t1)
            print(f"vessels_{n} round {r + 1}: skimage {ts:.3f} s, project {td:.3f} s ({threads} threads) "
                  f"= {ts / td:.1f}x, 1 thread {t1:.3f} s = {ts / t1:.1f}x", flush=True)
        med = statistics.median
        print(f"RATIO vessels_{n} full map, alternated rounds (median of {rounds} per-round ratios): "
              f"{med(r_def):.1f}x on {threads} threads (range {min(r_def):.1f}-{max(r_def):.1f}), "
              f"{med(r_one):.1f}x on 1 thread (range {min(r_one):.1f}-{max(r_one):.1f}); medians skimage "
              f"{med(t_sk):.3f} s, project {med(t_def):.3f} s / {med(t_one):.3f} s; terminal costs agree")
    return 0 if ok else 3


if __name__ == "__main__":
    sys.exit(main())
