// Automatic terminals that are not branch ends: a later path runs on through them, or the lumen goes on beyond them
// by another way (terminal_routes.h).
#include "tracking/terminal_routes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <queue>
#include <unordered_map>
#include <unordered_set>

namespace vs {

std::vector<size_t> terminalsOnRoute(const Geometry& g, const std::vector<TracedPath>& found,
                                     const std::vector<uint8_t>& kept, const std::vector<double>& radiusMm,
                                     const TracedPath& p) {
  std::vector<size_t> out;
  for (size_t k = 0; k < found.size(); ++k) {
    if (!kept[k]) continue;
    const Index3& t = found[k].target;
    for (size_t i = p.junctionIndex + 1; i < p.voxels.size(); ++i) {
      const Index3& v = p.voxels[i];
      if (g.stepLength(Vec3(static_cast<double>(v[0] - t[0]), static_cast<double>(v[1] - t[1]),
                            static_cast<double>(v[2] - t[2]))) <= radiusMm[k]) {
        out.push_back(k);
        break;
      }
    }
  }
  return out;
}

int32_t lumenGoesOnBeyond(const MedialTreeView& t, int32_t far, double reachMm, double joinMm, double apartMm) {
  // far's own chain, its first joinMm + reachMm.
  std::unordered_set<int32_t> chainSet;
  std::vector<int32_t> chain;
  double mm = 0;
  for (int32_t w = far; w >= 0 && mm <= joinMm + reachMm; w = t.pred[static_cast<size_t>(w)]) {
    chainSet.insert(w), chain.push_back(w);
    if (const int32_t p = t.pred[static_cast<size_t>(w)]; p >= 0) mm += t.mm(w, p);
  }
  // Whether w's chain, followed for joinMm, stays beside far's (it joins it, or ends within apartMm of it: two
  // chains down one thin lumen may run side by side a long way) or goes the other way round.
  auto otherWay = [&](int32_t w) {
    double walked = 0;
    for (; walked < joinMm; w = t.pred[static_cast<size_t>(w)]) {
      if (chainSet.count(w)) return false;
      const int32_t p = t.pred[static_cast<size_t>(w)];
      if (p < 0) break;
      walked += t.mm(w, p);
    }
    for (const int32_t c : chain)
      if (t.mm(w, c) <= apartMm) return false;
    return true;
  };
  // The voxels within reachMm of far over the region (a small Dijkstra).
  std::unordered_map<int32_t, double> dist{{far, 0.0}};
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  q.push({0.0, far});
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    if (d > dist[u]) continue;
    if (!chainSet.count(u) && otherWay(u)) return u;
    t.neighbours(u, [&](int32_t v, double step) {
      const double nd = d + step;
      if (nd > reachMm) return;
      const auto it = dist.find(v);
      if (it != dist.end() && it->second <= nd) return;
      dist[v] = nd;
      q.push({nd, v});
    });
  }
  return -1;
}

std::string EndsNotTaken::describe() const {
  if (count == 0) return {};
  static constexpr const char* kWhat[] = {"branch end(s) not taken: the lumen region stops inside a wide lumen",
                                          "far end(s) not taken: the lumen goes on beyond them by another way",
                                          "terminal(s) left out: a later path ran on through them within their lumen",
                                          "route(s) across background between two vessels cut from the medial tree",
                                          "terminal end(s) cut back where the chain fell below the half-maximum from "
                                          "its feeding tube's level to the background for a run and turned back"};
  static constexpr const char* kMeaning[] = {"where the cost's lumen ends, not the vessel",
                                             "where two ways round a loop of a vessel network meet, not a branch end",
                                             "not a branch end",
                                             "where the smoothed cost joins vessels the image does not",
                                             "tissue past the vessel's end, not its lumen (terminal_end.h)"};
  char buf[400];
  std::snprintf(buf, sizeof buf, "; %d %s (e.g. at (%lld,%lld,%lld), lumen radius %.1f mm), i.e. %s", count, kWhat[why],
                static_cast<long long>(first[0]), static_cast<long long>(first[1]), static_cast<long long>(first[2]),
                radiusMm, kMeaning[why]);
  return buf;
}

std::vector<uint8_t> directRoutes(const MedialTreeView& t, const std::vector<float>& sourceMm,
                                  const std::vector<double>& geodesicMm, double ratio, double slackMm) {
  const size_t n = t.pred.size();
  std::vector<float> len(n, -1.0f);  // the route's length from the root, -1 until found
  std::vector<int32_t> stack;
  for (size_t u = 0; u < n; ++u) {  // walk up to a node with its length, then unwind
    for (int32_t w = static_cast<int32_t>(u); w >= 0 && len[static_cast<size_t>(w)] < 0;
         w = t.pred[static_cast<size_t>(w)])
      stack.push_back(w);
    while (!stack.empty()) {
      const int32_t a = stack.back();
      stack.pop_back();
      const int32_t p = t.pred[static_cast<size_t>(a)];
      len[static_cast<size_t>(a)] =
          p < 0 ? sourceMm[static_cast<size_t>(a)] : len[static_cast<size_t>(p)] + static_cast<float>(t.mm(a, p));
    }
  }
  std::vector<uint8_t> direct(n);
  for (size_t u = 0; u < n; ++u) direct[u] = len[u] <= ratio * geodesicMm[u] + slackMm;
  return direct;
}

