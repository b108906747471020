// The terminal scan's region grown by depth-ordered fronts (region_fronts.h).
#include "tracking/region_fronts.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <numeric>

namespace vs {

namespace {

// The region's neighbours of a slot: 26 (18, 6) steps, from the adjacency's records when given (read in
// slot order: sequential), else through the volume-sized slot array.
struct Neighbours {
  const Geometry& g;
  const std::vector<int64_t>& voxel;
  const std::vector<std::array<int32_t, 3>>& at;
  const std::vector<int32_t>& slot;
  const RegionAdjacency adj;
  std::vector<std::array<int, 3>> step;
  std::vector<int64_t> offset;

  Neighbours(const Geometry& geom, int connectivity, const std::vector<int64_t>& v,
             const std::vector<std::array<int32_t, 3>>& a, const std::vector<int32_t>& s, const RegionAdjacency& ad)
      : g(geom), voxel(v), at(a), slot(s), adj(ad) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int n = std::abs(dx) + std::abs(dy) + std::abs(dz);
          if (n == 0 || (connectivity == 6 && n > 1) || (connectivity == 18 && n > 2)) continue;
          step.push_back({dx, dy, dz});
          offset.push_back(g.linear(dx, dy, dz));
        }
  }
  template <class F>
  void each(size_t i, F&& f) const {
    if (adj.records) {
      const uint32_t* rec = adj.records + i * adj.stride;
      for (uint32_t e = 1; e <= rec[0]; ++e) f(static_cast<size_t>(rec[e] >> 5));
      return;
    }
    const auto& p = at[i];
    const bool inner =
        p[0] > 0 && p[1] > 0 && p[2] > 0 && p[0] < g.dims[0] - 1 && p[1] < g.dims[1] - 1 && p[2] < g.dims[2] - 1;
    for (size_t k = 0; k < step.size(); ++k) {
      if (!inner && !g.contains(p[0] + step[k][0], p[1] + step[k][1], p[2] + step[k][2])) continue;
      const int32_t s = slot[static_cast<size_t>(voxel[i] + offset[k])];
      if (s >= 0) f(static_cast<size_t>(s));
    }
  }
};

int32_t findRoot(std::vector<int32_t>& up, int32_t a) {
  while (up[static_cast<size_t>(a)] != a) {
    up[static_cast<size_t>(a)] = up[static_cast<size_t>(up[static_cast<size_t>(a)])];
    a = up[static_cast<size_t>(a)];
  }
  return a;
}

// The fronts: per slot its front (ids in shell order), per front its shell, voxel count, first voxel.
struct Fronts {
  std::vector<int32_t> of;                       // per slot
  std::vector<int32_t> shell, count, firstSlot;  // firstSlot: its first voxel (slot)
  std::vector<size_t> order;                     // slots grouped by front
  std::vector<size_t> first;                     // per front: its first entry in order (size fronts + 1)
};

Fronts buildFronts(const Neighbours& nb, const std::vector<double>& dist, double shellMm) {
  const size_t L = dist.size();
  std::vector<int32_t> sh(L);
  int32_t maxShell = 0;
  for (size_t i = 0; i < L; ++i) {
    sh[i] = std::isfinite(dist[i]) ? static_cast<int32_t>(dist[i] / shellMm) : 0;
    maxShell = std::max(maxShell, sh[i]);
  }
  std::vector<int32_t> up(L);
  std::iota(up.begin(), up.end(), 0);
  for (size_t i = 0; i < L; ++i)
    nb.each(i, [&](size_t j) {
      if (j > i && sh[j] == sh[i]) {
        const int32_t a = findRoot(up, static_cast<int32_t>(i)), b = findRoot(up, static_cast<int32_t>(j));
        if (a != b) up[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
      }
    });
  // Slots by shell (counting sort), fronts numbered in that order.
  std::vector<size_t> byShell(static_cast<size_t>(maxShell) + 2, 0);
  for (size_t i = 0; i < L; ++i) ++byShell[static_cast<size_t>(sh[i]) + 1];
  std::partial_sum(byShell.begin(), byShell.end(), byShell.begin());
  std::vector<size_t> sorted(L);
  for (size_t i = 0; i < L; ++i) sorted[byShell[static_cast<size_t>(sh[i])]++] = i;
  Fronts f;
  f.of.assign(L, -1);
  std::vector<int32_t> rootFront(L, -1);
  for (size_t i : sorted) {
    const auto rt = static_cast<size_t>(findRoot(up, static_cast<int32_t>(i)));
    if (rootFront[rt] < 0) {
      rootFront[rt] = static_cast<int32_t>(f.shell.size());
      f.shell.push_back(sh[i]);
      f.count.push_back(0);
      f.firstSlot.push_back(static_cast<int32_t>(i));
    }
    const auto c = static_cast<size_t>(rootFront[rt]);
    f.of[i] = static_cast<int32_t>(c);
    ++f.count[c];
  }
  const size_t C = f.shell.size();
  f.first.assign(C + 1, 0);
  for (size_t c = 0; c < C; ++c) f.first[c + 1] = f.first[c] + static_cast<size_t>(f.count[c]);
  f.order.resize(L);
  std::vector<size_t> fill(f.first.begin(), f.first.end() - 1);
  for (size_t i = 0; i < L; ++i) f.order[fill[static_cast<size_t>(f.of[i])]++] = i;
  return f;
}

}  // namespace

