// Tests for tracking/terminal_gaps.cpp (issue 21): an automatic terminal's route across the background between two
// vessels of a masked volume that the smoothed cost's lumen region joins (the head CTA's routes across zero voxels).
#include "tracking/terminal_gaps.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "tracking/trace_run.h"
#include "tube_segments.h"

using namespace vs;

namespace {

// A vessel-only (masked) volume, 0.55 x 0.55 x 1 mm like the head CTA: vessel A (radius 1.6 mm) along y at x = 32,
// z = 20 from the root's end y = 8 to y = 56; vessel B (radius 0.9 mm) along x at y = 32, z = 20, from x = 36 to 62.
// A's wall ends at x = 34, B's at x = 36: one zero voxel (x = 35) between them, no voxel of one touching the other.
VolumeF32 twoVesselsOneVoxelApart() {
  Geometry g;
  g.dims = {64, 64, 40};
  g.spacing = Vec3(0.55, 0.55, 1.0);
  VolumeF32 v(g, 0.0f);
  using test_tubes::Segment;
  const Segment a{Vec3(32, 8, 20).cwiseProduct(g.spacing), Vec3(32, 56, 20).cwiseProduct(g.spacing), 1.6},
      b{Vec3(37, 32, 20).cwiseProduct(g.spacing), Vec3(62, 32, 20).cwiseProduct(g.spacing), 0.9};
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const Vec3 p =
            Vec3(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)).cwiseProduct(g.spacing);
        if (test_tubes::distanceToSegment(a, p) <= a.r || (x >= 36 && test_tubes::distanceToSegment(b, p) <= b.r))
          v(x, y, z) = 150.0f;
      }
  return v;
}

}  // namespace

TEST(TerminalGaps, ARouteAcrossAZeroVoxelBetweenTwoVesselsHasAGap) {
  const VolumeF32 v = twoVesselsOneVoxelApart();
  ASSERT_EQ(v(35, 32, 20), 0.0f);
  std::vector<Index3> route;
  for (int64_t y = 10; y <= 32; ++y) route.push_back({32, y, 20});
  for (int64_t x = 33; x <= 60; ++x) route.push_back({x, 32, 20});
  const auto gaps = routeGaps(v, route, 1, [](const Index3&) { return 0.9; });
  ASSERT_EQ(gaps.size(), 1u);
  EXPECT_EQ(route[gaps[0].index], (Index3{35, 32, 20}));
  EXPECT_GT(gaps[0].sign, 0);
  // Along A alone, and along a faint stretch at a third of the contrast: no gap (an end past the vessel is
  // terminal_end.h's).
  std::vector<Index3> alongA(route.begin(), route.begin() + 23);
  EXPECT_TRUE(routeGaps(v, alongA, 1, [](const Index3&) { return 1.6; }).empty());
  VolumeF32 faint = v;
  faint(35, 32, 20) = 50.0f;
  EXPECT_TRUE(routeGaps(faint, route, 1, [](const Index3&) { return 0.9; }).empty());
}

// End to end, defaults: B touches the root's vessel only through the smoothed cost's halo. No automatic terminal's
// path crosses the zero voxel into it; the notes say a route across background was cut.
TEST(TerminalGaps, NoAutomaticPathCrossesTheBackgroundBetweenTwoVesselsOfAMaskedVolume) {
  const VolumeF32 v = twoVesselsOneVoxelApart();
  TraceRequest rq;
  rq.root = {32, 10, 20};
  rq.autoTerminals = 2;
  const TraceResult r = runTrace(v, rq);
  ASSERT_GE(r.paths.size(), 1u);
  for (const TracedPath& p : r.paths)
    for (const Index3& q : p.voxels) EXPECT_GT(v(q[0], q[1], q[2]), 0.0f) << q[0] << "," << q[1] << "," << q[2];
  bool said = false;
  for (const std::string& n : r.notes) said = said || n.find("across background") != std::string::npos;
  EXPECT_TRUE(said) << "the notes do not say a route across background was cut";
}
