// Parallel tubes a slice apart (tracking/dip_retrace.h): a path that runs along a bright tube and
// jumps the background into a faded neighbour one slice away is searched again among the voxels
// brighter than the dip, so it follows the faded tube from their fork.
#include "tracking/dip_retrace.h"

#include <gtest/gtest.h>

#include <vector>

namespace vs {
namespace {

// Slices 2.4 mm thick, 1 mm in plane. B along y in slice 3 (smoothed 150), A along y in slice 6
// (smoothed 100) from their fork at y 10 (slices 4 and 5 join them there); tissue 30 elsewhere.
// A's node cost is the background's from y 20 to 45 (its local background taken from B), the
// rest of both tubes lumen; the gap between them one slice of tissue but at y 50, where it is
// dark (35) and costs as background too.
struct Pair {
  Geometry g;
  NodeCost3D cost;
  VolumeF32 smoothed;
  void set(int64_t y, int64_t z, float s, float c) {
    smoothed.data()[g.linear(10, y, z)] = s;
    cost.node[static_cast<size_t>(g.linear(10, y, z))] = c;
  }
};

// Tissue with B, the fork's two slices at y 10 and the dark gap at y 50-51 (A left to the caller).
Pair bAndGap(int64_t slices) {
  Pair p;
  p.g.dims = {20, 60, slices};
  p.g.spacing = Vec3(1.0, 1.0, 2.4);
  p.cost.kind = CostKind3D::Given;
  p.cost.geometry = p.g;
  p.cost.node.assign(static_cast<size_t>(p.g.voxelCount()), 1.0f);
  p.smoothed = VolumeF32(p.g, 30.0f);
  for (int64_t y = 0; y < 60; ++y) p.set(y, 3, 150, 0.001f);
  p.set(10, 4, 120, 0.001f);
  p.set(10, 5, 120, 0.001f);
  p.set(50, 4, 35, 1.0f);
  p.set(51, 5, 35, 1.0f);
  return p;
}

Pair parallelPair() {
  Pair p = bAndGap(10);
  for (int64_t y = 10; y < 60; ++y) p.set(y, 6, 100, y >= 20 && y <= 45 ? 1.0f : 0.001f);
  return p;
}

std::vector<Index3> line(int64_t x, int64_t y0, int64_t y1, int64_t z) {
  std::vector<Index3> v;
  for (int64_t y = y0; y <= y1; ++y) v.push_back({x, y, z});
  return v;
}

// The minimal path to A's end (y endY): along B to y 49, through the dark gap (y 50-51), then A.
std::vector<Index3> jumpIntoA(int64_t endY) {
  std::vector<Index3> jump = line(10, 0, 49, 3);
  jump.push_back({10, 50, 4});
  jump.push_back({10, 51, 5});
  for (const Index3& v : line(10, 52, endY, 6)) jump.push_back(v);
  return jump;
}

// The dip re-search on `jump`: one dip, the path changed between the same ends.
DipRetrace retracedJump(const Pair& p, const std::vector<Index3>& jump) {
  CrossingOptions o;
  o.smoothed = &p.smoothed;
  DipRetrace r = retraceAcrossDip(p.cost, jump, 26, 0.2, o);
  EXPECT_EQ(r.dips, 1);
  EXPECT_TRUE(r.changed) << r.why;
  if (r.changed) {
    EXPECT_EQ(r.voxels.front(), jump.front());
    EXPECT_EQ(r.voxels.back(), jump.back());
  }
  return r;
}

TEST(DipRetrace, AJumpThroughTheGapIntoAFadedTubeIsSearchedAgainAlongIt) {
  const Pair p = parallelPair();
  const std::vector<Index3> jump = jumpIntoA(59);
  const DipRetrace r = retracedJump(p, jump);
  if (!r.changed) return;
  // The new path runs in A from the fork: every voxel past y 12 lies in slice 6.
  int offA = 0;
  for (const Index3& v : r.voxels) offA += v[1] > 12 && v[2] != 6;
  EXPECT_EQ(offA, 0);
  // Without the smoothed intensities the test is off.
  EXPECT_FALSE(retraceAcrossDip(p.cost, jump, 26, 0.2, CrossingOptions{}).changed);
}

TEST(DipRetrace, APathAlongItsOwnTubeOrWithNoBrighterRouteIsKept) {
  const Pair p = parallelPair();
  CrossingOptions o;
  o.smoothed = &p.smoothed;
  // B's own path: no dip.
  const DipRetrace rb = retraceAcrossDip(p.cost, line(10, 0, 59, 3), 26, 0.2, o);
  EXPECT_EQ(rb.dips, 0);
  EXPECT_FALSE(rb.changed);
  // A's own path, its faded stretch dear but as bright as its ends: no dip either.
  std::vector<Index3> alongA = line(10, 0, 9, 3);
  alongA.push_back({10, 10, 4});
  alongA.push_back({10, 10, 5});
  for (const Index3& v : line(10, 11, 59, 6)) alongA.push_back(v);
  EXPECT_FALSE(retraceAcrossDip(p.cost, alongA, 26, 0.2, o).changed);
  // Without A's stretch before the gap (a single tube that narrows to tissue for a voxel), there
  // is no brighter route: the path is kept.
  Pair q = parallelPair();
  for (int64_t y = 10; y < 50; ++y) q.smoothed.data()[q.g.linear(10, y, 6)] = 30.0f;
  const std::vector<Index3> jump = jumpIntoA(59);
  o.smoothed = &q.smoothed;
  const DipRetrace rq = retraceAcrossDip(q.cost, jump, 26, 0.2, o);
  EXPECT_EQ(rq.dips, 1);
  EXPECT_FALSE(rq.changed);
}

// Session 23 (10311): the two tubes also touch between their fork and the gap. A leaves the fork
// (y 10) upwards (slice 8, out of reach across the gap), comes down beside B (slice 6 from y 25)
// and touches it at y 34-36 (slices 4 and 5 as bright as A there, dear as background); A's cost
// is the background's from y 20 to 45. Above the bottleneck the cheapest route runs along B and
// crosses where the tubes touch; with B blocked back from the gap while A lies across one from
// it (the touch bridged), the route follows A from the fork.
TEST(DipRetrace, WhereTheTubesAlsoTouchTheTubeLeftIsBlockedBackToTheFork) {
  Pair p = bAndGap(12);
  const auto zA = [](int64_t y) -> int64_t { return y == 11 ? 6 : y == 12 || y == 24 ? 7 : y < 24 ? 8 : 6; };
  for (int64_t y = 11; y < 60; ++y) p.set(y, zA(y), 100, y >= 20 && y <= 45 ? 1.0f : 0.001f);
  for (int64_t y = 34; y <= 36; ++y) p.set(y, 4, 100, 1.0f), p.set(y, 5, 100, 1.0f);
  const DipRetrace r = retracedJump(p, jumpIntoA(59));
  if (!r.changed) return;
  // Past the fork the new path keeps to A: no voxel in B's slice or the touch's.
  int offA = 0;
  for (const Index3& v : r.voxels) offA += v[1] > 11 && v[2] != zA(v[1]);
  EXPECT_EQ(offA, 0);
}

// Session 23 (10403): a gap two points before the path's end (the terminal just inside the faded
// tube) is a dip too: its flank after the gap is the points there are.
TEST(DipRetrace, AGapJustBeforeThePathsEndIsFound) { retracedJump(parallelPair(), jumpIntoA(52)); }

// Session 30 (kiss30, 11407): a jump through more tissue than the flanks' dipSteps points reach
// (the path ran its bright tube to the end and crossed 8 points outside the lumen to the faded
// tube's last points) is a dip too: its flanks are counted from the gap's ends.
TEST(DipRetrace, AGapLongerThanTheFlanksIsFound) {
  const Pair p = parallelPair();
  std::vector<Index3> jump = line(10, 0, 49, 3);
  // 8 points outside the lumen: none of them has lumen within 4 points on both sides.
  for (const Index3& v : {Index3{11, 50, 3}, Index3{12, 51, 3}, Index3{13, 52, 4}, Index3{13, 53, 4}, Index3{13, 54, 5},
                          Index3{12, 55, 5}, Index3{11, 56, 5}, Index3{11, 57, 6}})
    jump.push_back(v);
  for (const Index3& v : line(10, 58, 59, 6)) jump.push_back(v);
  const DipRetrace r = retracedJump(p, jump);
  if (!r.changed) return;
  int offA = 0;  // the new path runs in A from the fork, as above
  for (const Index3& v : r.voxels) offA += v[1] > 12 && v[2] != 6;
  EXPECT_EQ(offA, 0);
}

}  // namespace
}  // namespace vs
