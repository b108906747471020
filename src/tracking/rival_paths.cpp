#include "tracking/rival_paths.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <utility>

namespace vs {

namespace {

// The points met walking up from k over `lengthMm` of tree (k included).
void walkUp(const std::vector<Vec3>& a, const std::vector<int32_t>& parent, int32_t k, double lengthMm,
            std::vector<int32_t>& out) {
  out.clear();
  double len = 0;
  out.push_back(k);
  while (parent[static_cast<size_t>(k)] >= 0 && len <= lengthMm) {
    const int32_t p = parent[static_cast<size_t>(k)];
    len += (a[static_cast<size_t>(p)] - a[static_cast<size_t>(k)]).norm();
    out.push_back(p);
    k = p;
  }
}

}  // namespace

std::vector<Vec3> rivalAnchors(const std::vector<Vec3>& anchorMm, const std::vector<int32_t>& parent, double reachMm,
                               double forkMm, double minMm) {
  const size_t n = anchorMm.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Vec3> out(n, Vec3(nan, nan, nan));
  if (n < 2 || !(reachMm > 0)) return out;
  auto cellOf = [&](const Vec3& p, int a) { return static_cast<int64_t>(std::floor(p[a] / reachMm)); };
  auto key = [](int64_t x, int64_t y, int64_t z) { return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791); };
  std::unordered_multimap<int64_t, int32_t> grid;
  grid.reserve(n);
  for (size_t k = 0; k < n; ++k)
    grid.emplace(key(cellOf(anchorMm[k], 0), cellOf(anchorMm[k], 1), cellOf(anchorMm[k], 2)), static_cast<int32_t>(k));
  std::vector<int32_t> upK, upJ;
  std::vector<size_t> stamp(n, 0);  // k + 1 on the points of k's walk
  for (size_t k = 0; k < n; ++k) {
    const Vec3& p = anchorMm[k];
    // Candidates nearest first: the nearest that is another branch is the rival.
    std::vector<std::pair<double, int32_t>> cand;
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -1; dz <= 1; ++dz) {
          const auto range = grid.equal_range(key(cellOf(p, 0) + dx, cellOf(p, 1) + dy, cellOf(p, 2) + dz));
          for (auto it = range.first; it != range.second; ++it) {
            const double d = (anchorMm[static_cast<size_t>(it->second)] - p).norm();
            if (d >= minMm && d <= reachMm) cand.emplace_back(d, it->second);
          }
        }
    std::sort(cand.begin(), cand.end());
    for (const auto& [d, j] : cand) {
      walkUp(anchorMm, parent, static_cast<int32_t>(k), std::max(forkMm, 3 * d), upK);
      for (int32_t x : upK) stamp[static_cast<size_t>(x)] = k + 1;
      walkUp(anchorMm, parent, j, std::max(forkMm, 3 * d), upJ);
      bool meet = false;
      for (int32_t y : upJ) meet = meet || stamp[static_cast<size_t>(y)] == k + 1;
      for (int32_t x : upK) stamp[static_cast<size_t>(x)] = 0;
      if (meet) continue;
      out[k] = anchorMm[static_cast<size_t>(j)];
      break;
    }
  }
  return out;
}

double rivalPlaneDistance(const Vec3& c, const Vec3& d, const Vec3& own, const Vec3& rival) {
  if (std::isnan(rival[0])) return -1;
  const Vec3 nrm = (rival - own).normalized();
  const double ahead = nrm.dot(0.5 * (own + rival) - c);  // > 0: c on the own side
  const double s = nrm.dot(d);
  if (ahead <= 0 || s <= 1e-9) return -1;
  return ahead / s;
}

}  // namespace vs
