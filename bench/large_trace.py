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
    t = subprocess.run(["/usr/bin/time", "-f", "TIME %e %M %U %S"] + [str(c) for c in cmd], capture_output=True,
                       text=True)
    if t.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{t.stdout}\n{t.stderr}")
    line = [l for l in t.stderr.splitlines() if l.startswith("TIME ")][-1].split()
    run_timed.cpu = float(line[3]) + float(line[4])
    return float(line[1]), int(line[2]) / 1024.0, t.stdout


def truth_points(truth):
    """The truth centrelines, densely sampled (4 points per segment)."""
    import numpy as np
    dense = []
    for b in truth["branches"]:
        q = np.array(b["points"], dtype=float)
        dense.append(q)
        for f in (0.25, 0.5, 0.75):
            dense.append(q[:-1] * (1 - f) + q[1:] * f)
    return np.concatenate(dense)


def refined_distance(truth, points):
    """Distance (voxels) of the refined points to the truth centreline, the 3 points at each end left out."""
    import numpy as np
    if not points:
        return None
    t = truth_points(truth)
    p = np.array(points, dtype=float)
    p = p[3:-3] if len(p) > 8 else p
    d = np.array([np.min(np.linalg.norm(t - x, axis=1)) for x in p])
    return dict(mean=float(d.mean()), p95=float(np.percentile(d, 95)), max=float(d.max()))


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
    ap.add_argument("--reuse", action="store_true", help="use vN.zarr and vN.json in --work if they exist")
    ap.add_argument("--arcs", type=float, nargs="*", default=[],
                    help="more fixed-length targets: truth points this many voxels of arc from the root")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    rows = []
    for n in a.sizes:
        z, tj = os.path.join(a.work, f"v{n}.zarr"), os.path.join(a.work, f"v{n}.json")
        if a.reuse and os.path.exists(z) and os.path.exists(tj):
            gen_s, gen_mb = float("nan"), float("nan")
        else:
            gen_s, gen_mb, _ = run_timed([a.cli, "-q", "phantom", "vessels", "--size", f"{n},{n},{n}", "--seed",
                                          a.seed, "--out", z, "--truth", tj])
        truth = json.load(open(tj))
        root = truth["root_voxel"] if "root_voxel" in truth else truth["root"]
        leaves = [i for i, b in enumerate(truth["branches"]) if not b["children"]]
        far = max(leaves, key=lambda i: path_len(truth, i))
        far_t = [int(round(c)) for c in truth["branches"][far]["points"][-1]]
        fixed_t = walk(truth, a.length)
        cases = [("fixed", fixed_t, a.length), ("terminal", far_t, path_len(truth, far))]
        cases += [(f"arc{x:.0f}", walk(truth, x), x) for x in a.arcs]
        for name, tgt, arc in cases:
            rj = os.path.join(a.work, f"r{n}_{name}.json")
            s, mb, out = run_timed([a.cli, "-q", "trace", z, "--chunked-above", 0, "--cost", "intensity", "--root",
                                    ",".join(map(str, root)), "--target", ",".join(map(str, tgt)), "--json", rj])
            rep = json.load(open(rj))
            p = rep["paths"][0]
            rows.append(dict(n=n, kind=name, arc=arc, voxels=len(p["voxels"]), cost=p["cost"], s=s, mb=mb,
                             cpu=run_timed.cpu, refine_s=rep["seconds"].get("refine"),
                             refined=refined_distance(truth, p.get("points", [])),
                             euclid=math.dist(root, tgt),
                             gen_s=gen_s, gen_mb=gen_mb, blocks=rep["graph"]["blocks"],
                             block_mb=rep["graph"]["block_bytes"] / 2**20, chunks=rep["graph"]["chunks_read"],
                             settled=rep["graph"]["settled"], load=os.getloadavg()[0]))
            print(json.dumps(rows[-1]), flush=True)
        if not a.keep:
            subprocess.run(["rm", "-rf", z])
    print("\n| N^3 | path | truth arc / straight (vox) | path voxels | trace wall s (CPU s) | peak RSS MiB | settled | "
          "blocks (MiB) | chunks read | refined to truth mean / p95 (vox) | phantom write s / MiB | load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        d = r["refined"]
        ref = f"{d['mean']:.3f} / {d['p95']:.3f}" if d else "-"
        print(f"| {r['n']} | {r['kind']} | {r['arc']:.0f} / {r['euclid']:.0f} | {r['voxels']} | {r['s']:.2f} ({r['cpu']:.2f}) | "
              f"{r['mb']:.0f} | {r['settled']} | {r['blocks']} ({r['block_mb']:.1f}) | {r['chunks']} | {ref} | "
              f"{r['gen_s']:.0f} / {r['gen_mb']:.0f} | {r['load']:.1f} |")


if __name__ == "__main__":
    main()
