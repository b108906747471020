#include "tracking/dip_retrace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>

#include "tracking/box_search.h"

namespace vs {

using retrace::Box;
using retrace::boxPath;
using retrace::mmOf;
using retrace::stepsFor;

namespace {

double signedAt(const VolumeF32& sm, const Index3& v, double sign) { return sign * double(sm.at(v[0], v[1], v[2])); }

// The background round voxel v: the median of the smoothed intensity `radiusMm` away along the 26
// directions (in mm; samples outside the volume left out). Beside two tubes a slice apart most of
// those lie in the tissue round them.
double shellMedian(const VolumeF32& sm, const Index3& v, double radiusMm, double sign) {
  const Geometry& g = sm.geometry();
  std::vector<double> vals;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const Vec3 d = Vec3(dx, dy, dz).normalized();
        const Vec3 q = mmOf(g, v) + radiusMm * d;
        Index3 w;
        for (size_t a = 0; a < 3; ++a) w[a] = static_cast<int64_t>(std::llround(q[a] / g.spacing[a]));
        if (g.contains(w)) vals.push_back(signedAt(sm, w, sign));
      }
  if (vals.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(vals.begin(), vals.begin() + static_cast<std::ptrdiff_t>(vals.size() / 2), vals.end());
  return vals[vals.size() / 2];
}

struct Dip {
  size_t at = 0;
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
  for (size_t i = k; i + k < n; ++i) {
    if (lumen[i] || s[i] > s[i - 1] || s[i] > s[i + 1]) continue;
    double before = -std::numeric_limits<double>::infinity(), after = before;
    bool lumenBefore = false, lumenAfter = false;
    for (size_t j = i - k; j < i; ++j) before = std::max(before, s[j]), lumenBefore |= lumen[j] != 0;
    for (size_t j = i + 1; j <= i + k; ++j) after = std::max(after, s[j]), lumenAfter |= lumen[j] != 0;
    if (!lumenBefore || !lumenAfter) continue;
    const double flank = std::min(before, after);
    const double bg = shellMedian(sm, path[i], o.dipShellVoxels * g.spacing.minCoeff(), sign);
    if (!(flank > bg) || s[i] > bg + o.dipShare * (flank - bg)) continue;
    if (!dips.empty() && i <= dips.back().at + k) continue;
    dips.push_back({i, s[i], flank, bg});
  }
  return dips;
}

// The widest route's bottleneck in the box from a to b: the highest level at which a and b are
// joined by voxels at or above it (a maximin search; blocked voxels never entered).
double bottleneck(const VolumeF32& sm, double sign, const Box& b, const std::vector<retrace::Step>& steps,
                  const Index3& from, const Index3& to) {
  std::vector<double> best(static_cast<size_t>(b.size()), -std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int64_t>;
  std::priority_queue<Item> q;
  const int64_t s0 = b.index(from), t0 = b.index(to);
  best[static_cast<size_t>(s0)] = signedAt(sm, from, sign);
  q.push({best[static_cast<size_t>(s0)], s0});
  while (!q.empty()) {
    const auto [w, i] = q.top();
    q.pop();
    if (w < best[static_cast<size_t>(i)]) continue;
    if (i == t0) return w;
    const Index3 v = b.voxel(i);
    for (const retrace::Step& st : steps) {
      const Index3 u{v[0] + st.d[0], v[1] + st.d[1], v[2] + st.d[2]};
      if (!b.in(u)) continue;
      const int64_t j = b.index(u);
      const double wj = std::min(w, signedAt(sm, u, sign));
      if (wj > best[static_cast<size_t>(j)]) {
        best[static_cast<size_t>(j)] = wj;
        q.push({wj, j});
      }
    }
  }
  return -std::numeric_limits<double>::infinity();
}

// The search round one dip: from dipBack points before it to the brightest of the dipSteps past
// it, among the voxels at or above the widest route's bottleneck, which must lie at least dipLevel
// of the way from the dip to its dimmer flank.
DipRetrace searchAroundDip(const NodeCost3D& cost, const VolumeF32& sm, double sign, const std::vector<Index3>& full,
                           int connectivity, double lumenLevel, const CrossingOptions& o, const Dip& dip) {
  DipRetrace r;
  const Geometry& g = cost.geometry;
  const double level = dip.value + o.dipLevel * (dip.flank - dip.value);
  const size_t k = static_cast<size_t>(std::max(1, o.dipSteps));
  size_t lo = dip.at > size_t(o.dipBack) ? dip.at - size_t(o.dipBack) : 0;
  size_t hi = dip.at + 1;
  for (size_t j = dip.at + 1; j <= std::min(full.size() - 1, dip.at + k); ++j)
    if (signedAt(sm, full[j], sign) > signedAt(sm, full[hi], sign)) hi = j;
  while (lo > 0 && signedAt(sm, full[lo], sign) < level) --lo;
  if (signedAt(sm, full[lo], sign) < level || signedAt(sm, full[hi], sign) < level) {
    r.why = "the path's ends lie below the level";
    return r;
  }
  const Box b = retrace::boxAround(g, full, lo, hi);
  if (b.size() > (int64_t(1) << 23)) {
    r.why = "box too large";
    return r;
  }
  const double widest = bottleneck(sm, sign, b, stepsFor(g, connectivity), full[lo], full[hi]);
  if (widest < level) {
    r.why = "no route above the level";
    return r;
  }
  std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
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
