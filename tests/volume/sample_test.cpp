// Trilinear sampling: the bound sampler (hot loops) against the free function and against values
// known exactly (a trilinear field is reproduced exactly by trilinear interpolation).
#include "volume/sample.h"

#include <gtest/gtest.h>

#include <random>

namespace vs {
namespace {

// f = 1 + 2x - 3y + 0.5z + xy - yz + 0.25xyz: trilinear, so interpolation between the voxels is exact.
double trilinearField(const Vec3& p) {
  const double x = p[0], y = p[1], z = p[2];
  return 1 + 2 * x - 3 * y + 0.5 * z + x * y - y * z + 0.25 * x * y * z;
}

VolumeF32 fieldVolume(const Index3& dims) {
  Geometry g;
  g.dims = dims;
  g.spacing = Vec3(0.5, 1.0, 2.0);
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x)
        v(x, y, z) = static_cast<float>(
            trilinearField(Vec3(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z))));
  return v;
}

TEST(TrilinearSampler, ExactOnATrilinearFieldAndEqualToSampleTrilinear) {
  const VolumeF32 v = fieldVolume({7, 5, 4});
  const TrilinearSampler s(v);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ux(0, 6), uy(0, 4), uz(0, 3);
  for (int i = 0; i < 500; ++i) {
    const Vec3 p(ux(rng), uy(rng), uz(rng));
    EXPECT_TRUE(s.inside(p));
    EXPECT_NEAR(s.at(p), trilinearField(p), 1e-4);
    EXPECT_NEAR(s.at(p), sampleTrilinear(v, p), 1e-9);
  }
  // Corners and faces (the last cell), and clamping outside, as sampleTrilinear.
  for (const Vec3& p : {Vec3(6, 4, 3), Vec3(0, 0, 0), Vec3(6, 2.5, 1.5), Vec3(-1, 2, 9), Vec3(8, -3, 1.25)}) {
    EXPECT_NEAR(s.at(p), sampleTrilinear(v, p), 1e-9) << p.transpose();
  }
  EXPECT_FALSE(s.inside(Vec3(6.01, 1, 1)));
  EXPECT_FALSE(s.inside(Vec3(1, -0.01, 1)));
}

TEST(TrilinearSampler, AxesOneVoxelThick) {
  const VolumeF32 v = fieldVolume({5, 1, 1});
  const TrilinearSampler s(v);
  for (double x : {0.0, 1.3, 3.99, 4.0}) {
    const Vec3 p(x, 0, 0);
    EXPECT_NEAR(s.at(p), trilinearField(p), 1e-5);
    EXPECT_NEAR(s.at(Vec3(x, 0.7, -2)), sampleTrilinear(v, Vec3(x, 0.7, -2)), 1e-9);
  }
  const VolumeF32 one = fieldVolume({1, 1, 1});
  EXPECT_EQ(TrilinearSampler(one).at(Vec3(0, 0, 0)), 1.0);
}

}  // namespace
}  // namespace vs
