// A re-search's new stretch that starts by running back along the route kept before it (tracker.cpp,
// cutRetracedStart; issue 21, session 48 held17): the route is joined to the stretch where the stretch leaves the
// kept route, not after the loop out and back.
#include <gtest/gtest.h>

#include "family_trace.h"

namespace vs {
namespace {

// Tuning-grade seed 17401 (scan given, thin, 0.93 x 0.93 x 1.90 mm): the search to path 2's terminal
// hopped through the background from the tip of a sibling's branch; the support re-search, searching again from that
// tip, went back down the sibling to where the routes part and on along the own branch - the path ran 20 voxels out
// along the sibling and back (90.1 % within 1 voxel, mean 1.160, 42 points on a neighbour). Joined where the new
// stretch leaves the kept route: 98.5 %, mean 0.116.
TEST(RetracedStart, LaterRoundsStretchBackAlongTheKeptRouteCut) {
  const PointFigures p = tracedFigures("retraced start", 17401, VesselFamilyVariant::Thin, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
  EXPECT_LE(p.meanVox, 0.3);
}

// Tuning-grade seed 17712 (scan given, parallel, 0.61 x 0.61 x 1.72 mm): path 1's route ran 6 voxels into the
// neighbour tube; the lateral-step re-search replaced the stretch from there, its new stretch going back 4 voxels
// along the kept route before stepping down into the own tube (95.2 % within 1 voxel, mean 0.312, 7 points on a
// neighbour). Joined where the stretch leaves the kept route: 98.9 %, mean 0.146.
TEST(RetracedStart, FirstRoundsStretchBackAlongTheKeptRouteCut) {
  const PointFigures p = tracedFigures("retraced start", 17712, VesselFamilyVariant::Parallel, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
  EXPECT_LE(p.meanVox, 0.3);
}

}  // namespace
}  // namespace vs
