// Small synthetic images shared by the 2D tests (features, live-wire): header-only, no test
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

}  // namespace vs::test
