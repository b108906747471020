#include "tracking/crossing_retrace.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/box_search.h"
#include "volume/sample.h"

namespace vs {

using retrace::Box;
using retrace::boxPath;
using retrace::chainLength;
using retrace::mmOf;
using retrace::Step;
using retrace::stepsFor;

namespace {

// Blocks the tube the path leaves at the step where the two touch: voxels within the step's size
// of the path's points from the step back to where the tube entered no longer lies alongside
// (the point moved across by the step is out of the lumen twice in a row), and a step's length
// beyond, on the near side of the plane half-way across (up to half a voxel past it).
void blockBefore(const NodeCost3D& cost, const Box& b, const std::vector<Index3>& path, const LateralStep& s,
                 double lumenLevel, std::vector<uint8_t>& blocked) {
  const Geometry& g = cost.geometry;
  const double r = s.lateralMm;
  Index3 reach;
  for (size_t a = 0; a < 3; ++a) reach[a] = static_cast<int64_t>(std::ceil(r / g.spacing[a]));
  double arc = 0, beyond = -1;
  int out = 0;
  const double half = 0.5 * g.spacing.minCoeff();  // the plane itself and half a voxel beyond
  for (size_t j = s.after + 1; j-- > 0;) {
    if (j < s.before) arc += (mmOf(g, path[j + 1]) - mmOf(g, path[j])).norm();
    const Vec3 qj = mmOf(g, path[j]);
    if (beyond < 0 && j < s.before) {
      const Vec3 side = qj + r * s.normal;
      Index3 v;
      for (size_t a = 0; a < 3; ++a) v[a] = static_cast<int64_t>(std::llround(side[a] / g.spacing[a]));
      const bool in = g.contains(v) && cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] <= lumenLevel;
      out = in ? 0 : out + 1;
      if (out >= 2 || arc > 40 * r) beyond = arc;
    }
    if (beyond >= 0 && arc > beyond + r) break;
    for (int64_t z = path[j][2] - reach[2]; z <= path[j][2] + reach[2]; ++z)
      for (int64_t y = path[j][1] - reach[1]; y <= path[j][1] + reach[1]; ++y)
        for (int64_t x = path[j][0] - reach[0]; x <= path[j][0] + reach[0]; ++x) {
          const Index3 v{x, y, z};
          if (!b.in(v)) continue;
          const Vec3 p = mmOf(g, v);
          if ((p - qj).norm() <= r && (p - s.mid).dot(s.normal) < half) blocked[static_cast<size_t>(b.index(v))] = 1;
        }
  }
}

// Whether the line from p (mm) along unit d stays in the lumen for `reach` mm (all but a quarter of
// its samples, half a voxel apart, at or below the lumen level; outside the volume is not lumen).
bool inLumen(const NodeCost3D& cost, const Vec3& p, const Vec3& d, double reach, double lumenLevel) {
  const Geometry& g = cost.geometry;
  const double dt = 0.5 * g.spacing.minCoeff();
  int n = 0, in = 0;
  for (double t = dt; t <= reach; t += dt, ++n) {
    const Vec3 q = p + t * d;
    Index3 v;
    for (size_t a = 0; a < 3; ++a) v[a] = static_cast<int64_t>(std::llround(q[a] / g.spacing[a]));
    in += g.contains(v) && cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] <= lumenLevel;
  }
  return n > 0 && 4 * in >= 3 * n;
}

