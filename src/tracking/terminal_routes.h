// Automatic terminals that are not branch ends because a later path's route passes through them (auto_terminals.cpp,
// issue 21). In a vessel network (arteries and veins joined through an AVM, a circle of Willis) the medial tree from
// the root reaches a loop from both sides: the longest new branch can end where the two fronts meet, in the middle of
// a vessel, and a later path then runs on through that end. Such a terminal is replaced by the later path (it keeps
// the earlier one's route up to where it went on) or dropped, and the scan looks for another.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tracking/tracker.h"

namespace vs {

// The terminals of `found` (kept[k] != 0) that a new path `p` runs on through: its own part (beyond p.junctionIndex,
// where it leaves the paths so far) comes within radiusMm[k] of the terminal.
std::vector<size_t> terminalsOnRoute(const Geometry& g, const std::vector<TracedPath>& found,
                                     const std::vector<uint8_t>& kept, const std::vector<double>& radiusMm,
                                     const TracedPath& p);

// The terminal scan's medial tree seen from terminal_routes.cpp: per region slot its predecessor (-1 at a source),
// the mm between two slots, and a slot's neighbours in the region.
struct MedialTreeView {
  const std::vector<int32_t>& pred;
  std::function<double(int32_t, int32_t)> mm;
  std::function<void(int32_t, const std::function<void(int32_t, double)>&)> neighbours;
};

// Whether the lumen goes on beyond a branch's far end by another way (a loop of a vessel network, where the tree's
// fronts from the two ways round meet): a region voxel within reachMm of `far` (over the region) whose medial-tree
// chain, followed for joinMm, neither joins far's own chain nor ends within apartMm of it; returns it (its chain is
// the other way round), -1 if none. At a branch end every voxel near it is reached through the branch itself; where
// two fronts meet, the voxels across the meeting face come the other way round.
int32_t lumenGoesOnBeyond(const MedialTreeView& t, int32_t far, double reachMm, double joinMm, double apartMm);

// The notes' counts of branch ends not taken and terminals left out, by why.
struct EndsNotTaken {
  enum Why { kRegionCutInWideLumen, kLumenGoesOn, kOnLaterRoute } why;
  int count = 0;
  Index3 first{0, 0, 0};
  double radiusMm = 0;
  void add(const Index3& v, double r) {
    if (count++ == 0) first = v, radiusMm = r;
  }
  std::string describe() const;
};

}  // namespace vs
