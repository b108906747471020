"""Peer corpora: every NIfTI/Analyze file of nibabel's test data and every file of pydicom's test
data read as nibabel / pydicom read it (dims, spacing, origin, direction, every voxel value), or
refused with a message naming the file and the reason. Plus NIfTI files written with nibabel for
the header cases where readers differ (sform vs qform, units, scl_slope 0/NaN, 2D affine,
float32 near-orthonormal sform, negative pixdim).

The packages come from scripts/install-deps.sh (python3-nibabel, python3-pydicom); without them
the tests skip. Geometry in LPS mm: nibabel's RAS affine with x and y negated.
"""
import glob
import os

import numpy as np
import pytest

import volscissors as vs

nib = pytest.importorskip("nibabel")
pydicom = pytest.importorskip("pydicom")

NIB_DATA = os.path.join(os.path.dirname(nib.__file__), "tests", "data")
DCM_DATA = os.path.join(os.path.dirname(pydicom.__file__), "data", "test_files")


def _read(path):
    """(volume, None) or (None, message)."""
    try:
        return vs.read(path), None
    except Exception as e:  # noqa: BLE001 - any refusal is checked for its message
        return None, str(e)


def _check_refusal(path, message):
    name = os.path.basename(path)
    assert name in message, f"refusal does not name the file: {message}"
    reason = message.split(name, 1)[1].strip(" :")
    assert len(reason) > 8, f"refusal gives no reason: {message}"


def _geometry(v):
    return (np.array(v.dims), np.array(v.spacing), np.array(v.origin), np.array(v.direction))


def _nibabel_expected(img):
    """dims, spacing, origin, direction (LPS) as nibabel reads the header; origin/direction None
    when the header states no orientation (both codes 0)."""
    hdr = img.header
    shape = list(img.shape[:3]) + [1] * (3 - min(3, len(img.shape)))
    xyz = hdr.get_xyzt_units()[0] if hasattr(hdr, "get_xyzt_units") else "unknown"
    unit = {"meter": 1000.0, "micron": 0.001}.get(xyz, 1.0)
    codes = (int(hdr["sform_code"]), int(hdr["qform_code"])) if "sform_code" in hdr else (0, 0)
    if codes == (0, 0):
        zooms = np.abs(np.array(list(hdr.get_zooms()[:3]) + [1.0] * 3)[:3]) * unit
        zooms[zooms == 0] = 1.0
        return np.array(shape), zooms, None, None
    A = np.array(img.affine, float)
    A[:3] *= unit
    A[:2] *= -1
    M = A[:3, :3]
    sp = np.linalg.norm(M, axis=0)
    D = M / sp
    u, _, vt = np.linalg.svd(D)  # the reader orthonormalises float32 rounding
    return np.array(shape), sp, A[:3, 3], u @ vt


def _compare_nifti(path, v, img):
    dims, sp, origin, direction = _nibabel_expected(img)
    gd, gs, go, gdir = _geometry(v)
    assert list(gd) == list(dims), f"{path}: dims {gd} != nibabel {dims}"
    np.testing.assert_allclose(gs, sp, rtol=1e-4, atol=1e-5, err_msg=f"{path}: spacing")
    if origin is not None:
        np.testing.assert_allclose(go, origin, rtol=1e-5, atol=1e-3, err_msg=f"{path}: origin")
        np.testing.assert_allclose(gdir, direction, atol=1e-4, err_msg=f"{path}: direction")
    data = np.asanyarray(img.dataobj)
    while data.ndim > 3:
        data = data[..., 0]
    data = data.reshape(tuple(dims), order="F") if data.ndim < 3 else data
    want = np.transpose(data, (2, 1, 0)).astype(np.float64)
    got = np.asarray(v.array, np.float64)
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-5, equal_nan=True, err_msg=f"{path}: values")


def _nifti_files():
    out = []
    for pattern in ("*.nii", "*.nii.gz", "*.hdr"):
        out += sorted(glob.glob(os.path.join(NIB_DATA, pattern)))
    return out


@pytest.mark.parametrize("path", _nifti_files(), ids=os.path.basename)
def test_nibabel_test_data(path):
    v, err = _read(path)
    try:
        img = nib.load(path)
        np.asanyarray(img.dataobj)
    except Exception:  # noqa: BLE001 - nibabel cannot read it either: we must refuse clearly
        img = None
    if v is None:
        _check_refusal(path, err)
        return
    assert img is not None, f"{path}: read although nibabel refuses it"
    _compare_nifti(path, v, img)


def _dicom_expected(ds):
    cols, rows = int(ds.Columns), int(ds.Rows)
    # PixelSpacing, else ImagerPixelSpacing (projection radiographs: at the detector), else 1 mm.
    ps = [float(x) for x in ds.get("PixelSpacing", ds.get("ImagerPixelSpacing", [1, 1]))]
    spacing = [ps[1], ps[0]]
    iop = [float(x) for x in ds.get("ImageOrientationPatient", [1, 0, 0, 0, 1, 0])]
    r, c = np.array(iop[:3]), np.array(iop[3:])
    direction = np.column_stack([r, c, np.cross(r, c)])
    origin = [float(x) for x in ds.get("ImagePositionPatient", [0, 0, 0])]
    return [cols, rows, 1], spacing, origin, direction


def _dicom_files():
    return sorted(f for f in glob.glob(os.path.join(DCM_DATA, "**", "*"), recursive=True) if os.path.isfile(f))


