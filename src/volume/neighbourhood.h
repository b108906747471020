// Visiting the voxels within a physical radius of a voxel, the loop that cost estimation,
// snapping and terminal suppression all need (one home instead of one copy each).
#pragma once
#include <cmath>
#include <cstdint>

#include "volume/geometry.h"

namespace vs {

// Calls fn(x, y, z, distanceMm) for every voxel of `g` in the box that holds the ball of
// `radiusMm` around `c` (half-extent ceil(radius / spacing) per axis, anisotropic spacing
// honoured), in z, y, x order, with its physical distance from `c`; voxels outside the volume
// are skipped. Callers choose what distance counts (a ball, a shell, bins).
template <class Fn>
void forEachVoxelNear(const Geometry& g, const Index3& c, double radiusMm, Fn&& fn) {
  int64_t ext[3];
  for (int a = 0; a < 3; ++a) ext[a] = static_cast<int64_t>(std::ceil(radiusMm / g.spacing[a]));
  for (int64_t dz = -ext[2]; dz <= ext[2]; ++dz)
    for (int64_t dy = -ext[1]; dy <= ext[1]; ++dy)
      for (int64_t dx = -ext[0]; dx <= ext[0]; ++dx) {
        const int64_t x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
        if (!g.contains(x, y, z)) continue;
        const double d = g.stepLength(Vec3(static_cast<double>(dx), static_cast<double>(dy), static_cast<double>(dz)));
        fn(x, y, z, d);
      }
}

}  // namespace vs
