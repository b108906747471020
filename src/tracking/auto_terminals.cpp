// Automatic terminals at branch ends (thesis 6.2; issue 21): VesselTracker::autoTerminals.
//
// The lumen region is the set of voxels whose node cost is <= the lumen level, connected to the
// root and the paths so far (with AutoTerminalOptions::continueDimBranches, off by default: continued along
// branches that dim below that level where they stay a compact, resolved tube, region_continue.h), less where it
// spilled into tissue of the lumen's values: fronts grown from the root that widen far beyond the root's own
// (region_fronts.h). Inside it:
//  - depth d(v): geodesic distance (mm) to the region's boundary, plus half the smallest spacing
//    (a multi-source Dijkstra from the boundary voxels; the volume's edge is not a boundary, so a
//    vessel leaving the crop keeps its depth);
//  - a medial tree: one Dijkstra from the root and the paths so far with node cost (s / d)^2
//    (s = smallest spacing) x (0.5 + node cost / lumen level), so every path through a wide lumen follows its medial
//    ridge and two branches that share a lumen share one trunk (the tree has one way through it);
//  - terminals: repeatedly the region voxel whose tree path adds the most length beyond a
//    suppression zone around the paths taken (balls of 1.5 d + the largest spacing: the whole
//    cross-section, d being the depth of a medial voxel), i.e. the far end of the longest branch
//    not yet traced, among the voxels whose tree route is not much longer than the lumen's shortest way to them
//    (terminal_routes.h: in a vessel network the tree's route runs round the deep sinuses);
//  - its end moved back onto the medial ridge (ridgeEnd: the far voxel is a corner of the wall);
//  - an end where the region, not the vessel, stops (as deep as the branch, inside a wide lumen,
//    away from the volume's edge: the cost's lumen level cut a wide lumen, e.g. contrast wash-out
//    along an aorta) is no terminal: its chain is suppressed and the scan goes on; the note says so.
// Each terminal's path is the medial-tree chain, prefixed by the earlier path it starts from. The
// paths form one joined tree: after each terminal the medial tree is grown again from the root and
// every path so far, so the next chain stops where it meets the tree (one trunk per lumen).
#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <future>
#include <limits>
#include <memory>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "tracking/auto_cost.h"
#include "tracking/region_continue.h"
#include "tracking/region_fronts.h"
#include "tracking/region_notes.h"
#include "tracking/terminal_end.h"
#include "tracking/terminal_gaps.h"
#include "tracking/terminal_routes.h"
#include "tracking/tracker.h"
#include "tracking/tracker_impl.h"
#include "util/bucket_distances.h"
#include "util/exact_radix_queue.h"
#include "util/parallel.h"
#include "util/uninit_allocator.h"
#include "volume/neighbourhood.h"

