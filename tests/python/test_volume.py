"""Volume: zero-copy views, axis order and geometry against the CLI, explicit conversions, errors."""
import gc
import json
import os

import numpy as np
import pytest

import volscissors as vs
from conftest import cli, shared


def test_array_is_a_zero_copy_view_that_outlives_the_volume(vessels):
    path, _ = vessels
    v = vs.read(path)
    a, b = v.array, v.array
    assert np.shares_memory(a, b)
    assert a.flags.c_contiguous and a.flags.writeable
    assert a.shape == v.shape == tuple(reversed(v.dims))
    a[1, 2, 3] = 77
    assert v.array[1, 2, 3] == 77  # an edit through one view is seen by the next
    del v
    gc.collect()
    assert b[1, 2, 3] == 77  # the view keeps the voxels alive


def test_constructor_copies_once_and_edits_are_seen_by_calls(tmp_path):
    a = np.zeros((4, 5, 6), np.uint8)  # [z, y, x]
    v = vs.Volume(a, spacing=(0.5, 0.6, 2.0))
    assert v.dims == (6, 5, 4) and v.dtype == "uint8"
    assert not np.shares_memory(v.array, a)  # the one explicit copy
    v.array[3, 1, 2] = 200  # voxel x=2, y=1, z=3
    out = str(tmp_path / "v.nrrd")
    vs.write(v, out)
    cli("info", out, "--json", tmp_path / "info.json")
    info = json.load(open(tmp_path / "info.json"))
    assert info["dims"] == [6, 5, 4] and info["range"] == [0, 200]
    back = vs.read(out)
    assert back.spacing == pytest.approx((0.5, 0.6, 2.0))
    assert np.array_equal(back.array, v.array)
    assert np.argwhere(back.array == 200).tolist() == [[3, 1, 2]]


def test_axis_order_matches_the_phantom_truth_and_the_cli_geometry(vessels, tmp_path):
    path, truth = vessels
    v = vs.read(path)
    x, y, z = truth["root_voxel"]
    # The root lies in the brightest structure: array[z, y, x] is bright, the transposed index is not.
    assert v.array[z, y, x] > np.percentile(v.array, 99)
    cli("info", path, "--json", tmp_path / "info.json")
    info = json.load(open(tmp_path / "info.json"))
    assert list(v.dims) == info["dims"]
    assert v.spacing == pytest.approx(tuple(info["spacing"]))
    assert v.origin == pytest.approx(tuple(info["origin"]))
    w = v.index_to_world([[x, y, z]])[0]
    assert w == pytest.approx(np.array(v.origin) + np.array(v.spacing) * [x, y, z])
    assert v.world_to_index(w)[0] == pytest.approx([x, y, z])


def test_real_ct_round_trip_keeps_voxels_and_geometry(tmp_path):
    path = shared("chest_cta_totalseg/ct_cropped.nii.gz")
    v = vs.read(path)
    assert v.dims == (120, 126, 164) and v.dtype == "int16"
    assert v.spacing == pytest.approx((1.5, 1.5, 1.5))
    out = str(tmp_path / "ct.nii.gz")
    vs.write(v, out)
    back = vs.read(out)
    assert np.array_equal(back.array, v.array)
    assert back.origin == pytest.approx(v.origin) and np.allclose(back.direction, v.direction)


def test_other_dtypes_are_converted_only_when_asked():
    a = np.arange(24, dtype=np.float64).reshape(2, 3, 4)
    with pytest.raises(TypeError, match="float32"):
        vs.Volume(a)
    v = vs.Volume(a, dtype="float32")
    assert v.dtype == "float32" and np.array_equal(v.array, a.astype(np.float32))
    # Fortran order (e.g. a transposed nibabel array) is copied once into [z, y, x] order.
    f = np.asfortranarray(a.astype(np.float32))
    assert np.array_equal(vs.Volume(f).array, a)
    img = vs.Volume(np.ones((3, 7), np.int16))  # a 2D image is one slice
    assert img.dims == (7, 3, 1)


@pytest.mark.parametrize("shape", [(5,), (2, 2, 2, 2), (0, 3, 3)])
def test_arrays_that_are_not_volumes_are_refused(shape):
    with pytest.raises(ValueError):
        vs.Volume(np.zeros(shape, np.uint8))


