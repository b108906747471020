#include "tracking/trunk_join.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "tracking/box_search.h"
#include "tracking/crossing_retrace.h"
#include "tracking/voxel_line.h"

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

// Whether a mm point is lumen (node cost <= lumenLevel).
bool lumenAt(const NodeCost3D& cost, const Vec3& s, double lumenLevel) {
  const Geometry& g = cost.geometry;
  Index3 w;
  for (size_t c = 0; c < 3; ++c) w[c] = static_cast<int64_t>(std::llround(s[c] / g.spacing[c]));
  return g.contains(w) && cost.node[static_cast<size_t>(g.linear(w[0], w[1], w[2]))] <= lumenLevel;
}

// The lumen's chord through mm point p along unit u: the run both ways until a non-lumen run longer than holeMm.
double chordMm(const NodeCost3D& cost, const Vec3& p, const Vec3& u, double lumenLevel, double holeMm) {
  const Geometry& g = cost.geometry;
  const double dt = 0.5 * g.spacing.minCoeff();
  double len = 0;
  for (double sgn : {-1.0, 1.0}) {
    double t = dt, hole = 0, last = 0;
    for (;; t += dt) {
      const Vec3 s = p + sgn * t * u;
      if (!g.containsContinuous(Vec3(s[0] / g.spacing[0], s[1] / g.spacing[1], s[2] / g.spacing[2]))) break;
      if (lumenAt(cost, s, lumenLevel)) {
        hole = 0, last = t;
      } else if ((hole += dt) > holeMm + 1e-9) {
        break;
      }
    }
    len += last;
  }
  return len;
}

