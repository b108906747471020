// Internal to the shortest-path engine: the graph/cost models the search loop is templated
// over. GridModel: an implicit grid with K neighbour directions and one of three cost models
// (node, node + sign, per edge), reading and writing the packed node records; CsrModel: an
// explicit graph with flat arrays.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>

#include "graph/node_store.h"
#include "graph/record_layout.h"
#include "util/parallel.h"

namespace vs::engine {

enum class CostKind { Node, NodeSign, Edge };

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
  std::array<double, K> halfLen{};  // len * w_g / 2 (node models)
  std::array<double, K> lenZ{};     // len * w_z (sign model)
  std::array<int, K> dx{}, dy{}, dz{};
  int64_t nx = 1, ny = 1, nz = 1;
  // 3-D grids keep their records in 8^3 bricks (record_layout.h); 2-D grids in rows (a row of 3
  // records around a node already shares lines there, and its 3 rows fit in cache).
  static constexpr bool kBrick = !(K == 4 || K == 8);
  static constexpr Directions<K> kDir{};
  BrickLayout L;

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
      reach = std::max<uint32_t>(reach, uint32_t(std::abs(graph.linearOffset(k))));
    }
    shift = chunkShift(graph);
    n = nx * ny * nz;
    if constexpr (kBrick) L = BrickLayout(nx, ny, nz);
  }

  // Index of node v's record (node ids are linear; 3-D records are bricked).
  int64_t recIdx(uint32_t v) const {
    if constexpr (kBrick)
      return L.of(v);
    else
      return int64_t(v);
  }
  int64_t recordCount() const {
    if constexpr (kBrick)
      return L.recordCount();
    else
      return n;
  }
  double& T(uint32_t v) const { return R[recIdx(v)].t; }
  StateCell& S(uint32_t v) const { return R[recIdx(v)].s; }

  // Lazy record initialisation: the records are split into chunks of 2^shift consecutive node
  // ids, 2^shift >= reach (the largest |linear offset| of a neighbour), so the neighbourhood of a
  // node lies in at most three chunks (bricked 3-D records: one chunk per brick layer, 8 slices,
  // and a neighbourhood lies in at most two). A chunk is filled (T = +inf, -inf masked; state = no
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
  int64_t chunkCount() const {
    if constexpr (kBrick)
      return L.nbz;
    else
      return (n + (int64_t(1) << shift) - 1) >> shift;
  }
  // Where the two-thread full map splits the node ids: the first node of the middle slice (row
  // in 2-D), or 0 when the grid is too thin for the split band (one neighbour reach each side).
  int64_t splitId() const {
    const int64_t layers = (K == 4 || K == 8) ? ny : nz;
    if (layers < 8 || nx < 3 || ny < 3) return 0;
    // Bricked records: split at a brick layer, so the two threads never write one cache line.
    if (kBrick && layers >= 4 * BrickLayout::kB) return ((layers / 2) & ~BrickLayout::kMask) * layerSize();
    return (layers / 2) * layerSize();
  }
  // Nodes per slice (row in 2-D): the neighbours across the split lie in the adjacent one.
  int64_t layerSize() const { return (K == 4 || K == 8) ? nx : nx * ny; }
  bool isReady(uint32_t v) const {
    if constexpr (kBrick)
      return ready[L.zOf(v) >> BrickLayout::kLog] != 0;
    else
      return ready[v >> shift] != 0;
  }

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
    if constexpr (kBrick) {
      fillSlab(ch);
      return;
    }
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
        if constexpr (CK == CostKind::Edge)
          rc.c = 0.f;
        else
          rc.c = c[v];
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

  // Bricked records: fills brick layer ch (slices 8ch .. 8ch+7), row by row of each slice.
  void fillSlab(int64_t ch) const {
    const int64_t z1 = std::min(nz, (ch + 1) << BrickLayout::kLog);
    for (int64_t z = ch << BrickLayout::kLog; z < z1; ++z)
      for (int64_t y = 0; y < ny; ++y) {
        const bool innerRow = nx >= 3 && y >= 1 && y <= ny - 2 && z >= 1 && z <= nz - 2;
        const uint8_t sRow = uint8_t((innerRow ? kInterior : 0) | kNoDirection);
        const int64_t v0 = nx * (y + ny * z);
        for (int64_t x0 = 0; x0 < nx; x0 += BrickLayout::kB) {  // one brick row: consecutive records
          NodeRec* const rr = R + L.at(x0, y, z);
          const int64_t len = std::min(BrickLayout::kB, nx - x0);
          for (int64_t j = 0; j < len; ++j) {
            NodeRec& rc = rr[j];
            const int64_t v = v0 + x0 + j;
            rc.t = (mask.empty() || mask[size_t(v)] != 0) ? kInf : -kInf;
            if constexpr (CK == CostKind::Edge)
              rc.c = 0.f;
            else
              rc.c = c[v];
            rc.s = sRow;
            rc.sign = CK == CostKind::NodeSign ? uint8_t(sign[v] != 0) : uint8_t(0);
            rc.pad = 0;
          }
        }
        R[L.at(0, y, z)].s = kNoDirection;
        R[L.at(nx - 1, y, z)].s = kNoDirection;
      }
    ready[ch] = 1;
  }

  // Makes sure the records of u and all its neighbours are filled. O(1) when they are.
  void ensure(uint32_t u) const {
    if constexpr (kBrick) {
      const int64_t z = L.zOf(u);
      const int64_t lo = std::max<int64_t>(0, z - 1) >> BrickLayout::kLog;
      const int64_t hi = std::min<int64_t>(nz - 1, z + 1) >> BrickLayout::kLog;
      if (!ready[lo]) fillChunk(lo);
      if (!ready[hi]) fillChunk(hi);
      return;
    }
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
        kBrick ? std::max<int64_t>(1, (int64_t(1) << 20) / L.slabRecords())
               : std::max<int64_t>(1, (int64_t(1) << 20) >> shift));
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
      for (int ry = -1; ry <= 1; ++ry) {
        const NodeRec* p = R + (int64_t(u) + ry * nx);
        __builtin_prefetch(p - 1, 1);
        __builtin_prefetch(p + 1, 1);
      }
    } else {
      const int64_t r = recIdx(u);
      const BrickLayout::Steps st = L.steps(r);
      for (int rz = 0; rz <= 2; ++rz)
        for (int ry = 0; ry <= 2; ++ry) {
          const NodeRec* p = R + (r + st.y[ry] + st.z[rz]);
          __builtin_prefetch(p + st.x[0], 1);
          __builtin_prefetch(p + st.x[2], 1);
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
    const int64_t ru = recIdx(u);
    NodeRec* const pu = R + ru;
    const double cu = double(pu->c);
    const uint8_t su = pu->sign;
    if (stateU & kInterior) {
      // Branch-light: all K candidate totals are compared first (no branch depends on the
      // neighbours' loads, so they all issue at once), then only the improving neighbours
      // (bits of a mask, equal totals included) take f's path, with the very same weights.
      double w[K];
      int64_t o[K];  // record-index offsets of the neighbours
      if constexpr (kBrick) {
        const BrickLayout::Steps st = L.steps(ru);
#pragma GCC unroll 26
        for (int k = 0; k < K; ++k) o[k] = st.x[kDir.d[k].x + 1] + st.y[kDir.d[k].y + 1] + st.z[kDir.d[k].z + 1];
      } else {
#pragma GCC unroll 26
        for (int k = 0; k < K; ++k) o[k] = off[k];
      }
      uint32_t better = 0;
#pragma GCC unroll 26
      for (int k = 0; k < K; ++k) {
        const NodeRec& rv = pu[o[k]];
        w[k] = weight(u, rv, k, cu, su);
        better |= uint32_t(Tu + w[k] <= rv.t) << k;  // equal totals too: f breaks the tie
      }
      while (better) {
        const int k = __builtin_ctz(better);
        better &= better - 1;
        NodeRec& rv = pu[o[k]];
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
        NodeRec& rv = R[recIdx(v)];
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

}  // namespace vs::engine
