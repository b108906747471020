#include "tracking/dip_retrace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include "tracking/box_search.h"

namespace vs {

using retrace::bottleneck;
using retrace::Box;
using retrace::boxPath;
using retrace::mmOf;
using retrace::shellMedian;
using retrace::signedAt;
using retrace::stepsFor;

namespace {

struct Dip {
  size_t at = 0, end = 0;  // the lowest point; the run's last point outside the lumen (a long gap), else at
  double value = 0, flank = 0, background = 0;
};

// Path points outside the lumen whose smoothed intensity lies near the background's (within
// dipShare of the way from it to the dimmer of the brightest points dipSteps either side), with
// lumen on both sides: the path jumps a gap between two lumens there. One per run (its lowest).
std::vector<Dip> findDips(const NodeCost3D& cost, const VolumeF32& sm, double sign, const std::vector<Index3>& path,
                          double lumenLevel, const CrossingOptions& o) {
  std::vector<Dip> dips;
  const Geometry& g = cost.geometry;
  const size_t k = static_cast<size_t>(std::max(1, o.dipSteps)), n = path.size();
  if (n < 2 * k + 1) return dips;
  std::vector<double> s(n);
  std::vector<uint8_t> lumen(n);
  for (size_t i = 0; i < n; ++i) {
    s[i] = signedAt(sm, path[i], sign);
    lumen[i] = cost.node[static_cast<size_t>(g.linear(path[i][0], path[i][1], path[i][2]))] <= lumenLevel;
  }
  // The flanks run up to dipSteps points either side, fewer at the path's ends (a terminal just
  // past the gap).
  for (size_t i = 1; i + 1 < n; ++i) {
    if (lumen[i] || s[i] > s[i - 1] || s[i] > s[i + 1]) continue;
    double before = -std::numeric_limits<double>::infinity(), after = before;
    bool lumenBefore = false, lumenAfter = false;
    for (size_t j = i > k ? i - k : 0; j < i; ++j) before = std::max(before, s[j]), lumenBefore |= lumen[j] != 0;
    for (size_t j = i + 1; j <= std::min(n - 1, i + k); ++j) after = std::max(after, s[j]), lumenAfter |= lumen[j] != 0;
    size_t end = i;
    if (!lumenBefore || !lumenAfter) {
      // A gap longer than the flanks (11407: the path to B ran A to its end and crossed 8 points
      // outside the lumen, 6 of them background, to B's last points): the flanks counted from the
      // run of points outside the lumen round the dip, which must have lumen at both ends.
      size_t a = i;
      while (a > 0 && !lumen[a - 1]) --a;
      while (end + 1 < n && !lumen[end + 1]) ++end;
      if (a == 0 || end + 1 == n) continue;
      before = after = -std::numeric_limits<double>::infinity();
      for (size_t j = a > k ? a - k : 0; j < a; ++j) before = std::max(before, s[j]);
      for (size_t j = end + 1; j <= std::min(n - 1, end + k); ++j) after = std::max(after, s[j]);
    }
    const double flank = std::min(before, after);
    const double bg = shellMedian(sm, path[i], o.dipShellVoxels * g.spacing.minCoeff(), sign);
    if (!(flank > bg) || s[i] > bg + o.dipShare * (flank - bg)) continue;
    if (!dips.empty() && i <= std::max(dips.back().at, dips.back().end) + k) continue;
    dips.push_back({i, end, s[i], flank, bg});
  }
  return dips;
}

// Where the two tubes also touch between their fork and the dip, the route above the bottleneck
// can still follow the bright tube the path left and cross where they touch. So the tube left is
// blocked back from the dip while the other tube lies across a gap from the path: at each path
// point, along the jump's direction less its part along the path there, a run below the level and
// then a voxel at or above it (the other tube); the voxels nearer the point than that voxel (less
// half a smallest spacing) are blocked. Short stretches without a gap (where the tubes touch) are
// blocked with the nearest gap's radius; more than 2 largest spacings of path without one end the
// walk (the fork, where the lumens join), so the route reaches the other tube from there.
std::vector<uint8_t> tubeLeftBlocked(const VolumeF32& sm, double sign, const Box& b, const std::vector<Index3>& path,
                                     size_t lo, size_t at, double level) {
  const Geometry& g = sm.geometry();
  const double step = g.spacing.minCoeff(), stopMm = 2 * g.spacing.maxCoeff();
  const Vec3 jump = mmOf(g, path[at + 1]) - mmOf(g, path[at - 1]);
  const auto gapRadius = [&](size_t j) {  // mm; 0 where no gap lies across
    Vec3 t = mmOf(g, path[std::min(j + 2, at - 1)]) - mmOf(g, path[j > lo + 2 ? j - 2 : lo]);
    if (t.norm() > 0) t.normalize();
    Vec3 d = jump - jump.dot(t) * t;
    if (d.norm() < step) return 0.0;
    d.normalize();
    bool gap = false;
    for (double r = step; r <= jump.norm() + g.spacing.maxCoeff(); r += step) {
      const Vec3 q = mmOf(g, path[j]) + r * d;
      Index3 w;
      for (size_t a = 0; a < 3; ++a) w[a] = static_cast<int64_t>(std::llround(q[a] / g.spacing[a]));
      if (!g.contains(w)) break;
      if (signedAt(sm, w, sign) < level)
        gap = true;
      else if (gap)
        return (mmOf(g, w) - mmOf(g, path[j])).norm() - 0.5 * step;
    }
    return 0.0;
  };
  std::vector<std::pair<size_t, double>> balls;  // path point, radius (mm)
  std::vector<size_t> touching;                  // points since the last gap
  double sinceGap = 0, lastR = 0;
  for (size_t j = at - 1;; --j) {
    const double rj = gapRadius(j);
    if (rj > 0) {
      for (size_t k : touching) balls.push_back({k, std::min(lastR, rj)});
      touching.clear();
      balls.push_back({j, rj});
      sinceGap = 0, lastR = rj;
    } else if (!balls.empty()) {
      sinceGap += (mmOf(g, path[j + 1]) - mmOf(g, path[j])).norm();
      if (sinceGap > stopMm) break;
      touching.push_back(j);
    }
    if (j == lo) break;
  }
  std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
  for (const auto& [j, r] : balls) {
    Index3 lo3, hi3;
    for (size_t a = 0; a < 3; ++a) {
      const int64_t m = static_cast<int64_t>(std::ceil(r / g.spacing[a]));
      lo3[a] = std::max(b.lo[a], path[j][a] - m), hi3[a] = std::min(b.lo[a] + b.n[a] - 1, path[j][a] + m);
    }
    for (int64_t z = lo3[2]; z <= hi3[2]; ++z)
      for (int64_t y = lo3[1]; y <= hi3[1]; ++y)
        for (int64_t x = lo3[0]; x <= hi3[0]; ++x)
          if ((mmOf(g, {x, y, z}) - mmOf(g, path[j])).norm() < r) blocked[static_cast<size_t>(b.index({x, y, z}))] = 1;
  }
  return blocked;
}

// The route from full[lo] to full[hi] in the box among the voxels at or above the widest route's
// bottleneck (which must lie at or above `level`), `blocked` never entered; kept when it takes a
// route of its own, is not much longer and has no dip of its own.
DipRetrace routeAbove(const NodeCost3D& cost, const VolumeF32& sm, double sign, const std::vector<Index3>& full,
                      int connectivity, double lumenLevel, const CrossingOptions& o, const Box& b, size_t lo, size_t hi,
                      double level, std::vector<uint8_t> blocked) {
  DipRetrace r;
  const Geometry& g = cost.geometry;
  blocked[static_cast<size_t>(b.index(full[lo]))] = blocked[static_cast<size_t>(b.index(full[hi]))] = 0;
  const double widest = bottleneck(sm, sign, b, stepsFor(g, connectivity), full[lo], full[hi], blocked);
  if (widest < level) {
    r.why = "no route above the level";
    return r;
  }
  for (int64_t i = 0; i < b.size(); ++i)
    if (signedAt(sm, b.voxel(i), sign) < widest) blocked[static_cast<size_t>(i)] = 1;
  const std::vector<Index3> part = retrace::stretch(full, lo, hi);
  const double oldPart = chainCost(cost, part);
  r.oldCost = chainCost(cost, full);
  double c = 0;
  std::vector<Index3> next = boxPath(cost, b, blocked, stepsFor(g, connectivity), part.front(), part.back(),
                                     std::numeric_limits<double>::infinity(), &c);
  if (next.empty()) {
    r.why = "no route above the level";
    return r;
  }
  if (retrace::farthestFrom(g, next, part) < 2 * g.spacing.maxCoeff()) {
    r.why = "the new route stays beside the old one";
    return r;
  }
  if (retrace::chainLength(g, next) > (1 + o.lengthSlack) * retrace::chainLength(g, part)) {
    r.why = "the new route is too long";
    return r;
  }
  std::vector<Index3> p = retrace::spliced(full, lo, hi, next);
  for (const Dip& d : findDips(cost, sm, sign, p, lumenLevel, o))
    if (d.at >= lo && d.at < lo + next.size()) {
      r.why = "the new route dips too (point " + std::to_string(d.at) + ")";
      return r;
    }
  return retrace::accepted(std::move(r), oldPart, c, std::move(p));
}

// The search round one dip: from dipBack points before it to the brightest of the dipSteps past
// it, among the voxels at or above the widest route's bottleneck, which must lie at least dipLevel
// of the way from the dip to its dimmer flank; first with the tube left blocked (tubeLeftBlocked),
// then without.
DipRetrace searchAroundDip(const NodeCost3D& cost, const VolumeF32& sm, double sign, const std::vector<Index3>& full,
                           int connectivity, double lumenLevel, const CrossingOptions& o, const Dip& dip) {
  DipRetrace r;
  const Geometry& g = cost.geometry;
  const double level = dip.value + o.dipLevel * (dip.flank - dip.value);
  const size_t k = static_cast<size_t>(std::max(1, o.dipSteps));
  size_t lo = dip.at > size_t(o.dipBack) ? dip.at - size_t(o.dipBack) : 0;
  size_t hi = dip.at + 1;
  for (size_t j = dip.at + 1; j <= std::min(full.size() - 1, dip.end + k); ++j)
    if (signedAt(sm, full[j], sign) > signedAt(sm, full[hi], sign)) hi = j;
  while (lo > 0 && signedAt(sm, full[lo], sign) < level) --lo;
  if (signedAt(sm, full[lo], sign) < level || signedAt(sm, full[hi], sign) < level) {
    r.why = "the path's ends lie below the level";
    return r;
  }
  const Box b = retrace::boxAround(g, full, lo, hi, o.dipBoxVoxels);
  if (b.size() > (int64_t(1) << 23)) {
    r.why = "box too large";
    return r;
  }
  std::vector<uint8_t> open(static_cast<size_t>(b.size()), 0);
  const double widest = bottleneck(sm, sign, b, stepsFor(g, connectivity), full[lo], full[hi], open);
  if (dip.at > lo && widest >= level) {
    DipRetrace t = routeAbove(cost, sm, sign, full, connectivity, lumenLevel, o, b, lo, hi, level,
                              tubeLeftBlocked(sm, sign, b, full, lo, dip.at, widest));
    if (t.changed) return t;
    r.why = "tube left blocked: " + t.why + "; ";
  }
  DipRetrace plain = routeAbove(cost, sm, sign, full, connectivity, lumenLevel, o, b, lo, hi, level, std::move(open));
  if (!plain.changed) plain.why = r.why + plain.why;
  return plain;
}

}  // namespace

DipRetrace retraceAcrossDip(const NodeCost3D& cost, const std::vector<Index3>& full, int connectivity,
                            double lumenLevel, const CrossingOptions& o) {
  DipRetrace r;
  if (!o.enabled || !o.smoothed || o.dipSteps <= 0 || o.smoothed->geometry().dims != cost.geometry.dims) return r;
  const double sign = o.brightLumen ? 1.0 : -1.0;
  std::vector<Index3> path = full;
  for (int round = 0; round < o.maxRounds; ++round) {
    const std::vector<Dip> dips = findDips(cost, *o.smoothed, sign, path, lumenLevel, o);
    if (round == 0) r.dips = static_cast<int>(dips.size());
    bool changed = false;
    for (const Dip& d : dips) {
      DipRetrace one = searchAroundDip(cost, *o.smoothed, sign, path, connectivity, lumenLevel, o, d);
      if (!one.changed) {
        r.why += (r.why.empty() ? "" : "; ") + one.why;
        continue;
      }
      if (!r.changed) r.oldCost = one.oldCost;
      r.changed = changed = true;
      r.newCost = one.newCost;
      path = std::move(one.voxels);
      break;  // the dips of the new path
    }
    if (!changed) break;
  }
  if (r.changed) r.voxels = std::move(path);
  return r;
}

}  // namespace vs
