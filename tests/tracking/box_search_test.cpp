// The re-searches' box Dijkstra (box_search.h; session 39 cache702): the same routes as the lazy priority queue it
// replaced - voxels settled in (distance, box index) order, ties included - with each voxel's entry kept once and no
// step cost read into a voxel already settled.
#include "tracking/box_search.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <queue>
#include <random>
#include <utility>
#include <vector>

#include "few_valued_cost.h"

namespace vs {
namespace {

using retrace::Box;
using retrace::Step;

// Main's boxPath before session 39 (f03ae67), word for word: a lazy std::priority_queue of (distance, index) pairs.
std::vector<Index3> lazyBoxPath(const NodeCost3D& cost, const Box& b, const std::vector<uint8_t>& blocked,
                                const std::vector<Step>& steps, const Index3& from, const Index3& to, double cap,
                                double* outCost) {
  const Geometry& g = cost.geometry;
  const int64_t n = b.size();
  std::vector<double> dist(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<int32_t> prev(static_cast<size_t>(n), -1);
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  const int64_t s = b.index(from), t = b.index(to);
  dist[static_cast<size_t>(s)] = 0;
  q.push({0.0, static_cast<int32_t>(s)});
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    if (d > dist[static_cast<size_t>(u)]) continue;
    if (d > cap) return {};
    if (u == t) break;
    const Index3 uv = b.voxel(u);
    const int64_t ul = g.linear(uv[0], uv[1], uv[2]);
    for (const Step& st : steps) {
      const Index3 v{uv[0] + st.d[0], uv[1] + st.d[1], uv[2] + st.d[2]};
      if (!b.in(v)) continue;
      const int64_t vi = b.index(v);
      if (blocked[static_cast<size_t>(vi)]) continue;
      const double nd = d + cost.edgeCost(ul, g.linear(v[0], v[1], v[2]), st.lengthMm);
      if (nd < dist[static_cast<size_t>(vi)]) {
        dist[static_cast<size_t>(vi)] = nd;
        prev[static_cast<size_t>(vi)] = u;
        q.push({nd, static_cast<int32_t>(vi)});
      }
    }
  }
  if (!std::isfinite(dist[static_cast<size_t>(t)])) return {};
  std::vector<Index3> path;
  for (int64_t i = t; i >= 0; i = prev[static_cast<size_t>(i)]) path.push_back(b.voxel(i));
  std::reverse(path.begin(), path.end());
  *outCost = dist[static_cast<size_t>(t)];
  return path;
}

using testing_box::fewValuedCost;
using testing_box::inside;

}  // namespace

TEST(BoxSearch, SettlesAsTheLazyQueueDid) {
  std::mt19937 rng(39702);
  int compared = 0, found = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Vec3 spacing = trial % 3 == 0 ? Vec3(1, 1, 1) : trial % 3 == 1 ? Vec3(0.94, 0.94, 2.28) : Vec3(0.5, 0.7, 1);
    const NodeCost3D cost = fewValuedCost({14, 11, 9}, spacing, rng);
    const Geometry& g = cost.geometry;
    // A box of the volume (at its faces or not), a sixth of it blocked, its ends open.
    Box b;
    for (size_t a = 0; a < 3; ++a) {
      b.lo[a] = std::uniform_int_distribution<int64_t>(0, 3)(rng);
      b.n[a] = std::uniform_int_distribution<int64_t>(3, g.dims[a] - b.lo[a])(rng);
    }
    std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
    std::bernoulli_distribution block(trial % 2 ? 0.17 : 0.4);
    for (uint8_t& v : blocked) v = block(rng) ? 1 : 0;
    const Index3 from = inside(b, rng), to = inside(b, rng);
    blocked[static_cast<size_t>(b.index(from))] = blocked[static_cast<size_t>(b.index(to))] = 0;
    const int connectivity = trial % 4 == 3 ? 6 : trial % 4 == 2 ? 18 : 26;
    const std::vector<Step> steps = retrace::stepsFor(g, connectivity);
    for (const double cap : {std::numeric_limits<double>::infinity(), 3.0}) {
      double c0 = -1, c1 = -1;
      const std::vector<Index3> p0 = lazyBoxPath(cost, b, blocked, steps, from, to, cap, &c0);
      retrace::BoxSearchStats st;
      const std::vector<Index3> p1 = retrace::boxPath(cost, b, blocked, steps, from, to, cap, &c1, &st);
      ASSERT_EQ(p0, p1) << "trial " << trial << " cap " << cap;
      EXPECT_EQ(c0, c1) << "trial " << trial;  // exactly: the same sums in the same order
      EXPECT_LE(st.entries, b.size());
      ++compared;
      found += p1.empty() ? 0 : 1;
    }
  }
  EXPECT_EQ(compared, 120);
  EXPECT_GT(found, 60);  // most searches reach their target
}

