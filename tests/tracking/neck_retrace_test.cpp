// Kissing drifts (tracking/neck_retrace.h): a path that crosses gradually from one tube into a
// touching one, with no sideways step in its cost, is searched again with the neck between the
// smoothed intensity's two lobes blocked; a tube's own hairpin is no crossing.
#include "tracking/neck_retrace.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "kissing_tubes.h"
#include "tracking/neck_sections.h"

namespace vs {
namespace {

using namespace test_tubes;  // the kissing tubes (kissing_tubes.h)

// Bright tubes whose intensity falls from the axis (a Gaussian of 0.7 x the radius), the larger of
// the tubes' values where they touch: two peaks with a neck between, as the smoothed image shows.
// The tubes in mm, voxels `spacing` apart.
VolumeF32 tubeIntensity(const Index3& dims, const std::vector<Segment>& tubes, const Vec3& spacing = Vec3(1, 1, 1)) {
  Geometry g;
  g.dims = dims;
  g.spacing = spacing;
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x) {
        double best = 0;
        for (const Segment& s : tubes) {
          const double d =
              distanceToSegment(s, Vec3(double(x), double(y), double(z)).cwiseProduct(spacing)) / (0.7 * s.r);
          best = std::max(best, 100 * std::exp(-0.5 * d * d));
        }
        v.data()[g.linear(x, y, z)] = static_cast<float>(best);
      }
  return v;
}

// The crossing options with the neck re-search on: it reads its sections in the smoothed intensities.
CrossingOptions onSmoothed(const VolumeF32& smoothed) {
  CrossingOptions o;
  o.smoothed = &smoothed;
  return o;
}

TEST(NeckRetrace, DriftAcrossTheNeckIsSearchedAgainFromBeforeTheFork) {
  // A (radius 2.5) goes straight on from the trunk; B (radius 2) bends away and comes back to touch
  // A (no gap) from x 44 to 80. The path to B's end takes A to x 55 and crosses the contact into B.
  // The neck, blocked along the two-lobe stretch, leaves B's own bend as the only route.
  const std::vector<Segment> b = kissingB(), all = kissingPair();
  const Index3 dims{90, 40, 16};
  const NodeCost3D cost = tubeCost(dims, all);
  const VolumeF32 smoothed = tubeIntensity(dims, all);
  const std::vector<Index3> drift = chain({{4, 20, 8}, {55, 20, 8}, {59, 24, 8}, {79, 24, 8}});
  auto offB = [&](const std::vector<Index3>& p) { return voxelsOutside(b, p); };
  ASSERT_GT(offB(drift), 20);
  CrossingOptions o = onSmoothed(smoothed);
  const NeckRetrace r = retraceAcrossNeck(cost, drift, 26, o);
  EXPECT_EQ(r.crossings, 1);
  ASSERT_TRUE(r.changed) << r.why;
  EXPECT_EQ(r.voxels.front(), drift.front());
  EXPECT_EQ(r.voxels.back(), drift.back());
  EXPECT_LE(offB(r.voxels), 2);
  EXPECT_LE(r.newCost, 1.25 * r.oldCost);
  // A's own path (straight along A) holds no crossing: kept as it is.
  const std::vector<Index3> alongA = chain({{4, 20, 8}, {84, 20, 8}});
  const NeckRetrace ra = retraceAcrossNeck(cost, alongA, 26, o);
  EXPECT_EQ(ra.crossings, 0);
  EXPECT_FALSE(ra.changed);
  // Without the smoothed intensities the test is off.
  EXPECT_FALSE(retraceAcrossNeck(cost, drift, 26, CrossingOptions{}).changed);
}

TEST(NeckRetrace, AContactReadingAsBackgroundInTheCostIsKeptToByIntensity) {
  // Session 31 (11407): B's contact stretch before the crossing (x 44-54) costs as background (a
  // tube half-way between two thick slices under a bias field), so every route round the blocked
  // neck costs far more than the old part (A, then B past the crossing) and the cost slack refuses
  // it; the smoothed intensity still shows B there.
  const std::vector<Segment> b = kissingB(), all = kissingPair();
  const Index3 dims{90, 40, 16};
  NodeCost3D cost = tubeCost(dims, all);
  const Segment contact = b.back(), a = all.back();
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x) {
        const Vec3 p = at({x, y, z});
        if (x <= 54 && distanceToSegment(contact, p) <= contact.r && distanceToSegment(a, p) > a.r)
          cost.node[static_cast<size_t>(cost.geometry.linear(x, y, z))] = 1.0f;
      }
  const VolumeF32 smoothed = tubeIntensity(dims, all);
  const std::vector<Index3> drift = chain({{4, 20, 8}, {55, 20, 8}, {59, 24, 8}, {79, 24, 8}});
  ASSERT_GT(voxelsOutside(b, drift), 20);
  CrossingOptions o = onSmoothed(smoothed);
  EXPECT_FALSE(retraceAcrossNeck(cost, drift, 26, o).changed);  // the cost slack alone refuses it
  o.neckByIntensity = true;
  const NeckRetrace r = retraceAcrossNeck(cost, drift, 26, o);
  ASSERT_TRUE(r.changed) << r.why;
  EXPECT_EQ(r.voxels.front(), drift.front());
  EXPECT_EQ(r.voxels.back(), drift.back());
  EXPECT_LE(voxelsOutside(b, r.voxels), 2);
  EXPECT_GT(r.newCost, 1.25 * r.oldCost);  // beyond the slack: taken by intensity
}

