// 3D features and costs (thesis eq. 1-3, 19-24 with the reading-notes corrections).
#include "features/features3d.h"

#include <gtest/gtest.h>

#include <cmath>

#include "features/cost3d.h"

namespace vs {
namespace {

VolumeF32 ramp(Vec3 spacing) {
  Geometry g;
  g.dims = {9, 8, 7};
  g.spacing = spacing;
  VolumeF32 v(g);
  for (int64_t z = 0; z < 7; ++z)
    for (int64_t y = 0; y < 8; ++y)
      for (int64_t x = 0; x < 9; ++x) v(x, y, z) = static_cast<float>(2 * x + 3 * y + 5 * z);
  return v;
}

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
  const VolumeF32 v = ramp(Vec3(0.5, 2.0, 1.5));
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

TEST(Cost3D, GradientCostIsEq19WithCorrectedEq20AndNeverNegative) {
  const VolumeF32 v = ramp(Vec3(1, 1, 1));
  Geometry g = v.geometry();
  VolumeF32 w = v;
  w(4, 4, 3) = 500;  // strong edges around it: both ends above max G must still give cost >= 0
  const NodeCost3D c = computeNodeCost3D(w, Cost3DOptions{});
  EXPECT_FLOAT_EQ(c.nodeWeight, 0.7f);
  EXPECT_FLOAT_EQ(c.signWeight, 0.3f);
  ASSERT_EQ(c.sign.size(), c.node.size());
  const float floor = static_cast<float>(Cost3DOptions{}.gradientFloor);
  EXPECT_GT(floor, 0.0f);
  for (float x : c.node) {  // the floor: every edge costs at least w_g * floor per mm
    EXPECT_GE(x, floor);
    EXPECT_LE(x, 1.0f + floor);
  }
  // Every edge >= 0 and equal to eq. 19 by hand.
  const Features3D f = computeFeatures3D(w);
  const int64_t u = g.linear(4, 4, 3), n = g.linear(5, 4, 3);
  const double maxG = f.robustMaxGradient;
  auto G = [&](int64_t i) { return std::min<double>(f.gradientMagnitude[static_cast<size_t>(i)], maxG); };
  const double fg = 1 - (G(u) + G(n)) / (2 * maxG);
  const double fz = (f.laplacian[static_cast<size_t>(u)] > 0) == (f.laplacian[static_cast<size_t>(n)] > 0) ? 1 : 0;
  EXPECT_NEAR(c.edgeCost(u, n, 1.0), 0.7 * (fg + floor) + 0.3 * fz, 1e-6);
  for (int64_t i = 0; i + 1 < g.voxelCount(); ++i) EXPECT_GE(c.edgeCost(i, i + 1, std::sqrt(3.0)), 0.0);
}

TEST(Cost3D, GivenCostIsUsedAsIsAndValidated) {
  Geometry g;
  g.dims = {3, 3, 3};
  VolumeF32 v(g, 0.5f);
  Cost3DOptions o;
  o.kind = CostKind3D::Given;
  const NodeCost3D c = computeNodeCost3D(v, o);
  EXPECT_NEAR(c.edgeCost(0, 13, std::sqrt(3.0)), std::sqrt(3.0) * 0.5, 1e-6);  // MCP_Geometric
  EXPECT_TRUE(c.sign.empty());
  v(1, 2, 0) = -1;
  EXPECT_THROW(computeNodeCost3D(v, o), DataError);
}

TEST(Cost3D, IntensityPolarity) {
  Geometry g;
  g.dims = {4, 1, 1};
  VolumeF32 v(g);
  v(0, 0, 0) = 0, v(1, 0, 0) = 100, v(2, 0, 0) = 200, v(3, 0, 0) = 255;
  Cost3DOptions o;
  o.kind = CostKind3D::Intensity;
  o.windowLo = 0, o.windowHi = 255;
  const NodeCost3D bright = computeNodeCost3D(v, o);
  EXPECT_NEAR(bright.node[3], 1e-3, 1e-6);  // peers' costs.py: 1e-3 + (1 - I/255)^4
  EXPECT_NEAR(bright.node[1], 1e-3 + std::pow(1 - 100 / 255.0, 4), 1e-6);
  o.polarity = TubePolarity::Dark;
  const NodeCost3D dark = computeNodeCost3D(v, o);
  EXPECT_NEAR(dark.node[0], 1e-3, 1e-6);
  EXPECT_GT(dark.node[3], dark.node[0]);
  o.windowHi = -1;
  EXPECT_THROW(computeNodeCost3D(v, o), InvalidArgument);
  EXPECT_EQ(costKindFromName("vesselness"), CostKind3D::Vesselness);
  EXPECT_THROW(costKindFromName("magic"), UsageError);
}

}  // namespace
}  // namespace vs
