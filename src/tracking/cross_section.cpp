#include "tracking/cross_section.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "util/median.h"
#include "volume/plane_basis.h"

namespace vs {

namespace {

constexpr float kFar = kSectionFar;

// Squared distance transform of one line in place (Felzenszwalb-Huttenlocher lower envelope);
// f: 0 at sources, kFar elsewhere (or the first pass's squared distances).
void edt1d(float* f, int n, int stride, std::vector<float>& tmp, std::vector<int32_t>& idx) {
  tmp.resize(static_cast<size_t>(3 * n + 1));
  idx.resize(static_cast<size_t>(n));
  float* g = tmp.data();      // copy of f
  float* z = tmp.data() + n;  // envelope boundaries (n + 1)
  float* out = tmp.data() + 2 * n + 1;
  for (int q = 0; q < n; ++q) g[q] = f[q * stride];
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (g[q] >= kFar) continue;
    for (;;) {
      if (k < 0) {
        idx[0] = q, z[0] = -kFar, k = 0;
        break;
      }
      const int p = idx[static_cast<size_t>(k)];
      const float s = ((g[q] + float(q) * float(q)) - (g[p] + float(p) * float(p))) / (2.0f * float(q - p));
      if (s <= z[k]) {
        --k;
        continue;
      }
      ++k, idx[static_cast<size_t>(k)] = q, z[k] = s;
      break;
    }
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) f[q * stride] = kFar;
    return;
  }
  z[k + 1] = kFar;
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < float(q)) ++j;
    const int p = idx[static_cast<size_t>(j)];
    out[q] = float(q - p) * float(q - p) + g[p];
  }
  for (int q = 0; q < n; ++q) f[q * stride] = out[q];
}

struct Grid {
  int n = 0, m = 0;  // n = 2m + 1 samples a side, the point at (m, m)
  double h = 0;      // step (mm)
  int at(int i, int j) const { return i + n * j; }
};

// The component of lumen samples (beyond `level`, c's side) holding the centre sample, as
// sc.lumen = 2 (other lumen samples 1), and its squared distance map in sc.dist2 (the grid's
// outside counts as outside). False when the centre sample is not lumen.
bool component(const Grid& gr, double level, bool bright, SectionScratch& sc) {
  const int n = gr.n, nn = n * n;
  sc.lumen.assign(static_cast<size_t>(nn), 0);
  for (int i = 0; i < nn; ++i) {
    const float v = sc.value[static_cast<size_t>(i)];
    sc.lumen[static_cast<size_t>(i)] = !std::isnan(v) && (bright ? v > level : v < level);
  }
  const int seed = gr.at(gr.m, gr.m);
  if (!sc.lumen[static_cast<size_t>(seed)]) return false;
  sc.stack.clear();
  sc.stack.push_back(seed);
  sc.lumen[static_cast<size_t>(seed)] = 2;
  floodGrid4(n, sc.stack, [&](int k) {
    if (sc.lumen[static_cast<size_t>(k)] != 1) return false;
    sc.lumen[static_cast<size_t>(k)] = 2;
    return true;
  });
  sc.dist2.resize(static_cast<size_t>(nn));
  for (int i = 0; i < nn; ++i) sc.dist2[static_cast<size_t>(i)] = sc.lumen[static_cast<size_t>(i)] == 2 ? kFar : 0.0f;
  squaredDistance2d(sc.dist2.data(), n, sc.tmp, sc.stack);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float b = float(std::min(std::min(i + 1, n - i), std::min(j + 1, n - j)));
      float& d = sc.dist2[static_cast<size_t>(gr.at(i, j))];
      d = std::min(d, b * b);
    }
  return true;
}

// Steepest ascent of the distance map from the centre sample (8 neighbours) to a local maximum.
int ascend(const Grid& gr, const SectionScratch& sc) {
  int p = gr.at(gr.m, gr.m);
  for (;;) {
    const int i = p % gr.n, j = p / gr.n;
    int best = p;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const int a = i + di, b = j + dj;
        if (a < 0 || b < 0 || a >= gr.n || b >= gr.n) continue;
        const int k = gr.at(a, b);
        if (sc.dist2[static_cast<size_t>(k)] > sc.dist2[static_cast<size_t>(best)]) best = k;
      }
    if (best == p) return p;
    p = best;
  }
}