// Searched to the last voxel it settles (a uniform box from one corner to the opposite one, the largest index), the
// box search reads each step's cost once, from whichever end settles first - the box's 26-neighbour edges - and keeps
// one heap entry per voxel. The lazy queue read every edge from both ends (its step into a settled voxel was costed
// and refused) and pushed a voxel again for each shorter distance.
TEST(BoxSearch, ReadsEachStepCostOnce) {
  NodeCost3D cost;
  cost.kind = CostKind3D::Given;
  cost.geometry.dims = {7, 6, 5};
  cost.node.assign(7 * 6 * 5, 1.0f);
  Box b;
  b.n = cost.geometry.dims;
  const std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
  int64_t edges = 0;  // 26-neighbour pairs inside the box
  for (int64_t dz = -1; dz <= 1; ++dz)
    for (int64_t dy = -1; dy <= 1; ++dy)
      for (int64_t dx = -1; dx <= 1; ++dx)
        if (dx || dy || dz) edges += (7 - std::abs(dx)) * (6 - std::abs(dy)) * (5 - std::abs(dz));
  edges /= 2;
  double c = 0;
  retrace::BoxSearchStats st;
  const std::vector<Index3> p = retrace::boxPath(cost, b, blocked, retrace::stepsFor(cost.geometry, 26), {0, 0, 0},
                                                 {6, 5, 4}, std::numeric_limits<double>::infinity(), &c, &st);
  ASSERT_FALSE(p.empty());
  EXPECT_EQ(st.settled, b.size());
  EXPECT_EQ(st.entries, b.size());
  EXPECT_EQ(st.costsRead, edges);  // 1,871 (the lazy queue costed 3,742)
  std::printf("[box search] %lld voxels settled, %lld step costs read (%lld edges), %lld heap entries\n",
              static_cast<long long>(st.settled), static_cast<long long>(st.costsRead), static_cast<long long>(edges),
              static_cast<long long>(st.entries));
}

// Equal distances are settled by box index, the lower first (session 40 heap: the order the lazy queue, cache702's
// hand-written heap and Boost's d-ary heap all keep). On a uniform 3 x 3 x 1 box with six neighbours every monotone
// route from the corner (0,0,0) to (2,2,0) costs the same, and the one kept is the settling order's: the target's
// two neighbours at distance 3 are (2,1,0) (index 5) and (1,2,0) (index 7), so (2,1,0) settles first and is kept;
// its own two, (2,0,0) (index 2) and (1,1,0) (index 4), give (2,0,0) - the route runs along x first. Ties broken
// the other way would run along y first.
TEST(BoxSearch, SettlesTiesByBoxIndex) {
  NodeCost3D cost;
  cost.kind = CostKind3D::Given;
  cost.geometry.dims = {3, 3, 1};
  cost.node.assign(9, 1.0f);
  Box b;
  b.n = cost.geometry.dims;
  const std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
  double c = 0;
  retrace::BoxSearchStats st;
  const std::vector<Index3> p = retrace::boxPath(cost, b, blocked, retrace::stepsFor(cost.geometry, 6), {0, 0, 0},
                                                 {2, 2, 0}, std::numeric_limits<double>::infinity(), &c, &st);
  const std::vector<Index3> alongXFirst = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {2, 2, 0}};
  EXPECT_EQ(p, alongXFirst);
  EXPECT_EQ(st.settled, 9);  // the target has the box's largest index: every voxel before it
}

}  // namespace vs
