#include "volume/sample.h"

#include <algorithm>
#include <cmath>

namespace vs {

double sampleTrilinear(const VolumeF32& vol, const Vec3& p) {
  const Index3& d = vol.dims();
  double f[3];
  int64_t i0[3], i1[3];
  for (int a = 0; a < 3; ++a) {
    const double c = std::clamp(p[a], 0.0, static_cast<double>(d[static_cast<size_t>(a)] - 1));
    i0[a] = static_cast<int64_t>(std::floor(c));
    i1[a] = std::min(i0[a] + 1, d[static_cast<size_t>(a)] - 1);
    f[a] = c - static_cast<double>(i0[a]);
  }
  double v = 0;
  for (int k = 0; k < 8; ++k) {
    const int64_t x = (k & 1) ? i1[0] : i0[0], y = (k & 2) ? i1[1] : i0[1], z = (k & 4) ? i1[2] : i0[2];
    const double w = ((k & 1) ? f[0] : 1 - f[0]) * ((k & 2) ? f[1] : 1 - f[1]) * ((k & 4) ? f[2] : 1 - f[2]);
    if (w != 0) v += w * vol(x, y, z);
  }
  return v;
}

}  // namespace vs
