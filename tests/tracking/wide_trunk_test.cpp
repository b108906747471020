// Wide trunks and the daughters that leave them (src/tracking/wide_trunk.h, issue 21, session 15).
#include "tracking/wide_trunk.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <utility>
#include <vector>

#include "family_trace.h"
#include "phantom/phantom.h"
#include "tracking/centreline.h"
#include "tracking/cross_section.h"
#include "tracking/daughter_tube.h"
#include "tracking/trace_run.h"

namespace vs {
namespace {

// Distance from p to the segment a-b.
double segmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - a - t * ab).norm();
}

// A straight trunk of radius 12 voxels along x (axis y = z = 24) and a daughter of radius 2.5
// leaving it at 70 degrees from the axis point J = (34, 24, 24), flat inside (200 on 20), partial
// volume by 3x3x3 supersampling. With `bendVoxels` the daughter is straight to the trunk's wall and
// then bends along z, bendVoxels x (its length beyond the wall, as a share)^2 (as the family's).
struct TrunkCase {
  VolumeF32 volume;
  Vec3 J{34, 24, 24}, d;
  double R = 12, r, daughterLength = 29;
  double bend = 0;
  std::vector<Vec3> course;  // the daughter's axis from J, a polyline
  Vec3 at(double t) const {  // the daughter's axis t voxels from J (along d)
    const double inner = R / d[1], share = std::max(0.0, t - inner) / (daughterLength - inner);
    return J + t * d + bend * share * share * Vec3(0, 0, 1);
  }
  double courseDistance(const Vec3& p) const {
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 1; i < course.size(); ++i) best = std::min(best, segmentDistance(p, course[i - 1], course[i]));
    return best;
  }
  explicit TrunkCase(double degrees = 70, double daughterRadius = 2.5, double bendVoxels = 0)
      : volume(makeGeometry(), 20.0f),
        d(std::cos(degrees * M_PI / 180), std::sin(degrees * M_PI / 180), 0),
        r(daughterRadius),
        bend(bendVoxels) {
    course = {J, J + daughterLength * d};
    if (bend != 0) {
      course.clear();
      for (double t = 0; t <= daughterLength + 1e-9; t += 1) course.push_back(at(t));
    }
    const Index3 dims = volume.geometry().dims;
    for (int64_t z = 0; z < dims[2]; ++z)
      for (int64_t y = 0; y < dims[1]; ++y)
        for (int64_t x = 0; x < dims[0]; ++x) {
          int in = 0;
          for (int s = 0; s < 27; ++s) {
            const Vec3 p(static_cast<double>(x) + (s % 3 - 1) / 3.0, static_cast<double>(y) + (s / 3 % 3 - 1) / 3.0,
                         static_cast<double>(z) + (s / 9 - 1) / 3.0);
            in += std::hypot(p[1] - 24, p[2] - 24) <= R || courseDistance(p) <= r;
          }
          volume(x, y, z) = static_cast<float>(20.0 + 180.0 * in / 27.0);
        }
  }
  static Geometry makeGeometry() {
    Geometry g;
    g.dims = {64, 56, 48};
    return g;
  }
};

struct Figures {
  double trunkWorst = 0, daughterWorst = 0, daughterShare = 0;
  double radiusWorst = 0;  // the daughter path's points beyond the trunk's wall: |radius - r| (voxels)
  size_t beyondWall = 0;
};

// The paths above through case c, refined (wide trunk placement on or off), measured.
Figures refineWallAndCorner(const TrunkCase& c, bool wideTrunk) {
  CentrelineTree t;
  t.points.emplace_back(2, 24, 24);  // the root, on the axis
  t.parent.push_back(-1);
  std::vector<int32_t> trunk{0}, daughter{0, 1};
  for (int x = 3; x <= 61; ++x) {
    t.parent.push_back(static_cast<int32_t>(t.points.size()) - 1);
    trunk.push_back(static_cast<int32_t>(t.points.size()));
    t.points.emplace_back(x, 14, 24);
  }
  const Vec3 ostium = c.J + (c.R / c.d[1]) * c.d, start(3, 14, 24);
  int32_t prev = 1;
  auto add = [&](const Vec3& a, const Vec3& b) {
    const int steps = static_cast<int>(std::ceil((b - a).norm()));
    for (int i = 1; i <= steps; ++i) {
      const Vec3 p = a + (static_cast<double>(i) / steps) * (b - a);
      t.points.emplace_back(std::round(p[0]), std::round(p[1]), std::round(p[2]));
      t.parent.push_back(prev);
      prev = static_cast<int32_t>(t.points.size()) - 1;
      daughter.push_back(prev);
    }
  };
  add(start, ostium);
  if (c.bend == 0) {
    add(ostium, c.J + (c.daughterLength - 1) * c.d);
  } else {  // along the daughter's bent course, 3 voxels a step, up to a voxel before its end
    Vec3 from = ostium;
    for (double u = c.R / c.d[1] + 3; u < c.daughterLength - 1; u += 3) add(from, c.at(u)), from = c.at(u);
    add(from, c.at(c.daughterLength - 1));
  }
  auto measure = [&](const RefinedCentreline& out) {
    Figures f;
    const std::vector<int32_t> tc = refinedChain(out, trunk), dc = refinedChain(out, daughter);
    for (size_t i = 5; i < tc.size(); ++i) {
      const Vec3& p = out.points[static_cast<size_t>(tc[i])];
      f.trunkWorst = std::max(f.trunkWorst, std::hypot(p[1] - 24, p[2] - 24));
    }
    size_t within = 0, n = 0;
    for (size_t i = 5; i < dc.size(); ++i) {
      const Vec3& p = out.points[static_cast<size_t>(dc[i])];
      const double dist = std::min(segmentDistance(p, Vec3(0, 24, 24), c.J), c.courseDistance(p));
      f.daughterWorst = std::max(f.daughterWorst, dist);
      if (std::getenv("VS_WIDE_DEBUG")) std::printf("d %zu %.1f %.1f %.1f %.2f\n", i, p[0], p[1], p[2], dist);
      within += dist <= 1.0, ++n;
      if (std::hypot(p[1] - 24, p[2] - 24) > c.R + 0.5) {
        f.radiusWorst = std::max(f.radiusWorst, std::abs(out.radiiMm[static_cast<size_t>(dc[i])] - c.r));
        ++f.beyondWall;
      }
    }
    f.daughterShare = static_cast<double>(within) / static_cast<double>(n);
    return f;
  };
  CentrelineOptions o;
  o.wideTrunk = wideTrunk;
  return measure(refineCentreline(c.volume, t, o));
}

