// A minimum s-t cut for the cutting surface's Ishikawa graph (cutting_surface.cpp): edges are
// collected in pairs, then laid out once in compressed sparse rows and cut with Boost.Graph's
// Boykov-Kolmogorov max-flow. (An adjacency_list allocates every edge's properties one by one:
// ~3 million allocations for a nose's graph, most of the cutting surface's time.)
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vs {

class MinCutNetwork {
 public:
  explicit MinCutNetwork(size_t nodes) : nodes_(nodes) {}
  // An edge from -> to of `capacity` and its reverse to -> from of `reverseCapacity`.
  void addEdgePair(size_t from, size_t to, double capacity, double reverseCapacity) {
    from_.push_back(uint32_t(from)), to_.push_back(uint32_t(to)), capacity_.push_back(capacity);
    from_.push_back(uint32_t(to)), to_.push_back(uint32_t(from)), capacity_.push_back(reverseCapacity);
  }
  void reserve(size_t edgePairs) {
    from_.reserve(2 * edgePairs), to_.reserve(2 * edgePairs), capacity_.reserve(2 * edgePairs);
  }
  // Solves the maximum flow from `source` to `sink`; afterwards sourceSide(v) says whether node v
  // lies on the source's side of the minimum cut (Boost's black colour). Returns the flow.
  double solve(size_t source, size_t sink);
  bool sourceSide(size_t node) const { return sourceSide_[node] != 0; }

 private:
  size_t nodes_;
  std::vector<uint32_t> from_, to_;
  std::vector<double> capacity_;
  std::vector<uint8_t> sourceSide_;
};

}  // namespace vs
