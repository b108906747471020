// Parallel tubes a slice apart (issue 21, session 22): a path that runs along one tube and steps
// into its neighbour through the background between them. On coarse slices a faded tube beside a
// brighter one reads as background in the node cost (its local background takes the brighter
// tube's intensities), so the minimal path follows the bright neighbour and crosses where the two
// lie a slice apart: the path's smoothed intensity drops to the background's level for a voxel or
// two between bright stretches (two lumens resolved, the path jumping the gap). Where such a dip
// is found, the stretch from before it to past it is searched again among the voxels brighter than
// half-way from the dip to the dimmer flank: the faded tube stays above that level along its axis,
// the gap does not. The new route is kept only when it takes a route of its own, is not much
// longer, and has no such dip itself. Session 23: where the two tubes also touch between their
// fork and the gap, that route can still follow the bright tube and cross where they touch, so the
// search is first made with the tube left blocked back from the gap while the other tube lies
// across a gap from the path; a gap just before the path's end (a terminal inside the faded tube)
// counts too.
#pragma once

#include <string>
#include <vector>

#include "tracking/crossing_retrace.h"

namespace vs {

struct DipRetrace : RetraceOutcome {
  int dips = 0;  // dips found
};

// The dip re-search (o.smoothed must be set). lumenLevel: the node cost at or below which a voxel
// is lumen.
DipRetrace retraceAcrossDip(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                            double lumenLevel, const CrossingOptions& o);

}  // namespace vs