TEST(NeckRetrace, TheLastOfTheLobeChangesIsTheCrossing) {
  // The path to B's end takes A, touches B at x 47-54 and comes back, then crosses into B at x 60-64
  // (seed 517: the first change is a touch; searching to just past it ends in A again).
  const std::vector<Segment> b = kissingB(), all = kissingPair();
  const Index3 dims{90, 40, 16};
  const NodeCost3D cost = tubeCost(dims, all);
  const VolumeF32 smoothed = tubeIntensity(dims, all);
  const std::vector<Index3> drift =
      chain({{4, 20, 8}, {46, 20, 8}, {49, 24, 8}, {52, 24, 8}, {55, 20, 8}, {60, 20, 8}, {64, 24, 8}, {79, 24, 8}});
  ASSERT_GT(voxelsOutside(b, drift), 20);
  CrossingOptions o = onSmoothed(smoothed);
  const NeckRetrace r = retraceAcrossNeck(cost, drift, 26, o);
  EXPECT_EQ(r.crossings, 1);
  ASSERT_TRUE(r.changed) << r.why;
  EXPECT_LE(voxelsOutside(b, r.voxels), 2);
}

TEST(NeckRetrace, TubesTouchingAcrossThickSlicesTheTubeLeftIsBlocked) {
  // Session 22 (10507, 10404): 2 mm slices; B (radius 2) bends up from the fork and comes back onto
  // A (radius 2.5) from above, touching it (no gap) from x 44 to 80 mm: the axes lie 2.25 slices
  // apart, and no band across the neck is both closed to 26-steps and clear of B. The path to B's
  // end takes A from the fork to x 55 and climbs into B. The tube left, blocked before the
  // crossing, leaves B's own bend as the route.
  const Vec3 sp(1, 1, 2);
  const double zA = 16, zB = zA + 2.5 + 2;
  const std::vector<Segment> b{{{2, 20, zA}, {20, 20, zA}, 3},
                               {{20, 20, zA}, {26, 20, 30}, 2},
                               {{26, 20, 30}, {34, 20, 30}, 2},
                               {{34, 20, 30}, {44, 20, zB}, 2},
                               {{44, 20, zB}, {80, 20, zB}, 2}};
  std::vector<Segment> all = b;
  all.push_back({{20, 20, zA}, {86, 20, zA}, 2.5});
  const Index3 dims{90, 40, 20};
  const NodeCost3D cost = tubeCost(dims, all, sp);
  const VolumeF32 smoothed = tubeIntensity(dims, all, sp);
  const std::vector<Index3> drift = chain({{4, 20, 8}, {55, 20, 8}, {57, 20, 10}, {79, 20, 10}});
  const auto offB = [&](const std::vector<Index3>& p) {
    std::vector<Index3> mm;  // voxelsOutside takes voxel places as mm: scale z
    for (const Index3& v : p) mm.push_back({v[0], v[1], 2 * v[2]});
    return voxelsOutside(b, mm);
  };
  ASSERT_GT(offB(drift), 20);
  CrossingOptions o = onSmoothed(smoothed);
  const NeckRetrace r = retraceAcrossNeck(cost, drift, 26, o);
  ASSERT_TRUE(r.changed) << r.why;
  EXPECT_EQ(r.voxels.front(), drift.front());
  EXPECT_EQ(r.voxels.back(), drift.back());
  EXPECT_LE(offB(r.voxels), 2);
  EXPECT_LE(r.newCost, 1.25 * r.oldCost);
  // A's own path is kept.
  EXPECT_FALSE(retraceAcrossNeck(cost, chain({{4, 20, 8}, {84, 20, 8}}), 26, o).changed);
}

TEST(NeckRetrace, ATubesOwnHairpinIsNoNeckCrossing) {
  // One tube (radius 2) runs along x, turns back and runs along x again 5 voxels beside itself:
  // the two limbs are two lobes in the sections, and passing the turn moves the own lobe to where
  // the other was - but the path turns back, a drift across a neck goes on.
  const std::vector<Segment> tube{
      {{4, 20, 8}, {60, 20, 8}, 2}, {{60, 20, 8}, {60, 25, 8}, 2}, {{60, 25, 8}, {4, 25, 8}, 2}};
  const Index3 dims{70, 40, 16};
  const NodeCost3D cost = tubeCost(dims, tube);
  const VolumeF32 smoothed = tubeIntensity(dims, tube);
  const std::vector<Index3> path = chain({{4, 20, 8}, {60, 20, 8}, {60, 25, 8}, {10, 25, 8}});
  CrossingOptions o = onSmoothed(smoothed);
  const NeckRetrace r = retraceAcrossNeck(cost, path, 26, o);
  EXPECT_EQ(r.crossings, 0);
  EXPECT_FALSE(r.changed);
}

