// The one shortest-path engine (thesis 2.2 and Appendix A): Dijkstra with back pointers B(u)
// and total costs T(u) per node, early stop as soon as the requested target is settled, and
// resumption of the same search for further targets (live-wire: one search per seed, many
// targets; vessel tracking: one root, many terminals).
//
// Graphs: GridGraph (implicit 2D/3D grids, costs from GridCost) and CsrGraph (explicit).
// Queue (SearchOptions::queue): a monotone bucket queue (Dial; default) or radix heap over
// fixed-point keys, or a plain binary heap (reference). The totals T are always accumulated
// exactly in float64; the key only orders the queue, so every queue gives the same T (equal up
// to float64 rounding order).
//
// Threads: every search is sequential (Dijkstra order) except runToCompletion() on a large grid,
// which runs on two threads when SearchOptions::threads = 2 asks or, automatic, when a second
// core is idle; the totals and the tree are the sequential ones bit for bit. One
// ShortestPathSearch must not be used from two threads at once; distinct searches are independent.
// Memory: about 16 B per grid node touched by the search (filled lazily, so an early stop costs
// O(explored region) plus the O(N) cost validation), 13 B per CSR node, plus the queue; a
// 26-connected full map peaks at about 21 B/voxel including a float cost volume.
// Complexity: O(E + key range / 64) with the bucket queue, O(E log C) with the radix heap (C = key
// range of one edge), O(E log E) with the binary heap.
// Layout, memory and threading internals: docs/notes/engine.md.
//
// Cancellation/progress: the settle loops call progress.report(settled / N, "search") once per
// options.progressChunk extracted nodes; a cancel throws vs::Cancelled and leaves the search in a
// consistent state (it can be resumed).
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "graph/csr_graph.h"
#include "graph/grid_cost.h"
#include "graph/grid_graph.h"
#include "graph/path.h"
#include "util/progress.h"

namespace vs {

enum class QueueKind {
  Radix,       // monotone radix heap over fixed-point keys (fast)
  BinaryHeap,  // std::priority_queue of float64 keys (reference)
  Bucket,      // monotone bucket queue (Dial) over the same fixed-point keys, with prefetching of
               // the next nodes' neighbourhoods (fastest; default). Falls back to Radix when one
               // edge spans more than 2^16 keys (a huge cost range with a fine keyResolution).
};

struct SearchOptions {
  QueueKind queue = QueueKind::Bucket;
  // Optional ROI: one byte per node; nodes whose byte is 0 are excluded (never entered).
  // Empty = every node allowed. Must outlive the search. A source outside the mask is an error.
  std::span<const uint8_t> mask;
  // Fixed-point quantum of the radix keys in cost units; 0 = automatic (the smallest positive
  // edge cost, at least the largest / 2^20). Affects speed only, never the result.
  double keyResolution = 0;
  // Extracted nodes between two progress reports / cancellation checks.
  int64_t progressChunk = 1 << 16;
  // runToCompletion() on grids of at least parallelMinNodes nodes (bucket queue, no A*): 0 =
  // automatic = two threads when a second core is idle at the start of the map, else
  // sequential (`secondCoreIdle`, util/parallel.h: the two-thread map is ~2x faster on an idle
  // core and up to 2x slower on a busy one: docs/notes/engine.md), 1 = sequential, 2 = two
  // threads, one per half of the grid. Same totals either way; between two predecessors giving exactly equal totals
  // the two-thread choice may differ from run to run.
  int threads = 0;
  int64_t parallelMinNodes = int64_t(1) << 20;
  // findPath only: A* with the admissible bound (smallest cost per mm) * (Euclidean distance in
  // mm); the cost is the same as Dijkstra's, fewer nodes are settled. Ignored by
  // ShortestPathSearch (its searches serve many targets).
  bool useAStar = true;
};

// Back-pointer value meaning "none" (a source, or a node not reached yet).
inline constexpr uint8_t kNoDirection = 0x1f;

class ShortestPathSearch {
 public:
  // Grid search from one or more sources (node ids, all T = 0). `graph`, the cost arrays and the
  // mask are referenced: they must outlive the search (node costs and signs are copied into the
  // search's records as the search first reaches them; per-edge costs are read during the search). Validates the costs
  // (O(N) or O(N*K)): DataError for NaN/negative values or wrong array sizes (InvalidArgument), naming the voxel.
  // InvalidArgument for a source out of range or masked out, or no source.
  ShortestPathSearch(const GridGraph& graph, const GridCost& cost, std::vector<int64_t> sources,
                     const SearchOptions& options = {});
  // Explicit-graph search (weights already validated by CsrGraph). `graph` must outlive the search.
  ShortestPathSearch(const CsrGraph& graph, std::vector<int64_t> sources, const SearchOptions& options = {});
  ~ShortestPathSearch();
  ShortestPathSearch(ShortestPathSearch&&) noexcept;
  ShortestPathSearch& operator=(ShortestPathSearch&&) noexcept;

