#include "tracking/contact_retrace.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "tracking/box_search.h"

namespace vs {

using retrace::Box;
using retrace::mmOf;

namespace {

struct Lumen {
  const NodeCost3D& cost;
  double level;
  bool at(const Vec3& p) const {
    const Geometry& g = cost.geometry;
    Index3 v;
    for (size_t ax = 0; ax < 3; ++ax) v[ax] = static_cast<int64_t>(std::llround(p[ax] / g.spacing[ax]));
    return g.contains(v) && cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] <= level;
  }
};

// Two unit vectors normal to d.
void normals(const Vec3& d, Vec3& u, Vec3& w) {
  const Vec3 a = std::abs(d[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  u = d.cross(a).normalized();
  w = d.cross(u).normalized();
}

// The tube's radius at p (on its axis, direction d): the mean lumen run out from p in 8 directions
// of the cross-section.
double radiusAt(const Lumen& lu, const Vec3& p, const Vec3& d, double dt, double cap) {
  Vec3 u, w;
  normals(d, u, w);
  double sum = 0;
  for (int k = 0; k < 8; ++k) {
    const double a = k * M_PI / 4;
    const Vec3 e = std::cos(a) * u + std::sin(a) * w;
    double t = 0;
    while (t < cap && lu.at(p + (t + dt) * e)) t += dt;
    sum += t;
  }
  return sum / 8;
}

// Lumen in the cross-section at q (normal d) within `tol` of the line: the centre or one of 8 points
// round it. A staircase's direction is a few degrees off, so the line drifts from the axis.
bool sectionLumen(const Lumen& lu, const Vec3& q, const Vec3& d, double tol) {
  if (lu.at(q)) return true;
  Vec3 u, w;
  normals(d, u, w);
  for (int k = 0; k < 8; ++k) {
    const double a = k * M_PI / 4;
    if (lu.at(q + tol * (std::cos(a) * u + std::sin(a) * w))) return true;
  }
  return false;
}

// How far past s0 (up to `cap`) the line p + s d stays lumen; two sections off the lumen in a row end it.
double runLength(const Lumen& lu, const Vec3& p, const Vec3& d, double s0, double dt, double tol, double cap) {
  int miss = 0;
  double last = s0;
  for (double s = s0; s <= s0 + cap && miss < 2; s += dt)
    if (sectionLumen(lu, p + s * d, d, tol))
      miss = 0, last = s;
    else
      ++miss;
  return last - s0;
}

}  // namespace

ContactRetrace retraceAcrossContact(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                    double lumenLevel, const CrossingOptions& o) {
  ContactRetrace r;
  const Geometry& g = cost.geometry;
  const size_t h = static_cast<size_t>(std::max(1, o.spanSteps)),
               k = static_cast<size_t>(std::max(1, o.directionSteps));
  if (!o.enabled || path.size() < 2 * (h + k) + 1) return r;
  const double vmin = g.spacing.minCoeff(), vmax = g.spacing.maxCoeff(), dt = 0.5 * vmin;
  const double cosTurn = std::cos(o.contactTurnDeg * M_PI / 180.0);
  const Lumen lu{cost, lumenLevel};
  for (size_t i = h + k; i + h + k < path.size(); ++i) {
    const Vec3 a0 = mmOf(g, path[i - h - k]), a1 = mmOf(g, path[i - h]), b0 = mmOf(g, path[i + h]),
               b1 = mmOf(g, path[i + h + k]);
    if ((a1 - a0).norm() <= 0 || (b1 - b0).norm() <= 0) continue;
    const Vec3 tb = (a1 - a0).normalized(), ta = (b1 - b0).normalized();
    if (tb.dot(ta) > cosTurn) continue;
    if (!lu.at(a0) || !lu.at(a1) || !lu.at(b0) || !lu.at(b1)) continue;
    // A crossing, not a fork or a bend: the tube left (L, the stretch before, radius rL) runs on
    // from the turn across the tube entered (E, diameter 2 rE) and then contactReachRadii of its own
    // radii further, and E likewise back across L. At a fork or a bend one of them ends at the
    // other's far wall (family: 0.2-1.9 radii past it at the turns this fired at wrongly with a
    // looser test, 10301's crossing 2.3 / 3.0). Lines from the stretches' inner ends, sections
    // within half a radius of them.
    const Vec3 pc = mmOf(g, path[i]);
    const double rL = radiusAt(lu, a1, tb, dt, 6 * vmax), rE = radiusAt(lu, b0, ta, dt, 6 * vmax);
    const double needL = 2 * rE + o.contactReachRadii * rL, needE = 2 * rL + o.contactReachRadii * rE;
    if (runLength(lu, a1, tb, (pc - a1).dot(tb), dt, 0.5 * rL, needL + dt) < needL ||
        runLength(lu, b0, -ta, (pc - b0).dot(-ta), dt, 0.5 * rE, needE + dt) < needE)
      continue;
    ++r.turns;
    // The block: a disc normal to the tube left's direction through the turn's voxel, one step thick.
    const double R = 2 * vmax, half = 0.5 * (std::abs(tb[0]) * g.spacing[0] + std::abs(tb[1]) * g.spacing[1] +
                                             std::abs(tb[2]) * g.spacing[2]);
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
    if (next.empty() || retrace::farthestFrom(g, next, part) < 2 * vmax) {
      r.why = "no route of its own round the block";
      continue;
    }
    r.oldCost = chainCost(cost, path);
    return retrace::accepted(std::move(r), oldPart, nc, retrace::spliced(path, lo, hi, next));
  }
  return r;
}

}  // namespace vs
