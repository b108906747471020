#!/usr/bin/env python3
"""Targets in distal branches 40-60 % as bright as the root (issue 21), chosen by a fixed rule a
user would follow on a maximum intensity projection, before any trace runs, so the check of `trace`
on them is not tuned to them.

Rule (session 10; bright vessels). On the volume smoothed by 0.5 mm (what the cost sees):
  root level L = the median of the root's 3x3x3 neighbourhood;
  visible in a MIP: for each of the three axis-aligned MIPs, a pixel shows a vessel when it is a
    line in the picture (2D Hessian of the MIP at sigma 1 pixel: the larger-magnitude eigenvalue
    negative and at least twice the other's magnitude) that stands out (MIP value >= 1.2 x the
    median of the MIP over a ring 3-6 mm around the pixel); the voxel it shows is the brightest
    of its ray (argmax). A target is such a voxel in at least TWO of the three MIPs (a branch seen
    from two sides: not a crossing of two vessels in one picture);
  at its local centreline maximum: the maximum of its 3-voxel line along at least two of the
    three axes, and tubular in 3D (Hessian at sigma 1 voxel: the two largest-magnitude
    eigenvalues negative, the smallest at most half the middle one in magnitude);
  brightness: smoothed value in [0.4 L, 0.6 L];
  distal: at least --min-mm (40) from the root, and at least 3 mm from every face of the volume
    (a slab edge darkens vessels that are not branch ends);
  in the root's tree: in the 26-connected component of the root among the voxels that are at least
    0.3 L and tubular-or-blob (the two largest-magnitude Hessian eigenvalues negative: bright in
    two directions, i.e. not flat tissue);
  5 targets by farthest-point sampling (the first the farthest from the root), >= --sep-mm (10)
  apart.

Root: given, or "inflow": the brightest voxel within 10 mm of the inferior face (z index 0) shown
as a vessel by two MIPs and tubular (a user clicks the trunk where it enters the volume), or
"deepest" (saturated angiograms, where the inflow's brightest voxel is one of thousands at the
maximum): the voxel deepest inside the mask v >= half the maximum (largest Euclidean distance to
outside it, with the spacing) at least 25 mm from the deepest of all (an aneurysm sac or the widest
lumen is not where a user clicks the root; the parent artery beside it is).

  /usr/bin/python3 bench/dim_targets.py VOLUME X,Y,Z|inflow|deepest [-n 5] [--png OUT.png] [--cli build/volscissors]
prints "x,y,z;x,y,z;..." (for --target) and one line per target with its value / L and the MIP
views that show it; --png writes the three MIPs side by side with the root (blue) and the targets
(red, numbered by order) marked, for looking at.
"""
import argparse
import os
import sys

import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from trace_measures import ROOT, read_volume  # noqa: E402


def hessian_eigs(a, sigma):
    """Eigenvalues of the Gaussian-smoothed Hessian of `a` (2D or 3D), sorted by magnitude
    (last axis: smallest magnitude first)."""
    nd = a.ndim
    h = np.empty(a.shape + (nd, nd), np.float32)
    for i in range(nd):
        for j in range(i, nd):
            order = [0] * nd
            order[i] += 1
            order[j] += 1
            d = ndimage.gaussian_filter(a, sigma, order=order)
            h[..., i, j] = d
            h[..., j, i] = d
    ev = np.linalg.eigvalsh(h)
    idx = np.argsort(np.abs(ev), axis=-1)
    return np.take_along_axis(ev, idx, axis=-1)


def ring_median_2d(m, spacing2, r0=3.0, r1=6.0):
    """Per pixel: the median of m over the ring r0..r1 mm (a rank filter with a ring footprint)."""
    ext = np.ceil(r1 / spacing2).astype(int)
    gx, gy = np.meshgrid(np.arange(-ext[0], ext[0] + 1) * spacing2[0], np.arange(-ext[1], ext[1] + 1) * spacing2[1],
                         indexing="ij")
    d = np.hypot(gx, gy)
    foot = (d >= r0) & (d <= r1)
    return ndimage.median_filter(m, footprint=foot, mode="nearest")


def visible_voxels(sm, spacing):
    """Per voxel: in how many of the three axis MIPs it is shown as a vessel (see the rule)."""
    count = np.zeros(sm.shape, np.int8)
    for a in range(3):
        m = sm.max(axis=a)
        arg = sm.argmax(axis=a)
        sp2 = np.delete(spacing, a)
        ev = hessian_eigs(m, 1.0)
        line = (ev[..., 1] < 0) & (np.abs(ev[..., 1]) >= 2 * np.abs(ev[..., 0]))
        stands = m >= 1.2 * ring_median_2d(m, sp2)
        show = line & stands
        ii = np.argwhere(show)
        full = [None] * 3
        other = [k for k in range(3) if k != a]
        full[other[0]], full[other[1]] = ii[:, 0], ii[:, 1]
        full[a] = arg[ii[:, 0], ii[:, 1]]
        count[full[0], full[1], full[2]] += 1
    return count


