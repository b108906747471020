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

// Two children's chains that run together from the branch point b = (10, 0, 0) along x (centred on
// the fused lumen's middle line, y = +-0.05) and part at x = 19 towards G = (19, +-2, 0); the fork
// lies in the plane z = 0. Beyond G the arms bend so that their axes, extrapolated back, meet at
// (13, 0, 2.5): 2.5 mm beside the chains, off the lumen.
TEST(CentrelineJunctions, PartedForksJunctionIsTakenOnTheChainsWhereTheAxesMeetBesideThem) {
  std::vector<int32_t> parent;
  std::vector<std::vector<int32_t>> children;
  std::vector<double> radius;
  std::vector<Vec3> q;
  auto add = [&](int32_t p, const Vec3& at) {
    parent.push_back(p);
    children.emplace_back();
    if (p >= 0) children[static_cast<size_t>(p)].push_back(static_cast<int32_t>(q.size()));
    q.push_back(at), radius.push_back(2.0);
    return static_cast<int32_t>(q.size() - 1);
  };
  int32_t b = add(-1, Vec3(0, 0, 0));
  for (int x = 1; x <= 10; ++x) b = add(b, Vec3(x, 0, 0));
  const Vec3 X(13, 0, 2.5);
  for (const double side : {1.0, -1.0}) {
    int32_t last = b;
    for (int x = 11; x <= 18; ++x) last = add(last, Vec3(x, side * 0.05, 0));
    const Vec3 G(19, side * 2, 0), e = (G - X).normalized();
    for (int k = 0; k <= 10; ++k) last = add(last, G + k * e);
  }
  std::vector<uint8_t> frozen(q.size(), 0);
  const std::vector<Vec3> before = q;
  auto fusedAt = [](size_t, double) { return false; };
  centreline_detail::placeJunctions({parent, children, radius}, q, frozen, 1.0, fusedAt);
  // The junction on the chains: the parted section is placed (with J at the axes' meeting point
  // placeParted refused the fork and left it to the rays), and no point leaves the fork's plane.
  size_t moved = 0;
  for (size_t k = 11; k < q.size(); ++k) {
    EXPECT_LT(std::abs(q[k][2] - before[k][2]), 0.05) << "point " << k;
    moved += (q[k] - before[k]).norm() > 1e-9;
  }
  EXPECT_GT(moved, 0u);
}

}  // namespace
}  // namespace vs
