// The support re-search's rounds in one box (box_rounds.h; session 44 speedC): each round taken from the round before
// where the new blocks leave a voxel's route as it was gives boxPath's full search's route and cost, ties included.
#include "tracking/box_rounds.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "few_valued_cost.h"
#include "tracking/box_search.h"

namespace vs {
namespace {

using retrace::Box;
using retrace::Step;

using testing_box::fewValuedCost;
using testing_box::inside;

}  // namespace

// Rounds as retraceUnsupported runs them: a route found, a stretch of it blocked with the voxels round it, the box
// searched again - every round's route and cost exactly boxPath's, and most rounds after the first take voxels from
// the round before. A voxel opened again makes the next round a full search.
TEST(BoxRounds, EveryRoundIsTheFullSearchsRoute) {
  std::mt19937 rng(44);
  const double inf = std::numeric_limits<double>::infinity();
  int rounds = 0, resumed = 0, found = 0, full = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3 spacing = trial % 3 == 0 ? Vec3(1, 1, 1) : trial % 3 == 1 ? Vec3(0.94, 0.94, 2.28) : Vec3(0.5, 0.7, 1);
    const NodeCost3D cost = fewValuedCost({16, 13, 10}, spacing, rng);
    const Geometry& g = cost.geometry;
    Box b;
    for (size_t a = 0; a < 3; ++a) {
      b.lo[a] = std::uniform_int_distribution<int64_t>(0, 2)(rng);
      b.n[a] = std::uniform_int_distribution<int64_t>(6, g.dims[a] - b.lo[a])(rng);
    }
    std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
    std::bernoulli_distribution block(trial % 2 ? 0.05 : 0.15);
    for (uint8_t& v : blocked) v = block(rng) ? 1 : 0;
    const Index3 from = inside(b, rng), to = inside(b, rng);
    const int connectivity = trial % 4 == 3 ? 6 : trial % 4 == 2 ? 18 : 26;
    const std::vector<Step> steps = retrace::stepsFor(g, connectivity);
    retrace::BoxRounds search(cost, b, steps, from, to);
    for (int round = 0; round < 5; ++round) {
      blocked[static_cast<size_t>(b.index(from))] = blocked[static_cast<size_t>(b.index(to))] = 0;
      double c0 = -1, c1 = -1;
      const std::vector<Index3> p0 = retrace::boxPath(cost, b, blocked, steps, from, to, inf, &c0);
      const std::vector<Index3> p1 = search.search(blocked, &c1);
      ASSERT_EQ(p0, p1) << "trial " << trial << " round " << round;
      if (!p0.empty()) {
        EXPECT_EQ(c0, c1) << "trial " << trial << " round " << round;  // the same sums
      }
      ++rounds;
      resumed += search.kept() > 0 ? 1 : 0;
      if (p0.size() < 3) break;
      // A stretch of the route blocked (as blockStretch does), its ends' neighbours too.
      const size_t first = std::uniform_int_distribution<size_t>(1, p0.size() - 2)(rng);
      const size_t last = std::min(p0.size() - 2, first + std::uniform_int_distribution<size_t>(0, 3)(rng));
      for (size_t k = first; k <= last; ++k)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          const Index3 w{p0[k][0] + dx, p0[k][1], p0[k][2]};
          if (b.in(w) && (dx == 0 || round % 2)) blocked[static_cast<size_t>(b.index(w))] = 1;
        }
      ++found;
      if (round == 3 && trial % 5 == 0) {  // a voxel opened again: searched in full
        for (size_t i = 0; i < blocked.size(); ++i)
          if (blocked[i]) {
            blocked[i] = 0;
            break;
          }
        blocked[static_cast<size_t>(b.index(from))] = blocked[static_cast<size_t>(b.index(to))] = 0;
        double c2 = -1, c3 = -1;
        ASSERT_EQ(retrace::boxPath(cost, b, blocked, steps, from, to, inf, &c2), search.search(blocked, &c3));
        EXPECT_EQ(search.kept(), 0);
        ++full;
      }
    }
  }
  EXPECT_GT(rounds, 120);
  EXPECT_GT(found, 80);
  EXPECT_GT(resumed, 60);  // the rounds after the first mostly start from the round before
  EXPECT_GT(full, 4);
}

// A round keeps every voxel whose route the new block leaves open and searches only the rest: blocking one voxel
// beside the start's far side of a uniform box leaves most of the search as it was.
TEST(BoxRounds, ARoundSettlesOnlyWhatTheNewBlocksChange) {
  NodeCost3D cost;
  cost.kind = CostKind3D::Given;
  cost.geometry.dims = {12, 12, 12};
  cost.node.assign(12 * 12 * 12, 1.0f);
  Box b;
  b.n = cost.geometry.dims;
  std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
  const std::vector<Step> steps = retrace::stepsFor(cost.geometry, 26);
  const Index3 from{1, 1, 1}, to{10, 10, 10};
  retrace::BoxRounds search(cost, b, steps, from, to);
  double c0 = 0, c1 = 0;
  retrace::BoxSearchStats s0, s1;
  const std::vector<Index3> p0 = search.search(blocked, &c0, &s0);
  ASSERT_FALSE(p0.empty());
  blocked[static_cast<size_t>(b.index(p0[p0.size() / 2]))] = 1;
  const std::vector<Index3> p1 = search.search(blocked, &c1, &s1);
  double cFull = 0;
  EXPECT_EQ(p1, retrace::boxPath(cost, b, blocked, steps, from, to, std::numeric_limits<double>::infinity(), &cFull));
  EXPECT_EQ(c1, cFull);
  EXPECT_GT(search.kept(), 0);
  EXPECT_LT(s1.settled, s0.settled);
  EXPECT_LT(s1.costsRead, s0.costsRead);
}

}  // namespace vs