namespace vs {

namespace {

using Clock = std::chrono::steady_clock;
// At most this many rounds of the region's fronts (region_fronts.h), each after the last spill was left out.
constexpr int kFrontPasses = 6;
// At most this many rounds of the region's continuation along dim branches (region_continue.h).
constexpr int kContinueRounds = 2;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Step {
  int dx, dy, dz;
  double mm;
};

std::vector<Step> steps(const Geometry& g, int connectivity) {
  std::vector<Step> out;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int n = std::abs(dx) + std::abs(dy) + std::abs(dz);
        if (n == 0 || (connectivity == 6 && n > 1) || (connectivity == 18 && n > 2)) continue;
        out.push_back({dx, dy, dz, g.stepLength(Vec3(dx, dy, dz))});
      }
  return out;
}

// The lumen region around the sources, its depth and its medial tree.
struct LumenRegion {
  std::vector<int64_t> voxel;    // per slot: linear voxel index
  std::vector<int32_t> slot;     // per volume voxel: slot, -1 outside the region
  std::vector<float> depth;      // per slot: mm to the boundary (+ half the smallest spacing)
  std::vector<float> node;       // per slot: its voxel's node cost (cost.node, unweighted)
  std::vector<int32_t> pred;     // per slot: predecessor in the medial tree, -1 at a source
  std::vector<float> weight;     // per slot: the medial tree's node weight
  std::vector<double> treeDist;  // per slot: the medial tree's distance to the nearest source
  size_t treeSources = 0;        // sources the tree has grown from so far (they only get added)
  // The region's adjacency (empty when too large): per slot a record of kAdjStride entries, 128 bytes
  // aligned to a cache line: the count, then its neighbours' slots in `steps` order, packed as
  // slot << 5 | step index. Built once, it spares every Dijkstra over the region its look-ups in the
  // volume-sized slot array (random reads 4 bytes per voxel wide: most of their time on a head CTA); a
  // fixed-size record is found from the slot alone (one memory access per settled node, not an offset
  // then the list).
  static constexpr size_t kAdjStride = 32;
  std::vector<uint32_t, UninitAllocator<uint32_t>> adjStore;  // empty: no adjacency
  size_t adjFirst = 0;                                        // adjStore's first entry on a cache line
  const uint32_t* adjacency(int32_t s) const {
    return adjStore.data() + adjFirst + static_cast<size_t>(s) * kAdjStride;
  }
  std::vector<std::array<int32_t, 3>> at;  // per slot: its voxel's index (spares the divisions)
  size_t spilledVoxels = 0;                // left out where its fronts spilled (region_fronts.h)
  std::vector<uint8_t> spill;              // per volume voxel: 1 where left out (empty: none)
  Index3 spillAt{0, 0, 0};                 // a voxel of the first spill (nearest the root)
  double spillMm = 0;                      // its geodesic distance from the root
  size_t continuedVoxels = 0;              // admitted along dim branches (region_continue.h)
  int continuedPieces = 0;                 // the continuations they form
  Index3 index(int32_t s) const {
    const auto& a = at[static_cast<size_t>(s)];
    return {a[0], a[1], a[2]};
  }
};

// f(linear index, index, step mm) for each neighbour of voxel p inside the volume.
template <class F>
void forEachNeighbourAt(const Geometry& g, const std::vector<Step>& st, const Index3& p, F&& f) {
  for (const Step& s : st) {
    const Index3 q{p[0] + s.dx, p[1] + s.dy, p[2] + s.dz};
    if (g.contains(q)) f(g.linear(q[0], q[1], q[2]), q, s.mm);
  }
}

template <class F>
void forEachNeighbour(const Geometry& g, const std::vector<Step>& st, int64_t v, F&& f) {
  forEachNeighbourAt(g, st, g.unlinear(v), [&](int64_t nv, const Index3&, double mm) { f(nv, mm); });
}

// f(linear index) for each neighbour of voxel v inside the volume, in `st` order; `offset`: the steps'
// linear offsets (a voxel off the volume's faces has every neighbour inside: no bounds test).
template <class F>
void forEachNeighbourIndex(const Geometry& g, const std::vector<Step>& st, const std::vector<int64_t>& offset,
                           int64_t v, F&& f) {
  const Index3 p = g.unlinear(v);
  if (p[0] > 0 && p[1] > 0 && p[2] > 0 && p[0] < g.dims[0] - 1 && p[1] < g.dims[1] - 1 && p[2] < g.dims[2] - 1) {
    for (const int64_t o : offset) f(v + o);
    return;
  }
  forEachNeighbourAt(g, st, p, [&](int64_t nv, const Index3&, double) { f(nv); });
}

std::vector<int64_t> stepOffsets(const Geometry& g, const std::vector<Step>& st) {
  std::vector<int64_t> out;
  for (const Step& s : st) out.push_back(g.linear(s.dx, s.dy, s.dz));
  return out;
}

// Calls f(neighbour slot, step mm) for every neighbour of slot u inside the region, in `steps`
// order (the same order with or without the adjacency, so ties resolve the same).
template <class F>
void forEachRegionNeighbour(const Geometry& g, const std::vector<Step>& st, const LumenRegion& r, int32_t u, F&& f) {
  if (!r.adjStore.empty()) {
    const uint32_t* rec = r.adjacency(u);
    for (uint32_t e = 1; e <= rec[0]; ++e) f(static_cast<int32_t>(rec[e] >> 5), st[rec[e] & 31u].mm);
    return;
  }
  forEachNeighbour(g, st, r.voxel[static_cast<size_t>(u)], [&](int64_t nv, double mm) {
    const int32_t v = r.slot[static_cast<size_t>(nv)];
    if (v >= 0) f(v, mm);
  });
}

// forEachRegionNeighbour less the slots of infinite weight in `cut` (may be null): cut from the medial tree
// (terminal_gaps.h), no way through for the tree's views.
template <class F>
void forEachUncutNeighbour(const Geometry& g, const std::vector<Step>& st, const LumenRegion& r,
                           const std::vector<float>* cut, int32_t u, F&& f) {
  forEachRegionNeighbour(g, st, r, u, [&](int32_t v, double mm) {
    if (!cut || !std::isinf((*cut)[static_cast<size_t>(v)])) f(v, mm);
  });
}

// Builds the adjacency when it fits (at most 2^27 slots, 64 M entries: 256 MB).
void buildAdjacency(const Geometry& g, const std::vector<Step>& st, LumenRegion& r) {
  const size_t L = r.voxel.size(), K = LumenRegion::kAdjStride;
  r.adjStore.clear();
  if (st.size() >= K || L >= (size_t{1} << 27) || L * K > (size_t{64} << 20)) return;
  r.adjStore.resize(L * K + 16);  // not zeroed: each record's count is written first
  r.adjFirst = 0;                 // 4-byte entries: at most 15 steps to a cache line's start
  while (reinterpret_cast<uintptr_t>(r.adjStore.data() + r.adjFirst) % 64 != 0) ++r.adjFirst;
  const std::vector<int64_t> offset = stepOffsets(g, st);
  parallelFor(
      0, static_cast<int64_t>(L),
      [&](int64_t b, int64_t e) {
        for (auto i = static_cast<size_t>(b); i < static_cast<size_t>(e); ++i) {
          const Index3 p = r.index(static_cast<int32_t>(i));
          const int64_t v = r.voxel[i];
          uint32_t* rec = r.adjStore.data() + r.adjFirst + i * K;
          rec[0] = 0;
          const bool inner =
              p[0] > 0 && p[1] > 0 && p[2] > 0 && p[0] < g.dims[0] - 1 && p[1] < g.dims[1] - 1 && p[2] < g.dims[2] - 1;
          for (uint32_t k = 0; k < st.size(); ++k) {
            if (!inner && !g.contains(p[0] + st[k].dx, p[1] + st[k].dy, p[2] + st[k].dz)) continue;
            const int32_t u = r.slot[static_cast<size_t>(v + offset[k])];
            if (u >= 0) rec[++rec[0]] = static_cast<uint32_t>(u) << 5 | k;
          }
        }
      },
      4096);
}

// Dijkstra over region slots from `sources` (slot, start value); node weight w per slot (edge =
// mm * (w(u) + w(v)) / 2). Returns the totals; pred (if given) gets the predecessor slots.
// Continues a Dijkstra whose result `dist` (and `pred`) already holds: new sources only lower
// distances, so the nodes they do not reach closer keep theirs (the same distances as a run from
// every source at once, for a fraction of the work when a path is added to the tree).
// A slot's distance, weight and predecessor are read and written together, in one cache line (the
// relaxation's time went to two misses per neighbour, one on each array).
void regionDijkstraFrom(const Geometry& g, const std::vector<Step>& st, const LumenRegion& r,
                        const std::vector<std::pair<int32_t, double>>& sources, const std::vector<float>& w,
                        std::vector<double>& dist, std::vector<int32_t>* pred) {
  struct Node {
    double dist;
    float w;
    int32_t pred;
  };
  std::vector<Node> node(dist.size());
  for (size_t i = 0; i < node.size(); ++i) node[i] = {dist[i], w[i], pred ? (*pred)[i] : -1};
  ExactRadixQueue q;  // pops in (distance, slot) order, as a binary heap of the pairs would
  for (const auto& [s, d0] : sources)
    if (Node& n = node[static_cast<size_t>(s)]; d0 < n.dist) {
      n.dist = d0, q.push(d0, s);
      n.pred = -1;
    }
  // Settled in this run, one bit per slot (fits in the first-level cache, unlike the nodes): a node's first
  // entry popped carries its final distance (its entries are pushed with decreasing distances and popped
  // in increasing order, none lower can come after it), so every later entry is stale; and a settled
  // neighbour is never lowered (its distance <= this one's). Both skipped without reading its node.
  std::vector<uint64_t> settled((node.size() + 63) / 64, 0);
  auto isSettled = [&](int32_t v) { return (settled[static_cast<size_t>(v) >> 6] >> (v & 63)) & 1u; };
  while (!q.empty()) {
    const auto [d, u] = q.pop();
    if (isSettled(u)) continue;
    settled[static_cast<size_t>(u) >> 6] |= uint64_t{1} << (u & 63);
    const float wu = node[static_cast<size_t>(u)].w;
    forEachRegionNeighbour(g, st, r, u, [&](int32_t v, double mm) {
      if (isSettled(v)) return;
      Node& n = node[static_cast<size_t>(v)];
      const double nd = d + mm * 0.5 * (wu + n.w);
      if (nd < n.dist) {
        n.dist = nd;
        n.pred = u;
        q.push(nd, v);
        if (!r.adjStore.empty()) {  // its record is read when it is settled: on its way by then
          __builtin_prefetch(r.adjacency(v));
          __builtin_prefetch(r.adjacency(v) + 16);
        }
      }
    });
  }
  for (size_t i = 0; i < node.size(); ++i) dist[i] = node[i].dist;
  if (pred)
    for (size_t i = 0; i < node.size(); ++i) (*pred)[i] = node[i].pred;
}

// Geodesic distances (mm) over the region from `sources` (slot, start value): regionDijkstraFrom with every
// node weight 1 (an edge is mm * 0.5 * (1 + 1) = mm exactly) and no predecessors. Without predecessors the
// order of settling is free, so a bucket queue (util/bucket_distances.h) gives the same distances, no heap.
// `cut` (per slot, may be null): slots of infinite weight there are no way (cut from the medial tree, terminal_gaps.h).
std::vector<double> regionDistances(const Geometry& g, const std::vector<Step>& st, const LumenRegion& r,
                                    const std::vector<std::pair<int32_t, double>>& sources,
                                    const std::vector<float>* cut = nullptr) {
  double minMm = std::numeric_limits<double>::infinity(), maxMm = 0;
  for (const Step& s : st) minMm = std::min(minMm, s.mm), maxMm = std::max(maxMm, s.mm);
  return bucketDistances(
      r.voxel.size(), sources, minMm, maxMm,
      [&](int32_t u, auto&& relax) { forEachUncutNeighbour(g, st, r, cut, u, relax); },
      [&](int32_t v) {
        if (!r.adjStore.empty()) {  // its record is read when it is settled: on its way by then
          __builtin_prefetch(r.adjacency(v));
          __builtin_prefetch(r.adjacency(v) + 16);
        }
      });
}

// The medial tree: one Dijkstra over the region from every source (the root and every voxel of
// the paths so far) with the medial weights. A voxel's chain ends at the tree already traced
// where reaching it is cheapest, so a new branch joins the trunk where its lumen meets it.
void medialTree(const Geometry& g, const std::vector<Step>& st, LumenRegion& r, const std::vector<int64_t>& sources) {
  if (r.treeDist.size() != r.voxel.size() || sources.size() < r.treeSources) {
    r.treeDist.assign(r.voxel.size(), std::numeric_limits<double>::infinity());
    r.pred.assign(r.voxel.size(), -1);
    r.treeSources = 0;
  }
  std::vector<std::pair<int32_t, double>> src;
  for (size_t i = r.treeSources; i < sources.size(); ++i)
    if (r.slot[static_cast<size_t>(sources[i])] >= 0) src.push_back({r.slot[static_cast<size_t>(sources[i])], 0.0});
  regionDijkstraFrom(g, st, r, src, r.weight, r.treeDist, &r.pred);
  r.treeSources = sources.size();
}

// The region's voxels: the flood from the sources (which belong to it whatever their cost) through the
// voxels at or below the lumen level or `admitted` (a dim branch's continuation, region_continue.h), not
// through `excluded` ones (both per volume voxel; empty: none).
void floodRegion(const Geometry& g, const std::vector<Step>& st, const NodeCost3D& cost, double maxNode,
                 const std::vector<int64_t>& sources, const std::vector<uint8_t>& excluded,
                 const std::vector<uint8_t>& admitted, LumenRegion& r) {
  r = LumenRegion{};
  r.slot.assign(static_cast<size_t>(g.voxelCount()), -1);
  auto inLumen = [&](int64_t v) {
    const auto i = static_cast<size_t>(v);
    return (cost.nodeWeight * cost.node[i] <= maxNode || (!admitted.empty() && admitted[i])) &&
           (excluded.empty() || !excluded[i]);
  };
  for (int64_t s : sources)
    if (r.slot[static_cast<size_t>(s)] < 0) {
      r.slot[static_cast<size_t>(s)] = static_cast<int32_t>(r.voxel.size());
      r.voxel.push_back(s);
    }
  const std::vector<int64_t> offset = stepOffsets(g, st);
  for (size_t i = 0; i < r.voxel.size(); ++i)
    forEachNeighbourIndex(g, st, offset, r.voxel[i], [&](int64_t nv) {
      if (r.slot[static_cast<size_t>(nv)] >= 0 || !inLumen(nv)) return;
      r.slot[static_cast<size_t>(nv)] = static_cast<int32_t>(r.voxel.size());
      r.voxel.push_back(nv);
    });
  const size_t L = r.voxel.size();
  r.at.resize(L);
  r.node.resize(L);
  for (size_t i = 0; i < L; ++i) {
    const Index3 p = g.unlinear(r.voxel[i]);
    r.at[i] = {static_cast<int32_t>(p[0]), static_cast<int32_t>(p[1]), static_cast<int32_t>(p[2])};
    r.node[i] = cost.node[static_cast<size_t>(r.voxel[i])];
  }
  buildAdjacency(g, st, r);
}

// Depth: from the boundary voxels, those with a face neighbour outside the region that is a
// wall, not a hole: fewer than 4 of the outside voxel's own 6 face neighbours lie in the region.
// Noise holes inside a wide lumen (voxels just over the level where its intensity nears the
// threshold) are surrounded by the region; measured from them the depth was small everywhere
// and the medial paths zig-zagged between the holes.
void regionDepth(const Geometry& g, const std::vector<Step>& st, LumenRegion& r) {
  const size_t L = r.voxel.size();
  const double half = 0.5 * g.spacing.minCoeff();
  std::vector<std::pair<int32_t, double>> boundary;
  const std::vector<Step> faces = steps(g, 6);
  auto isWall = [&](int64_t nv, const Index3& q) {
    if (r.slot[static_cast<size_t>(nv)] >= 0) return false;
    int inside = 0;
    forEachNeighbourAt(g, faces, q,
                       [&](int64_t w, const Index3&, double) { inside += r.slot[static_cast<size_t>(w)] >= 0; });
    return inside < 4;
  };
  uint32_t faceSteps = 0;  // the steps (bits by index) that cross a face
  for (size_t k = 0; k < st.size(); ++k)
    if (std::abs(st[k].dx) + std::abs(st[k].dy) + std::abs(st[k].dz) == 1) faceSteps |= 1u << k;
  for (size_t i = 0; i < L; ++i) {
    if (!r.adjStore.empty()) {  // all six face neighbours in the region (most voxels): no wall beside it
      const uint32_t* rec = r.adjacency(static_cast<int32_t>(i));
      uint32_t seen = 0;
      for (uint32_t e = 1; e <= rec[0]; ++e) seen |= 1u << (rec[e] & 31u);
      if ((seen & faceSteps) == faceSteps && std::popcount(faceSteps) == 6) continue;
    }
    bool edge = false;
    forEachNeighbourAt(g, faces, r.index(static_cast<int32_t>(i)),
                       [&](int64_t nv, const Index3& q, double) { edge = edge || isWall(nv, q); });
    if (edge) boundary.push_back({static_cast<int32_t>(i), half});
  }
  if (boundary.empty()) boundary.push_back({0, half});  // the whole volume is lumen
  const std::vector<double> depth = regionDistances(g, st, r, boundary);
  r.depth.assign(depth.begin(), depth.end());
}

// The medial tree's node weights from the depth: (s / d)^2 (s = the smallest spacing) times 0.5 + the voxel's
// share of the lumen level (0.5..1.5): between voxels of equal depth (a thin lumen, a voxel wide) the more
// lumen-like one; the depth dominates in a wide lumen.
void medialWeights(const Geometry& g, const NodeCost3D& cost, double maxNode, LumenRegion& r) {
  const double s = g.spacing.minCoeff();
  const size_t L = r.voxel.size();
  std::vector<float>& w = r.weight;
  w.resize(L);
  for (size_t i = 0; i < L; ++i)
    w[i] = static_cast<float>((s / r.depth[i]) * (s / r.depth[i]) *
                              (0.5 + std::min(1.0, cost.nodeWeight * r.node[i] / std::max(maxNode, 1e-12))));
}

// The region's spills (region_fronts.h) left out, the region flooded again, until no front spills. `excluded`
// (per volume voxel, allocated at the first spill) gathers them; returns whether r.depth and the medial tree
// were found for the last region on the way.
struct SpillTrack {
  std::vector<uint8_t> excluded;
  size_t spilled = 0;
  Index3 at{0, 0, 0};
  double mm = 0;
};
bool leaveOutSpills(const Geometry& g, const std::vector<Step>& st, const NodeCost3D& cost, double maxNode,
                    int connectivity, const std::vector<int64_t>& sources, double rootRadiusMm,
                    const std::vector<uint8_t>& admitted, SpillTrack& sp, LumenRegion& r) {
  // Fronts from the root: where one widens beyond the tree's cross-sections, the region has spilled
  // into tissue of the lumen's values; those fronts are left out and the region flooded again
  // without them. Again, as the part beyond a spill may still be reached by another way into it
  // (a heart's chambers through the aorta and through the pulmonary veins): until no front spills.
  for (int pass = 0; pass < kFrontPasses; ++pass) {
    // The region's depth and medial tree need only the region: found on a second thread while the fronts are
    // (both read the region; only that thread writes, to r.depth, r.weight and the tree), kept when no front
    // spills (the common case: a tree).
    std::future<void> depth;
    const bool depthMeanwhile = workerCount() >= 2;
    if (depthMeanwhile)
      depth = std::async(std::launch::async, [&] {
        regionDepth(g, st, r);
        medialWeights(g, cost, maxNode, r);
        medialTree(g, st, r, sources);
      });
    const std::vector<double> dist = regionDistances(g, st, r, {{r.slot[static_cast<size_t>(sources[0])], 0.0}});
    const RegionFronts fr = regionFronts(g, connectivity, r.voxel, r.at, r.slot, dist, rootRadiusMm, {},
                                         {r.adjStore.empty() ? nullptr : r.adjacency(0), LumenRegion::kAdjStride});
    if (depth.valid()) depth.get();  // joined before the region changes (its exception rethrown)
    if (fr.spilledVoxels == 0) return depthMeanwhile;
    if (sp.excluded.empty()) {
      sp.excluded.assign(static_cast<size_t>(g.voxelCount()), 0);
      sp.at = fr.firstOnset;
      sp.mm = fr.firstOnsetMm;
    }
    for (size_t i = 0; i < r.voxel.size(); ++i)
      if (fr.spilled[i]) sp.excluded[static_cast<size_t>(r.voxel[i])] = 1;
    sp.spilled += fr.spilledVoxels;
    floodRegion(g, st, cost, maxNode, sources, sp.excluded, admitted, r);
  }
  return false;
}

LumenRegion lumenRegion(const Geometry& g, const NodeCost3D& cost, double maxNode, int connectivity,
                        const std::vector<int64_t>& sources, double rootRadiusMm, double minLengthMm,
                        bool continueDim) {
  const std::vector<Step> st = steps(g, connectivity);
  LumenRegion r;
  std::vector<uint8_t> admitted;
  SpillTrack sp;
  floodRegion(g, st, cost, maxNode, sources, sp.excluded, admitted, r);
  bool depthFound = leaveOutSpills(g, st, cost, maxNode, connectivity, sources, rootRadiusMm, admitted, sp, r);
  // Dim branches beyond the region's ends: continued where they stay a tube (region_continue.h), the region
  // flooded again with them; then its spills left out again (lumen joined beyond a dim stretch may be tissue).
  size_t continuedVoxels = 0;
  int continuedPieces = 0;
  for (int round = 0; continueDim && round < kContinueRounds; ++round) {
    RegionContinueOptions co;
    co.minReachMm = minLengthMm;
    const RegionContinuation cont = continueRegion(g, cost, maxNode, r.voxel, r.slot, sp.excluded, co);
    if (cont.admitted.empty()) break;
    if (admitted.empty()) admitted.assign(static_cast<size_t>(g.voxelCount()), 0);
    for (int64_t v : cont.admitted) admitted[static_cast<size_t>(v)] = 1;
    continuedVoxels += cont.admitted.size();
    continuedPieces += cont.continued;
    const size_t before = r.voxel.size();
    floodRegion(g, st, cost, maxNode, sources, sp.excluded, admitted, r);
    depthFound = false;
    // Another round only where this one can have left something: a continuation cut by the search's reach, or
    // lumen beyond a dim stretch joined through it (else the candidates beyond the region are those searched).
    if (cont.open == 0 && r.voxel.size() <= before + cont.admitted.size()) break;
  }
  if (continuedVoxels > 0)
    depthFound = leaveOutSpills(g, st, cost, maxNode, connectivity, sources, rootRadiusMm, admitted, sp, r);
  r.continuedVoxels = continuedVoxels;
  r.continuedPieces = continuedPieces;
  r.spilledVoxels = sp.spilled;
  r.spill = std::move(sp.excluded);
  r.spillAt = sp.at;
  r.spillMm = sp.mm;
  if (!depthFound) {  // the depth and medial tree of the region left
    regionDepth(g, st, r);
    medialWeights(g, cost, maxNode, r);
    medialTree(g, st, r, sources);
  }
  return r;
}

using Ends = EndsNotTaken;

// A terminal's last stretch fallen off its feeding tube's level (terminal_end.h): suppressed - the chain's voxels, and
// the paths' balls (suppressRadiusMm, NaN: 1.5 x the lumen radius + the largest spacing) of those clear of the voxel
// before it (the tube's end stays a candidate); the scan is run again. False where none was found.
template <class Tracker, class Radius>
bool cutFaded(const Tracker& m, const LumenRegion& r, int32_t far, double suppressRadiusMm, Radius&& lumenRadius,
              std::vector<uint8_t>& suppressed, EndsNotTaken& faded) {
  const VolumeF32& vol = m.vol;
  const LocalBackground* lb = m.opt.crossing.background;
  const Geometry& g = vol.geometry();
  std::vector<int32_t> w{far};  // the chain's slots, the end first
  for (; r.pred[static_cast<size_t>(w.back())] >= 0;) w.push_back(r.pred[static_cast<size_t>(w.back())]);
  std::vector<Index3> chain(w.size());
  for (size_t i = 0; i < w.size(); ++i) chain[i] = r.index(w[i]);
  size_t free = 0;
  while (free < w.size() && !suppressed[static_cast<size_t>(w[free])]) ++free;
  std::function<double(const Index3&)> bg;  // the auto cost's local background, where the trace has one
  if (lb) bg = [lb](const Index3& v) { return lb->at(v[0], v[1], v[2]); };
  const FadedStretch f = fadedStretch(vol, chain, free, lumenRadius, bg);
  for (size_t i = 0; f.found && i <= f.first; ++i) {
    suppressed[static_cast<size_t>(w[i])] = 1;
    const double ball =
        std::isnan(suppressRadiusMm) ? 1.5 * lumenRadius(chain[i]) + g.spacing.maxCoeff() : suppressRadiusMm;
    if (mmBetween(g, chain[i], chain[f.first + 1]) > ball) suppressBall(g, r.slot, chain[i], ball, suppressed);
  }
  if (f.found) faded.add(chain[f.first], lumenRadius(chain[f.first]));
  return f.found;
}

// The longest branch not yet traced: per slot the new part's length, cost, largest node cost
// and its anchor (the last suppressed voxel before it), computed along the medial tree. A
// candidate's reach is the straight distance from its anchor: a branch leads away from the paths,
// a tortuous wander inside a porous lumen does not.
struct BranchScan {
  std::vector<float> newLen, newCost, newMax;
  std::vector<int32_t> anchor;
  std::vector<uint8_t> done;
  std::vector<size_t> stack;
  int64_t best = -1;  // far end (slot) of the longest new part that reaches minLengthMm
  float bestLen = 0, longest = 0;

