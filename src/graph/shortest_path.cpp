// The shortest-path engine's public side: cost validation, the key quantum, the choice of queue
// and engine, and ShortestPathSearch / findPath on top of the engine (search_engine.h).
// See shortest_path.h for the contract and docs/notes/engine.md for the internals.
#include "graph/shortest_path.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "graph/priority_queues.h"
#include "graph/search_engine.h"
#include "util/error.h"
#include "util/parallel.h"

namespace vs {

using engine::kDirMask;
using engine::kInf;
using engine::voxelName;

std::string engine::voxelName(const GridGraph& g, int64_t n) {
  const auto c = g.coords(n);
  std::string s = "(";  // appended piece by piece: "(" + std::string trips GCC 12's -Wrestrict
  for (int a = 0; a < 3; ++a) {
    s += std::to_string(c[static_cast<size_t>(a)]);
    s += a < 2 ? ',' : ')';
  }
  return s;
}

namespace {

// The largest key step of one push above the extracted key, in cost units: one edge for
// Dijkstra, two for A* (the consistent bound changes by at most one edge weight per edge).
double maxQueueStep(double maxEdge) { return 2 * maxEdge; }

// The queue actually used: Bucket falls back to Radix when its window would be too large.
QueueKind effectiveQueue(QueueKind q, double scale, double maxEdge) {
  if (q == QueueKind::Bucket && detail::BucketQueue::bucketsFor(scale, maxQueueStep(maxEdge)) == UINT64_MAX)
    return QueueKind::Radix;
  return q;
}

struct CostStats {
  double maxEdge = 0;          // largest finite edge weight
  double minPositiveEdge = 0;  // smallest positive edge weight (a lower bound of it)
  double minPerMm = 0;         // smallest weight per mm (A* bound)
};

// Validates the cost arrays of a grid search; throws naming the voxel.
CostStats validateGridCost(const GridGraph& g, const GridCost& c) {
  const int64_t n = g.nodeCount();
  const int K = g.directionCount();
  CostStats st;
  double maxLen = 0, minLen = kInf;
  for (int k = 0; k < K; ++k) {
    maxLen = std::max(maxLen, g.length(k));
    minLen = std::min(minLen, g.length(k));
  }
  if (c.kind == GridCost::Kind::Node) {
    if (int64_t(c.node.size()) != n)
      throw InvalidArgument("node cost array has " + std::to_string(c.node.size()) + " values, grid " + g.describe() +
                            " needs " + std::to_string(n));
    if (!c.sign.empty() && int64_t(c.sign.size()) != n)
      throw InvalidArgument("sign array has " + std::to_string(c.sign.size()) + " values, grid " + g.describe() +
                            " needs " + std::to_string(n));
    if (!(std::isfinite(c.nodeWeight) && c.nodeWeight >= 0 && std::isfinite(c.signWeight) && c.signWeight >= 0))
      throw InvalidArgument("cost weights w_g = " + std::to_string(c.nodeWeight) +
                            ", w_z = " + std::to_string(c.signWeight) + " must be finite and >= 0");
    const float fInf = std::numeric_limits<float>::infinity();
    float mx = 0, mn = fInf, mnPos = fInf;
    bool bad = false;
    std::mutex mu;
    parallelFor(
        0, n,
        [&](int64_t b, int64_t e) {
          // Branch-free selects only, so that the loop vectorises.
          float lmx = 0, lmn = fInf, lmnPos = fInf;
          int lbad = 0;
          const float* const node = c.node.data();
          for (int64_t v = b; v < e; ++v) {
            const float x = node[v];
            lbad |= !(x >= 0);  // negative or NaN
            const float fin = x < fInf ? x : 0.f;
            lmx = fin > lmx ? fin : lmx;
            lmn = x < lmn ? x : lmn;
            const float pos = x > 0 ? x : fInf;
            lmnPos = pos < lmnPos ? pos : lmnPos;
          }
          std::lock_guard<std::mutex> lock(mu);
          bad |= lbad != 0;
          mx = std::max(mx, lmx);
          mn = std::min(mn, lmn);
          mnPos = std::min(mnPos, lmnPos);
        },
        int64_t(1) << 20);
    if (bad)
      for (int64_t v = 0; v < n; ++v) {
        const float x = c.node[size_t(v)];
        if (!(x >= 0))
          throw DataError("node cost at voxel " + voxelName(g, v) + " is " + std::to_string(x) +
                          " (costs must be >= 0 and not NaN)");
      }
    const bool signTerm = !c.sign.empty() && c.signWeight != 0;
    st.maxEdge = maxLen * (double(c.nodeWeight) * mx + (signTerm ? double(c.signWeight) : 0.0));
    st.minPerMm = double(c.nodeWeight) * (std::isfinite(mn) ? mn : 0.0);
    // An edge with a positive node cost at one end weighs at least minLen * w_g * mnPos / 2.
    st.minPositiveEdge = minLen * double(c.nodeWeight) * (std::isfinite(mnPos) ? double(mnPos) : 0.0) / 2;
    if (signTerm) st.minPositiveEdge = std::min(st.minPositiveEdge, minLen * double(c.signWeight));
  } else {
    if (int64_t(c.edge.size()) != n * K)
      throw InvalidArgument("per-edge cost array has " + std::to_string(c.edge.size()) + " values, grid " +
                            g.describe() + " needs N*K = " + std::to_string(n * K));
    double mx = 0, mnPerMm = kInf, mnPos = kInf;
    const auto& d = g.dims();
    for (int64_t z = 0; z < d[2]; ++z)
      for (int64_t y = 0; y < d[1]; ++y)
        for (int64_t x = 0; x < d[0]; ++x) {
          const int64_t v = g.node(x, y, z);
          const float* e = c.edge.data() + size_t(v) * size_t(K);
          for (int k = 0; k < K; ++k) {
            const auto& o = g.offset(k);
            if (!g.contains(x + o[0], y + o[1], z + o[2])) continue;
            const float w = e[k];
            if (!(w >= 0))
              throw DataError("per-edge cost at voxel " + voxelName(g, v) + ", direction " + std::to_string(k) +
                              " is " + std::to_string(w) + " (costs must be >= 0 and not NaN)");
            if (w < std::numeric_limits<float>::infinity()) mx = std::max(mx, double(w));
            if (w > 0) mnPos = std::min(mnPos, double(w));
            mnPerMm = std::min(mnPerMm, double(w) / g.length(k));
          }
        }
    st.maxEdge = mx;
    st.minPositiveEdge = std::isfinite(mnPos) ? mnPos : 0.0;
    st.minPerMm = std::isfinite(mnPerMm) ? mnPerMm : 0.0;
  }
  return st;
}

// The radix keys' quantum q: the smallest positive edge weight, so that every positive edge
// moves its head to a later key and nodes are never re-queued (only zero-weight edges can tie),
// but at least maxEdge / 2^20 so that one edge spans at most ~20 radix levels.
double keyScale(const SearchOptions& o, double maxEdge, double minPositiveEdge) {
  if (o.keyResolution > 0) return 1.0 / o.keyResolution;
  if (!(maxEdge > 0) || !std::isfinite(maxEdge)) return 1.0;
  double q = std::max(minPositiveEdge, maxEdge / 1048576.0);
  if (!(q > 0) || !std::isfinite(q)) q = maxEdge / 1048576.0;
  return 1.0 / q;
}

std::unique_ptr<ShortestPathSearch::Impl> makeGridImpl(const GridGraph& g, const GridCost& c, const SearchOptions& o,
                                                       double* minPerMm) {
  const CostStats st = validateGridCost(g, c);
  if (minPerMm) *minPerMm = st.minPerMm;
  const double scale = keyScale(o, st.maxEdge, st.minPositiveEdge);
  const double step = maxQueueStep(st.maxEdge);
  std::unique_ptr<ShortestPathSearch::Impl> impl;
  switch (effectiveQueue(o.queue, scale, st.maxEdge)) {
    case QueueKind::BinaryHeap:
      impl = engine::makeGridEngine<detail::HeapQueue>(g, c, scale, step);
      break;
    case QueueKind::Bucket:
      impl = engine::makeGridEngine<detail::BucketQueue>(g, c, scale, step);
      break;
    default:
      impl = engine::makeGridEngine<detail::RadixQueue>(g, c, scale, step);
      break;
  }
  impl->grid = &g;
  impl->n = g.nodeCount();
  impl->opt = o;
  return impl;
}

std::unique_ptr<ShortestPathSearch::Impl> makeCsrImpl(const CsrGraph& g, const SearchOptions& o) {
  const double scale = keyScale(o, g.maxFiniteWeight(), g.minPositiveWeight());
  const double step = maxQueueStep(g.maxFiniteWeight());
  std::unique_ptr<ShortestPathSearch::Impl> impl;
  switch (effectiveQueue(o.queue, scale, g.maxFiniteWeight())) {
    case QueueKind::BinaryHeap:
      impl = engine::makeCsrEngine<detail::HeapQueue>(g, scale, step);
      break;
    case QueueKind::Bucket:
      impl = engine::makeCsrEngine<detail::BucketQueue>(g, scale, step);
      break;
    default:
      impl = engine::makeCsrEngine<detail::RadixQueue>(g, scale, step);
      break;
  }
  impl->csr = &g;
  impl->n = g.nodeCount();
  impl->opt = o;
  return impl;
}

void checkMask(const SearchOptions& o, int64_t n) {
  if (!o.mask.empty() && int64_t(o.mask.size()) != n)
    throw InvalidArgument("search mask has " + std::to_string(o.mask.size()) + " values, the graph has " +
                          std::to_string(n) + " nodes");
}

}  // namespace

ShortestPathSearch::ShortestPathSearch(const GridGraph& graph, const GridCost& cost, std::vector<int64_t> sources,
                                       const SearchOptions& options) {
  checkMask(options, graph.nodeCount());
  impl_ = makeGridImpl(graph, cost, options, nullptr);
  impl_->reset(sources);
}

ShortestPathSearch::ShortestPathSearch(const CsrGraph& graph, std::vector<int64_t> sources,
                                       const SearchOptions& options) {
  checkMask(options, graph.nodeCount());
  impl_ = makeCsrImpl(graph, options);
  impl_->reset(sources);
}

ShortestPathSearch::~ShortestPathSearch() = default;
ShortestPathSearch::ShortestPathSearch(ShortestPathSearch&&) noexcept = default;
ShortestPathSearch& ShortestPathSearch::operator=(ShortestPathSearch&&) noexcept = default;

void ShortestPathSearch::restart(std::vector<int64_t> sources) { impl_->reset(sources); }

bool ShortestPathSearch::settleUntil(int64_t target, Progress& progress) {
  impl_->checkNode(target, "target");
  if (impl_->tAt(target) == -kInf) return false;  // masked out
  if (!impl_->isSettled(target)) impl_->settle(target, kInf, progress);
  return impl_->isSettled(target) && impl_->tAt(target) < kInf;
}

int64_t ShortestPathSearch::settleUntilAll(std::span<const int64_t> targets, Progress& progress) {
  for (int64_t t : targets) impl_->checkNode(t, "target");
  int64_t reachable = 0;
  for (int64_t t : targets) reachable += settleUntil(t, progress) ? 1 : 0;
  return reachable;
}

void ShortestPathSearch::settleUntilCost(double maxCost, Progress& progress) {
  VS_REQUIRE(!std::isnan(maxCost), "settleUntilCost: maxCost is NaN");
  impl_->settle(-1, maxCost, progress);
}

void ShortestPathSearch::runToCompletion(Progress& progress) {
  impl_->settleAll(progress);
  // The chunked reports stop short of the end (the last chunk, the other thread's domain): a
  // finished map says so, or a progress bar stops at 0.9.
  progress.report(1.0, "search");
}

double ShortestPathSearch::costTo(int64_t target, Progress& progress) {
  return settleUntil(target, progress) ? impl_->tAt(target) : kInf;
}

Path ShortestPathSearch::pathTo(int64_t target, Progress& progress) {
  if (!settleUntil(target, progress)) return {};
  return impl_->path(target);
}

Path ShortestPathSearch::settledPath(int64_t target) const {
  impl_->checkNode(target, "target");
  return impl_->path(target);
}

int64_t ShortestPathSearch::nodeCount() const { return impl_->n; }
int64_t ShortestPathSearch::settledCount() const { return impl_->settled; }
bool ShortestPathSearch::finished() const { return impl_->finished; }
int ShortestPathSearch::lastRunThreads() const { return impl_->lastRunThreads; }
bool ShortestPathSearch::isSettled(int64_t node) const {
  impl_->checkNode(node, "node");
  return impl_->isSettled(node);
}
double ShortestPathSearch::totalCost(int64_t node) const {
  impl_->checkNode(node, "node");
  const double t = impl_->tAt(node);
  return t == -kInf ? kInf : t;
}
int64_t ShortestPathSearch::predecessor(int64_t node) const {
  impl_->checkNode(node, "node");
  return impl_->predecessor(node);
}
uint8_t ShortestPathSearch::backDirection(int64_t node) const {
  impl_->checkNode(node, "node");
  return impl_->grid ? uint8_t(impl_->sAt(node) & kDirMask) : kNoDirection;
}
std::span<const double> ShortestPathSearch::totalCosts() const {
  impl_->materialize();
  return impl_->T;
}
std::span<const uint8_t> ShortestPathSearch::nodeState() const {
  impl_->materialize();
  return impl_->state;
}
std::span<const uint32_t> ShortestPathSearch::predecessors() const { return impl_->pred; }

namespace {
Path runPointToPoint(std::unique_ptr<ShortestPathSearch::Impl> impl, int64_t source, int64_t target, bool useAStar,
                     double perMm, Progress& progress) {
  impl->checkNode(source, "source");
  impl->checkNode(target, "target");
  if (useAStar && perMm > 0) {
    impl->astarTarget = target;
    impl->astarPerMm = perMm * (1.0 - 1e-9);  // keep the bound admissible under rounding
  }
  impl->reset({source});
  if (impl->tAt(target) == -kInf) return {};
  impl->settle(target, kInf, progress);
  return impl->path(target);
}
}  // namespace

Path findPath(const GridGraph& graph, const GridCost& cost, int64_t source, int64_t target,
              const SearchOptions& options, Progress& progress) {
  checkMask(options, graph.nodeCount());
  double perMm = 0;
  auto impl = makeGridImpl(graph, cost, options, &perMm);
  return runPointToPoint(std::move(impl), source, target, options.useAStar, perMm, progress);
}

Path findPath(const CsrGraph& graph, int64_t source, int64_t target, const SearchOptions& options, Progress& progress) {
  checkMask(options, graph.nodeCount());
  auto impl = makeCsrImpl(graph, options);
  return runPointToPoint(std::move(impl), source, target, options.useAStar, graph.minWeightPerMm(), progress);
}

}  // namespace vs
