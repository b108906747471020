// An automatic terminal's end on its vessel's lumen (auto_terminals.cpp, issue 21). The lumen region is flooded on
// the node costs of a smoothed image, so beside a vessel's end in a vessel-only (masked) volume, where every voxel
// off the vessels is 0, it takes in a voxel or two of that background: the branch's farthest voxel can be one of them
// (the head CTA's terminals on zero voxels just past a vessel's end), and the path's refined end lies off the vessel.
#pragma once

#include <cstddef>
#include <vector>

#include "util/median.h"
#include "volume/volume.h"

namespace vs {

// An end voxel's share of the contrast from its background to its lumen level below which it is off the lumen.
constexpr double kOffLumen = 0.25;

// The index in `chain` (the far end's medial chain, the end first, back towards the paths so far) of the end on the
// lumen. Level: the chain's median intensity over its first 5 mm; background: the median of a shell 2 r + 2 .. 2 r + 6
// mm round the end (outside the vessel whatever its width; r = radiusMm); either polarity. When a voxel within
// 2 r + 2 x the largest spacing of the end is off the lumen (below kOffLumen of the contrast), the end moves back to
// the first voxel on the lumen beyond the last such; 0 (the end kept) when none is off, none beyond is on, or the
// end has no contrast to its background.
size_t endOnLumen(const VolumeF32& vol, const std::vector<Index3>& chain, double radiusMm);

// The distance (mm) between two voxels.
inline double mmBetween(const Geometry& g, const Index3& a, const Index3& b) {
  return g.stepLength(
      Vec3(static_cast<double>(a[0] - b[0]), static_cast<double>(a[1] - b[1]), static_cast<double>(a[2] - b[2])));
}

// The median (util/median.h) of the voxels whose centres lie rIn .. rOut mm from e or from the continuous point p
// (NaN when the shell is empty): a vessel's level and its background, at an end, along a route
// (terminal_gaps.h) and round a refined point (dim_points.h; a shell round the point's nearest voxel instead is up to
// 0.87 voxel off, enough to leave a point just below the half-maximum).
double shellMedian(const VolumeF32& vol, const Vec3& p, double rIn, double rOut);
double shellMedian(const VolumeF32& vol, const Index3& e, double rIn, double rOut);

}  // namespace vs
