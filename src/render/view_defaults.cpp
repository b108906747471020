#include "render/view_defaults.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/window_level.h"
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
  WindowHistogram histogram(valueRange(volume));
  std::visit(
      [&](const auto& vol) {
        for (auto x : vol.voxels()) histogram.add(static_cast<double>(x));
      },
      volume);
  return histogram.window(lo, hi);
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
