#!/usr/bin/env python3
"""Time and peak memory of traces on OME-Zarr vessel phantoms written chunk by chunk (issue 25).

For each size N: `volscissors phantom vessels --size N,N,N --out vN.zarr` (chunk by chunk), then
two traces with the chunked tracer (`trace --chunked-above 0`, intensity cost):
  * fixed length: root -> the truth centreline point LENGTH voxels of arc from the root (the same
    path length at every size: memory must follow the explored region, not the volume);
  * root -> the terminal with the longest centreline path.
Each is run under /usr/bin/time (wall s, peak RSS). The cost of the fixed-length path is also
checked against the in-memory Dijkstra on a crop holding the path (`trace --cost intensity
--window` of the same window on `convert`ed crop) when the crop is small enough.
Prints a Markdown table. The machine is shared: the load average is printed with each row.

  /usr/bin/python3 bench/large_trace.py --cli build/volscissors --sizes 256 512 1024 --seed 25 --work /tmp/vs-large
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time


def run_timed(cmd):
    t = subprocess.run(["/usr/bin/time", "-f", "TIME %e %M"] + [str(c) for c in cmd], capture_output=True, text=True)
    if t.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{t.stdout}\n{t.stderr}")
    line = [l for l in t.stderr.splitlines() if l.startswith("TIME ")][-1].split()
    return float(line[1]), int(line[2]) / 1024.0, t.stdout


def walk(truth, length):
    """Voxel at `length` voxels of arc from the root along branch 0 then first children."""
    br = truth["branches"]
    b, acc = 0, 0.0
    while True:
        pts = br[b]["points"]
        for p, q in zip(pts, pts[1:]):
            d = math.dist(p, q)
            if acc + d >= length:
                return [int(round(c)) for c in q]
            acc += d
        if not br[b]["children"]:
            return [int(round(c)) for c in pts[-1]]
        b = br[b]["children"][0]


def path_len(truth, leaf):
    br, total, b = truth["branches"], 0.0, leaf
    while b >= 0:
        pts = br[b]["points"]
        total += sum(math.dist(p, q) for p, q in zip(pts, pts[1:]))
        b = br[b]["parent"]
    return total


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", default="build/volscissors")
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024])
    ap.add_argument("--seed", type=int, default=25)
    ap.add_argument("--length", type=float, default=150)
    ap.add_argument("--work", default="/tmp/vs-large")
    ap.add_argument("--keep", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    rows = []
    for n in a.sizes:
        z, tj = os.path.join(a.work, f"v{n}.zarr"), os.path.join(a.work, f"v{n}.json")
        gen_s, gen_mb, _ = run_timed([a.cli, "-q", "phantom", "vessels", "--size", f"{n},{n},{n}", "--seed", a.seed,
                                      "--out", z, "--truth", tj])
        truth = json.load(open(tj))
        root = truth["root_voxel"] if "root_voxel" in truth else truth["root"]
        leaves = [i for i, b in enumerate(truth["branches"]) if not b["children"]]
        far = max(leaves, key=lambda i: path_len(truth, i))
        far_t = [int(round(c)) for c in truth["branches"][far]["points"][-1]]
        fixed_t = walk(truth, a.length)
        for name, tgt, arc in (("fixed", fixed_t, a.length), ("terminal", far_t, path_len(truth, far))):
            rj = os.path.join(a.work, f"r{n}_{name}.json")
            s, mb, out = run_timed([a.cli, "-q", "trace", z, "--chunked-above", 0, "--cost", "intensity", "--root",
                                    ",".join(map(str, root)), "--target", ",".join(map(str, tgt)), "--json", rj])
            rep = json.load(open(rj))
            p = rep["paths"][0]
            rows.append(dict(n=n, kind=name, arc=arc, voxels=len(p["voxels"]), cost=p["cost"], s=s, mb=mb,
                             gen_s=gen_s, gen_mb=gen_mb, blocks=rep["graph"]["blocks"],
                             block_mb=rep["graph"]["block_bytes"] / 2**20, chunks=rep["graph"]["chunks_read"],
                             settled=rep["graph"]["settled"], load=os.getloadavg()[0]))
            print(json.dumps(rows[-1]), flush=True)
        if not a.keep:
            subprocess.run(["rm", "-rf", z])
    print("\n| N^3 | path | truth arc (vox) | path voxels | trace wall s | peak RSS MiB | settled | blocks (MiB) | chunks read | phantom write s / MiB | load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['n']} | {r['kind']} | {r['arc']:.0f} | {r['voxels']} | {r['s']:.2f} | {r['mb']:.0f} | {r['settled']} | "
              f"{r['blocks']} ({r['block_mb']:.0f}) | {r['chunks']} | {r['gen_s']:.0f} / {r['gen_mb']:.0f} | {r['load']:.1f} |")


if __name__ == "__main__":
    main()
