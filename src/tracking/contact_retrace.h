// Tubes that touch where they cross at an angle (issue 21, session 25): a path that runs in one
// tube and turns into another where the two touch, cutting the corner the tree's own route goes
// round (10301: the paths to branch 1's terminals ran down its sister branch 2 and turned about 90
// degrees into branch 1 where its loop comes back against branch 2; the lumens overlap there, so
// the cost has no wall). Told from a fork or a bend by the image, not by the path: at a crossing
// both tubes go on at both sides of the contact - each tube's own sections (its radius, centred,
// followed as it bends) continue beyond the other tube's wall; at a fork the branch entered ends
// at the trunk's far wall, at a bend the tube left ends at the other's. There a slab between the
// two tubes' axes (found from those sections) is blocked and the stretch searched again; the new
// route is kept only when it takes a route of its own and costs at most neckCostSlack more
// (session 26, cross2).
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "tracking/crossing_retrace.h"

namespace vs {

struct ContactRetrace : RetraceOutcome {
  int turns = 0;  // turns found where both tubes go on past each other
};

// The re-search round turns at a contact. lumenLevel: the node cost at or below which a voxel is
// lumen.
ContactRetrace retraceAcrossContact(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                    double lumenLevel, const CrossingOptions& o);

// The turn into a tube that loops back from the contact to the path's own route before it (issue 21,
// session 34: 11732 / 11622, the root fork's child 1 loops back against its sibling 2 and every path
// to its subtree runs up 2 and cuts through the contact, both routes at the cost floor). At a turn back
// (more than 90 degrees; session 38, diag232: not at a lesser bend, whose stretches' lines meet outside
// it) the tube entered is followed back from the contact section by section; where it comes back into the path's
// lumen well before the turn (the fork), the path's stretch from there to the turn is blocked across
// its lumen, the walked tube left open, and the stretch searched again from the fork. Kept by its
// cost per mm (not its total: the loop is longer than the shortcut) and only as a tube of its own
// (lumen all along, through the walked tube).
// The looped-contact re-search's path points that kept no route, remembered by the path voxels their test reads
// (session 39 cache702). What retraceLoopedContact asks at point i - the sharp turn there, its walks, the searches
// round their blocks - reads path[0 .. i + h + k] only (the turn's stretch and the path before it), besides the cost,
// the lumen level and the options, which are one tracker's own; a tracker's paths run from one root and share their
// trunks, so every path to a later target asked the shared trunk's turns again with the same answer (the carotid's
// five targets: four paths through the same 45-58 points, ~0.08 s of walks). Kept per prefix of path voxels (a trie,
// so a prefix is matched voxel by voxel, never by a hash), only where no route was kept (a kept route changes the
// path and returns).
class LoopedTurnMemo {
 public:
  // Each prefix path[0 .. j]'s node, j = 0 .. path.size() - 1.
  std::vector<int32_t> prefixes(const Geometry& g, const std::vector<Index3>& path) {
    std::vector<int32_t> nodes;
    int32_t at = -1;
    for (const Index3& v : path) {
      const auto [it, added] =
          child_.try_emplace({at, g.linear(v[0], v[1], v[2])}, static_cast<int32_t>(refused_.size()));
      if (added) refused_.push_back(0);
      nodes.push_back(at = it->second);
    }
    return nodes;
  }
  bool refused(int32_t node) const { return refused_[static_cast<size_t>(node)] != 0; }
  void refuse(int32_t node) { refused_[static_cast<size_t>(node)] = 1; }
  int64_t reused = 0;  // path points skipped: their refusal remembered

 private:
  struct Key {
    int32_t parent;
    int64_t voxel;
    bool operator==(const Key& o) const { return parent == o.parent && voxel == o.voxel; }
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      return std::hash<int64_t>()(k.voxel) * 1000003u ^ std::hash<int32_t>()(k.parent);
    }
  };
  std::unordered_map<Key, int32_t, KeyHash> child_;
  std::vector<uint8_t> refused_;
};

// memo (optional): the refusals of earlier calls on the same cost, lumen level and options (a tracker's).
ContactRetrace retraceLoopedContact(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                    double lumenLevel, const CrossingOptions& o, LoopedTurnMemo* memo = nullptr);

}  // namespace vs
