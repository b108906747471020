// VesselTracker's internal state, shared by tracker.cpp and auto_terminals.cpp (not a public
// header: front ends use tracker.h).
#pragma once

#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "tracking/contact_retrace.h"
#include "tracking/neck_sections.h"
#include "tracking/tracker.h"

namespace vs {

// A stretch of a target's path that a re-search replaced (crossing, neck or dip: the path stepped into a
// touching tube): the search's route from the root up to the first voxel after the stretch, and the
// route that replaced it (ending on that voxel). Every path whose route runs through the same stretch
// takes the same replacement, so two paths through one lumen share one trunk (issue 21: a re-search's
// acceptance depends on the whole path's cost, so a longer path took a route that a shorter one
// through the same stretch did not, and the two ran 1-4 mm apart through the head CTA's sinus).
struct Reroute {
  std::vector<Index3> found, kept;
  int sidewaysSteps = 0, neckCrossings = 0;
  // The path's own tube read by the width of its lobe (retraceByWidth): the stretch left is another tube's, and a path
  // whose route runs there keeps it (14707: the wide tube's path along the thin one's from the fork; the thin tube's
  // path, traced first, would be given the wide tube's route).
  bool ownTube = false;
};

struct VesselTracker::Impl {
  const VolumeF32& vol;
  const NodeCost3D& cost;
  TrackerOptions opt;
  std::optional<GridGraph> grid;
  GridCost gridCost;
  std::unique_ptr<PrunedGraph> pruned;
  std::unique_ptr<ShortestPathSearch> search;
  int64_t rootNode = 0;
  TrackerStats stats;
  double lumenLevel = -1;  // lumenCostThreshold(cost), when first needed (crossing re-trace)
  // Tree of extracted paths over voxels.
  std::unordered_map<int64_t, int32_t> treeIndex;  // linear voxel -> tree point
  std::vector<Index3> treeVoxel;
  std::vector<int32_t> treeParent, treeChildren, treeOwner;
  std::vector<Reroute> reroutes;  // in the order the re-searches were accepted
  LoopedTurnMemo loopedTurns;     // the looped-contact re-search's refused points, by path prefix (cache702)
  NeckSectionMemo neckSections;   // the neck re-search's sections read on any path (lazyA4)

  Impl(const VolumeF32& v, const NodeCost3D& c, const TrackerOptions& o) : vol(v), cost(c), opt(o) {}

  int64_t nodeOfVoxel(int64_t lin) const {
    if (grid) return lin;
    return pruned->voxelNode[static_cast<size_t>(lin)];
  }
  int64_t voxelOfNode(int64_t node) const {
    if (grid) return node;
    return pruned->nodeVoxel[static_cast<size_t>(node)];
  }
  int64_t snap(const Index3& v) const {
    if (grid) return grid->node(v[0], v[1], v[2]);
    return pruned->nearestNode(v);
  }
};

}  // namespace vs
