// Session 35 (centre35): the shared chain's points inside a fork's fused junction blob (trunk + both children's
// starts) were centred on the blob, up to 1.8 voxels off the trunk's axis (on the inner corner where the trunk bends);
// they now go onto the trunk's curve between its last unfused point and the children's first unfused points
// (fork_centring.cpp, centreForkTrunks).
#include <gtest/gtest.h>

#include "family_trace.h"

namespace vs {
namespace {

// Tuning-grade seed 11825 (thin forced, 0.97 x 0.97 x 2.64 mm): the trunk (radius 3.5 voxels) bends 79 degrees into
// its root fork; the point all five paths share 2 voxels before the junction sat 1.35 voxels off the trunk's axis
// with radius 4.47 voxels (main: 97.9 % within 1 voxel).
TEST(ForkCentring, SharedChainPointInTheJunctionBlobStaysOnTheTrunk) {
  const PointFigures p = tracedFigures("fork centring", 11825, VesselFamilyVariant::Thin);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);  // main 0.979
  EXPECT_LE(p.meanVox, 0.3);
}

}  // namespace
}  // namespace vs