// The component again with a level local to each side of the wall: per angular sector about the
// inscribed centre `top`, half-way between the lumen just inside the wall (component samples 2-5 steps
// from its edge) and the background just outside it (2-5 steps beyond the edge), or `level` where a
// sector has too few of either. Under a bias field a lumen's blurred wall crosses one level farther out
// on its bright side, and the centroid moves that way (503: a trunk of radius 21 voxels 0.3-0.5 voxel
// towards its brighter side along its whole length). sc.lumen = 2 on the new component (seeded at top).
void localComponent(const Grid& gr, double level, bool bright, int top, SectionScratch& sc) {
  constexpr int sectors = 32;
  constexpr float nearIn = 4.0f, farIn = 25.0f;  // the bands: 2-5 steps from the edge (squared)
  const int n = gr.n, nn = n * n, ti = top % n, tj = top / n;
  sc.outside2.resize(static_cast<size_t>(nn));
  for (int k = 0; k < nn; ++k)
    sc.outside2[static_cast<size_t>(k)] = sc.lumen[static_cast<size_t>(k)] == 2 ? 0.0f : kFar;
  squaredDistance2d(sc.outside2.data(), n, sc.tmp, sc.stack);
  auto sectorOf = [&](int i, int j) {
    const double a = std::atan2(double(j - tj), double(i - ti));
    return std::min(sectors - 1, static_cast<int>((a + M_PI) / (2 * M_PI) * sectors));
  };
  // inner samples as sector s, outer ones as sectors + s
  sc.banded.clear();
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const size_t k = static_cast<size_t>(gr.at(i, j));
      const float v = sc.value[k];
      if (std::isnan(v)) continue;
      if (sc.lumen[k] == 2 && sc.dist2[k] >= nearIn && sc.dist2[k] <= farIn)
        sc.banded.emplace_back(sectorOf(i, j), v);
      else if (sc.lumen[k] != 2 && sc.outside2[k] >= nearIn && sc.outside2[k] <= farIn)
        sc.banded.emplace_back(sectors + sectorOf(i, j), v);
    }
  std::sort(sc.banded.begin(), sc.banded.end());
  double median[2 * sectors];
  for (int s = 0; s < 2 * sectors; ++s) median[s] = std::numeric_limits<double>::quiet_NaN();
  for (size_t a = 0; a < sc.banded.size();) {
    size_t b = a;
    while (b < sc.banded.size() && sc.banded[b].first == sc.banded[a].first) ++b;
    if (b - a >= 3) median[sc.banded[a].first] = sc.banded[a + (b - a) / 2].second;
    a = b;
  }
  double local[sectors];
  for (int s = 0; s < sectors; ++s) {
    const double in = median[s], out = median[sectors + s];
    local[s] = !std::isnan(in) && !std::isnan(out) && (bright ? in > out : in < out) ? 0.5 * (in + out) : level;
  }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const size_t k = static_cast<size_t>(gr.at(i, j));
      const float v = sc.value[k];
      const double l = i == ti && j == tj ? level : local[sectorOf(i, j)];
      sc.lumen[k] = !std::isnan(v) && (bright ? v > l : v < l);
    }
  sc.stack.assign(1, top);
  sc.lumen[static_cast<size_t>(top)] = 2;
  floodGrid4(n, sc.stack, [&](int k) {
    if (sc.lumen[static_cast<size_t>(k)] != 1) return false;
    sc.lumen[static_cast<size_t>(k)] = 2;
    return true;
  });
}

}  // namespace

