// The lumen model's upper edge (auto_cost.h; docs/notes/tracking.md session 15 bone1): values far beyond the
// lumen (bright: bone, calcium, metal) and the partial-volume shell around them are not lumen.
#include <algorithm>
#include <cstdio>
#include <string>

#include "tracking/auto_cost.h"
#include "util/parallel.h"

namespace vs {

namespace {
std::string upperFmt(const char* f, double a, double b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}
}  // namespace

double LumenEstimate::upperCap(double v) const {
  if (!hasUpperEdge()) return 1.0;
  return std::clamp((v - upperHi) / (upperLo - upperHi), 0.0, 1.0);  // both polarities (upperLo nearer to L)
}

// ", upper edge 149.4..162 (full lumen up to 1 contrast beyond the lumen, none from 1.5)".
std::string LumenEstimate::upperText() const {
  if (!hasUpperEdge()) return ", no upper edge";
  return upperFmt(polarity == TubePolarity::Bright ? ", upper edge %.6g..%.6g" : ", lower edge %.6g..%.6g", upperLo,
                  upperHi) +
         upperFmt(" (lumen up to %.3g contrasts beyond it, none from %.3g)", upperFraction, 1.5 * upperFraction);
}

namespace {
// The largest (max) or smallest value of each voxel and its 26 neighbours (separable: x, then y, then z).
VolumeF32 extreme3(const VolumeF32& sm, bool max) {
  const Geometry& g = sm.geometry();
  VolumeF32 a = sm, b = sm;
  for (int axis = 0; axis < 3; ++axis) {
    const VolumeF32& from = axis == 1 ? b : a;
    VolumeF32& to = axis == 1 ? a : b;
    const int64_t stride = axis == 0 ? 1 : axis == 1 ? g.dims[0] : g.dims[0] * g.dims[1], n = g.dims[axis];
    parallelFor(
        0, g.dims[2],
        [&](int64_t z0, int64_t z1) {
          for (int64_t z = z0; z < z1; ++z)
            for (int64_t y = 0; y < g.dims[1]; ++y)
              for (int64_t x = 0; x < g.dims[0]; ++x) {
                const int64_t i = g.linear(x, y, z), p = axis == 0 ? x : axis == 1 ? y : z;
                const float* f = from.data();
                float v = f[i];
                if (p > 0) v = max ? std::max(v, f[i - stride]) : std::min(v, f[i - stride]);
                if (p + 1 < n) v = max ? std::max(v, f[i + stride]) : std::min(v, f[i + stride]);
                to.data()[i] = v;
              }
        },
        4);
  }
  return b;
}
}  // namespace

VolumeF32 upperTestValues(const VolumeF32& sm, const LumenEstimate& e) {
  const bool bright = e.polarity == TubePolarity::Bright;
  VolumeF32 most = extreme3(sm, bright);
  const VolumeF32 least = extreme3(sm, !bright);
  const float hi = static_cast<float>(e.upperHi), bg = static_cast<float>(bright ? e.windowLo : e.windowHi);
  float* m = most.data();
  const float *l = least.data(), *v = sm.data();
  for (int64_t i = 0; i < sm.geometry().voxelCount(); ++i) {
    // The shell: beside values beyond the edge and beside background (beyond the window) at once.
    const bool shell = bright ? (m[i] > hi && l[i] < bg) : (m[i] < hi && l[i] > bg);
    if (!shell) m[i] = v[i];
  }
  return most;
}

}  // namespace vs
