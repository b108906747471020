// Session 34 (cross34): a child entered mid-way through a contact with its sibling (issue 21). The root fork's
// child 1 loops back and touches / crosses its sibling 2 past the fork; every path to child 1's subtree ran up 2 and
// cut through the contact into 1 (both routes at the cost floor, the shortcut the shorter), so child 1's first part
// was never traced. The looped-contact re-search (contact_retrace.h) follows the tube entered back from the contact
// to the fork and searches the stretch again from there with the sibling's stretch blocked.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <initializer_list>
#include <vector>

#include "cost/cost3d.h"
#include "family_trace.h"
#include "tracking/contact_retrace.h"
#include "tracking/tracker.h"

namespace vs {
namespace {

// The share of branch b's truth points that some path's refined polyline passes within its radius (at least a
// voxel) of.
double branchCovered(const VesselTruth& t, const TraceResult& r, size_t b) {
  const double vox = t.spacing.minCoeff();
  const VesselBranch& br = t.branches[b];
  size_t covered = 0;
  for (size_t j = 0; j < br.points.size(); ++j) {
    const Vec3 x = br.points[j].cwiseProduct(t.spacing);
    const double reach = std::max(br.radiiMm[j], vox);
    bool near = false;
    for (size_t i = 0; i < r.points.size() && !near; ++i)
      for (size_t k = 0; k < r.points[i].size() && !near; ++k) {
        const Vec3 a = r.points[i][k].cwiseProduct(t.spacing);
        const Vec3 ab = (k + 1 < r.points[i].size() ? r.points[i][k + 1].cwiseProduct(t.spacing) : a) - a;
        const double s = ab.squaredNorm() > 0 ? std::clamp((x - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
        near = (a + s * ab - x).norm() <= reach;
      }
    covered += near;
  }
  return br.points.empty() ? 1 : double(covered) / double(br.points.size());
}

// The share of the refined points of the given paths within one voxel of their own tubes (the terminal's branch and
// those up to the root).
double ownPathWithin1(const VesselTruth& t, const TraceResult& r, std::initializer_list<size_t> paths) {
  const double vox = t.spacing.minCoeff();
  size_t n = 0, within = 0;
  for (size_t i : paths) {
    if (i >= r.points.size() || i >= t.terminalBranches.size()) continue;
    VesselTruth own = t;
    own.branches.clear();
    for (int b = t.terminalBranches[i]; b >= 0; b = t.branches[size_t(b)].parent)
      own.branches.push_back(t.branches[size_t(b)]);
    for (const Vec3& q : r.points[i]) within += distanceToCenterline(own, q).distanceMm <= vox, ++n;
  }
  return n ? double(within) / double(n) : 1;
}

// The case of `seed` (thin) traced, its figures - against every true centreline, or (ownPath) each path's own tubes -
// and branch b's coverage, printed as "[looped contact seed] ...".
struct LoopFigures {
  PointFigures p;
  double branch = 0;
};
LoopFigures loopFigures(uint64_t seed, size_t b, bool ownPath) {
  const FamilyTrace f = traceEveryTerminal(seed, VesselFamilyVariant::Thin);
  LoopFigures l;
  l.p = ownPath ? ownPathFigures(f.c.truth, f.r) : pointFigures(f.c.truth, f.r);
  l.branch = branchCovered(f.c.truth, f.r, b);
  std::printf("[looped contact %llu] %zu points: mean %.3f vox, within 1 vox%s %.1f%%, branch %zu covered %.1f%%\n",
              static_cast<unsigned long long>(seed), l.p.n, l.p.meanVox, ownPath ? " (own path)" : "",
              100 * l.p.within1, b, 100 * l.branch);
  return l;
}

// The looped child traced round: every point within 1 voxel (of its own path's tubes where ownPath) at least
// `within1`, and branch b at least 95 % covered by the paths.
void expectTracedRound(uint64_t seed, size_t b, bool ownPath, double within1) {
  const auto [p, covered] = loopFigures(seed, b, ownPath);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, within1);
  EXPECT_GE(covered, 0.95);
}

// Tuning-grade seed 11622 (thin forced, 0.89 x 0.89 x 2.03 mm): branch 1 loops back over the fork and crosses
// branch 2 at 77 degrees; on main the paths to branch 1's subtree went fork -> 2 -> through the crossing (branch 1's
// first 28 voxels never traced, 97.8 % within 1 voxel).
TEST(LoopedContact, ChildEnteredThroughItsSiblingsContactTracedFromTheFork) {
  const auto [p, covered] = loopFigures(11622, 1, false);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
  EXPECT_LE(p.meanVox, 0.35);
  EXPECT_GE(covered, 0.95);  // main: the first 28 voxels of branch 1 on no path
}

// Session 36 (walk36): tuning-grade seed 11930 (thin forced, 0.83 x 0.83 x 2.04 mm): branch 1 leaves the trunk's curled
// end at 89 degrees and at once turns back, lying antiparallel beside the trunk (walls 0.2-0.4 voxel apart); the paths
// to its subtree (2 / 3) hopped from the trunk into it through the contact 14 voxels before the fork, so the trunk's
// last ~30 truth samples and branch 1's first ~20 were on no path (main: branch 1 covered 90.9 %, route 89.3 %). The
// looped-contact re-search walks the entered child on its own side to its fork and searches the turn again with the
// contact strip blocked.
TEST(LoopedContact, ChildReturningBesideItsParentTracedFromTheFork) {
  const FamilyTrace f = traceEveryTerminal(11930, VesselFamilyVariant::Thin);
  const PointFigures p = pointFigures(f.c.truth, f.r);
  ASSERT_GT(p.n, 0u);
  const double trunk = branchCovered(f.c.truth, f.r, 0), child = branchCovered(f.c.truth, f.r, 1);
  std::printf(
      "[looped contact 11930] %zu points: mean %.3f vox, within 1 vox %.1f%%, trunk covered %.1f%%, branch 1 "
      "covered %.1f%%\n",
      p.n, p.meanVox, 100 * p.within1, 100 * trunk, 100 * child);
  EXPECT_GE(trunk, 0.95);
  EXPECT_GE(child, 0.95);
}

// Session 37 (uturn37): tuning-grade seed 10923 (thin forced, 0.80 x 0.80 x 1.88 mm): the trunk curls into a fork whose
// child 2 makes a U as tight as its own radius (two slices up, down to y 8.9) and returns over child 1's start; the
// paths to child 2's subtree (4-7) ran from child 1's start through that contact into child 2's return, its U on no
// path (main: 96.0 % within 1 voxel - 20 of the 28 far points there -, branch 2 covered 90.5 %). The looped-contact
// re-search walks child 2 back round its bend to the fork and searches the turn again with the boundary between child
// 2 and child 1 blocked near the cut.
TEST(LoopedContact, ChildsTightTurnRightPastItsForkTracedRound) { expectTracedRound(10923, 2, false, 0.98); }

// Session 37 (bend37): tuning-grade seed 12003 (given thin, 0.63 x 0.63 x 1.13 mm): child 3 leaves a narrow fork beside
// its sibling 4, makes a U as tight as twice its radius and returns over 4 about 8 mm from the fork; paths 5 / 6 ran
// fork -> 4's start -> through that crossing into 3's return, 3's U on no path (main: 98.4 % within 1 voxel of the
// path's own tubes, 8 points on sibling 4, branch 3 covered 51.7 %). The tube left's walk on from before the fork took
// child 3's first arm, so the walk round 3's bend met "the tube left" in its own U; where that walk on leaves the
// path's stretch before the turn, the walk round the bend is tried again with the path's own stretch as the tube left's
// axis past the fork.
TEST(LoopedContact, ChildsTightTurnOverItsSiblingTracedRound) { expectTracedRound(12003, 3, true, 0.99); }

// Session 38 (route326): tuning-grade seed 11326 (thin forced, 0.63 x 0.63 x 1.86 mm): child 1 leaves the trunk's end
// in +x, loops round and returns back over the trunk one slice above it, ~7 mm short of their fork; the paths to its
// subtree (0-3) stepped from the trunk's wall into child 1's return there, the trunk's last stretch and child 1's loop
// on no path of theirs and their two points at the step 1.1-3.2 voxels off (main: 98.1 % within 1 voxel, 12 far
// points of the 12 allowed, route worst path 84.3 %). The looped-contact re-search walks child 1 back round its loop
// to where it meets the trunk's onward axis ahead of the turn, and searches the turn again with the boundary between
// the two blocked near the cut.
TEST(LoopedContact, ChildCrossingBackOverItsParentShortOfTheForkTracedRound) {
  expectTracedRound(11326, 1, true, 0.99);
}

// Session 38 (diag232): tuning-grade seed 12232 (thin forced, 0.69 x 0.69 x 1.48 mm): branch 1 forks into 5 and 6;
// 5 turns -x in a tight U and its return arm lies against 6 (walls touching) where 6 bends by ~60 degrees, ~7 voxels
// past the fork. The paths to 6's subtree (4 / 5) were routed right by the search; at 6's bend the two stretches'
// lines meet outside the bend (2.7 mm off the path, in 5's U), the looped-contact walk back from there went round 5's
// U to the fork, and the re-search routed them fork -> 5's U -> across the contact into 6 (main: 97.9 % within 1
// voxel, 13 far points, 9 of them on paths 4 / 5). The walk back is asked at a turn back (over 90 degrees) only.
TEST(LoopedContact, BendBesideASiblingsUNotTakenForALoop) {
  const FamilyTrace f = traceEveryTerminal(12232, VesselFamilyVariant::Thin);
  const PointFigures p = pointFigures(f.c.truth, f.r), own = ownPathFigures(f.c.truth, f.r);
  ASSERT_GT(p.n, 0u);
  ASSERT_GE(f.r.points.size(), 6u);
  const double pathsToSix = ownPathWithin1(f.c.truth, f.r, {4, 5});
  std::printf(
      "[looped contact 12232] %zu points: mean %.3f vox, within 1 vox %.1f%% (own path %.1f%%), paths 4 / 5 within 1 "
      "vox of their own tubes %.1f%%\n",
      p.n, p.meanVox, 100 * p.within1, 100 * own.within1, 100 * pathsToSix);
  EXPECT_GE(p.within1, 0.99);   // main: 97.9 %
  EXPECT_GE(pathsToSix, 0.99);  // main: 80.7 % (paths 4 / 5 through 5's U, points 35 / 44-47 off)
}

// Session 39 (turn232): the same seed's paths to 5's subtree (0 / 1) ran fork -> 6's start -> across the contact into
// 5's return, 5's U on no path (main: route worst path 0 88.0 %, branch 5 covered 52.5 %, 98.0 % within 1 voxel of
// the paths' own tubes). The walk round 5's bend closed at the contact itself
// (b6's walked axis ended there, 5's walk drifted into 6 across it); it now holds its own direction through the
// contact, walks 5's U to the fork, and the tube left is walked again with its bend step, never into 5.
TEST(LoopedContact, ChildsUTouchingItsSiblingsBendTracedRound) { expectTracedRound(12232, 5, true, 0.99); }

// Session 39 (cache702): the looped-contact re-search's answer at a path point reads the path up to that point's turn
// stretch only, so a tracker remembers the points that kept no route by their path prefix and asks them once for
// every path through a shared trunk. Tuning-grade 12232's paths (all from one root): each asked with and without a
// memo shared along them gives the same outcome, and the memo skips points of the shared trunks; the tracker's own
// trace skips them too (main: every path asked its trunk's points again).
TEST(LoopedContact, AskedOnceForEveryPathThroughATrunk) {
  const FamilyTrace f = traceEveryTerminal(12232, VesselFamilyVariant::Thin);
  EXPECT_GT(f.r.stats.loopedTurnsReused, 0);
  Cost3DOptions co;
  co.kind = CostKind3D::Intensity;
  const NodeCost3D cost = computeNodeCost3D(f.c.volume, co);
  const double level = lumenCostThreshold(cost);
  const CrossingOptions o;
  LoopedTurnMemo memo;
  int changed = 0;
  for (const TracedPath& p : f.r.paths) {
    const ContactRetrace a = retraceLoopedContact(cost, p.voxels, 26, level, o);
    const ContactRetrace b = retraceLoopedContact(cost, p.voxels, 26, level, o, &memo);
    ASSERT_EQ(a.changed, b.changed);
    EXPECT_EQ(a.voxels, b.voxels);
    EXPECT_EQ(a.newCost, b.newCost);
    changed += a.changed;
  }
  std::printf("[looped contact memo 12232] %zu paths (%d re-routed), %lld points skipped; tracker: %lld skipped\n",
              f.r.paths.size(), changed, static_cast<long long>(memo.reused),
              static_cast<long long>(f.r.stats.loopedTurnsReused));
  EXPECT_GT(memo.reused, 0);
}

}  // namespace
}  // namespace vs
