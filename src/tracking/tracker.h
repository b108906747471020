// Vessel / airway tracking (thesis 4.3.2, 6.2; reading-notes.md): one root, any number of
// targets, ONE shortest-path search from the root that is resumed for each new target (never
// restarted), a tree of the extracted paths (back pointers kept only along extracted paths),
// branch points (nodes with >= 2 extracted children), and automatic terminal detection.
//
// Graph: the full implicit voxel grid (6/18/26-connected, the engine's GridGraph + GridCost) or
// the pruned IsoRegion graph (pruned_graph.h, CSR). Costs: cost/cost3d.h. Coordinates are
// 0-based voxel indices (x,y,z) of the volume given to the tracker; lengths in mm.
// A root or target in a pruned voxel snaps to the nearest graph node (reported in TracedPath).
// Failure: root/target outside the volume -> InvalidArgument naming it; a target the root cannot
// reach -> a TracedPath with reached = false (never a hang: the search just exhausts the queue).
// Not thread-safe; one tracker per root. Memory: engine arrays (~9-13 B per node) + graph.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cost/cost3d.h"
#include "graph/shortest_path.h"
#include "mesh/tri_mesh.h"
#include "tracking/centreline.h"
#include "tracking/crossing_retrace.h"
#include "tracking/pruned_graph.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

enum class PruneMode { None, IsoRegion };

struct TrackerOptions {
  int connectivity = 26;                // 6, 18 or 26
  PruneMode prune = PruneMode::None;    // IsoRegion: thesis 4.1 pruned graph
  IsoRegionOptions isoRegion;           // field (cost by default) and tolerances/threshold of the IsoRegion map
  QueueKind queue = QueueKind::Bucket;  // engine queue (bucket: the fastest monotone queue)
  // A target's path that steps sideways from one tube into a touching one is searched again with
  // the tube it leaves blocked there (crossing_retrace.h; the full grid only).
  CrossingOptions crossing;
};

struct TracedPath {
  Index3 requested{0, 0, 0};   // target as given
  Index3 target{0, 0, 0};      // graph node it snapped to (== requested on the full grid)
  bool reached = false;        // false: no path from the root (separate component)
  std::vector<Index3> voxels;  // root -> target, 26-connected (long pruned edges rasterised)
  double cost = 0;             // path cost (sum of edge costs)
  double lengthMm = 0;         // physical length of the voxel chain
  int parentPath = -1;         // path it branches off (-1: starts at the root alone)
  size_t junctionIndex = 0;    // index into voxels of the last voxel shared with earlier paths
  int sidewaysSteps = 0;       // sideways steps between touching tubes found on the search's path
  bool retraced = false;       // ... and the path searched again with them blocked (crossing_retrace.h)
  int neckCrossings = 0;       // a drift across two touching tubes' contact, searched again with the neck blocked
};

// Automatic terminals (thesis 6.2; auto_terminals.cpp): the lumen region (voxels whose node
// cost is <= maxNodeCost, on the voxel grid) connected to the root and the paths so far, its
// depth (distance to its boundary) and a medial tree from the root and the paths through it
// (node cost (smallest spacing / depth)^2: paths follow the lumen's medial ridge and branches
// that share a lumen share one trunk). Then repeatedly take the region voxel whose tree path adds
// the most new length beyond a suppression zone around the paths taken (the far end of the
// longest branch not yet traced), among voxels whose new part stays inside the structure (mean
// cost per mm <= maxCostPerMm); its path is the medial chain (prefixed by the earlier path it
// starts from). A terminal lies on the lumen's medial ridge (the far voxel moved back along the
// chain), and an end where the region stops inside a wide lumen (as deep as its branch, not at the
// volume's edge: the lumen level, not the vessel, ends there) is not taken. Grow the zone, repeat
// until `count` terminals or no new part reaches minLengthMm. O(region log region) once,
// O(region) per terminal; the background is never searched.
struct AutoTerminalOptions {
  int count = 8;            // at most this many terminals (0: no limit, stop on minLengthMm)
  double minLengthMm = 10;  // a terminal must add at least this much new path length
  // The region continued along branches that dim below the lumen level where they stay a resolved tube
  // (region_continue.h). Off by default: on the real sets it found no terminal more, put more points outside the
  // vessel (head CTA 5 -> 16) and cost ~70 % more CPU (docs/notes/tracking.md, sessions 18 region3, 19 region4/lead).
  bool continueDimBranches = false;
  double maxNodeCost = std::numeric_limits<double>::quiet_NaN();       // on every new node; NaN: 0.2 x median node cost
  double maxCostPerMm = std::numeric_limits<double>::quiet_NaN();      // of the new part; NaN: = maxNodeCost
  double suppressRadiusMm = std::numeric_limits<double>::quiet_NaN();  // NaN: 1.5 x lumen depth + largest spacing
};

