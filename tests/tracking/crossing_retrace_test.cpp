// Kissing vessels (tracking/crossing_retrace.h): a path that steps sideways from one tube into a
// touching one is searched again with the tube it leaves blocked there; a single tube's own bend
// has no route around it and is kept.
#include "tracking/crossing_retrace.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "kissing_tubes.h"
#include "tracking/tracker.h"

namespace vs {
namespace {

using namespace test_tubes;  // the kissing tubes (kissing_tubes.h)

TEST(CrossingRetrace, PathThroughTheContactIsSearchedAgainAlongItsOwnTube) {
  // A trunk goes on as A (radius 2.5); B (radius 2) bends away and comes back to touch A (no gap)
  // from x 44 to 80. The path to B's end as the search takes it where every lumen voxel costs the
  // same: along A to x 55, sideways into B, on along B.
  const std::vector<Segment> b = kissingB(), all = kissingPair();
  const NodeCost3D cost = tubeCost({90, 40, 16}, all);
  const std::vector<Index3> crossing = chain({{4, 20, 8}, {55, 20, 8}, {59, 24, 8}, {79, 24, 8}});
  auto offB = [&](const std::vector<Index3>& p) { return voxelsOutside(b, p); };
  ASSERT_GT(offB(crossing), 20);
  const double level = 0.2;
  const std::vector<LateralStep> steps = findLateralSteps(cost.geometry, crossing, {}, &cost, level);
  ASSERT_EQ(steps.size(), 1u);
  EXPECT_NEAR(steps[0].lateralMm, 4, 0.5);
  EXPECT_GT(steps[0].normal[1], 0.9);

  const CrossingRetrace r = retraceAcrossCrossings(cost, crossing, 26, level);
  ASSERT_TRUE(r.changed) << r.why;
  EXPECT_EQ(offB(r.voxels), 0);
  EXPECT_EQ(r.voxels.front(), crossing.front());
  EXPECT_EQ(r.voxels.back(), crossing.back());
  EXPECT_NEAR(r.newCost, chainCost(cost, r.voxels), 1e-9);
  EXPECT_LE(r.newCost, r.oldCost * 1.1);
  // Without the lumen test (the path alone) the step is seen too; A's own path has none.
  EXPECT_EQ(findLateralSteps(cost.geometry, crossing).size(), 1u);
  EXPECT_TRUE(findLateralSteps(cost.geometry, chain({{4, 20, 8}, {84, 20, 8}}), {}, &cost, level).empty());
}

TEST(CrossingRetrace, PathThatDriftsAcrossTheContactIsSearchedAgain) {
  // The same two tubes; the path drifts from A's axis into B's over 16 steps (one voxel sideways
  // every four), as a 26-connected path does where every lumen voxel costs the same: no sharp step
  // (kiss5's test alone sees none), but the tubes lie side by side at both ends of the drift.
  const std::vector<Segment> b = kissingB(), all = kissingPair();
  const NodeCost3D cost = tubeCost({90, 40, 16}, all);
  const std::vector<Index3> drift =
      chain({{4, 20, 8}, {48, 20, 8}, {52, 21, 8}, {56, 22, 8}, {60, 23, 8}, {64, 24, 8}, {79, 24, 8}});
  auto offB = [&](const std::vector<Index3>& p) { return voxelsOutside(b, p); };
  ASSERT_GT(offB(drift), 20);
  const double level = 0.2;
  CrossingOptions stepsOnly;
  stepsOnly.driftSteps = 0;
  EXPECT_TRUE(findLateralSteps(cost.geometry, drift, stepsOnly, &cost, level).empty());
  const std::vector<LateralStep> steps = findLateralSteps(cost.geometry, drift, {}, &cost, level);
  ASSERT_EQ(steps.size(), 1u);
  EXPECT_TRUE(steps[0].drift);
  EXPECT_GT(steps[0].normal[1], 0.9);
  EXPECT_GT(steps[0].lateralMm, 3.5);
  const CrossingRetrace r = retraceAcrossCrossings(cost, drift, 26, level);
  ASSERT_TRUE(r.changed) << r.why;
  EXPECT_EQ(offB(r.voxels), 0);
  EXPECT_EQ(r.voxels.front(), drift.front());
  EXPECT_EQ(r.voxels.back(), drift.back());
  // A's own path, straight along A past B's contact, has none.
  EXPECT_TRUE(findLateralSteps(cost.geometry, chain({{4, 20, 8}, {84, 20, 8}}), {}, &cost, level).empty());
}

TEST(CrossingRetrace, AGentleSBendOfOneTubeIsNoDrift) {
  // One tube (radius 2) that moves 6 voxels sideways over 24 (an S): parallel stretches either side,
  // but no second tube beside either of them.
  std::vector<Segment> t{{{2, 20, 8}, {40, 20, 8}, 2}};
  for (int j = 0; j < 12; ++j) {
    const double x0 = 40 + 2 * j, x1 = x0 + 2;
    const double y0 = 20 + 3 * (1 - std::cos(M_PI * j / 12)), y1 = 20 + 3 * (1 - std::cos(M_PI * (j + 1) / 12));
    t.push_back({{x0, y0, 8}, {x1, y1, 8}, 2});
  }
  t.push_back({{64, 26, 8}, {86, 26, 8}, 2});
  const NodeCost3D cost = tubeCost({90, 40, 16}, t);
  const std::vector<Index3> path =
      chain({{4, 20, 8}, {40, 20, 8}, {46, 21, 8}, {50, 23, 8}, {54, 25, 8}, {58, 26, 8}, {84, 26, 8}});
  EXPECT_TRUE(findLateralSteps(cost.geometry, path, {}, &cost, 0.2).empty());
  EXPECT_FALSE(retraceAcrossCrossings(cost, path, 26, 0.2).changed);
}

TEST(CrossingRetrace, ASharpJogOfOneTubeIsKept) {
  // One tube (radius 2) that jogs sideways by 6 voxels and its centreline: a sideways step between
  // parallel stretches, but the tube does not go on past it, so it is no crossing; and with the
  // tube blocked there no route through the lumen is left.
  const std::vector<Segment> t{
      {{2, 20, 8}, {50, 20, 8}, 2}, {{50, 20, 8}, {56, 26, 8}, 2}, {{56, 26, 8}, {86, 26, 8}, 2}};
  const NodeCost3D cost = tubeCost({90, 40, 16}, t);
  const std::vector<Index3> path = chain({{4, 20, 8}, {50, 20, 8}, {56, 26, 8}, {84, 26, 8}});
  EXPECT_EQ(findLateralSteps(cost.geometry, path).size(), 1u);
  EXPECT_TRUE(findLateralSteps(cost.geometry, path, {}, &cost, 0.2).empty());
  const CrossingRetrace r = retraceAcrossCrossings(cost, path, 26, 0.2);
  EXPECT_FALSE(r.changed);
  EXPECT_EQ(r.steps, 0);
  // The tracker leaves the search's path alone.
  const VolumeF32 intensities(cost.geometry, 0.0f);
  VesselTracker tr(intensities, cost, {4, 20, 8});
  const TracedPath& p = tr.addTarget({84, 26, 8});
  ASSERT_TRUE(p.reached);
  EXPECT_FALSE(p.retraced);
  for (const Index3& v : p.voxels) EXPECT_LE(distanceToPolyline(t, at(v)), 2.0);
}

TEST(CrossingRetrace, PathsThroughOneSearchedStretchShareItInEitherOrder) {
  // The kissing pair, the search's route laid along A and across the contact into B (its voxels a
  // little cheaper). One target far along B, one just past the contact: the far path's re-search is
  // accepted, the near one's alone is not (its cap is a share of its whole, shorter path), yet both
  // take the same route (one trunk: the nearer path is the start of the farther one), in either order
  // (issue 21: two paths through one stretch went two ways through one lumen, 1-4 mm apart).
  const std::vector<Segment> b = kissingB(), all = kissingPair();
  NodeCost3D cost = tubeCost({90, 40, 16}, all);
  const std::vector<Index3> route = chain({{4, 20, 8}, {55, 20, 8}, {59, 24, 8}, {79, 24, 8}});
  for (const Index3& v : route) cost.node[static_cast<size_t>(cost.geometry.linear(v[0], v[1], v[2]))] = 0.00095f;
  const VolumeF32 intensities(cost.geometry, 0.0f);
  const Index3 far{79, 24, 8}, near{60, 24, 8};
  std::vector<std::vector<Index3>> farPaths;
  for (const bool farFirst : {true, false}) {
    VesselTracker tr(intensities, cost, {4, 20, 8});
    tr.addTarget(farFirst ? far : near);
    tr.addTarget(farFirst ? near : far);
    const size_t fi = farFirst ? 0 : 1, ni = 1 - fi;
    const TracedPath& pf = tr.paths()[fi];
    const TracedPath& pn = tr.paths()[ni];
    ASSERT_TRUE(pf.reached && pn.reached);
    EXPECT_TRUE(pf.retraced && pn.retraced);
    EXPECT_EQ(voxelsOutside(b, pf.voxels), 0) << "far first " << farFirst;
    ASSERT_LE(pn.voxels.size(), pf.voxels.size());
    EXPECT_TRUE(std::equal(pn.voxels.begin(), pn.voxels.end(), pf.voxels.begin())) << "far first " << farFirst;
    EXPECT_NEAR(pf.cost, chainCost(cost, pf.voxels), 1e-9);
    EXPECT_NEAR(pn.cost, chainCost(cost, pn.voxels), 1e-9);
    // One tree: the nearer path's tree points are the start of the farther one's.
    const std::vector<int32_t>& tn = tr.pathTreePoints(ni);
    const std::vector<int32_t>& tf = tr.pathTreePoints(fi);
    ASSERT_LE(tn.size(), tf.size());
    EXPECT_TRUE(std::equal(tn.begin(), tn.end(), tf.begin())) << "far first " << farFirst;
    farPaths.push_back(pf.voxels);
  }
  EXPECT_EQ(farPaths[0], farPaths[1]);
}

TEST(CrossingRetrace, APathGivenASharedStretchIsCheckedBeyondIt) {
  // The kissing pair with B run on to x 160, and D, which forks from B at x 90, bends away and comes
  // back to touch B (no gap) from x 114 on. The search's route laid along A, across into B (the first
  // contact), along B and across into D (the second). The path to B's x 79 is searched again across
  // the first contact; the path to D's end takes that replacement (one trunk) and must still have its
  // own crossing into D searched again (issue 21, session 24: it skipped its own checks).
  std::vector<Segment> all = kissingPair(), d = kissingB();
  const double yB = 20 + 2.5 + 2, yD = yB + 2 + 2;
  all.push_back({{80, yB, 8}, {160, yB, 8}, 2});
  d.back().b = Vec3(90, yB, 8);  // B up to D's fork, then D
  d.push_back({{90, yB, 8}, {96, yB + 10, 8}, 2});
  d.push_back({{96, yB + 10, 8}, {104, yB + 10, 8}, 2});
  d.push_back({{104, yB + 10, 8}, {114, yD, 8}, 2});
  d.push_back({{114, yD, 8}, {150, yD, 8}, 2});
  all.insert(all.end(), d.end() - 4, d.end());
  NodeCost3D cost = tubeCost({166, 44, 16}, all);
  const std::vector<Index3> route =
      chain({{4, 20, 8}, {55, 20, 8}, {59, 24, 8}, {120, 24, 8}, {124, 28, 8}, {148, 28, 8}});
  ASSERT_GT(voxelsOutside(d, route), 40);
  for (const Index3& v : route) cost.node[static_cast<size_t>(cost.geometry.linear(v[0], v[1], v[2]))] = 0.00095f;
  const VolumeF32 intensities(cost.geometry, 0.0f);
  const Index3 onB{79, 24, 8}, onD{148, 28, 8};
  for (const bool bFirst : {true, false}) {
    VesselTracker tr(intensities, cost, {4, 20, 8});
    tr.addTarget(bFirst ? onB : onD);
    tr.addTarget(bFirst ? onD : onB);
    const TracedPath& pb = tr.paths()[bFirst ? 0 : 1];
    const TracedPath& pd = tr.paths()[bFirst ? 1 : 0];
    ASSERT_TRUE(pb.reached && pd.reached);
    EXPECT_TRUE(pb.retraced && pd.retraced);
    EXPECT_EQ(voxelsOutside(kissingB(), pb.voxels), 0) << "B first " << bFirst;
    EXPECT_EQ(voxelsOutside(d, pd.voxels), 0) << "B first " << bFirst;
    // One trunk: the path to B's x 79 is the start of the path to D.
    ASSERT_LE(pb.voxels.size(), pd.voxels.size());
    EXPECT_TRUE(std::equal(pb.voxels.begin(), pb.voxels.end(), pd.voxels.begin())) << "B first " << bFirst;
    EXPECT_NEAR(pd.cost, chainCost(cost, pd.voxels), 1e-9);
  }
}

TEST(CrossingRetrace, AStepInsideOneWideLumenIsNoCrossing) {
  // One wide tube (radius 7) whose lumen cost is patchy: one voxel in seven above the level, as in
  // a wide sinus whose intensity lies near the lumen level (issue 21, the head CTA's jugular bulb).
  // A path along it steps 3 voxels sideways: the lumen through the step, its holes bridged, is far
  // wider than the step both along and across it, so it is no crossing and the path is kept.
  NodeCost3D cost = tubeCost({90, 40, 24}, {{{0, 20, 12}, {89, 20, 12}, 7}});
  const Geometry& g = cost.geometry;
  for (int64_t z = 0; z < 24; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 90; ++x)
        if ((x + 2 * y + 3 * z) % 7 == 0) cost.node[static_cast<size_t>(g.linear(x, y, z))] = 1;
  const std::vector<Index3> path = chain({{4, 20, 12}, {40, 20, 12}, {42, 23, 12}, {84, 23, 12}});
  ASSERT_EQ(findLateralSteps(g, path).size(), 1u);  // a sideways step of the path alone
  CrossingOptions before;
  before.oneLumenSteps = 0;  // the test without the lumen's extent (main before session 24) takes it
  ASSERT_EQ(findLateralSteps(g, path, before, &cost, 0.2).size(), 1u);
  EXPECT_TRUE(findLateralSteps(g, path, {}, &cost, 0.2).empty());
  const CrossingRetrace r = retraceAcrossCrossings(cost, path, 26, 0.2);
  EXPECT_FALSE(r.changed);
  EXPECT_EQ(r.steps, 0);
}

TEST(CrossingRetrace, StraightAndObliqueChainsHaveNoSidewaysStep) {
  Geometry g;
  g.dims = {100, 100, 100};
  g.spacing = Vec3(0.7, 0.7, 1.5);
  std::vector<Index3> straight, oblique;
  for (int64_t i = 0; i < 60; ++i) {
    straight.push_back({10 + i, 50, 50});
    oblique.push_back({10 + i, 20 + (i * 2) / 5, 40 + i / 7});  // a staircase at ~22 degrees
  }
  EXPECT_TRUE(findLateralSteps(g, straight).empty());
  EXPECT_TRUE(findLateralSteps(g, oblique).empty());
  // The same chain with a 4-voxel sideways jump in 3 steps half-way has one, across it.
  std::vector<Index3> jump;
  for (int64_t i = 0; i < 60; ++i) jump.push_back({10 + i, 50 + std::clamp<int64_t>(i - 29, 0, 4), 50});
  const std::vector<LateralStep> s = findLateralSteps(g, jump);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_GT(s[0].normal[1], 0.9);
  EXPECT_NEAR(s[0].lateralMm, 4 * 0.7, 0.75);
}

}  // namespace
}  // namespace vs
