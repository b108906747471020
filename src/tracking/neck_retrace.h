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

}  // namespace vs