def inflow_root(sm, spacing, axis=2, mm=10.0):
    """The root a user clicks where the trunk enters: the brightest voxel within `mm` of the
    inferior face (index 0 of `axis`) that is shown as a vessel by two of the three MIPs and is
    tubular (as the targets)."""
    views = visible_voxels(sm, spacing)
    ev = hessian_eigs(sm, 1.0 * spacing.min() / spacing)
    tub = (ev[..., 2] < 0) & (ev[..., 1] < 0) & (np.abs(ev[..., 0]) <= 0.5 * np.abs(ev[..., 1]))
    ok = (views >= 2) & tub
    sl = [slice(None)] * 3
    sl[axis] = slice(int(np.floor(mm / spacing[axis])) + 1, None)
    ok[tuple(sl)] = False
    masked = np.where(ok, sm, -np.inf)
    return tuple(int(c) for c in np.unravel_index(int(np.argmax(masked)), sm.shape))


def deepest_root(vol, spacing, away_mm=25.0, earlier=(), earlier_mm=(30.0, 25.0, 20.0), min_depth_mm=2.0):
    """The "deepest" root rule (see the module's text). With `earlier` roots (sessions 26-36: a new
    real structure each session), also at least earlier_mm[0] from every one of them; where no voxel
    of depth >= min_depth_mm is left that far, the next distance. Returns (root, depth mm, limit used)."""
    inside = vol >= 0.5 * float(vol.max())
    depth = ndimage.distance_transform_edt(inside, sampling=spacing)
    sac = np.array(np.unravel_index(int(np.argmax(depth)), vol.shape))
    idx = np.indices(vol.shape)

    def dist(p):
        return np.sqrt(sum(((idx[a] - p[a]) * spacing[a]) ** 2 for a in range(3)))

    ok = inside & (dist(sac) >= away_mm)
    near = np.full(vol.shape, np.inf)
    for p in earlier:
        near = np.minimum(near, dist(p))
    for limit in earlier_mm if earlier else (None,):
        cand = np.where(ok & (near >= limit) if limit is not None else ok, depth, 0)
        k = int(np.argmax(cand))
        if cand.flat[k] >= min_depth_mm or limit == earlier_mm[-1] or limit is None:
            return tuple(int(c) for c in np.unravel_index(k, vol.shape)), float(cand.flat[k]), limit


def choose(vol, spacing, root, n=5, lo=0.4, hi=0.6, min_mm=40.0, sep_mm=10.0):
    sm = ndimage.gaussian_filter(vol, 0.5 / spacing).astype(np.float32)
    x, y, z = root
    L = float(np.median(sm[max(x - 1, 0):x + 2, max(y - 1, 0):y + 2, max(z - 1, 0):z + 2]))
    ev = hessian_eigs(sm, 1.0 * spacing.min() / spacing)
    bright2 = (ev[..., 2] < 0) & (ev[..., 1] < 0)
    tubular = bright2 & (np.abs(ev[..., 0]) <= 0.5 * np.abs(ev[..., 1]))
    del ev
    tree = bright2 & (sm >= 0.3 * L)
    lab, _ = ndimage.label(tree, structure=np.ones((3, 3, 3)))
    near = lab[max(x - 1, 0):x + 2, max(y - 1, 0):y + 2, max(z - 1, 0):z + 2]
    ids = np.unique(near[near > 0])
    comp = np.isin(lab, ids) if len(ids) else np.zeros(sm.shape, bool)
    ridge_axes = np.zeros(vol.shape, np.int8)
    for a in range(3):
        ridge_axes += ((sm >= np.roll(sm, 1, axis=a)) & (sm >= np.roll(sm, -1, axis=a))).astype(np.int8)
    views = visible_voxels(sm, spacing)
    cand = comp & tubular & (ridge_axes >= 2) & (views >= 2) & (sm >= lo * L) & (sm <= hi * L)
    # Not within 3 mm of a face of the volume (slab edges: no branch end a user would click).
    for a in range(3):
        e = int(np.ceil(3.0 / spacing[a]))
        sl = [slice(None)] * 3
        sl[a] = slice(0, e)
        cand[tuple(sl)] = False
        sl[a] = slice(sm.shape[a] - e, None)
        cand[tuple(sl)] = False
    idx = np.argwhere(cand)
    d_root = np.linalg.norm((idx - np.array(root)) * spacing, axis=1)
    idx, d_root = idx[d_root >= min_mm], d_root[d_root >= min_mm]
    chosen = []
    if len(idx):
        chosen.append(int(np.argmax(d_root)))
        dmin = np.linalg.norm((idx - idx[chosen[0]]) * spacing, axis=1)
        while len(chosen) < n:
            k = int(np.argmax(dmin))
            if dmin[k] < sep_mm:
                break
            chosen.append(k)
            dmin = np.minimum(dmin, np.linalg.norm((idx - idx[k]) * spacing, axis=1))
    targets = [tuple(int(c) for c in idx[k]) for k in chosen]
    info = {"L": L, "candidates": int(len(idx)), "component_voxels": int(comp.sum())}
    return sm, info, targets, [float(sm[t]) / L for t in targets], [int(views[t]) for t in targets]