// The lumen's extent (mm) through p along unit d, both ways to its last lumen sample before a run
// of samples above the level longer than holeMm (at most `most` each way): a wide lumen whose cost
// is patchy (noise, a lumen level near its intensity) is one lumen, not a sieve of narrow ones.
double lumenSpan(const NodeCost3D& cost, const Vec3& p, const Vec3& d, double lumenLevel, double most, double holeMm) {
  const Geometry& g = cost.geometry;
  const double dt = 0.5 * g.spacing.minCoeff();
  double w = 0;
  for (const double sign : {1.0, -1.0}) {
    double last = 0, hole = 0;
    for (double t = dt; t <= most && hole <= holeMm; t += dt) {
      const Vec3 q = p + sign * t * d;
      Index3 v;
      for (size_t a = 0; a < 3; ++a) v[a] = static_cast<int64_t>(std::llround(q[a] / g.spacing[a]));
      if (g.contains(v) && cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] <= lumenLevel)
        last = t, hole = 0;
      else
        hole += dt;
    }
    w += last;
  }
  return w;
}

// The lumen's width (mm) through p along unit d: both ways until the first sample above the level
// (at most `most` each way), i.e. its extent with no hole bridged.
double lumenWidth(const NodeCost3D& cost, const Vec3& p, const Vec3& d, double lumenLevel, double most) {
  return lumenSpan(cost, p, d, lumenLevel, most, 0.0);
}

}  // namespace

namespace {

// The spans (path steps between the two stretches) tried: spanSteps, then longer ones up to
// driftSteps, each about 1.5x the one before.
std::vector<size_t> spansFor(const CrossingOptions& o) {
  std::vector<size_t> spans{static_cast<size_t>(std::max(1, o.spanSteps))};
  const int driftSteps = o.driftSteps;
  for (size_t h = spans[0]; driftSteps > 0;) {
    h = std::max(h + 1, h * 3 / 2);
    if (h > static_cast<size_t>(driftSteps)) break;
    spans.push_back(h);
  }
  return spans;
}

}  // namespace

