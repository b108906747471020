// Tests for chainIntoBlob (tracking/region_fronts.cpp, issue 21): a terminal's chain that leaves its tube into a blob
// much wider than the tube ends where the tube does; a chain along a plain tube is left as it is.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <queue>

#include "tracking/region_fronts.h"

using namespace vs;

namespace {

// A region on a 1 mm grid: a tube of radius 2 along y = z = 20 from x = 2 to x = tubeEnd, and (ballR > 0) a ball of
// radius ballR centred on the axis just past the tube's end. Its geodesic distances from the root (x = 2, on the
// axis) by Dijkstra over 26 neighbours; the chain along the axis to the region's far end on it.
struct Region {
  Geometry g;
  std::vector<int64_t> voxel;
  std::vector<std::array<int32_t, 3>> at;
  std::vector<int32_t> slot, pred;
  std::vector<double> dist;
  int32_t root = -1, end = -1;
};

Region tubeInto(int tubeEnd, double ballR) {
  Region r;
  r.g.dims = {80, 41, 41};
  r.g.spacing = Vec3(1, 1, 1);
  r.slot.assign(static_cast<size_t>(r.g.voxelCount()), -1);
  const double cx = tubeEnd + ballR - 1;
  int farX = 0;
  for (int z = 0; z < 41; ++z)
    for (int y = 0; y < 41; ++y)
      for (int x = 2; x < 80; ++x) {
        const double rr = std::hypot(y - 20.0, z - 20.0);
        const bool tube = x <= tubeEnd && rr <= 2.0;
        const bool ball = ballR > 0 && std::hypot(x - cx, rr) <= ballR;
        if (!tube && !ball) continue;
        r.slot[static_cast<size_t>(r.g.linear(x, y, z))] = static_cast<int32_t>(r.voxel.size());
        r.voxel.push_back(r.g.linear(x, y, z));
        r.at.push_back({x, y, z});
        if (y == 20 && z == 20) farX = std::max(farX, x);
      }
  const size_t L = r.voxel.size();
  r.dist.assign(L, std::numeric_limits<double>::infinity());
  r.root = r.slot[static_cast<size_t>(r.g.linear(2, 20, 20))];
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  r.dist[static_cast<size_t>(r.root)] = 0;
  q.push({0, r.root});
  while (!q.empty()) {
    const auto [d, s] = q.top();
    q.pop();
    if (d > r.dist[static_cast<size_t>(s)]) continue;
    const auto& p = r.at[static_cast<size_t>(s)];
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (!r.g.contains(p[0] + dx, p[1] + dy, p[2] + dz)) continue;
          const int32_t t = r.slot[static_cast<size_t>(r.g.linear(p[0] + dx, p[1] + dy, p[2] + dz))];
          const double nd = d + std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
          if (t >= 0 && nd < r.dist[static_cast<size_t>(t)]) r.dist[static_cast<size_t>(t)] = nd, q.push({nd, t});
        }
  }
  r.pred.assign(L, -1);
  for (int x = 3; x <= farX; ++x)
    r.pred[static_cast<size_t>(r.slot[static_cast<size_t>(r.g.linear(x, 20, 20))])] =
        r.slot[static_cast<size_t>(r.g.linear(x - 1, 20, 20))];
  r.end = r.slot[static_cast<size_t>(r.g.linear(farX, 20, 20))];
  return r;
}

ChainBlob blobOf(const Region& r) {
  std::vector<uint8_t> suppressed(r.voxel.size(), 0);
  suppressed[static_cast<size_t>(r.root)] = 1;
  return chainIntoBlob(r.g, 26, r.voxel, r.at, r.slot, r.dist, r.pred, suppressed, r.end);
}

}  // namespace

TEST(ChainBlob, AChainIntoABlobMuchWiderThanItsTubeEndsWhereTheTubeDoes) {
  const Region r = tubeInto(40, 12.0);  // a radius-2 tube (~13 mm^2) into a ball of radius 12 (its caps ~450 mm^2)
  const ChainBlob b = blobOf(r);
  ASSERT_GT(b.endIndex, 0u);
  const auto& e = r.at[static_cast<size_t>(b.end)];
  EXPECT_GE(e[0], 36);  // on the tube, at most a few voxels short of its end
  EXPECT_LE(e[0], 42);  // not in the ball
  EXPECT_GT(b.blobArea, 8 * b.tubeArea);
  EXPECT_FALSE(b.slots.empty());
}

TEST(ChainBlob, AChainAlongAPlainTubeIsLeftAsItIs) {
  const Region r = tubeInto(70, 0.0);
  EXPECT_EQ(blobOf(r).endIndex, 0u);
  EXPECT_EQ(blobOf(r).end, -1);
}
