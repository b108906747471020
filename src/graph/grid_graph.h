// Implicit grid graphs for the shortest-path engine (thesis 2.2, 4.1; issue 3).
// Nodes are the voxels of a dims[0] x dims[1] x dims[2] grid, node id = linear index
// x + nx*(y + ny*z) (x fastest, the layout of vs::Volume). No edge is stored: the
// neighbours of a node are the in-grid voxels at the connectivity's offsets, and the
// length of an edge is its physical length in mm from the voxel spacing
// (sqrt((dx*sx)^2 + (dy*sy)^2 + (dz*sz)^2)).
//
// Connectivity: 4 or 8 (2D, needs dims[2] == 1), 6, 18 or 26 (3D; any dims).
//
// DIRECTION ORDER (used by per-edge costs, back pointers and offset()): all offsets
// (dx,dy,dz) in {-1,0,1}^3 minus (0,0,0) allowed by the connectivity (2D: dz = 0;
// 4/6: one non-zero component; 18: at most two; 8/26: any), enumerated with dz slowest,
// then dy, then dx fastest, each from -1 to 1. Example 8-connected (2D), k = 0..7:
//   (-1,-1) (0,-1) (1,-1) (-1,0) (1,0) (-1,1) (0,1) (1,1)        as (dx,dy)
// 4-connected: (0,-1) (-1,0) (1,0) (0,1). 6-connected: (0,0,-1) (0,-1,0) (-1,0,0) (1,0,0)
// (0,1,0) (0,0,1). 26-connected: k = 9*(dz+1) + 3*(dy+1) + (dx+1), minus 1 for k > 13.
// The order is symmetric: the opposite of direction k is K-1-k.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace vs {

class GridGraph {
 public:
  static constexpr int kMaxDirections = 26;

  GridGraph() = default;
  // dims: voxels along x, y, z (all >= 1, product < 2^32); spacing: mm per voxel (finite, > 0);
  // connectivity: 4, 8, 6, 18 or 26. Throws InvalidArgument naming the bad value.
  GridGraph(std::array<int64_t, 3> dims, std::array<double, 3> spacing, int connectivity);

  const std::array<int64_t, 3>& dims() const { return dims_; }
  const std::array<double, 3>& spacing() const { return spacing_; }
  int connectivity() const { return connectivity_; }
  int directionCount() const { return k_; }  // K (= connectivity)
  int64_t nodeCount() const { return dims_[0] * dims_[1] * dims_[2]; }

  // Offset (dx, dy, dz) of direction k (0 <= k < K), its linear index offset, and length in mm.
  const std::array<int, 3>& offset(int k) const { return offsets_[k]; }
  int64_t linearOffset(int k) const { return linear_[k]; }
  double length(int k) const { return lengths_[k]; }
  static int opposite(int k, int directionCount) { return directionCount - 1 - k; }
  int opposite(int k) const { return k_ - 1 - k; }
  // Direction index of offset (dx,dy,dz), or -1 if it is not an edge of this connectivity.
  int direction(int dx, int dy, int dz) const;

  int64_t node(int64_t x, int64_t y, int64_t z) const { return x + dims_[0] * (y + dims_[1] * z); }
  std::array<int64_t, 3> coords(int64_t node) const {
    return {node % dims_[0], (node / dims_[0]) % dims_[1], node / (dims_[0] * dims_[1])};
  }
  bool contains(int64_t x, int64_t y, int64_t z) const {
    return x >= 0 && y >= 0 && z >= 0 && x < dims_[0] && y < dims_[1] && z < dims_[2];
  }
  bool containsNode(int64_t node) const { return node >= 0 && node < nodeCount(); }
  // The neighbour of `node` in direction k, or -1 if it lies outside the grid. O(1).
  int64_t neighbor(int64_t node, int k) const;
  // Smallest edge length in mm (used by A* bounds).
  double minLength() const;

  // "256x256x1, 8-connected, 0.5x0.5x1 mm"
  std::string describe() const;

 private:
  std::array<int64_t, 3> dims_{1, 1, 1};
  std::array<double, 3> spacing_{1, 1, 1};
  int connectivity_ = 26;
  int k_ = 0;
  std::array<std::array<int, 3>, kMaxDirections> offsets_{};
  std::array<int64_t, kMaxDirections> linear_{};
  std::array<double, kMaxDirections> lengths_{};
};

// Throws InvalidArgument unless `node` is a node of g; `what` names the argument ("source", "target").
void requireGridNode(const GridGraph& g, int64_t node, const std::string& what);

}  // namespace vs
