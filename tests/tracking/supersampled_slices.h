// Partial-volume section images for the cross-section tests (cross_section_test.cpp, section_shape_test.cpp): a
// 2D shape swept along z, its edge voxels at their covered share.
#pragma once

#include <cstdint>
#include <functional>

#include "volume/volume.h"

namespace vs::test_slices {

// A volume of `dims` whose voxels (x, y) are `inside` by 4x4 supersampling: bg + (fg - bg) x share.
inline VolumeF32 supersampled(const Index3& dims, double fg, double bg,
                              const std::function<bool(double, double)>& inside) {
  Geometry g;
  g.dims = dims;
  VolumeF32 v(g, static_cast<float>(bg));
  for (int64_t y = 0; y < dims[1]; ++y)
    for (int64_t x = 0; x < dims[0]; ++x) {
      double in = 0;
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) in += inside(double(x) + (a - 1.5) / 4.0, double(y) + (b - 1.5) / 4.0);
      for (int64_t z = 0; z < dims[2]; ++z) v(x, y, z) = static_cast<float>(bg + (fg - bg) * in / 16.0);
    }
  return v;
}

}  // namespace vs::test_slices
