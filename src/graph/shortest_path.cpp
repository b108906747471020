// The shortest-path engine: one Dijkstra loop (Engine) templated over a graph/cost model and a
// priority queue, explicitly instantiated below for every grid connectivity and cost model and
// for CSR graphs. See shortest_path.h for the contract.
#include "graph/shortest_path.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "graph/priority_queues.h"
#include "util/error.h"

namespace vs {

namespace {

constexpr uint8_t kInterior = 0x20;
constexpr uint8_t kSettled = ShortestPathSearch::kSettledBit;
constexpr uint8_t kDirMask = ShortestPathSearch::kDirectionMask;
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string voxelName(const GridGraph& g, int64_t n) {
  const auto c = g.coords(n);
  return "(" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," + std::to_string(c[2]) + ")";
}

enum class CostKind { Node, NodeSign, Edge };

// Implicit grid with K neighbour directions and one of the three cost models.
template <int K, CostKind CK>
struct GridModel {
  static constexpr bool kCsr = false;
  const GridGraph* g = nullptr;
  const float* c = nullptr;
  const uint8_t* sign = nullptr;
  const float* edge = nullptr;
  std::array<int64_t, K> off{};
  std::array<double, K> halfLen{};  // len * w_g / 2 (node models)
  std::array<double, K> lenZ{};     // len * w_z (sign model)
  std::array<int, K> dx{}, dy{}, dz{};
  int64_t nx = 1, ny = 1, nz = 1;

  GridModel(const GridGraph& graph, const GridCost& cost) : g(&graph) {
    nx = graph.dims()[0];
    ny = graph.dims()[1];
    nz = graph.dims()[2];
    c = cost.node.data();
    sign = cost.sign.data();
    edge = cost.edge.data();
    for (int k = 0; k < K; ++k) {
      off[k] = graph.linearOffset(k);
      halfLen[k] = graph.length(k) * 0.5 * double(cost.nodeWeight);
      lenZ[k] = graph.length(k) * double(cost.signWeight);
      dx[k] = graph.offset(k)[0];
      dy[k] = graph.offset(k)[1];
      dz[k] = graph.offset(k)[2];
    }
  }

  double weight(uint32_t u, uint32_t v, int k, double cu, bool su) const {
    if constexpr (CK == CostKind::Node) {
      return halfLen[k] * (cu + double(c[v]));
    } else if constexpr (CK == CostKind::NodeSign) {
      return halfLen[k] * (cu + double(c[v])) + ((sign[v] != 0) == su ? lenZ[k] : 0.0);
    } else {
      (void)v;
      (void)cu;
      (void)su;
      return double(edge[size_t(u) * K + k]);
    }
  }

  // Calls f(v, w, backDirection) for every in-grid neighbour v of u.
  template <class F>
  void forEach(uint32_t u, uint8_t stateU, F&& f) const {
    double cu = 0;
    bool su = false;
    if constexpr (CK != CostKind::Edge) cu = double(c[u]);
    if constexpr (CK == CostKind::NodeSign) su = sign[u] != 0;
    if (stateU & kInterior) {
      for (int k = 0; k < K; ++k) {
        const uint32_t v = uint32_t(int64_t(u) + off[k]);
        f(v, weight(u, v, k, cu, su), uint8_t(K - 1 - k));
      }
    } else {
      const int64_t x = int64_t(u) % nx, y = (int64_t(u) / nx) % ny, z = int64_t(u) / (nx * ny);
      for (int k = 0; k < K; ++k) {
        const int64_t X = x + dx[k], Y = y + dy[k], Z = z + dz[k];
        if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
        const uint32_t v = uint32_t(int64_t(u) + off[k]);
        f(v, weight(u, v, k, cu, su), uint8_t(K - 1 - k));
      }
    }
  }

  double distMm(int64_t a, int64_t b) const {
    const auto ca = g->coords(a), cb = g->coords(b);
    const auto& s = g->spacing();
    const double x = double(ca[0] - cb[0]) * s[0], y = double(ca[1] - cb[1]) * s[1], z = double(ca[2] - cb[2]) * s[2];
    return std::sqrt(x * x + y * y + z * z);
  }
};

struct CsrModel {
  static constexpr bool kCsr = true;
  const CsrGraph* g = nullptr;
  explicit CsrModel(const CsrGraph& graph) : g(&graph) {}

