// Test volumes for the box searches (box_search_test.cpp, box_rounds_test.cpp): node costs of a few values only (the
// auto cost's floor and ceiling are two), so that many routes tie exactly and only the settling order picks one.
#pragma once

#include <cstdint>
#include <random>

#include "tracking/box_search.h"

namespace vs::testing_box {

inline NodeCost3D fewValuedCost(const Index3& dims, const Vec3& spacing, std::mt19937& rng) {
  NodeCost3D c;
  c.kind = CostKind3D::Given;
  c.geometry.dims = dims;
  c.geometry.spacing = spacing;
  const float values[] = {0.001f, 0.001f, 0.5f, 1.0f, 1.0f};
  std::uniform_int_distribution<int> pick(0, 4);
  c.node.resize(static_cast<size_t>(dims[0] * dims[1] * dims[2]));
  for (float& v : c.node) v = values[pick(rng)];
  return c;
}

// A voxel drawn uniformly inside the box.
inline Index3 inside(const retrace::Box& b, std::mt19937& rng) {
  Index3 v;
  for (size_t a = 0; a < 3; ++a) v[a] = b.lo[a] + std::uniform_int_distribution<int64_t>(0, b.n[a] - 1)(rng);
  return v;
}

}  // namespace vs::testing_box
