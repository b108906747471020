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


def test_bad_arguments_exit_2_and_bad_input_exit_1(tmp_path):
    run = lambda *a: subprocess.run([sys.executable, "-m", "volscissors.pyramid", *map(str, a)], capture_output=True,
                                    text=True, env={**os.environ})
    r = run(tmp_path / "none.zarr", "--out", tmp_path / "o.zarr", "--window", "5,1")
    assert r.returncode == 2 and "--window" in r.stderr
    r = run(tmp_path / "none.zarr", "--out", tmp_path / "o.zarr", "--scheduler", "synchronous")
    assert r.returncode == 1 and "not a folder" in r.stderr
    assert not (tmp_path / "o.zarr").exists()