RegionFronts regionFronts(const Geometry& g, int connectivity, const std::vector<int64_t>& voxel,
                          const std::vector<std::array<int32_t, 3>>& at, const std::vector<int32_t>& slot,
                          const std::vector<double>& dist, double rootRadiusMm, const RegionFrontOptions& o,
                          const RegionAdjacency& adjacency) {
  const Neighbours nb(g, connectivity, voxel, at, slot, adjacency);
  const double shellMm = g.spacing.maxCoeff();
  const Fronts f = buildFronts(nb, dist, shellMm);
  const size_t C = f.shell.size(), L = voxel.size();
  const double voxelMm3 = g.spacing.prod();
  auto area = [&](size_t c) { return f.count[c] * voxelMm3 / shellMm; };
  RegionFronts out;
  out.spilled.assign(L, 0);
  // The root's own fronts: within a few of its radii (at first a ball around it, then its lumen's
  // cross-section on either side, as one front until they part).
  const double refMm = o.refRadii * rootRadiusMm + 2 * shellMm;
  double ref = 0;
  for (size_t c = 0; c < C && f.shell[c] * shellMm <= refMm; ++c) ref = std::max(ref, area(c));
  out.rootArea = ref;
  auto beyondRef = [&](size_t c) { return f.shell[c] * shellMm > refMm; };
  std::vector<uint8_t> spilled(C, 0);
  std::vector<int32_t> seen(C, -1);
  std::vector<size_t> parentFirst(C + 1, 0);
  std::vector<int32_t> parent;
  for (size_t c = 0; c < C; ++c) {  // in shell order: a front's parents come before it
    int spilledParents = 0;
    for (size_t e = f.first[c]; e < f.first[c + 1]; ++e)
      nb.each(f.order[e], [&](size_t j) {
        const auto p = static_cast<size_t>(f.of[j]);
        if (f.shell[p] >= f.shell[c] || seen[p] == static_cast<int32_t>(c)) return;
        seen[p] = static_cast<int32_t>(c);
        parent.push_back(static_cast<int32_t>(p));
        spilledParents += spilled[p];
      });
    parentFirst[c + 1] = parent.size();
    const int parents = static_cast<int>(parentFirst[c + 1] - parentFirst[c]);
    const bool wide = beyondRef(c) && area(c) > o.maxAreaRatio * ref;
    spilled[c] = wide || (parents > 0 && spilledParents == parents);
    if (wide && spilledParents < parents) {
      ++out.onsets;
      if (out.onsets == 1) {
        const auto& p = at[static_cast<size_t>(f.firstSlot[c])];
        out.firstOnset = {p[0], p[1], p[2]};
        out.firstOnsetMm = f.shell[c] * shellMm;
        out.firstOnsetArea = area(c);
      }
    }
  }
  // Back to where the widening began: a spilled front's parents wider than backOffRatio x the root's
  // front are the spill's own start (a sheet's or blob's fronts widen from the neck where the tree
  // met it), not the tree's.
  for (size_t c = C; c-- > 0;)
    if (spilled[c])
      for (size_t e = parentFirst[c]; e < parentFirst[c + 1]; ++e) {
        const auto p = static_cast<size_t>(parent[e]);
        if (!spilled[p] && beyondRef(p) && area(p) > o.backOffRatio * ref) spilled[p] = 1;
      }
  for (size_t i = 0; i < L; ++i)
    if (spilled[static_cast<size_t>(f.of[i])]) out.spilled[i] = 1, ++out.spilledVoxels;
  return out;
}

}  // namespace vs
