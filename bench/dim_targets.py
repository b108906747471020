#!/usr/bin/env python3
"""Targets in distal branches 40-60 % as bright as the root (issue 21), chosen by a fixed rule
before any trace runs, so the check of `trace` on them is not tuned to them.

Rule: on the volume smoothed by 0.5 mm, the root level L is the median of the root's 3x3x3
neighbourhood. Candidates are voxels (a) in the component of (smoothed >= 0.3 L) that holds the
root, (b) with smoothed value in [0.4 L, 0.6 L], (c) a ridge: the maximum of its 3-voxel line along
at least two of the three axes, (d) at least 1.5 times as bright as the median of a shell 3-5 mm
around them (a vessel, not a bright patch), (e) at least 40 mm from the root. Up to N targets by
farthest-point sampling (the first farthest from the root), at least 15 mm apart. Bright vessels.

  /usr/bin/python3 bench/dim_targets.py VOLUME X,Y,Z [-n 5] [--cli build/volscissors]
prints "x,y,z;x,y,z;..." (for --target) and one line per target with its value / L.
"""
import argparse
import os
import sys

import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from trace_measures import ROOT, read_volume  # noqa: E402


def choose(vol, spacing, root, n=5):
    sm = ndimage.gaussian_filter(vol, 0.5 / spacing)
    x, y, z = root
    L = float(np.median(sm[max(x - 1, 0):x + 2, max(y - 1, 0):y + 2, max(z - 1, 0):z + 2]))
    lab, _ = ndimage.label(sm >= 0.3 * L, structure=np.ones((3, 3, 3)))
    comp = lab == lab[x, y, z]
    cand = comp & (sm >= 0.4 * L) & (sm <= 0.6 * L)
    ridge_axes = np.zeros(vol.shape, np.int8)
    for a in range(3):
        lo, hi = np.roll(sm, 1, axis=a), np.roll(sm, -1, axis=a)
        ridge_axes += ((sm >= lo) & (sm >= hi)).astype(np.int8)
    cand &= ridge_axes >= 2
    idx = np.argwhere(cand)
    d_root = np.linalg.norm((idx - np.array(root)) * spacing, axis=1)
    idx, d_root = idx[d_root >= 40], d_root[d_root >= 40]
    keep = []
    for k, v in enumerate(idx):
        ext = np.ceil(5.0 / spacing).astype(int)
        lo, hi = np.maximum(v - ext, 0), np.minimum(v + ext + 1, vol.shape)
        sub = sm[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        g = np.meshgrid(*[(np.arange(lo[a], hi[a]) - v[a]) * spacing[a] for a in range(3)], indexing="ij")
        d = np.sqrt(sum(c ** 2 for c in g))
        shell = sub[(d >= 3) & (d <= 5)]
        if shell.size and sm[tuple(v)] >= 1.5 * np.median(shell):
            keep.append(k)
    idx, d_root = idx[keep], d_root[keep]
    chosen = []
    if len(idx):
        chosen.append(int(np.argmax(d_root)))
        dmin = np.linalg.norm((idx - idx[chosen[0]]) * spacing, axis=1)
        while len(chosen) < n:
            k = int(np.argmax(dmin))
            if dmin[k] < 15:
                break
            chosen.append(k)
            dmin = np.minimum(dmin, np.linalg.norm((idx - idx[k]) * spacing, axis=1))
    return L, [tuple(int(c) for c in idx[k]) for k in chosen], [float(sm[tuple(idx[k])]) / L for k in chosen]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("volume")
    ap.add_argument("root")
    ap.add_argument("-n", type=int, default=5)
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "volscissors"))
    a = ap.parse_args()
    vol, spacing = read_volume(a.volume, a.cli)
    root = tuple(int(v) for v in a.root.split(","))
    L, targets, ratios = choose(vol, spacing, root, a.n)
    print(";".join(",".join(map(str, t)) for t in targets))
    for t, r in zip(targets, ratios):
        print(f"target {t}: {r:.2f} of the root level {L:.0f}")
    return 0 if targets else 1


if __name__ == "__main__":
    sys.exit(main())