  void run(const Geometry& g, const LumenRegion& r, const NodeCost3D& cost, const std::vector<uint8_t>& suppressed,
           double minLengthMm, double maxPerMm, double maxNode, const std::vector<uint8_t>& direct) {
    const size_t L = r.voxel.size();
    newLen.resize(L), newCost.resize(L), newMax.resize(L), anchor.assign(L, -1);
    done.assign(L, 0);
    best = -1;
    bestLen = longest = 0;
    // NodeCost3D::edgeCost from the region's own copy of the node costs (the same expression), unless the
    // cost has a sign term.
    const bool plainEdges = cost.sign.empty() || !(cost.signWeight > 0);
    double stepMm[27];  // a step to the predecessor (a 26-neighbour), by (dx + 1) + 3 (dy + 1) + 9 (dz + 1)
    for (int k = 0; k < 27; ++k) stepMm[k] = mmBetween(g, {k % 3 - 1, k / 3 % 3 - 1, k / 9 - 1}, {0, 0, 0});
    for (size_t u = 0; u < L; ++u) {
      if (done[u]) continue;
      // Walk up to a computed node, then unwind.
      int32_t w = static_cast<int32_t>(u);
      while (w >= 0 && !done[static_cast<size_t>(w)]) {
        stack.push_back(static_cast<size_t>(w));
        if (suppressed[static_cast<size_t>(w)]) break;
        w = r.pred[static_cast<size_t>(w)];
      }
      while (!stack.empty()) {
        const size_t a = stack.back();
        stack.pop_back();
        const int32_t pa = r.pred[a];
        float len = 0, c = 0, mx = 0, reach = 0;
        anchor[a] = static_cast<int32_t>(a);
        if (!suppressed[a] && pa >= 0) {
          const size_t ps = static_cast<size_t>(pa);
          mx = std::max(newMax[ps], cost.nodeWeight * r.node[a]);
          const Index3 A = r.index(static_cast<int32_t>(a)), P = r.index(pa);
          const double mm = stepMm[(A[0] - P[0] + 1) + 3 * (A[1] - P[1] + 1) + 9 * (A[2] - P[2] + 1)];
          len = newLen[ps] + static_cast<float>(mm);
          c = newCost[ps] +
              static_cast<float>(plainEdges ? mm * (cost.nodeWeight * 0.5 *
                                                    (static_cast<double>(r.node[ps]) + static_cast<double>(r.node[a])))
                                            : cost.edgeCost(r.voxel[ps], r.voxel[a], mm));
          anchor[a] = anchor[ps];
          reach = static_cast<float>(mmBetween(g, A, r.index(anchor[a])));
        }
        newLen[a] = len;
        newCost[a] = c;
        newMax[a] = mx;
        done[a] = 1;
        longest = std::max(longest, reach);
        if (len > bestLen && reach >= minLengthMm && c <= maxPerMm * len && mx <= maxNode && direct[a]) {
          bestLen = len;
          best = static_cast<int64_t>(a);
        }
      }
    }
  }
};

// The medial-tree chain from `end` back to a source, prefixed by the path that source lies on
// (the root alone when it is the root; voxelsOf(path) gives a path's voxels); its cost is the image cost along it,
// its junctionIndex the prefix's last voxel.
template <class VoxelsOf>
TracedPath medialPath(const Geometry& g, const LumenRegion& r, const NodeCost3D& cost, int32_t end,
                      const std::unordered_map<int64_t, std::pair<size_t, size_t>>& onPath, VoxelsOf&& voxelsOf) {
  std::vector<Index3> chain;
  int32_t w = end;
  for (; r.pred[static_cast<size_t>(w)] >= 0; w = r.pred[static_cast<size_t>(w)])
    chain.push_back(g.unlinear(r.voxel[static_cast<size_t>(w)]));
  const int64_t src = r.voxel[static_cast<size_t>(w)];
  TracedPath tp;
  if (const auto it = onPath.find(src); it != onPath.end()) {
    const std::vector<Index3>& pv = voxelsOf(it->second.first);
    tp.voxels.assign(pv.begin(), pv.begin() + static_cast<std::ptrdiff_t>(it->second.second + 1));
  } else {
    tp.voxels.push_back(g.unlinear(src));
  }
  tp.junctionIndex = tp.voxels.size() - 1;
  tp.voxels.insert(tp.voxels.end(), chain.rbegin(), chain.rend());
  for (size_t i = 1; i < tp.voxels.size(); ++i) {
    const Index3 &a = tp.voxels[i - 1], &b = tp.voxels[i];
    tp.cost += cost.edgeCost(g.linear(a[0], a[1], a[2]), g.linear(b[0], b[1], b[2]), mmBetween(g, b, a));
  }
  return tp;
}

// Where the lumen region, not the vessel, ends (returns the end's width; 0: a branch end): an
// end at least 2 voxels wide, 0.6 x as wide as the widest lumen on its medial chain back to the
// root or path it starts from, away from the volume's edge (a vessel leaving the field of view
// ends there). A branch narrows towards its distal end; a region cut off by the lumen level
// inside a wide lumen (contrast wash-out along an aorta) does not.
template <class Radius>
double cutInsideWideLumen(const Geometry& g, const LumenRegion& r, double minLengthMm, Radius&& lumenRadius,
                          int32_t end, int32_t anchor) {
  const double maxSp = g.spacing.maxCoeff();
  const Index3 E = g.unlinear(r.voxel[static_cast<size_t>(end)]);
  // The end's width: the widest lumen along its last minLengthMm (the end voxel itself may lie
  // at the wall of a porous region).
  double endR = 0;
  for (int32_t w = end; w >= 0 && w != anchor; w = r.pred[static_cast<size_t>(w)]) {
    const Index3 v = g.unlinear(r.voxel[static_cast<size_t>(w)]);
    if (mmBetween(g, v, E) > minLengthMm) break;
    endR = std::max(endR, lumenRadius(v));
  }
  if (endR < 2 * maxSp) return 0.0;
  if (spillNear(g, r.spill, E, endR + 2 * maxSp)) return 0.0;  // the tree's last voxels before a spill: its end
  for (int a = 0; a < 3; ++a)
    if (g.spacing[a] * static_cast<double>(std::min(E[a], g.dims[a] - 1 - E[a])) <= endR + maxSp) return 0.0;
  double widest = 0;  // along the whole medial chain back to its source
  for (int32_t w = end; w >= 0; w = r.pred[static_cast<size_t>(w)])
    widest = std::max(widest, lumenRadius(g.unlinear(r.voxel[static_cast<size_t>(w)])));
  return endR >= 0.6 * widest ? endR : 0.0;
}

// A route across background between two vessels (terminal_gaps.h): the background round it is cut from the medial
// tree, grown again without it (the lumen's own way, or the vessel beyond not reached); false where none was found.
template <class Radius>
bool cutRouteGaps(const VolumeF32& vol, const std::vector<Step>& st, LumenRegion& r, const TracedPath& tp,
                  const std::vector<int64_t>& sources, Radius&& radiusMm, EndsNotTaken& across,
                  std::vector<double>& geodesicMm) {
  const std::vector<RouteGap> gaps = routeGaps(vol, tp.voxels, tp.junctionIndex + 1, radiusMm);
  if (gaps.empty()) return false;
  for (const RouteGap& gp : gaps) cutGap(vol, r.slot, tp.voxels[gp.index], gp, r.weight);
  across.add(tp.voxels[gaps.front().index], gaps.front().radiusMm);
  r.treeDist.clear();  // grown again from every source
  medialTree(vol.geometry(), st, r, sources);
  geodesicMm = regionDistances(vol.geometry(), st, r, {{r.slot[static_cast<size_t>(sources[0])], 0.0}}, &r.weight);
  return true;
}

}  // namespace

