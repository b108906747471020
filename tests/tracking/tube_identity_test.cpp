// A touching-tubes re-search's new route refused where it changes tube, read by the width of the lobe it runs in,
// more times than the route it replaces (tracker.cpp retraceFrom, tube_identity.cpp; issue 21, session 41 tieA); the
// search's own route in the other width searched again with that width's lobe blocked (retraceByWidth, session 42
// kindA3).
#include <gtest/gtest.h>

#include "family_trace.h"

namespace vs {

// Tuning-grade scan seed 5509 (given kissing, bright, 0.60 x 0.60 x 1.22 mm): an unequal pair touching along the
// slice axis, the contact fused by the slices. The search's own route to path 1's end runs in its own tube; a lateral
// step found on it was re-searched and the route with the step blocked, 2 % dearer (0.1334 -> 0.1359, inside the
// slack), ran in the other tube along the contact - its own lobe the other width for 2k sections and more: 0 -> 1
// change of tube (main: the seed 67.0 % within 1 voxel, 2 of 2 paths reached; here 100 %). That replacement is
// refused: the path keeps its own tube.
TEST(TubeIdentity, RouteIntoTheOtherWidthAcrossAFusedContactRefused) {
  const PointFigures p = tracedFigures("tube identity", 5509, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Tuning-grade scan seed 3109 (given kissing, bright, 0.62 x 0.62 x 1.68 mm): a near-equal pair (radius ratio 1.1)
// whose thick slices make the lobe nearer a slice read 0.3-0.5 mm wider, which one wandering along the pair. The neck
// re-search's right route (0.0640 -> 0.0691) reads one change of width, the wrong route it replaces none; the pair's
// differences over the route's two-lobe sections have their median (0.25 mm) under the section grid's step (0.31 mm):
// the widths are not read and the route is taken (main 97.8 %; tieA's width read without it 73.1 %).
TEST(TubeIdentity, NearEqualPairAcrossThickSlicesNotReadAsTwoWidths) {
  const PointFigures p = tracedFigures("tube identity near-equal", 3109, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.97);
}

// Tuning-grade scan seed 5207 (given kissing, bright, 0.72 x 0.72 x 1.44 mm): an unequal pair touching across the
// slices. The search's own route to path 1's end runs from the fork in the other (wider) tube and crosses into its own
// at the contact's far end - one change of width, and no re-search moves it (the neck re-search's bands find no route
// within the slack: 6.2 x). With the wider lobe blocked over the stretch read in that width the route takes its own
// tube from the fork (0.0715 -> 0.0754, 5 % dearer; no change of width): main 85.4 % within 1 voxel, here 100 %.
TEST(TubeIdentity, SearchsOwnRouteInTheOtherWidthSearchedAgain) {
  const PointFigures p = tracedFigures("tube identity own route", 5207, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Tuning-grade scan seed 7108 (given kissing, dark, 0.71 x 0.71 x 1.72 mm): path 0 runs straight in its own thin tube,
// but from point 38 on its sections take the own lobe at the wide neighbour's peak (the highest sample within a largest
// spacing, 1.72 mm, of the path's voxel) and read the route wide with the thin tube as a small other lobe. The route
// has not moved: off its own lobe's disc there, those sections are not read for width (kindA4) and the route is kept
// (main 97.1 %, kindA3's form without the disc reading 77.8 %, pushed into the neighbour).
TEST(TubeIdentity, RouteOffItsOwnLobesDiscNotReadForWidth) {
  const PointFigures p = tracedFigures("tube identity own disc", 7108, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.96);
}

// Tuning-grade scan seed 7609 (given kissing, dark, 0.98 x 0.98 x 2.27 mm; an equal pair, 1.01): the search's own
// route to path 1's end runs along its neighbour and no re-search moved it (main 65.9 % within 1 voxel, 45 points on
// the neighbour). The neck re-search's sections took the own lobe at the highest sample within a largest spacing (2.27
// mm) of the route's voxel, which on thick slices can be the neighbour's peak (7108); with the own lobe's peak the one
// a climb from the route's voxel reaches (sectionAt, kindA5) the neck re-search changes the route (1.21 x the old
// cost): 100 % (5507 likewise, 65.8 -> 100 %).
TEST(TubeIdentity, OwnLobeClimbedToFromTheRoutesVoxel) {
  const PointFigures p = tracedFigures("tube identity climbed lobe", 7609, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Tuning-grade scan seed 6707 (given kissing, bright, 0.66 x 0.66 x 1.24 mm): path 1 (the thin tube) runs from the fork
// in the wide tube and crosses at ~44; with the climbed lobe (kindA5) its sections read one change of tube and the pair
// test's full band re-searches it first (stretch 14-76 from the fork at 14). The band's slab on the stretch's first
// section sat on the fork and made the route one voxel off the other right route there (fork point 13 1.12 vox off its
// axis, on the neighbour: 97.7 %). With no slab on the stretch's first k points (the fork's crotch, kindA7) 98.3 %.
TEST(TubeIdentity, FullBandLaysNoSlabOnTheForksCrotch) {
  const PointFigures p = tracedFigures("tube identity fork crotch", 6707, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Sweep seed 11808 (given kissing, bright, 0.94 x 0.94 x 1.31 mm): path 1 runs from the fork; the pair test's full band
// (no slab on its stretch's first k points, the fork's crotch: kindA7) re-searches it onto a route one voxel sideways
// at the crotch from the band's route with the slabs there. That route's first two-lobe stretch starts a point later,
// and the width reading took section 21 - at the crotch - into a run of exactly 2k sections of the wider own lobe, read
// as a change of tube against the old route's none: the right route refused, 78.1 % (25 points on the neighbour). With
// the width reading skipping the same first k points of the route's first stretch (kindA8) the run is flicker and the
// route is taken: 100 % (main 100 %).
TEST(TubeIdentity, WidthReadingSkipsTheForksCrotch) {
  const PointFigures p = tracedFigures("tube identity crotch widths", 11808, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Scan seed 7908 (given kissing, dark): the neck re-search's new route for path 0 runs in the wide neighbour (own lobe
// 1.7-2.0 mm beside 0.7) and comes back into its own thin tube where the tubes part, its second two-lobe stretch
// (points 71-81, after a 14-point one-lobe gap) read thin: one change of tube against the old route's none, refused
// (main 99.4 %). kindA8's first form left out the first k points of every stretch not starting at the route's start;
// it cut this stretch to 5 sections (flicker), the change went unread and the route into the neighbour was taken:
// 60.3 %, 40 points on a neighbour. Only the route's first stretch starts at the fork's crotch.
TEST(TubeIdentity, LaterStretchReadWholeForWidth) {
  const PointFigures p = tracedFigures("tube identity later stretch", 7908, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Scan seed 8508 (given kissing, bright, 0.65 x 0.65 x 1.76 mm; session 43's held-out miss, tuning-grade now): main
// 81.8 % within 1 voxel, 29 points on the neighbour; with the climbed lobe, the rim test, the crotch left out by the
// full band and by the width reading (kindA5-kindA8) 99.4 %, 0 on a neighbour.
TEST(TubeIdentity, HeldOutKissingMiss8508) {
  const PointFigures p = tracedFigures("tube identity 8508", 8508, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Scan seed 8209 (given kissing; session 43's held-out scan, tuning-grade now) - kind A's "drift at depart": path 0's
// route runs from the fork in the other tube along the contact and crosses into its own only where the tubes part, and
// its own tube's axis costs ~2 x the route (the dear own tube). Its sections read the other width over a long run and
// its own over a run of k to 2k sections at its end, flicker to the run rule: no change read, 53.7 % within 1 voxel, 70
// points on the neighbour. Read with the end's run (the target lies in the own tube) and the route the cost slack
// refuses held to the lumen by intensity (kindAdear): 100 %, 0 on a neighbour.
TEST(TubeIdentity, DriftAtDepartReadByTheEndsRun) {
  const PointFigures p = tracedFigures("tube identity end run", 8209, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Scan seed 6607 (given kissing, bright, 0.73 x 0.73 x 1.66 mm): the same form on a bright pair, path 1 in the other
// tube from the fork to the parting (main 66.1 %, 54 on the neighbour; here 100 %).
TEST(TubeIdentity, DriftAtDepartReadByTheEndsRunBright) {
  const PointFigures p = tracedFigures("tube identity end run bright", 6607, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Held-out seeds 15708 and 15408 (session 45's, given kissing, dark, 0.93 x 0.93 x 2.43 and 0.81 x 0.81 x 1.97 mm;
// tuning-grade since): the thin tube's route runs from the fork in the wide one (a run of 2k and more sections) and
// crosses into its own where they part (a run of 2k): the change is read, but between the two-lobe sections the pair is
// fused (one lobe over 28 sections on 15708, gap 0.06 voxel) and the last two-lobe section's disc, carried along that
// section's tangent (the wide tube's bow turning back beside the thin one) with the margin its own other lobe allowed,
// covered the thin tube: the blocked route ran through the background and was refused (main 61.6 % / 67.0 % within 1
// voxel, 55 / 63 points on the neighbour). The disc carried with the route, bounded by the other lobe at both ends of
// the gap (held15): 98.8 % / 98.5 %.
TEST(TubeIdentity, CarriedDiscLeavesTheFusedNeighbourFree) {
  const PointFigures p = tracedFigures("tube identity carried disc", 15708, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

TEST(TubeIdentity, CarriedDiscLeavesTheFusedNeighbourFreeDriftAtContact) {
  const PointFigures p =
      tracedFigures("tube identity carried disc at contact", 15408, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
}

// Scan seed 8007 (given kissing, dark, 0.98 x 0.98 x 1.22 mm, gap 0.04 voxel): path 0 (the thin tube) runs in the wide
// neighbour from the fork; its first round's re-search moved the route's end, and the second round's stretch starts 17
// sections into the wide lobe - the width re-search refused ("the path's ends lie in the blocked lobe": no search from
// a start inside the lobe to block): 60.3 % within 1 voxel, 46 points on the neighbour. The whole route read and
// searched from the path's own start there: 95.7 %, mean 0.171 voxel, 0 on a neighbour.
TEST(TubeIdentity, LaterRoundStartingInTheOtherTubeSearchedFromThePathsStart) {
  const PointFigures p = tracedFigures("tube identity later round", 8007, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.95);
  EXPECT_LE(p.meanVox, 0.3);
}

// Scan seed 8809 (given kissing, dark, 1.00 x 1.00 x 2.02 mm, gap 0.04 voxel): a near-equal pair (true radii 0.24 voxel
// apart, the sections' two radii under the grid's step: the widths are not read). Path 1's route runs from the fork in
// its neighbour b1 (its own tube beside it over 24 two-lobe sections) and goes over into its own where the two kiss -
// the sections one lobe for 13 points there - after which its own lobe lies where the other was (main 76.7 % within 1
// voxel, 31 points on the neighbour). Read by place (the lobes crossed sideways between two two-lobe sections) the
// stretch before the crossing is the neighbour's and is searched again with its lobe blocked: 100 %.
TEST(TubeIdentity, NearEqualPairReadByPlace) {
  const PointFigures p = tracedFigures("tube identity by place", 8809, VesselFamilyVariant::Kissing, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
  EXPECT_LE(p.meanVox, 0.3);
}

// Scan seed 4310 (given parallel, dark, 0.91 x 0.91 x 2.48 mm, gap 2.19 voxels): the same on two parallel tubes of
// near-equal radii (0.16 voxel apart), path 1 in its neighbour from the fork and over through the gap a thick slice
// thins (main 80.6 %, 28 points on the neighbour; by place 99.4 %).
TEST(TubeIdentity, NearEqualParallelPairReadByPlace) {
  const PointFigures p = tracedFigures("tube identity by place parallel", 4310, VesselFamilyVariant::Parallel, true);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, 0.98);
  EXPECT_LE(p.meanVox, 0.3);
}

}  // namespace vs