struct TrackerStats {
  int64_t voxels = 0, nodes = 0, edges = 0;  // edges: undirected (grid: counted analytically)
  int64_t repairEdges = 0;
  int64_t settled = 0;
  double graphSeconds = 0;            // building the graph (pruned) / the grid view
  double searchSeconds = 0;           // all search work so far (the terminal scan's lumen search included)
  int64_t terminalSearchSettled = 0;  // autoTerminals: lumen voxels its own search settled
  double terminalRegionSeconds = 0;   // autoTerminals: its lumen region, depth and first medial tree (wall)
  bool fullSearch = false;            // every node reachable from the root is settled
  int64_t loopedTurnsReused = 0;      // path points the looped-contact re-search skipped, refused on an earlier path
};

class VesselTracker {
 public:
  // volume: intensities (IsoRegion map, radius estimation); cost: node costs of the same
  // geometry. Both must outlive the tracker. Throws InvalidArgument for a root outside the
  // volume, a size mismatch or a bad connectivity.
  VesselTracker(const VolumeF32& volume, const NodeCost3D& cost, const Index3& root, const TrackerOptions& options = {},
                Progress& progress = Progress::none());
  ~VesselTracker();
  VesselTracker(const VesselTracker&) = delete;
  VesselTracker& operator=(const VesselTracker&) = delete;

  const Index3& root() const { return root_; }  // after snapping
  const Index3& requestedRoot() const { return requestedRoot_; }

  // Resumes the search until `target` is settled and records the path root -> target.
  // InvalidArgument if the target is outside the volume. O(1) search work if already settled.
  const TracedPath& addTarget(const Index3& target, Progress& progress = Progress::none());
  // Completes the whole single-source search (every reachable node settled).
  void runToCompletion(Progress& progress = Progress::none());
  // Proposes terminals (section 6.2) from the full cost map and adds each as a target.
  // Returns the indices into paths() of the added paths.
  std::vector<size_t> autoTerminals(const AutoTerminalOptions& options, Progress& progress = Progress::none());
  // Why the last autoTerminals() call stopped (e.g. no further branch adds the minimum length).
  const std::string& lastTerminalStop() const { return lastTerminalStop_; }
  // What the last autoTerminals() call scanned: "lumen region N voxels (V ml) ..., deepest D mm".
  const std::string& lastTerminalScan() const { return lastTerminalScan_; }

  const std::vector<TracedPath>& paths() const { return paths_; }
  // The tree of extracted paths as voxel points (point 0: the root), and the tree point of every
  // voxel of path i (same length as paths()[i].voxels; empty for an unreached path).
  CentrelineTree centrelineTree() const;
  const std::vector<int32_t>& pathTreePoints(size_t path) const;
  // Nodes (voxels) with >= 2 children in the tree of extracted paths.
  std::vector<Index3> branchPoints() const;
  // T(voxel) if settled/reached, +inf otherwise (pruned voxels: +inf).
  double totalCost(const Index3& voxel) const;
  TrackerStats stats() const;
  const Geometry& geometry() const { return geom_; }