  template <class F>
  void forEach(uint32_t u, uint8_t, F&& f) const {
    const int64_t* rs = g->rowStart().data();
    const uint32_t* tg = g->targets().data();
    const float* w = g->weights().data();
    for (int64_t e = rs[u], end = rs[u + 1]; e < end; ++e) f(tg[e], double(w[e]), kNoDirection);
  }
  double distMm(int64_t a, int64_t b) const {
    if (!g->hasPositions()) return 0;
    const auto& p = g->positions()[size_t(a)];
    const auto& q = g->positions()[size_t(b)];
    const double x = double(p[0]) - q[0], y = double(p[1]) - q[1], z = double(p[2]) - q[2];
    return std::sqrt(x * x + y * y + z * z);
  }
};

}  // namespace

struct ShortestPathSearch::Impl {
  virtual ~Impl() = default;
  std::vector<double> T;
  std::vector<uint8_t> state;
  std::vector<uint32_t> pred;  // CSR only
  int64_t n = 0;
  int64_t settled = 0;
  bool finished = false;
  SearchOptions opt;
  const GridGraph* grid = nullptr;
  const CsrGraph* csr = nullptr;
  int64_t astarTarget = -1;
  double astarPerMm = 0;

  virtual void reset(const std::vector<int64_t>& sources) = 0;
  // Settles until target (>= 0) is settled and final, or the next node costs more than maxCost,
  // or the queue is empty.
  virtual void settle(int64_t target, double maxCost, Progress& progress) = 0;

  bool isSettled(int64_t v) const { return (state[size_t(v)] & kSettled) != 0; }
  int64_t predecessor(int64_t v) const {
    if (csr) {
      const uint32_t p = pred[size_t(v)];
      return p == 0xffffffffu ? -1 : int64_t(p);
    }
    const int d = state[size_t(v)] & kDirMask;
    return d == kNoDirection ? -1 : v + grid->linearOffset(d);
  }
  double stepLength(int64_t u, int64_t v) const {
    if (csr) {
      if (!csr->hasPositions()) return 0;
      const auto& p = csr->positions()[size_t(u)];
      const auto& q = csr->positions()[size_t(v)];
      const double x = double(p[0]) - q[0], y = double(p[1]) - q[1], z = double(p[2]) - q[2];
      return std::sqrt(x * x + y * y + z * z);
    }
    const int d = state[size_t(v)] & kDirMask;  // v -> u direction
    return grid->length(d);
  }

  void checkNode(int64_t v, const char* what) const {
    if (v < 0 || v >= n)
      throw InvalidArgument(std::string(what) + " node " + std::to_string(v) + " is outside the graph (0.." +
                            std::to_string(n - 1) + ")" + (grid ? " of grid " + grid->describe() : std::string()));
  }

  Path path(int64_t t) const {
    Path p;
    if (!isSettled(t) || !(T[size_t(t)] < kInf)) return p;
    int64_t v = t;
    for (int64_t steps = 0;; ++steps) {
      if (steps > n) throw Error("shortest-path back pointers form a cycle (internal error)");
      p.nodes.push_back(v);
      const int64_t u = predecessor(v);
      if (u < 0) break;
      p.lengthMm += stepLength(u, v);
      v = u;
    }
    std::reverse(p.nodes.begin(), p.nodes.end());
    p.cost = T[size_t(t)];
    if (grid) {
      p.voxels.reserve(p.nodes.size());
      for (int64_t node : p.nodes) p.voxels.push_back(grid->coords(node));
    }
    return p;
  }
};

namespace {

template <class Model, class Queue>
struct Engine final : ShortestPathSearch::Impl {
  Model model;
  Queue queue;

  Engine(Model m, double scale) : model(std::move(m)), queue(scale) {}

  void reset(const std::vector<int64_t>& sources) override {
    if (sources.empty()) throw InvalidArgument("shortest-path search: no source given");
    for (int64_t s : sources) checkNode(s, "source");
    queue.clear();
    settled = 0;
    finished = false;
    T.assign(size_t(n), kInf);
    if constexpr (Model::kCsr) {
      state.assign(size_t(n), kNoDirection);
      pred.assign(size_t(n), 0xffffffffu);
    } else {
      state.resize(size_t(n));
      const auto& d = grid->dims();
      const bool twoD = grid->directionCount() == 4 || grid->directionCount() == 8;
      const int64_t nx = d[0], ny = d[1], nz = d[2];
      for (int64_t z = 0; z < nz; ++z)
        for (int64_t y = 0; y < ny; ++y) {
          uint8_t* row = state.data() + size_t(nx * (y + ny * z));
          const bool inner = y >= 1 && y <= ny - 2 && (twoD || (z >= 1 && z <= nz - 2)) && nx >= 3;
          if (inner) {
            std::fill(row, row + nx, uint8_t(kInterior | kNoDirection));
            row[0] = kNoDirection;
            row[nx - 1] = kNoDirection;
          } else {
            std::fill(row, row + nx, kNoDirection);
          }
        }
    }
    if (!opt.mask.empty()) {
      for (int64_t v = 0; v < n; ++v)
        if (opt.mask[size_t(v)] == 0) T[size_t(v)] = -kInf;
    }
    for (int64_t s : sources) {
      if (T[size_t(s)] == -kInf)
        throw InvalidArgument("source node " + std::to_string(s) +
                              (grid ? " " + voxelName(*grid, s) : std::string()) + " is outside the search mask");
      T[size_t(s)] = 0;
    }
    for (int64_t s : sources) queue.push(priority(uint32_t(s), 0.0), uint32_t(s));
  }

