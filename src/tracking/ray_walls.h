// Each ray's wall at its own level in a wide lumen (issue 21, session 26 wide22; internal to
// src/tracking, used by castRays in centreline.cpp). Under a bias field a wide lumen's plateau and
// its background both vary across it, and a blurred wall crosses the one level half-way between the
// point's value and the median surroundings farther out on its bright side and nearer on its dim one:
// the chords' midpoints, and the point, move towards the bright side (503's trunk, radius 21 voxels,
// bias 0.33: 0.4-0.55 voxel along a stretch its rays centred).
#pragma once

#include <cstddef>
#include <vector>

#include "volume/sample.h"

namespace vs::centreline_detail {

// Where the median of `found` (the crossings of `level`, mm) is at least minMedianMm, every marched
// ray (every `stride`-th of dirsIndex, index units per mm, from ci) whose crossing radius[k] lies at
// least 6 steps out moves it to the crossing, within 2 steps of it, of the level half-way between its
// own lumen (the mean of 4 samples 2-5 steps inside the crossing) and its own background (4 samples
// 2-5 steps beyond); rays whose two sides do not differ as the lumen's do keep theirs. `found` is
// rebuilt from `radius`. Thin lumens (the median under minMedianMm) are left as they are: there the
// bands would reach across the lumen.
void localRayWalls(const TrilinearSampler& sample, const Vec3& ci, const std::vector<Vec3>& dirsIndex, double centre,
                   double level, double step, size_t stride, double minMedianMm, std::vector<double>& radius,
                   std::vector<double>& found);

}  // namespace vs::centreline_detail
