#pragma once

#include <vector>

namespace vs {

// Pieces of the neck re-search's section (neck_retrace.cpp's sectionAt): a square grid of n x n samples of the smoothed
// intensity (signed so that the lumen is high), row-major, the path's voxel at its centre (m, m), n = 2m + 1.

// The own lobe's peak: the local maximum a steepest ascent (8 neighbours) from the path's voxel reaches, kept within
// `reach` samples of the voxel (kindA5). Not the highest sample in that reach: on thick slices it can lie past a
// valley, on the neighbour's peak (7108), and then every reader of the section takes the neighbour for the route's
// tube.
int climbedPeak(const std::vector<double>& val, int n, int m, int reach);

// Whether the grid's rim is the background its median is taken for (the split level is measured from it): every rim
// sample at or above `level` lies in the own or the other lobe (a tube wider than the grid reaches its rim). A rim
// sample at the level in a third component means the grid lies inside a lumen wider than itself, whose lobes at a
// level taken from its own median are the lumen's noise (6606's trunk: 4-27 components at the level, 1-9 of them at the
// rim) - no neck between two tubes.
bool rimIsBackground(const std::vector<double>& val, const std::vector<int>& lab, int n, double level, int own,
                     int other);

}  // namespace vs
