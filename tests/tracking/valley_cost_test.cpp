// The valley term of the auto cost (tracking/valley_cost.h): the dip between two tubes that
// touch is not lumen, so a path keeps to its own tube instead of jumping through the contact.
#include "tracking/valley_cost.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "phantom/phantom.h"
#include "tracking/trace_run.h"
#include "tube_segments.h"

namespace vs {
namespace {

using test_tubes::distanceToPolyline;
using test_tubes::distanceToSegment;
using test_tubes::drawTubes;
using test_tubes::Segment;

// A trunk splits into A (straight on, radius 2.5) and B (radius 2), which bends away and comes
// back to run beside A with a surface gap of 0.3 voxel for 30 voxels, then leaves: through the
// contact B's end is 20 voxels closer than along B.
struct Kissing {
  std::vector<Segment> a, b;  // A's and B's own tubes (the trunk in both)
  Index3 root{6, 20, 12}, endA{84, 20, 12}, endB{80, 36, 12};
};

Kissing kissing() {
  Kissing k;
  const Segment trunk{{2, 20, 12}, {20, 20, 12}, 3};
  const double yB = 20 + 2.5 + 0.3 + 2;  // A's radius + gap + B's radius
  k.a = {trunk, {{20, 20, 12}, {86, 20, 12}, 2.5}};
  k.b = {trunk,
         {{20, 20, 12}, {30, 32, 12}, 2},
         {{30, 32, 12}, {40, yB, 12}, 2},
         {{40, yB, 12}, {70, yB, 12}, 2},
         {{70, yB, 12}, {80, 36, 12}, 2}};
  return k;
}

TEST(ValleyCost, TheDipBetweenTwoTouchingTubesIsDeeperThanInsideEither) {
  const Kissing k = kissing();
  std::vector<Segment> all = k.a;
  all.insert(all.end(), k.b.begin() + 1, k.b.end());
  const VolumeF32 v = drawTubes({90, 42, 24}, all, 300, 40, 0, 1);
  const std::vector<RingScale> scales = ringScalesFor(v.geometry(), 1, 2);
  const double inf = 1e300;
  // In the contact (x 55, y between the tubes) against the axis of A and of B.
  const double contact = valleyDepth(v, scales, 55, 23, 12, true, inf);
  EXPECT_GT(contact, 30);
  EXPECT_LE(valleyDepth(v, scales, 55, 20, 12, true, inf), 1e-3);
  EXPECT_LE(valleyDepth(v, scales, 55, 25, 12, true, inf), 1e-3);
  // A wall (one side background) and the background are no valley.
  EXPECT_LE(valleyDepth(v, scales, 55, 17, 12, true, inf), 1e-3);
  EXPECT_LE(valleyDepth(v, scales, 55, 8, 12, true, inf), 1e-3);
  // Dark polarity: the same ridge with the values negated.
  VolumeF32 d = v;
  for (int64_t i = 0; i < d.geometry().voxelCount(); ++i) d.data()[i] = -d.data()[i];
  EXPECT_NEAR(valleyDepth(d, scales, 55, 23, 12, false, inf), contact, 1e-3);
  // capByValley: no cap without depth, none where s is 0, full cap at lo + span.
  EXPECT_EQ(capByValley(v, scales, 55, 20, 12, true, 0.9, 10, 50), 0.9);
  EXPECT_EQ(capByValley(v, scales, 55, 23, 12, true, 0, 10, 50), 0.0);
  EXPECT_EQ(capByValley(v, scales, 55, 23, 12, true, 1, 0, contact / 2), 0.0);
}

TEST(ValleyCost, BsPathStaysInBWhereTheTubesKiss) {
  const Kissing k = kissing();
  std::vector<Segment> all = k.a;
  all.insert(all.end(), k.b.begin() + 1, k.b.end());
  const VolumeF32 v = drawTubes({90, 42, 24}, all, 300, 40, 12, 7);
  TraceRequest rq;
  rq.root = k.root;
  rq.targets = {k.endA, k.endB};
  auto pointsOnA = [&](const TraceResult& r) {
    // B's refined points more than 1 voxel from B's centreline and within 1.5 of A's (A's own
    // part: past the split).
    int n = 0;
    for (const Vec3& p : r.points[1])
      n += p[0] > 24 && distanceToPolyline(k.b, p) > 1 && distanceToSegment(k.a[1], p) <= 1.5;
    return n;
  };
  const TraceResult r = runTrace(v, rq);
  ASSERT_EQ(r.paths.size(), 2u);
  ASSERT_TRUE(r.paths[0].reached && r.paths[1].reached);
  EXPECT_EQ(pointsOnA(r), 0);
  double worst = 0;
  for (const Vec3& p : r.points[1]) worst = std::max(worst, distanceToPolyline(k.b, p));
  EXPECT_LT(worst, 1.5);
  for (const Vec3& p : r.points[0]) EXPECT_LT(distanceToPolyline(k.a, p), 1.5);
  // Without the valley term B's path takes the shortcut through the contact. The re-searches off too:
  // since session 25 (kiss20) the neck re-search finds this crossing where the tubes part and searches
  // round it (no point on A without the valley term either); the control measures the term alone.
  rq.options.autoCost.valleyVoxels = 0;
  rq.options.tracker.crossing.enabled = false;
  const TraceResult without = runTrace(v, rq);
  ASSERT_EQ(without.paths.size(), 2u);
  EXPECT_GT(pointsOnA(without), 5);
}

}  // namespace
}  // namespace vs
