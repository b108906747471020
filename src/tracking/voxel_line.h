// The straight voxel chain between two voxels, 26-connected: one voxel per step along the longest axis, each rounded.
// The one rasterisation of the tracker's path output, the pruned graph's long edges (a pruned path never costs less
// than the full-grid path through the same voxels) and the trunk join's bridge.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "volume/geometry.h"

namespace vs {

// Calls visit(q) for each voxel of the chain after a, up to and including b (none where a == b).
template <class Visit>
void forEachVoxelAfter(const Index3& a, const Index3& b, Visit&& visit) {
  const int64_t steps = std::max({std::abs(b[0] - a[0]), std::abs(b[1] - a[1]), std::abs(b[2] - a[2])});
  for (int64_t s = 1; s <= steps; ++s) {
    Index3 q;
    for (size_t c = 0; c < 3; ++c)
      q[c] = a[c] +
             static_cast<int64_t>(std::llround(static_cast<double>((b[c] - a[c]) * s) / static_cast<double>(steps)));
    visit(q);
  }
}

// The chain's voxels after a, up to and including b.
inline std::vector<Index3> voxelsAfter(const Index3& a, const Index3& b) {
  std::vector<Index3> out;
  forEachVoxelAfter(a, b, [&](const Index3& q) { out.push_back(q); });
  return out;
}

}  // namespace vs
