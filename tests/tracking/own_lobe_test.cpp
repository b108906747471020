// The own lobe of a fused section (session 18 kiss8, own_lobe.h): two touching tubes along x give
// one region above the half-way level; the lobe of the anchor is its own tube's section.
#include "tracking/own_lobe.h"

#include <gtest/gtest.h>

#include <cmath>

#include "features/vesselness.h"
#include "volume/volume.h"

namespace vs {
namespace {

// Tubes along x in a 0.5 mm grid: A (radius ra) at (y, z) = (ay, az) and, when rb > 0, B (radius
// rb) beside it along y with surfaces `gap` apart; partial volume by 4x4 supersampling, 20 outside,
// 200 inside, smoothed by 0.5 mm.
VolumeF32 tubes(double ra, double rb, double gap, double ay, double az) {
  Geometry g;
  g.dims = {12, 40, 30};
  g.spacing = Vec3(0.5, 0.5, 0.5);
  VolumeF32 v(g, 20.0f);
  const double by = ay + ra + rb + gap;
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        double in = 0;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) {
            const double py = (double(y) - 0.375 + 0.25 * a) * 0.5, pz = (double(z) - 0.375 + 0.25 * b) * 0.5;
            in += std::hypot(py - ay, pz - az) <= ra || (rb > 0 && std::hypot(py - by, pz - az) <= rb);
          }
        v(x, y, z) = static_cast<float>(20.0 + 180.0 * in / 16.0);
      }
  return gaussianSmooth3D(v, 0.5);
}

TEST(OwnLobe, TouchingTubesSplitIntoTheAnchorsOwnTube) {
  const double ra = 1.5, rb = 2.5, gap = 0.1, ay = 6.1, az = 7.3, by = ay + ra + rb + gap;
  const VolumeF32 v = tubes(ra, rb, gap, ay, az);
  const TrilinearSampler s(v);
  const Vec3 sp = v.geometry().spacing, t(1, 0, 0);
  LobeScratch sc;
  // A point of A pulled 1 mm towards B, its path voxel on A's axis: A's centre.
  const Vec3 c(3.0, ay + 1.0, az), anchorA(3.0, ay, az), anchorB(3.0, by, az);
  const LobeResult a = ownLobe(s, sp, c, t, anchorA, 110, true, 8.0, 0.1, sc);
  ASSERT_TRUE(a.split);
  EXPECT_EQ(a.lobes, 2);
  EXPECT_NEAR(a.centre[1], ay, 0.25);
  EXPECT_NEAR(a.centre[2], az, 0.25);
  EXPECT_NEAR(a.radiusMm, ra, 0.3);
  EXPECT_NEAR(a.peak[1], ay, 0.25);  // the deepest sample of A's own lobe, on A's axis
  EXPECT_NEAR(a.peak[2], az, 0.25);
  // The same section with the anchor in B: B's centre.
  const LobeResult b = ownLobe(s, sp, c, t, anchorB, 110, true, 8.0, 0.1, sc);
  ASSERT_TRUE(b.split);
  EXPECT_NEAR(b.centre[1], by, 0.25);
  EXPECT_NEAR(b.centre[2], az, 0.25);
  EXPECT_NEAR(b.radiusMm, rb, 0.3);
  // A valley share above the valley's depth: one lobe.
  EXPECT_FALSE(ownLobe(s, sp, c, t, anchorA, 110, true, 8.0, 0.99, sc).split);
}

// Three tubes in a row, touching: three lobes (the refinement moves a point only where there are
// two: a pair of touching tubes), the middle anchor's lobe the middle tube.
TEST(OwnLobe, ThreeTouchingTubesAreThreeLobes) {
  Geometry g;
  g.dims = {12, 48, 30};
  g.spacing = Vec3(0.5, 0.5, 0.5);
  VolumeF32 v(g, 20.0f);
  const double r = 1.8, az = 7.3, ys[3] = {5.1, 5.1 + 2 * r + 0.1, 5.1 + 4 * r + 0.2};
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        double in = 0;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) {
            const double py = (double(y) - 0.375 + 0.25 * a) * 0.5, pz = (double(z) - 0.375 + 0.25 * b) * 0.5;
            bool hit = false;
            for (const double cy : ys) hit = hit || std::hypot(py - cy, pz - az) <= r;
            in += hit;
          }
        v(x, y, z) = static_cast<float>(20.0 + 180.0 * in / 16.0);
      }
  const VolumeF32 sm = gaussianSmooth3D(v, 0.5);
  const TrilinearSampler s(sm);
  LobeScratch sc;
  const Vec3 c(3.0, ys[1], az);
  const LobeResult l = ownLobe(s, g.spacing, c, Vec3(1, 0, 0), c, 110, true, 11.0, 0.1, sc);
  EXPECT_EQ(l.lobes, 3);
  EXPECT_NEAR(l.centre[1], ys[1], 0.25);
}

TEST(OwnLobe, OneTubeIsOneLobe) {
  const double ay = 9.7, az = 7.1;
  const VolumeF32 v = tubes(2.5, 0, 0, ay, az);
  const TrilinearSampler s(v);
  LobeScratch sc;
  const Vec3 c(3.0, ay + 0.8, az - 0.4);
  const LobeResult r = ownLobe(s, v.geometry().spacing, c, Vec3(1, 0, 0), c, 110, true, 8.0, 0.1, sc);
  EXPECT_FALSE(r.split);
  EXPECT_EQ(r.lobes, 1);
  // With one lobe too: its peak of lumen-ness on the tube's axis, read from a point 0.9 mm off it, and its width the
  // section's diameter at the half-way level (a disc's 4 x spread along its long axis = 2 x radius).
  EXPECT_NEAR(r.peak[1], ay, 0.25);
  EXPECT_NEAR(r.peak[2], az, 0.25);
  EXPECT_NEAR(r.widthMm, 5.0, 0.5);
  // Dark lumen (the polarity flipped): the same.
  VolumeF32 d = v;
  for (float& x : d.voxels()) x = 220.0f - x;
  const TrilinearSampler sd(d);
  EXPECT_FALSE(ownLobe(sd, v.geometry().spacing, c, Vec3(1, 0, 0), c, 110, false, 8.0, 0.1, sc).split);
}

TEST(OwnLobe, AnchorOutsideTheLumenFindsNothing) {
  const VolumeF32 v = tubes(2.0, 0, 0, 9.7, 7.1);
  const TrilinearSampler s(v);
  LobeScratch sc;
  const Vec3 c(3.0, 9.7, 7.1), far(3.0, 2.0, 7.1);
  EXPECT_FALSE(ownLobe(s, v.geometry().spacing, c, Vec3(1, 0, 0), far, 110, true, 8.0, 0.1, sc).split);
}

}  // namespace
}  // namespace vs
