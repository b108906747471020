// IsoRegion map and the pruned 3D graph (thesis 4.1 and Appendix B; reading-notes.md).
//
// IsoRegion map I(u): the largest d such that the (2d+1)^3 cube centred at u lies inside the
// volume and holds one value (within `tolerance`). Computed as the chessboard distance
// transform of the set S of voxels whose 3x3x3 block is not uniform (border voxels, whose block
// leaves the volume, are in S): I = 0 on S, else the chessboard distance to S. Two raster passes
// with the 13 causal / anti-causal 26-neighbours (exact for the chessboard metric), O(N), instead
// of the thesis's one full sweep per d. With tolerance > 0 "uniform" means every voxel of the
// block is within tolerance of the centre (not transitive; an approximation, as the notes allow).
// Optional threshold (thesis trick): values below it are set to 0 first, so noisy background
// becomes one uniform region.
//
// Field the map is computed on (IsoRegionOptions::field; docs/notes/tracking.md "Pruning on the
// cost field"):
//  * Cost (default): the node-cost field the search sees - c(u) and, when the cost uses it, the
//    sign bit (a block is uniform only if every voxel has the centre's sign bit and a cost equal
//    to the centre's, or within costTolerance * |c(centre)| - relative). Inside such a region
//    every full-grid edge has the same cost per mm, so straight segments are optimal up to the
//    chain weights below. A windowed/clipped cost (intensity window, thresholds, quantised or
//    given costs) is flat over huge regions even where the intensities are noisy (real CT in HU).
//  * Intensity: the thesis's literal rule on the voxel values, with `threshold` and the absolute
//    `tolerance`. Prunes little on noisy data unless thresholded.
//
// Pruned graph (4.1 pseudo-code + notes): nodes = voxels with I = 0 and IsoRegion centres (I >= I
// of all 26 neighbours; plateaus allowed). Edges (undirected): an I = 0 node links to its
// neighbouring nodes (the chosen connectivity); a centre with I = d links to the nodes among the
// voxels at offset d * (each direction of the connectivity). Edge weights from the same cost
// model as the full grid: a long edge costs what the straight voxel chain it spans costs in the full
// grid (NodeCost3D::edgeCost per step, lengths in mm), so pruned paths never undercut the full grid.
// Connectivity repair (our addition, documented in docs/notes/tracking.md): the thesis rule can
// leave a centre (or an inner I=0 shell) unconnected when its boundary voxels at d * direction
// are all pruned. We map every pruned voxel to a node by steepest ascent of I, then for every
// full-grid edge (a, b) join rep(a) and rep(b) with a union-find and add one bridging edge
// rep(a)-rep(b) whenever they were in different components. So two nodes connected in the full
// grid graph are always connected in the pruned graph (tested), at the price of a few extra edges.
//
// Layout: voxel ids are linear indices x + nx*(y + ny*z); graph node ids are 0..nodes-1.
// Complexity: O(N * K) time, memory ~ 2 + 4 bytes per voxel plus the CSR graph.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "cost/cost3d.h"
#include "graph/csr_graph.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

enum class IsoRegionField { Cost, Intensity };
std::string isoRegionFieldName(IsoRegionField f);             // "cost", "intensity"
IsoRegionField isoRegionFieldFromName(const std::string& s);  // throws InvalidArgument listing the choices

struct IsoRegionOptions {
  IsoRegionField field = IsoRegionField::Cost;  // which field buildPrunedGraph computes the map on
  double tolerance = 0;  // intensity field: |V(w) - V(u)| <= tolerance counts as "the same value" (>= 0)
  double threshold =
      -std::numeric_limits<double>::infinity();  // intensity field: values below are set to 0 first (thesis: 30)
  double costTolerance =
      0;  // cost field: |c(w) - c(u)| <= costTolerance * |c(u)| is "the same" (relative, >= 0; 0 = exact)
};

// Intensity-field I(u) per voxel (x fastest; options.field and costTolerance are not used).
// Saturates at 65535. Throws InvalidArgument for a negative tolerance.
std::vector<uint16_t> isoRegionMap(const VolumeF32& volume, const IsoRegionOptions& options = {},
                                   Progress& progress = Progress::none());
// Cost-field I(u): the same map computed on cost.node (+ cost.sign when cost.signWeight > 0) with
// the relative tolerance. Throws InvalidArgument for a negative or NaN tolerance or an empty cost.
std::vector<uint16_t> costIsoRegionMap(const NodeCost3D& cost, double relativeTolerance = 0,
                                       Progress& progress = Progress::none());

// Reference implementations of Appendix B (one sweep per d, O(N * maxI)); for tests only.
std::vector<uint16_t> isoRegionMapBruteForce(const VolumeF32& volume, const IsoRegionOptions& options = {});
std::vector<uint16_t> costIsoRegionMapBruteForce(const NodeCost3D& cost, double relativeTolerance = 0);

struct PrunedGraph {
  CsrGraph graph;  // undirected (both directions stored); positions in mm
  Geometry geometry;
  std::vector<int64_t> nodeVoxel;  // node -> linear voxel index
  std::vector<int32_t> voxelNode;  // voxel -> node, -1 if pruned
  int connectivity = 26;
  int64_t voxels = 0;
  int64_t nodes = 0;
  int64_t edges = 0;        // undirected edges (graph.edgeCount() / 2)
  int64_t repairEdges = 0;  // bridging edges added by the connectivity repair
  int maxIsoRegion = 0;
  IsoRegionField field = IsoRegionField::Cost;  // the field the IsoRegion map was computed on
  double buildSeconds = 0;                      // IsoRegion map + nodes + edges + CSR

  bool isNode(int64_t voxel) const { return voxelNode[static_cast<size_t>(voxel)] >= 0; }
  // The node nearest (Euclidean mm) to a voxel: itself if it is a node, else the closest node
  // found by scanning cubes of growing radius. -1 only if the graph has no node at all.
  int64_t nearestNode(const Index3& voxel) const;
};

// Builds the pruned graph of a volume with the given cost model (whose geometry must match).
// connectivity: 6, 18 or 26. Throws InvalidArgument for bad arguments, including a threshold or
// (absolute) tolerance with the cost field, or a cost tolerance with the intensity field (options
// of the other field would be silently ignored). Cancellable.
PrunedGraph buildPrunedGraph(const VolumeF32& volume, const NodeCost3D& cost, int connectivity = 26,
                             const IsoRegionOptions& options = {}, Progress& progress = Progress::none());

}  // namespace vs
