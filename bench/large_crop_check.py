#!/usr/bin/env python3
"""Checks a chunked trace (`trace X.zarr --chunked-above 0 --json R.json`) against the in-memory
search on a crop that holds the path (issue 25): the crop (path bounding box + MARGIN voxels) is
read with python-zarr, traced with volscissors.trace (26-connected, no pruning, no snapping, no
refinement, the same intensity window), and the two costs are compared (relative difference).

  /usr/bin/python3 bench/large_crop_check.py X.zarr R.json [--margin 24]
"""
import argparse
import json
import re
import sys

import numpy as np
import zarr

import volscissors as vs

ap = argparse.ArgumentParser()
ap.add_argument("zarr")
ap.add_argument("report")
ap.add_argument("--margin", type=int, default=24)
ap.add_argument("--truth", help="phantom truth JSON: also refine the path on the crop and report its distance "
                "to the true centreline (voxels)")
a = ap.parse_args()
rep = json.load(open(a.report))
m = re.search(r"window ([-0-9.e+]+)\.\.([-0-9.e+]+)", rep["cost"])
window = (float(m.group(1)), float(m.group(2)))
g = zarr.open_group(a.zarr, mode="r")
arr = g["0"]
p = rep["paths"][0]
vox = np.array(p["voxels"])  # (x, y, z)
lo = np.maximum(vox.min(0) - a.margin, 0)
hi = np.minimum(vox.max(0) + a.margin + 1, np.array(arr.shape[::-1]))
crop = np.ascontiguousarray(arr[lo[2]:hi[2], lo[1]:hi[1], lo[0]:hi[0]])
vol = vs.Volume(crop, spacing=(1.0, 1.0, 1.0))
root = tuple(int(v) for v in np.array(rep["root"]) - lo)
tgt = tuple(int(v) for v in np.array(p["target"]) - lo)
tree = vs.trace(vol, root=root, targets=[tgt], cost="intensity", window=window, smooth_mm=0, snap_mm=0,
                prune="none", connectivity=26, refine=False)
mem = tree.paths[0].cost
rel = abs(mem - p["cost"]) / mem
out = {"crop_xyz": (hi - lo).tolist(), "chunked_cost": p["cost"], "in_memory_cost": mem, "relative_difference": rel}
if a.truth:
    # The refinement of the in-memory tracer on the same crop (sub-voxel centreline), against the truth
    # centreline sampled densely; points within 3 voxels of either end are left out (the ends are the
    # given voxels, not centreline points).
    t = json.load(open(a.truth))
    pts = np.concatenate([np.array(b["points"]) for b in t["branches"]])
    dense = [pts]
    for b in t["branches"]:
        q = np.array(b["points"])
        for f in (0.25, 0.5, 0.75):
            dense.append(q[:-1] * (1 - f) + q[1:] * f)
    truth = np.concatenate(dense)
    ref = vs.trace(vol, root=root, targets=[tgt], cost="intensity", window=window, smooth_mm=0, snap_mm=0,
                   prune="none", connectivity=26, refine=True).paths[0]
    rp = np.asarray(ref.points) + lo
    keep = rp[3:-3] if len(rp) > 8 else rp
    d = np.array([np.min(np.linalg.norm(truth - x, axis=1)) for x in keep])
    out.update({"refined_points": int(len(keep)), "distance_to_truth_mean": float(d.mean()),
                "distance_to_truth_p95": float(np.percentile(d, 95)), "distance_to_truth_max": float(d.max())})
print(json.dumps(out))
sys.exit(0 if rel <= 1e-6 else 1)
