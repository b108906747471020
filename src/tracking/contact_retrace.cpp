#include "tracking/contact_retrace.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "tracking/box_search.h"

namespace vs {

using retrace::Box;
using retrace::mmOf;

namespace {

struct Turn {
  size_t at = 0;
  Vec3 mid{0, 0, 0}, n{0, 0, 0};  // half-way between the lines, unit from the tube left to the tube entered
  double sep = 0;
};

bool lumenAt(const NodeCost3D& cost, const Index3& v, double level) {
  return cost.node[static_cast<size_t>(cost.geometry.linear(v[0], v[1], v[2]))] <= level;
}

}  // namespace

ContactRetrace retraceAcrossContact(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                    double lumenLevel, const CrossingOptions& o) {
  ContactRetrace r;
  const Geometry& g = cost.geometry;
  const size_t h = static_cast<size_t>(std::max(1, o.spanSteps)),
               k = static_cast<size_t>(std::max(1, o.directionSteps));
  if (!o.enabled || path.size() < 2 * (h + k) + 1) return r;
  const double vmin = g.spacing.minCoeff(), vmax = g.spacing.maxCoeff();
  const double cosTurn = std::cos(o.contactTurnDeg * M_PI / 180.0);
  const bool dbg = std::getenv("VS_DBG_CONTACT") != nullptr;
  for (size_t i = h + k; i + h + k < path.size(); ++i) {
    const Vec3 a0 = mmOf(g, path[i - h - k]), a1 = mmOf(g, path[i - h]), b0 = mmOf(g, path[i + h]),
               b1 = mmOf(g, path[i + h + k]);
    if ((a1 - a0).norm() <= 0 || (b1 - b0).norm() <= 0) continue;
    const Vec3 tb = (a1 - a0).normalized(), ta = (b1 - b0).normalized();
    const double c = tb.dot(ta);
    if (c > cosTurn) continue;
    if (!lumenAt(cost, path[i - h - k], lumenLevel) || !lumenAt(cost, path[i - h], lumenLevel) ||
        !lumenAt(cost, path[i + h], lumenLevel) || !lumenAt(cost, path[i + h + k], lumenLevel))
      continue;
    // The lines' closest approach: the tube left goes on towards it (s >= 0), the tube entered
    // comes from before it (t <= 0).
    const Vec3 w = a1 - b0;
    const double d = 1 - c * c;
    if (d < 1e-6) continue;
    const double s = (c * ta.dot(w) - tb.dot(w)) / d, t = (ta.dot(w) - c * tb.dot(w)) / d;
    const Vec3 X1 = a1 + s * tb, X2 = b0 + t * ta;
    const double sep = (X2 - X1).norm();
    (void)sep;
    // The tube left goes on past the turn and the tube entered reaches back before it.
    static const double reachF = std::getenv("VS_CREACH") ? std::atof(std::getenv("VS_CREACH")) : 2.5;
    const Vec3 pi0 = mmOf(g, path[i]);
    auto inLumenLine = [&](const Vec3& p, const Vec3& dd, double reach) {
      const double dt = 0.5 * vmin;
      int nn = 0, in = 0;
      for (double tt = dt; tt <= reach; tt += dt, ++nn) {
        const Vec3 qq = p + tt * dd;
        Index3 v;
        for (size_t ax = 0; ax < 3; ++ax) v[ax] = static_cast<int64_t>(std::llround(qq[ax] / g.spacing[ax]));
        in += g.contains(v) && lumenAt(cost, v, lumenLevel);
      }
      return nn > 0 && 4 * in >= 3 * nn;
    };
    const bool goesOn = inLumenLine(pi0, tb, reachF * vmax), reachesBack = inLumenLine(pi0, -ta, reachF * vmax);
    if (dbg) std::fprintf(stderr, "  goesOn %d reachesBack %d\n", goesOn, reachesBack);
    if (!goesOn || !reachesBack) continue;
    ++r.turns;
    // The block: a disc normal to the tube left's direction through the turn's voxel.
    static const double Rf = std::getenv("VS_CR") ? std::atof(std::getenv("VS_CR")) : 2.0;
    const double R = Rf * vmax;
    const Vec3 pc = mmOf(g, path[i]);
    const double thick =
        std::abs(tb[0]) * g.spacing[0] + std::abs(tb[1]) * g.spacing[1] + std::abs(tb[2]) * g.spacing[2];
    const double half = 0.5 * thick;
    const size_t back = 3 * (h + k);
    const size_t lo = i > back ? i - back : 0, hi = std::min(path.size() - 1, i + back);
    const Box b = retrace::boxAround(g, path, lo, hi, o.dipBoxVoxels);
    if (b.size() > (int64_t(1) << 23)) continue;
    std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
    for (int64_t j = 0; j < b.size(); ++j) {
      const Vec3 dq = mmOf(g, b.voxel(j)) - pc;
      const double al = dq.dot(tb);
      if (std::abs(al) <= half && (dq - al * tb).norm() <= R) blocked[static_cast<size_t>(j)] = 1;
    }
    if (blocked[static_cast<size_t>(b.index(path[lo]))] || blocked[static_cast<size_t>(b.index(path[hi]))]) continue;
    const std::vector<Index3> part = retrace::stretch(path, lo, hi);
    const double oldPart = chainCost(cost, part);
    double nc = 0;
    std::vector<Index3> next = retrace::boxPath(cost, b, blocked, retrace::stepsFor(g, connectivity), part.front(),
                                                part.back(), (1 + o.neckCostSlack) * oldPart, &nc);
    const double far = next.empty() ? 0.0 : retrace::farthestFrom(g, next, part);
    if (dbg)
      std::fprintf(stderr, "  search lo %zu hi %zu old %.3f new %.3f n %zu far %.2f\n", lo, hi, oldPart, nc,
                   next.size(), far);
    if (next.empty() || far < 2 * vmax) continue;
    r.oldCost = chainCost(cost, path);
    return retrace::accepted(std::move(r), oldPart, nc, retrace::spliced(path, lo, hi, next));
  }
  (void)vmin;
  (void)vmax;
  return r;
}

}  // namespace vs
