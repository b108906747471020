// The auto cost (trace's default): polarity and window estimated at the root, errors when the
// root's surroundings have no contrast.
#include "tracking/auto_cost.h"

#include <gtest/gtest.h>

#include "phantom/phantom.h"

namespace vs {
namespace {

// A tube of radius 3 voxels along x at y = z = 16, value `in`, in a background `out`, plus noise.
VolumeF32 tube(float in, float out, double noise, uint64_t seed = 1) {
  Geometry g;
  g.dims = {48, 32, 32};
  VolumeF32 v(g);
  PhantomRng rng(seed);
  for (int64_t z = 0; z < 32; ++z)
    for (int64_t y = 0; y < 32; ++y)
      for (int64_t x = 0; x < 48; ++x) {
        const double r = std::hypot(static_cast<double>(y) - 16, static_cast<double>(z) - 16);
        v(x, y, z) = static_cast<float>((r <= 3 ? in : out) + rng.normal(0, noise));
      }
  return v;
}

TEST(AutoCost, BrightTubeOnDarkBackground) {
  const VolumeF32 v = tube(300, 40, 10);
  const AutoCost ac = computeAutoCost(v, {24, 16, 16});
  EXPECT_EQ(ac.estimate.polarity, TubePolarity::Bright);
  EXPECT_NEAR(ac.estimate.lumen, 300, 25);
  EXPECT_GT(ac.estimate.windowLo, 40);
  EXPECT_LT(ac.estimate.windowLo, ac.estimate.windowHi);
  // The lumen is cheap, the background costs the most.
  const Geometry& g = v.geometry();
  EXPECT_LT(ac.cost.node[static_cast<size_t>(g.linear(24, 16, 16))], 0.01f);
  EXPECT_GT(ac.cost.node[static_cast<size_t>(g.linear(24, 4, 4))], 0.99f);
  EXPECT_EQ(ac.cost.description.rfind("auto", 0), 0u);
}

TEST(AutoCost, DarkTubeIsAnAirway) {
  const VolumeF32 v = tube(-990, -820, 15);  // air in lung parenchyma
  const AutoCost ac = computeAutoCost(v, {24, 16, 16});
  EXPECT_EQ(ac.estimate.polarity, TubePolarity::Dark);
  EXPECT_LT(ac.estimate.windowHi, -840);  // the parenchyma stays out of the window
  const Geometry& g = v.geometry();
  EXPECT_LT(ac.cost.node[static_cast<size_t>(g.linear(24, 16, 16))], 0.01f);
  EXPECT_GT(ac.cost.node[static_cast<size_t>(g.linear(24, 4, 4))], 0.99f);
}

TEST(AutoCost, NoContrastIsAnErrorNamingTheOptions) {
  for (const VolumeF32& v : {tube(100, 100, 0), tube(100, 100, 10, 7)}) {
    try {
      computeAutoCost(v, {24, 16, 16});
      FAIL() << "no error";
    } catch (const DataError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("no contrast"), std::string::npos) << m;
      EXPECT_NE(m.find("--window"), std::string::npos) << m;
    }
  }
  EXPECT_THROW(computeAutoCost(tube(300, 40, 0), {48, 16, 16}), InvalidArgument);
}

}  // namespace
}  // namespace vs