std::vector<LateralStep> findLateralSteps(const Geometry& g, const std::vector<Index3>& path, const CrossingOptions& o,
                                          const NodeCost3D* cost, double lumenLevel) {
  const size_t k0 = static_cast<size_t>(std::max(1, o.directionSteps));
  std::vector<LateralStep> cand;
  // The step must exceed a voxel staircase's own steps: a z step of a path along a vessel that
  // slopes gently through thick slices is sideways too.
  const double minStep = std::max(o.minStepVoxels * g.spacing.minCoeff(), 1.25 * g.spacing.maxCoeff());
  const double cosPar = std::cos(o.parallelDeg * M_PI / 180.0);
  const std::vector<size_t> spans = spansFor(o);
  for (size_t si = 0; si < spans.size(); ++si) {
    const size_t h = spans[si];
    const bool drift = si > 0;
    if (drift && !cost) break;  // without the lumen a drift is any bend
    // A drift's stretches are as long as its span: their directions (end to end over a staircase)
    // are then good to about a voxel across the span.
    const size_t k = drift ? std::max(k0, h) : k0;
    for (size_t i = h + k; i + h + k < path.size(); ++i) {
      const Vec3 a0 = mmOf(g, path[i - h - k]), a1 = mmOf(g, path[i - h]), b0 = mmOf(g, path[i + h]),
                 b1 = mmOf(g, path[i + h + k]);
      const Vec3 tb = (a1 - a0).normalized(), ta = (b1 - b0).normalized();
      if (tb.dot(ta) < cosPar) continue;
      const Vec3 t = (tb + ta).normalized();
      // Between the two stretches' lines (their centroids, so one staircase step does not count).
      Vec3 cb = Vec3::Zero(), ca = Vec3::Zero();
      for (size_t j = 0; j <= k; ++j) cb += mmOf(g, path[i - h - j]), ca += mmOf(g, path[i + h + j]);
      const Vec3 d = (ca - cb) / double(k + 1);
      const Vec3 lat = d - d.dot(t) * t;
      const double l = lat.norm(), along = (b0 - a1).dot(t);
      if (l < minStep || (!drift && l < o.steepness * std::abs(along))) continue;
      const Vec3 n = lat / l;
      // Two tubes side by side: the one left goes on well past the step, the one entered reaches
      // back before it (a single tube's own bend does neither; nor does a child that leaves its
      // parent and turns parallel to it).
      if (cost && !(inLumen(*cost, a1, tb, o.reachLeft * l, lumenLevel) &&
                    inLumen(*cost, b0, -ta, o.reachEntered * l, lumenLevel)))
        continue;
      // A drift: the other tube alongside the stretch before it, the tube left alongside the one after.
      if (cost && drift &&
          !(inLumen(*cost, a1 + l * n, tb, l, lumenLevel) && inLumen(*cost, b0 - l * n, -ta, l, lumenLevel)))
        continue;
      // ... and the step goes from one tube's axis to the other's: at least about the two radii
      // (their half-widths across both the step and the direction), not across one tube.
      if (cost) {
        const Vec3 w =
            Vec3(t[1] * n[2] - t[2] * n[1], t[2] * n[0] - t[0] * n[2], t[0] * n[1] - t[1] * n[0]).normalized();
        const double radii =
            0.5 * (lumenWidth(*cost, a1, w, lumenLevel, 4 * l) + lumenWidth(*cost, b0, w, lumenLevel, 4 * l));
        if (l < (drift ? o.driftRadii : o.radiiShare) * radii) continue;
        // ... and not a step inside one lumen several times its size both along the step and
        // across it (a wide sinus, a fork's widening): two tubes side by side are about a step
        // wide across it where they touch, and two steps along it.
        const Vec3 mid = 0.5 * (a1 + b0);
        const double wide = o.oneLumenSteps * l, hole = o.lumenHoleVoxels * g.spacing.minCoeff();
        if (wide > 0 && lumenSpan(*cost, mid, n, lumenLevel, wide, hole) >= wide &&
            lumenSpan(*cost, mid, w, lumenLevel, wide, hole) >= wide)
          continue;
      }
      LateralStep s;
      s.before = i - h;
      s.after = i + h;
      s.mid = 0.5 * (a1 + b0);
      s.normal = n;
      s.lateralMm = l;
      s.drift = drift;
      cand.push_back(s);
    }
  }
  // Steps first (as found before drifts were looked for), then drifts; strongest first in each.
  std::sort(cand.begin(), cand.end(), [](const LateralStep& a, const LateralStep& b) {
    return a.drift != b.drift ? !a.drift : a.lateralMm > b.lateralMm;
  });
  std::vector<LateralStep> out;
  for (const LateralStep& s : cand) {
    bool overlaps = false;
    for (const LateralStep& t : out) overlaps |= s.before <= t.after + k0 && t.before <= s.after + k0;
    if (!overlaps) out.push_back(s);
  }
  return out;
}

double chainCost(const NodeCost3D& cost, const std::vector<Index3>& path) {
  const Geometry& g = cost.geometry;
  double c = 0;
  for (size_t i = 1; i < path.size(); ++i) {
    const Index3& a = path[i - 1];
    const Index3& b = path[i];
    c += cost.edgeCost(g.linear(a[0], a[1], a[2]), g.linear(b[0], b[1], b[2]), (mmOf(g, b) - mmOf(g, a)).norm());
  }
  return c;
}

