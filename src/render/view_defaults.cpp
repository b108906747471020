#include "render/view_defaults.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "util/error.h"
#include "volume/slice.h"

namespace vs {

std::array<double, 6> defaultCutBox(const Geometry& g) {
  std::array<double, 6> box{};
  for (size_t a = 0; a < 3; ++a) {
    const double n = static_cast<double>(g.dims[a] - 1);
    box[a] = std::round(n * 0.25);
    box[a + 3] = std::round(n * 0.75);
  }
  return box;
}

WindowLevel quantileWindow(const AnyVolume& volume, double lo, double hi) {
  VS_REQUIRE(lo >= 0 && lo < hi && hi <= 1, "window quantiles must satisfy 0 <= lo < hi <= 1");
  const ValueRange r = valueRange(volume);
  constexpr int kBins = 4096;
  std::vector<int64_t> hist(kBins, 0);
  const double span = std::max(r.max - r.min, 1e-12);
  int64_t n = 0;
  std::visit(
      [&](const auto& vol) {
        for (auto x : vol.voxels()) {
          const double v = static_cast<double>(x);
          if (!std::isfinite(v)) continue;
          hist[static_cast<size_t>(std::clamp(static_cast<int>((v - r.min) / span * (kBins - 1)), 0, kBins - 1))]++;
          ++n;
        }
      },
      volume);
  auto quantile = [&](double f) {
    const auto target = static_cast<int64_t>(f * static_cast<double>(n));
    int64_t acc = 0;
    for (int i = 0; i < kBins; ++i) {
      acc += hist[static_cast<size_t>(i)];
      if (acc > target) return r.min + span * i / (kBins - 1);
    }
    return r.max;
  };
  double a = quantile(lo), b = quantile(hi);
  if (!(b > a)) a = r.min, b = r.max > r.min ? r.max : r.min + 1;
  return {b - a, 0.5 * (a + b)};
}

RenderOptions defaultRenderOptions(const AnyVolume& volume, RenderMode mode) {
  const Geometry& g = geometryOf(volume);
  RenderOptions o;
  o.mode = mode;
  o.planeAxis = axialIndexAxis(g);
  if (mode == RenderMode::CutBox) o.box = defaultCutBox(g);
  if (mode == RenderMode::Mip) o.window = quantileWindow(volume, 0.01, 0.9999);
  return o;
}

}  // namespace vs