void addArcLengths(const Geometry& g, const std::vector<int32_t>& slot, const TracedPath& p,
                   std::vector<float>& sourceMm) {
  double mm = 0;
  for (size_t i = 0; i < p.voxels.size(); ++i) {
    const Index3& v = p.voxels[i];
    if (i > 0) {
      const Index3& u = p.voxels[i - 1];
      mm += g.stepLength(
          Vec3(static_cast<double>(v[0] - u[0]), static_cast<double>(v[1] - u[1]), static_cast<double>(v[2] - u[2])));
    }
    if (const int32_t s = slot[static_cast<size_t>(g.linear(v[0], v[1], v[2]))]; s >= 0)
      sourceMm[static_cast<size_t>(s)] = static_cast<float>(mm);
  }
}

// The box and distance are forEachVoxelNear's. The distance (the norm of the scaled offset: a square per axis, summed,
// its root, each step monotone) grows with each offset's magnitude and ignores its sign, so the ball's part of a row is
// one interval [-m, m] of dx, m shrinking as |dy| grows: found with a few distance evaluations per slab, not one per
// voxel of the box (most of the box is outside the ball or suppressed already, and balls along a path overlap).
void suppressBall(const Geometry& g, const std::vector<int32_t>& slot, const Index3& v, double rad,
                  std::vector<uint8_t>& suppressed) {
  int64_t ext[3];
  for (int a = 0; a < 3; ++a) ext[a] = static_cast<int64_t>(std::ceil(rad / g.spacing[a]));
  auto within = [&](int64_t dx, int64_t dy, int64_t dz) {
    return g.stepLength(Vec3(static_cast<double>(dx), static_cast<double>(dy), static_cast<double>(dz))) <= rad;
  };
  std::vector<int64_t> rowHalf(static_cast<size_t>(ext[1]) + 1);  // per |dy|: m, -1 for an empty row
  for (int64_t dz = -ext[2]; dz <= ext[2]; ++dz) {
    const int64_t z = v[2] + dz;
    if (z < 0 || z >= g.dims[2]) continue;
    int64_t m = ext[0];
    for (int64_t dy = 0; dy <= ext[1]; ++dy) {
      while (m >= 0 && !within(m, dy, dz)) --m;
      rowHalf[static_cast<size_t>(dy)] = m;
    }
    for (int64_t dy = -ext[1]; dy <= ext[1]; ++dy) {
      const int64_t y = v[1] + dy, half = rowHalf[static_cast<size_t>(std::abs(dy))];
      if (y < 0 || y >= g.dims[1] || half < 0) continue;
      const int64_t x0 = std::max<int64_t>(0, v[0] - half), x1 = std::min(g.dims[0] - 1, v[0] + half);
      const int32_t* row = slot.data() + g.linear(0, y, z);
      for (int64_t x = x0; x <= x1; ++x)
        if (const int32_t s = row[x]; s >= 0) suppressed[static_cast<size_t>(s)] = 1;
    }
  }
}

bool spillNear(const Geometry& g, const std::vector<uint8_t>& spill, const Index3& v, double rad) {
  if (spill.empty()) return false;
  int64_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const auto e = static_cast<int64_t>(std::ceil(rad / g.spacing[a]));
    lo[a] = std::max<int64_t>(0, v[a] - e), hi[a] = std::min(g.dims[a] - 1, v[a] + e);
  }
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x)
        if (spill[static_cast<size_t>(g.linear(x, y, z))] &&
            g.stepLength(Vec3(static_cast<double>(x - v[0]), static_cast<double>(y - v[1]),
                              static_cast<double>(z - v[2]))) <= rad)
          return true;
  return false;
}

void addPathSources(const Geometry& g, const TracedPath& p, size_t pi,
                    std::unordered_map<int64_t, std::pair<size_t, size_t>>& onPath, std::vector<int64_t>& sources) {
  for (size_t i = 0; i < p.voxels.size(); ++i) {
    const int64_t lin = g.linear(p.voxels[i][0], p.voxels[i][1], p.voxels[i][2]);
    if (onPath.emplace(lin, std::make_pair(pi, i)).second) sources.push_back(lin);
  }
}

std::vector<int64_t> scanSources(const Geometry& g, int64_t rootLin, const std::vector<TracedPath>& paths,
                                 std::unordered_map<int64_t, std::pair<size_t, size_t>>& onPath) {
  std::vector<int64_t> sources{rootLin};
  for (size_t p = 0; p < paths.size(); ++p) addPathSources(g, paths[p], p, onPath, sources);
  return sources;
}

}  // namespace vs
