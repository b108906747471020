// A path through the background where the tree's route is dearer (issue 21, session 37 crowd37; session 33 diag717's
// fix (iii)): a crowded block reads three thin tubes' partial volume as its local background (11702: p75 69.7 against
// 33-46 in its neighbours), so the first halves of two curled-back branches cost the cost's ceiling and the cheapest
// way to their ends is a hop from the trunk through 4-8 voxels of background. The path support test (path_support.h)
// already flags that hop in the trace's notes ("crosses ... without lumen"). Here the flagged stretch is searched
// again: the background it runs through is blocked (round each of its voxels, the ball that holds no supported voxel:
// up to the nearest lumen the test sees), the path searched again from its start to its target, and the new route is
// kept only where the same test flags no stretch of it - by support, not by cost (the tree's route is the dearer one:
// that is why the search took the hop). A route the test still flags has those stretches blocked too and is searched
// again, up to CrossingOptions::maxRounds searches.
#pragma once

#include <vector>

#include "tracking/crossing_retrace.h"

namespace vs {

struct SupportRetrace : RetraceOutcome {
  int stretches = 0;  // stretches the support test flags on the input path
  int rounds = 0;     // searches run
};

// Off (unchanged) unless o.autoCost, o.background, o.estimate and o.smoothed are set.
SupportRetrace retraceUnsupported(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                  const CrossingOptions& o);

}  // namespace vs
