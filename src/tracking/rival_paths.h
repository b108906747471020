// Kissing vessels across thick slices (issue 21, session 22 kiss15): two traced branches that touch
// are one region above the half-way level wherever their contact is thinner than the slice, and no
// valley shows between them where their axes lie in neighbouring slices (seed 541, 2.05 mm slices:
// ownLobe finds one lobe). The rays of a point on either branch then run through the contact into
// the other tube and both branches' points are centred on the pair's middle (kiss4's "pulled"
// class). The search, though, found each branch's path in its own tube: between two path voxels of
// branches that are not near one fork, the half-way plane is the best wall the data give.
//
// `rivalAnchors` returns per point the nearest path voxel (mm) of another branch within reachMm
// (NaN where none): another branch is one whose walk up the tree (towards the root) and this
// point's, each max(forkMm, 3 x their distance) long, do not meet (siblings near their fork
// are one lumen parting, placeForks' matter; a re-searched path that runs beside its trunk's). O(points x neighbours
// within reachMm).
#pragma once

#include <cstdint>
#include <vector>

#include "volume/sample.h"

namespace vs {

std::vector<Vec3> rivalAnchors(const std::vector<Vec3>& anchorMm, const std::vector<int32_t>& parent, double reachMm,
                               double forkMm, double minMm);

// The distance along the unit direction `d` from `c` to the half-way plane between `own` and
// `rival` (all mm), where the ray meets it on the rival's side; -1 where it does not (or where c
// already lies on the rival's side, or the rival is NaN).
double rivalPlaneDistance(const Vec3& c, const Vec3& d, const Vec3& own, const Vec3& rival);

}  // namespace vs
