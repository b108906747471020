"""OME-Zarr folders through vs.read / vs.write (issue 25), cross-checked with python3-zarr."""
import numpy as np
import pytest

import volscissors as vs


def test_zarr_round_trip_and_python_zarr_agrees(vessels, tmp_path):
    path, _ = vessels
    v = vs.read(path)
    out = tmp_path / "v.zarr"
    vs.write(v, out)
    back = vs.read(out)
    assert back.dims == v.dims and back.dtype == v.dtype
    assert np.array_equal(back.array, v.array)
    assert np.allclose(back.spacing, v.spacing)
    zarr = pytest.importorskip("zarr", reason="python3-zarr not installed (scripts/install-deps.sh)")
    g = zarr.open_group(str(out), mode="r")
    assert np.array_equal(g["0"][:], v.array)  # [z, y, x] on both sides
    levels = g.attrs["multiscales"][0]["datasets"]
    assert len(levels) == 1 and g["0"].chunks == (64, 64, 64)  # 64^3 fits one chunk: no coarser level


def test_zarr_bad_chunk_is_an_oserror_naming_it(vessels, tmp_path):
    path, _ = vessels
    out = tmp_path / "b.zarr"
    vs.write(vs.read(path), out)
    (out / "0" / "0.0.0").write_bytes(b"\x78\x01garbage")
    with pytest.raises(OSError, match="chunk 0.0.0"):
        vs.read(out)