def picture(sm, root, targets, out, scale=4):
    """The three axis MIPs side by side (x-y, x-z, y-z; superior up), root blue, targets red."""
    from PIL import Image, ImageDraw
    hi = float(np.percentile(sm, 99.9))
    tiles = []
    for a, (u, v) in ((2, (0, 1)), (1, (0, 2)), (0, (1, 2))):
        m = np.clip(sm.max(axis=a) / hi * 255, 0, 255).astype(np.uint8)  # [u, v]
        im = Image.fromarray(m.T[::-1]).convert("RGB").resize((m.shape[0] * scale, m.shape[1] * scale),
                                                                Image.NEAREST)
        d = ImageDraw.Draw(im)
        hgt = m.shape[1]
        for k, (p, col) in enumerate([(root, (60, 120, 255))] + [(t, (255, 40, 40)) for t in targets]):
            cx, cy = (p[u] + 0.5) * scale, (hgt - 1 - p[v] + 0.5) * scale
            d.ellipse([cx - 5, cy - 5, cx + 5, cy + 5], outline=col, width=2)
            if k:
                d.text((cx + 6, cy - 6), str(k), fill=col)
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
    ap.add_argument("root")
    ap.add_argument("-n", type=int, default=5, help="targets to choose (default 5)")
    ap.add_argument("--min-mm", type=float, default=40.0, help="least distance from the root, mm (default 40)")
    ap.add_argument("--sep-mm", type=float, default=10.0, help="least distance between targets, mm (default 10)")
    ap.add_argument("--png", help="write the three MIPs with root and targets marked (default: none)")
    ap.add_argument("--png-scale", type=int, default=4, help="picture pixels per voxel (default 4)")
    ap.add_argument("--earlier-roots", default="", help="x,y,z;... roots used before: the deepest root keeps "
                    "--earlier-mm from them (the first distance that leaves a voxel of depth >= 2 mm; default: none)")
    ap.add_argument("--earlier-mm", default="30,25,20", help="distances from the earlier roots tried in turn, mm (default 30,25,20)")
    ap.add_argument("--earlier-targets", default="", help="x,y,z;... targets used before: pick the first n of "
                    "--pool candidates in the rule's order that lie >= --sep-mm from all of them (default: none)")
    ap.add_argument("--pool", type=int, default=40, help="candidates chosen before the earlier targets are removed (default 40)")
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "volscissors"), help="the CLI that reads the volume (default build/volscissors)")
    a = ap.parse_args()

    def points(text):
        return [tuple(int(v) for v in p.split(",")) for p in text.split(";") if p.strip()]
    vol, spacing = read_volume(a.volume, a.cli)
    if a.root == "inflow":
        root = inflow_root(ndimage.gaussian_filter(vol, 0.5 / spacing).astype(np.float32), spacing)
        print(f"root (inflow rule): {root[0]},{root[1]},{root[2]}")
    elif a.root == "deepest":
        root, depth, limit = deepest_root(vol, spacing, earlier=points(a.earlier_roots),
                                          earlier_mm=tuple(float(v) for v in a.earlier_mm.split(",")))
        print(f"root (deepest rule): {root[0]},{root[1]},{root[2]} (depth {depth:.2f} mm"
              + (f", >= {limit:g} mm from the earlier roots)" if limit is not None else ")"))
    else:
        root = tuple(int(v) for v in a.root.split(","))
    old = points(a.earlier_targets)
    if old:
        sm, info, pool, ratios, views = choose(vol, spacing, root, a.pool, min_mm=a.min_mm, sep_mm=a.sep_mm)
        keep = [k for k, t in enumerate(pool)
                if all(np.linalg.norm((np.array(t) - np.array(o)) * spacing) >= a.sep_mm for o in old)][:a.n]
        targets, ratios, views = [pool[k] for k in keep], [ratios[k] for k in keep], [views[k] for k in keep]
        print(f"{len(pool)} in the pool of {a.pool}; {len(targets)} lie >= {a.sep_mm:g} mm from the {len(old)} earlier targets")
    else:
        sm, info, targets, ratios, views = choose(vol, spacing, root, a.n, min_mm=a.min_mm, sep_mm=a.sep_mm)
    print(";".join(",".join(map(str, t)) for t in targets))
    print(f"root level {info['L']:.1f}; {info['candidates']} candidates; root component {info['component_voxels']} voxels")
    for t, r, v in zip(targets, ratios, views):
        print(f"target {t}: {r:.2f} of the root level, shown by {v} of 3 MIPs")
    if a.png:
        picture(sm, root, targets, a.png, a.png_scale)
    return 0 if targets else 1


if __name__ == "__main__":
    sys.exit(main())