  // Starts over from new sources, reusing the allocations (live-wire: one restart per click).
  void restart(std::vector<int64_t> sources);

  // Settles nodes until `target` is settled (its T final) or the queue is empty.
  // Returns true if the target is reachable. O(1) when it is already settled.
  // InvalidArgument if target is not a node.
  bool settleUntil(int64_t target, Progress& progress = Progress::none());
  // Settles until every target is settled (or unreachable); returns how many are reachable.
  int64_t settleUntilAll(std::span<const int64_t> targets, Progress& progress = Progress::none());
  // Settles every node whose total cost is <= maxCost.
  void settleUntilCost(double maxCost, Progress& progress = Progress::none());
  // Settles every reachable node (the full single-source map).
  void runToCompletion(Progress& progress = Progress::none());

  // settleUntil(t) then T(t); +inf if unreachable.
  double costTo(int64_t target, Progress& progress = Progress::none());
  // settleUntil(t) then the path source -> t by following back pointers; empty if unreachable.
  Path pathTo(int64_t target, Progress& progress = Progress::none());
  // The path to an already settled node without searching further (empty if not settled).
  Path settledPath(int64_t target) const;

  // ---- state (valid between calls) ----
  int64_t nodeCount() const;
  int64_t settledCount() const;
  bool finished() const;  // queue exhausted: every reachable node settled
  // Threads the last runToCompletion() ran on (1 or 2; automatic mode decides per call).
  int lastRunThreads() const;
  bool isSettled(int64_t node) const;
  // T(u): final when settled, tentative (an upper bound) when reached, +inf when not reached
  // or masked out.
  double totalCost(int64_t node) const;
  // Predecessor node id on the shortest path, -1 for a source or an unreached node.
  int64_t predecessor(int64_t node) const;
  // Grid only: direction index (grid_graph.h order) from the node to its predecessor, i.e.
  // predecessor = node + offset(backDirection(node)); kNoDirection for sources/unreached.
  uint8_t backDirection(int64_t node) const;

  // Flat arrays (N entries, node order). T: float64 totals as totalCost() except masked nodes,
  // which hold -inf. State byte per node: bits 0-4 back direction (grid; 31 = none),
  // bit 5 internal (grid boundary flag), bit 6 settled, bit 7 unused.
  // For grids these are snapshots copied from the packed records on the first call after a
  // settle (O(N), 9 B/node extra); they stay valid until the next call to a settle/restart
  // function. For CSR graphs they are the live arrays.
  std::span<const double> totalCosts() const;
  std::span<const uint8_t> nodeState() const;
  // CSR only: predecessor ids (uint32; 0xffffffff = none). Empty for grids.
  std::span<const uint32_t> predecessors() const;

  static constexpr uint8_t kSettledBit = 0x40;
  static constexpr uint8_t kDirectionMask = 0x1f;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// One point-to-point query (A* unless options.useAStar is false; the CSR graph's A* bound needs
// node positions). Empty path if unreachable; source == target gives a 1-node path of cost 0.
Path findPath(const GridGraph& graph, const GridCost& cost, int64_t source, int64_t target,
              const SearchOptions& options = {}, Progress& progress = Progress::none());
Path findPath(const CsrGraph& graph, int64_t source, int64_t target, const SearchOptions& options = {},
              Progress& progress = Progress::none());

}  // namespace vs
