// Internal to the shortest-path engine: the search state behind ShortestPathSearch (Impl) and
// the sequential Dijkstra/A* loop (Engine), templated over a model (search_models.h) and a
// queue (priority_queues.h). The two-thread full map is in search_parallel.h; the engines are
// instantiated once per queue kind (search_bucket.cpp, search_radix.cpp, search_heap.cpp).
// Memory layout and threading: docs/notes/engine.md.
#pragma once

#include <algorithm>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "graph/priority_queues.h"
#include "graph/search_models.h"
#include "util/error.h"
#include "util/parallel.h"

namespace vs {

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
  int lastRunThreads = 1;  // threads of the last settleAll (runToCompletion): 1 or 2
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

  bool isSettled(int64_t v) const { return (sAt(v) & engine::kSettled) != 0; }
  int64_t predecessor(int64_t v) const {
    if (csr) {
      const uint32_t p = pred[size_t(v)];
      return p == 0xffffffffu ? -1 : int64_t(p);
    }
    const int d = sAt(v) & engine::kDirMask;
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
    const int d = sAt(v) & engine::kDirMask;  // v -> u direction
    return grid->length(d);
  }

  void checkNode(int64_t v, const char* what) const {
    if (v < 0 || v >= n)
      throw InvalidArgument(std::string(what) + " node " + std::to_string(v) + " is outside the graph (0.." +
                            std::to_string(n - 1) + ")" + (grid ? " of grid " + grid->describe() : std::string()));
  }

  Path path(int64_t t) const {
    Path p;
    if (!isSettled(t) || !(tAt(t) < engine::kInf)) return p;
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

namespace engine {

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

// Between predecessors giving exactly equal totals the smaller back direction wins, whatever
// order they arrive in (settled or not: the total does not change, so nothing is queued). The
// two-thread map relaxes in an order that varies from run to run; with this rule it gives the
// sequential map's tree, not only its totals. Only a predecessor whose own total is smaller
// takes part (callers check Tu < nt): across a zero-weight edge two nodes of equal totals would
// otherwise point at each other. On such plateaus (zero node costs) the first offer stays.
// A relaxation that ties: a finite total equal to the node's, from a predecessor of smaller total.
[[gnu::always_inline]] inline bool isTie(double Tu, double nt, double old) {
  return nt == old && Tu < nt && nt < std::numeric_limits<double>::infinity();
}

template <class State>
[[gnu::always_inline]] inline void breakTie(State& sv, uint8_t back) {
  if (back < (sv & kDirMask)) sv = uint8_t((sv & ~kDirMask) | back);
}

// Queues v at its lowered total nt (bucket queue), unless it already waits in the bucket of that
// key (its old, finite total had the same key); a node that was settled is always queued again.
template <class Queue>
[[gnu::always_inline]] inline void requeue(Queue& q, uint32_t v, double old, double nt, bool wasSettled) {
  const uint64_t nk = q.keyOf(nt);  // one key computation for the test and the push
  if (wasSettled || !(old < 1e300) || q.keyOf(old) != nk) q.pushKey(nk, v);
}

// "(x,y,z)" of grid node n, for error messages (shortest_path.cpp).
std::string voxelName(const GridGraph& g, int64_t n);

struct ParallelShared;  // search_parallel.h

template <class Model, class Queue>
struct Engine final : ShortestPathSearch::Impl {
  Model model;
  Queue queue;
  RecordStore rec;                  // grid only; filled lazily chunk by chunk (GridModel::ensure)
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
        T[size_t(v)] = model.T(uint32_t(v));
        state[size_t(v)] = model.S(uint32_t(v));
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
      if (!rec) rec.allocate(size_t(model.recordCount()));
      chunkReady.assign(size_t(model.chunkCount()), 0);
      model.setup(rec.get(), opt.mask, chunkReady.data());
    }
    for (int64_t s : sources) model.ensure(uint32_t(s));
    for (int64_t s : sources) {
      if (model.T(uint32_t(s)) == -kInf)
        throw InvalidArgument("source node " + std::to_string(s) + (grid ? " " + voxelName(*grid, s) : std::string()) +
                              " is outside the search mask");
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
      m.forEach(u, su, Tu,
                [P, u, Tu, astar, &q, &nSettled, this](uint32_t v, double& tv, auto& sv, double w, uint8_t back) {
                  const double nt = Tu + w;
                  const double old = tv;
                  if (nt < old) {
                    const bool was = lowerTotal(tv, sv, nt, back);
                    nSettled -= was;
                    if constexpr (Model::kCsr)
                      P[v] = u;
                    else
                      (void)P;
                    if (astar) {
                      q.push(priority(v, nt), v);
                    } else if constexpr (requires { q.pushKey(uint64_t(0), v); }) {
                      requeue(q, v, old, nt, was);
                    } else if (was || q.differentKey(old, nt)) {
                      q.push(nt, v);
                    }
                  } else if (isTie(Tu, nt, old)) {
                    if constexpr (!Model::kCsr) breakTie(sv, back);
                  }
                });
      if (++pops >= chunk && deferred.empty()) {  // (a cancel must not lose deferred nodes)
        pops = 0;
        settled = nSettled;
        progress.report(double(nSettled) / double(n), "search");
      }
    }
  }

  // ---- two-thread full map (runToCompletion on large grids): search_parallel.h ----
  // Grid searches with the bucket queue (the default) can run the two-thread full map.
  static constexpr bool kParallelCapable = !Model::kCsr && std::is_same_v<Queue, detail::BucketQueue>;

  bool parallelPossible() const {
    if constexpr (!kParallelCapable) {
      return false;
    } else {
      // Automatic (threads 0) takes two threads only when a second core is idle now: measured on
      // the 2-core machine (issue 25), the two-thread map is 1.1x-2x slower than one thread
      // whenever another process uses the second core and ~2x faster on an idle one
      // (docs/notes/engine.md). The cheap conditions go first: the idle test reads /proc/stat.
      if (astarTarget >= 0 || opt.threads == 1 || n < opt.parallelMinNodes || model.splitId() <= 0) return false;
      return opt.threads == 2 || secondCoreIdle();
    }
  }

  void settleAll(Progress& progress) override {
    lastRunThreads = parallelPossible() ? 2 : 1;
    if (lastRunThreads == 2)
      settleAllParallel(progress);
    else
      settle(-1, kInf, progress);
  }

  // Applies one improvement offer to a node of the calling thread's domain.
  static void offer(const Model& m, Queue& q, uint32_t v, double nt, uint8_t back, int64_t& settledDelta) {
    double& tv = m.T(v);
    if (!(nt < tv)) {
      if (nt == tv) breakTie(m.S(v), back);
      return;
    }
    settledDelta -= lowerTotal(tv, m.S(v), nt, back);
    q.push(nt, v);  // keys below the queue's current one are clamped to it
  }

  void settleAllParallel(Progress& progress);
  // One domain's loop. progress != nullptr on the calling thread only (reports and cancels).
  void domainWorker(int d, const Model& mref, Queue& q, uint32_t split, ParallelShared& sh, Progress* progress);
};

// One engine per grid connectivity and cost model (makeGridEngine) or for CSR graphs, for one
// queue kind; defined in search_instances.h, instantiated in search_<queue>.cpp.
template <class Queue>
std::unique_ptr<ShortestPathSearch::Impl> makeGridEngine(const GridGraph& g, const GridCost& c, double scale,
                                                         double step);
template <class Queue>
std::unique_ptr<ShortestPathSearch::Impl> makeCsrEngine(const CsrGraph& g, double scale, double step);

}  // namespace engine
}  // namespace vs