@pytest.mark.parametrize("path", _dicom_files(), ids=lambda p: os.path.relpath(p, DCM_DATA))
def test_pydicom_test_data(path):
    from pydicom.pixel_data_handlers.util import apply_modality_lut

    ext = os.path.splitext(path)[1].lower()
    if ext not in ("", ".dcm"):
        v, err = _read(path)
        assert v is None  # not a volume extension: refused
        _check_refusal(path, err)
        return
    v, err = _read(path)
    if v is None:
        _check_refusal(path, err)
        return
    ds = pydicom.dcmread(path, force=True)
    dims, spacing, origin, direction = _dicom_expected(ds)
    gd, gs, go, gdir = _geometry(v)
    assert list(gd[:2]) == dims[:2], f"{path}: dims {gd} != pydicom {dims}"
    np.testing.assert_allclose(gs[:2], spacing, rtol=1e-5, err_msg=f"{path}: spacing")
    np.testing.assert_allclose(gdir, direction, atol=1e-4, err_msg=f"{path}: direction")
    # A file of a series (the dicomdirtests folders): the volume holds its folder's series;
    # this file is the slice whose position is the file's ImagePositionPatient.
    k = 0
    if gd[2] > 1:
        k = int(round(float(np.dot(np.array(origin) - go, gdir[:, 2])) / gs[2]))
        assert 0 <= k < gd[2], f"{path}: its position is not one of the volume's {gd[2]} slices"
    np.testing.assert_allclose(go + k * gs[2] * gdir[:, 2], origin, atol=1e-3, err_msg=f"{path}: origin")
    try:
        want = apply_modality_lut(ds.pixel_array, ds).astype(np.float64)
    except Exception:  # noqa: BLE001 - no pydicom decoder for this transfer syntax here
        return
    got = np.asarray(v.array, np.float64)[k]
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-3, err_msg=f"{path}: values")


# ---------------------------------------------------------------- NIfTI header cases (nibabel-written)
def _ramp(shape, dtype=np.int16):
    return (np.arange(np.prod(shape)).reshape(shape, order="F") % 251).astype(dtype)


def _save(img, tmp_path, name):
    path = str(tmp_path / name)
    nib.save(img, path)
    return path


def _both(path):
    v, err = _read(path)
    assert v is not None, err
    img = nib.load(path)
    _compare_nifti(path, v, img)
    return v


def test_sform_preferred_over_a_different_qform(tmp_path):
    img = nib.Nifti1Image(_ramp((6, 5, 4)), np.diag([2.0, 2.0, 3.0, 1.0]))
    q = np.diag([2.0, 2.0, 3.0, 1.0])
    q[:3, 3] = [35, 0, 0]
    img.set_qform(q, code=1)
    s = np.diag([2.0, 2.0, 3.0, 1.0])
    img.set_sform(s, code=2)
    v = _both(_save(img, tmp_path, "sq.nii"))
    assert abs(v.origin[0]) < 1e-6  # the sform's origin, not the qform's 35 mm


@pytest.mark.parametrize("unit,factor", [("meter", 1000.0), ("micron", 0.001), ("mm", 1.0)])
def test_units_apply_to_spacing_and_origin(tmp_path, unit, factor):
    A = np.diag([0.002, 0.003, 0.004, 1.0])
    A[:3, 3] = [0.01, -0.02, 0.03]
    img = nib.Nifti1Image(_ramp((4, 4, 3)), A)
    img.header.set_xyzt_units(xyz=unit)
    v = _both(_save(img, tmp_path, f"u_{unit}.nii"))
    np.testing.assert_allclose(v.spacing, np.array([0.002, 0.003, 0.004]) * factor, rtol=1e-5)
    np.testing.assert_allclose(v.origin, np.array([-0.01, 0.02, 0.03]) * factor, rtol=1e-5)


@pytest.mark.parametrize("slope", [0.0, float("nan")])
def test_scl_slope_zero_or_nan_means_no_scaling(tmp_path, slope):
    img = nib.Nifti1Image(_ramp((4, 4, 3)), np.eye(4))
    path = _save(img, tmp_path, "slope.nii")
    raw = bytearray(open(path, "rb").read())
    raw[112:116] = np.float32(slope).tobytes()
    raw[116:120] = np.float32(-1024).tobytes()
    open(path, "wb").write(bytes(raw))
    v, err = _read(path)
    assert v is not None, err
    np.testing.assert_array_equal(np.asarray(v.array), np.transpose(_ramp((4, 4, 3)), (2, 1, 0)))
    _compare_nifti(path, v, nib.load(path))


def test_2d_image_keeps_the_affine_z_offset(tmp_path):
    A = np.diag([0.5, 0.5, 2.0, 1.0])
    A[:3, 3] = [1, 2, 37.5]
    v = _both(_save(nib.Nifti1Image(_ramp((5, 4)), A), tmp_path, "flat.nii"))
    assert abs(v.origin[2] - 37.5) < 1e-5


def test_float32_near_orthonormal_sform_is_accepted(tmp_path):
    a = np.deg2rad(17.0)
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    A = np.eye(4)
    A[:3, :3] = (R @ np.diag([0.9, 0.9, 1.2])).astype(np.float32)
    A[0, 1] += 2e-4  # beyond float32 rounding, well below a real shear
    img = nib.Nifti1Image(_ramp((5, 5, 3)), A)
    img.set_qform(None, code=0)
    _both(_save(img, tmp_path, "nearortho.nii"))


def test_negative_pixdim_read_as_nibabel_does(tmp_path):
    img = nib.Nifti1Image(_ramp((4, 3, 2)), np.diag([-2.0, 2.0, 2.0, 1.0]))
    img.set_sform(None, code=0)
    img.set_qform(np.diag([-2.0, 2.0, 2.0, 1.0]), code=1)
    path = _save(img, tmp_path, "negpix.nii")
    raw = bytearray(open(path, "rb").read())
    raw[80:84] = np.float32(-2.0).tobytes()  # pixdim[1] < 0 (nibabel takes |pixdim|)
    open(path, "wb").write(bytes(raw))
    _both(path)
