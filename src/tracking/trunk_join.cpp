#include "tracking/trunk_join.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "tracking/box_search.h"
#include "tracking/crossing_retrace.h"

namespace vs {

namespace {

using retrace::mmOf;

constexpr double kSameCost = 1e-6;  // relative: float rounding of equal sums

// Every voxel of `from` reaches the nearest voxel of `to` along a straight line through lumen, with
// non-lumen runs of at most holeMm (the cost's lumen is patchy inside a wide sinus: session 24, bulb1).
bool seesThroughLumen(const std::vector<Index3>& from, const std::vector<Index3>& to, const NodeCost3D& cost,
                      double lumenLevel, double holeMm) {
  const Geometry& g = cost.geometry;
  const double dt = 0.5 * g.spacing.minCoeff();
  for (const Index3& v : from) {
    const Vec3 p = mmOf(g, v);
    Vec3 q = p;
    double best = std::numeric_limits<double>::infinity();
    for (const Index3& u : to) {
      const double d = (mmOf(g, u) - p).squaredNorm();
      if (d < best) best = d, q = mmOf(g, u);
    }
    const double len = std::sqrt(best);
    double hole = 0;
    for (double t = 0; t <= len + 1e-9; t += dt) {
      const Vec3 s = len > 0 ? Vec3(p + (t / len) * (q - p)) : p;
      Index3 w;
      for (size_t c = 0; c < 3; ++c) w[c] = static_cast<int64_t>(std::llround(s[c] / g.spacing[c]));
      const bool lumen = g.contains(w) && cost.node[static_cast<size_t>(g.linear(w[0], w[1], w[2]))] <= lumenLevel;
      hole = lumen ? 0 : hole + dt;
      if (hole > holeMm + 1e-9) return false;
    }
  }
  return true;
}

double chainLength(const Geometry& g, const std::vector<Index3>& st) {
  double len = 0;
  for (size_t q = 1; q < st.size(); ++q) len += (mmOf(g, st[q]) - mmOf(g, st[q - 1])).norm();
  return len;
}

std::unordered_map<int64_t, size_t> positions(const Geometry& g, const std::vector<Index3>& path) {
  std::unordered_map<int64_t, size_t> at;
  for (size_t i = 0; i < path.size(); ++i) at.emplace(g.linear(path[i][0], path[i][1], path[i][2]), i);
  return at;
}

}  // namespace

int joinSharedLumen(std::vector<Index3>& a, std::vector<Index3>& b, const NodeCost3D& cost, double lumenLevel,
                    double holeMm, const std::unordered_set<int64_t>& researched) {
  const Geometry& g = cost.geometry;
  int changed = 0;
  std::unordered_map<int64_t, size_t> inA = positions(g, a);
  auto posA = [&](const Index3& v) {
    const auto it = inA.find(g.linear(v[0], v[1], v[2]));
    return it == inA.end() ? std::numeric_limits<size_t>::max() : it->second;
  };
  constexpr size_t none = std::numeric_limits<size_t>::max();
  for (size_t k = 0; k + 1 < b.size();) {
    const size_t pa = posA(b[k]);
    if (pa == none || posA(b[k + 1]) != none) {
      ++k;
      continue;
    }
    size_t m = k + 2;  // b leaves a after k: where does it meet a again?
    while (m < b.size() && posA(b[m]) == none) ++m;
    if (m == b.size()) break;  // parted for good
    const size_t pb = posA(b[m]);
    if (pb <= pa) {  // meets a behind where it left: not one stretch of both
      k = m;
      continue;
    }
    const std::vector<Index3> sa(a.begin() + static_cast<std::ptrdiff_t>(pa),
                                 a.begin() + static_cast<std::ptrdiff_t>(pb) + 1);
    const std::vector<Index3> sb(b.begin() + static_cast<std::ptrdiff_t>(k),
                                 b.begin() + static_cast<std::ptrdiff_t>(m) + 1);
    // Routes of one cost are one route (ties two searches broke differently). Of two that differ, the dearer one is
    // taken only where it is the cheaper per mm (corner37: the cheaper cuts the inside of a curl, see the header).
    const double ca = chainCost(cost, sa), cb = chainCost(cost, sb);
    const bool tie = std::abs(ca - cb) <= kSameCost * std::max(ca, cb);
    const double perA = ca / chainLength(g, sa), perB = cb / chainLength(g, sb);
    const bool dearerCentred = !tie && (ca > cb ? perA < perB : perB < perA);
    if ((!tie && !dearerCentred) || !seesThroughLumen(sb, sa, cost, lumenLevel, holeMm) ||
        !seesThroughLumen(sa, sb, cost, lumenLevel, holeMm)) {
      k = m;
      continue;
    }
    auto onResearch = [&](const std::vector<Index3>& st) {
      return std::any_of(st.begin() + 1, st.end() - 1,
                         [&](const Index3& v) { return researched.count(g.linear(v[0], v[1], v[2])) > 0; });
    };
    if (dearerCentred ? cb > ca : onResearch(sb) && !onResearch(sa)) {
      a.erase(a.begin() + static_cast<std::ptrdiff_t>(pa), a.begin() + static_cast<std::ptrdiff_t>(pb) + 1);
      a.insert(a.begin() + static_cast<std::ptrdiff_t>(pa), sb.begin(), sb.end());
      inA = positions(g, a);
      changed |= 1;
      k = m;
    } else {
      b.erase(b.begin() + static_cast<std::ptrdiff_t>(k), b.begin() + static_cast<std::ptrdiff_t>(m) + 1);
      b.insert(b.begin() + static_cast<std::ptrdiff_t>(k), sa.begin(), sa.end());
      changed |= 2;
      k += sa.size() - 1;
    }
  }
  return changed;
}

}  // namespace vs