@pytest.mark.parametrize("spacing", [(1, 1), (1, 0, 1), (1, float("nan"), 1), (1, -2, 1), "1,1,1"])
def test_bad_spacing_is_a_value_error(spacing):
    with pytest.raises(ValueError, match="spacing"):
        vs.Volume(np.zeros((2, 2, 2), np.uint8), spacing=spacing)
    v = vs.Volume(np.zeros((2, 2, 2), np.uint8))
    with pytest.raises(ValueError, match="spacing"):
        v.spacing = spacing
    assert v.spacing == (1, 1, 1)


def test_bad_direction_is_a_value_error():
    with pytest.raises(ValueError, match="direction"):
        vs.Volume(np.zeros((2, 2, 2), np.uint8), direction=np.zeros((3, 3)))
    with pytest.raises(ValueError, match="direction"):
        vs.Volume(np.zeros((2, 2, 2), np.uint8), direction=[1, 0, 0])


def test_file_errors_are_os_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        vs.read(tmp_path / "missing.nii.gz")
    bad = tmp_path / "corrupt.nii.gz"
    bad.write_bytes(b"\x1f\x8b not really gzip")
    with pytest.raises(OSError):
        vs.read(str(bad))
    v = vs.Volume(np.zeros((2, 2, 2), np.uint8))
    with pytest.raises(OSError):
        vs.write(v, tmp_path / "no" / "such" / "dir" / "v.nii.gz")
    with pytest.raises(OSError):
        vs.write(v, tmp_path / "v.unknown")
    assert sorted(os.listdir(tmp_path)) == ["corrupt.nii.gz"]


def test_functions_refuse_bare_arrays_with_a_hint():
    with pytest.raises(TypeError, match="spacing"):
        vs.trace(np.zeros((4, 4, 4), np.float32), root=(0, 0, 0), targets=[(3, 3, 3)])


def test_explicit_dtype_refuses_values_the_type_cannot_hold():
    with pytest.raises(ValueError, match="do not fit"):
        vs.Volume(np.full((2, 2, 2), 70000, np.int32), dtype="int16")  # NumPy would wrap it to 4464
    with pytest.raises(ValueError, match="NaN"):
        vs.Volume(np.full((2, 2, 2), np.nan, np.float32), dtype="uint8")
    with pytest.raises(ValueError, match="do not fit"):
        vs.Volume(np.full((2, 2, 2), -5, np.int16), dtype="uint8")  # not 251
    v = vs.Volume(np.full((2, 2, 2), 250.0), dtype="uint8")  # values that fit are converted
    assert v.dtype == "uint8" and int(v.array.max()) == 250


def test_direction_must_be_orthonormal():
    for bad in (np.diag([2.0, 1, 1]), [[1, 0.3, 0], [0, 1, 0], [0, 0, 1]]):
        with pytest.raises(ValueError, match="orthonormal"):
            vs.Volume(np.zeros((2, 2, 2), np.uint8), direction=bad)
    a = np.deg2rad(20)
    r = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]], np.float32)  # float32 rounding
    v = vs.Volume(np.zeros((2, 2, 2), np.uint8), direction=r)
    d = np.array(v.direction)
    assert np.allclose(d.T @ d, np.eye(3), atol=1e-12)


def test_trace_auto_terminals_out_of_range_is_a_value_error():
    vol = vs.Volume(np.zeros((8, 8, 8), np.float32))
    for n in (2**40, -1):
        with pytest.raises(ValueError, match="auto_terminals"):
            vs.trace(vol, root=(1, 1, 1), auto_terminals=n)


def test_read_warns_without_orientation_and_takes_a_code(tmp_path):
    # A raw NRRD header that states no orientation (as the shared head CT's).
    np.full(4 * 4 * 4, 7, np.int16).tofile(tmp_path / "v.raw")
    (tmp_path / "v.nhdr").write_text("NRRD0004\ntype: int16\ndimension: 3\nsizes: 4 4 4\nspacings: 1 1 1\n"
                                     "endian: little\nencoding: raw\ndata file: v.raw\n")
    with pytest.warns(UserWarning, match="states no orientation"):
        v = vs.read(str(tmp_path / "v.nhdr"))
    assert np.allclose(v.direction, np.eye(3))
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        las = vs.read(str(tmp_path / "v.nhdr"), orientation="LAS")
    assert np.allclose(las.direction, np.diag([1, -1, 1]))
    with pytest.raises(ValueError, match="orientation"):
        vs.read(str(tmp_path / "v.nhdr"), orientation="LRS")