// The discrete paths of a flat wide lumen: the trunk's path runs along its wall (10 voxels off the
// axis), the daughter's leaves it at once and cuts the corner straight to the daughter's ostium,
// then follows the daughter. Refined with defaults, every trunk point lies within a voxel of the
// trunk's axis and the daughter path's points within a voxel of its true course (the trunk's axis to
// J, then the daughter's axis), save its first points (the root's jump to the wall tilts their
// planes); without the wide trunk placement (its option off) they do not.
TEST(WideTrunk, PathsAlongTheWallAndAcrossTheCornerAreOnTheTrunksAxisAndTheDaughters) {
  const TrunkCase c;
  const Figures on = refineWallAndCorner(c, true), without = refineWallAndCorner(c, false);
  std::printf(
      "trunk R 12, daughter at 70 degrees: trunk worst %.2f voxel off its axis, daughter path worst %.2f, %.0f %% "
      "within 1 voxel, radius beyond the trunk's wall worst %.2f off the daughter's (without the placement: %.2f, "
      "%.2f, %.0f %%)\n",
      on.trunkWorst, on.daughterWorst, 100 * on.daughterShare, on.radiusWorst, without.trunkWorst,
      without.daughterWorst, 100 * without.daughterShare);
  EXPECT_LE(on.trunkWorst, 1.0);
  EXPECT_GE(on.daughterShare, 0.95);
  EXPECT_LE(on.daughterWorst, 1.5);
  EXPECT_LT(without.daughterShare, 0.8);
}

// The same paths with a daughter that bends beyond the trunk's wall (4 or 6 voxels over its 16 beyond
// the wall, the family's range): the chord through its first points is tilted by the bend, and J -> G
// along it ran beside the daughter's straight course through the trunk (session 21: the family's
// dominant loss; before, worst 1.19 / 97 % within 1 voxel at 4, 1.69 / 92 % at 6). J -> G now runs on
// to the daughter's first point beyond the wall: 0.89, 100 %.
TEST(WideTrunk, ADaughterThatBendsBeyondTheWallRunsStraightThroughTheTrunk) {
  for (const double bend : {4.0, -6.0}) {
    const TrunkCase c(70, 2.5, bend);
    const Figures on = refineWallAndCorner(c, true);
    std::printf("daughter bending %.0f voxels beyond the wall: daughter path worst %.2f, %.0f %% within 1 voxel\n",
                bend, on.daughterWorst, 100 * on.daughterShare);
    EXPECT_GE(on.daughterShare, 0.98) << bend;
    EXPECT_LE(on.daughterWorst, 1.0) << bend;
  }
}

// The same paths with the daughter at 40-45 degrees from the trunk's axis: the planes normal to the
// daughter just beyond the trunk's wall cut into the trunk through the ostium. The daughter's placed
// points there are measured in their own lumen (session 18). Before, they took the trunk's circle's
// radius (9.3 voxels off at 40 degrees, r 2) or, where the rays towards the ostium left too few
// chords to centre them, none (the 0.5-voxel floor: 1.5 off at 45 degrees, r 2; 2.5 at 40, r 3).
TEST(WideTrunk, ADaughtersPointsBesideItsOstiumHaveTheDaughtersRadius) {
  for (const auto& [degrees, r] : {std::pair{40.0, 2.0}, std::pair{45.0, 2.0}, std::pair{40.0, 3.0}}) {
    const TrunkCase c(degrees, r);
    const Figures on = refineWallAndCorner(c, true);
    std::printf("daughter r %.1f at %.0f degrees: %zu points beyond the trunk's wall, radius worst %.2f voxel off\n", r,
                degrees, on.beyondWall, on.radiusWorst);
    EXPECT_GE(on.beyondWall, 8u) << degrees << " " << r;
    EXPECT_LE(on.radiusWorst, 0.5) << degrees << " " << r;
  }
}

