// Kissing drifts (issue 21, sessions 20-21): the re-search across the neck between two touching
// tubes, where the path crosses gradually and its cost shows no sideways step (the options and the
// description: CrossingOptions' neck fields in crossing_retrace.h).
#pragma once

#include <string>
#include <vector>

#include "tracking/crossing_retrace.h"

namespace vs {

struct NeckRetrace : RetraceOutcome {
  int crossings = 0;  // own-lobe changes found
};

// The kissing-drift re-search (o.smoothed must be set).
NeckRetrace retraceAcrossNeck(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                              const CrossingOptions& o);

// How many times a route changes tube along two touching tubes: the lobes followed from one run of
// two-lobe sections to the next (runs of 2k sections or more, the fused stretches between them carried
// over, as the neck re-search's own-tube tier reads one change across a fused contact), each change
// between lobes alike in radius (kNeckLikeRatio, within k sections). 0 without o.smoothed.
int tubeChanges(const std::vector<Index3>& path, const CrossingOptions& o);

}  // namespace vs
