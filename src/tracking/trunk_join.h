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

}  // namespace vs