// The section normal to the daughter just beyond the trunk's wall cuts into the trunk through the
// ostium: its largest circle is the trunk's, which does not hold the point's own lumen; a point in the
// trunk, on its axis or near its wall, is held by the trunk's circle.
TEST(WideTrunk, TheSectionBesideAnOstiumDoesNotHoldTheDaughtersPoint) {
  const TrunkCase c(50);
  const TrilinearSampler s(c.volume);
  SectionScratch sc;
  for (const double beyond : {0.25, 0.5, 1.0}) {
    const Vec3 p = c.J + (c.R / c.d[1] + beyond) * c.d;
    const SectionResult r = sectionCentre(s, Vec3(1, 1, 1), p, c.d, s.at(p), 20, 30, sc);
    ASSERT_TRUE(r.ok) << beyond;
    EXPECT_GT(r.radiusMm, 2 * c.r) << beyond;  // the trunk's circle
    EXPECT_FALSE(sectionHoldsPoint(r)) << beyond << ": own " << r.ownMm << " top " << r.topMm << " circle "
                                       << r.inscribedMm;
  }
  for (const Vec3& p : {Vec3(14, 24, 24), Vec3(14, 14, 24), Vec3(50, 30, 33)}) {
    const SectionResult r = sectionCentre(s, Vec3(1, 1, 1), p, Vec3(1, 0, 0), s.at(p), 20, 30, sc);
    ASSERT_TRUE(r.ok);
    EXPECT_NEAR(r.radiusMm, c.R, 0.5) << p.transpose();
    EXPECT_TRUE(sectionHoldsPoint(r)) << p.transpose() << ": own " << r.ownMm << " top " << r.topMm << " circle "
                                      << r.inscribedMm;
  }
}

// onTrunkAxis: the trunk's axis is (also beside the volume's face, where the ball is cut on one
// side); a line beside it, tilted off it, or across the trunk is not (session 18: a line fitted
// through few centred points near a daughter ran across the trunk, and J on it lay 5-9 voxels off
// the axis on 7 of the wide tuning seeds' daughters).
TEST(WideTrunk, OnlyTheTrunksAxisIsOnItsAxis) {
  const TrunkCase c;
  const TrilinearSampler s(c.volume);
  centreline_detail::BallScratch sc;
  const Vec3 one(1, 1, 1), x(1, 0, 0);
  for (const Vec3& J : {Vec3(34, 24, 24), Vec3(20, 24, 24), Vec3(2, 24, 24)})
    EXPECT_TRUE(centreline_detail::onTrunkAxis(s, one, J, x, c.R, 110, sc)) << J.transpose();
  EXPECT_FALSE(centreline_detail::onTrunkAxis(s, one, Vec3(20, 28, 24), x, c.R, 110, sc));                // beside
  EXPECT_FALSE(centreline_detail::onTrunkAxis(s, one, Vec3(20, 24, 24), Vec3(1, 0.5, 0), c.R, 110, sc));  // tilted
  EXPECT_FALSE(centreline_detail::onTrunkAxis(s, one, Vec3(20, 24, 24), Vec3(0, 1, 0), c.R, 110, sc));    // across
  EXPECT_FALSE(centreline_detail::onTrunkAxis(s, one, Vec3(20, 27, 27), Vec3(0, 1, -1), c.R, 110, sc));
}

// ballCentre: from anywhere in a tube's cross-section onto its axis, not along it.
TEST(WideTrunk, BallCentreFindsTheAxisWithoutADirection) {
  const TrunkCase c;
  const TrilinearSampler s(c.volume);
  centreline_detail::BallScratch sc;
  for (const Vec3& from : {Vec3(12, 14, 24), Vec3(15, 30, 33), Vec3(48, 24, 13.5)}) {
    Vec3 p = from;
    ASSERT_TRUE(centreline_detail::ballCentre(s, Vec3(1, 1, 1), p, c.R, 110, sc));
    EXPECT_LE(std::hypot(p[1] - 24, p[2] - 24), 0.5) << from.transpose() << " -> " << p.transpose();
    EXPECT_NEAR(p[0], from[0], 1.0);
  }
}

// Every target of a wide family case traced together: the share of the refined points within a voxel
// of their own branches (root to leaf) and their mean distance (voxels); at least minPoints points.
std::pair<double, double> ownBranchFigures(uint64_t seed, size_t minPoints) {
  const VesselFamilyCase c = makeVesselFamilyCase(seed, VesselFamilyVariant::WideLumen);
  const VesselTruth& t = c.truth;
  TraceRequest rq;
  rq.root = t.rootVoxel;
  rq.targets = t.terminalVoxels;
  const TraceResult r = runTrace(c.volume, rq);
  EXPECT_EQ(r.paths.size(), t.terminalVoxels.size());
  const double vox = t.spacing.minCoeff();
  size_t n = 0, within = 0;
  double sum = 0;
  for (size_t i = 0; i < r.paths.size(); ++i) {
    EXPECT_TRUE(r.paths[i].reached) << i;
    std::vector<bool> keep(t.branches.size(), false);  // the path's own branches, root to leaf
    for (int b = t.terminalBranches[i]; b >= 0; b = t.branches[static_cast<size_t>(b)].parent)
      keep[static_cast<size_t>(b)] = true;
    VesselTruth own = t;
    own.branches.clear();
    for (size_t b = 0; b < t.branches.size(); ++b)
      if (keep[b]) own.branches.push_back(t.branches[b]);
    for (const Vec3& p : r.points[i]) {
      const double d = distanceToCenterline(own, p).distanceMm / vox;
      sum += d, within += d <= 1.0, ++n;
    }
  }
  EXPECT_GE(n, minPoints);
  const double share = static_cast<double>(within) / static_cast<double>(std::max<size_t>(n, 1));
  const double mean = sum / static_cast<double>(std::max<size_t>(n, 1));
  std::printf("family %llu: %zu refined points, %.1f %% within 1 voxel, mean %.3f voxel\n",
              static_cast<unsigned long long>(seed), n, 100 * share, mean);
  return {share, mean};
}