  double priority(uint32_t v, double t) const {
    if (astarTarget < 0) return t;
    return t + astarPerMm * model.distMm(v, astarTarget);
  }

  void settle(int64_t target, double maxCost, Progress& progress) override {
    double* Tp = T.data();
    uint8_t* S = state.data();
    uint32_t* P = pred.data();
    const int64_t chunk = std::max<int64_t>(1, opt.progressChunk);
    int64_t pops = 0;
    const bool astar = astarTarget >= 0;
    for (;;) {
      if (target >= 0 && (S[target] & kSettled) && !queue.sameKeyPending()) return;
      if (queue.empty()) {
        finished = true;
        return;
      }
      const uint32_t u = queue.pop();
      const uint8_t su = S[u];
      if (su & kSettled) continue;
      const double Tu = Tp[u];
      if (Tu > maxCost) {
        queue.push(priority(u, Tu), u);
        return;
      }
      S[u] = uint8_t(su | kSettled);
      ++settled;
      model.forEach(u, su, [&](uint32_t v, double w, uint8_t back) {
        const double nt = Tu + w;
        const double old = Tp[v];
        if (nt < old) {
          Tp[v] = nt;
          const uint8_t sv = S[v];
          const bool was = (sv & kSettled) != 0;
          settled -= was;
          S[v] = uint8_t((sv & kInterior) | back);
          if constexpr (Model::kCsr) P[v] = u;
          if (astar) {
            queue.push(priority(v, nt), v);
          } else if (was || queue.differentKey(old, nt)) {
            queue.push(nt, v);
          }
        }
      });
      if (++pops >= chunk) {
        pops = 0;
        progress.report(double(settled) / double(n), "search");
      }
    }
  }
};

template <class Queue, int K, CostKind CK>
std::unique_ptr<ShortestPathSearch::Impl> makeGrid3(const GridGraph& g, const GridCost& c, double scale) {
  return std::make_unique<Engine<GridModel<K, CK>, Queue>>(GridModel<K, CK>(g, c), scale);
}

template <class Queue, int K>
std::unique_ptr<ShortestPathSearch::Impl> makeGrid2(const GridGraph& g, const GridCost& c, double scale) {
  if (c.kind == GridCost::Kind::PerEdge) return makeGrid3<Queue, K, CostKind::Edge>(g, c, scale);
  if (!c.sign.empty() && c.signWeight != 0) return makeGrid3<Queue, K, CostKind::NodeSign>(g, c, scale);
  return makeGrid3<Queue, K, CostKind::Node>(g, c, scale);
}

template <class Queue>
std::unique_ptr<ShortestPathSearch::Impl> makeGrid(const GridGraph& g, const GridCost& c, double scale) {
  switch (g.directionCount()) {
    case 4: return makeGrid2<Queue, 4>(g, c, scale);
    case 8: return makeGrid2<Queue, 8>(g, c, scale);
    case 6: return makeGrid2<Queue, 6>(g, c, scale);
    case 18: return makeGrid2<Queue, 18>(g, c, scale);
    default: return makeGrid2<Queue, 26>(g, c, scale);
  }
}

struct CostStats {
  double maxEdge = 0;   // largest finite edge weight
  double minPerMm = 0;  // smallest weight per mm (A* bound)
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
      throw InvalidArgument("cost weights w_g = " + std::to_string(c.nodeWeight) + ", w_z = " +
                            std::to_string(c.signWeight) + " must be finite and >= 0");
    float mx = 0, mn = std::numeric_limits<float>::infinity();
    bool bad = false;
    for (int64_t v = 0; v < n; ++v) {
      const float x = c.node[size_t(v)];
      bad |= !(x >= 0);
      if (x > mx && x < std::numeric_limits<float>::infinity()) mx = x;
      mn = x < mn ? x : mn;
    }
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
  } else {
    if (int64_t(c.edge.size()) != n * K)
      throw InvalidArgument("per-edge cost array has " + std::to_string(c.edge.size()) + " values, grid " +
                            g.describe() + " needs N*K = " + std::to_string(n * K));
    double mx = 0, mnPerMm = kInf;
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
            mnPerMm = std::min(mnPerMm, double(w) / g.length(k));
          }
        }
    st.maxEdge = mx;
    st.minPerMm = std::isfinite(mnPerMm) ? mnPerMm : 0.0;
  }
  return st;
}

