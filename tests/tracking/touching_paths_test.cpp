// Session 37 (touch37): another traced path whose lumen touches a point's is a trigger of the rounds' own-lobe step
// (centreline.h: lobeValley; centreline_junctions.h: touchingPaths), beside the escaped and the long ray. At a kissing
// contact whose neck stops every ray (no ray escapes, the longest under lobeLongRay x the median) the chords across
// it end at the neck, not at the wall, and centre the point towards the other tube: the family's 524 had path 0's
// points 20-22 1.01-1.04 voxels off its own axis from round 0 on, where the root fork's second child comes back to run
// beside the first (the tubes 0.04 voxel apart).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "family_trace.h"
#include "test_tree.h"
#include "tracking/centreline_junctions.h"

namespace vs {
namespace {

// Chain A runs from the root along x (1 mm a point, radius 1 mm); chain B leaves the root and comes back beside A's
// point 8, 1.5 mm off; chain C leaves the root beside A's start (their fork).
TEST(TouchingPaths, APathComingBackBesideAnotherTouchesItsLumenAForkDoesNot) {
  TestTree t;
  t.add(-1, Vec3(0, 0, 0), 1);
  for (int i = 1; i <= 10; ++i) t.add(i - 1, Vec3(i, 0, 0), 1);  // 1..10 chain A
  const int32_t b0 = t.add(0, Vec3(0, 3, 0), 1);                 // 11..13 chain B
  const int32_t b1 = t.add(b0, Vec3(4, 3, 0), 1);
  const int32_t b2 = t.add(b1, Vec3(8, 1.5, 0), 1);
  const int32_t c0 = t.add(0, Vec3(1, 1.2, 0), 1);  // 14..15 chain C, A's sibling at their fork
  const int32_t c1 = t.add(c0, Vec3(2, 1.6, 0), 1);
  const centreline_detail::JunctionInput in{t.parent, t.children, t.radius, [&](size_t k) { return t.q[k]; }};
  CentrelineOptions o;
  std::vector<int64_t> touched = centreline_detail::touchingPaths(in, o, t.q);
  ASSERT_EQ(touched.size(), t.q.size());
  EXPECT_EQ(touched[8], b2);                        // B's voxel 1.5 mm off, within the two radii
  EXPECT_EQ(touched[static_cast<size_t>(b2)], 8);   // and A's 8 beside B's point
  EXPECT_EQ(touched[5], -1);                        // no other path near
  EXPECT_EQ(touched[1], -1);                        // C beside A's start: within the fork's reach
  EXPECT_EQ(touched[static_cast<size_t>(c1)], -1);  // the same from C's side
  // The rounds' positions, not the voxels, are tested: A's 5 drawn next to B's middle voxel touches it.
  std::vector<Vec3> q = t.q;
  q[5] = Vec3(4.5, 1.5, 0);
  touched = centreline_detail::touchingPaths(in, o, q);
  EXPECT_EQ(touched[5], b1);
  // A point whose radius is not known yet (not cast: 0) neither is touched nor touches.
  std::vector<double> radius = t.radius;
  radius[static_cast<size_t>(b2)] = 0;
  const centreline_detail::JunctionInput unknown{t.parent, t.children, radius, [&](size_t k) { return t.q[k]; }};
  touched = centreline_detail::touchingPaths(unknown, o, t.q);
  EXPECT_EQ(touched[8], -1);
  EXPECT_EQ(touched[static_cast<size_t>(b2)], -1);
}

// Two paths along one tube from their fork (a narrow fork's children side by side, two paths along a trunk's walls):
// chains A and D leave the root 1.2 mm apart and stay so for 10 mm; past the fork's reach they lie within the two radii
// of each other but never parted, so neither touches the other.
TEST(TouchingPaths, PathsSideBySideFromTheirForkDoNotTouch) {
  TestTree t;
  t.add(-1, Vec3(0, 0, 0), 1);
  for (int i = 1; i <= 10; ++i) t.add(i - 1, Vec3(i, 0, 0), 1);  // 1..10 chain A
  int32_t d = 0;
  for (int i = 1; i <= 10; ++i) d = t.add(d, Vec3(i, 1.2, 0), 1);  // 11..20 chain D
  const centreline_detail::JunctionInput in{t.parent, t.children, t.radius, [&](size_t k) { return t.q[k]; }};
  const std::vector<int64_t> touched = centreline_detail::touchingPaths(in, CentrelineOptions{}, t.q);
  for (size_t k = 0; k < touched.size(); ++k) EXPECT_EQ(touched[k], -1) << "point " << k;
}

// Tuning-grade seed 524 (kissing as drawn, bright, 0.64 x 0.64 x 1.26 mm): on main 97.2 % of the refined points within
// 1 voxel of their own tubes (3 far of 106: path 0's 20-22, 1.006 / 1.043 / 1.015), mean 0.193.
TEST(TouchingPaths, KissingChildrenOfTheRootForkKeepTheirOwnAxes) {
  const PointFigures p = tracedFigures("touching paths", 524, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);  // main 0.972
  EXPECT_LE(p.meanVox, 0.3);
}

// Session 44 (forkG): tuning-grade seed 7321 (scan thin forced, 0.95 x 0.95 x 1.88 mm) under forkE's second reading of
// the fused fork: path 0 now follows b1's hairpin loop (main cut across b2's start: its own route covered 80.6 %), and
// b1's return limb passes b2's start with the axes 2.3 mm apart (radii 2.5 mm). b2 runs along z there, in the plane of
// b1's sections: the valleys split the union into a lobe of b2's stripe with part of b1's disc, and the anchor's "own"
// lobe was that one (its centre 3.1 mm from b2's path voxel, 5.3 mm from the anchor) - the own-lobe step took b1's
// points 39-41 onto the union (96.5 % within 1 voxel). A lobe nearer the touching path's voxel than the anchor is not
// the own (lobeNearerTouching): the rays' step stands. Main's code: route 82.8 % (fails); forkE alone: 96.5 % (fails).
TEST(TouchingPaths, AnOwnLobeNearerTheTouchingPathsVoxelIsNotTheOwn) {
  const FamilyTrace f = traceEveryTerminal(7321, VesselFamilyVariant::Thin);
  const VesselTruth& t = f.c.truth;
  ASSERT_FALSE(t.terminalBranches.empty());
  ASSERT_FALSE(f.r.points.empty());
  const double covered = ownRouteCovered(t, f.r, 0);  // path 0 covers its own route
  const PointFigures p = pointFigures(t, f.r);
  std::printf("[touch 7321] path 0's own route covered %.1f%%, within 1 vox %.1f%%, mean %.3f vox\n", 100.0 * covered,
              100 * p.within1, p.meanVox);
  EXPECT_GE(covered, 0.99);
  EXPECT_GE(p.within1, 0.98);
  EXPECT_LE(p.meanVox, 0.2);
}

}  // namespace
}  // namespace vs