TEST(NeckRetrace, AThirdTubeOnTheFarSideIsNoLobeChange) {
  // Session 40 (sep41, head CTA 40,113,41's sinus): the path runs along a wide tube A (radius 3);
  // a thin tube N (radius 1) touches A on one side, then leaves the section, and a third thin tube
  // T comes in on the far side. A's axis steps a voxel sideways where they swap (the sinus's own lobe
  // moved 0.75 mm): the places' test reads the section's other lobe jumping across as the path's
  // lobe changing. The path's lobe stays on its disc and of its size: a third structure, not a
  // crossing - no try takes it for one and the path is kept.
  const std::vector<Segment> tubes{{{4, 20, 10}, {42, 20, 10}, 3},  {{42, 20, 10}, {44, 20, 11}, 3},
                                   {{44, 20, 11}, {84, 20, 11}, 3}, {{10, 16, 10}, {40, 16, 10}, 1},
                                   {{40, 16, 10}, {44, 2, 10}, 1},  {{44, 38, 11}, {48, 24, 11}, 1},
                                   {{48, 24, 11}, {80, 24, 11}, 1}};
  const Index3 dims{90, 40, 22};
  const NodeCost3D cost = tubeCost(dims, tubes);
  const VolumeF32 smoothed = tubeIntensity(dims, tubes);
  const std::vector<Index3> path = chain({{4, 20, 10}, {42, 20, 10}, {44, 20, 11}, {84, 20, 11}});
  CrossingOptions o = onSmoothed(smoothed);
  const NeckRetrace r = retraceAcrossNeck(cost, path, 26, o);
  EXPECT_FALSE(r.changed);
  EXPECT_EQ(r.why.find("own tube"), std::string::npos) << r.why;
  EXPECT_EQ(r.why.find("unlike tubes"), std::string::npos) << r.why;
}

// Session 43 (lazyA4): a section reads only the smoothed volume, the lumen's sign and three of the route's points
// (neck_sections.h), so the tracker keeps the sections it has read and reads each once - the neck re-search held to the
// cost, then to the intensity, and the width reading (retraceByWidth) read one route's sections three times on main,
// and a new route shares all but its re-searched stretch with the old one. With a memo every answer is the one without
// it, and a second reading of the same route reads no section again.
TEST(NeckRetrace, SectionsReadOnceForEveryReadingOfARoute) {
  const std::vector<Segment> all = kissingPair();
  const Index3 dims{90, 40, 16};
  const NodeCost3D cost = tubeCost(dims, all);
  const VolumeF32 smoothed = tubeIntensity(dims, all);
  const std::vector<Index3> drift = chain({{4, 20, 8}, {55, 20, 8}, {59, 24, 8}, {79, 24, 8}});
  CrossingOptions o = onSmoothed(smoothed);
  NeckSectionMemo memo;
  CrossingOptions m = o;
  m.neckSections = &memo;
  const NeckRetrace a = retraceAcrossNeck(cost, drift, 26, o), b = retraceAcrossNeck(cost, drift, 26, m);
  ASSERT_TRUE(a.changed) << a.why;
  EXPECT_EQ(a.changed, b.changed);
  EXPECT_EQ(a.voxels, b.voxels);
  EXPECT_EQ(a.newCost, b.newCost);
  EXPECT_EQ(a.crossings, b.crossings);
  EXPECT_EQ(a.why, b.why);
  const int64_t read = memo.read;
  EXPECT_GE(read, int64_t(drift.size()));                    // the old route's sections and the new one's stretch
  EXPECT_LT(read, int64_t(drift.size() + a.voxels.size()));  // the new route's shared points not read again
  for (const std::vector<Index3>& route : {drift, a.voxels}) {
    const std::vector<LobeWidths> wa = lobeWidthsAlong(route, o), wb = lobeWidthsAlong(route, m);
    ASSERT_EQ(wa.size(), wb.size());
    for (size_t i = 0; i < wa.size(); ++i) {
      EXPECT_EQ(wa[i].two, wb[i].two) << i;
      EXPECT_EQ(wa[i].rOwn, wb[i].rOwn) << i;
      EXPECT_EQ(wa[i].rOther, wb[i].rOther) << i;
      EXPECT_EQ(wa[i].own, wb[i].own) << i;
      EXPECT_EQ(wa[i].other, wb[i].other) << i;
      EXPECT_EQ(wa[i].t, wb[i].t) << i;
    }
    EXPECT_EQ(tubeWidthChanges(route, o), tubeWidthChanges(route, m));
  }
  EXPECT_EQ(memo.read, read);  // the width readings of both routes found every section read by the re-search
  EXPECT_GT(memo.reused, 0);
  for (const std::vector<Index3>& route : {drift, a.voxels}) {
    const RetraceOutcome wo = retraceByWidth(cost, route, 26, o), wm = retraceByWidth(cost, route, 26, m);
    EXPECT_EQ(wo.changed, wm.changed);
    EXPECT_EQ(wo.voxels, wm.voxels);
    EXPECT_EQ(wo.why, wm.why);
  }
}

}  // namespace
}  // namespace vs
