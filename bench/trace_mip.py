#!/usr/bin/env python3
"""The three axis-aligned MIPs of a volume side by side (x-y, x-z, y-z; the second index up) with
a trace report's refined paths drawn over them (one colour per path, the root blue, requested
targets as numbered circles), for looking at whether the paths run on vessels (issue 21).

  /usr/bin/python3 bench/trace_mip.py VOLUME REPORT.json OUT.png [--scale 3] [--smooth-mm 0.5]
      [--cli build/volscissors]
"""
import argparse
import json
import os
import sys

import numpy as np
from PIL import Image, ImageDraw
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from trace_measures import ROOT, read_volume  # noqa: E402

COLOURS = [(255, 60, 60), (60, 220, 60), (40, 220, 220), (240, 220, 40), (230, 60, 230), (255, 150, 40),
           (160, 120, 255), (255, 255, 255)]


def draw(vol, report, out, scale=3, smooth_mm=0.5, spacing=None):
    sm = ndimage.gaussian_filter(vol, smooth_mm / spacing) if smooth_mm > 0 else vol
    hi = float(np.percentile(sm, 99.9))
    lo = float(np.percentile(sm, 1))
    tiles = []
    for a, (u, v) in ((2, (0, 1)), (1, (0, 2)), (0, (1, 2))):
        m = np.clip((sm.max(axis=a) - lo) / max(hi - lo, 1e-9) * 255, 0, 255).astype(np.uint8)
        # physical aspect: stretch the v axis by spacing[v] / spacing[u]
        w, h = int(round(m.shape[0] * scale)), int(round(m.shape[1] * scale * spacing[v] / spacing[u]))
        sy = h / m.shape[1]
        im = Image.fromarray(m.T[::-1]).convert("RGB").resize((w, h), Image.BILINEAR)
        d = ImageDraw.Draw(im)

        def px(p):
            return (p[u] + 0.5) * scale, (m.shape[1] - 1 - p[v] + 0.5) * sy

        for i, p in enumerate(report["paths"]):
            pts = [px(q) for q in p["points"]]
            if len(pts) > 1:
                d.line(pts, fill=COLOURS[i % len(COLOURS)], width=2)
        for k, p in enumerate(report["paths"]):
            cx, cy = px(p["requested"])
            d.ellipse([cx - 5, cy - 5, cx + 5, cy + 5], outline=(255, 255, 255), width=1)
            d.text((cx + 6, cy - 6), str(k + 1), fill=(255, 255, 255))
        cx, cy = px(report["root"])
        d.ellipse([cx - 5, cy - 5, cx + 5, cy + 5], outline=(60, 120, 255), width=2)
        tiles.append(im)
    w = sum(t.width for t in tiles) + 8 * (len(tiles) - 1)
    canvas = Image.new("RGB", (w, max(t.height for t in tiles)), (0, 0, 0))
    x0 = 0
    for t in tiles:
        canvas.paste(t, (x0, 0))
        x0 += t.width + 8
    canvas.save(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("volume")
    ap.add_argument("report")
    ap.add_argument("out")
    ap.add_argument("--scale", type=float, default=3, help="picture pixels per voxel (smallest spacing)")
    ap.add_argument("--smooth-mm", type=float, default=0.5)
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "volscissors"))
    a = ap.parse_args()
    vol, spacing = read_volume(a.volume, a.cli)
    draw(vol, json.load(open(a.report)), a.out, a.scale, a.smooth_mm, spacing)
    return 0


if __name__ == "__main__":
    sys.exit(main())
