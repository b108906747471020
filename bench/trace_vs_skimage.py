#!/usr/bin/env python3
"""Centreline accuracy and speed of `volscissors trace` against scikit-image MCP_Geometric (issue 12).

Volumes: the project's vessel phantom (`volscissors phantom vessels`, no noise of its own) degraded
as scanners degrade images - anisotropic voxels, a smooth multiplicative bias field 0.8..1.2 and
Rician noise (the same recipe as tests/tracking/centreline_test.cpp) - for several seeds. Roots and
targets: the phantom's root and terminals. Cost: ONE intensity cost array given to both tools:
c = 1e-3 + (1 - s)^4, s = clip((I_smoothed - lo) / (hi - lo), 0, 1), with the polarity, window
and smoothing that the project's default auto cost estimated at the root (read from a default
`trace` run's report); the smoothed intensities are SciPy's gaussian_filter. Ours runs on it with
`--cost given` (discrete paths and their timing); the default run (auto cost) gives the refined
points. Distances to the true centreline in units of the smallest spacing; time ratio = skimage
(MCP_Geometric + find_costs to the targets + traceback) / ours (the report's search seconds on
the same cost array), same process, same machine.

  /usr/bin/python3 bench/trace_vs_skimage.py [--build build] [--seeds 11 12 13 14] [--out DIR]

Needs Debian's python3-numpy, python3-scipy and python3-skimage.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import ndimage
from skimage.graph import MCP_Geometric

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from trace_measures import read_volume  # noqa: E402

# seed -> (spacing mm, Rician sigma); tubes 200 on a background of 30
CASES = {11: ((0.8, 0.8, 1.6), 15), 12: ((1.0, 1.0, 1.0), 20), 13: ((0.7, 1.0, 1.3), 15),
         14: ((0.8, 0.8, 1.6), 25), 15: ((0.6, 0.6, 1.2), 20)}
SIZE = (72, 72, 56)


def write_mha(path, a, spacing):
    """Uncompressed MetaImage of a float32 array indexed [x, y, z]."""
    with open(path, "wb") as f:
        f.write(("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                 f"ElementSpacing = {spacing[0]} {spacing[1]} {spacing[2]}\n"
                 f"DimSize = {a.shape[0]} {a.shape[1]} {a.shape[2]}\nElementType = MET_FLOAT\n"
                 "ElementDataFile = LOCAL\n").encode())
        f.write(np.ascontiguousarray(a.astype("<f4").transpose(2, 1, 0)).tobytes())


def degrade(clean, seed, sigma):
    """I' = sqrt((b I + n1)^2 + n2^2), bias b = 1 + 0.2 sin(pi (u + w / 2)) across x and z."""
    rng = np.random.default_rng(seed)
    nx, _, nz = clean.shape
    u = np.arange(nx) / (nx - 1) - 0.5
    w = np.arange(nz) / (nz - 1) - 0.5
    bias = 1 + 0.2 * np.sin(np.pi * (u[:, None, None] + 0.5 * w[None, None, :]))
    a = bias * clean + rng.normal(0, sigma, clean.shape)
    b = rng.normal(0, sigma, clean.shape)
    return np.sqrt(a * a + b * b).astype(np.float32)


def centreline_distance(truth, points, spacing):
    """Distance (units of the smallest spacing) from each voxel point to the true centreline."""
    segs = []
    for br in truth["branches"]:
        p = np.array(br["points"], float) * spacing
        segs.append(np.stack([p[:-1], p[1:]], 1))
    segs = np.concatenate(segs)
    a, d = segs[:, 0], segs[:, 1] - segs[:, 0]
    dd = np.maximum((d * d).sum(1), 1e-12)
    out = []
    for q in np.asarray(points, float) * spacing:
        t = np.clip(((q - a) * d).sum(1) / dd, 0, 1)
        out.append(np.sqrt((((a + t[:, None] * d) - q) ** 2).sum(1)).min())
    return np.array(out) / min(spacing)


def trace(build, args):
    out = subprocess.run([os.path.join(build, "volscissors"), "-q", "trace", *args], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"trace {' '.join(args)}: {out.stderr}")


def stats(d):
    return {"mean": float(d.mean()), "within2": float(np.mean(d <= 2.0)), "n": int(len(d))}


