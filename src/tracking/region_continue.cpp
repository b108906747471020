// The terminal scan's lumen region continued along dim branches (region_continue.h).
#include "tracking/region_continue.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <queue>
#include <unordered_map>
#include <utility>

namespace vs {

namespace {

struct Step26 {
  int dx, dy, dz;
  int64_t offset;
  double mm;
};

std::vector<Step26> steps26(const Geometry& g) {
  std::vector<Step26> out;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dx || dy || dz) out.push_back({dx, dy, dz, g.linear(dx, dy, dz), g.stepLength(Vec3(dx, dy, dz))});
  return out;
}

// The candidates reached from the region: per candidate its voxel, distance from the region and predecessor
// (-1: a region voxel).
struct Candidates {
  std::vector<int32_t>
      id;  // per volume voxel, -1: none (a hash map took 1.5 s CPU on the head CTA's 0.4 M voxel region)
  std::vector<int64_t> lin;
  std::vector<float> dist;
  std::vector<int32_t> pred;
  std::vector<uint8_t> settled;
};

template <class F>
void eachNeighbour(const Geometry& g, const std::vector<Step26>& st, int64_t v, F&& f) {
  const Index3 p = g.unlinear(v);
  const bool inner =
      p[0] > 0 && p[1] > 0 && p[2] > 0 && p[0] < g.dims[0] - 1 && p[1] < g.dims[1] - 1 && p[2] < g.dims[2] - 1;
  for (const Step26& s : st)
    if (inner || g.contains(p[0] + s.dx, p[1] + s.dy, p[2] + s.dz)) f(v + s.offset, s.mm);
}

Candidates searchCandidates(const Geometry& g, const std::vector<Step26>& st, const std::vector<int64_t>& regionVoxels,
                            const std::function<bool(int64_t)>& eligible, double maxMm, size_t maxCount) {
  Candidates c;
  c.id.assign(static_cast<size_t>(g.voxelCount()), -1);
  using Item = std::pair<float, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
  auto reach = [&](int64_t nv, double d, int32_t from) {
    if (d > maxMm || !eligible(nv)) return;
    int32_t& slotId = c.id[static_cast<size_t>(nv)];
    if (slotId < 0) {
      if (c.lin.size() >= maxCount) return;
      slotId = static_cast<int32_t>(c.lin.size());
      c.lin.push_back(nv), c.dist.push_back(static_cast<float>(d)), c.pred.push_back(from), c.settled.push_back(0);
    } else if (c.settled[static_cast<size_t>(slotId)] || d >= c.dist[static_cast<size_t>(slotId)]) {
      return;
    }
    const auto k = static_cast<size_t>(slotId);
    c.dist[k] = static_cast<float>(d), c.pred[k] = from;
    heap.push({static_cast<float>(d), slotId});
  };
  for (int64_t v : regionVoxels) eachNeighbour(g, st, v, [&](int64_t nv, double mm) { reach(nv, mm, -1); });
  while (!heap.empty()) {
    const auto [d, u] = heap.top();
    heap.pop();
    const auto k = static_cast<size_t>(u);
    if (c.settled[k] || d > c.dist[k]) continue;
    c.settled[k] = 1;
    eachNeighbour(g, st, c.lin[k], [&](int64_t nv, double mm) { reach(nv, d + mm, u); });
  }
  return c;
}

int32_t findRoot(std::vector<int32_t>& up, int32_t a) {
  while (up[static_cast<size_t>(a)] != a) {
    up[static_cast<size_t>(a)] = up[static_cast<size_t>(up[static_cast<size_t>(a)])];
    a = up[static_cast<size_t>(a)];
  }
  return a;
}

}  // namespace

