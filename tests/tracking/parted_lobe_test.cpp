// placeParted's lobe centre read from the lobe's own walls (tracking/parted_lobe.cpp; issue 21, session 49 lobewalls).
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "tracking/centreline_junctions.h"

namespace vs {
namespace {

// Two overlapping tubes along z (0.5 mm voxels), centres at x = 10 -+ sep / 2 mm, y = 10 mm, radii ra / rb, bright
// (100) on 0, each voxel the union's area fraction over a 4 x 4 in-plane subgrid (partial volume).
VolumeF32 twoTubes(double sep, double ra, double rb) {
  Geometry g;
  g.dims = {40, 40, 8};
  g.spacing = {0.5, 0.5, 0.5};
  VolumeF32 v(g);
  for (int64_t y = 0; y < 40; ++y)
    for (int64_t x = 0; x < 40; ++x) {
      int in = 0;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
          const double px = 0.5 * (x + (i + 0.5) / 4 - 0.5), py = 0.5 * (y + (j + 0.5) / 4 - 0.5);
          in += std::hypot(px - (10 - sep / 2), py - 10) <= ra || std::hypot(px - (10 + sep / 2), py - 10) <= rb;
        }
      for (int64_t z = 0; z < 8; ++z) v(x, y, z) = static_cast<float>(100.0 * in / 16);
    }
  return v;
}

// The lobe on the +x side (centre 10 + sep / 2) read from the fused section's centre line (x = 10) along x.
Vec3 plusLobe(double sep, double ra, double rb) {
  const VolumeF32 v = twoTubes(sep, ra, rb);
  const TrilinearSampler sample(v);
  const Vec3 c(10, 10, 2), outer(10 + sep / 2 + rb, 10, 2), inner(10 - sep / 2 - ra, 10, 2);
  Vec3 centre(NAN, NAN, NAN);
  EXPECT_TRUE(centreline_detail::lobeCentreFromWalls(sample, v.geometry().spacing, c, Vec3(0, 0, 1), 0, 0.125,
                                                     Vec3(1, 0, 0), outer.x() - c.x(), inner.x() - c.x(), 8, centre));
  return centre;
}

// Session 49 (lobewalls): two children of 2.1 mm whose centres lie 2.5 mm apart (18430's root fork past its junction):
// the lobe's centre from its outer wall and the waist's two ends is the child's axis to a tenth of a millimetre, the
// child's radius never read; with both walls read 0.3 mm wider all round (partial volume across thick slices: 10621 /
// 13210 / 16128) the centre stays; and a smaller child (1.5 mm beside 2.1) is placed on its own axis too. The fork's
// old reading - the outer wall less a radius read in the parent's lumen (2.86 mm) - put it 0.76 mm in.
TEST(PartedLobe, CentreFromTheLobesOwnWalls) {
  for (const auto& [sep, ra, rb] :
       {std::tuple{2.5, 2.1, 2.1}, std::tuple{2.5, 2.4, 2.4}, std::tuple{2.4, 2.1, 1.5}, std::tuple{3.2, 2.1, 2.1}}) {
    const Vec3 centre = plusLobe(sep, ra, rb);
    EXPECT_NEAR(centre.x(), 10 + sep / 2, 0.1) << sep << " " << ra << " " << rb;
    EXPECT_NEAR(centre.y(), 10, 0.1);
  }
}

// One round lumen has no waist: nothing is read (placeParted keeps its other reading).
TEST(PartedLobe, NoWaistInOneRoundLumen) {
  const VolumeF32 v = twoTubes(0, 2.5, 2.5);
  const TrilinearSampler sample(v);
  Vec3 centre;
  EXPECT_FALSE(centreline_detail::lobeCentreFromWalls(sample, v.geometry().spacing, Vec3(10, 10, 2), Vec3(0, 0, 1), 0,
                                                      0.125, Vec3(1, 0, 0), 2.5, -2.5, 8, centre));
}

}  // namespace
}  // namespace vs
