#include "tracking/crossing_retrace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>

#include "volume/sample.h"

namespace vs {

namespace {

Vec3 mmOf(const Geometry& g, const Index3& v) {
  return Vec3(double(v[0]) * g.spacing[0], double(v[1]) * g.spacing[1], double(v[2]) * g.spacing[2]);
}

double chainLength(const Geometry& g, const std::vector<Index3>& path) {
  double len = 0;
  for (size_t i = 1; i < path.size(); ++i) len += (mmOf(g, path[i]) - mmOf(g, path[i - 1])).norm();
  return len;
}

// A box of the volume (the original path's, with a margin) and the search inside it.
struct Box {
  Index3 lo{0, 0, 0}, n{0, 0, 0};
  int64_t size() const { return n[0] * n[1] * n[2]; }
  bool in(const Index3& v) const {
    for (size_t a = 0; a < 3; ++a)
      if (v[a] < lo[a] || v[a] >= lo[a] + n[a]) return false;
    return true;
  }
  int64_t index(const Index3& v) const { return (v[0] - lo[0]) + n[0] * ((v[1] - lo[1]) + n[1] * (v[2] - lo[2])); }
  Index3 voxel(int64_t i) const { return {lo[0] + i % n[0], lo[1] + (i / n[0]) % n[1], lo[2] + i / (n[0] * n[1])}; }
};

struct Step {
  Index3 d;
  double lengthMm;
};

std::vector<Step> stepsFor(const Geometry& g, int connectivity) {
  std::vector<Step> s;
  for (int64_t dz = -1; dz <= 1; ++dz)
    for (int64_t dy = -1; dy <= 1; ++dy)
      for (int64_t dx = -1; dx <= 1; ++dx) {
        const int64_t m = std::abs(dx) + std::abs(dy) + std::abs(dz);
        if (m == 0 || (connectivity == 6 && m > 1) || (connectivity == 18 && m > 2)) continue;
        s.push_back({{dx, dy, dz}, mmOf(g, {dx, dy, dz}).norm()});
      }
  return s;
}

// Dijkstra from `from` to `to` inside the box, blocked voxels never entered; empty when the target
// is not reached at a cost <= cap.
std::vector<Index3> boxPath(const NodeCost3D& cost, const Box& b, const std::vector<uint8_t>& blocked,
                            const std::vector<Step>& steps, const Index3& from, const Index3& to, double cap,
                            double* outCost) {
  const Geometry& g = cost.geometry;
  const int64_t n = b.size();
  std::vector<double> dist(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<int32_t> prev(static_cast<size_t>(n), -1);
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  const int64_t s = b.index(from), t = b.index(to);
  dist[static_cast<size_t>(s)] = 0;
  q.push({0.0, static_cast<int32_t>(s)});
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    if (d > dist[static_cast<size_t>(u)]) continue;
    if (d > cap) return {};
    if (u == t) break;
    const Index3 uv = b.voxel(u);
    const int64_t ul = g.linear(uv[0], uv[1], uv[2]);
    for (const Step& st : steps) {
      const Index3 v{uv[0] + st.d[0], uv[1] + st.d[1], uv[2] + st.d[2]};
      if (!b.in(v)) continue;
      const int64_t vi = b.index(v);
      if (blocked[static_cast<size_t>(vi)]) continue;
      const double nd = d + cost.edgeCost(ul, g.linear(v[0], v[1], v[2]), st.lengthMm);
      if (nd < dist[static_cast<size_t>(vi)]) {
        dist[static_cast<size_t>(vi)] = nd;
        prev[static_cast<size_t>(vi)] = u;
        q.push({nd, static_cast<int32_t>(vi)});
      }
    }
  }
  if (!std::isfinite(dist[static_cast<size_t>(t)])) return {};
  std::vector<Index3> path;
  for (int64_t i = t; i >= 0; i = prev[static_cast<size_t>(i)]) path.push_back(b.voxel(i));
  std::reverse(path.begin(), path.end());
  *outCost = dist[static_cast<size_t>(t)];
  return path;
}

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

// The lumen's width (mm) through p along unit d: both ways until the first sample above the level
// (at most `most` each way).
double lumenWidth(const NodeCost3D& cost, const Vec3& p, const Vec3& d, double lumenLevel, double most) {
  const Geometry& g = cost.geometry;
  const double dt = 0.5 * g.spacing.minCoeff();
  double w = 0;
  for (const double sign : {1.0, -1.0}) {
    double t = 0;
    for (; t + dt <= most; t += dt) {
      const Vec3 q = p + sign * (t + dt) * d;
      Index3 v;
      for (size_t a = 0; a < 3; ++a) v[a] = static_cast<int64_t>(std::llround(q[a] / g.spacing[a]));
      if (!g.contains(v) || cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] > lumenLevel) break;
    }
    w += t;
  }
  return w;
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
  const std::vector<Index3> path(full.begin() + static_cast<std::ptrdiff_t>(lo),
                                 full.begin() + static_cast<std::ptrdiff_t>(hi) + 1);
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
    std::vector<Index3> p(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(lo));
    p.insert(p.end(), part.begin(), part.end());
    p.insert(p.end(), full.begin() + static_cast<std::ptrdiff_t>(hi) + 1, full.end());
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

namespace {

// The volume's trilinear sample (the project's one sampler) at p (mm), signed so that the lumen is
// high; NaN outside.
double sampleSigned(const TrilinearSampler& sampler, const Vec3& spacing, const Vec3& p, double sign) {
  const Vec3 index = p.cwiseQuotient(spacing);
  return sampler.inside(index) ? sign * sampler.at(index) : std::numeric_limits<double>::quiet_NaN();
}

struct Section {
  bool two = false;  // own lobe at the path's voxel and another lobe beside it
  Vec3 own{0, 0, 0}, other{0, 0, 0};
  double rOwn = 0, rOther = 0;  // radii of discs of the lobes' areas (mm)
  Vec3 t{0, 0, 1};
  Vec3 ownPeak{0, 0, 0}, otherPeak{0, 0, 0}, neck{0, 0, 0};
};

// The smoothed intensity's section normal to the path at point i (tangent over +-3 points), at the
// level half-way from the point's value to the section rim's median, split into 4-connected lobes.
Section sectionAt(const VolumeF32& sm, double sign, const std::vector<Index3>& path, size_t i) {
  Section sec;
  const Geometry& g = sm.geometry();
  const TrilinearSampler sampler(sm);
  const size_t a = i >= 3 ? i - 3 : 0, b = std::min(path.size() - 1, i + 3);
  Vec3 t = mmOf(g, path[b]) - mmOf(g, path[a]);
  if (t.norm() <= 0) return sec;
  t.normalize();
  sec.t = t;
  Vec3 u = std::abs(t[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  u = (u - u.dot(t) * t).normalized();
  const Vec3 w(t[1] * u[2] - t[2] * u[1], t[2] * u[0] - t[0] * u[2], t[0] * u[1] - t[1] * u[0]);
  const double h = 0.5 * g.spacing.minCoeff();
  const int m = 20;  // half size 10 smallest spacings: two touching tubes of up to ~4 voxels' radius
  const int n = 2 * m + 1;
  const Vec3 c = mmOf(g, path[i]);
  std::vector<double> val(static_cast<size_t>(n * n));
  std::vector<double> rim;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double v = sampleSigned(sampler, g.spacing, c + double(x - m) * h * u + double(y - m) * h * w, sign);
      val[static_cast<size_t>(y * n + x)] = v;
      if ((x == 0 || y == 0 || x == n - 1 || y == n - 1) && std::isfinite(v)) rim.push_back(v);
    }
  const double centre = val[static_cast<size_t>(m * n + m)];
  if (rim.size() < size_t(n) || !std::isfinite(centre)) return sec;
  std::nth_element(rim.begin(), rim.begin() + static_cast<std::ptrdiff_t>(rim.size() / 2), rim.end());
  const double bg = rim[rim.size() / 2];
  // The own lobe's peak: the highest sample within a voxel of the path's voxel (a path voxel off
  // its lumen's axis has a lower value, and a level set from it merges the lobes).
  int peakAt = m * n + m;
  const int pr = std::max(1, static_cast<int>(std::lround(g.spacing.maxCoeff() / h)));
  for (int y = m - pr; y <= m + pr; ++y)
    for (int x = m - pr; x <= m + pr; ++x)
      if ((x - m) * (x - m) + (y - m) * (y - m) <= pr * pr && std::isfinite(val[static_cast<size_t>(y * n + x)]) &&
          val[static_cast<size_t>(y * n + x)] > val[static_cast<size_t>(peakAt)])
        peakAt = y * n + x;
  const double peak = val[static_cast<size_t>(peakAt)];
  // Half-way first; where the neck is filled at that level (touching tubes smoothed), higher levels
  // up to 0.8 of the way from the rim to the point's value.
  // A small tube beside a large one may never be a lobe of its own at a level set from the large
  // one's peak half-way (its neck filled) nor at a high one (its own peak lower): levels in steps.
  for (const double frac : {0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9}) {
    const double level = bg + frac * (peak - bg);
    if (!(peak > level)) return sec;
    std::vector<int> lab(static_cast<size_t>(n * n), -1);
    std::vector<int> area, top;
    std::vector<Vec3> sum;
    for (int s0 = 0; s0 < n * n; ++s0) {
      if (lab[static_cast<size_t>(s0)] >= 0 || !(val[static_cast<size_t>(s0)] >= level)) continue;
      const int l = static_cast<int>(area.size());
      area.push_back(0);
      top.push_back(s0);
      sum.push_back(Vec3::Zero());
      std::vector<int> st{s0};
      lab[static_cast<size_t>(s0)] = l;
      while (!st.empty()) {
        const int q = st.back();
        st.pop_back();
        const int qx = q % n, qy = q / n;
        area[static_cast<size_t>(l)]++;
        if (val[static_cast<size_t>(q)] > val[static_cast<size_t>(top[static_cast<size_t>(l)])])
          top[static_cast<size_t>(l)] = q;
        sum[static_cast<size_t>(l)] += c + double(qx - m) * h * u + double(qy - m) * h * w;
        const int nb[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
        for (const auto& d : nb) {
          const int x = qx + d[0], y = qy + d[1];
          if (x < 0 || y < 0 || x >= n || y >= n) continue;
          const int r = y * n + x;
          if (lab[static_cast<size_t>(r)] < 0 && val[static_cast<size_t>(r)] >= level) {
            lab[static_cast<size_t>(r)] = l;
            st.push_back(r);
          }
        }
      }
    }
    const int own = lab[static_cast<size_t>(peakAt)];
    int other = -1;
    for (int l = 0; l < static_cast<int>(area.size()); ++l)
      if (l != own && (other < 0 || area[static_cast<size_t>(l)] > area[static_cast<size_t>(other)])) other = l;
    if (own < 0 || other < 0) continue;
    const double ao = area[static_cast<size_t>(own)], ax = area[static_cast<size_t>(other)];
    if (ax < 3 || ao < 3) continue;
    sec.two = true;
    const int tq = top[static_cast<size_t>(other)];
    sec.otherPeak = c + double(tq % n - m) * h * u + double(tq / n - m) * h * w;
    sec.ownPeak = c + double(peakAt % n - m) * h * u + double(peakAt / n - m) * h * w;
    // The neck: the lowest sample on the line between the two peaks.
    double lowest = std::numeric_limits<double>::infinity();
    for (int j = 1; j < 20; ++j) {
      const Vec3 q = sec.ownPeak + (double(j) / 20.0) * (sec.otherPeak - sec.ownPeak);
      const double v = sampleSigned(sampler, g.spacing, q, sign);
      if (std::isfinite(v) && v < lowest) lowest = v, sec.neck = q;
    }
    sec.own = sum[static_cast<size_t>(own)] / ao;
    sec.other = sum[static_cast<size_t>(other)] / ax;
    sec.rOwn = std::sqrt(ao / std::numbers::pi) * h;
    sec.rOther = std::sqrt(ax / std::numbers::pi) * h;
    return sec;
  }
  return sec;
}

struct NeckCrossing {
  bool found = false;
  size_t first = 0, last = 0, at = 0;  // the two-lobe stretch and the crossing in it
};

NeckCrossing findNeckCrossing(const VolumeF32& sm, double sign, const std::vector<Index3>& path, int k, int bridge,
                              std::vector<Section>* secsOut) {
  NeckCrossing nc;
  const size_t np = path.size();
  std::vector<Section> secs(np);
  for (size_t i = 0; i < np; ++i) secs[i] = sectionAt(sm, sign, path, i);
  const size_t ku = static_cast<size_t>(std::max(1, k));
  // Stretches of two-lobe sections, gaps of up to `bridge` points bridged (a section through a
  // voxel in the neck shows one lobe).
  size_t i = 0;
  while (i < np) {
    if (!secs[i].two) {
      ++i;
      continue;
    }
    size_t e = i, j = i + 1, gap = 0;
    for (; j < np; ++j) {
      if (secs[j].two) {
        e = j;
        gap = 0;
      } else if (++gap > static_cast<size_t>(bridge)) {
        break;
      }
    }
    // Not within 3k points of the stretch's start: a branch leaving its parent at a fork changes
    // lobe there in the same way (the unit test's re-searched route into B's own bend), while a
    // drift runs along the contact first.
    for (size_t c = i + 3 * ku; c + ku <= e; ++c) {
      const Section &p = secs[c - ku], &q = secs[c + ku];
      if (!p.two || !q.two) continue;
      // A drift goes on along the touching tubes; a tube's own hairpin turns back, its two limbs
      // show as two lobes and passing the turn moves the own lobe to where the other was (thin
      // seed 3: a route re-searched round a single tube's U-turn).
      if (p.t.dot(q.t) <= 0) continue;
      const double d0 = (q.own - p.own).norm();
      if ((q.own - p.other).norm() < d0 && (p.own - q.other).norm() < d0) {
        nc = {true, i, e, c};
        break;
      }
    }
    if (nc.found) break;
    i = e + 1;
  }
  if (secsOut) *secsOut = std::move(secs);
  return nc;
}

}  // namespace

NeckRetrace retraceAcrossNeck(const NodeCost3D& cost, const std::vector<Index3>& full, int connectivity,
                              const CrossingOptions& o) {
  NeckRetrace r;
  if (!o.enabled || !o.smoothed || o.smoothed->empty() || full.size() < 8) return r;
  const Geometry& g = cost.geometry;
  if (o.smoothed->geometry().dims != g.dims) return r;
  const double sign = o.brightLumen ? 1.0 : -1.0;
  const int k = std::max(1, o.neckLobeSteps);
  std::vector<Section> secs;
  const NeckCrossing nc = findNeckCrossing(*o.smoothed, sign, full, k, o.neckBridge, &secs);
  if (!nc.found) return r;
  r.crossings = 1;
  // From before the stretch (before the fork the other tube left from) to some points past the
  // crossing; the box holds the whole stretch (the ends move off the blocked neck below).
  size_t lo = nc.first > size_t(2 * k) ? nc.first - size_t(2 * k) : 0;
  size_t hi = std::min(full.size() - 1, nc.at + size_t(2 * k));
  const size_t boxHi = std::min(full.size() - 1, std::max(hi, nc.last) + size_t(2 * k));
  const double vmin = g.spacing.minCoeff(), vmax = g.spacing.maxCoeff();
  Box b;
  for (size_t a = 0; a < 3; ++a) {
    int64_t bl = full[lo][a], bh = full[lo][a];
    for (size_t j = lo; j <= boxHi; ++j) bl = std::min(bl, full[j][a]), bh = std::max(bh, full[j][a]);
    const int64_t mg = static_cast<int64_t>(std::ceil(12 * vmin / g.spacing[a]));
    b.lo[a] = std::max<int64_t>(0, bl - mg);
    b.n[a] = std::min<int64_t>(g.dims[a] - 1, bh + mg) - b.lo[a] + 1;
  }
  if (b.size() > (int64_t(1) << 23)) {
    r.why = "box too large";
    return r;
  }
  // The neck in every two-lobe section of the stretch: the plane through the lowest sample between
  // the two lobes' peaks, normal to the line between them, sum_a |n_a| s_a either side of it (half
  // that is a plane no 26-step jumps, but the planes of neighbouring sections are shifted and
  // tilted against each other: seed 558 leaked diagonally between them), within half the peaks'
  // distance + a voxel of that line (the contact is narrower than the smaller tube), half the
  // largest spacing either side of the section.
  std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
  // Sections in the stretch's bridged gaps (the path in the neck shows one lobe - exactly where it
  // crosses) take the last two-lobe section's neck, moved along its tangent to the path's point.
  size_t lastTwo = nc.first;
  for (size_t j = nc.first; j <= nc.last; ++j) {
    Section s = secs[j];
    if (s.two) {
      lastTwo = j;
    } else {
      s = secs[lastTwo];
      const Vec3 shift = (mmOf(g, full[j]) - mmOf(g, full[lastTwo])).dot(s.t) * s.t;
      s.neck += shift, s.ownPeak += shift, s.otherPeak += shift;
    }
    // The band's slab along the tubes' direction over 3k points either side: where the path
    // crosses, its own tangent is tilted across the contact and a slab normal to it leaves the
    // straight sections' slabs a gap (the unit test's route went through it).
    const size_t ja = j > size_t(3 * k) ? j - size_t(3 * k) : 0, jb = std::min(full.size() - 1, j + size_t(3 * k));
    Vec3 tl = mmOf(g, full[jb]) - mmOf(g, full[ja]);
    if (tl.norm() > 0) s.t = tl.normalized();
    Vec3 d = s.otherPeak - s.ownPeak;
    d -= d.dot(s.t) * s.t;
    const double dl = d.norm();
    if (dl <= 0) continue;
    const Vec3 n = d / dl;
    // The slab sits at the path point's place along the tubes, not at the neck sample's: where the
    // path bends across the contact its sections are tilted, their necks lie up to 1.7 voxels apart
    // along the tubes, and slabs of a fixed half voxel around them left holes the re-searched route
    // took (the unit test's route crossed again at x 56-58). Along, each slab reaches half-way to
    // the neighbouring points (a diagonal step advances more than a voxel) and a quarter voxel on.
    const Vec3 pj = mmOf(g, full[j]);
    const Vec3 mid = s.neck - (s.neck - pj).dot(s.t) * s.t;
    const double aPrev = j > 0 ? (mmOf(g, full[j - 1]) - pj).dot(s.t) : 0.0;
    const double aNext = j + 1 < full.size() ? (mmOf(g, full[j + 1]) - pj).dot(s.t) : 0.0;
    const double alongLo = std::min({0.0, 0.5 * aPrev, 0.5 * aNext}) - 0.25 * vmax;
    const double alongHi = std::max({0.0, 0.5 * aPrev, 0.5 * aNext}) + 0.25 * vmax;
    const double thick =
        (std::abs(n[0]) * g.spacing[0] + std::abs(n[1]) * g.spacing[1] + std::abs(n[2]) * g.spacing[2]);
    const double lateral = 0.5 * dl + vmax;  // the contact is narrower than the smaller tube
    const double alongMax = std::max(-alongLo, alongHi);
    const double reachMm = std::sqrt(thick * thick + alongMax * alongMax + lateral * lateral) + vmax;
    Index3 c0;
    for (size_t a = 0; a < 3; ++a) c0[a] = static_cast<int64_t>(std::llround(mid[a] / g.spacing[a]));
    Index3 rr;
    for (size_t a = 0; a < 3; ++a) rr[a] = static_cast<int64_t>(std::ceil(reachMm / g.spacing[a]));
    for (int64_t z = c0[2] - rr[2]; z <= c0[2] + rr[2]; ++z)
      for (int64_t y = c0[1] - rr[1]; y <= c0[1] + rr[1]; ++y)
        for (int64_t x = c0[0] - rr[0]; x <= c0[0] + rr[0]; ++x) {
          const Index3 v{x, y, z};
          if (!b.in(v)) continue;
          const Vec3 q = mmOf(g, v) - mid;
          const double along = q.dot(s.t), across = q.dot(n);
          const Vec3 side = q - along * s.t - across * n;
          if (std::abs(across) <= thick && along >= alongLo && along <= alongHi && side.norm() <= lateral)
            blocked[static_cast<size_t>(b.index(v))] = 1;
        }
  }
  // The search's ends off the neck: an end left inside the band and unblocked would be a hole in it
  // (the route would come along the tube left and step into the end from beside it).
  while (lo > 0 && blocked[static_cast<size_t>(b.index(full[lo]))]) --lo;
  while (hi < boxHi && blocked[static_cast<size_t>(b.index(full[hi]))]) ++hi;
  if (blocked[static_cast<size_t>(b.index(full[lo]))] || blocked[static_cast<size_t>(b.index(full[hi]))]) {
    r.why = "the path's ends lie in the neck";
    return r;
  }
  const std::vector<Index3> part(full.begin() + static_cast<std::ptrdiff_t>(lo),
                                 full.begin() + static_cast<std::ptrdiff_t>(hi) + 1);
  const double oldPart = chainCost(cost, part);
  r.oldCost = chainCost(cost, full);
  double c = 0;
  std::vector<Index3> next = boxPath(cost, b, blocked, stepsFor(g, connectivity), part.front(), part.back(),
                                     (1 + o.neckCostSlack) * oldPart, &c);
  if (next.empty()) {
    r.why = "no route within the cost slack with the neck blocked";
    return r;
  }
  if (next == part) {
    r.why = "the same route";
    return r;
  }
  std::vector<Index3> p(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(lo));
  p.insert(p.end(), next.begin(), next.end());
  p.insert(p.end(), full.begin() + static_cast<std::ptrdiff_t>(hi) + 1, full.end());
  const NeckCrossing again = findNeckCrossing(*o.smoothed, sign, p, k, o.neckBridge, nullptr);
  if (again.found) {
    r.why = "the new route crosses too (point " + std::to_string(again.at) + " of " + std::to_string(p.size()) +
            ", stretch " + std::to_string(again.first) + "-" + std::to_string(again.last) + "; searched " +
            std::to_string(lo) + "-" + std::to_string(hi) + ", crossing " + std::to_string(nc.at) + ")";
    return r;
  }
  r.changed = true;
  r.newCost = r.oldCost - oldPart + c;
  r.voxels = std::move(p);
  return r;
}

}  // namespace vs
