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

// Session 41 (part63, part63b): head CTA 63,84,103's paths 1 / 4 part at the top of one wide vessel, fed by a
// narrower one (4.7 mm across at the parting), and run down it on its opposite walls (up to 14.8 mm apart) for
// ~35 mm before each leaves by its own exit. Here a thin tube (radius 2) opens into a wide one (radius 8) that
// ends in two exits at x 60 (up and down in y); a and b share the thin tube up to x 18, then run 6 above / below
// the wide tube's axis (12 apart: more than two thin tubes' widths, 2 x ~4.5) into their exits - one lumen all
// the way, no meeting again (joinSharedLumen's case). b takes a's trunk up to near the exits; a is kept.
TEST(TrunkJoin, PathsThatPartWhereALumenWidensShareItsTrunk) {
  const NodeCost3D cost = tubeCost({80, 50, 20}, {{{2, 25, 10}, {26, 25, 10}, 2},
                                                  {{30, 25, 10}, {58, 25, 10}, 8},
                                                  {{60, 25, 10}, {60, 45, 10}, 2},
                                                  {{60, 25, 10}, {60, 5, 10}, 2}});
  const std::vector<Index3> a0 =
      chain({{2, 25, 10}, {18, 25, 10}, {22, 26, 10}, {32, 31, 10}, {56, 31, 10}, {60, 44, 10}});
  const std::vector<Index3> b0 =
      chain({{2, 25, 10}, {18, 25, 10}, {22, 24, 10}, {32, 19, 10}, {56, 19, 10}, {60, 6, 10}});
  std::vector<Index3> b = b0;
  ASSERT_TRUE(joinPartedLumen(a0, b, cost, kLevel, kHoleMm));
  size_t shared = 0;
  while (shared < b.size() && shared < a0.size() && b[shared] == a0[shared]) ++shared;
  EXPECT_GE(a0[shared - 1][0], 45) << "the trunk shared up to near the exits";
  EXPECT_EQ(b.back(), b0.back());
}

// The same two paths in a tube wide from the start (radius 5: 10 across at the parting, the paths 6 apart): two
// daughters of a parent that wide could lie that far apart, so nothing tells this from a fork - kept (part63b's
// bound; part63 joined it).
TEST(TrunkJoin, PathsPartedInsideAWideParentNoFartherThanItsWidthKeepTheirRoutes) {
  const NodeCost3D cost = tubeCost(
      {80, 50, 20}, {{{2, 25, 10}, {60, 25, 10}, 5}, {{60, 25, 10}, {60, 45, 10}, 2}, {{60, 25, 10}, {60, 5, 10}, 2}});
  const std::vector<Index3> a0 = chain({{2, 25, 10}, {10, 25, 10}, {13, 28, 10}, {58, 28, 10}, {75, 44, 10}});
  const std::vector<Index3> b0 = chain({{2, 25, 10}, {10, 25, 10}, {13, 22, 10}, {58, 22, 10}, {75, 6, 10}});
  std::vector<Index3> b = b0;
  EXPECT_FALSE(joinPartedLumen(a0, b, cost, kLevel, kHoleMm));
  EXPECT_EQ(b, b0);
}

// Two tubes side by side in contact (radius 3, axes 5 apart: kissing / parallel family seeds) leave one trunk:
// the straight line between the paths is lumen, but the lumen narrows at the contact - each keeps its own.
TEST(TrunkJoin, TouchingTubesBesideEachOtherKeepTheirRoutes) {
  const NodeCost3D cost = tubeCost({80, 50, 20}, {{{2, 25, 10}, {12, 25, 10}, 3},
                                                  {{12, 25, 10}, {16, 27, 10}, 3},
                                                  {{16, 27, 10}, {70, 27, 10}, 3},
                                                  {{12, 25, 10}, {16, 22, 10}, 3},
                                                  {{16, 22, 10}, {70, 22, 10}, 3}});
  const std::vector<Index3> a0 = chain({{2, 25, 10}, {12, 25, 10}, {14, 27, 10}, {68, 27, 10}});
  const std::vector<Index3> b0 = chain({{2, 25, 10}, {12, 25, 10}, {15, 22, 10}, {68, 22, 10}});
  std::vector<Index3> b = b0;
  EXPECT_FALSE(joinPartedLumen(a0, b, cost, kLevel, kHoleMm));
  EXPECT_EQ(b, b0);
}

