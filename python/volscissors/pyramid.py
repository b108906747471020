"""Cost volume and its pyramid of an OME-Zarr volume, chunk-parallel on Dask (issue 25).

    python3 -m volscissors.pyramid IN.zarr --out COST.zarr [--cost intensity|auto]
        [--window LO,HI] [--polarity bright|dark] [--power P]
        [--workers N | --scheduler ADDRESS|synchronous|threads]

Each chunk of IN's full-resolution level is turned into node costs by the core's one cost
function (``volscissors.cost``, the formulas of ``volscissors trace --cost``) through
``dask.array.map_overlap`` with the halo the cost needs (0 voxels for the intensity cost, which is
pointwise), so the result equals the cost computed in memory on the whole volume, voxel for voxel.
The window (lo, hi) must be the same for every chunk: given, or the 1st / 99.9th percentiles of
IN's coarsest pyramid level (one small read). ``auto`` is the intensity cost here (the automatic
estimate of ``trace`` needs a root). The output is an OME-Zarr 0.4 folder (float32, zlib, IN's
chunks, a 2x2x2-mean pyramid down to one chunk), written beside OUT and renamed into place, so
``volscissors trace COST.zarr --cost given`` reads it as a cost volume.

Scheduler: a local cluster of N worker processes (default: the machine's cores), or any Dask
scheduler by address, or ``synchronous`` / ``threads`` (no cluster; tests use ``synchronous``).
Exit status: 2 for bad arguments, 1 for unreadable input or a failed computation.
"""
import argparse
import json
import math
import os
import shutil
import sys
import time

import numpy as np

UNITS_MM = {"millimeter": 1.0, "micrometer": 1e-3, "nanometer": 1e-6, "centimeter": 10.0, "meter": 1000.0, None: 1.0}


class UsageError(Exception):
    pass


def _multiscale(group):
    attrs = group.attrs.asdict()
    if "multiscales" not in attrs:
        raise OSError(f"{group.store.path}: no OME-Zarr multiscales metadata")
    ms = attrs["multiscales"][0]
    unit = None
    if "axes" in ms:
        units = {a.get("unit") for a in ms["axes"][-3:] if isinstance(a, dict)}
        unit = units.pop() if len(units) == 1 else None
    scale = UNITS_MM.get(unit, 1.0)
    levels = []
    for d in ms["datasets"]:
        s, t = [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]
        for tr in d.get("coordinateTransformations", []):
            if tr["type"] == "scale":
                s = [v * scale for v in tr["scale"][-3:]]
            elif tr["type"] == "translation":
                t = [v * scale for v in tr["translation"][-3:]]
        levels.append((d["path"], s, t))
    return levels


def _cost_block(block, spacing_xyz, window, polarity, power):
    import volscissors as vs

    vol = vs.Volume(np.ascontiguousarray(block), spacing=spacing_xyz)
    return np.array(vs.cost(vol, "intensity", window=window, polarity=polarity, power=power).array, copy=True)


def _write_level(arr, store_path, chunks):
    import zarr
    from numcodecs import Zlib

    z = zarr.open_array(store_path, mode="w", shape=arr.shape, chunks=chunks, dtype="<f4", compressor=Zlib(level=1),
                        fill_value=0, dimension_separator=".")
    arr.to_zarr(z, compute=True)


