"""bench/trace_measures.py: the wall distance of the airway criteria on a tube of known radius."""
import os
import sys

import numpy as np
import pytest

pytest.importorskip("scipy")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "bench"))
from trace_measures import airway_criteria, wall_distances_mm  # noqa: E402

SPACING = np.array([0.5, 0.5, 1.0])
RADIUS = 4.0  # mm
AXIS = (20.3, 18.6)  # voxel index x, y of the tube's axis (along z)


def tube_hu():
    """-1000 HU inside a straight tube of radius 4 mm along z (voxel centres), 40 HU outside."""
    x, y = np.meshgrid(np.arange(40), np.arange(40), indexing="ij")
    r = np.hypot((x - AXIS[0]) * SPACING[0], (y - AXIS[1]) * SPACING[1])
    return np.repeat(np.where(r <= RADIUS, -1000.0, 40.0)[:, :, None], 30, axis=2).astype(np.float32)


def test_wall_distance_is_radius_minus_offset():
    lumen = tube_hu() < -900
    offsets = np.array([0.0, 1.0, 2.0, 3.0, 3.5])  # mm from the axis along x
    pts = np.array([[AXIS[0] + d / SPACING[0], AXIS[1], 15.0] for d in offsets])
    got = wall_distances_mm(lumen, SPACING, pts)
    # The nearest outside voxel centre lies beyond the circle, by less than one voxel diagonal in-plane.
    assert np.all(got >= RADIUS - offsets - 1e-9)
    assert np.all(got <= RADIUS - offsets + np.hypot(*SPACING[:2]))
    assert np.all(np.diff(got) < 0)  # farther from the axis, nearer the wall


def test_airway_criteria_on_the_tube():
    hu = tube_hu()
    axis_pts = [[AXIS[0], AXIS[1], z] for z in range(2, 28)]
    # 3.95 mm off the axis: the nearest outside voxel centre (x 29, y 19) is 0.40 mm away
    near_wall = [[AXIS[0] + 3.95 / SPACING[0], AXIS[1], z] for z in range(2, 6)]
    report = {"paths": [
        {"target": [20, 19, 27], "length_mm": 25.0, "voxels": [[20, 19, z] for z in range(2, 28)], "points": axis_pts},
        {"target": [27, 19, 5], "length_mm": 3.0, "voxels": [[20, 19, z] for z in range(2, 6)], "points": near_wall}]}
    rows, overall = airway_criteria(hu, SPACING, report)
    assert rows[0]["near_wall"] == 0 and rows[1]["near_wall"] == 1
    assert overall["near_wall"] == pytest.approx(4 / 30)
    assert overall["max_voxel_hu"] == -1000
    assert not overall["pass"]  # 13 % of the points within 0.5 mm of the wall
    report["paths"].pop()
    assert airway_criteria(hu, SPACING, report)[1]["pass"]
