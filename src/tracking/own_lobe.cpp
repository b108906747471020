#include "tracking/own_lobe.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/cross_section.h"
#include "volume/plane_basis.h"

namespace vs {

namespace {

constexpr float kFar = kSectionFar;

int32_t findRoot(std::vector<int32_t>& parent, int32_t a) {
  while (parent[static_cast<size_t>(a)] != a) {
    parent[static_cast<size_t>(a)] = parent[static_cast<size_t>(parent[static_cast<size_t>(a)])];
    a = parent[static_cast<size_t>(a)];
  }
  return a;
}

// The component (inside = 1) of samples beyond the level 4-connected to `seed`; false when the
// seed is not beyond it. heightAt(u) gives sample u's height (sc.height[u], formed when first asked).
template <class HeightAt>
bool componentOf(int n, int seed, LobeScratch& sc, HeightAt&& heightAt) {
  const size_t nn = static_cast<size_t>(n) * static_cast<size_t>(n);
  sc.inside.assign(nn, 0);
  if (!(heightAt(static_cast<size_t>(seed)) > 0)) return false;
  sc.stack.clear();
  sc.stack.push_back(seed);
  sc.inside[static_cast<size_t>(seed)] = 1;
  floodGrid4(n, sc.stack, [&](int k) {
    const size_t u = static_cast<size_t>(k);
    if (sc.inside[u] || !(heightAt(u) > 0)) return false;
    sc.inside[u] = 1;
    return true;
  });
  return true;
}

// Per component sample its peak by steepest ascent of sc.value (8 neighbours inside), in sc.label
// (-1 outside the component).
void basins(int n, LobeScratch& sc) {
  const size_t nn = static_cast<size_t>(n) * static_cast<size_t>(n);
  sc.label.assign(nn, -1);
  for (size_t s = 0; s < nn; ++s) {
    if (!sc.inside[s] || sc.label[s] >= 0) continue;
    sc.stack.clear();
    int p = static_cast<int>(s);
    for (;;) {
      if (sc.label[static_cast<size_t>(p)] >= 0) break;
      sc.stack.push_back(p);
      const int i = p % n, j = p / n;
      int best = p;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int a = i + di, b = j + dj;
          if (a < 0 || b < 0 || a >= n || b >= n) continue;
          const size_t k = static_cast<size_t>(a + n * b);
          if (sc.inside[k] && sc.value[k] > sc.value[static_cast<size_t>(best)]) best = static_cast<int>(k);
        }
      if (best == p) {
        sc.label[static_cast<size_t>(p)] = p;
        break;
      }
      p = best;
    }
    const int32_t peak = sc.label[static_cast<size_t>(p)];
    for (int q : sc.stack) sc.label[static_cast<size_t>(q)] = peak;
  }
}

}  // namespace

