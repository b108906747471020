// Kissing tubes for the re-search tests (crossing_retrace_test.cpp, neck_retrace_test.cpp): a
// node cost and chains of voxels through capsules, and the kissing pair both files search across.
#pragma once

#include <algorithm>
#include <vector>

#include "cost/cost3d.h"
#include "tube_segments.h"

namespace vs::test_tubes {

inline Vec3 at(const Index3& v) { return Vec3(double(v[0]), double(v[1]), double(v[2])); }

// Node cost 0.001 inside any tube, 1 outside: the contact between touching tubes costs what their
// insides cost (no neck in the data). The tubes in mm, voxels `spacing` apart.
inline NodeCost3D tubeCost(const Index3& dims, const std::vector<Segment>& tubes, const Vec3& spacing = Vec3(1, 1, 1)) {
  NodeCost3D c;
  c.kind = CostKind3D::Given;
  c.geometry.dims = dims;
  c.geometry.spacing = spacing;
  c.node.assign(static_cast<size_t>(dims[0] * dims[1] * dims[2]), 1.0f);
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x)
        for (const Segment& s : tubes)
          if (distanceToSegment(s, Vec3(double(x), double(y), double(z)).cwiseProduct(spacing)) <= s.r)
            c.node[static_cast<size_t>(c.geometry.linear(x, y, z))] = 0.001f;
  return c;
}

// A chain through `corners` (straight 26-connected runs between them).
inline std::vector<Index3> chain(const std::vector<Index3>& corners) {
  std::vector<Index3> out{corners.front()};
  for (size_t c = 1; c < corners.size(); ++c)
    while (out.back() != corners[c]) {
      Index3 v = out.back();
      for (size_t a = 0; a < 3; ++a) v[a] += (corners[c][a] > v[a]) - (corners[c][a] < v[a]);
      out.push_back(v);
    }
  return out;
}

// The kissing pair of the tests: a trunk (radius 3) that goes on as A (radius 2.5) along
// y = 20, and B (radius 2), which bends away from the trunk and comes back to touch A (no gap)
// from x 44 to 80. kissingB() is B with the trunk.
inline std::vector<Segment> kissingB() {
  const Segment trunk{{2, 20, 8}, {20, 20, 8}, 3};
  const double yB = 20 + 2.5 + 2;
  return {trunk,
          {{20, 20, 8}, {26, 30, 8}, 2},
          {{26, 30, 8}, {34, 30, 8}, 2},
          {{34, 30, 8}, {44, yB, 8}, 2},
          {{44, yB, 8}, {80, yB, 8}, 2}};
}

inline std::vector<Segment> kissingPair() {
  std::vector<Segment> all = kissingB();
  all.push_back({{20, 20, 8}, {86, 20, 8}, 2.5});
  return all;
}

// The path's voxels outside every one of the tubes.
inline int voxelsOutside(const std::vector<Segment>& tubes, const std::vector<Index3>& p) {
  int n = 0;
  for (const Index3& v : p)
    n += std::none_of(tubes.begin(), tubes.end(), [&](const Segment& s) { return distanceToSegment(s, at(v)) <= s.r; });
  return n;
}

}  // namespace vs::test_tubes
