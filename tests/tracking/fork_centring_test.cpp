// Session 35 (centre35): the shared chain's points inside a fork's fused junction blob (trunk + both children's
// starts) were centred on the blob, up to 1.8 voxels off the trunk's axis (on the inner corner where the trunk bends);
// they now go onto the trunk's curve between its last unfused point and the children's first unfused points
// (fork_centring.cpp, centreForkTrunks). Session 37 (cross37): the same at a junction the tree does not fork at (the
// sibling entered elsewhere): the chain's blob points onto its own curve through the junction.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "family_trace.h"
#include "test_tree.h"
#include "tracking/centreline_junctions.h"

namespace vs {
namespace {

// Tuning-grade seed 11825 (thin forced, 0.97 x 0.97 x 2.64 mm): the trunk (radius 3.5 voxels) bends 79 degrees into
// its root fork; the point all five paths share 2 voxels before the junction sat 1.35 voxels off the trunk's axis
// with radius 4.47 voxels (main: 97.9 % within 1 voxel).
TEST(ForkCentring, SharedChainPointInTheJunctionBlobStaysOnTheTrunk) {
  const PointFigures p = tracedFigures("fork centring", 11825, VesselFamilyVariant::Thin);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);  // main 0.979
  EXPECT_LE(p.meanVox, 0.3);
}

// Session 39 (ubottom), tuning-grade seed 12124 (thin forced, 0.66 x 0.66 x 1.24 mm): b1 turns round a U as tight as
// its tube, fused at the bottom with its sibling b2's curl, and the tree forks (paths 2 / 3 part) just past the U's
// bottom. The U bottom's two points (paths 2 / 3 points 34 / 35) were the fork's blob: the chords drew them towards b2,
// and centre35's curve, scaled by the chord across the U, cut its inside (1.11 / 1.29 voxels off b1's axis). Where
// every child turns back against the trunk at A, the curve is scaled by the chain's own length round the U and each
// point takes its share of it: against the paths' own tubes every point within 1 voxel.
TEST(ForkCentring, TrunkTurnedRoundBeforeItsForkKeepsTheUBottomOnTheTrunk) {
  const PointFigures p = tracedFigures("fork centring", 12124, VesselFamilyVariant::Thin, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.999);  // main 0.984 (4 far: the U bottom's inside), here 1.000
  EXPECT_LE(p.meanVox, 0.135);  // main 0.145, here 0.128
}

// Session 41 (lobeC) / 42 (kindC3), tuning-grade seed 12432 (thin forced): at fork 22 the rounds centred both
// children's points on the union of their lumens (95.7 % within 1 voxel). The fused section, read along each child's
// chain from where its section is its own tube alone back towards the fork, goes to the peak of the child's own lobe of
// each section (placeFusedLobes), the walk stopped where the lobe swells beyond its step and a point the lobe would
// take nearer the sibling's lobe left where it is.
TEST(ForkCentring, FusedSectionGoesToTheChildsOwnLobeAlongItsChain) {
  const PointFigures p = tracedFigures("fused lobes", 12432, VesselFamilyVariant::Thin);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.979);  // main 0.957, here 0.980 (391 / 399)
  EXPECT_LE(p.meanVox, 0.130);  // main 0.154, here 0.121
}

// Session 42 (kindC3), tuning-grade seed 10929 (thin forced, 0.95 x 0.95 x 2.16 mm): 11 voxels past fork 43 the child
// (truth branch 4) and its sibling (branch 3) are still one blob, 2.1 mm apart almost along the thick slice axis.
// Walked back from the child's own tube, its lobe there takes in the sibling too (width 4.3 -> 6.3 mm over a 1.2 mm
// step) and its peak drew paths 4 / 5 point 51 onto the sibling (0.91 -> 1.02 voxels: lobeC2's 97.9 %). The walk stops
// where the own lobe's width grows by more than the step along the child: main's 98.3 % kept.
TEST(ForkCentring, LobeThatSwellsTowardsTheForkTakesInAnotherTubeAndStopsTheWalk) {
  const PointFigures p = tracedFigures("fused lobes", 10929, VesselFamilyVariant::Thin);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);  // main 0.983, lobeC2 0.979, here 0.983
}

// A plain chain along y (0.6 mm apart) from a tube of radius `up` into one of radius `down` at y 15 mm, its two points
// there 1 mm off the axis in x with radius 2.7 mm (a sibling's fused start beside them, traced by no path).
struct UnforkedJunction : TestTree {
  std::vector<uint8_t> frozen;
  UnforkedJunction(double up, double down) {
    for (int i = 0; i <= 50; ++i) {
      const double y = 0.6 * i;
      const bool blob = i == 25 || i == 26;
      add(i - 1, Vec3(blob ? 1.0 : 0.0, y, 0), blob ? 2.7 : y < 15 ? up : down);
      frozen.push_back(0);
    }
  }
  size_t run() {
    const centreline_detail::JunctionInput in{parent, children, radius};
    return centreline_detail::centreForkTrunks(in, frozen, CentrelineOptions{}, 0.63, q, radius);
  }
};

TEST(ForkCentring, UnforkedJunctionBlobGoesOntoTheChainsCurve) {
  UnforkedJunction t(2.2, 1.7);  // the chain passes from the trunk into a narrower child
  EXPECT_EQ(t.run(), 2u);
  for (size_t k : {25u, 26u}) {
    EXPECT_NEAR(t.q[k][0], 0.0, 0.05) << k;
    EXPECT_LT(t.radius[k], 2.2) << k;
  }
}

TEST(ForkCentring, UnforkedJunctionWithTheSiblingTracedIsLeft) {
  UnforkedJunction t(2.2, 1.7);
  const int32_t side = t.add(2, Vec3(3.0, 2.0, 0), 1.0);  // another path from a fork up the trunk ...
  t.add(side, Vec3(3.0, 15.0, 0), 1.0);                   // ... whose point lies in the blob: its fork is traced
  t.frozen.resize(t.q.size(), 0);
  EXPECT_EQ(t.run(), 0u);
  EXPECT_DOUBLE_EQ(t.q[25][0], 1.0);
}

TEST(ForkCentring, BumpOnOneCalibreIsNoUnforkedJunction) {
  UnforkedJunction t(2.0, 2.0);  // no calibre step: a contact's bump (the two-tube fit's), not a junction
  EXPECT_EQ(t.run(), 0u);
  EXPECT_DOUBLE_EQ(t.q[25][0], 1.0);
}

// Tuning-grade seed 11326 (thin forced, 0.63 x 0.63 x 1.86 mm): the paths to child b1 enter it through its contact
// with the trunk before the junction, so the tree does not fork there; b2's first point past the junction sat in the
// b1 / b2 crotch, 1.39 voxels off (main: 97.5 % within 1 voxel, 16 far points; the bound allows 12).
TEST(ForkCentring, UnforkedJunctionPointStaysOnItsChild) {
  const PointFigures p = tracedFigures("unforked junction", 11326, VesselFamilyVariant::Thin);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);  // main 0.975
}

}  // namespace
}  // namespace vs
