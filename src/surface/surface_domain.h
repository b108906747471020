// One octant's 3D search domain of the surface extraction (surface_detail.h).
#pragma once

#include "surface/surface_detail.h"

namespace vs::surface_detail {

// The 3D search domain of one octant: its box (planes included), the node costs there and the
// search band. It depends on the cost and the octant only, so an edited side reuses it.
struct OctantDomain {
  Index3 lo{0, 0, 0}, box{1, 1, 1};
  GridGraph graph;
  std::vector<float> cost;
  std::vector<uint8_t> band;  // search mask: within two voxels of an iso crossing

  OctantDomain(const Shared& s, const SurfaceCost& sc, const OctantSigns& sign) {
    const Index3& d = s.vol.dims();
    for (int a = 0; a < 3; ++a) {
      lo[a] = sign[a] > 0 ? s.center[a] : 0;
      const int64_t hi = sign[a] > 0 ? d[a] - 1 : s.center[a];
      box[a] = hi - lo[a] + 1;
    }
    const Vec3& sp = s.vol.geometry().spacing;
    graph = GridGraph(box, {sp[0], sp[1], sp[2]}, s.opt.connectivity);
    cost.resize(static_cast<size_t>(graph.nodeCount()));
    for (int64_t z = 0; z < box[2]; ++z)
      for (int64_t y = 0; y < box[1]; ++y) {
        const int64_t cx = lo[0] - s.costLo[0], cy = lo[1] + y - s.costLo[1], cz = lo[2] + z - s.costLo[2];
        const float* src = sc.node.data() + cx + s.costDims[0] * (cy + s.costDims[1] * cz);
        std::copy(src, src + box[0], cost.data() + box[0] * (y + box[1] * z));
      }
    // The search band: voxels within two voxels of an iso crossing. Paths on the surface never
    // leave it, so searching inside it only saves the exploration of the volume around the
    // surface; a path the band cannot hold (a gap) is searched again on the whole box.
    std::vector<uint8_t> side(cost.size());
    parallelFor(0, box[2], [&](int64_t z0, int64_t z1) {
      for (int64_t z = z0; z < z1; ++z)
        for (int64_t y = 0; y < box[1]; ++y)
          for (int64_t x = 0; x < box[0]; ++x)
            side[static_cast<size_t>(graph.node(x, y, z))] = s.inside(s.vol(lo[0] + x, lo[1] + y, lo[2] + z));
    });
    std::vector<uint8_t> crossing(cost.size(), 0);
    forEachVoxel([&](int64_t n, auto&& anyNeighbor) {
      crossing[static_cast<size_t>(n)] =
          anyNeighbor([&](int64_t m) { return side[static_cast<size_t>(m)] != side[static_cast<size_t>(n)]; });
    });
    band.assign(cost.size(), 0);
    forEachVoxel([&](int64_t n, auto&& anyNeighbor) {
      band[static_cast<size_t>(n)] = crossing[static_cast<size_t>(n)] ||
                                     anyNeighbor([&](int64_t m) { return crossing[static_cast<size_t>(m)] != 0; });
    });
  }

  // Calls f(node, anyNeighbor) for every voxel of the box, slices in parallel; anyNeighbor(pred)
  // tells whether pred holds for one of the node's in-box neighbours.
  template <class F>
  void forEachVoxel(F&& f) const {
    const int K = graph.directionCount();
    parallelFor(0, box[2], [&](int64_t z0, int64_t z1) {
      for (int64_t z = z0; z < z1; ++z)
        for (int64_t y = 0; y < box[1]; ++y)
          for (int64_t x = 0; x < box[0]; ++x) {
            const int64_t n = graph.node(x, y, z);
            const bool interior = x > 0 && y > 0 && z > 0 && x + 1 < box[0] && y + 1 < box[1] && z + 1 < box[2];
            f(n, [&](auto&& pred) {
              for (int k = 0; k < K; ++k) {
                if (!interior) {
                  const auto& o = graph.offset(k);
                  if (!graph.contains(x + o[0], y + o[1], z + o[2])) continue;
                }
                if (pred(n + graph.linearOffset(k))) return true;
              }
              return false;
            });
          }
    });
  }