// Issue 21's bounds on ownBranchFigures: >= 98 % within a voxel, mean <= 0.3 voxel.
void expectOwnBranchBounds(uint64_t seed, size_t minPoints = 101) {
  const auto [share, mean] = ownBranchFigures(seed, minPoints);
  EXPECT_GE(share, 0.98);
  EXPECT_LE(mean, 0.3);
}

// A trunk about as long as it is wide, on coarse slices: the family's seed 10506 (dark, trunk radius 16.8
// voxels and 40 long, 0.6 x 0.6 x 1.76 mm, two daughters of radius 2.7-3.5; session 21's blind seed, the
// worst of its wide set). Its trunk's rays centred most of its points, so they were no axis points (2-4
// near a daughter); the ball moves J +- a radius along the short trunk, so its axis was not confirmed;
// the chord through a daughter's points took one its rays had centred 6 voxels towards the trunk, J
// moved 10 voxels along the axis, and a daughter point inside the trunk was centred 7 voxels off by its
// section. Before: 78.9 % of the refined points within a voxel of their own branches, mean 0.864, 2 on
// a neighbour; now every bound of issue 21 holds.
TEST(WideTrunk, AShortWideTrunksDaughtersLeaveItAlongTheirOwnAxes) { expectOwnBranchBounds(10506); }

// Family seed 525 (a faded trunk of radius 8.6 voxels on 2.28 mm slices, two daughters, a target at the
// trunk's far end). Its far end's points, centred on the axis by their rays, lie above the lumen level
// by cost, so confineToLumen pulled them back to their path voxels along the wall (4-6.6 voxels off;
// now they are confined within half a voxel), and the points before its second daughter, centred in
// sections tilted by the path along the wall, lay 1-2 voxels beside the axis (now on their ball's
// centre, which lies deeper). Before: 87.8 % within a voxel, mean 0.577; now every bound of issue 21.
TEST(WideTrunk, AFadedTrunksFarEndStaysOnItsAxis) { expectOwnBranchBounds(525); }

// Family seed 10706 (session 23's blind wide seed: trunk radius 8.2 voxels but 5.8 mm on 0.7 mm voxels,
// under the 7.5 mm from which a lumen counted as wide; three daughters of radius 1.6-3.2 voxels
// leaving it a radius or so apart). Its rays centred the daughters' first points on the trunk's axis,
// so each path ran up the axis a trunk radius past its junction and cut back through the lumen to its
// daughter (up to 8.4 voxels off). Before: 86.5 % within a voxel, mean 0.566, 5 points on a
// neighbour; now the trunk counts as wide (placeWide's wideTrunkVoxels) and every bound of issue 21.
TEST(WideTrunk, ATrunkWideInVoxelsOnlyLetsItsDaughtersLeaveAtTheirJunctions) { expectOwnBranchBounds(10706); }

// Family seed 537 (trunk radius 19.4 voxels on 1.84 mm slices, four daughters of radius 2-3 voxels). Its
// first daughter's chord rests on linePoints points only (the path ends 7 points past the wall), tilted
// by the coarse slices: J -> G ran along it and G lay 1.5 voxels beside the daughter, its first points
// off by as much. Now J -> G runs on to the first point beyond the wall as on a longer chord. Before:
// 97.9 % within a voxel (4 points off); now every bound of issue 21.
TEST(WideTrunk, AShortDaughtersJunctionLineRunsToItsFirstPointBeyondTheWall) { expectOwnBranchBounds(537); }

// Family seed 10406 (trunk radius 16.3 voxels along z on 1.65 mm slices, three daughters). The path to
// its third daughter ran on up the trunk's axis past the junction (its last point before J 1.8 voxels
// short of it, a slice being 2.6 voxels) and came back; the points up there stayed on the trunk's axis
// (up to 4.2 voxels off their own branches, 2 on a neighbour). Now the chain is the daughter's from
// where it passes J along the axis. Before: 95.4 % within a voxel, mean 0.263; now 100 %.
TEST(WideTrunk, AChainThatRunsOnPastItsJunctionIsTheDaughtersFromThere) { expectOwnBranchBounds(10406); }

// Family seeds 10705 (trunk radius 24.9 voxels along z on 1.29 mm slices) and 10504 (19.9 voxels): the
// chain's point nearest J lay on the trunk's axis just past J, the last before it turned into the
// daughter, and stayed there (1.09 / 1.14 voxels off their own branches, on the trunk beyond the
// junction). Now the chain is the daughter's from that point too (beforeAxisPass). Before: 98.9 / 99.2 %
// within a voxel; now every point within a voxel.
TEST(WideTrunk, AChainsPointNearestItsJunctionButPastItIsTheDaughters) {
  for (const uint64_t seed : {10705u, 10504u}) EXPECT_EQ(ownBranchFigures(seed, 90).first, 1.0) << seed;
}

