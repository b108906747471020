#!/usr/bin/env python3
"""Measures of a traced tree against its volume (issue 12), and the airway criteria.

Airway criteria (a `trace --json` report of a chest CT): every path point below -900 HU (the
voxels of the discrete paths and the refined points, trilinear HU), and the share of refined
points within 0.5 mm of the wall, the wall distance being the distance (mm, with the volume's
spacing) from each refined point to the nearest voxel outside the lumen (HU >= -900), found with
SciPy's exact Euclidean distance transform (its feature transform gives every voxel's nearest
outside voxel; a continuous point takes the nearest among those of its 8 surrounding voxels).

  /usr/bin/python3 bench/trace_measures.py airway VOLUME REPORT.json [--threshold -900] [--wall-mm 0.5]
      [--cli build/volscissors]
  /usr/bin/python3 bench/trace_measures.py lumen VOLUME REPORT.json   # vessels: points on the lumen
      side of the auto cost's window edge (half-way from the lumen to its surroundings)
  /usr/bin/python3 bench/trace_measures.py branches VOLUME REPORT.json [--min-own-mm 10]
      # automatic terminals (issue 21): paths along distinct branches, none side by side, every
      # refined point in the vessel (see branch_criteria)

Volumes are read through the CLI (`volscissors convert` to MetaImage), so every format the project
reads works. Needs Debian's python3-numpy and python3-scipy. Exit 1 when a criterion fails.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import zlib

import numpy as np
from scipy import ndimage

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MET_TYPES = {"MET_UCHAR": np.uint8, "MET_CHAR": np.int8, "MET_USHORT": np.uint16, "MET_SHORT": np.int16,
             "MET_UINT": np.uint32, "MET_INT": np.int32, "MET_FLOAT": np.float32, "MET_DOUBLE": np.float64}


def read_volume(path, cli=os.path.join(ROOT, "build", "volscissors")):
    """Returns (array indexed [x, y, z] as float32, spacing (3,) mm) of any volume the CLI reads."""
    with tempfile.TemporaryDirectory() as tmp:
        mha = os.path.join(tmp, "v.mha")
        subprocess.run([cli, "-q", "convert", path, mha], check=True)
        data = open(mha, "rb").read()
    head, fields = 0, {}
    while True:
        end = data.index(b"\n", head)
        key, _, value = data[head:end].decode().partition(" = ")
        fields[key.strip()] = value.strip()
        head = end + 1
        if key.strip() == "ElementDataFile":
            break
    body = data[head:]
    if fields.get("CompressedData") == "True":
        body = zlib.decompress(body)
    dims = [int(v) for v in fields["DimSize"].split()]
    dtype = np.dtype(MET_TYPES[fields["ElementType"]]).newbyteorder(
        ">" if fields.get("BinaryDataByteOrderMSB") == "True" else "<")
    a = np.frombuffer(body, dtype=dtype, count=int(np.prod(dims))).reshape(dims[::-1]).transpose(2, 1, 0)
    return a.astype(np.float32), np.array([float(v) for v in fields["ElementSpacing"].split()])


def trilinear(vol, points):
    """Values of vol (indexed [x, y, z]) at continuous voxel points (n, 3)."""
    return ndimage.map_coordinates(vol, np.asarray(points, float).T, order=1, mode="nearest")


def wall_distances_mm(lumen, spacing, points):
    """Distance (mm) from each continuous voxel point (n, 3) to the centre of the nearest voxel
    where `lumen` is False, by the exact EDT's feature transform (sampling = spacing)."""
    lumen = np.asarray(lumen, bool)
    if lumen.all():
        raise ValueError("the lumen mask has no outside voxel")
    _, nearest = ndimage.distance_transform_edt(lumen, sampling=spacing, return_indices=True)
    pts = np.asarray(points, float)
    hi = np.array(lumen.shape) - 1
    best = np.full(len(pts), np.inf)
    base = np.floor(pts).astype(int)
    for corner in np.ndindex(2, 2, 2):
        v = np.clip(base + np.array(corner), 0, hi)
        b = nearest[:, v[:, 0], v[:, 1], v[:, 2]].T  # nearest outside voxel of that corner
        best = np.minimum(best, np.linalg.norm((b - pts) * spacing, axis=1))
    return best


