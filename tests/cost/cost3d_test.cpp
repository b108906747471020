// 3D node costs (thesis eq. 19-22 with the reading-notes corrections).
#include "cost/cost3d.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/test_images.h"

namespace vs {
namespace {

using test::makeRamp3D;

TEST(Cost3D, GradientCostIsEq19WithCorrectedEq20AndNeverNegative) {
  const VolumeF32 v = makeRamp3D(Vec3(1, 1, 1));
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