double keyScale(const SearchOptions& o, double maxEdge) {
  if (o.keyResolution > 0) return 1.0 / o.keyResolution;
  if (!(maxEdge > 0) || !std::isfinite(maxEdge)) return 1.0;
  return 65536.0 / maxEdge;
}

std::unique_ptr<ShortestPathSearch::Impl> makeGridImpl(const GridGraph& g, const GridCost& c, const SearchOptions& o,
                                                       double* minPerMm) {
  const CostStats st = validateGridCost(g, c);
  if (minPerMm) *minPerMm = st.minPerMm;
  const double scale = keyScale(o, st.maxEdge);
  auto impl = o.queue == QueueKind::BinaryHeap ? makeGrid<detail::HeapQueue>(g, c, scale)
                                               : makeGrid<detail::RadixQueue>(g, c, scale);
  impl->grid = &g;
  impl->n = g.nodeCount();
  impl->opt = o;
  return impl;
}

std::unique_ptr<ShortestPathSearch::Impl> makeCsrImpl(const CsrGraph& g, const SearchOptions& o) {
  const double scale = keyScale(o, g.maxFiniteWeight());
  std::unique_ptr<ShortestPathSearch::Impl> impl;
  if (o.queue == QueueKind::BinaryHeap)
    impl = std::make_unique<Engine<CsrModel, detail::HeapQueue>>(CsrModel(g), scale);
  else
    impl = std::make_unique<Engine<CsrModel, detail::RadixQueue>>(CsrModel(g), scale);
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
  if (impl_->T[size_t(target)] == -kInf) return false;  // masked out
  if (!impl_->isSettled(target)) impl_->settle(target, kInf, progress);
  return impl_->isSettled(target) && impl_->T[size_t(target)] < kInf;
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

void ShortestPathSearch::runToCompletion(Progress& progress) { impl_->settle(-1, kInf, progress); }

double ShortestPathSearch::costTo(int64_t target, Progress& progress) {
  return settleUntil(target, progress) ? impl_->T[size_t(target)] : kInf;
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
bool ShortestPathSearch::isSettled(int64_t node) const {
  impl_->checkNode(node, "node");
  return impl_->isSettled(node);
}
double ShortestPathSearch::totalCost(int64_t node) const {
  impl_->checkNode(node, "node");
  const double t = impl_->T[size_t(node)];
  return t == -kInf ? kInf : t;
}
int64_t ShortestPathSearch::predecessor(int64_t node) const {
  impl_->checkNode(node, "node");
  return impl_->predecessor(node);
}
uint8_t ShortestPathSearch::backDirection(int64_t node) const {
  impl_->checkNode(node, "node");
  return impl_->grid ? uint8_t(impl_->state[size_t(node)] & kDirMask) : kNoDirection;
}
std::span<const double> ShortestPathSearch::totalCosts() const { return impl_->T; }
std::span<const uint8_t> ShortestPathSearch::nodeState() const { return impl_->state; }
std::span<const uint32_t> ShortestPathSearch::predecessors() const { return impl_->pred; }

namespace {
Path runAStar(std::unique_ptr<ShortestPathSearch::Impl> impl, int64_t source, int64_t target, bool useAStar,
              double perMm, Progress& progress) {
  impl->checkNode(source, "source");
  impl->checkNode(target, "target");
  if (useAStar && perMm > 0) {
    impl->astarTarget = target;
    impl->astarPerMm = perMm * (1.0 - 1e-9);  // keep the bound admissible under rounding
  }
  impl->reset({source});
  if (impl->T[size_t(target)] == -kInf) return {};
  impl->settle(target, kInf, progress);
  return impl->path(target);
}
}  // namespace

Path findPath(const GridGraph& graph, const GridCost& cost, int64_t source, int64_t target, bool useAStar,
              const SearchOptions& options, Progress& progress) {
  checkMask(options, graph.nodeCount());
  double perMm = 0;
  auto impl = makeGridImpl(graph, cost, options, &perMm);
  return runAStar(std::move(impl), source, target, useAStar, perMm, progress);
}

Path findPath(const CsrGraph& graph, int64_t source, int64_t target, bool useAStar, const SearchOptions& options,
              Progress& progress) {
  checkMask(options, graph.nodeCount());
  auto impl = makeCsrImpl(graph, options);
  return runAStar(std::move(impl), source, target, useAStar, graph.minWeightPerMm(), progress);
}

}  // namespace vs
