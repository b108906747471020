// Internal to the shortest-path engine: the engine factories, included only by the
// instantiation units search_bucket.cpp, search_radix.cpp and search_heap.cpp (one queue kind
// each, so the 48 engine instantiations compile in three units side by side).
#pragma once

#include "graph/search_engine.h"
#include "graph/search_parallel.h"

namespace vs::engine {

template <class Queue, int K, CostKind CK>
std::unique_ptr<ShortestPathSearch::Impl> makeGrid3(const GridGraph& g, const GridCost& c, double scale, double step) {
  return std::make_unique<Engine<GridModel<K, CK>, Queue>>(GridModel<K, CK>(g, c), scale, step);
}

template <class Queue, int K>
std::unique_ptr<ShortestPathSearch::Impl> makeGrid2(const GridGraph& g, const GridCost& c, double scale, double step) {
  if (c.kind == GridCost::Kind::PerEdge) return makeGrid3<Queue, K, CostKind::Edge>(g, c, scale, step);
  if (!c.sign.empty() && c.signWeight != 0) return makeGrid3<Queue, K, CostKind::NodeSign>(g, c, scale, step);
  return makeGrid3<Queue, K, CostKind::Node>(g, c, scale, step);
}

template <class Queue>
std::unique_ptr<ShortestPathSearch::Impl> makeGridEngine(const GridGraph& g, const GridCost& c, double scale,
                                                         double step) {
  switch (g.directionCount()) {
    case 4:
      return makeGrid2<Queue, 4>(g, c, scale, step);
    case 8:
      return makeGrid2<Queue, 8>(g, c, scale, step);
    case 6:
      return makeGrid2<Queue, 6>(g, c, scale, step);
    case 18:
      return makeGrid2<Queue, 18>(g, c, scale, step);
    default:
      return makeGrid2<Queue, 26>(g, c, scale, step);
  }
}

template <class Queue>
std::unique_ptr<ShortestPathSearch::Impl> makeCsrEngine(const CsrGraph& g, double scale, double step) {
  return std::make_unique<Engine<CsrModel, Queue>>(CsrModel(g), scale, step);
}

}  // namespace vs::engine

// Explicit instantiation of both factories for one queue type.
#define VS_INSTANTIATE_SEARCH_ENGINES(Queue)                                                                           \
  template std::unique_ptr<vs::ShortestPathSearch::Impl> vs::engine::makeGridEngine<Queue>(                            \
      const vs::GridGraph&, const vs::GridCost&, double, double);                                                      \
  template std::unique_ptr<vs::ShortestPathSearch::Impl> vs::engine::makeCsrEngine<Queue>(const vs::CsrGraph&, double, \
                                                                                          double);
