// Internal to the shortest-path engine: the two-thread full map (ShortestPathSearch::
// runToCompletion on large grids with the bucket queue).
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
// same float64 edge weight, so the totals are the sequential search's bit for bit, and between
// predecessors giving exactly equal totals both take the smaller back direction (`breakTie`), so
// the tree is the sequential one too (with positive edge weights), whatever the order of messages.
// Nodes within one neighbour reach of the split take the bounds-checked relaxation (their
// interior flag is cleared for the run), so no thread ever reads a record the other writes.
#pragma once

#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "graph/search_engine.h"

namespace vs::engine {

// Spin-wait hint (the two threads wait for each other in short spins).
inline void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

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
  Mailbox mail[2];                              // mail[d]: messages for domain d
  PaddedKey at[2];                              // the key each domain is working on
  alignas(64) std::atomic<int64_t> pending{0};  // messages posted and not yet applied
  PaddedFlag idle[2];
  PaddedCount settledDelta[2];
  alignas(64) std::atomic<bool> stop{false};
};

template <class Model, class Queue>
void Engine<Model, Queue>::settleAllParallel(Progress& progress) {
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
      if (v >= 0 && v < n && m.interiorAt(v % m.nx, (v / m.nx) % m.ny, v / (m.nx * m.ny)))
        m.S(uint32_t(v)) |= kInterior;
    if (mainError) std::rethrow_exception(mainError);
    if (error) std::rethrow_exception(error);
    finished = queue.empty();
  }
}

template <class Model, class Queue>
void Engine<Model, Queue>::domainWorker(int d, const Model& mref, Queue& q, uint32_t split, ParallelShared& sh,
                                        Progress* progress) {
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
    if (q.empty()) {               // restart the empty queue's window at the earliest offered key
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
        for (uint32_t spin = 0;
             spin < 4096 && !q.empty() && q.lastKey() > sh.at[1 - d].key.load(std::memory_order_relaxed) + lead &&
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
          if (spin > 64)
            std::this_thread::yield();
          else
            cpuRelax();
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
          if (!(nt < best || isTie(Tu, nt, best))) return;  // equal totals: the owner breaks the tie
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
        } else if (isTie(Tu, nt, old)) {
          breakTie(sv, back);
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

}  // namespace vs::engine
