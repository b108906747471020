// Session 36 (fork36): where a fork starts on the refined tree (fork_start.cpp). splitForks re-branched 11932's
// b5 -> {b9, b10} 10.7 mm up the parent, whose sections between two 2.19 mm slices read as a plateau of widening, and
// laid path 4's copies of the trunk's points on a line to b10 (7 points 1.2-1.7 voxels off); the fork now starts at the
// first section wider than the trunk. placeFork laid 11902's first child point past the midline onto the sibling (the
// children cross past a narrow fork); it keeps the rounds' position there.
#include <gtest/gtest.h>

#include "family_trace.h"

namespace vs {
namespace {

// Tuning-grade seed 11932 (thin forced, 0.80 x 0.80 x 2.19 mm); main 97.3 % within 1 voxel (18 far points).
TEST(ForkStart, ForkPlateauBetweenSlicesStaysOnTheTrunkUntilItWidens) {
  const PointFigures p = tracedFigures("fork start", 11932, VesselFamilyVariant::Thin);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);  // main 0.973
  EXPECT_LE(p.meanVox, 0.16);  // main 0.174
}

// Tuning-grade seed 11902 (given block 11901, thin; 0.92 x 0.92 x 1.74 mm), against each path's own tubes: main 98.6 %
// (path 0's point 44 1.76 voxels off its own branch, 0.82 from the sibling's axis).
TEST(ForkStart, ChildPointIsNotLaidOntoTheSibling) {
  const PointFigures p = tracedFigures("fork start", 11902, VesselFamilyVariant::Thin, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.99);  // main 0.986
}

}  // namespace
}  // namespace vs
