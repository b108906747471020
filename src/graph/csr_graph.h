// Explicit graphs in compressed sparse row form (meshes, the pruned IsoRegion graph of
// thesis 4.1 / Appendix B) for the shortest-path engine. Directed edges with float weights
// (>= 0, +inf allowed = impassable; NaN/negative rejected); an undirected graph stores both
// directions. Optional node positions (mm) give path lengths and the A* bound.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace vs {

class CsrGraph {
 public:
  struct Edge {
    int64_t from = 0, to = 0;
    float weight = 0;
  };

  CsrGraph() = default;
  // rowStart: nodeCount+1 non-decreasing offsets into targets/weights (rowStart[0] = 0);
  // the out-edges of node u are targets[rowStart[u] .. rowStart[u+1]). positions: empty or one per node.
  // Throws InvalidArgument (bad structure, node id out of range, >= 2^32 nodes) or
  // DataError (NaN or negative weight, naming the edge). O(E).
  CsrGraph(std::vector<int64_t> rowStart, std::vector<uint32_t> targets, std::vector<float> weights,
           std::vector<std::array<float, 3>> positions = {});

  // Builds from an edge list; undirected = true adds each edge in both directions. O(E + N).
  static CsrGraph fromEdges(int64_t nodeCount, const std::vector<Edge>& edges, bool undirected = true,
                            std::vector<std::array<float, 3>> positions = {});

  int64_t nodeCount() const { return static_cast<int64_t>(rowStart_.size()) - 1; }
  int64_t edgeCount() const { return static_cast<int64_t>(targets_.size()); }  // directed edges
  const std::vector<int64_t>& rowStart() const { return rowStart_; }
  const std::vector<uint32_t>& targets() const { return targets_; }
  const std::vector<float>& weights() const { return weights_; }
  const std::vector<std::array<float, 3>>& positions() const { return positions_; }
  bool hasPositions() const { return !positions_.empty(); }
  float maxFiniteWeight() const { return maxWeight_; }
  float minPositiveWeight() const { return minPositive_; }  // 0 if no edge has a positive weight
  // Smallest weight / Euclidean length over edges with positive length (A* bound); 0 without positions.
  double minWeightPerMm() const { return minPerMm_; }

 private:
  std::vector<int64_t> rowStart_{0};
  std::vector<uint32_t> targets_;
  std::vector<float> weights_;
  std::vector<std::array<float, 3>> positions_;
  float maxWeight_ = 0;
  float minPositive_ = 0;
  double minPerMm_ = 0;
};

}  // namespace vs