LobeResult ownLobe(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                   const Vec3& anchor, double level, bool bright, double halfMm, double valleyShare, LobeScratch& sc) {
  LobeResult res;
  if (!(halfMm > 0)) return res;
  const Vec3 t = tangent.norm() > 0 ? Vec3(tangent.normalized()) : Vec3(0, 0, 1);
  const PlaneBasis basis = planeBasis(t);
  const Vec3 &u = basis.u, &v = basis.v;
  const double h = 0.5 * spacing.minCoeff();
  const int m = static_cast<int>(std::ceil(halfMm / h)), n = 2 * m + 1;
  const size_t nn = static_cast<size_t>(n) * static_cast<size_t>(n);
  const Vec3 inv = spacing.cwiseInverse();
  // A sample's height is formed when the component's flood first reads it (session 45 speedE: only the component
  // and its rim are read - the height of the rest of the window was formed and never used).
  sc.height.resize(nn);
  sc.heightKnown.assign(nn, 0);
  const auto heightAt = [&](size_t k) {
    if (!sc.heightKnown[k]) {
      const int i = static_cast<int>(k % static_cast<size_t>(n)), j = static_cast<int>(k / static_cast<size_t>(n));
      const Vec3 q = (c + (i - m) * h * u + (j - m) * h * v).cwiseProduct(inv);
      const double x = sample.inside(q) ? sample.at(q) : std::numeric_limits<double>::quiet_NaN();
      const double e = bright ? x - level : level - x;
      sc.height[k] = std::isnan(e) ? -1.0f : static_cast<float>(e);
      sc.heightKnown[k] = 1;
    }
    return sc.height[k];
  };
  const Vec3 rel = anchor - c;
  const int ai = m + static_cast<int>(std::lround(rel.dot(u) / h)),
            aj = m + static_cast<int>(std::lround(rel.dot(v) / h));
  if (ai < 0 || aj < 0 || ai >= n || aj >= n || !componentOf(n, ai + n * aj, sc, heightAt)) return res;
  // Lumen-ness: the excess over the level times the distance (samples) to the component's edge.
  sc.dist2.resize(nn);
  for (size_t k = 0; k < nn; ++k) sc.dist2[k] = sc.inside[k] ? kFar : 0.0f;
  squaredDistance2d(sc.dist2.data(), n, sc.tmp, sc.idx);
  sc.value.resize(nn);
  for (size_t k = 0; k < nn; ++k) sc.value[k] = sc.inside[k] ? sc.height[k] * std::sqrt(sc.dist2[k]) : 0.0f;
  basins(n, sc);
  // Merge basins across their highest saddles unless both peaks stand above it by more than
  // valleyShare x the lower peak (union-find, saddles in decreasing order).
  sc.edges.clear();
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const size_t k = static_cast<size_t>(i + n * j);
      if (sc.label[k] < 0) continue;
      const int nb[2][2] = {{i + 1, j}, {i, j + 1}};
      for (const auto& q : nb) {
        if (q[0] >= n || q[1] >= n) continue;
        const size_t l = static_cast<size_t>(q[0] + n * q[1]);
        if (sc.label[l] >= 0 && sc.label[l] != sc.label[k])
          sc.edges.push_back({std::min(sc.value[k], sc.value[l]), sc.label[k], sc.label[l]});
      }
    }
  std::sort(sc.edges.begin(), sc.edges.end(), [](const auto& a, const auto& b) { return a.saddle > b.saddle; });
  sc.parent.resize(nn);
  sc.peak.resize(nn);
  for (size_t k = 0; k < nn; ++k) sc.parent[k] = static_cast<int32_t>(k), sc.peak[k] = sc.value[k];
  for (const auto& e : sc.edges) {
    const int32_t a = findRoot(sc.parent, e.a), b = findRoot(sc.parent, e.b);
    if (a == b) continue;
    const float lower = std::min(sc.peak[static_cast<size_t>(a)], sc.peak[static_cast<size_t>(b)]);
    if (lower - e.saddle > valleyShare * lower) continue;  // a valley: two lobes
    const float top = std::max(sc.peak[static_cast<size_t>(a)], sc.peak[static_cast<size_t>(b)]);
    sc.parent[static_cast<size_t>(b)] = a;
    sc.peak[static_cast<size_t>(a)] = top;
  }
  const int32_t own = findRoot(sc.parent, sc.label[static_cast<size_t>(ai + n * aj)]);
  double si = 0, sj = 0, area = 0, sii = 0, sjj = 0, sij = 0;
  float best = -1;
  int bi = -1, bj = -1;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const size_t k = static_cast<size_t>(i + n * j);
      if (sc.label[k] < 0) continue;
      const int32_t r = findRoot(sc.parent, sc.label[k]);
      if (r == static_cast<int32_t>(k)) ++res.lobes;
      if (r != own) continue;
      si += i, sj += j, area += 1, sii += double(i) * i, sjj += double(j) * j, sij += double(i) * j;
      if (sc.value[k] > best) best = sc.value[k], bi = i, bj = j;
    }
  if (bi >= 0) {
    const double cii = sii / area - si * si / (area * area), cjj = sjj / area - sj * sj / (area * area),
                 cij = sij / area - si * sj / (area * area);
    const double longVar = 0.5 * (cii + cjj) + std::sqrt(0.25 * (cii - cjj) * (cii - cjj) + cij * cij);
    res.widthMm = 4 * std::sqrt(std::max(0.0, longVar)) * h;
    const auto vertex = [&](int i0, int j0, int i1, int j1) {  // of the parabola through the peak and two neighbours
      if (i0 < 0 || j0 < 0 || i1 >= n || j1 >= n) return 0.0;
      const double a = sc.value[static_cast<size_t>(i0 + n * j0)], b = best,
                   d = a - 2 * b + sc.value[static_cast<size_t>(i1 + n * j1)];
      return d < 0 ? std::clamp(0.5 * (a - sc.value[static_cast<size_t>(i1 + n * j1)]) / d, -0.5, 0.5) : 0.0;
    };
    res.peak =
        c + (bi + vertex(bi - 1, bj, bi + 1, bj) - m) * h * u + (bj + vertex(bi, bj - 1, bi, bj + 1) - m) * h * v;
  }
  if (res.lobes < 2 || area <= 0) return res;
  res.split = true;
  res.centre = c + (si / area - m) * h * u + (sj / area - m) * h * v;
  res.radiusMm = std::sqrt(area / M_PI) * h;
  return res;
}

bool neighboursInOtherLobe(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                           const Vec3* ends, double level, bool bright, double halfMm, double valleyShare,
                           const Vec3& ownCentre, LobeScratch& scratch, size_t count) {
  for (const Vec3* e = ends; e != ends + count; ++e) {
    const LobeResult l = ownLobe(sample, spacing, c, tangent, *e, level, bright, halfMm, valleyShare, scratch);
    if (l.lobes != 2 || (l.centre - ownCentre).norm() <= 0.5 * spacing.minCoeff()) return false;
  }
  return true;
}

size_t plainChainChild(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                       size_t k) {
  if (k == 0 || children[k].size() != 1) return 0;
  const size_t child = static_cast<size_t>(children[k][0]);
  return children[static_cast<size_t>(parent[k])].size() == 1 && children[child].size() == 1 ? child : 0;
}

std::vector<double> alongTreeFromForks(const std::vector<int32_t>& parent, const std::vector<Vec3>& q) {
  const size_t n = q.size();
  std::vector<int> children(n, 0);
  for (size_t k = 1; k < n; ++k) ++children[static_cast<size_t>(parent[k])];
  std::vector<double> d(n, std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < n; ++k)
    if (children[k] >= 2) d[k] = 0;
  // Up from the leaves (the nearest branch point below), then down from the root (or above).
  for (size_t k = n; k-- > 1;) {
    const size_t p = static_cast<size_t>(parent[k]);
    d[p] = std::min(d[p], d[k] + (q[k] - q[p]).norm());
  }
  for (size_t k = 1; k < n; ++k) {
    const size_t p = static_cast<size_t>(parent[k]);
    d[k] = std::min(d[k], d[p] + (q[k] - q[p]).norm());
  }
  return d;
}

}  // namespace vs
