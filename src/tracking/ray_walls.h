// Each ray's wall at its own level in a wide lumen (issue 21, session 26 wide22; internal to
// src/tracking, used by castRays in centreline.cpp). Under a bias field a wide lumen's plateau and
// its background both vary across it, and a blurred wall crosses the one level half-way between the
// point's value and the median surroundings farther out on its bright side and nearer on its dim one:
// the chords' midpoints, and the point, move towards the bright side (503's trunk, radius 21 voxels,
// bias 0.33: 0.4-0.55 voxel along a stretch its rays centred).
#pragma once

#include <Eigen/Core>
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

// Whether the chords through a point agree on one centre, as in a round section (castRays' rule 2): the rms of the
// chords' midpoint offsets (ray k and its opposite k + n/2, both crossed: radius >= 0) from the least-squares centre
// offset o2 (in the plane's u, v) is at most tolMm. On the vessel family a round tube's rms was 0.002-0.10 mm, a
// wide trunk's wall cut obliquely 0.7-1.0 mm (session 28 thin22).
bool chordsAgree(const std::vector<Vec3>& dirs, const std::vector<double>& radius, const Vec3& u, const Vec3& v,
                 size_t stride, const Eigen::Vector2d& o2, double tolMm);

}  // namespace vs::centreline_detail
