"""isosurface, cut and surface from Python against analytic shapes (sphere, box)."""
import numpy as np
import pytest

import volscissors as vs


def _volume(dims, spacing, signed_distance):
    """100 inside, 0 outside, a 1 mm linear ramp across the boundary (signed distance > 0 inside)."""
    x, y, z = np.meshgrid(*(np.arange(n) * s for n, s in zip(dims, spacing)), indexing="ij")
    a = 100 * np.clip(0.5 + signed_distance(x, y, z), 0, 1)
    return vs.Volume(a.transpose(2, 1, 0), spacing=spacing, dtype="float32")  # [x,y,z] -> [z,y,x]


def test_isosurface_of_an_anisotropic_sphere_lies_on_the_sphere(tmp_path):
    c, r = np.array([16.0, 15.0, 17.0]), 9.0
    v = _volume((40, 32, 24), (0.8, 1.0, 1.5), lambda x, y, z: r - np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 +
                                                                          (z - c[2]) ** 2))
    m = vs.isosurface(v, iso=50)
    d = np.linalg.norm(m.vertices - c, axis=1)
    assert np.abs(d - r).max() < 0.3
    assert np.all(np.einsum("ij,ij->i", m.normals, m.vertices - c) > 0)  # outward
    assert m.triangles.max() < len(m.vertices) and len(m) > 100
    out = tmp_path / "sphere.ply"
    m.save(str(out))
    assert out.stat().st_size > 0
    with pytest.raises(vs.DataError):
        vs.isosurface(v, iso=1000)


def _box():
    lo, hi = np.array([8.3, 7.6, 6.2]), np.array([31.4, 28.5, 37.7])
    return _volume((40, 36, 44), (1, 1, 1), lambda x, y, z: np.minimum.reduce(
        [x - lo[0], y - lo[1], z - lo[2], hi[0] - x, hi[1] - y, hi[2] - z])), lo, hi


def test_cut_a_box_around_its_waist():
    v, lo, hi = _box()
    z0 = 15.3
    points = [(lo[0], 12, z0), (lo[0], 24, z0), (20, hi[1], z0), (hi[0], 24, z0), (hi[0], 12, z0), (20, lo[1], z0)]
    labels = vs.cut(v, iso=50, points=points)
    L, obj = labels.array, v.array >= 50  # [z, y, x]
    assert labels.dtype == "uint8" and labels.dims == v.dims
    assert np.array_equal(L > 0, obj)  # every object voxel labelled, nothing else
    zs = np.arange(L.shape[0])[:, None, None]
    below, above = obj & (zs < z0 - 1.5), obj & (zs > z0 + 1.5)
    assert (L[below] == 2).mean() > 0.99 and (L[above] == 1).mean() > 0.99  # the smaller part is cut
    kept = vs.cut(v, iso=50, points=points, keep=(20, 18, 10))
    assert kept.array[10, 18, 20] == 1 and kept.array[30, 18, 20] == 2
    with pytest.raises(ValueError, match="3 points"):
        vs.cut(v, iso=50, points=points[:2])
    with pytest.raises(ValueError, match="outside"):
        vs.cut(v, iso=50, points=[(0, 0, 0), (1, 1, 1), (99, 1, 1)])
    # The weights of the CLI (eq. 15-18 and eq. 13) with the same defaults and checks.
    same = vs.cut(v, iso=50, points=points, wg=1.0, wc=0.1, wp=1.0, wd=0.5, contour_wg=0.45, contour_wn=0.45,
                  contour_wl=0.1)
    assert np.array_equal(same.array, L)
    for bad in ({"wg": -1}, {"wc": 0}, {"wd": 2}, {"contour_wl": 0}):
        with pytest.raises(ValueError, match="w_"):
            vs.cut(v, iso=50, points=points, **bad)


def test_closed_surface_of_a_sphere_from_three_contours():
    c, r = np.array([20.0, 20.0, 20.0]), 12.0
    v = _volume((41, 41, 41), (1, 1, 1), lambda x, y, z: r - np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 +
                                                                     (z - c[2]) ** 2))
    m = vs.surface(v, planes=(20, 20, 20), iso=50, level=3, closed=True)
    d = np.linalg.norm(m.vertices - c, axis=1)
    assert np.abs(d - r).max() < 0.75 and len(m) >= 8 * 16
    with pytest.raises(ValueError):
        vs.surface(v, planes=(20, 20, 99))


def _read_obj(path):
    """Vertices and triangles of a Wavefront OBJ as the CLI writes it."""
    v, f = [], []
    for line in open(path):
        parts = line.split()
        if parts and parts[0] == "v":
            v.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "f":
            f.append([int(x.split("/")[0]) - 1 for x in parts[1:4]])
    return np.array(v), np.array(f)


def test_surface_and_cut_equal_the_cli_with_its_defaults(tmp_path):
    from conftest import cli
    c, r = np.array([20.0, 19.0, 21.0]), 11.0
    v = _volume((42, 40, 44), (0.9, 1.0, 1.1), lambda x, y, z: r - np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 +
                                                                         (z - c[2]) ** 2))
    path = tmp_path / "sphere.nii.gz"
    vs.write(v, path)
    # surface: every option at its default on both sides (Otsu iso, level, octant, connectivity).
    cli("-q", "surface", path, "--planes", "22,19,19", "--out", tmp_path / "cli.obj")
    mesh = vs.surface(vs.read(path), planes=(22, 19, 19))
    verts, tris = _read_obj(tmp_path / "cli.obj")
    assert np.array_equal(mesh.triangles, tris)
    assert np.allclose(mesh.vertices, verts, rtol=0, atol=1e-4)  # the OBJ holds 6+ significant digits
    # cut: the points around the sphere's waist, default snap radius and side.
    z0 = 21
    points = [(c[0] + r * np.cos(a) / 0.9, c[1] + r * np.sin(a), z0) for a in np.linspace(0, 2 * np.pi, 7)[:-1]]
    cli("-q", "cut", path, "--iso", 50, "--points", ";".join(",".join(f"{q:.3f}" for q in p) for p in points),
        "--labels", tmp_path / "cli_labels.nii.gz")
    labels = vs.cut(vs.read(path), iso=50, points=[[float(f"{q:.3f}") for q in p] for p in points])
    assert np.array_equal(labels.array, vs.read(tmp_path / "cli_labels.nii.gz").array)
    assert set(np.unique(labels.array)) == {0, 1, 2}
