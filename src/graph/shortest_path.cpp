// The shortest-path engine: one Dijkstra loop (Engine) templated over a graph/cost model and a
// priority queue, explicitly instantiated below for every grid connectivity and cost model and
// for CSR graphs. See shortest_path.h for the contract.
#include "graph/shortest_path.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <type_traits>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <string>

#include <sys/mman.h>

#include "graph/priority_queues.h"
#include "util/error.h"
#include "util/parallel.h"

namespace vs {

namespace {

constexpr uint8_t kInterior = 0x20;
constexpr uint8_t kSettled = ShortestPathSearch::kSettledBit;
constexpr uint8_t kDirMask = ShortestPathSearch::kDirectionMask;
constexpr double kInf = std::numeric_limits<double>::infinity();
// Bucket queue: prefetch the neighbourhood of the node popped this many pops ahead.
#ifndef VS_PREFETCH_AHEAD
#define VS_PREFETCH_AHEAD 3
#endif
constexpr size_t kPrefetchAhead = VS_PREFETCH_AHEAD;

// Lowers a node's total to nt (the caller checked nt < tv), keeps its interior flag and records
// the back direction; returns whether the node was settled (it is not any more: label-correcting).
template <class State>
inline bool lowerTotal(double& tv, State& sv, double nt, uint8_t back) {
  tv = nt;
  const bool was = (sv & kSettled) != 0;
  sv = uint8_t((sv & kInterior) | back);
  return was;
}

// Queues v at its lowered total nt (bucket queue), unless it already waits in the bucket of that
// key (its old, finite total had the same key); a node that was settled is always queued again.
template <class Queue>
[[gnu::always_inline]] inline void requeue(Queue& q, uint32_t v, double old, double nt, bool wasSettled) {
  const uint64_t nk = q.keyOf(nt);  // one key computation for the test and the push
  if (wasSettled || !(old < 1e300) || q.keyOf(old) != nk) q.pushKey(nk, v);
}

// Spin-wait hint (the two-thread search waits for the other thread in short spins).
inline void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

std::string voxelName(const GridGraph& g, int64_t n) {
  const auto c = g.coords(n);
  return "(" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," + std::to_string(c[2]) + ")";
}

enum class CostKind { Node, NodeSign, Edge };

// The state byte of a grid node record (bits 0-4 back direction, 5 interior, 6 settled). Not a
// plain uint8_t: a store through an unsigned char lvalue may alias any object, so the compiler
// reloaded the queue's and the model's fields after every state store in the hot loops (the
// two-thread loop ran ~1.5x slower per node for that alone). An enum has its own alias set.
enum class StateByte : uint8_t {};
struct StateCell {
  StateByte b;
  operator uint8_t() const { return uint8_t(b); }
  StateCell& operator=(uint8_t v) {
    b = StateByte(v);
    return *this;
  }
  StateCell& operator&=(uint8_t v) { return *this = uint8_t(uint8_t(b) & v); }
  StateCell& operator|=(uint8_t v) { return *this = uint8_t(uint8_t(b) | v); }
};
static_assert(sizeof(StateCell) == 1);

// Per-node record of grid searches: T, the node's cost, state and sign share one 16-byte
// record, so relaxing a neighbour touches one cache line instead of three arrays.
struct NodeRec {
  double t;
  float c;
  StateCell s;
  uint8_t sign;
  uint16_t pad;
};
static_assert(sizeof(NodeRec) == 16);

// Record storage: anonymous mmap with transparent huge pages requested (madvise), because the
// 3x3x3 neighbourhood of a node spans 9 rows nx*16 B apart (and slices nx*ny*16 B apart): with
// 4 KiB pages every relaxation would touch up to 9 pages and miss the TLB on large volumes.
// Falls back to operator new where mmap fails. Not initialised (chunks are filled lazily, GridModel::ensure).
struct RecordStore {
  NodeRec* p = nullptr;
  size_t bytes = 0;
  bool mapped = false;
  RecordStore() = default;
  RecordStore(const RecordStore&) = delete;
  RecordStore& operator=(const RecordStore&) = delete;
  ~RecordStore() { release(); }
  void release() {
    if (mapped) munmap(p, bytes);
    else delete[] p;
    p = nullptr;
    mapped = false;
  }
  void allocate(size_t n) {
    release();
    bytes = n * sizeof(NodeRec);
    if (bytes >= (size_t(4) << 20)) {
      void* m = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (m != MAP_FAILED) {
#ifdef MADV_HUGEPAGE
        madvise(m, bytes, MADV_HUGEPAGE);
#endif
        p = static_cast<NodeRec*>(m);
        mapped = true;
        return;
      }
    }
    p = new NodeRec[n];
  }
  NodeRec* get() const { return p; }
  explicit operator bool() const { return p != nullptr; }
};

// Implicit grid with K neighbour directions and one of the three cost models.
template <int K, CostKind CK>
struct GridModel {
  static constexpr bool kCsr = false;
  const GridGraph* g = nullptr;
  const float* c = nullptr;  // the caller's arrays, copied into the records at reset
  const uint8_t* sign = nullptr;
  const float* edge = nullptr;
  NodeRec* R = nullptr;  // the engine's records
  std::array<int64_t, K> off{};
  std::array<int64_t, K> offB{};  // off * sizeof(NodeRec)
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
      offB[k] = off[k] * int64_t(sizeof(NodeRec));
      halfLen[k] = graph.length(k) * 0.5 * double(cost.nodeWeight);
      lenZ[k] = graph.length(k) * double(cost.signWeight);
      dx[k] = graph.offset(k)[0];
      dy[k] = graph.offset(k)[1];
      dz[k] = graph.offset(k)[2];
      reach = std::max<uint32_t>(reach, uint32_t(std::abs(graph.linearOffset(k))));
    }
    shift = chunkShift(graph);
    n = nx * ny * nz;
  }

  double& T(uint32_t v) const { return R[v].t; }
  StateCell& S(uint32_t v) const { return R[v].s; }

  // Lazy record initialisation: the records are split into chunks of 2^shift consecutive node
  // ids, 2^shift >= reach (the largest |linear offset| of a neighbour), so the neighbourhood of a
  // node lies in at most three chunks. A chunk is filled (T = +inf, -inf masked; state = no
  // direction + interior flag; cost; sign) the first time a settled node's neighbourhood reaches
  // it (ensure()), so early-exit and point-to-point queries pay for the region they explore,
  // not O(N) (the untouched part of the record array is never even faulted in).
  std::span<const uint8_t> mask;
  uint8_t* ready = nullptr;  // one byte per chunk
  int shift = 12;
  int64_t n = 0;
  uint32_t reach = 0;

  void setup(NodeRec* recs, std::span<const uint8_t> m, uint8_t* readyFlags) {
    R = recs;
    mask = m;
    ready = readyFlags;
  }
  static int chunkShift(const GridGraph& g) {
    int64_t reach = 0;
    for (int k = 0; k < g.directionCount(); ++k) reach = std::max(reach, std::abs(g.linearOffset(k)));
    int sh = 14;
    while ((int64_t(1) << sh) < reach) ++sh;
    return sh;
  }
  int64_t chunkCount() const { return (n + (int64_t(1) << shift) - 1) >> shift; }
  // Where the two-thread full map splits the node ids: the first node of the middle slice (row
  // in 2-D), or 0 when the grid is too thin for the split band (one neighbour reach each side).
  int64_t splitId() const {
    const int64_t layers = (K == 4 || K == 8) ? ny : nz;
    if (layers < 8 || nx < 3 || ny < 3) return 0;
    return (layers / 2) * layerSize();
  }
  // Nodes per slice (row in 2-D): the neighbours across the split lie in the adjacent one.
  int64_t layerSize() const { return (K == 4 || K == 8) ? nx : nx * ny; }
  bool isReady(uint32_t v) const { return ready[v >> shift] != 0; }

  bool interiorAt(int64_t x, int64_t y, int64_t z) const {
    const bool twoD = K == 4 || K == 8;
    return nx >= 3 && x >= 1 && x <= nx - 2 && y >= 1 && y <= ny - 2 && (twoD || (z >= 1 && z <= nz - 2));
  }
  // The record a node has before its chunk is filled (for reads of untouched nodes).
  double defaultT(int64_t v) const { return (mask.empty() || mask[size_t(v)] != 0) ? kInf : -kInf; }
  uint8_t defaultS(int64_t v) const {
    return uint8_t((interiorAt(v % nx, (v / nx) % ny, v / (nx * ny)) ? kInterior : 0) | kNoDirection);
  }

  void fillChunk(int64_t ch) const {
    const int64_t b = ch << shift, e = std::min(n, (ch + 1) << shift);
    int64_t x0 = b % nx, r = b / nx;
    for (int64_t v0 = b; v0 < e; x0 = 0, ++r) {  // one row segment [v0, v1) per pass
      const int64_t v1 = std::min(e, v0 + (nx - x0));
      const int64_t y = r % ny, z = r / ny;
      const bool innerRow = nx >= 3 && y >= 1 && y <= ny - 2 && ((K == 4 || K == 8) || (z >= 1 && z <= nz - 2));
      const uint8_t sRow = uint8_t((innerRow ? kInterior : 0) | kNoDirection);
      // Plain stores first (vectorisable), then the row ends, the mask and the signs.
      for (int64_t v = v0; v < v1; ++v) {
        NodeRec& rc = R[v];
        rc.t = kInf;
        if constexpr (CK == CostKind::Edge) rc.c = 0.f;
        else rc.c = c[v];
        rc.s = sRow;
        rc.sign = 0;
        rc.pad = 0;
      }
      if (x0 == 0) R[v0].s = kNoDirection;
      if (x0 + (v1 - v0) == nx) R[v1 - 1].s = kNoDirection;
      if (!mask.empty())
        for (int64_t v = v0; v < v1; ++v)
          if (mask[size_t(v)] == 0) R[v].t = -kInf;
      if constexpr (CK == CostKind::NodeSign)
        for (int64_t v = v0; v < v1; ++v) R[v].sign = uint8_t(sign[v] != 0);
      v0 = v1;
    }
    ready[ch] = 1;
  }

  // Makes sure the records of u and all its neighbours are filled. O(1) when they are.
  void ensure(uint32_t u) const {
    const int64_t lo = (int64_t(u) - reach) < 0 ? 0 : (int64_t(u) - reach) >> shift;
    const int64_t hi = std::min<int64_t>(n - 1, int64_t(u) + reach) >> shift;
    for (int64_t ch = lo; ch <= hi; ++ch)
      if (!ready[ch]) fillChunk(ch);
  }
  // Fills every chunk not filled yet (materialize()); parallel for large grids.
  void fillAll() const {
    const int64_t nc = chunkCount();
    parallelFor(
        0, nc,
        [&](int64_t c0, int64_t c1) {
          for (int64_t ch = c0; ch < c1; ++ch)
            if (!ready[ch]) fillChunk(ch);
        },
        std::max<int64_t>(1, (int64_t(1) << 20) >> shift));
  }

  double weight(uint32_t u, const NodeRec& rv, int k, double cu, uint8_t su) const {
    if constexpr (CK == CostKind::Node) {
      (void)u;
      (void)su;
      return halfLen[k] * (cu + double(rv.c));
    } else if constexpr (CK == CostKind::NodeSign) {
      (void)u;
      return halfLen[k] * (cu + double(rv.c)) + (rv.sign == su ? lenZ[k] : 0.0);
    } else {
      (void)rv;
      (void)cu;
      (void)su;
      return double(edge[size_t(u) * K + k]);
    }
  }

  // Prefetches the records of u's neighbourhood (the rows of 3 around it).
  void prefetch(uint32_t u) const {
    if constexpr (K == 4 || K == 8) {
      for (int dy = -1; dy <= 1; ++dy) {
        const NodeRec* p = R + (int64_t(u) + dy * nx);
        __builtin_prefetch(p - 1, 1);
        __builtin_prefetch(p + 1, 1);
      }
    } else {
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
          const NodeRec* p = R + (int64_t(u) + dy * nx + dz * nx * ny);
          __builtin_prefetch(p - 1, 1);
          __builtin_prefetch(p + 1, 1);
        }
    }
  }

  // Calls f(v, T(v), S(v), w, backDirection) for the in-grid neighbours v of u that f may
  // improve: on interior nodes only those with Tu + w < T(v) (f re-tests, the same value), on
  // boundary nodes all of them. The interior path addresses the neighbour records by byte
  // offsets from u's record, so the node id v (only needed when v improves) is not on the
  // common path.
  template <class F>
  void forEach(uint32_t u, uint8_t stateU, double Tu, F&& f) const {
    NodeRec* const pu = R + u;
    const double cu = double(pu->c);
    const uint8_t su = pu->sign;
    if (stateU & kInterior) {
      // Branch-light: all K candidate totals are compared first (no branch depends on the
      // neighbours' loads, so they all issue at once), then only the improving neighbours
      // (bits of a mask) take f's path, with the very same weights (results are identical).
      char* const bu = reinterpret_cast<char*>(pu);
      double w[K];
      uint32_t better = 0;
#pragma GCC unroll 26
      for (int k = 0; k < K; ++k) {
        const NodeRec& rv = *reinterpret_cast<const NodeRec*>(bu + offB[k]);
        w[k] = weight(u, rv, k, cu, su);
        better |= uint32_t(Tu + w[k] < rv.t) << k;
      }
      while (better) {
        const int k = __builtin_ctz(better);
        better &= better - 1;
        NodeRec& rv = *reinterpret_cast<NodeRec*>(bu + offB[k]);
        f(uint32_t(int64_t(u) + off[k]), rv.t, rv.s, w[k], uint8_t(K - 1 - k));
      }
      return;
    }
    {  // boundary node: bounds-checked
      const int64_t x = int64_t(u) % nx, y = (int64_t(u) / nx) % ny, z = int64_t(u) / (nx * ny);
      for (int k = 0; k < K; ++k) {
        const int64_t X = x + dx[k], Y = y + dy[k], Z = z + dz[k];
        if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
        const uint32_t v = uint32_t(int64_t(u) + off[k]);
        NodeRec& rv = R[v];
        f(v, rv.t, rv.s, weight(u, rv, k, cu, su), uint8_t(K - 1 - k));
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
  double* Tp = nullptr;
  uint8_t* Sp = nullptr;
  explicit CsrModel(const CsrGraph& graph) : g(&graph) {}

  double& T(uint32_t v) const { return Tp[v]; }
  uint8_t& S(uint32_t v) const { return Sp[v]; }
  void prefetch(uint32_t) const {}
  void ensure(uint32_t) const {}
  bool isReady(uint32_t) const { return true; }

  template <class F>
  void forEach(uint32_t u, uint8_t, double, F&& f) const {
    const int64_t* rs = g->rowStart().data();
    const uint32_t* tg = g->targets().data();
    const float* w = g->weights().data();
    for (int64_t e = rs[u], end = rs[u + 1]; e < end; ++e) {
      const uint32_t v = tg[e];
      f(v, Tp[v], Sp[v], double(w[e]), kNoDirection);
    }
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
  // CSR: the canonical T / state / predecessor arrays. Grid: T and state live in packed records
  // and are copied here on demand by materialize() (totalCosts(), nodeState()).
  mutable std::vector<double> T;
  mutable std::vector<uint8_t> state;
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
  // Settles every reachable node (runToCompletion): the two-thread domain search on large grids
  // when options allow it (same totals), else settle(-1, +inf).
  virtual void settleAll(Progress& progress) { settle(-1, std::numeric_limits<double>::infinity(), progress); }
  virtual double tAt(int64_t v) const = 0;
  virtual uint8_t sAt(int64_t v) const = 0;
  virtual void materialize() const = 0;

  bool isSettled(int64_t v) const { return (sAt(v) & kSettled) != 0; }
  int64_t predecessor(int64_t v) const {
    if (csr) {
      const uint32_t p = pred[size_t(v)];
      return p == 0xffffffffu ? -1 : int64_t(p);
    }
    const int d = sAt(v) & kDirMask;
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
    const int d = sAt(v) & kDirMask;  // v -> u direction
    return grid->length(d);
  }

  void checkNode(int64_t v, const char* what) const {
    if (v < 0 || v >= n)
      throw InvalidArgument(std::string(what) + " node " + std::to_string(v) + " is outside the graph (0.." +
                            std::to_string(n - 1) + ")" + (grid ? " of grid " + grid->describe() : std::string()));
  }

  Path path(int64_t t) const {
    Path p;
    if (!isSettled(t) || !(tAt(t) < kInf)) return p;
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
    p.cost = tAt(t);
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
  RecordStore rec;  // grid only; filled lazily chunk by chunk (GridModel::ensure)
  std::vector<uint8_t> chunkReady;  // grid only
  mutable bool flatValid = false;

  double qScale = 1, qStep = 0;  // the queue's parameters (the parallel search makes two more)

  Engine(Model m, double scale, double maxStep)
      : model(std::move(m)), queue(scale, maxStep), qScale(scale), qStep(maxStep) {}

  double tAt(int64_t v) const override {
    if constexpr (!Model::kCsr)
      if (!model.isReady(uint32_t(v))) return model.defaultT(v);
    return model.T(uint32_t(v));
  }
  uint8_t sAt(int64_t v) const override {
    if constexpr (!Model::kCsr)
      if (!model.isReady(uint32_t(v))) return model.defaultS(v);
    return model.S(uint32_t(v));
  }
  void materialize() const override {
    if constexpr (!Model::kCsr) {
      if (flatValid) return;
      model.fillAll();
      T.resize(size_t(n));
      state.resize(size_t(n));
      for (int64_t v = 0; v < n; ++v) {
        T[size_t(v)] = rec.p[size_t(v)].t;
        state[size_t(v)] = rec.p[size_t(v)].s;
      }
      flatValid = true;
    }
  }

  void reset(const std::vector<int64_t>& sources) override {
    if (sources.empty()) throw InvalidArgument("shortest-path search: no source given");
    for (int64_t s : sources) checkNode(s, "source");
    queue.clear();
    settled = 0;
    finished = false;
    flatValid = false;
    if constexpr (Model::kCsr) {
      T.assign(size_t(n), kInf);
      state.assign(size_t(n), kNoDirection);
      pred.assign(size_t(n), 0xffffffffu);
      model.Tp = T.data();
      model.Sp = state.data();
      if (!opt.mask.empty())
        for (int64_t v = 0; v < n; ++v)
          if (opt.mask[size_t(v)] == 0) T[size_t(v)] = -kInf;
    } else {
      T.clear();
      T.shrink_to_fit();
      state.clear();
      state.shrink_to_fit();
      if (!rec) rec.allocate(size_t(n));
      chunkReady.assign(size_t(model.chunkCount()), 0);
      model.setup(rec.get(), opt.mask, chunkReady.data());
    }
    for (int64_t s : sources) model.ensure(uint32_t(s));
    for (int64_t s : sources) {
      if (model.T(uint32_t(s)) == -kInf)
        throw InvalidArgument("source node " + std::to_string(s) +
                              (grid ? " " + voxelName(*grid, s) : std::string()) + " is outside the search mask");
      model.T(uint32_t(s)) = 0;
    }
    for (int64_t s : sources) queue.push(priority(uint32_t(s), 0.0), uint32_t(s));
  }

  double priority(uint32_t v, double t) const {
    if (astarTarget < 0) return t;
    return t + astarPerMm * model.distMm(v, astarTarget);
  }

  void settle(int64_t target, double maxCost, Progress& progress) override {
    flatValid = false;
    // Plain local copies: the uint8_t state stores may alias anything, so nothing the hot loop
    // reads should live behind a pointer or a member.
    uint32_t* const P = pred.data();
    const int64_t chunk = std::max<int64_t>(1, opt.progressChunk);
    const bool astar = astarTarget >= 0;
    const Model m = model;
    Queue& q = queue;
    int64_t pops = 0;
    int64_t nSettled = settled;
    std::vector<uint32_t> deferred;
    struct Flush {  // keeps the settled count right on every exit, Cancelled included
      int64_t& dst;
      const int64_t& src;
      ~Flush() { dst = src; }
    } flush{settled, nSettled};
    for (;;) {
      if (!deferred.empty() && !q.sameKeyPending()) {
        // Nodes sharing a radix key are popped in no particular order, so a node found above
        // maxCost is set aside until its key's bucket is finished (it may still improve); then
        // the set-aside nodes go back to the queue, and the search stops unless one improved.
        bool again = false;
        for (uint32_t d : deferred) {
          q.push(priority(d, m.T(d)), d);
          again |= m.T(d) <= maxCost;
        }
        deferred.clear();
        if (!again) return;
      }
      if (target >= 0 && m.isReady(uint32_t(target)) && (m.S(uint32_t(target)) & kSettled) && !q.sameKeyPending())
        return;
      if (q.empty()) {
        finished = true;
        return;
      }
      const uint32_t u = q.pop();
      const uint8_t su = m.S(u);
      if (su & kSettled) continue;
      const double Tu = m.T(u);
      if (Tu > maxCost) {
        deferred.push_back(u);
        continue;
      }
      m.S(u) = uint8_t(su | kSettled);
      ++nSettled;
      m.ensure(u);
      if constexpr (requires { q.peekAhead(size_t(0)); }) {
        if (const uint32_t next = q.peekAhead(kPrefetchAhead); next != UINT32_MAX) m.prefetch(next);
      } else if (const uint32_t next = q.peek(); next != UINT32_MAX) {
        m.prefetch(next);
      }
      m.forEach(u, su, Tu, [P, u, Tu, astar, &q, &nSettled, this](uint32_t v, double& tv, auto& sv, double w,
                                                               uint8_t back) {
        const double nt = Tu + w;
        const double old = tv;
        if (nt < old) {
          const bool was = lowerTotal(tv, sv, nt, back);
          nSettled -= was;
          if constexpr (Model::kCsr) P[v] = u;
          else (void)P;
          if (astar) {
            q.push(priority(v, nt), v);
          } else if constexpr (requires { q.pushKey(uint64_t(0), v); }) {
            requeue(q, v, old, nt, was);
          } else if (was || q.differentKey(old, nt)) {
            q.push(nt, v);
          }
        }
      });
      if (++pops >= chunk && deferred.empty()) {  // (a cancel must not lose deferred nodes)
        pops = 0;
        settled = nSettled;
        progress.report(double(nSettled) / double(n), "search");
      }
    }
  }

  // ---- two-thread full map (runToCompletion on large grids) ----
  //
  // The node ids are split at a slice (row in 2-D) boundary into two domains, one thread each,
  // each with its own bucket queue and exclusive write access to its domain's records. A
  // relaxation that crosses the split is not applied by the sender: it becomes a message
  // (node, total, back direction) to the owner, which applies it if it improves the node. The
  // threads stay within half a bucket window of each other in key space (a bounded wait), not in
  // lockstep key by key, so a message may arrive after its node was settled: the owner then
  // un-settles and re-queues it (label-correcting, as the engine already
  // does inside a key), and terminates only when both threads are idle and no message is in
  // flight. Every total is still the minimum over the final totals of its neighbours plus the
  // same float64 edge weight, so the totals are the sequential search's bit for bit; only the
  // choice between two predecessors giving exactly equal totals may differ (equal-cost paths).
  // Nodes within one neighbour reach of the split take the bounds-checked relaxation (their
  // interior flag is cleared for the run), so no thread ever reads a record the other writes.
  struct Msg {
    uint32_t v;
    uint8_t back;
    double t;
  };
  struct alignas(64) Mailbox {
    std::mutex mu;
    std::vector<Msg> box;
    std::atomic<bool> nonEmpty{false};
  };
  struct alignas(64) PaddedFlag {
    std::atomic<bool> idle{false};
  };
  struct alignas(64) PaddedCount {
    std::atomic<int64_t> value{0};
  };
  struct alignas(64) PaddedKey {
    std::atomic<uint64_t> key{0};
  };
  struct ParallelShared {
    Mailbox mail[2];  // mail[d]: messages for domain d
    PaddedKey at[2];  // the key each domain is working on
    alignas(64) std::atomic<int64_t> pending{0};  // messages posted and not yet applied
    PaddedFlag idle[2];
    PaddedCount settledDelta[2];
    alignas(64) std::atomic<bool> stop{false};
  };

  // Grid searches with the bucket queue (the default) can run the two-thread full map.
  static constexpr bool kParallelCapable = !Model::kCsr && std::is_same_v<Queue, detail::BucketQueue>;

  bool parallelPossible() const {
    if constexpr (!kParallelCapable) {
      return false;
    } else {
      if (astarTarget >= 0 || opt.threads == 1 || n < opt.parallelMinNodes) return false;
      if (opt.threads == 0 && workerCount() < 2) return false;
      return model.splitId() > 0;
    }
  }

  void settleAll(Progress& progress) override {
    if (parallelPossible()) settleAllParallel(progress);
    else settle(-1, kInf, progress);
  }

  // Applies one improvement offer to a node of the calling thread's domain.
  static void offer(const Model& m, Queue& q, uint32_t v, double nt, uint8_t back, int64_t& settledDelta) {
    double& tv = m.T(v);
    if (!(nt < tv)) return;
    settledDelta -= lowerTotal(tv, m.S(v), nt, back);
    q.push(nt, v);  // keys below the queue's current one are clamped to it
  }

  void settleAllParallel(Progress& progress) {
    if constexpr (kParallelCapable) {
      flatValid = false;
      model.fillAll();  // no lazy fill while two threads run
      const Model m = model;
      const uint32_t split = uint32_t(m.splitId());
      const uint32_t band = m.reach;
      // Nodes within one reach of the split relax through the checked path for this run.
      for (int64_t v = int64_t(split) - band; v < int64_t(split) + band; ++v)
        if (v >= 0 && v < n) m.S(uint32_t(v)) &= uint8_t(~kInterior);

      // The frontier so far (the sources, or a resumed search's queue), split by domain; both
      // queues' windows start at its smallest total.
      std::vector<uint32_t> frontier;
      double minT = kInf;
      while (!queue.empty()) {
        const uint32_t u = queue.pop();
        if (m.S(u) & kSettled) continue;
        frontier.push_back(u);
        minT = std::min(minT, m.T(u));
      }
      // Each queue on cache lines of its own: a push or pop writes the queue's size and key, and
      // two queues side by side on the stack made every one of them a cache-line transfer
      // between the cores (false sharing; it made each thread ~3x slower per node).
      struct alignas(128) OwnLines {
        Queue q;
      };
      OwnLines ql0{Queue(qScale, qStep)}, ql1{Queue(qScale, qStep)};
      Queue& q0 = ql0.q;
      Queue& q1 = ql1.q;
      if (!frontier.empty()) {
        q0.rebase(q0.keyOf(minT));
        q1.rebase(q1.keyOf(minT));
      }
      for (uint32_t u : frontier) (u < split ? q0 : q1).push(m.T(u), u);
      ParallelShared sh;
      sh.at[0].key.store(q0.lastKey());
      sh.at[1].key.store(q1.lastKey());
      std::exception_ptr error;
      std::thread other([&] {
        try {
          domainWorker(1, m, q1, split, sh, nullptr);
        } catch (...) {
          error = std::current_exception();
          sh.stop.store(true);
        }
      });
      std::exception_ptr mainError;
      try {
        domainWorker(0, m, q0, split, sh, &progress);
      } catch (...) {
        mainError = std::current_exception();
        sh.stop.store(true);
      }
      other.join();

      // After a cancel or an error work is left: undelivered messages are applied, both queues
      // merged into the one queue, and the nodes that a pending node could still improve (T
      // above the smallest pending total) are un-settled and queued again, so that "settled"
      // means final again and the search can be resumed by either loop. (After a completed run
      // nothing is pending and this changes nothing.)
      int64_t delta = sh.settledDelta[0].value.load() + sh.settledDelta[1].value.load();
      for (int d = 0; d < 2; ++d) {
        for (const Msg& msg : sh.mail[d].box) offer(m, q0, msg.v, msg.t, msg.back, delta);
        sh.mail[d].box.clear();
      }
      std::vector<uint32_t> pending;
      double minPending = kInf;
      for (Queue* qq : {&q0, &q1})
        while (!qq->empty()) {
          const uint32_t u = qq->pop();
          if (m.S(u) & kSettled) continue;
          pending.push_back(u);
          minPending = std::min(minPending, m.T(u));
        }
      if (!pending.empty())
        for (int64_t v = 0; v < n; ++v) {
          auto& sv = m.S(uint32_t(v));
          if ((sv & kSettled) && m.T(uint32_t(v)) > minPending) {
            sv &= uint8_t(~kSettled);
            --delta;
            pending.push_back(uint32_t(v));
          }
        }
      Queue merged(qScale, qStep);
      if (!pending.empty()) merged.rebase(merged.keyOf(minPending));
      for (uint32_t u : pending) merged.push(m.T(u), u);
      queue = std::move(merged);
      settled += delta;
      for (int64_t v = int64_t(split) - band; v < int64_t(split) + band; ++v)
        if (v >= 0 && v < n && m.interiorAt(v % m.nx, (v / m.nx) % m.ny, v / (m.nx * m.ny))) m.S(uint32_t(v)) |= kInterior;
      if (mainError) std::rethrow_exception(mainError);
      if (error) std::rethrow_exception(error);
      finished = queue.empty();
    }
  }

  // One domain's loop. progress != nullptr on the calling thread only (reports and cancels).
  void domainWorker(int d, const Model& mref, Queue& q, uint32_t split, ParallelShared& sh, Progress* progress) {
    // A local copy, like settle()'s: the hot loop's stores (totals) could alias the fields of a
    // model behind a reference, which the compiler would then reload after each of them.
    const Model m = mref;
    const bool mine0 = d == 0;
    auto own = [split, mine0](uint32_t v) { return (v < split) == mine0; };
    std::vector<Msg> out, in;
    out.reserve(1024);
    // The best total this domain has offered to each node of the other side's layer next to the
    // split: a node there hears from up to 9 band nodes, and only a better offer can change it
    // (this cut the messages ~4x).
    const int64_t layer = m.layerSize();
    const int64_t foreignStart = mine0 ? int64_t(split) : int64_t(split) - layer;
    std::vector<double> offered(size_t(layer), kInf);
    int64_t delta = 0;  // settled count change of this domain
    auto flush = [&] {
      if (out.empty()) return;
      Mailbox& mb = sh.mail[1 - d];
      sh.pending.fetch_add(int64_t(out.size()));
      {
        std::lock_guard<std::mutex> lock(mb.mu);
        mb.box.insert(mb.box.end(), out.begin(), out.end());
        mb.nonEmpty.store(true, std::memory_order_release);
      }
      out.clear();
    };
    auto drain = [&] {  // returns true if messages were applied
      Mailbox& mb = sh.mail[d];
      if (!mb.nonEmpty.load(std::memory_order_acquire)) return false;
      {
        std::lock_guard<std::mutex> lock(mb.mu);
        in.swap(mb.box);
        mb.nonEmpty.store(false, std::memory_order_relaxed);
      }
      if (in.empty()) return false;
      sh.idle[d].idle.store(false);  // before `pending` drops: see the termination test below
      if (q.empty()) {  // restart the empty queue's window at the earliest offered key
        double lo = kInf;
        for (const Msg& msg : in) lo = std::min(lo, msg.t);
        q.rebase(q.keyOf(lo));
      }
      for (const Msg& msg : in) offer(m, q, msg.v, msg.t, msg.back, delta);
      sh.at[d].key.store(q.lastKey(), std::memory_order_relaxed);
      sh.pending.fetch_sub(int64_t(in.size()));
      in.clear();
      return true;
    };
    const int64_t chunk = std::max<int64_t>(1, opt.progressChunk);
    // Keys: one edge spans at most half the window. On the peers' vessels_128 a lead of 1/4-1/2
    // window re-settled < 1 % of the nodes (1/2 waited least), 3/4 or more 1.5x (offers then land
    // beyond the receiver's window and come out early).
    const uint64_t lead = q.window() / 2;
    // Messages, the mailbox and the keys are exchanged every 1024 pops: a cache line passed
    // between the cores costs ~200 ns on this VM, and exchanging every 64 pops gave no fewer
    // re-settles (vessels_128: 1.055M settles per domain either way).
    constexpr uint32_t kExchangeMask = 1023;
    int64_t pops = 0;
    uint32_t tick = 0;
    try {
    for (;;) {
      if ((++tick & kExchangeMask) == 0) {
        flush();
        drain();
        if (sh.stop.load(std::memory_order_relaxed)) break;
        // Keep the two domains within `lead` keys of each other: a domain far ahead would settle
        // nodes that the other's late offers then improve, and re-settle them in cascades. The
        // wait is bounded (~0.1 ms): when the other thread is descheduled (a loaded machine),
        // going on and re-settling a little beats spinning while it sleeps.
        sh.at[d].key.store(q.lastKey(), std::memory_order_relaxed);
        for (uint32_t spin = 0; spin < 4096 && !q.empty() &&
                                q.lastKey() > sh.at[1 - d].key.load(std::memory_order_relaxed) + lead &&
                                !sh.idle[1 - d].idle.load() && !sh.stop.load(std::memory_order_relaxed);
             ++spin) {
          if ((spin & 15) == 0) drain();
          cpuRelax();
        }
      }
      if (q.empty()) {
        flush();
        if (drain()) continue;
        // Idle. Terminated when the other domain is idle too and no message is in flight: the
        // other sets its flag only after posting all it sent, and clears it before a message
        // it takes stops counting as pending, so "other idle, then nothing pending" means that
        // nobody can send anything any more.
        sh.idle[d].idle.store(true);
        bool done = false;
        for (uint32_t spin = 0;; ++spin) {
          if (sh.stop.load()) {
            done = true;
            break;
          }
          if (sh.mail[d].nonEmpty.load(std::memory_order_acquire) && drain()) break;
          if (sh.idle[1 - d].idle.load() && sh.pending.load() == 0) {
            done = true;
            break;
          }
          if (spin > 64) std::this_thread::yield();
          else cpuRelax();
        }
        if (done) break;
        continue;
      }
      const uint32_t u = q.pop();
      const uint8_t su = m.S(u);
      if (su & kSettled) continue;
      const double Tu = m.T(u);
      m.S(u) = uint8_t(su | kSettled);
      ++delta;
      if (const uint32_t next = q.peekAhead(kPrefetchAhead); next != UINT32_MAX) m.prefetch(next);
      m.forEach(u, su, Tu, [&](uint32_t v, double& tv, auto& sv, double w, uint8_t back) {
        const double nt = Tu + w;
        if (!own(v)) {  // the other domain's record: never read here, offered by message
          double& best = offered[size_t(int64_t(v) - foreignStart)];
          if (!(nt < best)) return;
          best = nt;
          out.push_back({v, back, nt});
          if (out.size() >= 1024) flush();
          return;
        }
        const double old = tv;
        if (nt < old) {
          const bool was = lowerTotal(tv, sv, nt, back);
          delta -= was;
          requeue(q, v, old, nt, was);
        }
      });
      if (++pops >= chunk) {
        pops = 0;
        flush();
        sh.settledDelta[d].value.store(delta, std::memory_order_relaxed);
        if (progress) {
          const int64_t total = settled + delta + sh.settledDelta[1 - d].value.load(std::memory_order_relaxed);
          progress->report(double(total) / double(n), "search");  // may throw Cancelled
        }
      }
    }
    } catch (...) {  // a cancel: hand over what this domain holds, so the caller can merge it
      flush();
      sh.settledDelta[d].value.store(delta);
      throw;
    }
    flush();
    sh.settledDelta[d].value.store(delta);
  }
};

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
std::unique_ptr<ShortestPathSearch::Impl> makeGrid(const GridGraph& g, const GridCost& c, double scale, double step) {
  switch (g.directionCount()) {
    case 4: return makeGrid2<Queue, 4>(g, c, scale, step);
    case 8: return makeGrid2<Queue, 8>(g, c, scale, step);
    case 6: return makeGrid2<Queue, 6>(g, c, scale, step);
    case 18: return makeGrid2<Queue, 18>(g, c, scale, step);
    default: return makeGrid2<Queue, 26>(g, c, scale, step);
  }
}

// The largest key step of one push above the extracted key, in cost units: one edge for
// Dijkstra, two for A* (the consistent bound changes by at most one edge weight per edge).
double maxQueueStep(double maxEdge) { return 2 * maxEdge; }

// The queue actually used: Bucket falls back to Radix when its window would be too large.
QueueKind effectiveQueue(QueueKind q, double scale, double maxEdge) {
  if (q == QueueKind::Bucket &&
      detail::BucketQueue::bucketsFor(scale, maxQueueStep(maxEdge)) == UINT64_MAX)
    return QueueKind::Radix;
  return q;
}

struct CostStats {
  double maxEdge = 0;   // largest finite edge weight
  double minPositiveEdge = 0;  // smallest positive edge weight (a lower bound of it)
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
    case QueueKind::BinaryHeap: impl = makeGrid<detail::HeapQueue>(g, c, scale, step); break;
    case QueueKind::Bucket: impl = makeGrid<detail::BucketQueue>(g, c, scale, step); break;
    default: impl = makeGrid<detail::RadixQueue>(g, c, scale, step); break;
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
      impl = std::make_unique<Engine<CsrModel, detail::HeapQueue>>(CsrModel(g), scale, step);
      break;
    case QueueKind::Bucket:
      impl = std::make_unique<Engine<CsrModel, detail::BucketQueue>>(CsrModel(g), scale, step);
      break;
    default: impl = std::make_unique<Engine<CsrModel, detail::RadixQueue>>(CsrModel(g), scale, step); break;
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

void ShortestPathSearch::runToCompletion(Progress& progress) { impl_->settleAll(progress); }

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
Path runAStar(std::unique_ptr<ShortestPathSearch::Impl> impl, int64_t source, int64_t target, bool useAStar,
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
