// Iso crossings along a ray (the walk shared by the environment map and the surface fold check):
// a hollow ball seen from its centre, against the analytic radii.
#include "volume/ray_crossings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace vs {
namespace {

// A shell between radii 6 and 12 mm around the volume's centre: 1 inside, 0 outside, linear over
// one voxel around each radius (so the iso-value 0.5 lies exactly on the radii).
VolumeF32 shell() {
  Geometry g;
  g.dims = {40, 36, 30};
  g.spacing = Vec3(0.8, 0.9, 1.1);
  g.origin = Vec3(-5, 2, 7);
  VolumeF32 v(g);
  const Vec3 c = g.indexToWorld(Vec3(19.5, 17.5, 14.5));
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const double r = (g.indexToWorld(Vec3(double(x), double(y), double(z))) - c).norm();
        v(x, y, z) = static_cast<float>(std::clamp(std::min(r - 6, 12 - r) + 0.5, 0.0, 1.0));
      }
  return v;
}

TEST(RayCrossings, HollowBallFromItsCentre) {
  const VolumeF32 v = shell();
  const Geometry& g = v.geometry();
  const Vec3 c = g.indexToWorld(Vec3(19.5, 17.5, 14.5));
  for (const Vec3& d :
       {Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(1, 1, 1).normalized(), Vec3(-0.3, 0.5, -0.8).normalized()}) {
    const RayIsoCrossings r = rayIsoCrossings(v, 0.5, c, d, 0.2, 1000);
    EXPECT_FALSE(r.startsAbove);
    ASSERT_EQ(r.crossings.size(), 2u);
    EXPECT_TRUE(r.crossings[0].rising);
    EXPECT_FALSE(r.crossings[1].rising);
    EXPECT_NEAR(r.crossings[0].t, 6, 0.25);  // trilinear between voxel centres: within a quarter voxel
    EXPECT_NEAR(r.crossings[1].t, 12, 0.25);
    // The walk ends at the first sample more than half a voxel outside the volume.
    const Vec3 endIndex = g.worldToIndex(c + r.end * d);
    bool outside = false;
    for (int k = 0; k < 3; ++k) outside |= endIndex[k] < -0.5 || endIndex[k] > double(g.dims[size_t(k)]) - 0.5;
    EXPECT_TRUE(outside);
    // Stopping at the first crossing, and at maxLength.
    const RayIsoCrossings first = rayIsoCrossings(v, 0.5, c, d, 0.2, 1000, 1);
    ASSERT_EQ(first.crossings.size(), 1u);
    EXPECT_LT(first.end, 6.5);
    EXPECT_TRUE(rayIsoCrossings(v, 0.5, c, d, 0.2, 5).crossings.empty());
  }
}

}  // namespace
}  // namespace vs
