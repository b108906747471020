#include "surface/surface_cost.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "features/features3d.h"
#include "util/error.h"
#include "util/parallel.h"

namespace vs {

SurfaceCost computeSurfaceCost(const VolumeF32& volume, double iso, const SurfaceCostOptions& o, Progress& progress) {
  VS_REQUIRE(!volume.empty(), "surface cost: empty volume");
  VS_REQUIRE(std::isfinite(o.floor) && o.floor > 0, "surface cost: the floor must be > 0");
  VS_REQUIRE(std::isfinite(o.weightGradient) && o.weightGradient >= 0 && std::isfinite(o.weightIso) && o.weightIso >= 0,
             "surface cost: weights must be finite and >= 0");
  VS_REQUIRE(std::isfinite(iso), "surface cost: the iso-value must be finite");
  Features3DOptions fo;
  fo.laplacian = false;
  fo.robustMaxPercentile = o.robustMaxPercentile;
  const Features3D f = computeFeatures3D(volume, fo, progress);
  const Geometry& g = volume.geometry();
  const double h = std::min({g.spacing[0], g.spacing[1], g.spacing[2]});
  const double maxG = f.robustMaxGradient;
  const double tiny = 1e-6 * std::max(maxG, 1e-30);
  SurfaceCost sc;
  sc.iso = iso;
  sc.robustMaxGradient = maxG;
  sc.node.resize(static_cast<size_t>(volume.size()));
  const float* v = volume.data();
  parallelFor(
      0, volume.size(),
      [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
          const size_t k = static_cast<size_t>(i);
          const double G = f.gradientMagnitude[k];
          const double fg = 1.0 - std::min(G, maxG) / maxG;
          const double d = std::abs(static_cast<double>(v[k]) - iso) / std::max(G, tiny);
          sc.node[k] = static_cast<float>(o.floor + o.weightGradient * fg + o.weightIso * std::min(d / h, 1.0));
        }
      },
      1 << 16);
  char buf[200];
  std::snprintf(buf, sizeof buf, "surface (floor %.3g, w_g %.3g, w_iso %.3g, iso %.6g, maxG = p%.4g = %.4g)", o.floor,
                o.weightGradient, o.weightIso, iso, o.robustMaxPercentile, maxG);
  sc.description = buf;
  progress.report(1.0, "cost");
  return sc;
}

double otsuThreshold(const VolumeF32& volume) {
  VS_REQUIRE(!volume.empty(), "otsu: empty volume");
  const double lo = percentileOf(volume.voxels(), 0.1), hi = percentileOf(volume.voxels(), 99.9);
  if (!(hi > lo)) return lo;
  constexpr int kBins = 256;
  std::vector<double> hist(kBins, 0.0);
  for (float x : volume.voxels()) {
    const int b = std::clamp(static_cast<int>((x - lo) / (hi - lo) * kBins), 0, kBins - 1);
    hist[static_cast<size_t>(b)] += 1;
  }
  double total = 0, sumAll = 0;
  for (int b = 0; b < kBins; ++b) total += hist[b], sumAll += b * hist[b];
  double w0 = 0, sum0 = 0, best = -1;
  int bestBin = kBins / 2;
  for (int b = 0; b < kBins - 1; ++b) {
    w0 += hist[b];
    sum0 += b * hist[b];
    const double w1 = total - w0;
    if (w0 <= 0 || w1 <= 0) continue;
    const double m0 = sum0 / w0, m1 = (sumAll - sum0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) best = between, bestBin = b;
  }
  return lo + (bestBin + 1.0) / kBins * (hi - lo);
}

Vec3 sampleGradient(const VolumeF32& vol, const Vec3& p) {
  Vec3 g;
  const Vec3& s = vol.geometry().spacing;
  for (int a = 0; a < 3; ++a) {
    Vec3 lo = p, hi = p;
    lo[a] = std::max(0.0, p[a] - 1.0);
    hi[a] = std::min(static_cast<double>(vol.dims()[a] - 1), p[a] + 1.0);
    const double span = (hi[a] - lo[a]) * s[a];
    g[a] = span > 0 ? (sampleTrilinear(vol, hi) - sampleTrilinear(vol, lo)) / span : 0.0;
  }
  return g;
}

}  // namespace vs
