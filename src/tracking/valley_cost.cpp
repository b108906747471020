#include "tracking/valley_cost.h"

#include <algorithm>
#include <limits>

namespace vs {

double valleyDepth(const VolumeF32& sm, const std::vector<RingScale>& scales, int64_t x, int64_t y, int64_t z,
                   bool bright, double enough) {
  const Geometry& g = sm.geometry();
  const float* base = sm.data() + g.linear(x, y, z);
  const double v = *base;
  double best = -std::numeric_limits<double>::infinity();
  for (const RingScale& r : scales) {
    const bool inside = x >= r.reach[0] && x < g.dims[0] - r.reach[0] && y >= r.reach[1] &&
                        y < g.dims[1] - r.reach[1] && z >= r.reach[2] && z < g.dims[2] - r.reach[2];
    auto sample = [&](size_t j, int64_t sign) -> double {
      if (inside) return base[sign * r.linear[j]];
      const Index3& o = r.offset[j];
      return sm(std::clamp<int64_t>(x + sign * o[0], 0, g.dims[0] - 1),
                std::clamp<int64_t>(y + sign * o[1], 0, g.dims[1] - 1),
                std::clamp<int64_t>(z + sign * o[2], 0, g.dims[2] - 1));
    };
    // Inside, the pairs straight from the offsets' linear steps (session 47 speed2: the same samples and order).
    if (inside) {
      for (const int64_t step : r.linear) {
        const double a = base[step], b = base[-step];
        const double d = bright ? std::min(a, b) - v : v - std::max(a, b);
        if (d > best && (best = d) >= enough) return best;
      }
      continue;
    }
    for (size_t j = 0; j < r.offset.size(); ++j) {
      const double a = sample(j, 1), b = sample(j, -1);
      const double d = bright ? std::min(a, b) - v : v - std::max(a, b);
      if (d > best && (best = d) >= enough) return best;
    }
  }
  return best;
}

double capByValley(const VolumeF32& sm, const std::vector<RingScale>& scales, int64_t x, int64_t y, int64_t z,
                   bool bright, double s, double lo, double span) {
  if (!(s > 0) || scales.empty()) return s;
  // Depth at which the cap falls to s: deeper than that lowers s, at lo + span it is 0.
  const double depth = valleyDepth(sm, scales, x, y, z, bright, lo + span);
  const double u = std::clamp((depth - lo) / span, 0.0, 1.0);
  return std::min(s, 1.0 - u);
}

}  // namespace vs