RegionContinuation continueRegion(const Geometry& g, const NodeCost3D& cost, double level,
                                  const std::vector<int64_t>& regionVoxels, const std::vector<int32_t>& slot,
                                  const std::vector<uint8_t>& excluded, const RegionContinueOptions& o) {
  RegionContinuation out;
  const double weak = o.continueFactor * level, sp = g.spacing.maxCoeff();
  const double wall = o.wallSpacings * sp, reachMm = std::max(wall + o.reachSpacings * sp, o.minReachMm);
  const std::vector<Step26> st = steps26(g);
  const double maxReach = std::max(o.maxReachMm, 2 * reachMm);
  auto eligible = [&](int64_t v) {
    const auto i = static_cast<size_t>(v);
    return slot[i] < 0 && (excluded.empty() || !excluded[i]) &&
           static_cast<double>(cost.nodeWeight) * static_cast<double>(cost.node[i]) <= weak;
  };
  const Candidates c =
      searchCandidates(g, st, regionVoxels, eligible, maxReach, std::max<size_t>(4 * regionVoxels.size(), 100000));
  out.candidates = c.lin.size();
  const size_t N = c.lin.size();
  // The pieces beyond the wall.
  std::vector<int32_t> up(N);
  for (size_t k = 0; k < N; ++k) up[k] = static_cast<int32_t>(k);
  auto beyond = [&](size_t k) { return c.settled[k] && c.dist[k] > wall; };
  for (size_t k = 0; k < N; ++k) {
    if (!beyond(k)) continue;
    eachNeighbour(g, st, c.lin[k], [&](int64_t nv, double) {
      const int32_t j = c.id[static_cast<size_t>(nv)];
      if (j < 0 || !beyond(static_cast<size_t>(j))) return;
      const int32_t a = findRoot(up, static_cast<int32_t>(k)), b = findRoot(up, j);
      if (a != b) up[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
    });
  }
  std::unordered_map<int32_t, std::vector<int32_t>> pieces;
  for (size_t k = 0; k < N; ++k)
    if (beyond(k)) pieces[findRoot(up, static_cast<int32_t>(k))].push_back(static_cast<int32_t>(k));
  // A tube's cross-section at least: a disc of the largest spacing's radius, one shell thick, or 4 voxels.
  const double minRef = std::max(4.0, std::numbers::pi * sp * sp * sp / g.spacing.prod());
  std::vector<uint8_t> taken(N, 0);
  for (auto& [root, ks] : pieces) {
    ++out.pieces;
    // Per shell (one largest spacing of dR beyond the wall) its voxels and bounding box.
    struct Shell {
      double count = 0;
      int64_t lo[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, hi[3] = {INT64_MIN, INT64_MIN, INT64_MIN};
    };
    std::vector<Shell> shell;
    for (int32_t k : ks) {
      const auto s = static_cast<size_t>((c.dist[static_cast<size_t>(k)] - wall) / sp);
      if (shell.size() <= s) shell.resize(s + 1);
      shell[s].count += 1;
      const Index3 p = g.unlinear(c.lin[static_cast<size_t>(k)]);
      for (int a = 0; a < 3; ++a)
        shell[s].lo[a] = std::min(shell[s].lo[a], p[a]), shell[s].hi[a] = std::max(shell[s].hi[a], p[a]);
    }
    // A tube's shell is compact: its area (voxels x voxel volume / the shell's thickness) at least
    // minCompactness x its bounding box's longest side squared (a disc: pi / 4; an ellipse 4:1 ~ 0.2). A sheet's
    // shell is a strip as long as the sheet (a sheet touching the tree along a line keeps the strip's width
    // from shell to shell, so only its shape tells it from a tube).
    auto compact = [&](const Shell& sh) {
      double side = 0;
      for (int a = 0; a < 3; ++a) side = std::max(side, static_cast<double>(sh.hi[a] - sh.lo[a] + 1) * g.spacing[a]);
      return sh.count * g.spacing.prod() / sp >= o.minCompactness * side * side;
    };
    const double ref = std::max({minRef, shell[0].count, shell.size() > 1 ? shell[1].count : 0.0});
    size_t cut = shell.size();
    for (size_t s = 0; s < shell.size() && cut == shell.size(); ++s)
      if ((s >= 2 && shell[s].count > o.widenRatio * ref) || (shell[s].count > 0 && !compact(shell[s]))) cut = s;
    double reach = 0, kept = 0, keptShells = 0;
    for (int32_t k : ks) {
      const double d = c.dist[static_cast<size_t>(k)];
      if (static_cast<size_t>((d - wall) / sp) < cut) reach = std::max(reach, d), kept += 1;
    }
    for (size_t s = 0; s < cut; ++s) keptShells += shell[s].count > 0;
    // A resolved tube: its cross-section (the kept voxels' volume per shell over the shell's thickness) at least
    // minCrossSectionSquares squares of the largest spacing (a tube under that is partial volume, its values say
    // nothing of its lumen; a noise streak is one voxel wide). Counted in voxels, as before, a 2 mm slice volume's
    // strand one slice thick in the slice plane holds 2 mm / (in-plane spacing) voxels per voxel of its cross-section
    // and passed (the 4D-CT trachea's small bronchi, session 18); measured against the spacing across the piece along
    // its direction a bronchus along the slices' normal, 2.3 mm wide on 1 mm pixels, still passed at -876 HU (the
    // scanner resolves less than its pixels): the largest spacing is the grid's resolution on every axis (as minRef
    // above). Isotropic grids: the count as before.
    const double area = keptShells > 0 ? kept * g.spacing.prod() / (keptShells * sp) : 0.0;
    const bool ok = reach >= reachMm && area >= o.minCrossSectionSquares * sp * sp;
    if (!ok) continue;
    ++out.continued;
    out.open += reach >= maxReach - sp;
    for (int32_t k : ks) {
      if (static_cast<size_t>((c.dist[static_cast<size_t>(k)] - wall) / sp) >= cut) continue;
      // The voxel and its way back to the region (through the wall's candidates).
      for (int32_t w = k; w >= 0 && !taken[static_cast<size_t>(w)]; w = c.pred[static_cast<size_t>(w)]) {
        taken[static_cast<size_t>(w)] = 1;
        out.admitted.push_back(c.lin[static_cast<size_t>(w)]);
      }
    }
  }
  return out;
}

}  // namespace vs
