"""bench/trace_measures.py: the wall distance of the airway criteria on a tube of known radius."""
import os
import sys

import numpy as np
import pytest

pytest.importorskip("scipy")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "bench"))
from trace_measures import airway_criteria, branch_criteria, wall_distances_mm  # noqa: E402

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


def test_branch_criteria_counts_the_points_outside_on_a_stretch_the_trace_flags():
    """Two bright tubes along z (300 in 100, radius 2 voxels, axes at x 10 and 19) and a path that goes up the first,
    hops across the background at z 10 and goes up the second (a target no lumen joins to the root): its points in the
    gap are outside; those on the voxels the trace's own note flags as crossing without lumen are counted apart."""
    x, y = np.meshgrid(np.arange(30), np.arange(20), indexing="ij")
    disc = (np.hypot(x - 10, y - 10) <= 2) | (np.hypot(x - 19, y - 10) <= 2)
    vol = np.repeat(np.where(disc, 300.0, 100.0)[:, :, None], 30, axis=2).astype(np.float32)
    path = [[10, 10, z] for z in range(2, 11)] + [[c, 10, 10] for c in range(11, 19)] + \
        [[19, 10, z] for z in range(10, 28)]  # the gap x 13..16 is path voxels 11-14 of 35
    report = {"paths": [{"target": [19, 10, 27], "voxels": path, "points": path, "radii_mm": [1.0] * len(path)}]}
    spacing = np.array([1.0, 1.0, 1.0])
    overall = branch_criteria(vol, spacing, report)[1]
    assert overall["points_outside"] == 4 and "points_outside_flagged" not in overall  # no note: no key
    # The note as src/tracking/path_support.cpp writes it, for the gap's first two voxels only.
    report["notes"] = ["target #1 (19,10,27): its path crosses 1.0 mm without lumen from (13,10,10) to (14,10,10) "
                       "(path voxels 11-12 of 35): no lumen in the cost's model and intensity 100..100, contrast to "
                       "the local background 0 (median) to 0 (most), not beyond the noise spread 1; the path may not "
                       "follow a vessel there"]
    flagged = branch_criteria(vol, spacing, report)[1]
    assert flagged["points_outside"] == 4 and flagged["points_outside_flagged"] == 2
    report["notes"][0] = report["notes"][0].replace("of 35", "of 36")  # another path's note: not this one's
    assert "points_outside_flagged" not in branch_criteria(vol, spacing, report)[1]
