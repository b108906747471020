// The lumen model's upper edge (auto_cost.h; docs/notes/tracking.md session 15 bone1): values far beyond the
// lumen (bright: bone, calcium, metal) and the partial-volume shell around them are not lumen.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

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
// Per voxel: does its 3x3x3 neighbourhood hold a value beyond the edge (separable: x, then y, then z, on bytes)?
// Row by row, so that the compiler vectorises the byte ORs (one voxel at a time, with the bounds tests inside the
// loop, the three passes took the head CTA ~0.15 s CPU).
std::vector<uint8_t> besideBeyond(const VolumeF32& sm, bool bright, float hi) {
  const Geometry& g = sm.geometry();
  const size_t n = static_cast<size_t>(g.voxelCount());
  std::vector<uint8_t> a(n), b(n);
  const float* v = sm.data();
  const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2], slice = nx * ny;
  parallelFor(
      0, nz,
      [&](int64_t z0, int64_t z1) {
        for (int64_t i = z0 * slice; i < z1 * slice; ++i) a[static_cast<size_t>(i)] = bright ? v[i] > hi : v[i] < hi;
      },
      4);
  // to[row] = from[row - stride] | from[row] | from[row + stride] (the rows that exist), nx bytes.
  auto orRows = [nx](uint8_t* to, const uint8_t* mid, const uint8_t* lo, const uint8_t* up) {
    if (lo && up)
      for (int64_t x = 0; x < nx; ++x) to[x] = static_cast<uint8_t>(lo[x] | mid[x] | up[x]);
    else if (lo || up)
      for (int64_t x = 0; x < nx; ++x) to[x] = static_cast<uint8_t>(mid[x] | (lo ? lo : up)[x]);
    else
      for (int64_t x = 0; x < nx; ++x) to[x] = mid[x];
  };
  for (int axis = 0; axis < 3; ++axis) {
    const uint8_t* from = axis == 1 ? b.data() : a.data();
    uint8_t* to = axis == 1 ? a.data() : b.data();
    parallelFor(
        0, nz,
        [&](int64_t z0, int64_t z1) {
          for (int64_t z = z0; z < z1; ++z)
            for (int64_t y = 0; y < ny; ++y) {
              const int64_t i = g.linear(0, y, z);
              const uint8_t* f = from + i;
              uint8_t* t = to + i;
              if (axis == 0) {
                if (nx == 1) {
                  t[0] = f[0];
                  continue;
                }
                t[0] = static_cast<uint8_t>(f[0] | f[1]);
                for (int64_t x = 1; x + 1 < nx; ++x) t[x] = static_cast<uint8_t>(f[x - 1] | f[x] | f[x + 1]);
                t[nx - 1] = static_cast<uint8_t>(f[nx - 2] | f[nx - 1]);
              } else {
                const int64_t p = axis == 1 ? y : z, len = axis == 1 ? ny : nz, stride = axis == 1 ? nx : slice;
                orRows(t, f, p > 0 ? f - stride : nullptr, p + 1 < len ? f + stride : nullptr);
              }
            }
        },
        4);
  }
  return b;
}
}  // namespace

// A voxel tests its own value unless it lies in the shell: beside values beyond the edge and beside background
// (beyond the window) at once; then it tests its neighbourhood's most extreme value. Only voxels beside values
// beyond the edge can be in the shell, so the neighbourhood's extremes are taken there alone (bone is a small part
// of a volume; two whole-volume extreme filters cost the head CTA 0.3 s).
VolumeF32 upperTestValues(const VolumeF32& sm, const LumenEstimate& e) {
  const bool bright = e.polarity == TubePolarity::Bright;
  const float hi = static_cast<float>(e.upperHi), bg = static_cast<float>(bright ? e.windowLo : e.windowHi);
  const std::vector<uint8_t> beside = besideBeyond(sm, bright, hi);
  VolumeF32 out = sm;
  const Geometry& g = sm.geometry();
  const float* v = sm.data();
  float* o = out.data();
  parallelFor(
      0, g.dims[2],
      [&](int64_t z0, int64_t z1) {
        for (int64_t z = z0; z < z1; ++z)
          for (int64_t y = 0; y < g.dims[1]; ++y)
            for (int64_t x = 0; x < g.dims[0]; ++x) {
              const int64_t i = g.linear(x, y, z);
              // A value beyond the edge tests beyond it either way (its neighbourhood's extreme is further).
              if (!beside[static_cast<size_t>(i)] || (bright ? v[i] > hi : v[i] < hi)) continue;
              float most = v[i], least = v[i];
              for (int64_t dz = std::max<int64_t>(z - 1, 0); dz <= std::min(z + 1, g.dims[2] - 1); ++dz)
                for (int64_t dy = std::max<int64_t>(y - 1, 0); dy <= std::min(y + 1, g.dims[1] - 1); ++dy)
                  for (int64_t dx = std::max<int64_t>(x - 1, 0); dx <= std::min(x + 1, g.dims[0] - 1); ++dx) {
                    const float w = v[g.linear(dx, dy, dz)];
                    most = bright ? std::max(most, w) : std::min(most, w);
                    least = bright ? std::min(least, w) : std::max(least, w);
                  }
              if (bright ? least < bg : least > bg) o[i] = most;
            }
      },
      4);
  return out;
}

}  // namespace vs
