// Tubes touching where they cross at an angle (tracking/contact_retrace.h): a path that runs down
// one tube and turns into another at their contact is searched again round a block across the
// contact when both tubes go on past each other; at a T fork, where the branch entered ends at the
// trunk's wall, the same turn is left alone though a lumen route round a block exists.
#include "tracking/contact_retrace.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace vs {
namespace {

// 1 mm voxels, node cost 1 (background) except in capsules of lumen (0.001).
struct Scene {
  Geometry g;
  NodeCost3D cost;
  Scene() {
    g.dims = {60, 60, 40};
    g.spacing = Vec3(1.0, 1.0, 1.0);
    cost.kind = CostKind3D::Given;
    cost.geometry = g;
    cost.node.assign(static_cast<size_t>(g.voxelCount()), 1.0f);
  }
  void capsule(const Vec3& a, const Vec3& b, double r, float c = 0.001f) {
    const Vec3 d = b - a;
    for (int64_t z = 0; z < g.dims[2]; ++z)
      for (int64_t y = 0; y < g.dims[1]; ++y)
        for (int64_t x = 0; x < g.dims[0]; ++x) {
          const Vec3 p{double(x), double(y), double(z)};
          const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
          if ((p - (a + t * d)).norm() <= r) {
            float& v = cost.node[static_cast<size_t>(g.linear(x, y, z))];
            v = std::min(v, c);
          }
        }
  }
};

// L along y (x 20, z 20, radius 1), and a lumen loop off it at y 12 over to x `loopX`.
Scene trunkWithLoop(double loopX) {
  Scene s;
  s.capsule({20, 0, 20}, {20, 59, 20}, 1);
  s.capsule({20, 12, 20}, {loopX, 12, 20}, 1);
  return s;
}

// The path down L to y 30, then up (z) and along x to x 50 at height z.
std::vector<Index3> turnAt30(int64_t z) {
  std::vector<Index3> p;
  for (int64_t y = 0; y <= 30; ++y) p.push_back({20, y, 20});
  for (int64_t zz = 21; zz <= z; ++zz) p.push_back({20, 30, zz});
  for (int64_t x = 21; x <= 50; ++x) p.push_back({x, 30, z});
  return p;
}

// The contact's turn re-searched: same ends, and the new route leaves L by the loop and comes back along E
// (it passes x 10 or less).
void expectRoutedRoundTheLoop(const ContactRetrace& r, const std::vector<Index3>& path) {
  EXPECT_GE(r.turns, 1);
  ASSERT_TRUE(r.changed) << r.why;
  EXPECT_EQ(r.voxels.front(), path.front());
  EXPECT_EQ(r.voxels.back(), path.back());
  EXPECT_TRUE(std::any_of(r.voxels.begin(), r.voxels.end(), [](const Index3& v) { return v[0] <= 10; }));
}

TEST(ContactRetrace, ATurnThroughTheContactOfTwoCrossingTubesIsSearchedAgainRoundIt) {
  // E along x at y 30, z 23 (radius 1), crossing 3 mm above L's axis: their voxels touch there;
  // the loop joins E at x 8. The contact's two voxels on the path are dimmer (still lumen).
  Scene s = trunkWithLoop(8);
  s.capsule({8, 12, 20}, {8, 30, 23}, 1);
  s.capsule({0, 30, 23}, {59, 30, 23}, 1);
  for (int64_t z = 21; z <= 22; ++z) s.cost.node[static_cast<size_t>(s.g.linear(20, 30, z))] = 0.1f;
  const std::vector<Index3> path = turnAt30(23);
  const ContactRetrace r = retraceAcrossContact(s.cost, path, 26, 0.2, CrossingOptions{});
  expectRoutedRoundTheLoop(r, path);
}

TEST(ContactRetrace, ATurnIntoABranchThatEndsAtTheTrunkIsLeftAlone) {
  // E leaves L at y 30 along x (a T fork, same height); the loop joins E at x 32, so a lumen route
  // round a block at the fork exists.
  Scene s = trunkWithLoop(32);
  s.capsule({32, 12, 20}, {32, 30, 20}, 1);
  s.capsule({20, 30, 20}, {59, 30, 20}, 1);
  const std::vector<Index3> path = turnAt30(20);
  const ContactRetrace r = retraceAcrossContact(s.cost, path, 26, 0.2, CrossingOptions{});
  EXPECT_EQ(r.turns, 0) << r.why;
  EXPECT_FALSE(r.changed);
}

TEST(ContactRetrace, ATubeThatBendsAtTheContactIsFollowedPastIt) {
  // L bends 35 degrees upwards at y 30 (as 10301's branch 2 at its contact): a straight line along
  // its stretch before leaves it 2 voxels on; its own sections, followed, go on. E along x at y 31,
  // z 24 crosses it there (radius 1.5 both, the axes 2.7 apart); the loop joins E at x 8. The path's
  // voxels between the axes are dimmer (still lumen).
  Scene s;
  s.capsule({20, 0, 20}, {20, 30, 20}, 1.5);
  s.capsule({20, 30, 20}, {20, 40, 27}, 1.5);
  s.capsule({20, 12, 20}, {8, 12, 20}, 1.5);
  s.capsule({8, 12, 20}, {8, 31, 24}, 1.5);
  s.capsule({0, 31, 24}, {59, 31, 24}, 1.5);
  for (int64_t z = 21; z <= 23; ++z) s.cost.node[static_cast<size_t>(s.g.linear(20, 31, z))] = 0.1f;
  std::vector<Index3> path;
  for (int64_t y = 0; y <= 30; ++y) path.push_back({20, y, 20});
  for (int64_t z = 21; z <= 24; ++z) path.push_back({20, 31, z});
  for (int64_t x = 21; x <= 50; ++x) path.push_back({x, 31, 24});
  const ContactRetrace r = retraceAcrossContact(s.cost, path, 26, 0.2, CrossingOptions{});
  expectRoutedRoundTheLoop(r, path);
}

}  // namespace
}  // namespace vs