def run_case(build, tmp, seed):
    spacing, sigma = CASES[seed]
    vs = os.path.join(build, "volscissors")
    clean_path, truth_path = os.path.join(tmp, f"clean{seed}.nii.gz"), os.path.join(tmp, f"truth{seed}.json")
    subprocess.run([vs, "-q", "phantom", "vessels", "--seed", str(seed), "--size", ",".join(map(str, SIZE)),
                    "--spacing", ",".join(map(str, spacing)), "--noise", "0", "--out", clean_path,
                    "--truth", truth_path], check=True, capture_output=True)
    truth = json.load(open(truth_path))
    clean, sp = read_volume(clean_path, vs)
    vol = degrade(clean, seed, sigma)
    vol_path = os.path.join(tmp, f"v{seed}.mha")
    write_mha(vol_path, vol, sp)
    # Ours, defaults (auto cost, refinement).
    rep_path = os.path.join(tmp, f"r{seed}.json")
    trace(build, [vol_path, "--targets-file", truth_path, "--snap", "0", "--json", rep_path])
    rep = json.load(open(rep_path))
    e = rep["cost_estimate"]
    # The same intensity cost for both tools.
    sm = ndimage.gaussian_filter(vol.astype(np.float64), e["smooth_mm"] / sp) if e["smooth_mm"] > 0 else vol
    lo, hi = e["window"]
    s = np.clip((sm - lo) / (hi - lo), 0, 1)
    cost = (1e-3 + ((1 - s) if e["polarity"] == "bright" else s) ** 4).astype(np.float32)
    cost_path = os.path.join(tmp, f"c{seed}.mha")
    write_mha(cost_path, cost, sp)
    given_path = os.path.join(tmp, f"g{seed}.json")
    trace(build, [cost_path, "--cost", "given", "--targets-file", truth_path, "--no-refine", "--json", given_path])
    given = json.load(open(given_path))
    root = tuple(truth["root_voxel"])
    targets = [tuple(t["voxel"]) for t in truth["terminals"]]
    t0 = time.perf_counter()
    mcp = MCP_Geometric(cost, fully_connected=True, sampling=tuple(sp))
    cum, _ = mcp.find_costs([root], targets)
    theirs = [np.array(mcp.traceback(t)) for t in targets]
    t_sk = time.perf_counter() - t0
    reached = {"ours": sum(p["reached"] for p in rep["paths"]), "skimage": int(np.isfinite([cum[t] for t in targets]).sum())}
    cost_agree = max(abs(p["cost"] - cum[tuple(p["target"])]) / max(cum[tuple(p["target"])], 1e-12)
                     for p in given["paths"])
    pts = lambda r, key: np.concatenate([np.array(p[key], float) for p in r["paths"]])  # noqa: E731
    return {"seed": seed, "spacing": list(sp), "rician": sigma, "terminals": len(targets), "reached": reached,
            "estimate": f"{e['polarity']} window {lo:.0f}..{hi:.0f} smooth {e['smooth_mm']} mm",
            "refined": stats(centreline_distance(truth, pts(rep, "points"), sp)),
            "ours_voxels": stats(centreline_distance(truth, pts(given, "voxels"), sp)),
            "skimage": stats(centreline_distance(truth, np.concatenate(theirs), sp)),
            "max_rel_cost_diff": float(cost_agree), "seconds_ours": given["seconds"]["search"], "seconds_skimage": t_sk}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "build"))
    ap.add_argument("--seeds", type=int, nargs="+", default=[11, 12, 13, 14, 15], choices=sorted(CASES))
    a = ap.parse_args()
    ok = True
    print("| seed | spacing mm | Rician | terminals reached (ours / skimage) | ours refined: mean, within 2 | "
          "ours voxels: mean, within 2 | skimage: mean, within 2 | path cost diff | time skimage / ours |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in a.seeds:
            r = run_case(a.build, tmp, seed)
            f = lambda s: f"{s['mean']:.3f}, {100 * s['within2']:.1f}%"  # noqa: E731
            print(f"| {seed} | {','.join(f'{v:g}' for v in r['spacing'])} | {r['rician']} | "
                  f"{r['reached']['ours']}/{r['terminals']} / {r['reached']['skimage']}/{r['terminals']} | "
                  f"{f(r['refined'])} | {f(r['ours_voxels'])} | {f(r['skimage'])} | {r['max_rel_cost_diff']:.1e} | "
                  f"{r['seconds_skimage']:.3f} / {r['seconds_ours']:.3f} s = RATIO {r['seconds_skimage'] / max(r['seconds_ours'], 1e-6):.1f}x |",
                  flush=True)
            ok &= (r["refined"]["mean"] <= 0.5 and r["refined"]["within2"] >= 0.98 and
                   r["reached"]["ours"] == r["terminals"])
    print("goal (refined mean <= 0.5 voxel, >= 98 % within 2 voxels, every terminal reached):", "met" if ok else "NOT met")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