std::vector<size_t> VesselTracker::autoTerminals(const AutoTerminalOptions& o, Progress& progress) {
  VS_REQUIRE(o.count >= 0, "auto terminals: count must be >= 0");
  VS_REQUIRE(o.count > 0 || o.minLengthMm > 0, "auto terminals: give a count or a minimum length > 0");
  Impl& m = *impl_;
  const Geometry& g = geom_;
  double maxNode = o.maxNodeCost;
  if (std::isnan(maxNode)) maxNode = lumenCostThreshold(m.cost);
  const double maxSp = g.spacing.maxCoeff();

  const auto tLumen = Clock::now();
  const int64_t rootLin = m.voxelOfNode(m.rootNode);
  std::unordered_map<int64_t, std::pair<size_t, size_t>> onPath;  // voxel -> (path, index)
  std::vector<int64_t> sources = scanSources(g, rootLin, paths_, onPath);
  LumenRegion r = lumenRegion(g, m.cost, maxNode, m.opt.connectivity, sources, radiusAt(g.unlinear(rootLin)),
                              o.minLengthMm, o.continueDimBranches);
  // A branch's new part lies in the region: at or below the lumen level, or its continuation's level where the
  // region was continued along dim branches.
  const double scanNode = r.continuedVoxels > 0 ? RegionContinueOptions{}.continueFactor * maxNode : maxNode;
  const double maxPerMm = std::isnan(o.maxCostPerMm) ? scanNode : o.maxCostPerMm;
  const size_t L = r.voxel.size();
  m.stats.terminalSearchSettled = static_cast<int64_t>(L);
  m.stats.terminalRegionSeconds = since(tLumen);
  m.stats.searchSeconds += m.stats.terminalRegionSeconds;
  progress.check();

  // The lumen's radius at a voxel: its depth in the region or the intensity profile's half-maximum
  // radius, the larger (the region is porous where the lumen nears the level).
  auto lumenRadius = [&](const Index3& v) {
    const int32_t sv = r.slot[static_cast<size_t>(g.linear(v[0], v[1], v[2]))];
    return std::max(sv >= 0 ? static_cast<double>(r.depth[static_cast<size_t>(sv)]) : 0.0, radiusAt(v));
  };
  std::vector<uint8_t> suppressed(L, 0);
  std::unordered_set<int64_t> ballDone;  // voxels whose ball is on (the same every time; paths repeat trunks)
  auto suppressPath = [&](const TracedPath& p) {
    for (const Index3& v : p.voxels)
      if (ballDone.insert(g.linear(v[0], v[1], v[2])).second)
        suppressBall(g, r.slot, v, std::isnan(o.suppressRadiusMm) ? 1.5 * lumenRadius(v) + maxSp : o.suppressRadiusMm,
                     suppressed);
  };
  suppressed[static_cast<size_t>(r.slot[static_cast<size_t>(rootLin)])] = 1;
  for (const auto& p : paths_)
    if (p.reached) suppressPath(p);

  std::vector<size_t> added;
  BranchScan scan;
  lastTerminalStop_.clear();
  // Branch ends not taken and terminals left out (terminal_routes.h).
  Ends cut{Ends::kRegionCutInWideLumen}, loop{Ends::kLumenGoesOn}, onRoute{Ends::kOnLaterRoute},
      across{Ends::kAcrossBackground}, faded{Ends::kFadedPastTube};
  const int maxCuts = 2 * std::max(o.count, 4), maxLoops = 8 * maxCuts;
  const std::vector<Step> st = steps(g, m.opt.connectivity);
  const MedialTreeView tree{r.pred, [&](int32_t a, int32_t b) { return mmBetween(g, r.index(a), r.index(b)); },
                            [&](int32_t u, const std::function<void(int32_t, double)>& f) {
                              forEachUncutNeighbour(g, st, r, &r.weight, u, f);
                            }};
  // The paths found, recorded once the scan is done (a terminal a later path runs on through is left out: kept 0).
  const size_t base = paths_.size();
  std::vector<TracedPath> found;
  // Candidates whose medial route runs round a vessel network are left out (terminal_routes.h, kDetourRatio): the
  // routes' lengths from the root, against the lumen's shortest way over the region.
  std::vector<double> geodesicMm = regionDistances(g, st, r, {{r.slot[static_cast<size_t>(rootLin)], 0.0}});
  std::vector<float> sourceMm(L, 0.0f);
  for (const auto& p : paths_) addArcLengths(g, r.slot, p, sourceMm);
  std::vector<uint8_t> kept;
  std::vector<double> endRadius;  // per found path: its terminal's lumen radius + the largest spacing
  int keptCount = 0;
  auto voxelsOf = [&](size_t p) -> const std::vector<Index3>& {
    return p < base ? paths_[p].voxels : found[p - base].voxels;
  };
  while (o.count == 0 || keptCount < o.count) {
    progress.check();
    scan.run(g, r, m.cost, suppressed, o.minLengthMm, maxPerMm, scanNode,
             directRoutes(tree, sourceMm, geodesicMm, kDetourRatio, o.minLengthMm));
    const int64_t best = scan.best;
    if (best < 0 || cut.count > maxCuts || onRoute.count > maxCuts) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "no further branch of the lumen reaches %g mm beyond the paths so far (the farthest %.1f mm)",
                    o.minLengthMm, static_cast<double>(scan.longest));
      lastTerminalStop_ = buf + describeAll(cut, loop, onRoute, across, faded);
      break;
    }
    const int32_t far = ridgeEnd(g, r, suppressed, int32_t(best));
    if (faded.count <= maxLoops && cutFaded(m, r, far, o.suppressRadiusMm, lumenRadius, suppressed, faded)) continue;
    const int32_t end = endOnItsLumen(m.vol, r, suppressed, far, lumenRadius);
    // Not a branch end (the region cut inside a wide lumen, or the lumen going on by another way round a loop): its
    // chain is suppressed like a path's, so branches beyond it still count.
    auto notAnEnd = [&](EndsNotTaken& why, int32_t from, double radiusMm) {
      TracedPath chainOnly;
      for (int32_t w = from; w >= 0 && !suppressed[static_cast<size_t>(w)]; w = r.pred[static_cast<size_t>(w)])
        chainOnly.voxels.push_back(r.index(w));
      why.add(chainOnly.voxels.front(), radiusMm);
      suppressPath(chainOnly);
    };
    if (const double cutWidth =
            cutInsideWideLumen(g, r, o.minLengthMm, lumenRadius, end, scan.anchor[static_cast<size_t>(end)]);
        cutWidth > 0) {
      notAnEnd(cut, end, cutWidth);
      continue;
    }
    // Where two ways round a loop meet: both ways' chains suppressed (the next far end of either is no branch end).
    const double endR = lumenRadius(r.index(end));
    if (const int32_t other = loop.count > maxLoops ? -1
                                                    : lumenGoesOnBeyond(tree, static_cast<int32_t>(best), 2 * maxSp,
                                                                        std::max(o.minLengthMm, 3 * endR + 2 * maxSp),
                                                                        2 * endR + 2 * maxSp);
        other >= 0) {
      notAnEnd(loop, static_cast<int32_t>(best), endR);
      int32_t w = other;  // the other way's chain beyond the zone just suppressed
      for (int k = 0; w >= 0 && suppressed[static_cast<size_t>(w)] && k < 64; ++k) w = r.pred[static_cast<size_t>(w)];
      if (w >= 0 && !suppressed[static_cast<size_t>(w)]) notAnEnd(loop, w, endR), --loop.count;
      continue;
    }
    TracedPath tp = medialPath(g, r, m.cost, end, onPath, voxelsOf);
    if (across.count <= maxCuts && cutRouteGaps(m.vol, st, r, tp, sources, lumenRadius, across, geodesicMm)) continue;
    tp.requested = tp.target = tp.voxels.back();
    tp.reached = true;
    // An earlier terminal this route runs on through (within its lumen) is not a branch end: left out, the new
    // path keeps its route up to where it went on.
    for (const size_t k : terminalsOnRoute(g, found, kept, endRadius, tp)) {
      kept[k] = 0, --keptCount;
      onRoute.add(found[k].target, endRadius[k] - maxSp);
    }
    endRadius.push_back(lumenRadius(tp.target) + maxSp);
    addArcLengths(g, r.slot, tp, sourceMm);
    found.push_back(std::move(tp));
    kept.push_back(1), ++keptCount;
    const TracedPath& p = found.back();
    suppressPath(p);
    // One joined tree: the new path becomes a source of the medial tree, so the next terminal's
    // chain ends where it meets any path so far (two paths that share a lumen share one trunk,
    // not two chains side by side through it).
    addPathSources(g, p, base + found.size() - 1, onPath, sources);
    if (o.count == 0 || keptCount < o.count) medialTree(g, st, r, sources);
  }
  for (size_t k = 0; k < found.size(); ++k)
    if (kept[k]) {
      recordPath(std::move(found[k]));
      added.push_back(paths_.size() - 1);
    }
  if (lastTerminalStop_.empty() && o.count > 0)
    lastTerminalStop_ = "the " + std::to_string(o.count) + " terminals asked for were found" +
                        describeAll(cut, loop, onRoute, across, faded);
  lastTerminalScan_ = describeRegion(g, L, r.depth);
  lastTerminalScan_ += describeRegionChanges(
      g, {r.continuedVoxels, r.continuedPieces, r.spilledVoxels, r.spillAt, r.spillMm, o.continueDimBranches});
  if (static_cast<int>(added.size()) >= o.count && o.count > 0)
    lastTerminalScan_ += describeAll(cut, loop, onRoute, across, faded);
  return added;
}

}  // namespace vs