  // The tree of extracted paths (world mm, SWC semantics: root type 1, others 3) with radii
  // estimated by radiusAt(). Empty if no path was reached.
  Tree toTree() const;
  // The same tree at refined positions with refined radii (refineCentreline of centrelineTree()),
  // with the refined tree's links: where refineCentreline re-branched a fork (splitForks) it has
  // copies of the shared points (RefinedCentreline::parent, source).
  Tree toTree(const RefinedCentreline& refined) const;
  // Keeps the refined points in the lumen: a point whose node cost exceeds the lumen level
  // lumenNodeCost moves back along the segment to its voxel until it is within max(maxNodeCost, the
  // mean of the voxel's cost and lumenNodeCost) (bisection): half as deep in the lumen as its voxel.
  // A point the cost still marks as lumen stays: between a thin lumen's noisy partial-volume voxels
  // the centred point reads the mean of voxels the search did not pick, above the picked one's cost
  // (the family's thin and kissing tubes). Centring can push a point into the wall where a branch or
  // a thin lumen disturbs the rays; the voxel path itself stays where the search put it. A point whose voxel's cost is
  // above lumenNodeCost (the cost's lumen level: the path crosses what the cost does not mark as lumen, a dim thin end)
  // has no lumen to be kept in and stays where the centring put it. The cost between voxels: trilinear, except along an
  // axis coarser than the finest, where a voxel's cost holds within its own slab and passes to the next voxel's over
  // the finest spacing around the slabs' boundary (issue 21: a thin lumen 2.5 mm slices apart; interpolated over the
  // whole interval, a steep cost pulled centred points back towards the slice of their voxel). A wide trunk's point
  // (RefinedCentreline::wideTrunk) is not moved back: placed ones (1) stay, kept ones (2) move at most half the finest
  // spacing, to the lowest cost there. Where refined.polarity is set, a point that reads in the image at least as
  // lumen-like as its voxel (brighter for a bright lumen, darker for a dark one) and not beyond `imageUpper` (the
  // lumen model's upper edge in the image; NaN: none) stays: the pull would take it to a place the image marks no
  // deeper; where `readsLumen` (per point, optional) marks the point as lumen by the lumen model at its place, the
  // voxel's value averaged with its six face neighbours is the reference instead of the voxel's own. Returns the
  // number of points moved.
  size_t confineToLumen(RefinedCentreline& refined, double maxNodeCost, double lumenNodeCost,
                        double imageUpper = std::numeric_limits<double>::quiet_NaN(),
                        const std::vector<uint8_t>* readsLumen = nullptr) const;
  // A label volume (uint16): path index + 1 on the voxels of each path (earlier paths win).
  VolumeU16 labelVolume() const;
  // Local lumen radius (mm) at a voxel: half-maximum crossing of the intensity profile along the
  // 26 directions (threshold midway between the 3x3x3 mean at the voxel and the median far value
  // at maxMm), the 30th percentile over directions. At least half the smallest spacing.
  double radiusAt(const Index3& voxel, double maxMm = 12.0) const;

 private:
  // Computes the length of tp's voxel chain (root -> target, 26-connected, starting at the root)
  // and merges it into the tree of extracted paths (shared prefix = shared trunk).
  const TracedPath& recordPath(TracedPath tp);
  // The search's path to a target checked for steps and drifts into a touching tube and searched
  // again there (crossing, neck, dip re-searches), or given the replacement an earlier path's
  // re-search made of the same stretch; an accepted re-search is given to the earlier paths through
  // that stretch too (the tree rebuilt).
  void retraceCrossings(TracedPath& tp);
  bool retraceFusedForks(TracedPath& tp);
  // Paths whose routes part and meet again inside one lumen take one trunk there (trunk_join.h);
  // earlier paths that change are recorded again.
  void joinTrunks(TracedPath& tp);
  // The tree of extracted paths recorded again from the root (after earlier paths changed).
  void rebuildTree();

  struct Impl;
  std::unique_ptr<Impl> impl_;
  Geometry geom_;
  Index3 root_{0, 0, 0}, requestedRoot_{0, 0, 0};
  std::vector<TracedPath> paths_;
  std::vector<std::vector<int32_t>> pathTreePoints_;
  std::string lastTerminalStop_, lastTerminalScan_;
};

// The node cost at or below which a voxel counts as inside the traced structure (automatic
// terminals, snapping): 0.2 x nodeWeight x the background's cost, taken as the 90th percentile of
// the node costs. (The median was used until lumen-like voxels turned out to be most of some
// volumes: the air around the body of a 512 x 512 chest CT put the median at the cost floor, so
// the level fell below the root's own cost and every root was refused. Where the background is
// most of the volume, as usual, both are its cost.)
double lumenCostThreshold(const NodeCost3D& cost);

// The thesis's snap, in 3D: the voxel nearest to `voxel` (physical distance, at most radiusMm)
// whose weighted node cost is <= maxNodeCost; `voxel` itself when it qualifies. found = false
// (voxel unchanged) when there is none within the radius.
struct LumenSnap {
  Index3 voxel{0, 0, 0};
  bool found = false;
  double distanceMm = 0;
};
LumenSnap snapToLumen(const NodeCost3D& cost, const Index3& voxel, double radiusMm, double maxNodeCost);

}  // namespace vs
