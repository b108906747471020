"""Cost volume and its pyramid of an OME-Zarr volume, chunk-parallel on Dask (issue 25).

    python3 -m volscissors.pyramid IN.zarr --out COST.zarr [--cost intensity|auto|vesselness]
        [--window LO,HI] [--scales MM,...] [--polarity bright|dark] [--power P]
        [--workers N | --scheduler ADDRESS|synchronous|threads]

Each chunk of IN's full-resolution level is turned into node costs by the core's one cost
function (``volscissors.cost``, the formulas of ``volscissors trace --cost``), so the result
equals the cost computed in memory on the whole volume, voxel for voxel. Every 2x2x2 block of chunks
is one Dask task that reads its input region from IN and writes its own output chunks (no array
graph, no rechunking); each coarser level is one task per block of chunks, from the level below.

``intensity`` (and ``auto``, which is the intensity cost here: the automatic estimate of
``trace`` needs a root) is pointwise; its window (lo, hi) is the same for every chunk: given, or
the 1st / 99.9th percentiles of IN's coarsest pyramid level (one small read). ``vesselness``
(Frangi) needs context and two whole-volume quantities: each chunk is read with the halo its
largest Gaussian kernel and the Hessian need (none beyond the volume's faces, where the core
clamps), Frangi's c per scale is the maximum of the chunks' own (a first pass), and the
response's 99.5th percentile comes from the same subsample of linear indices the core takes.

The output is an OME-Zarr 0.4 folder (float32, zlib, IN's chunks, a 2x2x2-mean pyramid down to
one chunk), written beside OUT and renamed into place, so ``volscissors trace COST.zarr --cost
given`` reads it as a cost volume.

Scheduler: a local cluster of N worker processes (default: the machine's cores), or any Dask
scheduler by address, or ``synchronous`` / ``threads`` (no cluster; tests use ``synchronous``).
Exit status: 2 for bad arguments, 1 for unreadable input or a failed computation.
"""
import argparse
import functools
import itertools
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


@functools.lru_cache(maxsize=64)
def _array(path, mode="r"):
    """A zarr array opened once per worker process (tasks name arrays by path, so they pickle small)."""
    import zarr

    return zarr.open_array(path, mode=mode)


# Stored chunks per task along each axis: a task of 2x2x2 chunks (8 x 64^3 floats, 8 MiB) keeps the
# scheduler's per-task work (~1 ms, on a core the workers need) and the vesselness halo's re-reads
# small against the work, and still gives 512 tasks on a 1024^3 volume of 64^3 chunks.
TASK_CHUNKS = 2


def _unit(chunks):
    return tuple(TASK_CHUNKS * c for c in chunks)


def _box(shape, chunks, index, halo=0):
    """Box `index` (of `chunks` voxels) of an array (z, y, x), with `halo` voxels of context clipped to the array.
    Returns the read slices and the slices of the chunk inside what is read."""
    read, inner = [], []
    for n, c, i in zip(shape, chunks, index):
        lo, hi = i * c, min(n, (i + 1) * c)
        rlo, rhi = max(0, lo - halo), min(n, hi + halo)
        read.append(slice(rlo, rhi))
        inner.append(slice(lo - rlo, hi - rlo))
    return tuple(read), tuple(inner)


