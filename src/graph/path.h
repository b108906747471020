// A shortest path as returned by the search engine (thesis 2.2, Appendix A).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace vs {

// A path through a graph, source first, target last.
// "Not found" (target unreachable, masked out, or cost +inf) is an empty Path.
// A path from a node to itself is one node with cost 0.
struct Path {
  std::vector<int64_t> nodes;                  // node ids; for grids the linear voxel index x + nx*(y + ny*z)
  std::vector<std::array<int64_t, 3>> voxels;  // grids only: (x, y, z) of each node (same order); empty for CSR graphs
  double cost = 0;                             // sum of edge costs along the path (float64 accumulation)
  double lengthMm = 0;                         // physical length: sum of step lengths in mm (grid: from voxel spacing;
                                               // CSR: Euclidean distance between node positions, 0 without positions)

  bool empty() const { return nodes.empty(); }
  size_t size() const { return nodes.size(); }
};

}  // namespace vs
