#include "tracking/support_retrace.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "tracking/auto_cost.h"
#include "tracking/box_search.h"
#include "tracking/path_support.h"

namespace vs {

namespace {

using retrace::Box;
using retrace::mmOf;

// The support test's verdict per voxel (path_support.h), each voxel asked once.
class Support {
 public:
  Support(const NodeCost3D& cost, const CrossingOptions& o) : cost_(cost), o_(o) {}
  bool at(const Index3& v) { return of(v).supported; }
  // Background, not a dim tube: unsupported and no brighter than the local background.
  bool background(const Index3& v) {
    const VoxelSupport& s = of(v);
    return !s.supported && s.contrast <= 0;
  }
  std::vector<UnsupportedStretch> stretches(const std::vector<Index3>& path) {
    return unsupportedStretches(cost_.geometry, path,
                                pathSupport(path, cost_, *o_.autoCost, *o_.smoothed, *o_.background, *o_.estimate));
  }

 private:
  const VoxelSupport& of(const Index3& v) {
    const int64_t key = cost_.geometry.linear(v[0], v[1], v[2]);
    const auto it = known_.find(key);
    if (it != known_.end()) return it->second;
    return known_.emplace(key, pathSupport({v}, cost_, *o_.autoCost, *o_.smoothed, *o_.background, *o_.estimate)[0])
        .first->second;
  }
  const NodeCost3D& cost_;
  const CrossingOptions& o_;
  std::unordered_map<int64_t, VoxelSupport> known_;
};

// Blocks the background a flagged stretch runs through: the unsupported voxels joined to its voxels (26-connected)
// up to the stretch's own length from them (it crosses no more background than that). Noise leaves single supported
// voxels in the background; the fill goes round them, as a route would.
void blockStretch(const Geometry& g, const Box& b, const std::vector<Index3>& path, const UnsupportedStretch& s,
                  Support& support, std::vector<uint8_t>& blocked) {
  std::vector<Index3> seeds(path.begin() + static_cast<std::ptrdiff_t>(s.first),
                            path.begin() + static_cast<std::ptrdiff_t>(s.last) + 1);
  const auto within = [&](const Index3& w) {
    for (const Index3& v : seeds)
      if ((mmOf(g, w) - mmOf(g, v)).norm() <= s.lengthMm) return true;
    return false;
  };
  std::vector<Index3> queue = seeds;
  for (const Index3& v : seeds) blocked[static_cast<size_t>(b.index(v))] = 1;
  while (!queue.empty()) {
    const Index3 v = queue.back();
    queue.pop_back();
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          const Index3 w{v[0] + dx, v[1] + dy, v[2] + dz};
          if (!b.in(w) || blocked[static_cast<size_t>(b.index(w))] || !within(w) || !support.background(w)) continue;
          blocked[static_cast<size_t>(b.index(w))] = 1;
          queue.push_back(w);
        }
  }
}

}  // namespace

SupportRetrace retraceUnsupported(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                  const CrossingOptions& o) {
  SupportRetrace r;
  r.oldCost = chainCost(cost, path);
  if (!o.autoCost || !o.background || !o.estimate || !o.smoothed || path.size() < 3) return r;
  Support support(cost, o);
  std::vector<UnsupportedStretch> flagged = support.stretches(path);
  r.stretches = static_cast<int>(flagged.size());
  if (flagged.empty()) return r;
  const Geometry& g = cost.geometry;
  // The tree's route round the hop may run far from it (11702: through branch 4 and the curled branch's first half):
  // the whole volume, as large as the other re-searches' boxes may be.
  Box b;
  b.n = g.dims;
  if (b.size() > (int64_t(1) << 23)) {
    r.why = "volume too large for the support re-search";
    return r;
  }
  std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
  const std::vector<retrace::Step> steps = retrace::stepsFor(g, connectivity);
  std::vector<Index3> route = path;
  for (int round = 0; round < std::max(1, o.maxRounds); ++round) {
    for (const UnsupportedStretch& s : flagged) blockStretch(g, b, route, s, support, blocked);
    blocked[static_cast<size_t>(b.index(path.front()))] = 0;
    blocked[static_cast<size_t>(b.index(path.back()))] = 0;
    double c = 0;
    route = retrace::boxPath(cost, b, blocked, steps, path.front(), path.back(),
                             std::numeric_limits<double>::infinity(), &c);
    ++r.rounds;
    if (route.empty()) {
      r.why = "no route with the stretch without lumen blocked";
      return r;
    }
    flagged = support.stretches(route);
    if (flagged.empty()) return retrace::accepted(r, r.oldCost, c, std::move(route));
  }
  r.why = "every route searched again still crosses a stretch without lumen";
  return r;
}

}  // namespace vs