def airway_criteria(hu, spacing, report, threshold=-900.0, wall_mm=0.5):
    """Per-path and overall figures of a trace report against a CT in HU (see the module doc)."""
    lumen = hu < threshold
    rows, all_vox_hu, all_pt_hu, all_wall = [], [], [], []
    for i, p in enumerate(report["paths"]):
        vox = np.array(p["voxels"], int)
        pts = np.array(p["points"], float)
        vox_hu = hu[vox[:, 0], vox[:, 1], vox[:, 2]]
        pt_hu = trilinear(hu, pts)
        wall = wall_distances_mm(lumen, spacing, pts)
        rows.append({"path": i, "target": p["target"], "length_mm": p["length_mm"], "points": len(pts),
                     "max_voxel_hu": float(vox_hu.max()), "max_point_hu": float(pt_hu.max()),
                     "mean_point_hu": float(pt_hu.mean()), "near_wall": float(np.mean(wall <= wall_mm)),
                     "median_wall_mm": float(np.median(wall))})
        all_vox_hu.append(vox_hu)
        all_pt_hu.append(pt_hu)
        all_wall.append(wall)
    vox_hu, pt_hu, wall = (np.concatenate(a) for a in (all_vox_hu, all_pt_hu, all_wall))
    overall = {"paths": len(rows), "distinct_terminals": len({tuple(r["target"]) for r in rows}),
               "max_voxel_hu": float(vox_hu.max()), "max_point_hu": float(pt_hu.max()),
               "points_below": float(np.mean(pt_hu < threshold)), "voxels_below": float(np.mean(vox_hu < threshold)),
               "near_wall": float(np.mean(wall <= wall_mm)), "median_wall_mm": float(np.median(wall))}
    overall["pass"] = bool(overall["max_voxel_hu"] < threshold and overall["max_point_hu"] < threshold and
                           overall["near_wall"] < 0.10)
    return rows, overall


def lumen_criteria(vol, report):
    """Vessels (any polarity): the share of refined points and path voxels on the lumen side of the
    window edge the auto cost estimated (cost_estimate.window: half-way from the lumen to its
    surroundings), and the mean intensity at the points against a shell 2-3 radii around them."""
    e = report["cost_estimate"]
    bright = e["polarity"] == "bright"
    edge = e["window"][0] if bright else e["window"][1]
    inside = (lambda v: v >= edge) if bright else (lambda v: v <= edge)
    rows, all_pts, all_vox = [], [], []
    for i, p in enumerate(report["paths"]):
        vox = np.array(p["voxels"], int)
        pts = np.array(p["points"], float)
        pt_v = trilinear(vol, pts)
        vox_v = vol[vox[:, 0], vox[:, 1], vox[:, 2]]
        rows.append({"path": i, "target": p["target"], "length_mm": p["length_mm"], "points": len(pts),
                     "points_inside": float(np.mean(inside(pt_v))), "voxels_inside": float(np.mean(inside(vox_v))),
                     "mean_point": float(pt_v.mean())})
        all_pts.append(pt_v)
        all_vox.append(vox_v)
    pt_v, vox_v = np.concatenate(all_pts), np.concatenate(all_vox)
    overall = {"paths": len(rows), "distinct_terminals": len({tuple(r["target"]) for r in rows}), "edge": edge,
               "points_inside": float(np.mean(inside(pt_v))), "voxels_inside": float(np.mean(inside(vox_v))),
               "surroundings": e["surroundings"], "lumen": e["lumen"]}
    return rows, overall


# The trace's own path support note (src/tracking/path_support.cpp): a stretch of a path's voxels with no lumen in the
# cost's model and no contrast in the image.
_NO_LUMEN = re.compile(r"\((-?\d+),(-?\d+),(-?\d+)\): its path crosses [\d.]+ mm without lumen .*?"
                       r"\(path voxels (\d+)-(\d+) of (\d+)\)")


