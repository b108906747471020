// Kissing drifts (issue 21, sessions 20-21): the re-search across the neck between two touching
// tubes, where the path crosses gradually and its cost shows no sideways step (the options and the
// description: CrossingOptions' neck fields in crossing_retrace.h).
#pragma once

#include <string>
#include <vector>

#include "tracking/box_search.h"
#include "tracking/crossing_retrace.h"

namespace vs {

struct NeckRetrace : RetraceOutcome {
  int crossings = 0;  // own-lobe changes found
};

// The route from part's first voxel to its last in box b with `blocked` refused by the cost slack, held to the lumen by
// intensity instead (neck_retrace.cpp; the neck re-search's with neckByIntensity): empty, with `why`, where none.
std::vector<Index3> lumenRoute(const NodeCost3D& cost, const CrossingOptions& o, const retrace::Box& b,
                               std::vector<uint8_t> blocked, int connectivity, const std::vector<Index3>& part,
                               double* c, std::string* why);

// The kissing-drift re-search (o.smoothed must be set).
NeckRetrace retraceAcrossNeck(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                              const CrossingOptions& o);

// The neck re-search's sections along a path (its runs of 2k two-lobe sections or more, longRunsOnly): per point
// whether the section shows the path's own lobe and another beside it, and the two lobes' radii (mm). Empty without
// o.smoothed.
struct LobeWidths {
  bool two = false;
  double rOwn = 0, rOther = 0;
  Vec3 own{0, 0, 0}, other{0, 0, 0}, t{0, 0, 1};  // the lobes' centroids (mm) and the section's normal
};
std::vector<LobeWidths> lobeWidthsAlong(const std::vector<Index3>& path, const CrossingOptions& o);

// How many times a route changes tube, the tube read by the width of the lobe the route runs in where two touching
// tubes of unlike width show in its sections (tube_identity.cpp).
int tubeWidthChanges(const std::vector<Index3>& path, const CrossingOptions& o);

// The search's own route read for its tube by width (tubeWidthChanges): where it changes tube, the stretches it runs in
// the width it does not end in are searched again with that width's lobe blocked, from the path's start; the new route
// is kept where it changes tube fewer times and costs within the neck re-search's slack (tube_identity.cpp).
// startBlocked (optional): set where the route's first point lies in a lobe to block (the route starts in the other
// tube: no search from there).
RetraceOutcome retraceByWidth(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                              const CrossingOptions& o, bool* startBlocked = nullptr);

}  // namespace vs