// Family seed 10804 (session 24's blind wide seed, tuning-grade since: trunk radius 18.5 voxels, a daughter
// of radius 1.75 that turns round the trunk where it leaves its wall) and 552 (trunk along z on 2.17 mm
// slices, a daughter leaving almost in-plane). The chord through the daughter's points tilted sideways and
// its nearest approach put J 3.4 voxels (10804) up the trunk's axis; J now comes from the daughter's axial
// course against its distance from the axis, its end left out. Before: 10804 88.9 % within a voxel (mean
// 0.360, 1 point on a neighbour), 552 86.0 % (0.391); now every bound of issue 21.
TEST(WideTrunk, ADaughterTurningRoundItsTrunkMeetsTheAxisWhereItsAxialCourseDoes) {
  expectOwnBranchBounds(10804);
  expectOwnBranchBounds(552);
}

// Family seed 10906 (session 25's blind wide seed, tuning-grade since: trunk radius 12.7 voxels, a daughter of
// radius 2.5 leaving it 9.7 voxels from the root at ~70 degrees to its axis). The daughter's first point
// beyond the wall, whose section still takes in the trunk's lumen through the ostium, lay 0.8 voxel low
// along the axis, and with the longest lever of the (distance, position) fit it put J 1.55 voxels off; the
// points within a daughter radius of the wall now stay out of that fit. Before: 95.1 % within a voxel (9
// points on J -> G 1.2-1.65 voxels off), mean 0.221; now every bound of issue 21.
TEST(WideTrunk, ADaughtersPointsAtTheOstiumStayOutOfItsAxialCourse) { expectOwnBranchBounds(10906); }

// Family seed 11006 (session 26's blind wide seed, tuning-grade since: trunk radius 13 voxels, a daughter of
// radius 1.56 voxels that bends where it leaves the wall and a dimmer one of radius 3.3). The thin daughter's
// G, carried back from its straight distal course, lay on its wall, which reads under the trunk's level:
// its placement was refused and its first points were left 1.8-4.2 voxels off; the wider daughter's first
// points, centred on its axis, read as not-lumen by the cost and confineToLumen pulled them back towards the
// ostium (1.1-1.4 voxels). Now J -> G's check ends a daughter radius short of G, and a placed daughter's
// points beyond the wall that lie deep in their own section's lumen stay. Before: 95.8 % within a voxel, mean
// 0.142; now every bound of issue 21.
TEST(WideTrunk, ADaughterPastTheWallIsJudgedByItsOwnLumen) { expectOwnBranchBounds(11006, 90); }

// Family seed 11204 (session 28's blind wide seed, tuning-grade since: dark, trunk radius 16.7 voxels on 2.10 mm
// slices, a daughter of radius 3.3 voxels leaving at 64 degrees whose path ends 23 mm from the axis). Its J
// came from 4 chord points 18.7-21.8 mm from the trunk's axis, their slope carried 20 mm back to it: axial
// errors of 0.07-0.10 mm put J 1.65 voxels down the axis, and the points on J -> G 1.06-1.36 voxels off. J is now
// fitted again on the daughter's points as the final centring leaves them (replaceJunctions). Before: 96.4 %
// within a voxel (4 points off), mean 0.154; now every bound of issue 21.
TEST(WideTrunk, AJunctionIsPlacedAgainFromItsDaughtersFinallyCentredPoints) { expectOwnBranchBounds(11204, 100); }

// Given seed 12404 (session 40's blind wide seed, tuning-grade since: dark, trunk radius 22.1 voxels on 2.08 mm
// slices, a daughter of radius 1.6 mm whose path ends 32.7 mm from the axis) and scan seed 3204 (dark, trunk radius
// 21.3 voxels, a thin dim daughter of radius 1.1 mm). 12404's J came from a chord of 4 points 26-31 mm from the
// trunk's axis, levered 26 mm back to it: 1.6 voxels down the axis, the points on J -> G 1.06-1.27 voxels off. 3204's
// J was right but refused: its J -> G line read the daughter's own lumen, dimmer than the trunk's level, 0.8 mm
// beyond the trunk's radius, and its 16 points were left on the trunk's axis. Now the daughter's own lumen walked
// back to its opening in the trunk's wall joins the axial course's fit, and J -> G outside the trunk is read at the
// daughter's own level. Before: 97.2 % within a voxel (mean 0.122) and 89.0 % (mean 1.396); now every bound.
TEST(WideTrunk, ADaughtersJunctionIsReadFromItsOpeningInTheTrunksWall) {
  expectOwnBranchBounds(12404, 100);
  expectOwnBranchBounds(3204, 100);
}

// Family seed 5605 (session 41's scan seed, tuning-grade: dark, trunk radius 12.9 voxels on 1.22 mm slices, four
// daughters). The final centring read one daughter's first free point's section across the tangent of the J -> G
// stretch placeWide froze just before it: the section took in the trunk (radius 8.8 mm) and moved the point 10 mm
// into it, and replaceJunctions laid J -> G again through it (11 points 1.3-7.5 voxels off their branch). The final
// centring now takes no section move beyond the rounds' step bound (1.5 mm there). Before: 92.7 % within a voxel,
// mean 0.457; now every point within a voxel.
TEST(WideTrunk, AFinalSectionMoveBeyondTheRoundsStepBoundIsNotTaken) { expectOwnBranchBounds(5605, 140); }