def build_pyramid(src, out, window=None, polarity="bright", power=4.0, scheduler=None, workers=None, log=print):
    """Computes the cost volume of OME-Zarr `src` into OME-Zarr `out` (see the module help).
    Returns a dict of figures (seconds, window, shape, levels)."""
    import dask
    import dask.array as da
    import zarr

    t0 = time.perf_counter()
    if not os.path.isdir(src):
        raise OSError(f"{src}: not a folder (an OME-Zarr volume is a folder)")
    group = zarr.open_group(src, mode="r")
    levels = _multiscale(group)
    path0, scale0, trans0 = levels[0]
    a0 = group[path0]
    if a0.ndim != 3:
        raise OSError(f"{src}/{path0}: {a0.ndim} axes; 3 (z, y, x) are supported")
    spacing_xyz = tuple(reversed(scale0))
    if window is None:
        coarse = np.asarray(group[levels[-1][0]][:], dtype=np.float64)
        window = (float(np.percentile(coarse, 1.0)), float(np.percentile(coarse, 99.9)))
        if not window[1] > window[0]:
            raise ValueError(f"{src}: no contrast in the coarsest level (window {window}); give --window")
    img = da.from_zarr(a0)
    cost = img.map_overlap(_cost_block, depth=0, boundary="none", dtype=np.float32, spacing_xyz=spacing_xyz,
                           window=window, polarity=polarity, power=power, meta=np.empty((0, 0, 0), np.float32))

    client = cluster = None
    if scheduler in ("synchronous", "threads"):
        ctx = dask.config.set(scheduler=scheduler)
    else:
        from distributed import Client, LocalCluster

        if scheduler:
            client = Client(scheduler)
        else:
            cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        ctx = dask.config.set(scheduler=client.get)
    parent = os.path.dirname(os.path.abspath(out)) or "."
    tmp = os.path.join(parent, f".{os.path.basename(os.path.abspath(out))}.tmp{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    figures = {"window": list(window), "shape_zyx": list(a0.shape), "chunks_zyx": list(a0.chunks)}
    try:
        with ctx:
            t1 = time.perf_counter()
            _write_level(cost, os.path.join(tmp, "0"), a0.chunks)
            figures["cost_seconds"] = time.perf_counter() - t1
            datasets = []
            level, scale, arr = 0, list(scale0), da.from_zarr(os.path.join(tmp, "0"))
            while True:
                origin = [t + 0.5 * (s - s0) for t, s, s0 in zip(trans0, scale, scale0)]
                datasets.append({"path": str(level), "coordinateTransformations": [
                    {"type": "scale", "scale": scale}, {"type": "translation", "translation": origin}]})
                if max(arr.shape[i] / a0.chunks[i] for i in range(3)) <= 1 or level >= 15:
                    break
                pad = [(0, s % 2) for s in arr.shape]
                arr = da.coarsen(np.mean, da.pad(arr, pad, mode="edge"), {0: 2, 1: 2, 2: 2}).astype(np.float32)
                level += 1
                scale = [2 * s for s in scale]
                _write_level(arr.rechunk(a0.chunks), os.path.join(tmp, str(level)), a0.chunks)
                arr = da.from_zarr(os.path.join(tmp, str(level)))
        root = zarr.open_group(tmp, mode="a")
        root.attrs["multiscales"] = [{
            "version": "0.4", "name": os.path.basename(out), "type": "mean",
            "axes": [{"name": n, "type": "space", "unit": "millimeter"} for n in "zyx"],
            "datasets": datasets,
            "metadata": {"volscissors": {"cost": "intensity", "window": list(window), "polarity": polarity,
                                         "power": power, "source": os.path.abspath(src)}}}]
        if os.path.exists(out):
            if not os.path.isdir(out) or not os.path.exists(os.path.join(out, ".zattrs")):
                raise OSError(f"{out}: exists and is not an OME-Zarr folder (refusing to replace it)")
            old = tmp + ".old"
            os.rename(out, old)
            os.rename(tmp, out)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.rename(tmp, out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    figures["levels"] = len(datasets)
    figures["seconds"] = time.perf_counter() - t0
    return figures


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m volscissors.pyramid", description=__doc__.split("\n\n")[0])
    ap.add_argument("input", help="OME-Zarr folder (its full-resolution level is read chunk by chunk)")
    ap.add_argument("--out", required=True, help="output OME-Zarr folder: float32 costs and their pyramid")
    ap.add_argument("--cost", default="intensity", choices=["intensity", "auto"],
                    help="cost kind (default intensity; auto = intensity here)")
    ap.add_argument("--window", help="intensity window lo,hi (default: 1st/99.9th percentiles of the coarsest level)")
    ap.add_argument("--polarity", default="bright", choices=["bright", "dark"], help="tubes brighter or darker (default bright)")
    ap.add_argument("--power", type=float, default=4.0, help="cost exponent (default 4)")
    ap.add_argument("--workers", type=int, help="local cluster worker processes (default: the machine's cores)")
    ap.add_argument("--scheduler", help="Dask scheduler address, or 'synchronous' / 'threads' (no cluster)")
    ap.add_argument("--json", help="write the figures (seconds, window, levels) as JSON here")
    try:
        a = ap.parse_args(argv)
    except SystemExit as e:
        return 2 if e.code else 0
    try:
        window = None
        if a.window:
            try:
                window = tuple(float(v) for v in a.window.split(","))
            except ValueError:
                raise UsageError(f"--window '{a.window}': expected lo,hi")
            if len(window) != 2 or not all(math.isfinite(v) for v in window) or not window[1] > window[0]:
                raise UsageError(f"--window '{a.window}': expected finite lo,hi with lo < hi")
        if a.workers is not None and a.workers < 1:
            raise UsageError("--workers must be >= 1")
        if a.power <= 0 or not math.isfinite(a.power):
            raise UsageError("--power must be > 0")
        if os.path.abspath(a.input) == os.path.abspath(a.out):
            raise UsageError("--out is the input")
        fig = build_pyramid(a.input, a.out, window, a.polarity, a.power, a.scheduler, a.workers)
    except UsageError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except (OSError, ValueError, KeyError, RuntimeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    print(f"cost intensity window {fig['window'][0]:.6g}..{fig['window'][1]:.6g}: {fig['levels']} levels -> {a.out} "
          f"({fig['seconds']:.1f} s)")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(fig, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
