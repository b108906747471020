// Junction placement of the refined centreline (src/tracking/centreline_junctions.h, issue 21).
#include "tracking/centreline_junctions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "test_tree.h"

namespace vs {
namespace {

// A tree in mm (voxel 1 mm): a parent along x to the branch point b = (10, 0, 0), a child that
// continues it along x and a side branch leaving at 70 degrees whose axis beyond its zone runs 4 mm
// off in z (skew: the children's axes do not meet, so neither fork placement applies). The
// continuing child's first `zone` points lie `pull` mm off its axis towards the side branch, as the
// rays leave them in the section fused with it.
struct SkewFork : TestTree {
  std::vector<uint8_t> fused;
  std::vector<size_t> trunkZone;  // the continuing child's zone points
  explicit SkewFork(double pull) {
    auto add = [&](int32_t p, const Vec3& at, double r, bool f) {
      fused.push_back(f ? 1 : 0);
      return TestTree::add(p, at, r);
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

// Session 45 (held14404): a side branch's zone goes onto the line from b where the parent is no wider than the wide
// trunk's bound; in a wider lumen (the parent's radius 2 mm here, the bound 1.5 mm) it is left to placeWideTrunk.
TEST(CentrelineJunctions, SideBranchsZoneInAWideTrunkIsLeftToTheWideTrunk) {
  for (const double bound : {std::numeric_limits<double>::infinity(), 1.5}) {
    SkewFork f(1.5);
    const std::vector<Vec3> before = f.q;
    std::vector<uint8_t> frozen(f.q.size(), 0);
    auto fusedAt = [&](size_t k, double) { return f.fused[k] != 0; };
    centreline_detail::placeJunctions({f.parent, f.children, f.radius}, f.q, frozen, 1.0, fusedAt, {}, {}, nullptr,
                                      bound);
    const size_t side = f.q.size() - 20;  // the side branch's first point; its first two are its zone
    for (size_t k = side; k < side + 2; ++k) {
      EXPECT_EQ(frozen[k] != 0, std::isinf(bound)) << "bound " << bound << " point " << k;
      if (!std::isinf(bound)) {
        EXPECT_EQ(f.q[k], before[k]) << "point " << k;
      }
    }
    for (size_t k : f.trunkZone) EXPECT_TRUE(frozen[k]) << "bound " << bound << " point " << k;  // placeTrunk's
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

// A tree built point by point (each of radius 2 mm), linked as refineCentreline's.
struct PointTree {
  std::vector<int32_t> parent;
  std::vector<std::vector<int32_t>> children;
  std::vector<double> radius;
  std::vector<Vec3> q;
  int32_t add(int32_t p, const Vec3& at) {
    parent.push_back(p);
    children.emplace_back();
    if (p >= 0) children[static_cast<size_t>(p)].push_back(static_cast<int32_t>(q.size()));
    q.push_back(at), radius.push_back(2.0);
    return static_cast<int32_t>(q.size() - 1);
  }
  // splitForks' copy: a detached copy of point k (its parent and children set by the split), not frozen.
  size_t copyPoint(size_t k, std::vector<uint8_t>& frozen) {
    parent.push_back(-1), children.emplace_back(), q.push_back(q[k]), radius.push_back(radius[k]);
    frozen.push_back(0);
    return q.size() - 1;
  }
};

// Two children's chains that run together from the branch point b = (10, 0, 0) along x (centred on
// the fused lumen's middle line, y = +-0.05) and part at x = 19 towards G = (19, +-2, 0); the fork
// lies in the plane z = 0. Beyond G the arms bend so that their axes, extrapolated back, meet at
// (13, 0, 2.5): 2.5 mm beside the chains, off the lumen.
TEST(CentrelineJunctions, PartedForksJunctionIsTakenOnTheChainsWhereTheAxesMeetBesideThem) {
  PointTree t;
  auto& [parent, children, radius, q] = t;
  int32_t b = t.add(-1, Vec3(0, 0, 0));
  for (int x = 1; x <= 10; ++x) b = t.add(b, Vec3(x, 0, 0));
  const Vec3 X(13, 0, 2.5);
  for (const double side : {1.0, -1.0}) {
    int32_t last = b;
    for (int x = 11; x <= 18; ++x) last = t.add(last, Vec3(x, side * 0.05, 0));
    const Vec3 G(19, side * 2, 0), e = (G - X).normalized();
    for (int k = 0; k <= 10; ++k) last = t.add(last, G + k * e);
  }
  std::vector<uint8_t> frozen(q.size(), 0);
  const std::vector<Vec3> before = q;
  auto fusedAt = [](size_t, double) { return false; };
  centreline_detail::placeJunctions({parent, children, radius}, q, frozen, 1.0, fusedAt);
  // The junction on the chains: the parted section is placed (with J at the axes' meeting point
  // placeParted refused the fork and left it to the rays), and no point leaves the fork's plane.
  size_t moved = 0;
  // (The curve from J to G arrives at G along the arm's axis, which leaves the plane beyond G: the
  // last points before G move up to 0.14 mm out of it; J at the axes' meeting point moves them
  // more than a millimetre.)
  for (size_t k = 11; k < q.size(); ++k) {
    EXPECT_LT(std::abs(q[k][2] - before[k][2]), 0.25) << "point " << k;
    moved += (q[k] - before[k]).norm() > 1e-9;
  }
  EXPECT_GT(moved, 0u);
}

// The root's own fork of the two tests below: both chains leave the root (0, 0, 0) together
// along x, centred on the fused lumen's middle line (y = +-0.05), and part at x = 15, where they
// follow the children's curves y = +-c(x). chain[a] holds child a's points before the parting.
struct RootFork : TestTree {
  std::vector<std::vector<size_t>> chain;
};

RootFork makeRootFork(double r, const std::function<double(double)>& c) {
  RootFork f;
  auto add = [&](int32_t p, const Vec3& at) { return f.add(p, at, r); };
  const int32_t root = add(-1, Vec3(0, 0, 0));
  f.chain.resize(2);
  for (size_t a = 0; a < 2; ++a) {
    const double side = a == 0 ? 1.0 : -1.0;
    int32_t last = root;
    for (int x = 1; x <= 30; ++x) {
      last = add(last, Vec3(x, side * (x < 15 ? 0.05 : c(x)), 0));
      if (x < 15) f.chain[a].push_back(static_cast<size_t>(last));
    }
  }
  return f;
}

// The children's curve of the root fork below: y = +-c(x), c = 0.2 (x - 8) + 0.015 (x - 8)^2 past the
// junction at x = 8; their radius 2 mm.
constexpr double kForkRadius = 2, kForkJunction = 8;
double forkCurve(double x) {
  const double d = x - kForkJunction;
  return d <= 0 ? 0.0 : 0.2 * d + 0.015 * d * d;
}

// The widths of the fork's section at q[k]: two discs of radius r about y = +-c(x + earlyMm) (a
// positive earlyMm: the image's junction lies that much before the children's).
auto forkWidths(const std::vector<Vec3>& q, double r, std::function<double(double)> c, double earlyMm) {
  return [&q, r, c = std::move(c), earlyMm](size_t k, double, double& widest, double& narrowest) {
    const double sep = 2 * c(q[k][0] + earlyMm);
    narrowest = 2 * r, widest = sep < 2 * r ? 2 * r + sep : 2 * r;
    return true;
  };
}

// The true section at q[k] (normal to x) of the fork's two discs, radius r1 about y = +c(x) and r2
// about y = -c(x): their union along y (the widest chord) and along z; none where they have parted.
auto forkLobes(const std::vector<Vec3>& q, std::function<double(double)> c, double r1, double r2) {
  return [&q, c = std::move(c), r1, r2](size_t k, double, Vec3& dir, double& plus, double& minus, double& narrowest) {
    const double cc = c(q[k][0]), y = q[k][1];
    if (2 * cc >= r1 + r2) return false;  // parted: no wall between the lumens on this chord
    dir = Vec3(0, 1, 0), plus = cc + r1 - y, minus = cc + r2 + y;
    const double half = std::max(std::sqrt(std::max(0.0, r1 * r1 - (y - cc) * (y - cc))),
                                 std::sqrt(std::max(0.0, r2 * r2 - (y + cc) * (y + cc))));
    narrowest = std::min(2 * half, plus + minus);
    return true;
  };
}

// The root's own fork (session 18): both chains leave the root (0, 0, 0) together along x, centred
// on the fused lumen's middle line (y = +-0.05), and part at x = 15, where the children's lumens
// no longer overlap. The true children (radius 2 mm)
// leave the junction at x = 8 and curve away: y = +-c(x), c = 0.2 (x - 8) + 0.015 (x - 8)^2, so the
// arms' axes at their first round sections, extrapolated back, meet near x = 11, 3 mm past the
// junction. The image (the widths of a cross-section at x, from the two discs of radius 2 about
// the children's centres) widens the section by their separation 2 c(x) where they overlap.
TEST(CentrelineJunctions, RootForksJunctionIsTakenFromTheSectionsWidening) {
  RootFork fork = makeRootFork(kForkRadius, forkCurve);
  std::vector<Vec3>& q = fork.q;
  std::vector<uint8_t> frozen(q.size(), 0);
  const auto widths = forkWidths(q, kForkRadius, forkCurve, 0);
  auto fusedAt = [](size_t, double) { return false; };
  const std::vector<Vec3> before = q;
  centreline_detail::placeJunctions({fork.parent, fork.children, fork.radius}, q, frozen, 1.0, fusedAt, widths);
  // Every together point on its own child (or, before the junction, on the parent's axis y = 0):
  // within 0.3 mm. Left where they were, the points at x = 14 lie 1.7 mm off; with J where the axes
  // meet, those at x = 10 lie 0.4 mm off.
  for (size_t a = 0; a < 2; ++a) {
    const double side = a == 0 ? 1.0 : -1.0;
    for (size_t k : fork.chain[a]) {
      double off = 1e9;  // to the child's curve, sampled every 0.01 mm
      for (double x = 0; x <= 20; x += 0.01) off = std::min(off, (q[k] - Vec3(x, side * forkCurve(x), 0)).norm());
      EXPECT_LT(off, 0.3) << "child " << a << " x " << before[k][0];
    }
  }
}

// Session 20 (thin10): the same root fork, but the image's J lies 3 mm early (its widths are those of
// a fork at x = 5, as on thin seed 26's root fork, 3.3 mm early): the curve from that J runs beside
// the children.
// The sections themselves (two discs of radius 2 about y = +-c(x), the chains run between them)
// give each child's own centre: its lobe's end of the widest chord less the child's radius, and the
// child's own radius instead of the fused blob's.
TEST(CentrelineJunctions, FusedSectionsPointsGoToTheirOwnLobe) {
  constexpr double r = kForkRadius, x0 = kForkJunction;
  const auto c = forkCurve;
  RootFork fork = makeRootFork(r, c);
  std::vector<Vec3>& q = fork.q;  // a plain reference (the lambdas below capture it)
  const std::vector<std::vector<size_t>>& chain = fork.chain;
  const auto widths = forkWidths(q, r, c, 3);  // a junction 3 mm early
  const auto lobes = forkLobes(q, c, r, r);
  auto fusedAt = [](size_t, double) { return false; };
  auto worst = [&](const std::vector<Vec3>& pts, const std::vector<Vec3>& from) {
    double w = 0;
    for (size_t a = 0; a < 2; ++a) {
      const double side = a == 0 ? 1.0 : -1.0;
      for (size_t k : chain[a]) {
        if (from[k][0] <= x0 + 1) continue;  // the fused section: past the junction
        double off = 1e9;
        for (double x = 0; x <= 20; x += 0.01) off = std::min(off, (pts[k] - Vec3(x, side * c(x), 0)).norm());
        w = std::max(w, off);
      }
    }
    return w;
  };
  const std::vector<Vec3> before = q;
  std::vector<Vec3> curveOnly = q;
  std::vector<uint8_t> frozen(q.size(), 0);
  centreline_detail::placeJunctions({fork.parent, fork.children, fork.radius}, curveOnly, frozen, 1.0, fusedAt, widths);
  // The curve from the early J: 0.09 mm off the children (0.14 with J right, 1.6 with J 5 mm early:
  // refused by the reach check, the points left in the blob).
  EXPECT_GT(worst(curveOnly, before), 0.05);  // the curve from the early J: beside the children
  frozen.assign(q.size(), 0);
  std::vector<double> ownRadius(q.size(), std::numeric_limits<double>::quiet_NaN());
  centreline_detail::placeJunctions({fork.parent, fork.children, fork.radius}, q, frozen, 1.0, fusedAt, widths, lobes,
                                    &ownRadius);
  EXPECT_LT(worst(q, before), 0.05);  // in its own lobe: on the child
  size_t inLobe = 0;
  for (size_t a = 0; a < 2; ++a)
    for (size_t k : chain[a])
      if (!std::isnan(ownRadius[k])) {
        ++inLobe;
        EXPECT_DOUBLE_EQ(ownRadius[k], r);
      }
  EXPECT_GE(inLobe, 4u);
}

// A fork b = (11, 0, 0) whose children's axes meet at X = (8, 0, 0), 3 mm before b (splitForks
// re-branches it at the parent arm's point nearest X). With `parentFork` b's parent (10, 0, 0) is
// itself a branch point (a side branch leaves it along z): analyseFork's parent arm is empty, which
// splitForks indexed (a crash, seen on thin seed 33 with the local background's tail cap 3).
struct ForkAfterFork : PointTree {
  explicit ForkAfterFork(bool parentFork) {
    int32_t a = add(-1, Vec3(0, 0, 0));
    for (int x = 1; x <= 10; ++x) a = add(a, Vec3(x, 0, 0));
    if (parentFork) {
      int32_t last = a;
      for (int z = 1; z <= 10; ++z) last = add(last, Vec3(10, 0, z));
    }
    const int32_t b = add(a, Vec3(11, 0, 0));
    const Vec3 X(8, 0, 0);
    for (const double side : {1.0, -1.0}) {
      const Vec3 e(std::cos(20 * M_PI / 180), side * std::sin(20 * M_PI / 180), 0);
      int32_t last = b;
      for (int t = 4; t <= 20; ++t) last = add(last, X + t * e);
    }
  }
};

TEST(CentrelineJunctions, SplitForksLeavesAForkWhoseParentIsABranchPoint) {
  for (const bool parentFork : {false, true}) {
    ForkAfterFork f(parentFork);
    std::vector<uint8_t> frozen(f.q.size(), 0);
    const auto fusedAt = [](size_t, double) { return false; };
    const auto copy = [&](size_t k) { return f.copyPoint(k, frozen); };
    const size_t n = f.q.size();
    const size_t split = centreline_detail::splitForks(f.parent, f.children, f.q, frozen, f.radius, 1.0, fusedAt, copy);
    // A plain parent arm: the fork is re-branched (the geometry reaches the re-branching); a branch
    // point as the parent: no parent point to re-branch at, the tree is left as it was.
    EXPECT_EQ(split, parentFork ? 0u : 1u) << "parent fork " << parentFork;
    if (parentFork) {
      EXPECT_EQ(f.q.size(), n);
    }
  }
}

// Session 27 (par5): a fork whose thin child leaves steeply, its branch point b = (12, 0, 0) 2 mm past the
// junction J = (10, 0, 0) where the axes meet (10311: 2.5 mm past, slices 2.4 mm thick). The parent (radius 4 mm)
// goes on as the wide child (3 mm) along x; the thin child (1.5 mm) leaves J at 60 degrees towards +z. The shared
// points x = 11, 12 lie on the wide child's axis; b lies 1.73 mm from the thin child's, more than its radius: it
// sits in the wide child alone, which is where the thin child's path ran through the parent's lumen. With `off`
// the shared points lie 3.5 mm off both axes (towards -y): in neither tube, the axes do not describe them.
struct SteepLateFork : PointTree {
  int32_t b = -1, thinFirst = -1;
  explicit SteepLateFork(double off) {
    int32_t a = add(-1, Vec3(0, 0, 0));
    for (int x = 1; x <= 10; ++x) a = add(a, Vec3(x, 0, 0)), radius.back() = 4;
    a = add(a, Vec3(11, -off, 0)), radius.back() = 4;
    b = add(a, Vec3(12, -off, 0)), radius.back() = 4;
    int32_t last = b;
    for (int x = 13; x <= 40; ++x) last = add(last, Vec3(x, 0, 0)), radius.back() = 3;
    const Vec3 e(0.5, 0, std::sqrt(3.0) / 2);
    last = b;
    for (int t = 3; t <= 20; ++t) {
      last = add(last, Vec3(10, 0, 0) + t * e), radius.back() = 1.5;
      if (t == 3) thinFirst = last;
    }
  }
};

TEST(CentrelineJunctions, SplitForksReBranchesAForkWhoseSharedPointsLieInOneChildsTube) {
  for (const double off : {0.0, 3.5}) {
    SteepLateFork f(off);
    std::vector<uint8_t> frozen(f.q.size(), 0);
    const auto fusedAt = [](size_t, double) { return false; };
    const auto copy = [&](size_t k) { return f.copyPoint(k, frozen); };
    const size_t n = f.q.size();
    const size_t split = centreline_detail::splitForks(f.parent, f.children, f.q, frozen, f.radius, 1.0, fusedAt, copy);
    if (off > 0) {  // in neither child's tube: left alone
      EXPECT_EQ(split, 0u);
      EXPECT_EQ(f.q.size(), n);
      continue;
    }
    ASSERT_EQ(split, 1u);
    ASSERT_EQ(f.q.size(), n + 2);  // x = 11 and b copied for the thin child
    // The thin child hangs from the copies, which lie on its axis from J; the copies hang from P = (10, 0, 0).
    const size_t c2 = static_cast<size_t>(f.parent[static_cast<size_t>(f.thinFirst)]);
    EXPECT_EQ(c2, n + 1);
    EXPECT_EQ(f.parent[n + 1], static_cast<int32_t>(n));
    EXPECT_DOUBLE_EQ(f.q[static_cast<size_t>(f.parent[n])][0], 10);
    const Vec3 e(0.5, 0, std::sqrt(3.0) / 2), J(10, 0, 0);
    for (size_t k : {n, n + 1}) {
      const Vec3 d = f.q[k] - J;
      EXPECT_LT((d - d.dot(e) * e).norm(), 1e-9) << "copy " << k;  // on the thin child's axis
      EXPECT_GT(d.dot(e), 0) << "copy " << k;
    }
    EXPECT_LT(f.q[static_cast<size_t>(f.b)][2], 1e-9);  // b stays on the wide child's axis
    EXPECT_EQ(f.children[static_cast<size_t>(f.b)].size(), 1u);
  }
}

// Session 22 (thin12): the root fork with children of unequal radii (1.5 mm on +y, 2.5 mm on -y),
// as on thin seed 10525's coarse slices. At x = 14 the chains still run together in the fused
// section (the children's centres 3.5 mm apart, less than their summed radii); the smaller
// child's lobe centre lies 1.69 mm from its chain point, more than its own radius: a point
// centred between two lobes lies up to half the summed radii from each. The move guard took that
// for a wrong junction and left the whole fork to the rays (1.7 mm off the smaller child).
TEST(CentrelineJunctions, LobePointsOfASmallerChildMayMoveUpToHalfTheSummedRadii) {
  constexpr double r1 = 1.5, r2 = 2.5;
  const auto c = forkCurve;
  RootFork fork = makeRootFork(kForkRadius, c);
  std::vector<Vec3>& q = fork.q;
  for (size_t k = 1; k < q.size(); ++k) fork.radius[k] = k <= 30 ? r1 : r2;  // the +y chain first (30 points)
  const auto lobes = forkLobes(q, c, r1, r2);
  auto fusedAt = [](size_t, double) { return false; };
  std::vector<uint8_t> frozen(q.size(), 0);
  const std::vector<Vec3> before = q;
  std::vector<double> ownRadius(q.size(), std::numeric_limits<double>::quiet_NaN());
  centreline_detail::placeJunctions({fork.parent, fork.children, fork.radius}, q, frozen, 1.0, fusedAt, {}, lobes,
                                    &ownRadius);
  const size_t k14 = fork.chain[0].back();  // the smaller child's last together point, x = 14
  ASSERT_DOUBLE_EQ(before[k14][0], 14);
  EXPECT_LT((q[k14] - Vec3(14, c(14), 0)).norm(), 0.1);  // left by the guard: 1.69 mm off
  EXPECT_DOUBLE_EQ(ownRadius[k14], r1);
}

// A fork at b = (10, 0, 0) whose children leave it 30 degrees either side of x in the plane z = 0;
// their first two points lie in the section fused with the sibling, and beyond them the arms bend
// down so that their axes, extrapolated back, meet at X = (8, 0, 3): 3 mm off every point of the
// tree (10529's root fork: 6 voxels beside it). Placed on segments from X the zone points would go
// 2 mm into the background; with J refused they are left or placed from the chains themselves.
TEST(CentrelineJunctions, ForkWhoseAxesMeetOffTheTreeIsNotPlacedFromThere) {
  PointTree t;
  int32_t b = t.add(-1, Vec3(0, 0, 0));
  for (int x = 1; x <= 10; ++x) b = t.add(b, Vec3(x, 0, 0));
  const Vec3 X(8, 0, 3);
  std::vector<size_t> zone;
  for (const double side : {1.0, -1.0}) {
    const Vec3 d(std::cos(30 * M_PI / 180), side * std::sin(30 * M_PI / 180), 0);
    int32_t last = b;
    for (int k = 1; k <= 2; ++k) zone.push_back(static_cast<size_t>(last = t.add(last, Vec3(10, 0, 0) + k * d)));
    const Vec3 G = Vec3(10, 0, 0) + 3 * d, e = (G - X).normalized();
    for (int k = 0; k <= 10; ++k) last = t.add(last, G + k * e);
  }
  std::vector<uint8_t> frozen(t.q.size(), 0);
  const std::vector<Vec3> before = t.q;
  auto fusedAt = [&](size_t k, double) { return std::find(zone.begin(), zone.end(), k) != zone.end(); };
  centreline_detail::placeJunctions({t.parent, t.children, t.radius}, t.q, frozen, 1.0, fusedAt);
  // No zone point leaves the fork's plane towards X (from X: 2 mm and 1 mm up; the chains' own
  // placement (placeParted) keeps them within 0.35 mm of it).
  for (size_t k : zone) EXPECT_LT(std::abs(t.q[k][2]), 0.5) << "point " << k << " from " << before[k].transpose();
}

// A fork whose branch point B = (10, 0, 0) ends a parent along x from the root (0, 0, 0) and whose
// children leave `deg` degrees either side of x (dir): each child's 4 fused zone points at
// zoneAt(k, side, dir), its first round section G at gAt(dir), then 10 points on from G away from
// X = (14, 0, 0), where the children's axes meet.
struct LateFork {
  PointTree t;
  std::vector<size_t> zone;  // both children's zone points, the first child's first
  Vec3 dir[2], G[2];
};
const Vec3 kLateB(10, 0, 0), kLateX(14, 0, 0);
LateFork makeLateFork(double deg, const std::function<Vec3(int, double, const Vec3&)>& zoneAt,
                      const std::function<Vec3(const Vec3&)>& gAt) {
  LateFork f;
  int32_t b = f.t.add(-1, Vec3(0, 0, 0));
  for (int x = 1; x <= 10; ++x) b = f.t.add(b, Vec3(x, 0, 0));
  for (size_t a = 0; a < 2; ++a) {
    const double side = a == 0 ? 1.0 : -1.0;
    f.dir[a] = Vec3(std::cos(deg * M_PI / 180), side * std::sin(deg * M_PI / 180), 0);
    int32_t last = b;
    for (int k = 1; k <= 4; ++k) f.zone.push_back(static_cast<size_t>(last = f.t.add(last, zoneAt(k, side, f.dir[a]))));
    f.G[a] = gAt(f.dir[a]);
    const Vec3 e = (f.G[a] - kLateX).normalized();
    for (int k = 0; k <= 10; ++k) last = f.t.add(last, f.G[a] + k * e);
  }
  return f;
}

// Session 22 (thin13): a narrow fork (children 12 degrees either side of x) that parts at its
// branch point b = (10, 0, 0), whose children's axes beyond their zones (4 fused points each, on
// their own lines from b) meet at X = (14, 0, 0), 4 mm late (10532's fork 5: near-parallel axes).
// From X the zones go onto b -> X -> G, the first points of both children onto one line between
// them (up to 0.66 mm off their own); the sections' widening (two discs of radius 2 whose centres
// part from b) puts J at b.
TEST(CentrelineJunctions, NarrowForksJunctionIsTakenFromTheSectionsWhereTheAxesMeetLate) {
  LateFork f = makeLateFork(
      12, [](int k, double, const Vec3& d) { return Vec3(kLateB + k * d); },
      [](const Vec3& d) { return Vec3(kLateB + 5 * d); });
  PointTree& t = f.t;
  const std::vector<size_t>& zone = f.zone;
  std::vector<uint8_t> frozen(t.q.size(), 0);
  auto fusedAt = [&](size_t k, double) { return std::find(zone.begin(), zone.end(), k) != zone.end(); };
  const double r = 2.0;
  auto widths = [&t, r](size_t k, double, double& widest, double& narrowest) {
    const double sep = 2 * std::abs(t.q[k][1]);
    narrowest = 2 * r, widest = sep < 2 * r ? 2 * r + sep : 2 * r;
    return true;
  };
  const std::vector<Vec3> before = t.q;
  centreline_detail::placeJunctions({t.parent, t.children, t.radius}, t.q, frozen, 1.0, fusedAt, widths);
  for (size_t i = 0; i < zone.size(); ++i) {
    const Vec3 v = t.q[zone[i]] - kLateB, d = f.dir[i / 4];
    EXPECT_LT((v - v.dot(d) * d).norm(), 0.3) << "point " << zone[i] << " from " << before[zone[i]].transpose();
  }
}

// Session 23 (thin14): a fork whose discrete paths part at b = (10, 0, 0), 4 mm before the
// children's axes meet at X = (14, 0, 0) (children 40 degrees either side of x; their 4 zone points
// run side by side from b), and whose sections widen along the tree from x = 5, well behind b (on
// 10621 the fused section of the fork above, up the parent arm): the widening's J lies 5 mm behind
// b. Taken, the zones went onto J -> G, behind b; the axes' J keeps them on b -> X -> G.
TEST(CentrelineJunctions, ForksImageJunctionBehindTheBranchPointIsNotTaken) {
  LateFork f = makeLateFork(
      40, [](int k, double side, const Vec3&) { return Vec3(kLateB + Vec3(k, side * 0.2 * k, 0)); },
      [](const Vec3& d) { return Vec3(kLateX + 2 * d); });
  PointTree& t = f.t;
  const std::vector<size_t>& zone = f.zone;
  std::vector<uint8_t> frozen(t.q.size(), 0);
  auto fusedAt = [&](size_t k, double) { return std::find(zone.begin(), zone.end(), k) != zone.end(); };
  auto widths = [&t](size_t k, double, double& widest, double& narrowest) {
    narrowest = 4, widest = 4 + 0.5 * std::max(0.0, t.q[k][0] - 5);
    return true;
  };
  const std::vector<Vec3> before = t.q;
  centreline_detail::placeJunctions({t.parent, t.children, t.radius}, t.q, frozen, 1.0, fusedAt, widths);
  auto toSegment = [](const Vec3& p, const Vec3& a, const Vec3& c) {
    const double s = std::clamp((p - a).dot(c - a) / (c - a).squaredNorm(), 0.0, 1.0);
    return (p - (a + s * (c - a))).norm();
  };
  for (size_t i = 0; i < zone.size(); ++i) {
    const Vec3& p = t.q[zone[i]];
    EXPECT_LT(std::min(toSegment(p, kLateB, kLateX), toSegment(p, kLateX, f.G[i / 4])), 0.1)
        << "point " << zone[i] << " from " << before[zone[i]].transpose() << " at " << p.transpose();
  }
}

// Session 23 (thin14): PartedForksJunction...'s chains (together from b = (10, 0, 0) along x to
// x = 18, G = (19, +-2, 0)), the arms' axes meeting on them at X = (15, 0, 0); the sections widen
// slowly from x = 6 (a plateau 0.6 mm wide rising 0.08 mm per mm: the fused section of a fork
// above), so the widening's fitted line reaches 0 at x = -1.5, before the track. Clamped, J went
// to the track's start and the fork was refused (the chains' ends out of its reach); with no J from
// the image, the axes' J places the points past X on their children.
TEST(CentrelineJunctions, PartedForksImageJunctionBeforeTheTrackIsNotTaken) {
  PointTree t;
  int32_t b = t.add(-1, Vec3(0, 0, 0));
  for (int x = 1; x <= 10; ++x) b = t.add(b, Vec3(x, 0, 0));
  const Vec3 X(15, 0, 0);
  std::vector<std::pair<size_t, Vec3>> past;  // the together points past X and their child's G
  for (const double side : {1.0, -1.0}) {
    int32_t last = b;
    const Vec3 G(19, side * 2, 0), e = (G - X).normalized();
    for (int x = 11; x <= 18; ++x) {
      last = t.add(last, Vec3(x, side * 0.05, 0));
      if (x > 15) past.emplace_back(static_cast<size_t>(last), G);
    }
    for (int k = 0; k <= 10; ++k) last = t.add(last, G + k * e);
  }
  std::vector<uint8_t> frozen(t.q.size(), 0);
  auto fusedAt = [](size_t, double) { return false; };
  auto widths = [&t](size_t k, double, double& widest, double& narrowest) {
    narrowest = 4, widest = 4 + (t.q[k][0] >= 6 ? 0.6 + 0.08 * (t.q[k][0] - 6) : 0.0);
    return true;
  };
  centreline_detail::placeJunctions({t.parent, t.children, t.radius}, t.q, frozen, 1.0, fusedAt, widths);
  for (const auto& [k, G] : past) {
    const Vec3 v = t.q[k] - X, d = (G - X).normalized();
    EXPECT_LT((v - v.dot(d) * d).norm(), 0.3) << "point " << k << " at " << t.q[k].transpose();
  }
}

// Appends a point to a search tree under parent p; returns its index.
int32_t addTreePoint(CentrelineTree& t, int32_t p, const Vec3& at) {
  t.points.push_back(at), t.parent.push_back(p);
  return static_cast<int32_t>(t.points.size() - 1);
}

// Session 25 (fork3): two sibling paths that differ by one voxel in z from the search tree's fork (10, 0, 0) on
// and run side by side through their common parent up to (20, 0, 0), where they part (the family's 10801 /
// 10201). The later chain's points there follow the earlier's and its rest hangs from the earlier's point where
// they part; the refinement of that tree, expanded, gives each path's chain its input parents and a follower
// its leader's position.
TEST(CentrelineTogether, SiblingChainsAVoxelApartAreOneChainUpToWhereTheyPart) {
  CentrelineTree t;
  auto add = [&t](int32_t p, const Vec3& at) { return addTreePoint(t, p, at); };
  int32_t b = add(-1, Vec3(0, 0, 0));
  for (int x = 1; x <= 10; ++x) b = add(b, Vec3(x, 0, 0));
  int32_t a = b, c = b;
  std::vector<int32_t> lead, follow;
  for (int x = 11; x <= 20; ++x) lead.push_back(a = add(a, Vec3(x, 0, 0)));
  for (int k = 1; k <= 5; ++k) a = add(a, Vec3(20 + k, 2 * k, 0));
  for (int x = 11; x <= 20; ++x) follow.push_back(c = add(c, Vec3(x, 0, 1)));
  const int32_t rest = add(c, Vec3(21, -2, 1));
  for (int k = 2; k <= 5; ++k) add(static_cast<int32_t>(t.points.size() - 1), Vec3(20 + k, -2 * k, 1));
  const Vec3 sp(1, 1, 1);
  // A run of 10 mm: merged from 5 mm, left as it is from 12 mm.
  EXPECT_EQ(centreline_detail::mergeTogetherChains(t, sp, 12).merges, 0u);
  const centreline_detail::TogetherForks m = centreline_detail::mergeTogetherChains(t, sp, 5);
  ASSERT_EQ(m.merges, 1u);
  ASSERT_EQ(m.merged.points.size(), t.points.size() - follow.size());
  for (size_t s = 0; s < follow.size(); ++s) EXPECT_EQ(m.leader[static_cast<size_t>(follow[s])], lead[s]);
  // The fork lies at (20, 0, 0) now: its two children are the earlier chain's next point and the rest.
  EXPECT_EQ(m.merged.parent[static_cast<size_t>(m.newIndex[static_cast<size_t>(rest)])], m.newIndex[lead.back()]);
  // Expanded: a "refinement" that moves every merged point by +0.25 in y.
  RefinedCentreline r;
  for (size_t k = 0; k < m.merged.points.size(); ++k) {
    r.points.push_back(m.merged.points[k] + Vec3(0, 0.25, 0));
    r.radiiMm.push_back(1.0 + static_cast<double>(k));
    r.parent.push_back(m.merged.parent[k]);
    r.source.push_back(static_cast<int32_t>(k));
  }
  r.polarity = -1;  // a dark lumen: the expanded tree keeps it (confineToLumen's image test reads it)
  const RefinedCentreline out = centreline_detail::expandTogether(m, t, r);
  ASSERT_EQ(out.points.size(), t.points.size());
  EXPECT_EQ(out.polarity, -1);
  EXPECT_EQ(out.parent, t.parent);
  for (size_t s = 0; s < follow.size(); ++s) {
    const size_t f = static_cast<size_t>(follow[s]), l = static_cast<size_t>(lead[s]);
    EXPECT_LT((out.points[f] - out.points[l]).norm(), 1e-9);
    EXPECT_EQ(out.radiiMm[f], out.radiiMm[l]);
  }
  EXPECT_LT((out.points[static_cast<size_t>(rest)] - Vec3(21, -1.75, 1)).norm(), 1e-9);
}

// Session 30 (thin27): 11402's sibling paths (0.99 x 0.99 x 2.01 mm), one voxel apart from the tree's fork
// (34, 60, 30) on: across a slice (a face neighbour, 2.01 mm) where the nearest pair is an in-plane diagonal (1.40
// mm). Walked by the nearest pair the run ended at its fourth pair, 6.7 mm along (under 10 mm: not merged); with
// the pairs within a voxel first it ends at the sixth, 11.6 mm, and the later chain's rest hangs from (37, 66, 34).
TEST(CentrelineTogether, PairsWithinAVoxelCarryTheRunAcrossThickSlices) {
  CentrelineTree t;
  auto add = [&t](int32_t p, const Vec3& at) { return addTreePoint(t, p, at); };
  int32_t b = add(-1, Vec3(34, 50, 30));
  for (int y = 51; y <= 60; ++y) b = add(b, Vec3(34, y, 30));
  const std::vector<Vec3> earlier{{34, 61, 31}, {34, 62, 31}, {34, 63, 31}, {35, 64, 32}, {36, 65, 33},
                                  {37, 66, 34}, {38, 65, 35}, {39, 64, 35}, {40, 63, 36}, {40, 62, 36}};
  const std::vector<Vec3> later{{35, 61, 31}, {35, 62, 31}, {35, 63, 31}, {36, 64, 32}, {36, 65, 32}, {37, 66, 33},
                                {38, 67, 34}, {39, 67, 35}, {40, 67, 35}, {41, 68, 36}, {42, 67, 37}};
  std::vector<int32_t> lead, follow;
  int32_t a = b;
  for (const Vec3& p : earlier) lead.push_back(a = add(a, p));
  a = b;
  for (const Vec3& p : later) follow.push_back(a = add(a, p));
  const centreline_detail::TogetherForks m = centreline_detail::mergeTogetherChains(t, Vec3(0.99, 0.99, 2.01), 10);
  ASSERT_EQ(m.merges, 1u);
  for (size_t s = 0; s < 6; ++s) EXPECT_EQ(m.leader[static_cast<size_t>(follow[s])], lead[s]) << s;
  const size_t rest = static_cast<size_t>(follow[6]);
  EXPECT_EQ(m.merged.parent[static_cast<size_t>(m.newIndex[rest])], m.newIndex[static_cast<size_t>(lead[5])]);
}

// Session 26 (thin19): a narrow fork whose children run on side by side, their lumens fused, for
// 10 mm before the tree's branch point b = (20, 0, 0) (10929 / 10221). The parent arm's sections
// from x = 11 on are widened by a plateau (two discs of radius 2, centres 2-2.2 mm apart); the
// children run parallel beyond b (their axes do not meet), so only the sections show the junction
// at x = 10. `firstApart`: the children's first points' separation. Apart (2.4 mm: the paths step
// into their own lumens where the shared stretch ends) the fork is re-branched at x = 10; starting
// together (0.6 mm: a fork branched at its junction, the parent widened before it, 10201) it is
// left alone; so it is where the sections are one oval lumen (a 6 mm lumen cut obliquely, widened by
// 1.2 mm: not two discs of radius 2), and without the sections (main before session 26).
struct SideBySideFork : PointTree {
  explicit SideBySideFork(double firstApart) {
    int32_t a = add(-1, Vec3(0, 0, 0));
    for (int x = 1; x <= 20; ++x) a = add(a, Vec3(x, 0, 0));
    for (const double side : {1.0, -1.0}) {
      int32_t last = add(a, Vec3(21, side * 0.5 * firstApart, 0));
      for (int x = 22; x <= 27; ++x) last = add(last, Vec3(x, side * 1.2, 0));
      for (int t = 1; t <= 15; ++t)
        last = add(last, Vec3(27 + t * std::cos(M_PI / 6), side * (1.2 + t * std::sin(M_PI / 6)), 0));
    }
  }
  // The stretch's widening over the narrowest chord: `by` at x = 11, rising 0.02 mm per mm to b.
  double widening(size_t k, double by) const {
    const bool stretch = k < 21 && q[k][0] >= 11;
    return stretch ? by + 0.02 * (q[k][0] - 11) : 0.0;
  }
};

TEST(CentrelineJunctions, SplitForksReBranchesSideBySideChildrenWhereTheirTwoLumensStart) {
  struct Case {
    double apart;
    bool sections, oval, split;
  };
  for (const Case c : {Case{2.4, true, false, true}, Case{0.6, true, false, false}, Case{2.4, true, true, false},
                       Case{2.4, false, false, false}}) {
    SideBySideFork f(c.apart);
    std::vector<uint8_t> frozen(f.q.size(), 0);
    const auto fusedAt = [](size_t, double) { return false; };
    const auto copy = [&](size_t k) { return f.copyPoint(k, frozen); };
    const double narrow = c.oval ? 6 : 4, by = c.oval ? 1.2 : 2.0;
    const centreline_detail::SectionWidths widths = [&](size_t k, double, double& widest, double& narrowest) {
      narrowest = narrow, widest = narrow + f.widening(k, by);
      return true;
    };
    const centreline_detail::SectionLobes lobes = [&](size_t k, double, Vec3& dir, double& plus, double& minus,
                                                      double& narrowest) {
      dir = Vec3(0, 1, 0), plus = minus = 0.5 * (narrow + f.widening(k, by)), narrowest = narrow;
      return true;
    };
    const size_t split =
        c.sections ? centreline_detail::splitForks(f.parent, f.children, f.q, frozen, f.radius, 1.0, fusedAt, copy,
                                                   widths, {}, lobes)
                   : centreline_detail::splitForks(f.parent, f.children, f.q, frozen, f.radius, 1.0, fusedAt, copy);
    EXPECT_EQ(split, c.split ? 1u : 0u) << "apart " << c.apart << " sections " << c.sections << " oval " << c.oval;
    if (!c.split) continue;
    // The new branch point: the parent arm's point at x = 10, with two children (one a copy).
    EXPECT_EQ(f.children[10].size(), 2u);
    EXPECT_TRUE(frozen[20]);
  }
}
// Session 49 (fork16110): inParent on the sections' own readings (widest / narrowest chord, mm) of two parted forks on
// thick slices. 16110 (0.79 x 0.79 x 2.30 mm): the trunk's own sections read up to 1 mm wider than its 4.94 mm
// diameter across the slices, gradually (5.18-5.93 after b's 5.54), until the union (7.60) - all 11 are the parent's.
// 11932 (0.80 x 0.80 x 2.19 mm): b reads the diameter (4.61), the third section 5.20 - the fork's first widening, a
// jump of 0.75 mm within half a slice of the diameter - then the union (6.49): the run ends before it (half the
// smallest voxel kept 3 of 16110's, half the coarsest spacing alone took 11932's widening section in).
TEST(CentrelineJunctions, InParentKeepsTheSmearOfThickSlicesButNotAForksFirstWidening) {
  auto readings = [](std::vector<std::pair<double, double>> w) {
    return [w](size_t k, double, double& widest, double& narrowest) {
      if (k >= w.size()) return false;
      widest = w[k].first, narrowest = w[k].second;
      return true;
    };
  };
  const std::vector<size_t> arm = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  const centreline_detail::SectionWidths trunk16110 = readings({{5.54, 4.94},
                                                                {5.32, 4.75},
                                                                {5.18, 4.68},
                                                                {5.30, 4.84},
                                                                {5.39, 4.91},
                                                                {5.48, 5.00},
                                                                {5.34, 4.99},
                                                                {5.49, 5.08},
                                                                {5.33, 4.89},
                                                                {5.33, 4.78},
                                                                {5.53, 4.83},
                                                                {5.93, 4.59},
                                                                {7.60, 4.11}});
  EXPECT_EQ(centreline_detail::inParent(arm, 0, 12, trunk16110, 20, 2.47, 0.79, 2.30), 11u);
  const centreline_detail::SectionWidths fork11932 =
      readings({{4.61, 3.79}, {4.52, 3.83}, {4.45, 3.74}, {5.20, 3.78}, {6.49, 3.86}, {7.29, 3.71}});
  EXPECT_EQ(centreline_detail::inParent(arm, 0, 5, fork11932, 20, 2.30, 0.80, 2.19), 2u);
  const centreline_detail::SectionWidths fork11932b =
      readings({{4.61, 3.79}, {4.42, 3.80}, {4.72, 3.72}, {5.33, 3.70}, {6.94, 3.77}});
  EXPECT_EQ(centreline_detail::inParent(arm, 0, 4, fork11932b, 20, 2.30, 0.80, 2.19), 2u);
  // With the coarsest spacing the smallest (isotropic voxels) the allowance is half the voxel, as before.
  EXPECT_EQ(centreline_detail::inParent(arm, 0, 12, trunk16110, 20, 2.47, 0.79, 0.79), 3u);
}

}  // namespace
}  // namespace vs