// A tree of centreline points for placeWideTrunk: each point added is the child of the one before, on one
// level (110, between the tests' background 20 and lumen 200); place() runs the placement on it.
struct TrunkTree {
  std::vector<Vec3> q;
  std::vector<int32_t> parent;
  std::vector<uint8_t> wide, placed;
  std::vector<double> radius, level;
  void add(const Vec3& p, bool isWide, double r) {
    parent.push_back(static_cast<int32_t>(q.size()) - 1);
    q.push_back(p), wide.push_back(isWide), radius.push_back(r), level.push_back(110);
  }
  size_t place(const TrilinearSampler& s) {
    std::vector<std::vector<int32_t>> children(q.size());
    for (size_t k = 1; k < q.size(); ++k) children[static_cast<size_t>(parent[k])].push_back(static_cast<int32_t>(k));
    std::vector<uint8_t> frozen(q.size(), 0);
    placed.assign(q.size(), 0);
    std::vector<double> kept;
    auto copy = [&](size_t k) {
      q.push_back(q[k]), parent.push_back(parent[k]), children.emplace_back(), frozen.push_back(0);
      wide.push_back(wide[k]), radius.push_back(radius[k]), level.push_back(level[k]), placed.push_back(0);
      return q.size() - 1;
    };
    return centreline_detail::placeWideTrunk({s, Vec3(1, 1, 1), wide, radius, level, 1}, parent, children, q, frozen,
                                             placed, copy, kept);
  }
};

// A chain that leaves a bright trunk (radius 8 voxels along x) for points in the background beside it
// (a dim vessel the level does not show, 20 voxels off the axis, along the trunk): the daughter's axis
// carried back from its first point misses the trunk, and the ball there centres the background. Such
// a junction is not the trunk's: no point is placed on the background side of the level (the aorta MRA
// from 69,350,15: a J 19 mm off the aorta's axis put 11 points across the background, 100-180 against a
// background of 240 and a lumen of 870-1400).
TEST(WideTrunk, AJunctionOutsideTheTrunksLumenPlacesNothing) {
  Geometry g;
  g.dims = {64, 48, 72};
  VolumeF32 v(g, 20.0f);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x)
        if (std::hypot(static_cast<double>(y) - 24, static_cast<double>(z) - 24) <= 8) v(x, y, z) = 200.0f;
  const TrilinearSampler s(v);
  TrunkTree t;
  for (int x = 2; x <= 30; ++x) t.add(Vec3(x, 24, 24), x > 2, 8);   // the root, then the trunk on its axis
  for (int x = 31; x <= 50; ++x) t.add(Vec3(x, 24, 44), false, 2);  // the chain beside it
  t.place(s);
  for (size_t k = 0; k < t.q.size(); ++k)
    if (t.placed[k] == 1) {
      EXPECT_GT(s.at(t.q[k]), 110.0) << k << ": " << t.q[k].transpose();
    }
}

// A path from the root through a thin U-turn into a wide trunk and out into a daughter, no branch point on
// the way: placeWideTrunk balls every unmoved point of the daughter's chain from the root with the trunk's
// radius. At the U's legs the ball takes in both legs, and its centroid lies between them, on the background
// side of the level, where lumenClearance measures the background's depth (the distance to the legs' walls),
// as deep as or deeper than the point's own in its leg. Such a centre is not taken: every point the
// placement moves lies on the lumen's side of the level (head CTA 40,113,41 auto 6, path 0 point 118: a
// centre at 97 against a level of 114 taken on a clearance tie, 0.27 = 0.27 mm; before: here the two legs'
// ends at the U's bottom moved between the legs, 2.7 voxels off their axes, value 20 against the level 110).
TEST(WideTrunk, AChainsBallCentreOutsideTheLumenIsNotTaken) {
  Geometry g;
  g.dims = {96, 48, 48};
  VolumeF32 v(g, 20.0f);
  const Vec3 J(62, 24, 24), d(std::cos(70 * M_PI / 180), std::sin(70 * M_PI / 180), 0), bottom(10, 24, 28.5);
  auto lumen = [&](const Vec3& p) {
    const double axial = std::hypot(p[1] - 24, p[2] - 24);
    if (p[0] >= 30 && p[0] <= 90 && axial <= 8) return true;                         // the trunk
    if (segmentDistance(p, J, J + 22.0 * d) <= 2) return true;                       // the daughter
    if (segmentDistance(p, Vec3(10, 24, 24), Vec3(30, 24, 24)) <= 1.5) return true;  // the U's leg into the trunk
    if (segmentDistance(p, Vec3(10, 24, 33), Vec3(24, 24, 33)) <= 1.5) return true;  // the root's leg
    const double round = std::hypot(std::hypot(p[0] - bottom[0], p[2] - bottom[2]) - 4.5, p[1] - 24);
    return p[0] <= 10 && round <= 1.5;  // the U's bottom
  };
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x)
        if (lumen(Vec3(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)))) v(x, y, z) = 200.0f;
  const TrilinearSampler s(v);
  TrunkTree t;
  for (int x = 24; x >= 10; --x) t.add(Vec3(x, 24, 33), false, 1.5);  // the root, then its leg
  for (int a = 1; a < 9; ++a)                                         // the U's bottom
    t.add(bottom + 4.5 * Vec3(-std::sin(a * M_PI / 9), 0, std::cos(a * M_PI / 9)), false, 1.5);
  for (int x = 10; x <= 30; ++x) t.add(Vec3(x, 24, 24), false, 1.5);  // the leg into the trunk
  for (int x = 31; x <= 62; ++x) t.add(Vec3(x, 24, 24), true, 8);     // the trunk on its axis
  for (int k = 1; k <= 22; ++k) t.add(J + k * d, false, 2);           // the daughter
  const std::vector<Vec3> before = t.q;
  const size_t moved = t.place(s);
  size_t outside = 0;
  for (size_t k = 0; k < before.size(); ++k)
    if (t.placed[k] == 1 && !(s.at(t.q[k]) > 110.0)) {
      ++outside;
      ADD_FAILURE() << k << ": " << before[k].transpose() << " -> " << t.q[k].transpose() << " value " << s.at(t.q[k]);
    }
  std::printf("U before a wide trunk: %zu points moved, %zu of them outside the lumen\n", moved, outside);
  EXPECT_GT(moved, 0u);  // the daughter is placed (the chain's pass runs)
}

