// The auto cost's medial term (medial_cost.h): the exact distance transform, the local lumen
// radius, and a raw minimum-cost path that keeps to the axis of a wide bent lumen.
#include "tracking/medial_cost.h"

#include <gtest/gtest.h>

#include <cmath>

#include "phantom/phantom.h"
#include "tracking/auto_cost.h"
#include "tracking/tracker.h"

namespace vs {
namespace {

TEST(MedialCost, DistanceTransformIsExactWithAnisotropicSpacing) {
  Geometry g;
  g.dims = {13, 11, 9};
  g.spacing = Vec3(0.7, 1.3, 2.1);
  PhantomRng rng(5);
  std::vector<uint8_t> inside(static_cast<size_t>(g.voxelCount()));
  for (auto& v : inside) v = rng.uniform(0, 1) < 0.85 ? 1 : 0;
  const std::vector<float> d = distanceToOutside(g, inside);
  int checked = 0;
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const size_t i = static_cast<size_t>(g.linear(x, y, z));
        if (!inside[i]) {
          EXPECT_EQ(d[i], 0.0f);
          continue;
        }
        // Brute force: every outside voxel, and the layer just outside the volume (nearest along an axis).
        double best = std::numeric_limits<double>::infinity();
        const Index3 p{x, y, z};
        for (int a = 0; a < 3; ++a)
          best = std::min({best, static_cast<double>(p[a] + 1) * g.spacing[a],
                           static_cast<double>(g.dims[a] - p[a]) * g.spacing[a]});
        for (int64_t j = 0; j < g.voxelCount(); ++j) {
          if (inside[static_cast<size_t>(j)]) continue;
          const Index3 q = g.unlinear(j);
          const Vec3 diff((q[0] - x) * g.spacing[0], (q[1] - y) * g.spacing[1], (q[2] - z) * g.spacing[2]);
          best = std::min(best, diff.norm());
        }
        EXPECT_NEAR(d[i], best, 1e-4) << x << "," << y << "," << z;
        ++checked;
      }
  EXPECT_GT(checked, 800);
}

// A straight tube of radius 6 (x axis, spacing 1) feeding a thin one of radius 2: every lumen
// voxel's local radius is its own tube's.
TEST(MedialCost, LocalRadiusIsEachTubesOwn) {
  Geometry g;
  g.dims = {60, 32, 32};
  std::vector<uint8_t> inside(static_cast<size_t>(g.voxelCount()));
  for (int64_t z = 0; z < 32; ++z)
    for (int64_t y = 0; y < 32; ++y)
      for (int64_t x = 0; x < 60; ++x) {
        const double r = std::hypot(y - 16.0, z - 16.0);
        inside[static_cast<size_t>(g.linear(x, y, z))] = (x < 30 && r <= 6.2) || (x >= 30 && r <= 2.2) ? 1 : 0;
      }
  const std::vector<float> d = distanceToOutside(g, inside);
  const std::vector<float> r = localLumenRadius(g, d, 0.5);
  auto at = [&](const std::vector<float>& f, int64_t x, int64_t y, int64_t z) {
    return f[static_cast<size_t>(g.linear(x, y, z))];
  };
  // On the axis D is the distance to the nearest voxel outside the disc: sqrt(6^2 + 2^2) for the
  // wide tube, sqrt(2^2 + 1^2) for the thin one; off the axis R_loc is the axis's.
  EXPECT_NEAR(at(d, 15, 16, 16), std::sqrt(40.0), 1e-4);
  EXPECT_NEAR(at(d, 15, 20, 16), std::sqrt(8.0), 1e-4);
  for (const Index3& p : {Index3{15, 16, 16}, Index3{15, 20, 16}, Index3{15, 16, 11}, Index3{10, 13, 19}})
    EXPECT_NEAR(at(r, p[0], p[1], p[2]), std::sqrt(40.0), 1e-4) << p[0] << "," << p[1] << "," << p[2];
  for (const Index3& p : {Index3{45, 16, 16}, Index3{45, 17, 16}, Index3{50, 16, 15}})
    EXPECT_NEAR(at(r, p[0], p[1], p[2]), std::sqrt(5.0), 1e-4) << p[0] << "," << p[1] << "," << p[2];
  EXPECT_EQ(at(r, 45, 25, 16), 0.0f);  // outside
}

// A wide lumen (radius 7 voxels) bent by a quarter circle of radius 22: without the medial term
// the raw path from one end's axis to the other's is the shortest chord, along the inner wall;
// with it, the path keeps to the axis.
TEST(MedialCost, RawPathInAWideBentLumenFollowsItsAxis) {
  Geometry g;
  g.dims = {40, 40, 20};
  VolumeF32 v(g);
  PhantomRng rng(11);
  const double bend = 26, radius = 7, cz = 10;  // arc centre (3, 3, cz) in the z = cz plane
  auto offAxis = [&](const Index3& p) {
    const double rr = std::hypot(p[0] - 3.0, p[1] - 3.0);
    const double ang = std::atan2(p[1] - 3.0, p[0] - 3.0);
    if (ang < 0 || ang > M_PI / 2) return 1e9;  // beyond the arc's ends
    return std::hypot(rr - bend, p[2] - cz);
  };
  for (int64_t z = 0; z < 20; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 40; ++x)
        v(x, y, z) = static_cast<float>((offAxis({x, y, z}) <= radius ? 200 : 20) + rng.normal(0, 4));
  const Index3 root{29, 6, 10}, target{6, 29, 10};  // the axis at both ends of the arc
  double worst[2] = {0, 0}, mean[2] = {0, 0};
  for (int with = 0; with < 2; ++with) {
    AutoCostOptions o;
    o.medial.weight = with ? 0.01 : 0.0;  // off by default
    const AutoCost ac = computeAutoCost(v, root, o);
    EXPECT_EQ(ac.cost.description.find("medial") != std::string::npos, with == 1) << ac.cost.description;
    VesselTracker tr(v, ac.cost, root);
    const TracedPath& p = tr.addTarget(target);
    ASSERT_TRUE(p.reached);
    for (const Index3& q : p.voxels) {
      const double d = std::min(offAxis(q), 1e3);
      worst[with] = std::max(worst[with], d);
      mean[with] += d / static_cast<double>(p.voxels.size());
    }
  }
  EXPECT_GT(worst[0], 4.0) << "without the term the path should hug the inner wall";
  EXPECT_LT(worst[1], 1.5) << "mean " << mean[1];
  EXPECT_LT(mean[1], 0.8);
}

}  // namespace
}  // namespace vs
