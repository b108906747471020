#include "features/features3d.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "util/parallel.h"

namespace vs {

namespace {
inline int64_t clampi(int64_t v, int64_t lo, int64_t hi) { return v < lo ? lo : (v > hi ? hi : v); }
}  // namespace

Vec3 centralGradient(const VolumeF32& vol, int64_t x, int64_t y, int64_t z) {
  const Geometry& g = vol.geometry();
  const int64_t p[3] = {x, y, z};
  Vec3 out;
  for (int a = 0; a < 3; ++a) {
    int64_t lo[3] = {x, y, z}, hi[3] = {x, y, z};
    lo[a] = std::max<int64_t>(0, p[a] - 1);
    hi[a] = std::min<int64_t>(g.dims[a] - 1, p[a] + 1);
    const int64_t steps = hi[a] - lo[a];
    if (steps == 0) {
      out[a] = 0;
      continue;
    }
    const double d = static_cast<double>(vol(hi[0], hi[1], hi[2])) - static_cast<double>(vol(lo[0], lo[1], lo[2]));
    out[a] = d / (static_cast<double>(steps) * g.spacing[a]);
  }
  return out;
}

Index3 strongestGradientVoxel(const VolumeF32& vol, const Index3& p, double radius) {
  const Geometry& g = vol.geometry();
  VS_REQUIRE(g.contains(p), "gradient snap: point outside the volume " + g.describe());
  if (!(radius > 0)) return p;
  const int r = static_cast<int>(std::floor(radius));
  Index3 best = p;
  double bestG = -1, bestD = 0;
  for (int dz = -r; dz <= r; ++dz)
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        const double d2 = double(dx * dx + dy * dy + dz * dz);
        if (d2 > radius * radius) continue;
        const Index3 q{p[0] + dx, p[1] + dy, p[2] + dz};
        if (!g.contains(q)) continue;
        const double gm = centralGradient(vol, q[0], q[1], q[2]).squaredNorm();
        if (gm > bestG || (gm == bestG && d2 < bestD)) best = q, bestG = gm, bestD = d2;
      }
  return best;
}

size_t percentileSampleStride(size_t n) { return std::max<size_t>(1, n / (size_t{1} << 22)); }

float percentileOf(const std::vector<float>& values, double p, bool positiveOnly) {
  if (values.empty()) return 0.0f;
  // Subsample very large arrays with a fixed stride (deterministic, <= ~4M values).
  const size_t n = values.size();
  const size_t stride = percentileSampleStride(n);
  std::vector<float> copy;
  copy.reserve(n / stride + 1);
  for (size_t i = 0; i < n; i += stride)
    if (!positiveOnly || values[i] > 0.0f) copy.push_back(values[i]);
  if (copy.empty()) return 0.0f;
  if (p >= 100.0) return *std::max_element(copy.begin(), copy.end());
  const double pos = std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(copy.size() - 1);
  const size_t k = static_cast<size_t>(std::llround(pos));
  std::nth_element(copy.begin(), copy.begin() + static_cast<std::ptrdiff_t>(k), copy.end());
  return copy[k];
}

Features3D computeFeatures3D(const VolumeF32& vol, const Features3DOptions& opt, Progress& progress) {
  VS_REQUIRE(!vol.empty(), "computeFeatures3D: empty volume");
  VS_REQUIRE(
      opt.robustMaxPercentile > 0.0 && opt.robustMaxPercentile <= 100.0,
      "computeFeatures3D: robustMaxPercentile must be in (0, 100], got " + std::to_string(opt.robustMaxPercentile));
  requireFinite(AnyVolume(vol), "computeFeatures3D input");
  const Geometry& g = vol.geometry();
  const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  Features3D f;
  f.geometry = g;
  f.gradientMagnitude.assign(static_cast<size_t>(g.voxelCount()), 0.0f);
  if (opt.laplacian) f.laplacian.assign(static_cast<size_t>(g.voxelCount()), 0.0f);
  const float* v = vol.data();
  const double sx = g.spacing[0], sy = g.spacing[1], sz = g.spacing[2];
  const int64_t sxy = nx * ny;

  std::atomic<int64_t> done{0};
  parallelFor(0, nz, [&](int64_t z0, int64_t z1) {
    for (int64_t z = z0; z < z1; ++z) {
      progress.check();
      const int64_t zm = clampi(z - 1, 0, nz - 1), zp = clampi(z + 1, 0, nz - 1);
      const double dz = static_cast<double>(zp - zm) * sz;
      for (int64_t y = 0; y < ny; ++y) {
        const int64_t ym = clampi(y - 1, 0, ny - 1), yp = clampi(y + 1, 0, ny - 1);
        const double dy = static_cast<double>(yp - ym) * sy;
        for (int64_t x = 0; x < nx; ++x) {
          const int64_t xm = clampi(x - 1, 0, nx - 1), xp = clampi(x + 1, 0, nx - 1);
          const double dx = static_cast<double>(xp - xm) * sx;
          const int64_t i = x + nx * y + sxy * z;
          const double gx = dx > 0 ? (v[xp + nx * y + sxy * z] - v[xm + nx * y + sxy * z]) / dx : 0.0;
          const double gy = dy > 0 ? (v[x + nx * yp + sxy * z] - v[x + nx * ym + sxy * z]) / dy : 0.0;
          const double gz = dz > 0 ? (v[x + nx * y + sxy * zp] - v[x + nx * y + sxy * zm]) / dz : 0.0;
          f.gradientMagnitude[static_cast<size_t>(i)] = static_cast<float>(std::sqrt(gx * gx + gy * gy + gz * gz));
          if (opt.laplacian) {
            // eq. 24: (27 V - sum of the 3x3x3 block) / 26 = V - mean of the 26 neighbours.
            double sum = 0;
            for (int64_t c = -1; c <= 1; ++c) {
              const int64_t zz = clampi(z + c, 0, nz - 1);
              for (int64_t b = -1; b <= 1; ++b) {
                const int64_t yy = clampi(y + b, 0, ny - 1);
                const float* row = v + nx * yy + sxy * zz;
                sum += row[clampi(x - 1, 0, nx - 1)] + row[x] + row[clampi(x + 1, 0, nx - 1)];
              }
            }
            f.laplacian[static_cast<size_t>(i)] = static_cast<float>((27.0 * v[i] - sum) / 26.0);
          }
        }
      }
      const int64_t d = ++done;
      if ((d & 7) == 0) progress.report(0.9 * static_cast<double>(d) / static_cast<double>(nz), "features");
    }
  });
  f.maxGradient = *std::max_element(f.gradientMagnitude.begin(), f.gradientMagnitude.end());
  f.robustMaxGradient = std::min(f.maxGradient, percentileOf(f.gradientMagnitude, opt.robustMaxPercentile, true));
  if (!(f.robustMaxGradient > 0.0f)) f.robustMaxGradient = f.maxGradient > 0.0f ? f.maxGradient : 1.0f;
  progress.report(1.0, "features");
  return f;
}

}  // namespace vs
