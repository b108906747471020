// A thin tube kissing a wide one on thick slices (two_tubes.cpp, fitTwoTubeSection; issue 21, session 49 kissthin):
// the two-tube fit's own disc at the chain's radius (its rays' median, wide across thick slices) is held to the thin
// tube's outer edge with its centre short of the axis; the own centre is read again with the own radius fitted too.
#include <gtest/gtest.h>

#include "family_trace.h"

namespace vs {
namespace {

// Tuning-grade seed 17709 (scan given, kissing, dark, 0.66 x 0.66 x 1.71 mm): its fused points 67-69 were fitted
// with the own disc at the chain's radius and their own centres fell short of the thin tube (96.2 % within 1 voxel,
// mean 0.240); with the own radius free 98.9 %, mean 0.219.
TEST(ThickSliceOwnDisc, ThinKissingTubeCentredWithItsOwnRadius) {
  const PointFigures p = tracedFigures("thick slice own disc", 17709, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
  EXPECT_LE(p.meanVox, 0.3);
}

}  // namespace
}  // namespace vs
