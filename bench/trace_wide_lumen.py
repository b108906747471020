#!/usr/bin/env python3
"""Wide-lumen criteria of a trace report on a real volume (issue 21): are the refined points in the
vessel, centred, and are their radii the lumen's?

The vessel is where the volume, smoothed with a Gaussian of --smooth-mm (sigma), is >= --threshold
(bright) or <= it (--dark), and (with --upper) not beyond --upper on the other side: a CT lumen's
band between soft tissue and bone, calcium or metal. Per refined point of every path:
- inside: the trilinear value of the unsmoothed volume (--inside-smoothed: of the smoothed one) is in
  the vessel's band;
- wall distance: SciPy's exact Euclidean distance transform (mm, the volume's spacing) of the vessel,
  trilinear at the point;
- centred: the wall distance is >= --centred (0.5) x the largest wall distance within --near-mm (10)
  of the point (the medial axis of a round lumen has ratio 1, its wall 0);
- radius ratio: the report's radius / the inscribed radius, the largest wall distance within
  --inscribed-mm (5) of the point.
Prints per path and overall: points, share inside, share centred, the worst centring ratio, the
radius ratio's median, 5th and 95th percentiles. Exit 1 when a point is outside or not centred.

  /usr/bin/python3 bench/trace_wide_lumen.py VOLUME REPORT.json --threshold 90 [--upper U] [--dark]
      [--inside-smoothed] [--smooth-mm 1]
      [--near-mm 10] [--inscribed-mm 5] [--centred 0.5] [--cli build/volscissors] [--json out.json]
"""
import argparse
import json
import os
import sys

import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from trace_measures import ROOT, read_volume, trilinear  # noqa: E402


def ball_max(field, spacing, point, radius_mm):
    """Largest value of field (indexed [x, y, z]) at voxel centres within radius_mm of a continuous point."""
    r = np.ceil(radius_mm / spacing).astype(int)
    c = np.round(point).astype(int)
    lo = np.maximum(c - r, 0)
    hi = np.minimum(c + r + 1, field.shape)
    sub = field[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    grids = np.meshgrid(*[(np.arange(lo[a], hi[a]) - point[a]) * spacing[a] for a in range(3)], indexing="ij")
    inside = grids[0] ** 2 + grids[1] ** 2 + grids[2] ** 2 <= radius_mm ** 2
    return float(sub[inside].max()) if inside.any() else 0.0


def in_band(values, threshold, upper, dark):
    """The vessel side of threshold, and not beyond upper (None: no upper edge)."""
    inside = values <= threshold if dark else values >= threshold
    if upper is not None:
        inside &= values >= upper if dark else values <= upper
    return inside


def measure(vol, spacing, report, threshold, dark=False, smooth_mm=1.0, near_mm=10.0, inscribed_mm=5.0,
            centred=0.5, upper=None, inside_smoothed=False):
    sm = ndimage.gaussian_filter(vol, smooth_mm / spacing) if smooth_mm > 0 else vol
    vessel = in_band(sm, threshold, upper, dark)
    edt = ndimage.distance_transform_edt(vessel, sampling=spacing).astype(np.float32)
    rows, ratios_all, radius_all, inside_all = [], [], [], []
    for i, p in enumerate(report["paths"]):
        pts = np.array(p["points"], float)
        if len(pts) == 0:
            continue
        values = trilinear(sm if inside_smoothed else vol, pts)
        inside = in_band(values, threshold, upper, dark)
        wall = trilinear(edt, pts)
        ratio = np.array([w / max(ball_max(edt, spacing, q, near_mm), 1e-9) for q, w in zip(pts, wall)])
        radii = np.array(p.get("radii_mm", [np.nan] * len(pts)), float)
        rr = np.array([rad / max(ball_max(edt, spacing, q, inscribed_mm), 1e-9) for q, rad in zip(pts, radii)])
        rows.append({"path": i, "target": p["target"], "points": len(pts), "inside": float(inside.mean()),
                     "centred": float(np.mean(ratio >= centred)), "worst_centring": float(ratio.min()),
                     "radius_ratio_median": float(np.nanmedian(rr))})
        ratios_all.append(ratio)
        radius_all.append(rr)
        inside_all.append(inside)
    ratio, rr, inside = np.concatenate(ratios_all), np.concatenate(radius_all), np.concatenate(inside_all)
    overall = {"paths": len(rows), "points": int(len(ratio)), "inside": float(inside.mean()),
               "outside_points": int((~inside).sum()), "centred": float(np.mean(ratio >= centred)),
               "not_centred_points": int((ratio < centred).sum()), "worst_centring": float(ratio.min()),
               "radius_ratio": [float(np.nanpercentile(rr, q)) for q in (5, 50, 95)]}
    return rows, overall


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("volume")
    ap.add_argument("report")
    ap.add_argument("--threshold", type=float, required=True, help="the vessel's edge value (no default)")
    ap.add_argument("--upper", type=float, help="the band's other edge (bone, metal; default none)")
    ap.add_argument("--dark", action="store_true", help="the lumen is darker than the threshold (airways)")
    ap.add_argument("--inside-smoothed", action="store_true", help="judge inside on the smoothed volume")
    ap.add_argument("--smooth-mm", type=float, default=1.0, help="Gaussian sigma of the vessel mask (default 1)")
    ap.add_argument("--near-mm", type=float, default=10.0, help="centring neighbourhood (default 10)")
    ap.add_argument("--inscribed-mm", type=float, default=5.0, help="inscribed radius neighbourhood (default 5)")
    ap.add_argument("--centred", type=float, default=0.5, help="least wall-distance ratio (default 0.5)")
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "volscissors"))
    ap.add_argument("--json", help="write rows and overall here")
    a = ap.parse_args()
    vol, spacing = read_volume(a.volume, a.cli)
    rows, overall = measure(vol, spacing, json.load(open(a.report)), a.threshold, a.dark, a.smooth_mm, a.near_mm,
                            a.inscribed_mm, a.centred, a.upper, a.inside_smoothed)
    for r in rows:
        print("path %d -> %s: %d points, inside %.1f %%, centred %.1f %% (worst %.2f), radius / inscribed %.2f" %
              (r["path"], r["target"], r["points"], 100 * r["inside"], 100 * r["centred"], r["worst_centring"],
               r["radius_ratio_median"]))
    o = overall
    print("overall: %d paths, %d points, inside %.2f %% (%d out), centred %.2f %% (%d not, worst %.2f), "
          "radius / inscribed p5 %.2f median %.2f p95 %.2f" %
          (o["paths"], o["points"], 100 * o["inside"], o["outside_points"], 100 * o["centred"],
           o["not_centred_points"], o["worst_centring"], *o["radius_ratio"]))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"rows": rows, "overall": overall}, f, indent=1)
    return 1 if o["outside_points"] or o["not_centred_points"] else 0


if __name__ == "__main__":
    sys.exit(main())
