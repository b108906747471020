// Junction placement of the refined centreline (src/tracking/centreline_junctions.h, issue 21).
#include "tracking/centreline_junctions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace vs {
namespace {

// A tree in mm (voxel 1 mm): a parent along x to the branch point b = (10, 0, 0), a child that
// continues it along x and a side branch leaving at 70 degrees whose axis beyond its zone runs 4 mm
// off in z (skew: the children's axes do not meet, so neither fork placement applies). The
// continuing child's first `zone` points lie `pull` mm off its axis towards the side branch, as the
// rays leave them in the section fused with it.
struct SkewFork {
  std::vector<int32_t> parent;
  std::vector<std::vector<int32_t>> children;
  std::vector<double> radius;
  std::vector<Vec3> q;
  std::vector<uint8_t> fused;
  std::vector<size_t> trunkZone;  // the continuing child's zone points
  explicit SkewFork(double pull) {
    auto add = [&](int32_t p, const Vec3& at, double r, bool f) {
      parent.push_back(p);
      children.emplace_back();
      if (p >= 0) children[static_cast<size_t>(p)].push_back(static_cast<int32_t>(q.size()));
      q.push_back(at), radius.push_back(r), fused.push_back(f ? 1 : 0);
      return static_cast<int32_t>(q.size() - 1);
    };
    int32_t last = add(-1, Vec3(0, 0, 0), 2.0, false);
    for (int x = 1; x <= 10; ++x) last = add(last, Vec3(x, 0, 0), 2.0, false);
    const int32_t b = last;
    for (int x = 11; x <= 30; ++x) {
      const bool zone = x <= 14;
      last = add(last, Vec3(x, zone ? pull : 0.0, 0), 2.0, zone);
      if (zone) trunkZone.push_back(static_cast<size_t>(last));
    }
    const Vec3 d(std::cos(70 * M_PI / 180), std::sin(70 * M_PI / 180), 0);
    last = b;
    for (int k = 1; k <= 20; ++k) last = add(last, Vec3(10, 0, 0) + k * d + Vec3(0, 0, k > 2 ? 4.0 : 0.0), 1.2, k <= 2);
  }
};

TEST(CentrelineJunctions, ContinuingChildsFusedZoneGoesOntoTheTrunkWhereNoForkPlacementApplies) {
  SkewFork f(1.5);
  std::vector<uint8_t> frozen(f.q.size(), 0);
  auto fusedAt = [&](size_t k, double) { return f.fused[k] != 0; };
  centreline_detail::placeJunctions({f.parent, f.children, f.radius}, f.q, frozen, 1.0, fusedAt);
  // The trunk's chord from the parent's first round point (9, 0, 0) to the child's first round
  // section (15, 0, 0): the zone points back on the axis, frozen, in their order along it.
  double x = 10;
  for (size_t k : f.trunkZone) {
    EXPECT_LT(std::hypot(f.q[k][1], f.q[k][2]), 0.05) << "point " << k;
    EXPECT_TRUE(frozen[k]) << "point " << k;
    EXPECT_GT(f.q[k][0], x) << "point " << k;
    x = f.q[k][0];
  }
}

TEST(CentrelineJunctions, TrunkZoneFartherThanTheChildsRadiusFromTheChordIsLeftAlone) {
  SkewFork f(2.5);  // more than the child's own radius (2 mm) off: the chord is not the trunk's
  std::vector<uint8_t> frozen(f.q.size(), 0);
  auto fusedAt = [&](size_t k, double) { return f.fused[k] != 0; };
  centreline_detail::placeJunctions({f.parent, f.children, f.radius}, f.q, frozen, 1.0, fusedAt);
  for (size_t k : f.trunkZone) {
    EXPECT_NEAR(f.q[k][1], 2.5, 1e-12) << "point " << k;
    EXPECT_FALSE(frozen[k]) << "point " << k;
  }
}

}  // namespace
}  // namespace vs