// Family seeds 10206 (dark, trunk 13.3 mm on 2.69 mm slices, a daughter of radius 1.58 mm leaving at 84
// degrees) and 11206 (bright, trunk 20.7 mm on 2.54 mm slices, a daughter of radius 1.97 mm): J, carried back
// 16-26 mm along the trunk's axis from the daughter's centred points, lay 1.5 / 1.8 mm up the axis - those
// points sit on plateaus along the slice axis. The chord's points now go onto the daughter's axis as fitted
// to the image's voxels (daughter_tube.h) before J is fitted. Before: 10206 96.2 % within a voxel (mean
// 0.178), 11206 95.1 % (0.231); now every bound of issue 21.
TEST(WideTrunk, ADaughtersAxisIsReadFromTheImageBeforeItsJunctionIsCarriedBack) {
  expectOwnBranchBounds(10206);
  expectOwnBranchBounds(11206);
}

// A thin tube (radius 1.6 mm) nearly in-plane on 2.5 mm slices, rising 0.15 mm per mm across them, with the
// family's partial volume (a linear ramp over the voxel's extent along the normal) and no noise; the chord's
// points are its axis with their z snapped to the nearest slice (the plateaus of centred points, up to 1.25 mm
// off). The fitted axis is the tube's: within 0.05 mm of it over the chord, its direction within half a degree.
TEST(WideTrunk, ADaughterTubeFittedToTheVoxelsIsNotOnTheSlicePlateaus) {
  Geometry g;
  g.dims = {72, 40, 16};
  g.spacing = Vec3(0.8, 0.8, 2.5);
  VolumeF32 v(g, 0.0f);
  const Vec3 a(4, 16, 12), e = Vec3(1, 0, 0.15).normalized();
  const double r = 1.6;
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const Vec3 p = Vec3(double(x), double(y), double(z)).cwiseProduct(g.spacing), w = p - a;
        const Vec3 off = w - w.dot(e) * e;
        const double d = off.norm(), extent = (off / std::max(d, 1e-12)).cwiseAbs().dot(g.spacing);
        v(x, y, z) = static_cast<float>(100 + 120 * std::clamp(0.5 - (d - r) / extent, 0.0, 1.0));
      }
  std::vector<Vec3> chord;
  double plateau = 0;
  for (double t = 20; t <= 40; t += 2) {
    Vec3 p = a + t * e;
    const double snapped = std::round(p[2] / 2.5) * 2.5;
    plateau = std::max(plateau, std::abs(snapped - p[2]));
    p[2] = snapped;
    chord.push_back(p);
  }
  EXPECT_GT(plateau, 1.0);
  // The trunk far away: every voxel beyond its wall.
  Vec3 c, dir;
  ASSERT_TRUE(centreline_detail::fitDaughterTube(TrilinearSampler(v), g.spacing, chord, Vec3(-100, -100, 0),
                                                 Vec3(0, 0, 1), 1.0, 1.5, 1, c, dir));
  EXPECT_LT(std::acos(std::min(1.0, dir.dot(e))) * 180 / M_PI, 0.5);
  for (double t = 20; t <= 40; t += 5) {
    const Vec3 p = a + t * e, w = p - c;
    EXPECT_LT((w - w.dot(dir) * dir).norm(), 0.05) << t;
  }
}

