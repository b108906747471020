"""volscissors.pyramid (issue 25): the Dask cost volume equals the in-memory cost voxel for voxel,
its pyramid is readable by the core, and `trace --cost given` on it equals the intensity trace."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import volscissors as vs
from conftest import cli

pytest.importorskip("dask.array", reason="python3-dask not installed (scripts/install-deps.sh)")
pytest.importorskip("zarr", reason="python3-zarr not installed (scripts/install-deps.sh)")

from volscissors import pyramid  # noqa: E402


def test_dask_cost_equals_in_memory_cost_and_traces_the_same(vessels, tmp_path):
    path, truth = vessels
    v = vs.read(path)
    src = tmp_path / "in.zarr"
    # Input chunks of 16^3 (written with python-zarr, as another tool would): a 3-level pyramid.
    import zarr

    root_group = zarr.open_group(str(src), mode="w")
    root_group.create_dataset("0", data=v.array, chunks=(16, 16, 16), dimension_separator=".")
    sx, sy, sz = v.spacing
    root_group.attrs["multiscales"] = [{"version": "0.4", "axes": [
        {"name": n, "type": "space", "unit": "millimeter"} for n in "zyx"], "datasets": [
        {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [sz, sy, sx]}]}]}]
    out = tmp_path / "cost.zarr"
    fig = pyramid.build_pyramid(str(src), str(out), window=(20.0, 220.0), scheduler="synchronous")
    assert fig["levels"] == 3  # 64 -> 32 -> 16 voxels per side, chunks of 16
    c = vs.read(out)  # the core's reader: float32 costs
    ref = vs.cost(v, "intensity", window=(20.0, 220.0))
    assert c.dtype == "float32" and c.dims == v.dims
    assert np.array_equal(c.array, ref.array)
    # The chunked tracer on the cost volume (given) equals the chunked intensity trace on the image.
    root = ",".join(map(str, truth["root_voxel"]))
    tgt = ",".join(map(str, truth["terminals"][0]["voxel"]))
    r1, r2 = tmp_path / "r1.json", tmp_path / "r2.json"
    cli("trace", out, "--chunked-above", 0, "--cost", "given", "--root", root, "--target", tgt, "--json", r1)
    cli("trace", src, "--chunked-above", 0, "--cost", "intensity", "--window", "20,220", "--root", root, "--target",
        tgt, "--json", r2)
    p1, p2 = json.load(open(r1))["paths"][0], json.load(open(r2))["paths"][0]
    assert p1["cost"] == pytest.approx(p2["cost"], rel=1e-12)


def _write_ome_zarr(path, v, chunks):
    import zarr

    g = zarr.open_group(str(path), mode="w")
    g.create_dataset("0", data=v.array, chunks=chunks, dimension_separator=".")
    sx, sy, sz = v.spacing
    g.attrs["multiscales"] = [{"version": "0.4", "axes": [
        {"name": n, "type": "space", "unit": "millimeter"} for n in "zyx"], "datasets": [
        {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [sz, sy, sx]}]}]}]


def test_dask_vesselness_equals_in_memory_vesselness_and_levels_are_means(vessels, tmp_path):
    """The vesselness cost needs a halo and two whole-volume figures (Frangi's c per scale, the
    response's percentile): block by block it must still equal the in-memory cost exactly."""
    import zarr

    path, _ = vessels
    v = vs.read(path)
    src = tmp_path / "in.zarr"
    _write_ome_zarr(src, v, (16, 16, 16))
    out = tmp_path / "vcost.zarr"
    fig = pyramid.build_pyramid(str(src), str(out), scheduler="synchronous", cost="vesselness")
    ref = vs.cost(v, "vesselness")
    c = vs.read(out)
    assert fig["halo"] == vs.vesselness_halo(v.dims, v.spacing) and fig["halo"] > 1
    assert np.array_equal(c.array, ref.array), f"{np.count_nonzero(c.array != ref.array)} voxels differ"
    assert fig["c_per_scale"] == pytest.approx(vs.vesselness_structure_scale(v), rel=0, abs=0)
    # Level 1 holds the 2x2x2 means of level 0.
    g = zarr.open_group(str(out), mode="r")
    l0, l1 = g["0"][:], g["1"][:]
    z, y, x = l0.shape
    assert l1.shape == ((z + 1) // 2, (y + 1) // 2, (x + 1) // 2)
    even = l0[: z // 2 * 2, : y // 2 * 2, : x // 2 * 2]
    mean = even.reshape(z // 2, 2, y // 2, 2, x // 2, 2).mean(axis=(1, 3, 5))
    assert np.allclose(l1[: z // 2, : y // 2, : x // 2], mean, rtol=1e-6)
    # A chunk smaller than the halo still gives the same cost (the read region grows).
    out2 = tmp_path / "vcost8.zarr"
    src8 = tmp_path / "in8.zarr"
    _write_ome_zarr(src8, v, (8, 8, 8))
    pyramid.build_pyramid(str(src8), str(out2), scheduler="synchronous", cost="vesselness")
    assert np.array_equal(vs.read(out2).array, ref.array)
    assert vs.read(out2).dims == v.dims


def test_bad_arguments_exit_2_and_bad_input_exit_1(tmp_path):
    run = lambda *a: subprocess.run([sys.executable, "-m", "volscissors.pyramid", *map(str, a)], capture_output=True,
                                    text=True, env={**os.environ})
    r = run(tmp_path / "none.zarr", "--out", tmp_path / "o.zarr", "--window", "5,1")
    assert r.returncode == 2 and "--window" in r.stderr
    r = run(tmp_path / "none.zarr", "--out", tmp_path / "o.zarr", "--cost", "vesselness", "--window", "1,5")
    assert r.returncode == 2 and "--window is for --cost intensity" in r.stderr
    r = run(tmp_path / "none.zarr", "--out", tmp_path / "o.zarr", "--scales", "1,2")
    assert r.returncode == 2 and "--scales is for --cost vesselness" in r.stderr
    r = run(tmp_path / "none.zarr", "--out", tmp_path / "o.zarr", "--scheduler", "synchronous")
    assert r.returncode == 1 and "not a folder" in r.stderr
    assert not (tmp_path / "o.zarr").exists()


def test_missing_or_truncated_chunks_exit_1_naming_the_chunk(vessels, tmp_path):
    path, _ = vessels
    v = vs.read(path)
    run = lambda *a: subprocess.run([sys.executable, "-m", "volscissors.pyramid", *map(str, a)], capture_output=True,
                                    text=True, env={**os.environ})
    for cost in ("intensity", "vesselness"):
        src = tmp_path / f"in_{cost}.zarr"
        _write_ome_zarr(src, v, (16, 16, 16))
        os.remove(src / "0" / "1.2.3")  # python-zarr would read it as zeros
        out = tmp_path / f"o_{cost}.zarr"
        r = run(src, "--out", out, "--cost", cost, "--scheduler", "synchronous")
        assert r.returncode == 1 and "chunk 1.2.3 is missing" in r.stderr, r.stderr
        assert not out.exists() and not list(tmp_path.glob(f".o_{cost}.zarr.tmp*"))
    src = tmp_path / "in_cut.zarr"
    _write_ome_zarr(src, v, (16, 16, 16))
    chunk = src / "0" / "2.0.1"
    chunk.write_bytes(chunk.read_bytes()[:40])
    r = run(src, "--out", tmp_path / "o.zarr", "--window", "20,220", "--scheduler", "synchronous")
    assert r.returncode == 1 and "chunk 2.0.1 cannot be decoded" in r.stderr, r.stderr
    assert not (tmp_path / "o.zarr").exists()
