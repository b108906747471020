// Paths that part and meet again inside one lumen take one stretch there (tracking/trunk_join.h);
// two vessels of a loop with background between them keep their own routes.
#include "tracking/trunk_join.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <unordered_set>
#include <vector>

#include "family_trace.h"
#include "kissing_tubes.h"
#include "tracking/crossing_retrace.h"

namespace vs {
namespace {

using namespace test_tubes;  // tubeCost, chain (kissing_tubes.h)

constexpr double kLevel = 0.2, kHoleMm = 2.0;

// A wide trunk (radius 5) with a branch leaving it at x 60. Paths a and b (as two separate re-searches
// leave them, issue 21: the head CTA's sinuses) part at x 20, run 3 voxels either side of the axis
// inside the same lumen at the same cost and meet again at x 43; b then takes the branch.
struct PartedInOneLumen {
  NodeCost3D cost = tubeCost({80, 40, 20}, {{{2, 20, 10}, {75, 20, 10}, 5}, {{60, 20, 10}, {60, 36, 10}, 2}});
  std::vector<Index3> a0 = chain({{2, 20, 10}, {20, 20, 10}, {23, 23, 10}, {40, 23, 10}, {43, 20, 10}, {74, 20, 10}});
  std::vector<Index3> b0 =
      chain({{2, 20, 10}, {20, 20, 10}, {23, 17, 10}, {40, 17, 10}, {43, 20, 10}, {60, 20, 10}, {60, 34, 10}});
};

TEST(TrunkJoin, PathsThatPartAndMeetAgainInOneLumenShareOneStretch) {
  const PartedInOneLumen c;
  for (const bool aFirst : {true, false}) {
    std::vector<Index3> a = c.a0, b = c.b0;
    const int changed =
        aFirst ? joinSharedLumen(a, b, c.cost, kLevel, kHoleMm) : joinSharedLumen(b, a, c.cost, kLevel, kHoleMm);
    EXPECT_NE(changed, 0) << "a first " << aFirst;
    // One trunk: both run on the same voxels up to where b takes the branch (the earlier path's: a tie).
    ASSERT_GE(b.size(), 59u);
    EXPECT_TRUE(std::equal(b.begin(), b.begin() + 59, a.begin())) << "a first " << aFirst;
    EXPECT_EQ(aFirst ? a : b, aFirst ? c.a0 : c.b0) << "the earlier path kept";
    EXPECT_EQ(a.back(), c.a0.back());
    EXPECT_EQ(b.back(), c.b0.back());
  }
}

TEST(TrunkJoin, AReSearchedStretchIsKept) {
  // b's stretch put there by a re-search: a takes it, whichever path came first.
  const PartedInOneLumen c;
  std::unordered_set<int64_t> researched;
  for (size_t i = 19; i < 44; ++i) researched.insert(c.cost.geometry.linear(c.b0[i][0], c.b0[i][1], c.b0[i][2]));
  for (const bool aFirst : {true, false}) {
    std::vector<Index3> a = c.a0, b = c.b0;
    if (aFirst)
      joinSharedLumen(a, b, c.cost, kLevel, kHoleMm, researched);
    else
      joinSharedLumen(b, a, c.cost, kLevel, kHoleMm, researched);
    EXPECT_EQ(b, c.b0) << "a first " << aFirst;
    EXPECT_TRUE(std::equal(b.begin(), b.begin() + 59, a.begin())) << "a first " << aFirst;
  }
}

// Session 37 (corner37): a tube (radius 6) bending 90 degrees, its node cost nearly flat inside (0.001 on the axis,
// 0.0012 at the wall: a lumen at the cost's floor, as 11930's fused hairpin) - path a, the cheaper, cuts the bend's
// inside on a diagonal (14.1 mm, off the axis), path b goes round it on the axis (20 mm, dearer, cheaper per mm). Both
// take b's stretch; on main (ties only) each kept its own.
TEST(TrunkJoin, ACutThroughABendsInsideGoesRoundOnTheDearerStretchCheaperPerMm) {
  const std::vector<Segment> bend{{{2, 10, 6}, {30, 10, 6}, 6}, {{30, 10, 6}, {30, 38, 6}, 6}};
  NodeCost3D cost = tubeCost({40, 46, 13}, bend);
  for (int64_t z = 0; z < 13; ++z)
    for (int64_t y = 0; y < 46; ++y)
      for (int64_t x = 0; x < 40; ++x) {
        const double d = distanceToPolyline(bend, Vec3(double(x), double(y), double(z)));
        if (d <= 6) cost.node[static_cast<size_t>(cost.geometry.linear(x, y, z))] = float(0.001 + 0.0002 * d / 6);
      }
  const std::vector<Index3> a0 = chain({{2, 10, 6}, {20, 10, 6}, {30, 20, 6}, {30, 36, 6}});
  const std::vector<Index3> b0 = chain({{2, 10, 6}, {30, 10, 6}, {30, 36, 6}});
  ASSERT_LT(chainCost(cost, a0), chainCost(cost, b0));  // a is the shortest route: the search's
  for (const bool aFirst : {true, false}) {
    std::vector<Index3> a = a0, b = b0;
    const int changed =
        aFirst ? joinSharedLumen(a, b, cost, kLevel, kHoleMm) : joinSharedLumen(b, a, cost, kLevel, kHoleMm);
    EXPECT_EQ(changed, aFirst ? 1 : 2) << "a first " << aFirst;
    EXPECT_EQ(a, b0) << "a first " << aFirst;
    EXPECT_EQ(b, b0) << "a first " << aFirst;
  }
}

// The same on tuning-grade seed 11930 (thin forced, 0.83 x 0.83 x 2.04 mm): the trunk curls into a fork whose child 1
// turns back at once beside the curl (the two overlap); paths 0 / 1 / 3 cut from the trunk's voxel 62,20,15 into child
// 1's start, path 2 went round the curl (main: 95.8 % within 1 voxel, 6 of the 12 far points at that corner). They now
// all go round it.
TEST(TrunkJoin, TrunksCurlIntoAChildTurningBackTracedRoundTheCurl) {
  const PointFigures p = tracedFigures("trunk join", 11930, VesselFamilyVariant::Thin);
  EXPECT_GE(p.within1, 0.98);
}

TEST(TrunkJoin, TwoVesselsOfALoopKeepTheirRoutes) {
  // A loop of two equally long arcs (radius 2) with background inside it: a along the lower arc, b
  // along the upper one. They part and meet again at the same cost, yet are not one lumen.
  const std::vector<Segment> tubes{{{2, 15, 10}, {20, 15, 10}, 2},  {{20, 15, 10}, {30, 5, 10}, 2},
                                   {{30, 5, 10}, {40, 5, 10}, 2},   {{40, 5, 10}, {50, 15, 10}, 2},
                                   {{20, 15, 10}, {30, 25, 10}, 2}, {{30, 25, 10}, {40, 25, 10}, 2},
                                   {{40, 25, 10}, {50, 15, 10}, 2}, {{50, 15, 10}, {70, 15, 10}, 2}};
  const NodeCost3D cost = tubeCost({80, 40, 20}, tubes);
  const std::vector<Index3> a0 =
      chain({{2, 15, 10}, {20, 15, 10}, {30, 5, 10}, {40, 5, 10}, {50, 15, 10}, {68, 15, 10}});
  const std::vector<Index3> b0 =
      chain({{2, 15, 10}, {20, 15, 10}, {30, 25, 10}, {40, 25, 10}, {50, 15, 10}, {68, 15, 10}});
  std::vector<Index3> a = a0, b = b0;
  EXPECT_EQ(joinSharedLumen(a, b, cost, kLevel, kHoleMm), 0);
  EXPECT_EQ(a, a0);
  EXPECT_EQ(b, b0);
}

}  // namespace
}  // namespace vs
