// A child fused with its sibling over its first arm and U walked back through that stretch on a run of two-disc
// sections (tracking/contact_walk.h walksFusedRun; issue 21, session 38 walk124).
#include <gtest/gtest.h>

#include "family_trace.h"

namespace vs {
namespace {

// The seed's refined points (against the paths' own tubes where ownPath) within the given bounds.
void expectTraced(uint64_t seed, double within1, double meanVox, bool ownPath = false) {
  const PointFigures p = tracedFigures("fused walk", seed, VesselFamilyVariant::Thin, ownPath);
  ASSERT_GT(p.n, 0u);
  EXPECT_GE(p.within1, within1);
  EXPECT_LE(p.meanVox, meanVox);
}

// Session 38 (walk124): tuning-grade seed 12124 (thin forced, 0.66 x 0.66 x 1.24 mm): the root fork's child b1 runs
// fused beside its sibling b2 over its whole first arm (axes 0.9-2.9 mm apart against radii 3.8-4.1 mm together) and
// is entered at its own tight U; paths 2 / 3 ran in b2 and cut through the U's bottom into b1's return arm, which no
// walk on own sections could follow back (main: 95.5 % within 1 voxel, 11 far points). The fused walk follows b1 from
// its return arm round the U and along the fused arm on a run of split sections to the fork; the bend's strip lies on
// the tube left's side of the two discs' midline.
TEST(FusedWalk, ChildFusedBesideItsSiblingWalkedBackToItsFork) { expectTraced(12124, 0.98, 0.3); }

// Session 38 (walk124b): tuning-grade seed 10929 (thin forced, 0.95 x 0.95 x 2.16 mm): the walk round b5's tight U
// ran on through b5's fork into its parent b2 - the tube left, where the path ran - and split b2's oblique sections on
// the thick slices into a run of "two discs", both in b2 (the tube left's walked axis within the own radius of every
// own disc, 0.7-1.4 mm against 1.66). Closing there moved the route in the same tube (98.3 -> 97.9 %, lost); the
// fused walk does not close where the tube left's axis runs through every own disc of the run.
TEST(FusedWalk, WalkInsideTheTubeLeftDoesNotClose) { expectTraced(10929, 0.98, 0.3); }

// Session 38 (axis729): tuning-grade seed 11729 (thin forced, 0.89 x 0.89 x 2.12 mm): 10929's kind with a thin child
// (own radius 1.06 mm) - the walk ran on into b5, the tube left, and its 7 own discs all lie in b5, but the tube left's
// axis passes 1.15-1.59 mm from them, just outside the child's radius, so the own-radius bound let the run close
// (99.7 -> 98.2 %, mean 0.092 -> 0.111). The bound is the tube left's own radius where wider (the median section
// along the path's stretch: 1.72 mm here): every own disc inside the tube left, the run refused.
TEST(FusedWalk, ThinChildsWalkInsideTheTubeLeftDoesNotClose) { expectTraced(11729, 0.99, 0.1); }

// Session 39 (route124): the same seed's paths 2 / 3 now run in b1 (their voxels 1.1-1.6 mm off its axis over its
// fused first arm), but the fused overlap's two-disc placement (placeOverlaps) walked b1's chain back from its return
// arm across the U's tight bottom, where its previous point lies nearer the disc on the U's inside - b2's curl - and
// continuity kept it on b2 up to the fork: both children's chains on b2's disc, b1's first arm passed by (route covered
// 92.4 %; against the paths' own tubes points 22-35 of paths 2 / 3 are off). A walk back on its sibling's disc at
// every point it placed over more than the contact's reach goes to the other discs where its discrete path's voxels
// lie nearer them: b1's chain on b1 (main 89.0 %, mean 0.479; here 98.4 %, and 100 % once ubottom placed the U
// bottom's points 34 / 35).
TEST(FusedWalk, ChildsChainAcrossItsTightUStaysOnItsOwnDisc) { expectTraced(12124, 0.98, 0.2, true); }

}  // namespace
}  // namespace vs
