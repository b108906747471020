// Paths that part and meet again inside one lumen take one stretch there (tracking/trunk_join.h);
// two vessels of a loop with background between them keep their own routes.
#include "tracking/trunk_join.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <unordered_set>
#include <vector>

#include "kissing_tubes.h"

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
