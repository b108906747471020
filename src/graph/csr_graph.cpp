#include "graph/csr_graph.h"

#include <cmath>
#include <limits>
#include <string>

#include "util/error.h"

namespace vs {

CsrGraph::CsrGraph(std::vector<int64_t> rowStart, std::vector<uint32_t> targets, std::vector<float> weights,
                   std::vector<std::array<float, 3>> positions)
    : rowStart_(std::move(rowStart)),
      targets_(std::move(targets)),
      weights_(std::move(weights)),
      positions_(std::move(positions)) {
  if (rowStart_.empty()) throw InvalidArgument("CsrGraph: rowStart must have nodeCount+1 entries (got 0)");
  const int64_t n = nodeCount();
  if (n >= 4294967295LL) throw InvalidArgument("CsrGraph: too many nodes (limit 2^32-1)");
  if (rowStart_[0] != 0) throw InvalidArgument("CsrGraph: rowStart[0] must be 0");
  for (int64_t u = 0; u < n; ++u)
    if (rowStart_[u + 1] < rowStart_[u])
      throw InvalidArgument("CsrGraph: rowStart decreases at node " + std::to_string(u));
  if (rowStart_[n] != static_cast<int64_t>(targets_.size()) || targets_.size() != weights_.size())
    throw InvalidArgument("CsrGraph: rowStart[N] = " + std::to_string(rowStart_[n]) + ", targets " +
                          std::to_string(targets_.size()) + " and weights " + std::to_string(weights_.size()) +
                          " must agree");
  if (!positions_.empty() && static_cast<int64_t>(positions_.size()) != n)
    throw InvalidArgument("CsrGraph: positions must be empty or one per node (" + std::to_string(n) + "), got " +
                          std::to_string(positions_.size()));
  maxWeight_ = 0;
  float minPos = std::numeric_limits<float>::infinity();
  minPerMm_ = std::numeric_limits<double>::infinity();
  for (int64_t u = 0; u < n; ++u)
    for (int64_t e = rowStart_[u]; e < rowStart_[u + 1]; ++e) {
      const uint32_t v = targets_[e];
      if (static_cast<int64_t>(v) >= n)
        throw InvalidArgument("CsrGraph: edge " + std::to_string(e) + " from node " + std::to_string(u) +
                              " targets node " + std::to_string(v) + " >= node count " + std::to_string(n));
      const float w = weights_[e];
      if (!(w >= 0))
        throw DataError("CsrGraph: edge " + std::to_string(u) + " -> " + std::to_string(v) + " has weight " +
                        std::to_string(w) + " (must be >= 0, not NaN)");
      if (std::isfinite(w) && w > maxWeight_) maxWeight_ = w;
      if (w > 0 && w < minPos) minPos = w;
      if (!positions_.empty()) {
        const auto& a = positions_[u];
        const auto& b = positions_[v];
        const double d = std::sqrt(double(a[0] - b[0]) * (a[0] - b[0]) + double(a[1] - b[1]) * (a[1] - b[1]) +
                                   double(a[2] - b[2]) * (a[2] - b[2]));
        if (d > 0) minPerMm_ = std::min(minPerMm_, double(w) / d);
      }
    }
  if (positions_.empty() || !std::isfinite(minPerMm_)) minPerMm_ = 0;
  minPositive_ = std::isfinite(minPos) ? minPos : 0.f;
}

CsrGraph CsrGraph::fromEdges(int64_t nodeCount, const std::vector<Edge>& edges, bool undirected,
                             std::vector<std::array<float, 3>> positions) {
  if (nodeCount < 0) throw InvalidArgument("CsrGraph::fromEdges: negative node count");
  std::vector<int64_t> start(static_cast<size_t>(nodeCount) + 1, 0);
  for (const auto& e : edges) {
    if (e.from < 0 || e.from >= nodeCount || e.to < 0 || e.to >= nodeCount)
      throw InvalidArgument("CsrGraph::fromEdges: edge " + std::to_string(e.from) + " -> " + std::to_string(e.to) +
                            " has a node outside 0.." + std::to_string(nodeCount - 1));
    ++start[e.from + 1];
    if (undirected) ++start[e.to + 1];
  }
  for (int64_t u = 0; u < nodeCount; ++u) start[u + 1] += start[u];
  std::vector<int64_t> fill(start.begin(), start.end() - 1);
  std::vector<uint32_t> targets(static_cast<size_t>(start.back()));
  std::vector<float> weights(targets.size());
  for (const auto& e : edges) {
    targets[fill[e.from]] = static_cast<uint32_t>(e.to);
    weights[fill[e.from]++] = e.weight;
    if (undirected) {
      targets[fill[e.to]] = static_cast<uint32_t>(e.from);
      weights[fill[e.to]++] = e.weight;
    }
  }
  return CsrGraph(std::move(start), std::move(targets), std::move(weights), std::move(positions));
}

}  // namespace vs