CrossingRetrace retraceAcrossCrossings(const NodeCost3D& cost, const std::vector<Index3>& full, int connectivity,
                                       double lumenLevel, const CrossingOptions& o) {
  CrossingRetrace r;
  if (!o.enabled || full.size() < 2) return r;
  const Geometry& g = cost.geometry;
  std::vector<LateralStep> steps = findLateralSteps(g, full, o, &cost, lumenLevel);
  r.steps = static_cast<int>(steps.size());
  if (steps.empty()) return r;
  // The stretch searched again: around the strongest step, from windowBack steps' lengths before
  // it (back past the fork the other tube left from) to windowAhead after it.
  const double l0 = steps.front().lateralMm;
  size_t lo = steps.front().before, hi = steps.front().after;
  for (double arc = 0; lo > 0 && arc < o.windowBack * l0; --lo)
    arc += (mmOf(g, full[lo]) - mmOf(g, full[lo - 1])).norm();
  for (double arc = 0; hi + 1 < full.size() && arc < o.windowAhead * l0; ++hi)
    arc += (mmOf(g, full[hi + 1]) - mmOf(g, full[hi])).norm();
  const std::vector<Index3> path = retrace::stretch(full, lo, hi);
  for (LateralStep& s : steps) s.before -= std::min(s.before, lo), s.after -= std::min(s.after, lo);
  steps.resize(1);
  const double vmin = g.spacing.minCoeff();
  const double marginMm = std::max(o.marginSteps * l0, 12 * vmin);
  Box b;
  for (size_t a = 0; a < 3; ++a) {
    int64_t bl = path[0][a], bh = path[0][a];
    for (const Index3& v : path) bl = std::min(bl, v[a]), bh = std::max(bh, v[a]);
    const int64_t m = static_cast<int64_t>(std::ceil(marginMm / g.spacing[a]));
    b.lo[a] = std::max<int64_t>(0, bl - m);
    b.n[a] = std::min<int64_t>(g.dims[a] - 1, bh + m) - b.lo[a] + 1;
  }
  if (b.size() > (int64_t(1) << 23)) {
    r.why = "box too large";
    return r;
  }
  r.oldCost = chainCost(cost, full);
  const double oldPart = chainCost(cost, path);
  const double cap = oldPart + o.costSlack * r.oldCost;
  const double departure = o.departSteps * l0;
  const double oldLength = chainLength(g, full);
  const std::vector<Step> nbr = stepsFor(g, connectivity);
  std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
  std::vector<Index3> cur = path;
  double curCost = oldPart;
  // A step that has no route around it in the lumen is a tube's own bend: the path found before
  // it was blocked is kept (the first round's failure keeps the input path).
  auto accept = [&](std::vector<Index3>&& part, double c, const char* why) {
    std::vector<Index3> p = retrace::spliced(full, lo, hi, part);
    if (chainLength(g, p) > oldLength * (1 + o.lengthSlack)) {
      r.why = "the route with the crossing blocked is too long";
      return r;
    }
    // A new route (through a tube of its own), not the same tube's voxels shuffled.
    double far = 0;
    for (const Index3& v : part) {
      double near = std::numeric_limits<double>::infinity();
      for (const Index3& u : path) near = std::min(near, (mmOf(g, v) - mmOf(g, u)).squaredNorm());
      far = std::max(far, near);
    }
    if (std::sqrt(far) < departure) {
      r.why = "the route with the crossing blocked runs in the same tube";
      return r;
    }
    r.changed = true;
    r.newCost = r.oldCost - oldPart + c;
    r.voxels = std::move(p);
    r.why = why;
    return r;
  };
  for (int round = 1; round <= o.maxRounds; ++round) {
    for (const LateralStep& s : steps) {
      blockBefore(cost, b, cur, s, lumenLevel, blocked);
    }
    blocked[static_cast<size_t>(b.index(path.front()))] = 0;
    blocked[static_cast<size_t>(b.index(path.back()))] = 0;
    r.rounds = round;
    double c = 0;
    std::vector<Index3> next = boxPath(cost, b, blocked, nbr, path.front(), path.back(), cap, &c);
    if (next.empty()) {
      if (round > 1) return accept(std::move(cur), curCost, "the remaining steps are bends of its own tube");
      r.why = "no route in the lumen with the crossing blocked";
      return r;
    }
    // Later rounds look for sharp steps only: a route forced round the blocks bends gently where
    // it meets them, and taken for a drift that drives it into the other tube (seed 510).
    CrossingOptions ro = o;
    ro.driftSteps = 0;
    steps = findLateralSteps(g, next, ro, &cost, lumenLevel);
    cur = std::move(next);
    curCost = c;
    if (steps.empty()) return accept(std::move(cur), curCost, "");
  }
  r.why = "still stepping sideways";
  return r;
}

}  // namespace vs