// The lumen's widest chord through mm point p normal to unit axis (16 directions, no holes bridged): the diameter of
// a tube of that axis p lies in, wherever in its section p lies (the longest chord through a point of a disc is the
// diameter through it).
double sectionWidthMm(const NodeCost3D& cost, const Vec3& p, const Vec3& axis, double lumenLevel) {
  const Vec3 e1 = axis.unitOrthogonal(), e2 = axis.cross(e1).normalized();
  double w = 0;
  for (int s = 0; s < 16; ++s) {
    const double ang = M_PI * s / 16;
    w = std::max(w, chordMm(cost, p, std::cos(ang) * e1 + std::sin(ang) * e2, lumenLevel, 0));
  }
  return w;
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

// Whether b's voxel j runs beside a there (q: a's voxel nearest to b[j], mm), b's voxels from its parting k on: the
// segment between them is across both paths, not along one - b's voxel nearest to q (b[m]) lies no farther from b[j]
// than q lies from b (beside3). For two straight paths parting at an angle theta, |b[j] - b[m]| / |q - b[m]| =
// tan(theta): beyond 1 b moves more away from a than along it - a wide-angle fork's arm, whose straight line back to
// a runs down the arm's own lumen into the fork's funnel (thin forced 10724: one lumen by every other test, yet past
// the fork). Read from positions, not from the chains' steps (a 26-connected chain's step zigzags by 45 degrees).
bool besideA(const Geometry& g, const std::vector<Index3>& b, size_t k, size_t j, const Vec3& q) {
  double e = std::numeric_limits<double>::infinity();
  size_t m = k;
  for (size_t i = k; i < b.size(); ++i) {
    const double di = (mmOf(g, b[i]) - q).squaredNorm();
    if (di < e) e = di, m = i;
  }
  return (mmOf(g, b[m]) - mmOf(g, b[j])).norm() <= std::sqrt(e);
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

bool joinPartedLumen(const std::vector<Index3>& a, std::vector<Index3>& b, const NodeCost3D& cost, double lumenLevel,
                     double holeMm) {
  const Geometry& g = cost.geometry;
  const std::unordered_map<int64_t, size_t> inA = positions(g, a);
  auto posA = [&](const Index3& v) {
    const auto it = inA.find(g.linear(v[0], v[1], v[2]));
    return it == inA.end() ? std::numeric_limits<size_t>::max() : it->second;
  };
  constexpr size_t none = std::numeric_limits<size_t>::max();
  size_t k = 0;  // b's last voxel of its shared start on a
  while (k + 1 < b.size() && posA(b[k + 1]) != none) ++k;
  if (b.empty() || posA(b[0]) == none || k + 2 >= b.size()) return false;
  for (size_t m = k + 1; m < b.size(); ++m)
    if (posA(b[m]) != none) return false;  // meets a again: joinSharedLumen's
  const size_t pa = posA(b[k]);
  const std::vector<Index3> restA(a.begin() + static_cast<std::ptrdiff_t>(pa), a.end());
  // b's voxels after the parting, one by one while each sees a's nearest voxel through lumen with no waist between.
  size_t last = k, lastNear = 0, prevNear = none;
  double prevD = 0;
  double widest = 0, apart = 0;  // apart: the farthest the two lie apart in one lumen
  for (size_t j = k + 1; j < b.size(); ++j) {
    const Vec3 p = mmOf(g, b[j]);
    size_t near = 0;
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < restA.size(); ++i) {
      const double d = (mmOf(g, restA[i]) - p).squaredNorm();
      if (d < best) best = d, near = i;
    }
    const std::vector<Index3> one{b[j]}, other{restA[near]};
    if (!seesThroughLumen(one, other, cost, lumenLevel, holeMm)) break;
    const Vec3 q = mmOf(g, restA[near]);
    const Vec3 d = q - p;
    // Beside a, not leaving it: a's nearest voxel on a's own way on; one whose nearest is still the parting voxel
    // moves straight away from it (a fork's arm, or the first steps of two paths parting to opposite walls).
    if (near == 0) continue;
    if (near + 1 == restA.size()) break;  // past a's end: nothing of a beside b
    // The same generalised: a voxel whose nearest on a is its predecessor's, and farther from it, moves straight away
    // from that one voxel of a (a fork's arm leaving a's bend; 10501: a turns to z, b runs on in y) - nothing of a
    // runs beside it, so it neither ends nor extends the run nor counts for "apart".
    const bool away = near == prevNear && d.norm() > prevD;
    prevNear = near, prevD = d.norm();
    if (away) continue;
    if (d.norm() > g.spacing.maxCoeff() && !besideA(g, b, k, j, q)) continue;
    // Across the two paths: normal to the line between them and to their mean direction.
    const Vec3 t =
        (mmOf(g, b[std::min(j + 1, b.size() - 1)]) - mmOf(g, b[j - 1])).normalized() +
        (mmOf(g, restA[std::min(near + 1, restA.size() - 1)]) - mmOf(g, restA[near > 0 ? near - 1 : 0])).normalized();
    Vec3 n = t.cross(d);
    if (n.norm() > 1e-9 && d.norm() > g.spacing.maxCoeff()) {
      // Two touching tubes meet at a waist; one lumen, convex across, is no narrower between than at either path.
      n.normalize();
      const double mid = chordMm(cost, 0.5 * (p + q), n, lumenLevel, holeMm);
      if (mid < std::min(chordMm(cost, p, n, lumenLevel, holeMm), chordMm(cost, q, n, lumenLevel, holeMm))) break;
      widest = std::max(widest, chordMm(cost, 0.5 * (p + q), d.normalized(), lumenLevel, holeMm));
      // One lumen between them, no hole bridged: the lumen's run through the middle along the line between them.
      if (chordMm(cost, 0.5 * (p + q), d.normalized(), lumenLevel, 0) < d.norm()) break;
      apart = std::max(apart, d.norm());
    }
    last = j, lastNear = near;
  }
  const Vec3 axisA = mmOf(g, a[std::min(pa + 1, a.size() - 1)]) - mmOf(g, a[pa > 0 ? pa - 1 : 0]);
  const double parentWidth = sectionWidthMm(cost, mmOf(g, a[pa]), axisA.normalized(), lumenLevel);
  // A fork's funnel is about as long as it is wide; two paths in one lumen for longer than its width share a trunk.
  // And what is wide: two daughters of a parent W wide (the lumen's widest chord through a's parting voxel, normal to
  // a) are each at most W wide, so two points inside two touching daughters lie at most 2W apart; paths further
  // apart than that in one lumen (no hole bridged between) are in a lumen wider than the fork (head CTA 63,84,103:
  // 14.8 mm apart from a 4.7 mm parent; the family's forks: at most 1.4 W).
  if (last == k ||
      chainLength(g, std::vector<Index3>(b.begin() + static_cast<std::ptrdiff_t>(k),
                                         b.begin() + static_cast<std::ptrdiff_t>(last) + 1)) <= widest ||
      apart <= 2 * parentWidth)
    return false;
  std::vector<Index3> out(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(pa + lastNear) + 1);
  const std::vector<Index3> bridge = voxelsAfter(out.back(), b[last]);  // ends on b[last]
  out.insert(out.end(), bridge.begin(), bridge.end());
  out.insert(out.end(), b.begin() + static_cast<std::ptrdiff_t>(last) + 1, b.end());
  b = std::move(out);
  return true;
}

}  // namespace vs
