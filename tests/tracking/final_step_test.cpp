// Session 36 (kiss36): the refinement's final centring step taken back where the rounds were swinging - their last
// two steps pointing against each other - and the final step goes on the way the last round went (out of the bracket
// of the swing's last two positions) towards another traced path whose lumen touches the point's, where no later
// placement moved the point (centreline_junctions.h: holdReversedSteps). At a kissing contact the chords through the
// fused blob swing a point towards the other tube round after round; the rounds' smoothing holds it, the final step
// (smoothed only where it zig-zags against its neighbours, and here they all step alike) carried it 0.35-1.15 voxels
// towards the other tube.
#include <gtest/gtest.h>

#include <vector>

#include "family_trace.h"
#include "tracking/centreline_junctions.h"

namespace vs {
namespace {

TEST(FinalStep, RoundsSwingingAreReversed) {
  centreline_detail::RoundSteps rounds;
  std::vector<Vec3> q = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  const Vec3 swing[3] = {Vec3(0, 0.5, 0), Vec3(0, -0.3, 0), Vec3(0, 0.2, 0)};
  for (const Vec3& s : swing) {
    rounds.begin(q);
    q[0] += s;                // swings
    q[1] += Vec3(0, 0.1, 0);  // settles one way
    rounds.end(q);
  }
  rounds.copy(0);  // a copy keeps its source's state
  ASSERT_EQ(rounds.reversed.size(), 3u);
  EXPECT_TRUE(rounds.reversed[0]);
  EXPECT_FALSE(rounds.reversed[1]);
  EXPECT_TRUE(rounds.reversed[2]);
  EXPECT_EQ(rounds.last[2], Vec3(0, 0.2, 0));
}

// Chain A runs from the root along x (1 mm a point), chain B leaves the root and comes back beside A's point 8, 1.5 mm
// off (its voxel within the two 1 mm radii); both swung in the rounds, their last round along +y.
TEST(FinalStep, AStepOnPastASwingTowardsATouchingPathIsTakenBack) {
  std::vector<Vec3> p;
  std::vector<int32_t> parent;
  for (int i = 0; i <= 10; ++i) p.emplace_back(i, 0, 0), parent.push_back(i - 1);  // 0 root, 1..10 chain A
  p.emplace_back(0, 3, 0), parent.push_back(0);                                    // 11: chain B
  p.emplace_back(4, 3, 0), parent.push_back(11);
  p.emplace_back(8, 1.5, 0), parent.push_back(12);  // 13: beside A's 8
  std::vector<std::vector<int32_t>> children(p.size());
  for (size_t i = 1; i < p.size(); ++i) children[static_cast<size_t>(parent[i])].push_back(static_cast<int32_t>(i));
  const std::vector<double> radius(p.size(), 1.0);
  const centreline_detail::JunctionInput in{parent, children, radius, [&](size_t k) { return p[k]; }};
  centreline_detail::RoundSteps rounds;
  rounds.last.assign(p.size(), Vec3(0, 0.1, 0));
  rounds.reversed.assign(p.size(), 1);
  std::vector<Vec3> stepped = p;
  stepped[8] += Vec3(0, 0.4, 0);  // on past its swing, towards B's voxel: taken back
  stepped[5] += Vec3(0, 0.4, 0);  // on past its swing, no other path's voxel near: kept
  stepped[7] += Vec3(0, 0.4, 0);  // as 8, but not swinging: kept
  rounds.reversed[7] = 0;
  std::vector<Vec3> q = stepped;
  q[9] += Vec3(0, 0.4, 0), stepped[9] = q[9] + Vec3(0, -0.1, 0);  // a later placement moved it: kept
  EXPECT_EQ(centreline_detail::holdReversedSteps(in, CentrelineOptions{}, rounds, p, stepped, q), 1u);
  EXPECT_EQ(q[8], p[8]);
  EXPECT_EQ(q[5], stepped[5]);
  EXPECT_EQ(q[7], stepped[7]);
  EXPECT_EQ(q[9], p[9] + Vec3(0, 0.4, 0));
}

// Tuning-grade seed 11108 (kissing given, dark, 0.87 x 0.87 x 2.20 mm): path 0's points 33-35 and path 1's 40 swung
// in the rounds (0/33: 0.20, 0.73, 0.36, 0.76 voxels off its own axis) and the final step took them to 1.06-1.20
// voxels, straight towards the other tube (on main 97.8 % within 1 voxel of the own tubes, mean 0.246).
TEST(FinalStep, KissingPointsSwingingInTheRoundsKeepTheirRest) {
  const PointFigures p = tracedFigures("final step", 11108, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);  // main 0.978
  EXPECT_LE(p.meanVox, 0.3);
}

}  // namespace
}  // namespace vs
