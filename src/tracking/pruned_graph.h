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
#include <vector>

#include "features/cost3d.h"
#include "graph/csr_graph.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct IsoRegionOptions {
  double tolerance = 0;   // |V(w) - V(u)| <= tolerance counts as "the same value" (>= 0)
  double threshold = -std::numeric_limits<double>::infinity();  // values below are set to 0 first (thesis: 30)
};

// I(u) per voxel (x fastest). Saturates at 65535. Throws InvalidArgument for a negative tolerance.
std::vector<uint16_t> isoRegionMap(const VolumeF32& volume, const IsoRegionOptions& options = {},
                                   Progress& progress = Progress::none());

// Reference implementation of Appendix B (one sweep per d, O(N * maxI)); for tests only.
std::vector<uint16_t> isoRegionMapBruteForce(const VolumeF32& volume, const IsoRegionOptions& options = {});

struct PrunedGraph {
  CsrGraph graph;                      // undirected (both directions stored); positions in mm
  Geometry geometry;
  std::vector<int64_t> nodeVoxel;      // node -> linear voxel index
  std::vector<int32_t> voxelNode;      // voxel -> node, -1 if pruned
  int connectivity = 26;
  int64_t voxels = 0;
  int64_t nodes = 0;
  int64_t edges = 0;                   // undirected edges (graph.edgeCount() / 2)
  int64_t repairEdges = 0;             // bridging edges added by the connectivity repair
  int maxIsoRegion = 0;
  double buildSeconds = 0;             // IsoRegion map + nodes + edges + CSR

  bool isNode(int64_t voxel) const { return voxelNode[static_cast<size_t>(voxel)] >= 0; }
  // The node nearest (Euclidean mm) to a voxel: itself if it is a node, else the closest node
  // found by scanning cubes of growing radius. -1 only if the graph has no node at all.
  int64_t nearestNode(const Index3& voxel) const;
};

// Builds the pruned graph of a volume with the given cost model (whose geometry must match).
// connectivity: 6, 18 or 26. Throws InvalidArgument for bad arguments. Cancellable.
PrunedGraph buildPrunedGraph(const VolumeF32& volume, const NodeCost3D& cost, int connectivity = 26,
                             const IsoRegionOptions& options = {}, Progress& progress = Progress::none());

}  // namespace vs