SectionResult sectionCentre(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                            double centreValue, double surroundings, double halfMm, SectionScratch& sc) {
  SectionResult res;
  if (!(halfMm > 0) || std::isnan(surroundings) || centreValue == surroundings) return res;
  const bool bright = centreValue > surroundings;
  Vec3 t = tangent.norm() > 0 ? tangent.normalized() : Vec3(0, 0, 1);
  const PlaneBasis basis = planeBasis(t);
  const Vec3 &u = basis.u, &v = basis.v;
  Grid gr;
  gr.h = std::max(spacing.minCoeff(), halfMm / 60.0);
  gr.m = static_cast<int>(std::ceil(halfMm / gr.h));
  gr.n = 2 * gr.m + 1;
  const Vec3 inv = spacing.cwiseInverse();
  sc.value.resize(static_cast<size_t>(gr.n * gr.n));
  for (int j = 0; j < gr.n; ++j)
    for (int i = 0; i < gr.n; ++i) {
      const Vec3 q = (c + (i - gr.m) * gr.h * u + (j - gr.m) * gr.h * v).cwiseProduct(inv);
      sc.value[static_cast<size_t>(gr.at(i, j))] =
          sample.inside(q) ? static_cast<float>(sample.at(q)) : std::numeric_limits<float>::quiet_NaN();
    }
  double level = 0.5 * (centreValue + surroundings);
  int top = 0;
  float firstDist2 = 0;
  for (int pass = 0; pass < 2; ++pass) {
    if (!component(gr, level, bright, sc)) return res;
    top = ascend(gr, sc);
    if (pass == 1) {
      // The section's own level moves the edge by a fraction of a step; where it moves it by more
      // than 2 steps it has broken through a wall (a thin bright wall between a dark lumen and a
      // darker-than-the-wall material beyond, a bronchus in the lung): the first level stands.
      const double grown = std::sqrt(double(sc.dist2[static_cast<size_t>(top)])) - std::sqrt(double(firstDist2));
      if (grown > 2 && !component(gr, 0.5 * (centreValue + surroundings), bright, sc)) return res;
      if (grown > 2) top = ascend(gr, sc), level = 0.5 * (centreValue + surroundings);
      break;
    }
    firstDist2 = sc.dist2[static_cast<size_t>(top)];
    // The section's own plateau and background around the inscribed circle.
    const double rho = std::sqrt(static_cast<double>(sc.dist2[static_cast<size_t>(top)]));
    const int ti = top % gr.n, tj = top / gr.n;
    std::vector<double>& in = sc.pick;
    in.clear();
    for (int k = 0; k < gr.n * gr.n; ++k)
      if (sc.lumen[static_cast<size_t>(k)] == 2 && sc.dist2[static_cast<size_t>(k)] >= 4.0f)
        in.push_back(sc.value[static_cast<size_t>(k)]);
    if (in.size() < 5) break;
    const double plateau = medianInPlace(in);
    in.clear();
    for (int j = 0; j < gr.n; ++j)
      for (int i = 0; i < gr.n; ++i) {
        const int k = gr.at(i, j);
        const double r = std::hypot(double(i - ti), double(j - tj));
        if (r >= rho + 2 && r <= rho + 5 && sc.lumen[static_cast<size_t>(k)] != 2 &&
            !std::isnan(sc.value[static_cast<size_t>(k)]))
          in.push_back(sc.value[static_cast<size_t>(k)]);
      }
    if (in.size() < 8) break;
    const double bg = medianInPlace(in);
    if (bright ? plateau <= bg : plateau >= bg) break;
    level = 0.5 * (plateau + bg);
  }
  // The centroid and area of the component within the inscribed radius + 2 steps, twice.
  const double rho = std::sqrt(static_cast<double>(sc.dist2[static_cast<size_t>(top)]));
  localComponent(gr, level, bright, top, sc);
  double ci = top % gr.n, cj = top / gr.n, area = 0;
  for (int round = 0; round < 2; ++round) {
    const double reach = rho + 2;
    double si = 0, sj = 0;
    area = 0;
    const int i0 = std::max(0, static_cast<int>(std::floor(ci - reach))),
              i1 = std::min(gr.n - 1, static_cast<int>(std::ceil(ci + reach)));
    const int j0 = std::max(0, static_cast<int>(std::floor(cj - reach))),
              j1 = std::min(gr.n - 1, static_cast<int>(std::ceil(cj + reach)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i)
        if (sc.lumen[static_cast<size_t>(gr.at(i, j))] == 2 && std::hypot(i - ci, j - cj) <= reach)
          si += i, sj += j, area += 1;
    if (area <= 0) return res;
    ci = si / area, cj = sj / area;
  }
  res.ok = true;
  res.centre = c + (ci - gr.m) * gr.h * u + (cj - gr.m) * gr.h * v;
  res.radiusMm = std::sqrt(area / M_PI) * gr.h;
  res.inscribedMm = rho * gr.h;
  res.ownMm = std::sqrt(static_cast<double>(sc.dist2[static_cast<size_t>(gr.at(gr.m, gr.m))])) * gr.h;
  res.topMm = std::hypot(double(top % gr.n - gr.m), double(top / gr.n - gr.m)) * gr.h;
  res.stepMm = gr.h;
  res.level = level;
  return res;
}

bool sectionHoldsPoint(const SectionResult& s) { return s.ok && s.ownMm + s.topMm <= s.inscribedMm + 2 * s.stepMm; }

void squaredDistance2d(float* f, int n, std::vector<float>& tmp, std::vector<int32_t>& idx) {
  for (int j = 0; j < n; ++j) edt1d(f + n * j, n, 1, tmp, idx);
  for (int i = 0; i < n; ++i) edt1d(f + i, n, n, tmp, idx);
}

}  // namespace vs
