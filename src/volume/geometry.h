// Volume geometry: the mapping between voxel index space and world (patient, mm) space.
//   world = origin + direction * diag(spacing) * index
// Index coordinates are 0-based (x, y, z) with x fastest in memory. Spacing is in mm,
// direction is a 3x3 matrix whose columns are the world directions of the index axes
// (ITK/NIfTI-sform convention, LPS world as ITK reads it). Spacing and direction are
// never optional: every volume carries them.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>

namespace vs {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Index3 = std::array<int64_t, 3>;

struct Geometry {
  Index3 dims{0, 0, 0};               // voxels along x, y, z
  Vec3 spacing{1.0, 1.0, 1.0};        // mm per voxel along x, y, z (all > 0)
  Vec3 origin{0.0, 0.0, 0.0};         // world position of voxel (0,0,0), mm
  Mat3 direction = Mat3::Identity();  // columns: world direction of each index axis

  int64_t voxelCount() const { return dims[0] * dims[1] * dims[2]; }
  bool contains(int64_t x, int64_t y, int64_t z) const {
    return x >= 0 && y >= 0 && z >= 0 && x < dims[0] && y < dims[1] && z < dims[2];
  }
  bool contains(const Index3& i) const { return contains(i[0], i[1], i[2]); }
  // Continuous index inside [0, dims-1] on every axis.
  bool containsContinuous(const Vec3& i) const;
  // Linear offset of voxel (x,y,z): x + dims.x * (y + dims.y * z).
  int64_t linear(int64_t x, int64_t y, int64_t z) const { return x + dims[0] * (y + dims[1] * z); }
  Index3 unlinear(int64_t i) const { return {i % dims[0], (i / dims[0]) % dims[1], i / (dims[0] * dims[1])}; }

  Vec3 indexToWorld(const Vec3& index) const;
  Vec3 worldToIndex(const Vec3& world) const;
  // Physical length (mm) of an index-space step d (e.g. a neighbour offset).
  double stepLength(const Vec3& d) const;
  bool is2D() const { return dims[2] == 1; }
  // True when a world point lies within one voxel of the volume (continuous index in
  // [-1, dims] on every axis): the one sanity check of overlays against their volume.
  bool nearVolume(const Vec3& world) const;

  // Throws InvalidArgument unless dims >= 1, spacing finite and > 0, direction invertible.
  void validate() const;
  // One-line description "256x256x108, 0.957x0.957x1.5 mm".
  std::string describe() const;
};

// Nearest voxel index to a continuous index (rounding half away from zero).
Index3 roundIndex(const Vec3& continuousIndex);

}  // namespace vs
