// Session 36 (contact36): a run of points that no cast ever centred (too few chords in every round: the route runs
// along the wider tube's wall into a kissing contact, whose section is neither round nor closed) goes onto the line
// between its chain's centred points either side (uncentred_runs.cpp, lineUncentred).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "family_trace.h"
#include "test_tree.h"
#include "tracking/centreline_junctions.h"

namespace vs {
namespace {

// A chain along x (1 mm voxels, radius 2 mm) whose points 4-7 no cast centred: they sat on their path voxels 1.5 mm
// off the axis in y while the casts centred the rest on it.
struct WallRun : TestTree {
  std::vector<Vec3> raw;
  std::vector<uint8_t> frozen, cast;
  explicit WallRun(size_t branchAt = 0) {
    for (int x = 0; x <= 12; ++x) {
      const size_t k = q.size();
      const bool run = x >= 4 && x <= 7;
      add(static_cast<int32_t>(k) - 1, Vec3(x, run ? 1.5 : 0.0, 0), run ? 1.2 : 2.0);
      raw.emplace_back(x, run ? 1.5 : 0.4, 0);
      frozen.push_back(0), cast.push_back(k == 0 ? 0 : run ? 1 : 2);
    }
    if (branchAt > 0) {  // a side branch leaving there: that end is a fork, not the tube's own centred point
      add(static_cast<int32_t>(branchAt), Vec3(double(branchAt), -3, 0), 1.0);
      raw.push_back(q.back()), frozen.push_back(0), cast.push_back(2);
    }
  }
  size_t run(const CentrelineOptions& o) {
    const centreline_detail::JunctionInput in{parent, children, radius, [this](size_t k) { return raw[k]; }};
    return centreline_detail::lineUncentred(in, frozen, cast, o, Vec3(1, 1, 1), q, radius);
  }
};

TEST(UncentredRuns, RunBetweenCentredPointsGoesOntoTheirLine) {
  WallRun w;
  EXPECT_EQ(w.run({}), 4u);
  for (size_t k = 4; k <= 7; ++k) {
    EXPECT_NEAR(w.q[k][1], 0.0, 1e-9) << k;
    EXPECT_NEAR(w.radius[k], 2.0, 1e-9) << k;
  }
}

TEST(UncentredRuns, RunNextToAForkAPlacedPointOrABumpIsLeft) {
  WallRun fork(3);
  EXPECT_EQ(fork.run({}), 0u);
  WallRun placed;
  placed.frozen[8] = 1;
  EXPECT_EQ(placed.run({}), 0u);
  EXPECT_NEAR(placed.q[5][1], 1.5, 1e-9);
  WallRun blob;  // the far end's section 1.6x the near end's: a bump (a junction blob, a wider lumen), not the tube
  blob.radius[8] = 3.2;
  EXPECT_EQ(blob.run({}), 0u);
}

TEST(UncentredRuns, RunFartherThanTheReachOrOutsideTheLumenIsLeft) {
  CentrelineOptions o;
  o.lobeForkRadii = 1;  // each end reaches 2 mm along the path voxels: point 7 lies 4.5 mm from point 3
  WallRun far;
  EXPECT_EQ(far.run(o), 0u);
  WallRun wall;
  for (size_t k = 4; k <= 7; ++k) wall.raw[k][1] = 3.5;  // the line 3.5 mm from the voxels: radius 2 + 0.87 short
  EXPECT_EQ(wall.run({}), 0u);
}

// Tuning-grade given seed 11908 (kissing, dark, 0.82 x 0.82 x 1.14 mm): path 0's route runs along the wider tube's
// wall into the contact; its points 36-41 were never moved by a cast (rule 2 refused: the contact's section is not
// round) and stayed 2.9-3.3 voxels off the axis (main: 96.5 % within 1 voxel).
TEST(UncentredRuns, KissingContactRunGoesOntoTheWiderTubesAxis) {
  const PointFigures p = tracedFigures("uncentred run", 11908, VesselFamilyVariant::Kissing);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);  // main 0.965
}

}  // namespace
}  // namespace vs
