#!/usr/bin/env python3
"""Picks a root and dim distal targets on a bright-vessel volume by a fixed rule (issue 21), so
that a volume nobody developed on is tested with points nobody chose by looking at traces.

Rule (fractions of the volume's maximum, which is the lumen level of a saturated angiogram):
- vessel mask M = v >= --vessel (0.5) x max; root = the voxel of M deepest inside it (largest
  Euclidean distance to outside M, with the spacing) at least --away-mm (25) from the deepest of all
  (an aneurysm sac or the widest lumen is not a place to click a root);
- targets = local maxima (3x3x3) whose value lies in --dim (0.4-0.6) x the root's value, in the
  root's 26-connected component of v >= --connect (0.25) x max, in the farther half by geodesic
  (26-connected BFS) distance from the root; the farthest first, then farthest-point sampling
  (each next target maximises its distance to those chosen), --count (5) of them.

  /usr/bin/python3 bench/pick_dim_targets.py VOLUME [--count 5] [--png picks.png] [--json picks.json]

Prints the root and targets as `x,y,z` and writes a targets JSON (`{"root":..,"targets":[..]}`) that
`volscissors trace --targets-file` reads. Needs Debian's python3-numpy, python3-scipy (and PIL for --png).
"""
import argparse
import json
import os
import sys
from collections import deque

import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from trace_measures import read_volume  # noqa: E402


def geodesic_bfs(mask, start):
    dist = np.full(mask.shape, -1, np.int32)
    dist[start] = 0
    queue = deque([start])
    n = mask.shape
    offsets = [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) != (0, 0, 0)]
    while queue:
        p = queue.popleft()
        d = dist[p] + 1
        for o in offsets:
            r = (p[0] + o[0], p[1] + o[1], p[2] + o[2])
            if 0 <= r[0] < n[0] and 0 <= r[1] < n[1] and 0 <= r[2] < n[2] and mask[r] and dist[r] < 0:
                dist[r] = d
                queue.append(r)
    return dist


def pick(v, spacing, count=5, vessel=0.5, connect=0.25, dim=(0.4, 0.6), away_mm=25.0):
    top = float(v.max())
    inside = v >= vessel * top
    depth = ndimage.distance_transform_edt(inside, sampling=spacing)
    deepest = np.array(np.unravel_index(np.argmax(depth), v.shape))
    idx = np.indices(v.shape)
    away = np.sqrt(sum(((idx[a] - deepest[a]) * spacing[a]) ** 2 for a in range(3))) >= away_mm
    root = np.unravel_index(np.argmax(np.where(inside & away, depth, 0)), v.shape)
    labels, _ = ndimage.label(v >= connect * top, structure=np.ones((3, 3, 3)))
    component = labels == labels[root]
    dist = geodesic_bfs(component, root)
    peak = ndimage.maximum_filter(v, size=3)
    rv = float(v[root])
    ok = component & (v >= dim[0] * rv) & (v <= dim[1] * rv) & (v >= peak) & (dist > 0)
    pts, geo = np.argwhere(ok), dist[ok]
    if not len(pts):
        raise SystemExit("pick_dim_targets: no local maximum at 40-60 % of the root's value is connected to it")
    far = geo >= np.median(geo)
    pts, geo = pts[far], geo[far]
    chosen = [pts[np.argmax(geo)]]
    while len(chosen) < min(count, len(pts)):
        gap = np.min(np.stack([np.linalg.norm((pts - c) * spacing, axis=1) for c in chosen]), axis=0)
        chosen.append(pts[np.argmax(gap)])
    return tuple(int(x) for x in root), [tuple(int(x) for x in c) for c in chosen], deepest


def draw(v, root, targets, deepest, path):
    from PIL import Image, ImageDraw
    n = v.shape
    out = Image.new("RGB", (n[1] + n[0] + n[0], max(n)))
    x0 = 0
    top = max(float(v.max()), 1e-9)
    for ax in range(3):
        keep = [a for a in range(3) if a != ax]
        mip = np.flipud((v.max(axis=ax) * (255.0 / top)).T).astype(np.uint8)
        tile = Image.fromarray(mip).convert("RGB")
        pen = ImageDraw.Draw(tile)
        marks = [(root, (255, 0, 0)), (tuple(deepest), (0, 0, 255))] + [(t, (0, 255, 0)) for t in targets]
        for p, colour in marks:
            a, b = p[keep[0]], n[keep[1]] - 1 - p[keep[1]]
            pen.ellipse([a - 4, b - 4, a + 4, b + 4], outline=colour, width=2)
        out.paste(tile, (x0, 0))
        x0 += n[keep[0]]
    out.save(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("volume")
    ap.add_argument("--count", type=int, default=5)
    ap.add_argument("--vessel", type=float, default=0.5)
    ap.add_argument("--connect", type=float, default=0.25)
    ap.add_argument("--dim", default="0.4,0.6")
    ap.add_argument("--away-mm", type=float, default=25.0)
    ap.add_argument("--png")
    ap.add_argument("--json")
    ap.add_argument("--cli", default=os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                                  "build", "volscissors"))
    a = ap.parse_args()
    v, spacing = read_volume(a.volume, a.cli)
    lo, hi = (float(x) for x in a.dim.split(","))
    root, targets, deepest = pick(v, spacing, a.count, a.vessel, a.connect, (lo, hi), a.away_mm)
    print("root %d,%d,%d (value %g)" % (root + (v[root],)))
    for t in targets:
        print("target %d,%d,%d (value %g)" % (t + (v[t],)))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"root": list(root), "targets": [list(t) for t in targets]}, f)
    if a.png:
        draw(v, root, targets, deepest, a.png)


if __name__ == "__main__":
    main()
