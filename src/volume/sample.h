#pragma once
// Continuous sampling of a volume at a (fractional) index position.

#include <algorithm>
#include <array>
#include <cstdint>

#include "volume/volume.h"

namespace vs {

// Trilinear interpolation at a continuous index (x, y, z), clamped to the volume: the one sampler
// shared by the centreline refinement and the surface cost.
double sampleTrilinear(const VolumeF32& volume, const Vec3& index);

// The same interpolation bound to one volume, for hot loops (the centreline refinement takes
// ~100 samples per point and round): strides and bounds computed once, inlined, no branches
// per corner. Equal to sampleTrilinear up to floating-point rounding. The volume must outlive it.
class TrilinearSampler {
 public:
  explicit TrilinearSampler(const VolumeF32& volume) : data_(volume.data()) {
    const Index3& d = volume.dims();
    const std::array<int64_t, 3> stride{1, d[0], d[0] * d[1]};
    for (size_t a = 0; a < 3; ++a) {
      hi_[a] = static_cast<double>(d[a] - 1);
      lastCell_[a] = std::max<int64_t>(0, d[a] - 2);
      stride_[a] = stride[a];
      next_[a] = d[a] > 1 ? stride[a] : 0;  // an axis one voxel thick has no upper neighbour
    }
  }
  // Whether a continuous index lies in the volume (no clamping needed).
  bool inside(const Vec3& p) const {
    return p[0] >= 0 && p[0] <= hi_[0] && p[1] >= 0 && p[1] <= hi_[1] && p[2] >= 0 && p[2] <= hi_[2];
  }
  double at(const Vec3& p) const {
    double f[3];
    int64_t base = 0;
    for (size_t a = 0; a < 3; ++a) {
      const double c = std::clamp(p[static_cast<Eigen::Index>(a)], 0.0, hi_[a]);
      const int64_t i = std::min(static_cast<int64_t>(c), lastCell_[a]);
      f[a] = c - static_cast<double>(i);
      base += i * stride_[a];
    }
    const float* v = data_ + base;
    const int64_t x = next_[0], y = next_[1], z = next_[2];
    auto lerp = [](double a, double b, double t) { return a + t * (b - a); };
    const double c00 = lerp(v[0], v[x], f[0]), c10 = lerp(v[y], v[y + x], f[0]);
    const double c01 = lerp(v[z], v[z + x], f[0]), c11 = lerp(v[z + y], v[z + y + x], f[0]);
    return lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2]);
  }

 private:
  const float* data_;
  std::array<double, 3> hi_{};
  std::array<int64_t, 3> lastCell_{}, stride_{}, next_{};
};

}  // namespace vs
