// Exact minimal paths on grids too large to hold (issue 25): a 26-connected grid of node costs
// (edge w(u,v) = len_mm * (c(u) + c(v)) / 2, the GridCost::nodes model of the engine) whose
// costs come block by block from a provider (a chunked volume, a cost computed per block), with
// the search state allocated per block the first time the search touches it, so memory is
// proportional to the explored region, never to the grid (2048^3 and beyond: node ids are
// 64-bit). Blocks are cubes of 2^shift voxels per side; the block slabs are pooled (reused by the
// next search of the same object).
//
// Goal-directed and exact: findPaths() is A* towards the set of targets with the bound
// h(v) = cmin * min_t ||p(v) - p(t)||_mm, cmin a lower bound of every node cost (the provider's,
// or 0 = plain Dijkstra). With node costs >= cmin every edge costs >= cmin * len, so h is
// consistent and the first time a target leaves the queue its total is final; a node improved
// after it was settled (possible only through float64 rounding of h) is re-opened, so the
// totals equal the full Dijkstra's (tests/graph/block_search_test.cpp: every target on random
// volumes, block sizes that do not divide the dims, walls and zero costs).
// Costs must be >= 0 (+inf = impassable); NaN/negative -> DataError naming the voxel.
// Memory: per touched block 13 B/voxel (T float64, cost float32, state byte) + the queue
// (16 B per queued entry); the block directory is 8 B per block of the whole grid.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "graph/path.h"
#include "util/progress.h"

namespace vs {

struct BlockCostSource {
  std::array<int64_t, 3> dims{1, 1, 1};    // voxels along x, y, z
  std::array<double, 3> spacing{1, 1, 1};  // mm per voxel
  int blockShift = 5;                      // blocks of 2^shift voxels per side (2..8)
  double minCost = 0;                      // a lower bound of every node cost (0: Dijkstra)
  // Writes the node costs of block (bx, by, bz), voxels [b*2^shift, (b+1)*2^shift) clipped to
  // dims, x fastest over the full 2^shift-wide block (entries outside the grid are ignored).
  std::function<void(const std::array<int64_t, 3>& block, std::span<float> out)> fill;
};

struct BlockSearchStats {
  int64_t settled = 0;        // nodes taken off the queue as final
  int64_t blocksTouched = 0;  // blocks whose state was allocated
  int64_t blockBytes = 0;     // bytes of block state (all touched blocks)
  int64_t peakQueue = 0;      // largest queue size
};

class BlockSearch {
 public:
  explicit BlockSearch(BlockCostSource source);
  ~BlockSearch();
  BlockSearch(BlockSearch&&) noexcept;
  BlockSearch& operator=(BlockSearch&&) noexcept;

  // Shortest paths from `source` (x, y, z) to every target: one A* search towards all of them
  // (Dijkstra when minCost is 0). Unreachable targets give empty paths. InvalidArgument for a
  // voxel outside the grid; DataError for a NaN/negative cost reached by the search.
  std::vector<Path> findPaths(const std::array<int64_t, 3>& source, std::span<const std::array<int64_t, 3>> targets,
                              Progress& progress = Progress::none());
  Path findPath(const std::array<int64_t, 3>& source, const std::array<int64_t, 3>& target,
                Progress& progress = Progress::none());

  const BlockSearchStats& stats() const;  // of the last search

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace vs
