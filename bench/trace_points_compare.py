#!/usr/bin/env python3
"""Compare two directories of `trace --json` reports (bench/trace_depth.sh) point by point.

For each report present in both: paths whose voxel routes differ, and refined points that moved by more
than --tol voxel (paths matched by index; a path whose point count changed counts all its points).
    bench/trace_points_compare.py OLD_DIR NEW_DIR [--tol 0.01]
"""
import argparse
import json
import math
import pathlib


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--tol", type=float, default=0.01, help="a point moved by more than this, voxels (default 0.01)")
    a = ap.parse_args()
    total = moved = 0
    for f in sorted(pathlib.Path(a.old).glob("*.json")):
        g = pathlib.Path(a.new) / f.name
        if not g.exists():
            print(f"{f.name}: missing in {a.new}")
            continue
        x, y = json.loads(f.read_text()), json.loads(g.read_text())
        px, py = x.get("paths", []), y.get("paths", [])
        here = routes = 0
        worst = 0.0
        n = sum(len(p["points"]) for p in px)
        for i, p in enumerate(px):
            if i >= len(py):
                here += len(p["points"])
                continue
            q = py[i]
            routes += p["voxels"] != q["voxels"]
            if len(p["points"]) != len(q["points"]):
                here += len(p["points"])
                continue
            for u, v in zip(p["points"], q["points"]):
                d = math.dist(u, v)
                if d > a.tol:
                    here += 1
                    worst = max(worst, d)
        total += n
        moved += here
        if here or routes or len(px) != len(py):
            print(f"{f.name}: {len(px)} -> {len(py)} paths, {routes} routes changed, {here} of {n} points moved "
                  f"(largest {worst:.2f})")
    print(f"{moved} of {total} refined points moved by more than {a.tol}")


if __name__ == "__main__":
    main()
