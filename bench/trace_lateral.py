#!/usr/bin/env python3
"""Side-to-side alternation of refined points, apart from the vessel's own bends (issue 21; session 29 zig2).

Per refined point its lateral residual: the point minus a Gaussian-weighted local quadratic through the path's
points within +-2 of its radii along the arc (sigma one radius), the component normal to the fit's direction. A
bend of constant curvature is fitted, so a tortuous vessel (the carotid siphon) is not punished, as the 2 mm
smoothing of `trace_zigzag.py` does; a point centred on the other side of the axis than its neighbours is.
Alternating: successive points' residuals both over --threshold mm and opposite (cos < -0.5). Per report: per
radius class the points (each counted once over the paths), the share alternating and the rms residual; and the
median over paths of trace_zigzag's figure for the points and for their local fit (the part that is real bends).

  /usr/bin/python3 bench/trace_lateral.py REPORT.json [...] [--spacing 0.55,0.55,1] [--cli build/volscissors]
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from trace_zigzag import figures  # noqa: E402


def lateral(p, radii, reach_radii=2.0, min_reach=2.0):
    """p: N x 3 points (mm), radii (mm). Returns (residuals N x 3, measured mask)."""
    n = len(p)
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    res, ok = np.zeros((n, 3)), np.zeros(n, bool)
    for i in range(n):
        h = max(min_reach, reach_radii * np.median(radii[max(0, i - 3):i + 4]))
        m = np.abs(s - s[i]) <= h
        if m.sum() < 5 or s[i] - s[0] < h or s[-1] - s[i] < h:
            continue  # the ends: the window would be one-sided
        t = s[m] - s[i]
        w = np.sqrt(np.exp(-0.5 * (t / (h / 2)) ** 2))[:, None]
        c, *_ = np.linalg.lstsq(np.stack([np.ones_like(t), t, t * t], 1) * w, p[m] * w, rcond=None)
        d = p[i] - c[0]
        tan = c[1] / max(np.linalg.norm(c[1]), 1e-9)
        res[i], ok[i] = d - tan.dot(d) * tan, True
    return res, ok


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reports", nargs="+")
    ap.add_argument("--spacing", default=None, help="x,y,z mm (else read with --cli)")
    ap.add_argument("--cli", default=os.path.join(os.path.dirname(__file__), "..", "build", "volscissors"))
    ap.add_argument("--threshold", type=float, default=0.3)
    a = ap.parse_args()
    bins = [0, 1, 2, 3, 5, np.inf]
    for fn in a.reports:
        r = json.load(open(fn))
        if a.spacing:
            sp = np.array([float(x) for x in a.spacing.split(",")])
        else:
            from trace_measures import read_volume
            sp = read_volume(r["volume"], a.cli)[1]
        seen, cls, zz, zf = set(), [[0, 0, 0.0] for _ in bins[:-1]], [], []
        for path in r["paths"]:
            p = np.array(path["points"], float) * sp
            rad = np.array(path["radii_mm"], float)
            res, ok = lateral(p, rad)
            mag = np.linalg.norm(res, axis=1)
            alt = np.zeros(len(p), bool)
            for i in range(len(p) - 1):
                if ok[i] and ok[i + 1] and min(mag[i], mag[i + 1]) > a.threshold and \
                        res[i].dot(res[i + 1]) < -0.5 * mag[i] * mag[i + 1]:
                    alt[i] = alt[i + 1] = True
            zz.append(figures(p)[0])
            zf.append(figures(p - res)[0])
            for i, x in enumerate(path["points"]):
                key = tuple(np.round(x, 4))
                if key in seen or not ok[i]:
                    continue
                seen.add(key)
                b = int(np.searchsorted(bins, rad[i], side="right") - 1)
                cls[b][0] += 1
                cls[b][1] += int(alt[i])
                cls[b][2] += mag[i] ** 2
        print(f"{os.path.basename(fn)}: 2 mm zig-zag of the points (median over {len(zz)} paths) "
              f"{100 * np.median(zz):.1f} %, of their local fit (bends) {100 * np.median(zf):.1f} %")
        for b, (n, k, e) in enumerate(cls):
            if n:
                print(f"  radius {bins[b]}-{bins[b + 1]} mm: {n} points, alternating {100 * k / n:.1f} %, "
                      f"rms lateral residual {np.sqrt(e / n):.2f} mm")


if __name__ == "__main__":
    main()
