// An automatic terminal's route across background between two vessels (terminal_gaps.h).
#include "tracking/terminal_gaps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/terminal_end.h"

namespace vs {

std::vector<RouteGap> routeGaps(const VolumeF32& vol, const std::vector<Index3>& route, size_t from,
                                const std::function<double(const Index3&)>& radiusMm) {
  const Geometry& g = vol.geometry();
  const size_t n = route.size();
  std::vector<RouteGap> out;
  if (n < 3) return out;
  auto at = [&](size_t i) { return static_cast<double>(vol(route[i][0], route[i][1], route[i][2])); };
  std::vector<double> arc(n, 0.0);
  for (size_t i = 1; i < n; ++i) arc[i] = arc[i - 1] + mmBetween(g, route[i], route[i - 1]);
  constexpr double kAlongMm = 5.0;
  // Per voxel its verdict: 1 on the lumen, 0 off it (a RouteGap is kept for it), in order along the route.
  std::vector<int8_t> on(n, 1);
  std::vector<RouteGap> off(n);
  size_t lo = 0, hi = 0;                // the window [lo, hi) of voxels within kAlongMm of i
  std::vector<double> radius(n, -1.0);  // radiusMm per voxel, once (-1: not yet)
  double bg = 0, bgArc = -std::numeric_limits<double>::infinity(), bgR = -1;  // the last shell's median, where, r
  for (size_t i = from; i < n; ++i) {
    while (arc[i] - arc[lo] > kAlongMm) ++lo;
    while (hi < n && arc[hi] - arc[i] <= kAlongMm) ++hi;
    std::vector<double> near;
    double r = 0;
    for (size_t k = lo; k < hi; ++k) near.push_back(at(k));
    const double level = medianOf(near);
    for (double& x : near) x = std::abs(x - level);
    const double spread = medianOf(std::move(near));
    // Within the level's own spread: on the lumen whatever the background (spares the shell for most voxels).
    if (std::abs(at(i) - level) <= 3 * spread) continue;
    for (size_t k = lo; k < hi; ++k) {
      if (radius[k] < 0) radius[k] = radiusMm(route[k]);
      r = std::max(r, radius[k]);
    }
    // The background varies over the shell's own size, not voxel to voxel: one shell per half window along the route
    // and per largest spacing of its radius (a shell is ~1e5 voxels round a sinus).
    if (arc[i] - bgArc > 0.5 * kAlongMm || std::abs(r - bgR) > 0.5 * g.spacing.maxCoeff()) {
      bg = shellMedian(vol, route[i], 2 * r + 2, 2 * r + 6);
      bgArc = arc[i], bgR = r;
    }
    if (!(std::abs(level - bg) > 3 * spread)) continue;  // no lumen contrast here (or no shell)
    const double cut = bg + kOffLumen * (level - bg), sign = level > bg ? 1.0 : -1.0;
    if (sign * (at(i) - cut) >= 0) continue;
    on[i] = 0;
    off[i] = {i, cut, sign, r};
  }
  // A gap has the lumen on the route on both sides (an end past its vessel is terminal_end.h's).
  bool onBefore = false;
  std::vector<size_t> pending;
  for (size_t i = from; i < n; ++i) {
    if (!on[i]) {
      if (onBefore) pending.push_back(i);
      continue;
    }
    for (const size_t k : pending) out.push_back(off[k]);
    pending.clear();
    onBefore = true;
  }
  return out;
}

size_t cutGap(const VolumeF32& vol, const std::vector<int32_t>& slot, const Index3& v, const RouteGap& gap,
              std::vector<float>& weight) {
  const Geometry& g = vol.geometry();
  const double rad = 2 * (gap.radiusMm + g.spacing.maxCoeff());
  int64_t ext[3];
  for (int a = 0; a < 3; ++a) ext[a] = static_cast<int64_t>(std::ceil(rad / g.spacing[a]));
  size_t cut = 0;
  for (int64_t z = std::max<int64_t>(0, v[2] - ext[2]); z <= std::min(g.dims[2] - 1, v[2] + ext[2]); ++z)
    for (int64_t y = std::max<int64_t>(0, v[1] - ext[1]); y <= std::min(g.dims[1] - 1, v[1] + ext[1]); ++y)
      for (int64_t x = std::max<int64_t>(0, v[0] - ext[0]); x <= std::min(g.dims[0] - 1, v[0] + ext[0]); ++x) {
        const int32_t s = slot[static_cast<size_t>(g.linear(x, y, z))];
        if (s < 0 || mmBetween(g, {x, y, z}, v) > rad) continue;
        if (gap.sign * (static_cast<double>(vol(x, y, z)) - gap.cut) >= 0) continue;
        float& w = weight[static_cast<size_t>(s)];
        if (!std::isinf(w)) w = std::numeric_limits<float>::infinity(), ++cut;
      }
  return cut;
}

}  // namespace vs
