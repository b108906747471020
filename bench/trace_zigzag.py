#!/usr/bin/env python3
"""Zig-zag figure of traced paths (issue 21: paths run along the vessel, without zig-zag).

A path (its search route's voxel centres, or its refined points) is resampled every 0.25 mm of arc
length (mm, the volume's spacing) and smoothed along its arc with a Gaussian of sigma `--sigma-mm`;
the zig-zag of a stretch is its length over the smoothed path's length over the same stretch, minus
one (the first and last 2 sigma left out: the smoothing shortens a path's ends). A vessel's own bends survive a 2 mm smoothing, a route that wanders from side to side within a
few millimetres does not. Per path: the whole path's figure, the worst `--window-mm` window's, and
the reversals per 100 mm (turns of more than 90 degrees between successive 2 mm chords).

  /usr/bin/python3 bench/trace_zigzag.py REPORT.json [REPORT.json ...] [--spacing 0.55,0.55,1] [--cli build/volscissors]
  /usr/bin/python3 bench/trace_zigzag.py --family DUMP_DIR [--seeds 501-560]   (VS_FAMILY_DUMP files;
      voxel units: the dumps carry no spacing)
"""
import argparse
import glob
import json
import os
import re
import sys

import numpy as np
from scipy import ndimage


def resample(p, step=0.25):
    d = np.linalg.norm(np.diff(p, axis=0), axis=1)
    keep = np.concatenate([[True], d > 1e-9])
    p = p[keep]
    if len(p) < 2:
        return p
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    t = np.arange(0, s[-1], step)
    return np.stack([np.interp(t, s, p[:, k]) for k in range(3)], axis=1)


def figures(p, sigma=2.0, window=8.0, step=0.25):
    """p: N x 3 points in mm. Returns (whole, worst window, reversals per 100 mm, length)."""
    q = resample(np.asarray(p, float), step)
    if len(q) < 8:
        return 0.0, 0.0, 0.0, 0.0
    sm = ndimage.gaussian_filter1d(q, sigma / step, axis=0, mode="nearest")
    seg = np.linalg.norm(np.diff(q, axis=0), axis=1)
    segs = np.linalg.norm(np.diff(sm, axis=0), axis=1)
    # the smoothing shortens the path within ~2 sigma of its ends (a straight path too): left out
    e = int(round(2 * sigma / step))
    if len(seg) > 2 * e + 8:
        seg, segs = seg[e:-e], segs[e:-e]
    whole = seg.sum() / max(segs.sum(), 1e-9) - 1
    w = max(int(round(window / step)), 1)
    if len(seg) > w:
        c = np.concatenate([[0], np.cumsum(seg)])
        cs = np.concatenate([[0], np.cumsum(segs)])
        a = (c[w:] - c[:-w]) / np.maximum(cs[w:] - cs[:-w], 1e-9) - 1
        worst = float(a.max())
    else:
        worst = whole
    k = int(round(2.0 / step))
    ch = q[k::k] - q[:-k:k]
    rev = 0
    if len(ch) > 1:
        cos = np.einsum("ij,ij->i", ch[1:], ch[:-1]) / np.maximum(
            np.linalg.norm(ch[1:], axis=1) * np.linalg.norm(ch[:-1], axis=1), 1e-9)
        rev = int((cos < 0).sum())
    length = seg.sum()
    return float(whole), worst, 100.0 * rev / max(length, 1e-9), float(length)


def report_rows(path, spacing, sigma, window):
    r = json.load(open(path))
    rows = []
    for i, p in enumerate(r["paths"]):
        vox = np.array(p["voxels"], float) * spacing
        pts = np.array(p["points"], float) * spacing
        rows.append((i + 1, p.get("target"), figures(vox, sigma, window), figures(pts, sigma, window)))
    return rows


def print_rows(name, rows):
    for i, t, fv, fp in rows:
        print(f"{name} #{i} {t}: raw {fv[3]:.1f} mm zz {100 * fv[0]:.2f} % worst{100 * fv[1]:6.1f} % rev/100mm "
              f"{fv[2]:.1f} | refined zz {100 * fp[0]:.2f} % worst {100 * fp[1]:.1f} % rev/100mm {fp[2]:.1f}")
    if rows:
        lv = sum(r[2][3] for r in rows)
        lp = sum(r[3][3] for r in rows)
        mv = sum(r[2][0] * r[2][3] for r in rows) / max(lv, 1e-9)
        mp = sum(r[3][0] * r[3][3] for r in rows) / max(lp, 1e-9)
        rv = sum(r[2][2] * r[2][3] for r in rows) / max(lv, 1e-9)
        rp = sum(r[3][2] * r[3][3] for r in rows) / max(lp, 1e-9)
        print(f"{name} ALL: raw zz {100 * mv:.2f} % worst {100 * max(r[2][1] for r in rows):.1f} % rev/100mm {rv:.1f}"
              f" | refined zz {100 * mp:.2f} % worst {100 * max(r[3][1] for r in rows):.1f} % rev/100mm {rp:.1f}")


def read_dump(fn):
    paths = {}
    for line in open(fn):
        f = line.split()
        paths.setdefault(int(f[0]), []).append([float(v) for v in f[1:4]])
    return [np.array(paths[k]) for k in sorted(paths)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reports", nargs="*")
    ap.add_argument("--spacing", default=None, help="x,y,z mm (default: the report's volume's, read with --cli)")
    ap.add_argument("--cli", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "volscissors"))
    ap.add_argument("--sigma-mm", type=float, default=2.0)
    ap.add_argument("--window-mm", type=float, default=8.0)
    ap.add_argument("--family", default=None)
    ap.add_argument("--seeds", default=None)
    a = ap.parse_args()
    for rep in a.reports:
        sp = np.array([float(v) for v in a.spacing.split(",")]) if a.spacing else None
        if sp is None:
            sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
            from trace_measures import read_volume  # noqa: E402
            sp = read_volume(json.load(open(rep))["volume"], a.cli)[1]
        print_rows(os.path.basename(rep), report_rows(rep, sp, a.sigma_mm, a.window_mm))
    if a.family:
        lo, hi = (int(v) for v in a.seeds.split("-")) if a.seeds else (0, 1 << 30)
        for fn in sorted(glob.glob(os.path.join(a.family, "family_*_raw.txt"))):
            seed = int(re.search(r"family_(\d+)_raw", fn).group(1))
            if not lo <= seed <= hi:
                continue
            raw = read_dump(fn)
            ref = read_dump(fn.replace("_raw.txt", ".txt")) if os.path.exists(fn.replace("_raw.txt", ".txt")) else []
            rows = []
            for i, v in enumerate(raw):
                fp = figures(ref[i], a.sigma_mm, a.window_mm) if i < len(ref) else (0, 0, 0, 0)
                rows.append((i + 1, None, figures(v, a.sigma_mm, a.window_mm), fp))
            print_rows(f"seed {seed}", rows)


if __name__ == "__main__":
    main()
