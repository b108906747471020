// Automatic terminals that are not branch ends: a later path runs on through them, or the lumen goes on beyond them
// by another way (terminal_routes.h).
#include "tracking/terminal_routes.h"

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
                                          "terminal(s) left out: a later path ran on through them within their lumen"};
  static constexpr const char* kMeaning[] = {"where the cost's lumen ends, not the vessel",
                                             "where two ways round a loop of a vessel network meet, not a branch end",
                                             "not a branch end"};
  char buf[400];
  std::snprintf(buf, sizeof buf, "; %d %s (e.g. at (%lld,%lld,%lld), lumen radius %.1f mm), i.e. %s", count, kWhat[why],
                static_cast<long long>(first[0]), static_cast<long long>(first[1]), static_cast<long long>(first[2]),
                radiusMm, kMeaning[why]);
  return buf;
}

}  // namespace vs