// Session 44 (heldmiss): a wide run is kept only when it holds 5 points, and the root is never cast, so never wide.
// A daughter whose path parts from the others at the root itself (given 6205, 8806, 12706: the paths inside one wide
// trunk share no voxel past the root) had its 2-3 points in the trunk cleared as a flicker; placeWideTrunk then never
// saw it. Runs on two of the root's children are one run through the root; a short run elsewhere is still cleared.
TEST(KeepWideRuns, RunsMeetingAtTheRootAreOneRun) {
  // 0 root; chain A 1-6 (all wide), chain B 7-12 (7, 8 wide: the daughter's first points in the trunk; 11, 12 wide:
  // a flicker down the daughter); 13-14 a side chain off node 3, not wide.
  std::vector<int32_t> parent{-1, 0, 1, 2, 3, 4, 5, 0, 7, 8, 9, 10, 11, 3, 13};
  std::vector<std::vector<int32_t>> children(parent.size());
  for (size_t i = 1; i < parent.size(); ++i)
    children[static_cast<size_t>(parent[i])].push_back(static_cast<int32_t>(i));
  std::vector<uint8_t> wide{0, 1, 1, 1, 1, 1, 1, 2, 2, 0, 0, 1, 1, 0, 0};
  centreline_detail::keepWideRuns(parent, children, wide);
  const std::vector<uint8_t> expected{0, 1, 1, 1, 1, 1, 1, 2, 2, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(wide, expected);
  // The root's children alone, no trunk of 5 through the root: still a flicker.
  std::vector<uint8_t> few{0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0};
  centreline_detail::keepWideRuns(parent, children, few);
  EXPECT_EQ(few, std::vector<uint8_t>(parent.size(), 0));
}

// Session 45 (held14404): tuning-grade seed 14404 (wide, 0.67 x 0.67 x 1.64 mm, trunk radius 12.1 mm) - the discrete
// routes to the daughter b5 and to the trunk's end part at x 28, 18 voxels before b5's junction (x 46), inside the
// trunk. placeJunctions took that parting for a side branch's ostium and laid b5's 21 zone points on the line from it
// to b5's first round section, across the trunk to its wall; placeWideTrunk re-placed most of them, but two stayed at
// the wall 1.8-2.9 voxels off (97.8 % within a voxel; the old route of path 3 along the axis hid it: a three-way
// parting, which placeJunctions leaves). In a lumen wider than the wide trunk's bound the zone is placeWideTrunk's.
TEST(WideTrunk, ADaughtersZoneInsideTheTrunkIsNotLaidFromWhereTheRoutesPart) {
  const FamilyTrace f = traceEveryTerminal(14404, VesselFamilyVariant::WideLumen);
  const PointFigures p = ownPathFigures(f.c.truth, f.r);
  std::printf("[wide 14404] %zu points: mean %.3f vox, within 1 vox %.1f%%\n", p.n, p.meanVox, 100 * p.within1);
  EXPECT_GE(p.within1, 0.99);
  EXPECT_LE(p.meanVox, 0.1);
}

// A daughter's points placed on J -> G or on its line just beyond the trunk's wall (family seeds 16305 / 16606: dark,
// trunks of 21.8 / 20.5 voxels on 2.1-2.2 mm slices): their sections normal to the daughter open into the trunk through
// the ostium, and their rays read 12.8 / 11.0 mm where the daughter is 1.2 / 1.6 mm (radius error 0.607 / 0.586 with
// every point within a voxel). The radius points (true radius >= 1 voxel, the nearest own centreline point
// outside every other tube) are measured within 2 voxels each (a trunk's reading is 10 or more) and 0.5 on average.
TEST(WideTrunk, ADaughtersPointsBeyondTheWallDoNotTakeTheTrunksRadiusThroughTheOstium) {
  for (const uint64_t seed : {16305u, 16606u}) {
    const FamilyTrace f = traceEveryTerminal(seed, VesselFamilyVariant::WideLumen);
    const VesselTruth& t = f.c.truth;
    const double vox = t.spacing.minCoeff();
    const auto only = [&](const std::vector<bool>& keep) {
      VesselTruth out = t;
      out.branches.clear();
      for (size_t b = 0; b < t.branches.size(); ++b)
        if (keep[b]) out.branches.push_back(t.branches[b]);
      return out;
    };
    std::vector<VesselTruth> single;
    for (size_t b = 0; b < t.branches.size(); ++b) {
      std::vector<bool> keep(t.branches.size(), false);
      keep[b] = true;
      single.push_back(only(keep));
    }
    size_t n = 0;
    double sum = 0, worst = 0;
    for (size_t i = 0; i < f.r.points.size(); ++i) {
      std::vector<bool> own(t.branches.size(), false);
      std::vector<size_t> ids;
      for (int b = t.terminalBranches[i]; b >= 0; b = t.branches[static_cast<size_t>(b)].parent)
        own[static_cast<size_t>(b)] = true;
      for (size_t b = 0; b < own.size(); ++b)
        if (own[b]) ids.push_back(b);
      const VesselTruth ownT = only(own);
      for (size_t k = 0; k < f.r.points[i].size(); ++k) {
        const CenterlineDistance d = distanceToCenterline(ownT, f.r.points[i][k]);
        const size_t b = ids[static_cast<size_t>(d.branch)];
        if (d.radiusMm < vox) continue;
        bool fused = false;
        for (size_t o = 0; o < single.size() && !fused; ++o) {
          const CenterlineDistance other = distanceToCenterline(single[o], d.closest);
          fused = o != b && other.distanceMm < other.radiusMm;
        }
        if (fused) continue;
        const double e = std::abs(f.r.radiiMm[i][k] - d.radiusMm) / vox;
        sum += e, worst = std::max(worst, e), ++n;
      }
    }
    std::printf("family %llu: %zu radius points, mean error %.3f voxel, worst %.2f\n",
                static_cast<unsigned long long>(seed), n, sum / double(std::max<size_t>(n, 1)), worst);
    EXPECT_GE(n, 30u) << seed;
    EXPECT_LE(worst, 2.0) << seed;
    EXPECT_LE(sum / double(std::max<size_t>(n, 1)), 0.5) << seed;
  }
}

// A daughter whose target lies 4 refined points past the trunk's wall (family seed 16004: trunk radius 24 voxels, the
// daughter 3.1): its line was too short for placeWideTrunk (5 points), so its points inside the trunk were left to the
// sections, which slid them along the trunk's axis 17 voxels past J and back (mean 0.774 voxel, 93.3 % within a voxel,
// 8 points on the trunk's continuation). Placed from its two points past the skipped ones: mean 0.154, 97.0 % (its
// J -> G line, fitted on two points, runs just over a voxel off at G: not yet the 98 %).
TEST(WideTrunk, ADaughterEndingJustPastTheWallIsPlacedFromItsFewPoints) {
  const auto [share, mean] = ownBranchFigures(16004, 101);
  EXPECT_LE(mean, 0.3);
  EXPECT_GE(share, 0.95);
}

}  // namespace
}  // namespace vs