  // The minimum-cost path a -> b (voxel positions) inside the band of the sub-box regionLo..regionHi
  // (box coordinates, inclusive; the ends always take part); if the band has a gap there, inside
  // the band of the whole box, then inside the whole box. Voxel indices of the volume; empty if
  // there is no path at all.
  std::vector<Index3> path(const Vec3& a, const Vec3& b, const Index3& regionLo, const Index3& regionHi,
                           SurfaceLevelStats& st) {
    st.paths += 1;
    useRegion(regionLo, regionHi);
    Path p = search(local_, localNode(a), localNode(b), st);
    Index3 offset = local_.lo;
    if (p.empty()) {
      useRegion({0, 0, 0}, {box[0] - 1, box[1] - 1, box[2] - 1});
      p = search(local_, localNode(a), localNode(b), st);
      offset = {0, 0, 0};
    }
    if (p.empty()) {
      const int64_t src = graph.node(int64_t(a[0]) - lo[0], int64_t(a[1]) - lo[1], int64_t(a[2]) - lo[2]);
      const int64_t dst = graph.node(int64_t(b[0]) - lo[0], int64_t(b[1]) - lo[1], int64_t(b[2]) - lo[2]);
      ShortestPathSearch full(graph, GridCost::nodes(cost), {src});
      p = full.pathTo(dst);
      st.nodesSettled += full.settledCount();
      st.edgesScanned += full.settledCount() * graph.directionCount();
    }
    std::vector<Index3> out;
    out.reserve(p.voxels.size());
    for (const auto& q : p.voxels)
      out.push_back({q[0] + offset[0] + lo[0], q[1] + offset[1] + lo[1], q[2] + offset[2] + lo[2]});
    return out;
  }

 private:
  // The search inside one sub-box (its own small graph, costs and band), reused while the sub-box
  // stays the same: a search over the whole box would initialise its records in chunks of whole
  // slices for every short path.
  struct Local {
    Index3 lo{0, 0, 0}, hi{-1, -1, -1};
    GridGraph graph;
    std::vector<float> cost;
    std::vector<uint8_t> band;
    std::unique_ptr<ShortestPathSearch> search;
  } local_;

  void useRegion(const Index3& rlo, const Index3& rhi) {
    if (local_.search && rlo == local_.lo && rhi == local_.hi) return;
    local_.search.reset();  // it references the graph and arrays replaced below
    local_.lo = rlo;
    local_.hi = rhi;
    const Index3 d{rhi[0] - rlo[0] + 1, rhi[1] - rlo[1] + 1, rhi[2] - rlo[2] + 1};
    local_.graph = GridGraph(d, graph.spacing(), graph.connectivity());
    local_.cost.resize(static_cast<size_t>(local_.graph.nodeCount()));
    local_.band.resize(local_.cost.size());
    for (int64_t z = 0; z < d[2]; ++z)
      for (int64_t y = 0; y < d[1]; ++y) {
        const size_t from = static_cast<size_t>(graph.node(rlo[0], rlo[1] + y, rlo[2] + z));
        const size_t to = static_cast<size_t>(local_.graph.node(0, y, z));
        std::copy_n(cost.begin() + static_cast<std::ptrdiff_t>(from), d[0],
                    local_.cost.begin() + static_cast<std::ptrdiff_t>(to));
        std::copy_n(band.begin() + static_cast<std::ptrdiff_t>(from), d[0],
                    local_.band.begin() + static_cast<std::ptrdiff_t>(to));
      }
  }
  int64_t localNode(const Vec3& p) const {
    return local_.graph.node(int64_t(p[0]) - lo[0] - local_.lo[0], int64_t(p[1]) - lo[1] - local_.lo[1],
                             int64_t(p[2]) - lo[2] - local_.lo[2]);
  }
  static Path search(Local& l, int64_t src, int64_t dst, SurfaceLevelStats& st) {
    uint8_t& bs = l.band[static_cast<size_t>(src)];
    uint8_t& bd = l.band[static_cast<size_t>(dst)];
    const uint8_t bandSrc = bs, bandDst = bd;
    bs = bd = 1;
    if (!l.search) {
      SearchOptions so;
      so.mask = l.band;
      l.search = std::make_unique<ShortestPathSearch>(l.graph, GridCost::nodes(l.cost), std::vector<int64_t>{src}, so);
    } else {
      l.search->restart({src});
    }
    Path p = l.search->pathTo(dst);
    bs = bandSrc;  // restored: the next search sees the same band
    bd = bandDst;
    st.nodesSettled += l.search->settledCount();
    st.edgesScanned += l.search->settledCount() * l.graph.directionCount();
    return p;
  }
};

}  // namespace vs::surface_detail
