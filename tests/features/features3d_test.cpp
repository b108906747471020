// 3D features (thesis eq. 1-3, 23-24 with the reading-notes corrections).
#include "features/features3d.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/test_images.h"

namespace vs {
namespace {

using test::makeRamp3D;

TEST(Features3D, UniformVolumeHasZeroFeatures) {
  Geometry g;
  g.dims = {6, 5, 4};
  const VolumeF32 v(g, 42.0f);
  const Features3D f = computeFeatures3D(v);
  for (float x : f.gradientMagnitude) EXPECT_EQ(x, 0.0f);
  for (float x : f.laplacian) EXPECT_EQ(x, 0.0f);
  EXPECT_GT(f.robustMaxGradient, 0.0f);  // never 0 (no division by zero later)
}

TEST(Features3D, RampGradientIsDividedByAnisotropicSpacing) {
  const VolumeF32 v = makeRamp3D(Vec3(0.5, 2.0, 1.5));
  const Features3D f = computeFeatures3D(v);
  const double expect = std::sqrt(4.0 * 4.0 + 1.5 * 1.5 + (5 / 1.5) * (5 / 1.5));  // (2/0.5, 3/2, 5/1.5)
  const Geometry& g = v.geometry();
  for (int64_t z = 0; z < 7; ++z)
    for (int64_t y = 0; y < 8; ++y)
      for (int64_t x = 0; x < 9; ++x)  // one-sided differences keep a ramp exact at the border too
        EXPECT_NEAR(f.gradientMagnitude[static_cast<size_t>(g.linear(x, y, z))], expect, 1e-4);
  const Vec3 gr = centralGradient(v, 4, 4, 3);
  EXPECT_NEAR(gr[0], 4.0, 1e-9);
  EXPECT_NEAR(gr[1], 1.5, 1e-9);
  EXPECT_NEAR(gr[2], 5 / 1.5, 1e-9);
  // Laplacian of a linear function is 0 in the interior.
  EXPECT_NEAR(f.laplacian[static_cast<size_t>(g.linear(4, 4, 3))], 0.0f, 1e-4);
}

// The viewer's point snap: the strongest gradient within the radius, the nearest of equals.
TEST(Features3D, StrongestGradientVoxelFindsTheEdgeWithinTheRadius) {
  Geometry g;
  g.dims = {20, 12, 12};
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < 12; ++z)
    for (int64_t y = 0; y < 12; ++y)
      for (int64_t x = 12; x < 20; ++x) v(x, y, z) = 100.0f;  // a step between x = 11 and 12
  // From x = 9 (3 voxels away) the snap reaches the step's two voxels; x = 11 is the nearer.
  EXPECT_EQ(strongestGradientVoxel(v, {9, 6, 6}, 3.0), (Index3{11, 6, 6}));
  EXPECT_EQ(strongestGradientVoxel(v, {14, 6, 6}, 3.0), (Index3{12, 6, 6}));
  // Out of reach, or radius 0: the point itself.
  EXPECT_EQ(strongestGradientVoxel(v, {5, 6, 6}, 3.0), (Index3{5, 6, 6})) << "flat: the nearest (itself) wins";
  EXPECT_EQ(strongestGradientVoxel(v, {9, 6, 6}, 0.0), (Index3{9, 6, 6}));
  EXPECT_THROW(strongestGradientVoxel(v, {20, 6, 6}, 1.0), InvalidArgument);
}

TEST(Features3D, Eq24OnASinglePeak) {
  Geometry g;
  g.dims = {5, 5, 5};
  VolumeF32 v(g, 0.0f);
  v(2, 2, 2) = 26.0f;
  const Features3D f = computeFeatures3D(v);
  EXPECT_FLOAT_EQ(f.laplacian[static_cast<size_t>(g.linear(2, 2, 2))], 26.0f);  // (27*26 - 26) / 26
  EXPECT_FLOAT_EQ(f.laplacian[static_cast<size_t>(g.linear(1, 2, 2))], -1.0f);  // (0 - 26) / 26
  EXPECT_FLOAT_EQ(f.laplacian[static_cast<size_t>(g.linear(0, 0, 0))], 0.0f);
  EXPECT_TRUE(f.laplacianPositive(g.linear(2, 2, 2)));
  EXPECT_FALSE(f.laplacianPositive(g.linear(1, 1, 1)));
}

TEST(Features3D, RobustMaxIgnoresOneOutlier) {
  Geometry g;
  g.dims = {40, 40, 40};
  VolumeF32 v(g);
  for (int64_t z = 0; z < 40; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 40; ++x) v(x, y, z) = static_cast<float>(x);  // |grad| = 1
  v(20, 20, 20) = 1e6f;
  const Features3D f = computeFeatures3D(v);
  EXPECT_GT(f.maxGradient, 1e5f);
  EXPECT_NEAR(f.robustMaxGradient, 1.0f, 1e-3);
  Features3DOptions o;
  o.robustMaxPercentile = 100;
  EXPECT_EQ(computeFeatures3D(v, o).robustMaxGradient, computeFeatures3D(v, o).maxGradient);
  o.robustMaxPercentile = 0;
  EXPECT_THROW(computeFeatures3D(v, o), InvalidArgument);
}

TEST(Features3D, RejectsNaN) {
  Geometry g;
  g.dims = {4, 4, 4};
  VolumeF32 v(g, 1.0f);
  v(1, 1, 1) = NAN;
  EXPECT_THROW(computeFeatures3D(v), DataError);
}

}  // namespace
}  // namespace vs