def flagged_voxels(report):
    """Per path: the voxel index ranges [first, last] its trace's notes flag as crossing without lumen (a path told by
    its target and its voxel count)."""
    out = [[] for _ in report["paths"]]
    for note in report.get("notes") or []:
        for m in _NO_LUMEN.finditer(note):
            target, (first, last, n) = [int(v) for v in m.group(1, 2, 3)], [int(v) for v in m.group(4, 5, 6)]
            for i, p in enumerate(report["paths"]):
                if list(p["target"]) == target and len(p["voxels"]) == n:
                    out[i].append((first, last))
    return out


def on_flagged(path, ranges):
    """Per refined point of `path`: on a flagged stretch (its nearest path voxel's index in one of `ranges`)."""
    pts = np.array(path["points"], float)
    if not ranges or not len(pts):
        return np.zeros(len(pts), bool)
    vox = np.array(path["voxels"], float)
    k = np.argmin(np.linalg.norm(pts[:, None, :] - vox[None, :, :], axis=2), axis=1)
    return np.array([any(a <= j <= b for a, b in ranges) for j in k], bool)


def branch_criteria(vol, spacing, report, min_own_mm=10.0, near=(1.0, 4.0)):
    """Automatic terminals (issue 21), from the refined points of a report (bright vessels).

    - in the vessel: a refined point's trilinear intensity is at least half-way (half maximum)
      from its local background to its vessel's level. Vessel level: median intensity at the
      refined points of the same path within 5 mm (index distance in mm); background: median of
      the voxels in a shell from 2 r + 2 mm to 2 r + 6 mm around the point (r: its refined radius),
      i.e. outside the vessel whatever its width, independent of the trace's cost model.
    - side by side: for each ordered pair of paths (i, j), the share of i's refined points (per
      mm of i) whose distance to j's nearest refined point lies in [1, 4] mm; the worst pair.
      Points within 4 mm of a point the two paths share (their common trunk, the root) are left
      out: two paths that leave one point in different directions are 1-4 mm apart there whatever
      they do next ("side_by_side_raw" counts them too).
    - distinct branches: each path's own length (its points farther than 4 mm from every other
      path's points, in mm along the path) is at least min_own_mm.
    Where the trace's notes flag a stretch as crossing without lumen (a target no lumen joins to the root: the path
    hops through the background, and says so), "points_outside_flagged" counts the points outside on such stretches
    (their nearest path voxel in the flagged range): points_outside less it is what the refinement left outside where
    the trace claims a vessel. The key is there only when a stretch is flagged; nothing else depends on it."""
    paths = [np.array(p["points"], float) for p in report["paths"]]
    mm = [q * spacing for q in paths]
    seg = [np.r_[0.0, np.linalg.norm(np.diff(q, axis=0), axis=1)] for q in mm]
    arc = [np.cumsum(s_) for s_ in seg]
    rows = []
    hi = np.array(vol.shape) - 1
    inside_all = []
    ranges = flagged_voxels(report)
    flagged_all = [on_flagged(p, ranges[i]) for i, p in enumerate(report["paths"])]
    for i, p in enumerate(report["paths"]):
        pts, q = paths[i], mm[i]
        val = trilinear(vol, pts)
        radii = np.array(p["radii_mm"], float)
        inside = np.zeros(len(pts), bool)
        for k in range(len(pts)):
            near_k = np.abs(arc[i] - arc[i][k]) <= 5.0
            level = np.median(val[near_k])
            r_in, r_out = 2 * radii[k] + 2.0, 2 * radii[k] + 6.0
            ext = np.ceil(r_out / spacing).astype(int)
            c = np.rint(pts[k]).astype(int)
            lo_, hi_ = np.maximum(c - ext, 0), np.minimum(c + ext, hi)
            sub = vol[lo_[0]:hi_[0] + 1, lo_[1]:hi_[1] + 1, lo_[2]:hi_[2] + 1]
            gx, gy, gz = np.meshgrid(*[(np.arange(lo_[a], hi_[a] + 1) - pts[k][a]) * spacing[a] for a in range(3)],
                                     indexing="ij")
            d = np.sqrt(gx ** 2 + gy ** 2 + gz ** 2)
            shell = sub[(d >= r_in) & (d <= r_out)]
            bg = np.median(shell) if shell.size else np.min(sub)
            inside[k] = val[k] >= 0.5 * (level + bg)
        inside_all.append(inside)
        own = np.ones(len(pts), bool)
        worst, worst_raw = (0.0, -1), (0.0, -1)
        for j in range(len(paths)):
            if j == i:
                continue
            dist = np.min(np.linalg.norm(q[:, None, :] - mm[j][None, :, :], axis=2), axis=1)
            own &= dist > near[1]
            beside = (dist >= near[0]) & (dist <= near[1])
            shared = q[dist < 1e-6]
            apart = np.ones(len(q), bool) if not len(shared) else \
                np.min(np.linalg.norm(q[:, None, :] - shared[None, :, :], axis=2), axis=1) > near[1]
            share = float(np.sum(seg[i][beside & apart]) / max(arc[i][-1], 1e-9))
            worst = max(worst, (share, j))
            worst_raw = max(worst_raw, (float(np.sum(seg[i][beside]) / max(arc[i][-1], 1e-9)), j))
        rows.append({"path": i, "target": p["target"], "length_mm": round(float(arc[i][-1]), 1),
                     "own_mm": round(float(np.sum(seg[i][own])), 1), "inside": float(np.mean(inside)),
                     "side_by_side": round(worst[0], 3), "with": worst[1],
                     "side_by_side_raw": round(worst_raw[0], 3)})
    inside = np.concatenate(inside_all)
    overall = {"paths": len(rows), "distinct_terminals": len({tuple(r["target"]) for r in rows}),
               "points_inside": float(np.mean(inside)), "points_outside": int(np.sum(~inside)),
               **({"points_outside_flagged": int(np.sum(~inside & np.concatenate(flagged_all)))}
                  if any(ranges) else {}),
               "worst_side_by_side": max((r["side_by_side"] for r in rows), default=0.0),
               "worst_side_by_side_raw": max((r["side_by_side_raw"] for r in rows), default=0.0),
               "min_own_mm": min((r["own_mm"] for r in rows), default=0.0)}
    overall["pass"] = bool(overall["paths"] >= 6 and overall["points_outside"] == 0 and
                           overall["worst_side_by_side"] <= 0.10 and overall["min_own_mm"] >= min_own_mm)
    return rows, overall


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=["airway", "lumen", "branches"])
    ap.add_argument("volume")
    ap.add_argument("report")
    ap.add_argument("--threshold", type=float, default=-900.0, help="lumen: HU below this (default -900)")
    ap.add_argument("--wall-mm", type=float, default=0.5, help="'near the wall' distance (default 0.5 mm)")
    ap.add_argument("--min-own-mm", type=float, default=10.0, help="branches: own length per path (default 10)")
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "volscissors"))
    a = ap.parse_args()
    hu, spacing = read_volume(a.volume, a.cli)
    if a.what == "lumen":
        rows, overall = lumen_criteria(hu, json.load(open(a.report)))
        for r in rows:
            print(f"path {r['path']} target {r['target']} {r['length_mm']:.1f} mm: points inside "
                  f"{100 * r['points_inside']:.1f}%, voxels inside {100 * r['voxels_inside']:.1f}%, "
                  f"mean at points {r['mean_point']:.0f}")
        print(json.dumps(overall))
        return 0
    if a.what == "branches":
        rows, overall = branch_criteria(hu, spacing, json.load(open(a.report)), a.min_own_mm)
        for r in rows:
            print(json.dumps(r))
        print(json.dumps(overall))
        return 0 if overall["pass"] else 1
    rows, overall = airway_criteria(hu, spacing, json.load(open(a.report)), a.threshold, a.wall_mm)
    print(f"{'path':>4} {'target':>14} {'length_mm':>9} {'points':>6} {'max HU vox':>10} {'max HU pt':>9} "
          f"{'mean HU pt':>10} {'near wall':>9} {'median wall mm':>14}")
    for r in rows:
        t = ",".join(map(str, r["target"]))
        print(f"{r['path']:>4} {t:>14} {r['length_mm']:>9.1f} {r['points']:>6} {r['max_voxel_hu']:>10.0f} "
              f"{r['max_point_hu']:>9.0f} {r['mean_point_hu']:>10.0f} {100 * r['near_wall']:>8.1f}% "
              f"{r['median_wall_mm']:>14.2f}")
    print(json.dumps(overall))
    return 0 if overall["pass"] else 1


if __name__ == "__main__":
    sys.exit(main())