// An ordinary fork: the two children see each other through the fork's funnel for about its width only.
TEST(TrunkJoin, AnOrdinaryForkKeepsItsBranchPoint) {
  const NodeCost3D cost = tubeCost(
      {80, 60, 20}, {{{2, 30, 10}, {40, 30, 10}, 4}, {{40, 30, 10}, {70, 50, 10}, 3}, {{40, 30, 10}, {70, 10, 10}, 3}});
  const std::vector<Index3> a0 = chain({{2, 30, 10}, {38, 30, 10}, {69, 50, 10}});
  const std::vector<Index3> b0 = chain({{2, 30, 10}, {38, 30, 10}, {69, 10, 10}});
  std::vector<Index3> b = b0;
  EXPECT_FALSE(joinPartedLumen(a0, b, cost, kLevel, kHoleMm));
  EXPECT_EQ(b, b0);
}

// A fork's arm leaving a's way on (10501, part63c): a thin tube (radius 2) opens into a wide one (radius 6, along x)
// that turns up (+y) at x 56; a and b run beside each other 8 apart, then a goes on along x into a thin exit while
// b turns up the wide tube. b's nearest voxel on a stays where a passed the turn while b moves straight away from
// it: nothing of a runs beside b there, so those voxels neither extend the run nor count as "apart" - b keeps its
// route (part63b joined it: the two end up far more than twice the thin parent's width apart).
TEST(TrunkJoin, AForksArmMovingStraightAwayFromItsBendKeepsItsRoute) {
  const NodeCost3D cost = tubeCost({80, 80, 20}, {{{2, 10, 10}, {36, 10, 10}, 2},
                                                  {{36, 10, 10}, {56, 10, 10}, 6},
                                                  {{56, 10, 10}, {56, 50, 10}, 6},
                                                  {{56, 10, 10}, {77, 10, 10}, 2},
                                                  {{56, 50, 10}, {30, 50, 10}, 2}});
  const std::vector<Index3> a0 =
      chain({{2, 10, 10}, {28, 10, 10}, {36, 6, 10}, {52, 6, 10}, {58, 10, 10}, {76, 10, 10}});
  const std::vector<Index3> b0 = chain(
      {{2, 10, 10}, {28, 10, 10}, {36, 14, 10}, {52, 14, 10}, {56, 18, 10}, {56, 46, 10}, {52, 50, 10}, {31, 50, 10}});
  std::vector<Index3> b = b0;
  EXPECT_FALSE(joinPartedLumen(a0, b, cost, kLevel, kHoleMm));
  EXPECT_EQ(b, b0);
}

// A wide-angle fork (beside3, thin forced 10724): a thin trunk (radius 2) goes on up (+y) as one daughter and gives
// the other off at 74 degrees (radius 3.5: as wide as 10724's blurred arm reads at the lumen level) - the paths run a
// voxel apart up the trunk (a tie), then a goes on up along its daughter's outer wall while b takes the wide-angle
// arm. The straight line from b on its arm to a's nearest voxel runs back along the arm's lumen into the fork's
// funnel - lumen all the way, no waist - so the two "see" each other through lumen until they are more than twice
// the trunk's width apart, and part63c joined them (b up a's daughter past the fork, then straight back across the
// crotch to its arm). But b does not run beside a there: it moves more away from a than along it (b's voxel nearest
// to a's nearest lies back at the fork, farther from b's voxel than a's nearest lies from b) - those voxels are no
// stretch of one lumen shared by both, and b keeps its route. Fails on main's code (part63c joins: apart 17 > 2 x
// the trunk's 5).
TEST(TrunkJoin, AWideAngleForksArmMovingMoreAwayFromThePathThanAlongItKeepsItsRoute) {
  const NodeCost3D cost =
      tubeCost({80, 80, 20},
               {{{40, 2, 10}, {40, 30, 10}, 2}, {{40, 30, 10}, {40, 77, 10}, 2}, {{40, 30, 10}, {12, 38, 10}, 3.5}});
  const std::vector<Index3> a0 = chain({{40, 2, 10}, {40, 6, 10}, {41, 7, 10}, {42, 30, 10}, {42, 76, 10}});
  const std::vector<Index3> b0 =
      chain({{40, 2, 10}, {40, 30, 10}, {33, 32, 10}, {26, 34, 10}, {19, 36, 10}, {13, 38, 10}});
  std::vector<Index3> b = b0;
  EXPECT_FALSE(joinPartedLumen(a0, b, cost, kLevel, kHoleMm));
  EXPECT_EQ(b, b0);
}

}  // namespace
}  // namespace vs
