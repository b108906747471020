// A kissing contact only a point or two long (two_tubes.cpp, fitTwoTubes; issue 21, session 48 held17b): where the
// rounds' own-lobe look found every section of the run fused with a touching traced path, the run is fitted as two
// tubes whatever its length, the other tube's going on past both ends still deciding.
#include <gtest/gtest.h>

#include "family_trace.h"

namespace vs {
namespace {

// Tuning-grade seed 17308 (scan given, kissing, 0.67 x 0.67 x 1.29 mm): path 0, a thin tube (r 1.2 mm), touches its
// neighbour over two points twice; there the own-lobe look reads one lobe and the chords' centre drew the points a
// slice towards the neighbour (1.8-3.0 voxels off; 97.8 % within 1 voxel, mean 0.179). The two-point runs fit two
// tubes decisively but were shorter than twoTubeRun: fitted, 100 %, mean 0.123.
TEST(ShortContact, TwoPointKissFittedAsTwoTubes) {
  const PointFigures p = tracedFigures("short contact", 17308, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
  EXPECT_LE(p.meanVox, 0.3);
}

}  // namespace
}  // namespace vs
