// Automatic terminals that are not branch ends because a later path's route passes through them (auto_terminals.cpp,
// issue 21). In a vessel network (arteries and veins joined through an AVM, a circle of Willis) the medial tree from
// the root reaches a loop from both sides: the longest new branch can end where the two fronts meet, in the middle of
// a vessel, and a later path then runs on through that end. Such a terminal is replaced by the later path (it keeps
// the earlier one's route up to where it went on) or dropped, and the scan looks for another.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <utility>
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

// A route to an automatic terminal that runs round a vessel network (issue 21). The medial tree weights a lumen
// (s / d)^2, so a route through a 3.5 mm deep sinus costs ~1/50 per mm of one through a 0.5 mm deep vessel: in a
// network (a head's veins and arteries joined through an AVM) a voxel near the root is reached round the deep sinuses
// and over the vertex, 1.4-2x the lumen's shortest way to it over the region. A voxel whose tree route is longer than
// kDetourRatio x that way + the minimum length is no terminal candidate (the scan takes ends reached directly). A tree
// follows its lumen's medial ridge round bends (1.0-1.2x the geodesic that cuts them along the inner wall).
constexpr double kDetourRatio = 1.3;

// Per region slot whether its medial-tree route from the root is direct: its length (the chain's to its source, plus
// sourceMm at that source: its arc length along its path from the root, 0 at the root) is at most
// ratio x geodesicMm (the lumen's shortest way from the root) + slackMm.
std::vector<uint8_t> directRoutes(const MedialTreeView& t, const std::vector<float>& sourceMm,
                                  const std::vector<double>& geodesicMm, double ratio, double slackMm);

// sourceMm (per region slot, slot[voxel] >= 0) of p's voxels in the region: their arc length along p from the root.
void addArcLengths(const Geometry& g, const std::vector<int32_t>& slot, const TracedPath& p,
                   std::vector<float>& sourceMm);

// Marks the region's voxels (slot[voxel] >= 0) within `rad` mm of v suppressed (auto_terminals.cpp's suppression
// zone around a path taken).
void suppressBall(const Geometry& g, const std::vector<int32_t>& slot, const Index3& v, double rad,
                  std::vector<uint8_t>& suppressed);

// Whether a voxel the region's fronts left out (spill, per volume voxel; empty: none) lies within rad mm of v.
bool spillNear(const Geometry& g, const std::vector<uint8_t>& spill, const Index3& v, double rad);

// The terminal scan's sources: the root and every voxel of the paths so far; onPath gets the path (and index) of each.
std::vector<int64_t> scanSources(const Geometry& g, int64_t rootLin, const std::vector<TracedPath>& paths,
                                 std::unordered_map<int64_t, std::pair<size_t, size_t>>& onPath);
// Path p's (index pi) voxels not yet sources added to them.
void addPathSources(const Geometry& g, const TracedPath& p, size_t pi,
                    std::unordered_map<int64_t, std::pair<size_t, size_t>>& onPath, std::vector<int64_t>& sources);

// The notes' counts of branch ends not taken and terminals left out, by why.
struct EndsNotTaken {
  enum Why { kRegionCutInWideLumen, kLumenGoesOn, kOnLaterRoute, kAcrossBackground, kFadedPastTube } why;
  int count = 0;
  Index3 first{0, 0, 0};
  double radiusMm = 0;
  void add(const Index3& v, double r) {
    if (count++ == 0) first = v, radiusMm = r;
  }
  std::string describe() const;
};

// Every one's description, in order.
template <class... Ends>
std::string describeAll(const Ends&... e) {
  return (e.describe() + ...);
}

}  // namespace vs
