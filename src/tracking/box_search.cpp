#include "tracking/box_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "tracking/open_voxels.h"

namespace vs::retrace {

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

Box boxAround(const Geometry& g, const std::vector<Index3>& path, size_t lo, size_t hi, double margin) {
  Box b;
  for (size_t a = 0; a < 3; ++a) {
    int64_t bl = path[lo][a], bh = path[lo][a];
    for (size_t j = lo; j <= hi; ++j) bl = std::min(bl, path[j][a]), bh = std::max(bh, path[j][a]);
    const int64_t mg = static_cast<int64_t>(std::ceil(margin * g.spacing.minCoeff() / g.spacing[a]));
    b.lo[a] = std::max<int64_t>(0, bl - mg);
    b.n[a] = std::min<int64_t>(g.dims[a] - 1, bh + mg) - b.lo[a] + 1;
  }
  return b;
}

double farthestFrom(const Geometry& g, const std::vector<Index3>& route, const std::vector<Index3>& old) {
  double farthest = 0;
  for (const Index3& v : route) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Index3& w : old) nearest = std::min(nearest, (mmOf(g, v) - mmOf(g, w)).norm());
    farthest = std::max(farthest, nearest);
  }
  return farthest;
}

std::vector<Index3> stretch(const std::vector<Index3>& full, size_t lo, size_t hi) {
  return std::vector<Index3>(full.begin() + static_cast<std::ptrdiff_t>(lo),
                             full.begin() + static_cast<std::ptrdiff_t>(hi) + 1);
}

std::vector<Index3> spliced(const std::vector<Index3>& full, size_t lo, size_t hi, const std::vector<Index3>& part) {
  std::vector<Index3> p(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(lo));
  p.insert(p.end(), part.begin(), part.end());
  p.insert(p.end(), full.begin() + static_cast<std::ptrdiff_t>(hi) + 1, full.end());
  return p;
}

double chainLength(const Geometry& g, const std::vector<Index3>& path) {
  double len = 0;
  for (size_t i = 1; i < path.size(); ++i) len += (mmOf(g, path[i]) - mmOf(g, path[i - 1])).norm();
  return len;
}

using detail::OpenVoxels;

// Dijkstra from `from` to `to` inside the box, blocked voxels never entered; empty when the target
// is not reached at a cost <= cap. Session 39 cache702: the same search, cheaper per voxel - one heap entry per
// voxel (OpenVoxels), a step into a voxel already settled or blocked skipped before its cost is read (no step of
// cost >= 0 lowers a settled voxel's distance), the steps' offsets in the box and the volume computed once, and the
// box test per step only for a voxel within a step of the box's faces.
std::vector<Index3> boxPath(const NodeCost3D& cost, const Box& b, const std::vector<uint8_t>& blocked,
                            const std::vector<Step>& steps, const Index3& from, const Index3& to, double cap,
                            double* outCost, BoxSearchStats* stats) {
  const Geometry& g = cost.geometry;
  const int64_t n = b.size();
  std::vector<double> dist(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<int32_t> prev(static_cast<size_t>(n), -1);
  std::vector<uint8_t> closed = blocked;  // settled or blocked
  struct Offset {
    int64_t box, volume;
    double lengthMm;
  };
  std::vector<Offset> offsets;
  Index3 reach{0, 0, 0};  // the longest step along each axis
  for (const Step& st : steps) {
    offsets.push_back(
        {st.d[0] + b.n[0] * (st.d[1] + b.n[1] * st.d[2]), g.linear(st.d[0], st.d[1], st.d[2]), st.lengthMm});
    for (size_t a = 0; a < 3; ++a) reach[a] = std::max(reach[a], std::abs(st.d[a]));
  }
  const int32_t n0 = static_cast<int32_t>(b.n[0]), n1 = static_cast<int32_t>(b.n[1]);
  BoxSearchStats count;
  OpenVoxels q(n);
  const int64_t s = b.index(from), t = b.index(to);
  dist[static_cast<size_t>(s)] = 0;
  q.set(static_cast<int32_t>(s), 0.0);
  bool reached = false;
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    if (d > cap) break;
    closed[static_cast<size_t>(u)] = 1;
    ++count.settled;
    if (u == t) {
      reached = true;
      break;
    }
    const int32_t ux = u % n0, uyz = u / n0;  // b.voxel(u), in 32 bits (a box holds at most 2^23 voxels)
    const Index3 uv{b.lo[0] + ux, b.lo[1] + uyz % n1, b.lo[2] + uyz / n1};
    const int64_t ul = g.linear(uv[0], uv[1], uv[2]);
    bool inner = true;
    for (size_t a = 0; a < 3; ++a) inner = inner && uv[a] - reach[a] >= b.lo[a] && uv[a] + reach[a] < b.lo[a] + b.n[a];
    for (size_t k = 0; k < offsets.size(); ++k) {
      const Offset& o = offsets[k];
      if (!inner && !b.in({uv[0] + steps[k].d[0], uv[1] + steps[k].d[1], uv[2] + steps[k].d[2]})) continue;
      const int64_t vi = u + o.box;
      if (closed[static_cast<size_t>(vi)]) continue;
      ++count.costsRead;
      const double nd = d + cost.edgeCost(ul, ul + o.volume, o.lengthMm);
      if (nd < dist[static_cast<size_t>(vi)]) {
        dist[static_cast<size_t>(vi)] = nd;
        prev[static_cast<size_t>(vi)] = u;
        q.set(static_cast<int32_t>(vi), nd);
      }
    }
  }
  count.entries = q.entries();
  if (stats) *stats = count;
  if (!reached) return {};
  std::vector<Index3> path;
  for (int64_t i = t; i >= 0; i = prev[static_cast<size_t>(i)]) path.push_back(b.voxel(i));
  std::reverse(path.begin(), path.end());
  *outCost = dist[static_cast<size_t>(t)];
  return path;
}

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

// The widest route's bottleneck in the box from a to b: the highest level at which a and b are
// joined by voxels at or above it (a maximin search; blocked voxels never entered).
double bottleneck(const VolumeF32& sm, double sign, const Box& b, const std::vector<Step>& steps, const Index3& from,
                  const Index3& to, const std::vector<uint8_t>& blocked) {
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
    for (const Step& st : steps) {
      const Index3 u{v[0] + st.d[0], v[1] + st.d[1], v[2] + st.d[2]};
      if (!b.in(u)) continue;
      const int64_t j = b.index(u);
      if (blocked[static_cast<size_t>(j)]) continue;
      const double wj = std::min(w, signedAt(sm, u, sign));
      if (wj > best[static_cast<size_t>(j)]) {
        best[static_cast<size_t>(j)] = wj;
        q.push({wj, j});
      }
    }
  }
  return -std::numeric_limits<double>::infinity();
}

}  // namespace vs::retrace
