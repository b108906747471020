// The contact re-searches' walk sections and steps (see contact_walk.h).
#include "tracking/contact_walk.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>

namespace vs::walk {

namespace {

// std::cos and std::sin of k pi / 4, k = 0..7, as sectionAt formed them per call (session 45 speedE: 1.7 % of the
// carotid trace), formed once by the same library calls at run time (the angle read through a volatile, so that no
// compile-time folding can give other bits).
struct EightWays {
  double c[8], s[8];
  EightWays() {
    for (int k = 0; k < 8; ++k) {
      volatile double va = k * M_PI / 4;
      const double a = va;
      c[k] = std::cos(a), s[k] = std::sin(a);
    }
  }
};

const EightWays& eightWays() {
  static const EightWays w;
  return w;
}

}  // namespace

Section sectionAt(const Lumen& lu, const Vec3& p, const Vec3& d, double dt, double cap) {
  Section s;
  s.centre = p;
  if (!lu.at(p)) return s;
  s.lumen = true;
  Vec3 u, w;
  normals(d, u, w);
  const EightWays& ways = eightWays();
  double run[8];
  Vec3 e[8];
  for (int k = 0; k < 8; ++k) {
    e[k] = ways.c[k] * u + ways.s[k] * w;
    double t = 0;
    while (t < cap && lu.at(p + (t + dt) * e[k])) t += dt;
    run[k] = t;
    s.radius += t / 8;
  }
  Vec3 shift = Vec3::Zero();
  for (int k = 0; k < 4; ++k) shift += 0.25 * (run[k] - run[k + 4]) * e[k];
  s.centre = p + shift;
  return s;
}

// The section re-centred once on its own lumen (a line a few degrees off the axis drifts from it).
Section centredSection(const Lumen& lu, const Vec3& p, const Vec3& d, double dt, double cap) {
  const Section s = sectionAt(lu, p, d, dt, cap);
  if (!s.lumen) return s;
  const Section t = sectionAt(lu, s.centre, d, dt, cap);
  return t.lumen ? t : s;
}

// One step of a walk along a tube (walksBackToPath, walksBesideToFork): an own section's centre taken, the walk
// turned towards it; or, through a section of no tube's own radius (fused, or cut obliquely in a tight bend), kept to
// its lumen by the centre's sideways shift without taking the centre as the tube's. Returns the next position.
Vec3 takeCentre(const Section& s, double step, Vec3& d, std::vector<Vec3>* centres) {
  if (!centres->empty() && (s.centre - centres->back()).norm() > 0.25 * step)
    d = (d + (s.centre - centres->back()).normalized()).normalized();
  centres->push_back(s.centre);
  return s.centre + step * d;
}
Vec3 keepToLumen(const Vec3& q, const Vec3& side, double step, Vec3& d) {
  if (side.norm() > 0.25 * step) d = (d + (side.normalized() * std::min(1.0, side.norm() / step))).normalized();
  return q + side + step * d;
}

// A step round a bend as tight as the tube's own radius (issue 21, session 37: a child's U right past its fork, 10923):
// where the straight step leaves the lumen, the directions turned from d by 30, 60 and 90 degrees (8 ways round each)
// from the last own centre c, the least turn whose section one step on, normal to the turned direction, is the tube's
// own (radius 0.5-2 rOwn, centred within rOwn, as every walk's own section); of those, the best centred.
bool bendStep(const Lumen& lu, const Vec3& c, const Vec3& d, double step, double rOwn, double dt, double cap,
              Section* out, const std::vector<Vec3>* avoid, double rAvoid) {
  return leastTurn(d, [&](const Vec3& e, double& best) {
    const Vec3 q = c + step * e;
    const Section s = centredSection(lu, q, e, dt, cap);
    const Vec3 off = s.centre - q, side = off - off.dot(e) * e;
    if (!s.lumen || s.radius < 0.5 * rOwn || s.radius > 2 * rOwn || side.norm() > rOwn) return;
    size_t at = 0;
    if (avoid && !avoid->empty() && toPolyline(s.centre, *avoid, &at) <= rAvoid) return;
    if (side.norm() < best) best = side.norm(), *out = s;
  });
}

WalkStep stepOn(const Lumen& lu, const Section& s, const Vec3& q, bool inLeft, double step, double rOwn, double dt,
                double cap, double maxBad, double& bad, Vec3& d, std::vector<Vec3>* centres, Vec3* next,
                const std::vector<Vec3>* avoid, double rAvoid) {
  const Vec3 off = s.centre - q, side = off - off.dot(d) * d;
  if (s.lumen && !inLeft && s.radius >= 0.5 * rOwn && s.radius <= 2 * rOwn && side.norm() <= rOwn) {
    bad = 0;
    *next = takeCentre(s, step, d, centres);
    return WalkStep::Own;
  }
  Section b;
  if (!s.lumen && !centres->empty() && bendStep(lu, centres->back(), d, step, rOwn, dt, cap, &b, avoid, rAvoid)) {
    bad = 0;
    d = (b.centre - centres->back()).normalized();
    centres->push_back(b.centre);
    *next = b.centre + step * d;
    return WalkStep::Bend;
  }
  if ((bad += step) > maxBad) return WalkStep::Lost;
  if (s.lumen && !inLeft) *next = keepToLumen(q, side, step, d);
  return WalkStep::Missed;
}

// The distance from p to the line through c along unit d; and to the polyline through pts.
double toLine(const Vec3& p, const Vec3& c, const Vec3& d) {
  const Vec3 v = p - c;
  return (v - v.dot(d) * d).norm();
}
double toPolyline(const Vec3& p, const std::vector<Vec3>& pts, size_t* nearest) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < pts.size(); ++t) {
    const Vec3 a = pts[t], ab = (t + 1 < pts.size() ? pts[t + 1] : a) - a;
    const double l2 = ab.squaredNorm(), s = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
    const double d = (a + s * ab - p).norm();
    if (d >= best) continue;
    best = d;
    if (nearest) *nearest = s < 0.5 ? t : std::min(t + 1, pts.size() - 1);
  }
  return best;
}

}  // namespace vs::walk
