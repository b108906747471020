#!/usr/bin/env python3
"""Dask pyramid on one worker and on two (issue 25: two local workers <= 0.6x the time of one).

    python3 bench/pyramid_workers.py IN.zarr --work DIR [--repeats 3] [--cost intensity] [--window LO,HI]

Runs `python3 -m volscissors.pyramid` with --workers 1 and --workers 2, alternating, `--repeats`
times each (alternating pairs keep a drifting machine load out of the ratio), prints every time,
the medians and their ratio, and checks the outputs: every level of every run equals the first
run's, and level 0 equals the in-memory cost (`volscissors.cost` on slabs of 64 z-slices; exact for
the pointwise intensity cost, and skipped for vesselness, whose equality the tests check).
Wall time of the whole command (cluster start included), so the figure is what a user waits."""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np


def run(inp, out, workers, extra):
    t = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "volscissors.pyramid", inp, "--out", out, "--workers", str(workers),
                        "--json", out + ".json", *extra], capture_output=True, text=True)
    wall = time.perf_counter() - t
    if r.returncode != 0:
        sys.exit(f"pyramid failed ({r.returncode}): {r.stderr.strip()}")
    return wall, json.load(open(out + ".json"))


def same(a, b):
    import zarr

    ga, gb = zarr.open_group(a, mode="r"), zarr.open_group(b, mode="r")
    for name in sorted(ga.array_keys()):
        x, y = ga[name], gb[name]
        if x.shape != y.shape:
            return f"level {name}: shapes {x.shape} vs {y.shape}"
        for z0 in range(0, x.shape[0], x.chunks[0]):
            if not np.array_equal(x[z0:z0 + x.chunks[0]], y[z0:z0 + x.chunks[0]]):
                return f"level {name} differs in z {z0}.."
    return None


def equals_in_memory(inp, out, fig):
    import zarr

    import volscissors as vs

    src, cost = zarr.open_group(inp, mode="r")["0"], zarr.open_group(out, mode="r")["0"]
    attrs = zarr.open_group(inp, mode="r").attrs.asdict()["multiscales"][0]["datasets"][0]
    sz, sy, sx = attrs["coordinateTransformations"][0]["scale"][-3:]
    for z0 in range(0, src.shape[0], 64):
        v = vs.Volume(np.ascontiguousarray(src[z0:z0 + 64]), spacing=(sx, sy, sz))
        ref = vs.cost(v, "intensity", window=tuple(fig["window"])).array
        if not np.array_equal(ref, cost[z0:z0 + 64]):
            return f"level 0 differs from vs.cost in z {z0}.."
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("input")
    ap.add_argument("--work", required=True)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cost", default="intensity")
    ap.add_argument("--window")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    extra = ["--cost", a.cost] + (["--window", a.window] if a.window else [])
    times = {1: [], 2: []}
    first, fig0 = None, None
    for r in range(a.repeats):
        for w in (1, 2):
            out = os.path.join(a.work, f"cost_w{w}_r{r}.zarr")
            wall, fig = run(a.input, out, w, extra)
            times[w].append(wall)
            print(f"run {r} workers {w}: {wall:.1f} s (cost level {fig['cost_seconds']:.1f} s, "
                  f"{fig['levels']} levels), load {os.getloadavg()[0]:.2f}", flush=True)
            if first is None:
                first, fig0 = out, fig
            else:
                bad = same(first, out)
                if bad:
                    sys.exit(f"outputs differ: {out}: {bad}")
                shutil.rmtree(out)
    if a.cost in ("intensity", "auto"):
        bad = equals_in_memory(a.input, first, fig0)
        print("level 0 equals the in-memory cost" if not bad else f"NOT EQUAL: {bad}")
    m1, m2 = statistics.median(times[1]), statistics.median(times[2])
    print(f"median 1 worker {m1:.1f} s, 2 workers {m2:.1f} s: ratio {m2 / m1:.2f} "
          f"(pairwise {', '.join(f'{b / c:.2f}' for b, c in zip(times[2], times[1]))})")
    shutil.rmtree(first, ignore_errors=True)


if __name__ == "__main__":
    main()
