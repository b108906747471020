// Refined points on a partial-volume dip of a thin vessel (dim_points.h).
#include "tracking/dim_points.h"

#include <cmath>
#include <vector>

#include "tracking/terminal_end.h"
#include "volume/sample.h"

namespace vs {

namespace {

// The refined points within reachMm of point k along the refined tree (k included).
void alongTree(const RefinedCentreline& r, const std::vector<std::vector<int32_t>>& children, const Vec3& sp, size_t k,
               double reachMm, std::vector<size_t>& out) {
  out.clear();
  struct Item {
    size_t at, from;
    double mm;
  };
  std::vector<Item> stack{{k, k, 0.0}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    out.push_back(it.at);
    auto visit = [&](size_t j) {
      if (j == it.from) return;
      const double mm = it.mm + (r.points[j] - r.points[it.at]).cwiseProduct(sp).norm();
      if (mm <= reachMm) stack.push_back({j, it.at, mm});
    };
    if (r.parent[it.at] >= 0) visit(static_cast<size_t>(r.parent[it.at]));
    for (const int32_t c : children[it.at]) visit(static_cast<size_t>(c));
  }
}

}  // namespace

size_t ridgeDimPoints(const VolumeF32& vol, RefinedCentreline& refined, int polarity) {
  const size_t n = refined.points.size();
  if (polarity == 0 || n < 2 || refined.parent.size() != n || refined.radiiMm.size() != n) return 0;
  const double sign = polarity > 0 ? 1.0 : -1.0;
  const Geometry& g = vol.geometry();
  const Vec3 sp = g.spacing;
  const TrilinearSampler sample(vol);
  std::vector<std::vector<int32_t>> children(n);
  for (size_t i = 0; i < n; ++i)
    if (refined.parent[i] >= 0) children[static_cast<size_t>(refined.parent[i])].push_back(static_cast<int32_t>(i));
  // Candidate offsets: a grid of an eighth of a voxel over the ball of half a voxel round the point (index space).
  std::vector<Vec3> offsets;
  for (int z = -4; z <= 4; ++z)
    for (int y = -4; y <= 4; ++y)
      for (int x = -4; x <= 4; ++x)
        if (x * x + y * y + z * z <= 16 && (x || y || z)) offsets.emplace_back(x / 8.0, y / 8.0, z / 8.0);
  size_t moves = 0;
  std::vector<size_t> near;
  std::vector<double> values, spread;
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<double> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = sign * sample.at(refined.points[i]);
    size_t moved = 0;
    for (size_t k = 0; k < n; ++k) {
      if (refined.parent[k] < 0) continue;
      if (k < refined.wideTrunk.size() && refined.wideTrunk[k])
        continue;  // on a wide trunk's axis: deep by construction
      alongTree(refined, children, sp, k, 5.0, near);
      values.clear();
      for (const size_t j : near) values.push_back(v[j]);
      const double level = medianOf(values);
      if (v[k] >= level) continue;
      const Vec3& p = refined.points[k];
      const Index3 c{std::llround(p[0]), std::llround(p[1]), std::llround(p[2])};
      const double r = refined.radiiMm[k];
      const double bg = sign * shellMedian(vol, c, 2 * r + 2, 2 * r + 6);
      if (std::isnan(bg)) continue;
      spread.clear();
      for (const double x : values) spread.push_back(std::abs(x - level));
      // No contrast beyond the level's own spread: one median absolute deviation, since a thin vessel's values vary
      // widely voxel to voxel (37..152 along the 3DRA's), where terminal_end's 3 would leave every such point.
      if (!(level - bg > medianOf(spread))) continue;
      if (v[k] >= 0.5 * (level + bg)) continue;
      Vec3 best = p;
      double bestV = v[k];
      for (const Vec3& o : offsets) {
        const Vec3 q = p + o;
        if (!sample.inside(q)) continue;
        if (const double s = sign * sample.at(q); s > bestV) bestV = s, best = q;
      }
      if (best != p) refined.points[k] = best, v[k] = bestV, ++moved;
    }
    moves += moved;
    if (!moved) break;
  }
  return moves;
}

}  // namespace vs
