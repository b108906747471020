// Paths of one trace that part and meet again inside one lumen are given one trunk (issue 21).
#pragma once

#include <cstdint>
#include <unordered_set>
#include <vector>

#include "cost/cost3d.h"

namespace vs {

// Where b's route leaves a's and meets it again further along both (possible only after re-searches:
// each neck / crossing re-search searches its own path again from its start, so two paths through one
// wide sinus take routes a voxel or two apart that part and meet again), the two stretches between
// cost the same (a tie the two searches broke differently; a dearer or cheaper one differs in the
// image, e.g. a neck one re-search kept out of) and lie in one lumen - every voxel of each sees the
// other stretch's nearest voxel through lumen (node cost <= lumenLevel, holes up to holeMm bridged) -
// both paths take one of them: the one through a re-search's replacement (a voxel in `researched`)
// when only one is, else a's (the earlier path's). Two vessels of a loop, with background between
// them, keep their own. Two stretches of different cost in one lumen (the same test) are one route
// too where the dearer costs less per mm: both paths take the dearer (corner37, 11930: where a trunk
// curls into a child that turns back at once, the fused hairpin's lumen is at the cost's floor, the
// cheaper stretch is the shorter one cutting the curl's inside from the trunk into the child's start,
// the other path's goes round the curl, nearer the axis, a little cheaper per mm). Where the cheaper
// is also the cheaper per mm (a neck or a dark contact one re-search kept out of) each keeps its own.
// Returns 1 when a changed, 2 when b did, 3 both, 0 neither.
int joinSharedLumen(std::vector<Index3>& a, std::vector<Index3>& b, const NodeCost3D& cost, double lumenLevel,
                    double holeMm, const std::unordered_set<int64_t>& researched = {});

// Where b leaves a at its shared start and never meets it again, yet runs on beside a inside one lumen (a
// split inside one wide vessel: each geodesic hugs the inside of its own exit's turn, so the single search's tree
// parts at the top of the tube, not where the lumen does - head CTA 63,84,103's paths 1 / 4, blindcta): every
// voxel of b after the parting that sees a's nearest voxel through lumen (seesThroughLumen's test) with no waist
// between them (the lumen's chord across the two, at the middle, no narrower than at either path: two touching
// tubes narrow at their contact, one convex lumen does not) is in a's lumen; where that run is longer than the
// lumen's widest chord across the two paths (a fork's funnel is about as long as it is wide), b takes a's voxels up to
// a's voxel nearest the run's last, the straight lumen line to it and its own route on. A voxel of b whose nearest
// on a is still the parting voxel moves straight away from it (a fork's arm; the first steps of two paths parting to
// opposite walls) and neither ends nor extends the run; nor does one whose nearest on a is its predecessor's nearest
// and which lies farther from it (part63c: b moving straight away from one voxel of a - a fork's arm leaving a's
// bend; nothing of a runs beside it), and such a voxel does not count for "apart" either; nor does one that is not
// beside a (beside3): b's voxel nearest to a's nearest lies farther from it than a's nearest lies from b - the segment
// between them runs along b, not across both (b moves more away from a than along it: a wide-angle fork's arm, whose
// straight line back to a runs down the arm's own lumen into the fork's funnel). Bounded by what is wide
// (part63b): the run also ends where a's nearest is a's last voxel (b has passed a's end) or where the straight line
// between the two crosses non-lumen (no hole bridged), and b is joined only where the two lie, somewhere in the run,
// more than twice the parent's width apart (the lumen's widest chord through a's parting voxel normal to a: two
// daughters no wider than their parent, touching, hold no two points farther apart) - a lumen wider than any fork of
// that parent. True when b changed.
bool joinPartedLumen(const std::vector<Index3>& a, std::vector<Index3>& b, const NodeCost3D& cost, double lumenLevel,
                     double holeMm);

}  // namespace vs