def _read(a, path, read):
    """a[read] from its stored chunks, checked as the core's reader checks them (io/zarr_io.h):
    python-zarr would read a missing chunk as fill values and a truncated blosc chunk as whatever
    its header promises, so a chunk that is not stored, does not decode, or decodes to the wrong
    size is an OSError naming it."""
    out = np.empty([r.stop - r.start for r in read], dtype=a.dtype)
    ranges = [range(r.start // c, -(-r.stop // c)) for r, c in zip(read, a.chunks)]
    expected = int(np.prod(a.chunks)) * a.dtype.itemsize
    for index in itertools.product(*ranges):
        key = a._chunk_key(index)
        name = f"{path} chunk {key.rsplit('/', 1)[-1]}"
        if key not in a.chunk_store:
            raise OSError(f"{name} is missing")
        raw = a.chunk_store[key]
        try:
            if a.compressor is not None and a.compressor.codec_id == "blosc":
                if len(raw) < 16 or int.from_bytes(bytes(raw[12:16]), "little") != len(raw):
                    raise ValueError(f"{len(raw)} bytes stored, the blosc header says otherwise")
            data = a.compressor.decode(raw) if a.compressor is not None else raw
            for f in reversed(a.filters or []):
                data = f.decode(data)
        except Exception as e:  # any codec's failure is this chunk's
            raise OSError(f"{name} cannot be decoded: {e}") from e
        data = np.frombuffer(data, dtype=np.uint8)
        if data.size != expected:
            raise OSError(f"{name}: {data.size} bytes decoded, {expected} expected for chunks {a.chunks} {a.dtype}")
        chunk = data.view(a.dtype).reshape(a.chunks, order=a.order)
        src, dst = [], []
        for i, r, c in zip(index, read, a.chunks):
            lo, hi = max(r.start, i * c), min(r.stop, (i + 1) * c)
            src.append(slice(lo - i * c, hi - i * c))
            dst.append(slice(lo - r.start, hi - r.start))
        out[tuple(dst)] = chunk[tuple(src)]
    return out


def _chunk_indices(shape, chunks):
    return list(itertools.product(*(range(-(-n // c)) for n, c in zip(shape, chunks))))


def _volume(block, spacing_xyz):
    import volscissors as vs

    return vs.Volume(np.ascontiguousarray(block), spacing=spacing_xyz)


def _intensity_task(src, dst, index, spacing_xyz, window, polarity, power):
    import volscissors as vs

    a, out = _array(src), _array(dst, "r+")
    read, _ = _box(a.shape, _unit(a.chunks), index)
    cost = vs.cost(_volume(_read(a, src, read), spacing_xyz), "intensity", window=window, polarity=polarity, power=power)
    out[read] = cost.array


def _structure_task(src, index, spacing_xyz, scales, halo):
    import volscissors as vs

    a = _array(src)
    read, inner = _box(a.shape, _unit(a.chunks), index, halo)
    lo = [inner[2].start, inner[1].start, inner[0].start]
    hi = [inner[2].stop, inner[1].stop, inner[0].stop]
    return vs.vesselness_structure_scale(_volume(_read(a, src, read), spacing_xyz), scales, lo, hi)


def _response_task(src, tmp, index, spacing_xyz, scales, polarity, c_per_scale, halo, stride):
    """The vesselness of box `index` (written to tmp) and its values at the whole volume's linear
    indices k * stride (x fastest), the subsample the core's percentile takes (percentileOf)."""
    import volscissors as vs

    a, out = _array(src), _array(tmp, "r+")
    read, inner = _box(a.shape, _unit(a.chunks), index, halo)
    v = vs.vesselness(_volume(_read(a, src, read), spacing_xyz), scales, polarity, c_per_scale).array[inner]
    own, _ = _box(a.shape, _unit(a.chunks), index)
    out[own] = v
    nz, ny, nx = a.shape
    z = np.arange(own[0].start, own[0].stop, dtype=np.int64)[:, None, None]
    y = np.arange(own[1].start, own[1].stop, dtype=np.int64)[None, :, None]
    x = np.arange(own[2].start, own[2].stop, dtype=np.int64)[None, None, :]
    return v[((x + nx * (y + ny * z)) % stride) == 0]


def _vesselness_cost_task(tmp, dst, index, spacing_xyz, max_response, power):
    import volscissors as vs

    a, out = _array(tmp), _array(dst, "r+")
    read, _ = _box(a.shape, _unit(a.chunks), index)
    out[read] = vs.vesselness_cost(_volume(a[read], spacing_xyz), max_response, power).array


def _mean_task(src, dst, index):
    """Box `index` of the next level: the 2x2x2 means of the level below (its last odd row of
    voxels repeated), as dask.array.coarsen(np.mean) of the edge-padded level computes them."""
    a, out = _array(src), _array(dst, "r+")
    read, _ = _box(out.shape, _unit(out.chunks), index)
    block = a[tuple(slice(2 * r.start, min(a.shape[i], 2 * r.stop)) for i, r in enumerate(read))]
    pad = [(0, 2 * (r.stop - r.start) - n) for r, n in zip(read, block.shape)]
    if any(p[1] for p in pad):
        block = np.pad(block, pad, mode="edge")
    z, y, x = block.shape
    out[read] = np.mean(block.reshape(z // 2, 2, y // 2, 2, x // 2, 2), axis=(1, 3, 5)).astype(np.float32)


def _new_level(path, shape, chunks, compressor="zlib"):
    import zarr
    from numcodecs import Zlib

    zarr.open_array(path, mode="w", shape=shape, chunks=chunks, dtype="<f4",
                    compressor=Zlib(level=1) if compressor == "zlib" else None, fill_value=0,
                    dimension_separator=".")
    return path


def _run(tasks):
    import dask

    return dask.compute(*tasks) if tasks else ()


def build_pyramid(src, out, window=None, polarity="bright", power=4.0, scheduler=None, workers=None, log=print,
                  cost="intensity", scales=None):
    """Computes the cost volume of OME-Zarr `src` into OME-Zarr `out` (see the module help).
    Returns a dict of figures (seconds, window, shape, levels)."""
    import dask
    import zarr

    t0 = time.perf_counter()
    if cost not in ("intensity", "auto", "vesselness"):
        raise UsageError(f"--cost {cost}: expected intensity, auto or vesselness")
    if not os.path.isdir(src):
        raise OSError(f"{src}: not a folder (an OME-Zarr volume is a folder)")
    group = zarr.open_group(src, mode="r")
    levels = _multiscale(group)
    path0, scale0, trans0 = levels[0]
    a0 = group[path0]
    if a0.ndim != 3:
        raise OSError(f"{src}/{path0}: {a0.ndim} axes; 3 (z, y, x) are supported")
    spacing_xyz = tuple(reversed(scale0))
    src0 = os.path.join(os.path.abspath(src), path0)
    vesselness = cost == "vesselness"
    if vesselness:
        if window is not None:
            raise UsageError("--window is for the intensity cost; vesselness normalises by its own percentile")
    elif window is None:
        coarse = np.asarray(group[levels[-1][0]][:], dtype=np.float64)
        window = (float(np.percentile(coarse, 1.0)), float(np.percentile(coarse, 99.9)))
        if not window[1] > window[0]:
            raise ValueError(f"{src}: no contrast in the coarsest level (window {window}); give --window")
    delayed = dask.delayed(pure=False)

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
    figures = {"cost": "vesselness" if vesselness else "intensity", "shape_zyx": list(a0.shape),
               "chunks_zyx": list(a0.chunks)}
    if not vesselness:
        figures["window"] = list(window)
    chunks = a0.chunks
    try:
        with ctx:
            t1 = time.perf_counter()
            level0 = _new_level(os.path.join(tmp, "0"), a0.shape, chunks)
            indices = _chunk_indices(a0.shape, _unit(chunks))
            if vesselness:
                import volscissors as vs

                nz, ny, nx = a0.shape
                halo = vs.vesselness_halo((nx, ny, nz), spacing_xyz, scales)
                c = _run([delayed(_structure_task)(src0, i, spacing_xyz, scales, halo) for i in indices])
                c_per_scale = [max(v) for v in zip(*c)]
                stride = vs.percentile_sample_stride(a0.size)
                resp = _new_level(os.path.join(tmp, "response"), a0.shape, chunks, compressor=None)
                samples = _run([delayed(_response_task)(src0, resp, i, spacing_xyz, scales, polarity, c_per_scale,
                                                        halo, stride) for i in indices])
                samples = np.concatenate(samples) if samples else np.zeros(0, np.float32)
                max_response = max(1e-12, float(vs.percentile(samples, vs.VESSELNESS_MAX_PERCENTILE, True)))
                _run([delayed(_vesselness_cost_task)(resp, level0, i, spacing_xyz, max_response, power)
                      for i in indices])
                shutil.rmtree(resp, ignore_errors=True)
                figures.update(c_per_scale=c_per_scale, max_response=max_response, halo=halo)
            else:
                _run([delayed(_intensity_task)(src0, level0, i, spacing_xyz, window, polarity, power)
                      for i in indices])
            figures["cost_seconds"] = time.perf_counter() - t1
            datasets = []
            level, scale, shape = 0, list(scale0), a0.shape
            while True:
                origin = [t + 0.5 * (s - s0) for t, s, s0 in zip(trans0, scale, scale0)]
                datasets.append({"path": str(level), "coordinateTransformations": [
                    {"type": "scale", "scale": scale}, {"type": "translation", "translation": origin}]})
                if max(shape[i] / chunks[i] for i in range(3)) <= 1 or level >= 15:
                    break
                shape = tuple((n + 1) // 2 for n in shape)
                below = os.path.join(tmp, str(level))
                level += 1
                scale = [2 * s for s in scale]
                here = _new_level(os.path.join(tmp, str(level)), shape, chunks)
                _run([delayed(_mean_task)(below, here, i) for i in _chunk_indices(shape, _unit(chunks))])
        root = zarr.open_group(tmp, mode="a")
        meta = {"cost": figures["cost"], "polarity": polarity, "power": power, "source": os.path.abspath(src)}
        meta.update({"window": list(window)} if not vesselness else
                    {"scales_mm": scales, "c_per_scale": figures["c_per_scale"],
                     "max_response": figures["max_response"]})
        root.attrs["multiscales"] = [{
            "version": "0.4", "name": os.path.basename(out), "type": "mean",
            "axes": [{"name": n, "type": "space", "unit": "millimeter"} for n in "zyx"],
            "datasets": datasets, "metadata": {"volscissors": meta}}]
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
    ap.add_argument("--cost", default="intensity", choices=["intensity", "auto", "vesselness"],
                    help="cost kind (default intensity; auto = intensity here; vesselness: Frangi, halo per block)")
    ap.add_argument("--scales", help="vesselness scales in mm, comma-separated (default 1,2,3 x the smallest spacing)")
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
        scales = None
        if a.scales:
            try:
                scales = [float(v) for v in a.scales.split(",")]
            except ValueError:
                raise UsageError(f"--scales '{a.scales}': expected mm values separated by commas")
            if a.cost != "vesselness":
                raise UsageError("--scales is for --cost vesselness")
            if not all(math.isfinite(v) and v > 0 for v in scales):
                raise UsageError(f"--scales '{a.scales}': values must be > 0")
        if window is not None and a.cost == "vesselness":
            raise UsageError("--window is for --cost intensity (vesselness normalises by its own percentile)")
        fig = build_pyramid(a.input, a.out, window, a.polarity, a.power, a.scheduler, a.workers, cost=a.cost,
                            scales=scales)
    except UsageError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except (OSError, ValueError, KeyError, RuntimeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    what = (f"window {fig['window'][0]:.6g}..{fig['window'][1]:.6g}" if "window" in fig else
            f"max response {fig['max_response']:.6g} (p99.5 of V > 0), halo {fig['halo']} voxels")
    print(f"cost {fig['cost']} {what}: {fig['levels']} levels -> {a.out} ({fig['seconds']:.1f} s)")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(fig, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
