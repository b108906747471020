#include "cutting/min_cut.h"

// GCC 12 at -O2 reports -Wmaybe-uninitialized inside Boost.Graph's edge iterators (an optional
// it cannot see through); the warning's location is these headers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/property_map/property_map.hpp>
#pragma GCC diagnostic pop
#include <utility>

#include "util/error.h"

namespace vs {

double MinCutNetwork::solve(size_t source, size_t sink) {
  using Graph = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                                   boost::no_property, uint32_t, uint32_t>;
  using Edge = boost::graph_traits<Graph>::edge_descriptor;
  VS_REQUIRE(nodes_ < (size_t(1) << 32) && from_.size() < (size_t(1) << 32), "minimum cut: the graph is too large");
  const size_t m = from_.size();
  // Counting sort by source: position[e] is edge e's place in the rows; pairs stay known, so the
  // reverse of the edge at position[e] is the one at position[e ^ 1].
  std::vector<uint32_t> start(nodes_ + 1, 0), position(m);
  for (uint32_t f : from_) ++start[f + 1];
  for (size_t v = 0; v < nodes_; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> next(start.begin(), start.end() - 1);
  std::vector<std::pair<uint32_t, uint32_t>> sorted(m);
  for (size_t e = 0; e < m; ++e) {
    position[e] = next[from_[e]]++;
    sorted[position[e]] = {from_[e], to_[e]};
  }
  const Graph graph(boost::edges_are_sorted, sorted.begin(), sorted.end(), nodes_);
  // With sorted input the graph keeps the order: the edge index is the position.
  std::vector<double> capacity(m), residual(m);
  std::vector<Edge> reverse(m);
  for (size_t e = 0; e < m; ++e) {
    capacity[position[e]] = capacity_[e];
    reverse[position[e]] = Edge(to_[e], position[e ^ 1]);  // a CSR edge is (source, index)
  }
  const auto edgeIndex = boost::get(boost::edge_index, graph);
  const auto vertexIndex = boost::get(boost::vertex_index, graph);
  std::vector<boost::default_color_type> color(nodes_);
  std::vector<Edge> predecessor(nodes_);
  std::vector<long> distance(nodes_);
  const double flow = boost::boykov_kolmogorov_max_flow(
      graph, boost::make_iterator_property_map(capacity.begin(), edgeIndex),
      boost::make_iterator_property_map(residual.begin(), edgeIndex),
      boost::make_iterator_property_map(reverse.begin(), edgeIndex),
      boost::make_iterator_property_map(predecessor.begin(), vertexIndex),
      boost::make_iterator_property_map(color.begin(), vertexIndex),
      boost::make_iterator_property_map(distance.begin(), vertexIndex), vertexIndex, uint32_t(source), uint32_t(sink));
  sourceSide_.assign(nodes_, 0);
  for (size_t v = 0; v < nodes_; ++v) sourceSide_[v] = color[v] == boost::black_color;
  return flow;
}

}  // namespace vs
