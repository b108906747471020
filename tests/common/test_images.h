// Small synthetic images shared by the 2D and 3D tests (features, costs, live-wire): header-only, no test
// executable of its own (tests/common has no .cpp).
#pragma once

#include <cstdint>
#include <functional>

#include "volume/volume.h"

namespace vs::test {

// A w x h one-slice float image with pixel spacing (su, sv) mm and value fn(u, v) at pixel (u, v).
inline VolumeF32 makeImage(int64_t w, int64_t h, double su, double sv,
                           const std::function<float(int64_t, int64_t)>& fn) {
  Geometry g;
  g.dims = {w, h, 1};
  g.spacing = {su, sv, 1.0};
  VolumeF32 vol(g);
  for (int64_t v = 0; v < h; ++v)
    for (int64_t u = 0; u < w; ++u) vol(u, v, 0) = fn(u, v);
  return vol;
}

// A 9 x 8 x 7 volume with spacing (mm) and the linear ramp 2x + 3y + 5z (index units): known
// gradients for the 3D feature and cost tests.
inline VolumeF32 makeRamp3D(const Vec3& spacing) {
  Geometry g;
  g.dims = {9, 8, 7};
  g.spacing = spacing;
  VolumeF32 v(g);
  for (int64_t z = 0; z < 7; ++z)
    for (int64_t y = 0; y < 8; ++y)
      for (int64_t x = 0; x < 9; ++x) v(x, y, z) = static_cast<float>(2 * x + 3 * y + 5 * z);
  return v;
}

}  // namespace vs::test
