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

// Whether the grid's rim is the background its median `bg` is taken for (the split level is measured from it). Rim
// samples at or above `level` in a third component (neither the own nor the other lobe) mean the grid lies inside a
// lumen wider than itself, whose lobes at a level taken from its own median are the lumen's noise (6606's trunk: 4-27
// components at the level, 1-9 of them at the rim) - no neck between two tubes - where the rim holds at least as many
// samples as far below its median as the level lies above it: noise about the median puts as many samples that far
// down as up. A third tube the grid's edge cuts in the background (a sibling beside a thin fork, 511; a trunk turned
// round before its fork, 12124) puts more on the rim above the level than the background's noise puts that far below
// (kindA9: kindA6's form read every third component at the rim as a wider lumen and lost both forks' necks).
bool rimIsBackground(const std::vector<double>& val, const std::vector<int>& lab, int n, double bg, double level,
                     int own, int other);

}  // namespace vs
