// BlockSearch (block-sparse state, A* towards a set of targets) against the full Dijkstra of the
// in-memory engine on random small volumes: every target's cost, every path's validity.
#include "graph/block_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "graph/grid_graph.h"
#include "graph/shortest_path.h"
#include "util/error.h"

namespace vs {
namespace {

struct Case {
  std::array<int64_t, 3> dims;
  std::array<double, 3> spacing;
  std::vector<float> cost;
};

Case randomCase(std::mt19937& rng, bool walls, bool zeros) {
  std::uniform_int_distribution<int> d(3, 21);
  Case c;
  c.dims = {d(rng), d(rng), d(rng)};
  std::uniform_real_distribution<double> sp(0.4, 2.0);
  c.spacing = {sp(rng), sp(rng), sp(rng)};
  std::uniform_real_distribution<float> u(0.01f, 1.0f);
  std::uniform_real_distribution<float> p(0, 1);
  c.cost.resize(size_t(c.dims[0] * c.dims[1] * c.dims[2]));
  for (float& v : c.cost) {
    v = u(rng);
    if (walls && p(rng) < 0.15f) v = std::numeric_limits<float>::infinity();
    if (zeros && p(rng) < 0.05f) v = 0;
  }
  return c;
}

BlockCostSource sourceOf(const Case& c, int shift, bool goal) {
  BlockCostSource s;
  s.dims = c.dims;
  s.spacing = c.spacing;
  s.blockShift = shift;
  float lo = std::numeric_limits<float>::infinity();
  for (float v : c.cost) lo = std::min(lo, v);
  s.minCost = goal ? double(lo) : 0.0;
  s.fill = [&c, shift](const std::array<int64_t, 3>& b, std::span<float> out) {
    const int64_t B = int64_t(1) << shift;
    for (int64_t z = 0; z < B; ++z)
      for (int64_t y = 0; y < B; ++y)
        for (int64_t x = 0; x < B; ++x) {
          const int64_t gx = b[0] * B + x, gy = b[1] * B + y, gz = b[2] * B + z;
          float v = -1;  // outside the grid: must be ignored by the search
          if (gx < c.dims[0] && gy < c.dims[1] && gz < c.dims[2])
            v = c.cost[size_t(gx + c.dims[0] * (gy + c.dims[1] * gz))];
          out[size_t(x + B * (y + B * z))] = v;
        }
  };
  return s;
}

TEST(BlockSearch, EqualsFullDijkstraOnRandomVolumes) {
  std::mt19937 rng(20251);
  int checked = 0;
  for (int iter = 0; iter < 60; ++iter) {
    const bool walls = iter % 3 == 1, zeros = iter % 4 == 2;
    const Case c = randomCase(rng, walls, zeros);
    const GridGraph g(c.dims, c.spacing, 26);
    std::uniform_int_distribution<int64_t> pick(0, g.nodeCount() - 1);
    int64_t src = pick(rng);
    while (!std::isfinite(c.cost[size_t(src)])) src = pick(rng);
    ShortestPathSearch full(g, GridCost::nodes(c.cost), {src});
    full.runToCompletion();
    std::vector<std::array<int64_t, 3>> targets;
    for (int t = 0; t < 1 + iter % 5; ++t) {
      const auto p = g.coords(pick(rng));
      targets.push_back({p[0], p[1], p[2]});
    }
    const auto s3 = g.coords(src);
    for (bool goal : {false, true}) {
      BlockSearch bs(sourceOf(c, 2 + iter % 3, goal));
      for (int rep = 0; rep < 2; ++rep) {  // the second search reuses the pooled blocks
        const auto paths = bs.findPaths({s3[0], s3[1], s3[2]}, targets);
        ASSERT_EQ(paths.size(), targets.size());
        for (size_t i = 0; i < targets.size(); ++i) {
          const int64_t tn = g.node(targets[i][0], targets[i][1], targets[i][2]);
          const double ref = full.totalCost(tn);
          const Path& p = paths[i];
          if (!std::isfinite(ref)) {
            EXPECT_TRUE(p.empty()) << "iter " << iter;
            continue;
          }
          ASSERT_FALSE(p.empty()) << "iter " << iter;
          EXPECT_NEAR(p.cost, ref, 1e-12 * std::max(1.0, ref)) << "iter " << iter << " goal " << goal;
          // The path is connected, starts at the source, ends at the target, and its edge sum is its cost.
          EXPECT_EQ(p.nodes.front(), src);
          EXPECT_EQ(p.nodes.back(), tn);
          double sum = 0;
          for (size_t k = 1; k < p.voxels.size(); ++k) {
            const auto& a = p.voxels[k - 1];
            const auto& b = p.voxels[k];
            const int dx = int(b[0] - a[0]), dy = int(b[1] - a[1]), dz = int(b[2] - a[2]);
            const int dirk = g.direction(dx, dy, dz);
            ASSERT_GE(dirk, 0);
            sum += g.length(dirk) * 0.5 * (double(c.cost[size_t(p.nodes[k - 1])]) + double(c.cost[size_t(p.nodes[k])]));
          }
          EXPECT_NEAR(sum, ref, 1e-9 * std::max(1.0, ref));
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 200);
}

TEST(BlockSearch, GoalDirectedSettlesFewerNodesAndTouchesFewerBlocks) {
  // Uniform cost on a 96^3 grid: A* towards a target 40 voxels away settles a thin region.
  Case c;
  c.dims = {96, 96, 96};
  c.spacing = {1, 1, 1};
  c.cost.assign(size_t(96 * 96 * 96), 0.5f);
  BlockSearch dijkstra(sourceOf(c, 4, false)), astar(sourceOf(c, 4, true));
  const auto a = dijkstra.findPath({10, 48, 48}, {50, 48, 48});
  const auto b = astar.findPath({10, 48, 48}, {50, 48, 48});
  EXPECT_DOUBLE_EQ(a.cost, b.cost);
  EXPECT_DOUBLE_EQ(a.cost, 40 * 0.5);
  EXPECT_LT(astar.stats().settled * 20, dijkstra.stats().settled);
  EXPECT_LT(astar.stats().blocksTouched * 4, dijkstra.stats().blocksTouched);
  EXPECT_LT(astar.stats().blocksTouched, 6 * 6 * 6 * 6 / 10);
}

TEST(BlockSearch, BadInput) {
  Case c;
  c.dims = {8, 8, 8};
  c.spacing = {1, 1, 1};
  c.cost.assign(512, 1.0f);
  c.cost[size_t(3 + 8 * (4 + 8 * 5))] = std::numeric_limits<float>::quiet_NaN();
  BlockSearch bs(sourceOf(c, 2, false));
  EXPECT_THROW(bs.findPath({-1, 0, 0}, {1, 1, 1}), InvalidArgument);
  EXPECT_THROW(bs.findPath({0, 0, 0}, {8, 1, 1}), InvalidArgument);
  try {
    bs.findPath({0, 0, 0}, {7, 7, 7});
    FAIL() << "NaN accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("(3,4,5)"), std::string::npos) << e.what();
  }
  BlockCostSource bad = sourceOf(c, 2, false);
  bad.blockShift = 9;
  EXPECT_THROW(BlockSearch{bad}, InvalidArgument);
}

}  // namespace
}  // namespace vs
