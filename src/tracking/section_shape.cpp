#include "tracking/section_shape.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vs {
namespace {

// The waist of a profile: its deepest dip, the smallest ratio of a value to the lower of the largest values on
// either side of it (1 where the profile rises to one top and falls: an ellipse's chords; two lobes, however
// unequal, give their contact's chord over the narrower lobe's widest).
double profileWaist(const std::vector<double>& raw) {
  const int n = static_cast<int>(raw.size());
  if (n < 3) return 1;
  std::vector<double> p(raw.size());  // three-bin mean: the edge's grid noise is not a waist
  for (int k = 0; k < n; ++k) {
    double s = 0;
    int m = 0;
    for (int d = -1; d <= 1; ++d)
      if (k + d >= 0 && k + d < n) s += raw[static_cast<size_t>(k + d)], ++m;
    p[static_cast<size_t>(k)] = s / m;
  }
  std::vector<double> fromRight(p.size());
  double top = 0;
  for (int k = n - 1; k >= 0; --k) fromRight[static_cast<size_t>(k)] = top = std::max(top, p[static_cast<size_t>(k)]);
  double waist = 1, fromLeft = 0;
  for (int k = 0; k < n; ++k) {
    fromLeft = std::max(fromLeft, p[static_cast<size_t>(k)]);
    const double high = std::min(fromLeft, fromRight[static_cast<size_t>(k)]);
    if (high > 0) waist = std::min(waist, p[static_cast<size_t>(k)] / high);
  }
  return waist;
}

}  // namespace

SectionShape sectionShape(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                          double centreValue, double surroundings, double halfMm, SectionScratch& sc) {
  SectionShape out;
  const SectionResult sec = sectionCentre(sample, spacing, c, tangent, centreValue, surroundings, halfMm, sc);
  if (!sec.ok) return out;
  // sc.value holds sectionCentre's grid (the same step and size as there).
  const double h = std::max(spacing.minCoeff(), halfMm / 60.0);
  const int m = static_cast<int>(std::ceil(halfMm / h)), n = 2 * m + 1;
  const bool bright = centreValue > surroundings;
  const double level = sec.level;
  auto inLumen = [&](int k) {
    const float v = sc.value[static_cast<size_t>(k)];
    return !std::isnan(v) && (bright ? v > level : v < level);
  };
  std::vector<uint8_t> comp(static_cast<size_t>(n * n), 0);
  const int seed = m + n * m;
  if (!inLumen(seed)) return out;
  comp[static_cast<size_t>(seed)] = 1;
  sc.stack.clear();
  sc.stack.push_back(seed);
  floodGrid4(n, sc.stack, [&](int k) {
    if (comp[static_cast<size_t>(k)] || !inLumen(k)) return false;
    comp[static_cast<size_t>(k)] = 1;
    return true;
  });
  double si = 0, sj = 0, cnt = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (comp[static_cast<size_t>(i + n * j)]) {
        si += i, sj += j, cnt += 1;
        if (i == 0 || j == 0 || i == n - 1 || j == n - 1) out.clipped = true;
      }
  if (cnt < 5) return out;
  const double ci = si / cnt, cj = sj / cnt;
  double sxx = 0, syy = 0, sxy = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (comp[static_cast<size_t>(i + n * j)]) {
        const double x = i - ci, y = j - cj;
        sxx += x * x, syy += y * y, sxy += x * y;
      }
  sxx /= cnt, syy /= cnt, sxy /= cnt;
  const double tr = sxx + syy, det = sxx * syy - sxy * sxy;
  const double disc = std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
  const double l1 = 0.5 * tr + disc, l2 = std::max(1e-9, 0.5 * tr - disc);
  const double ang = 0.5 * std::atan2(2 * sxy, sxx - syy);
  const double ex = std::cos(ang), ey = std::sin(ang);
  out.aspect = std::sqrt(l1 / l2);
  // Profiles along the major axis, one bin per grid step; the contrast summed over the strip the component spans
  // across (its farthest sample from the major axis + 2 steps), as the fraction of the half-way contrast x 2.
  double sMin = 0, sMax = 0, tMax = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (comp[static_cast<size_t>(i + n * j)]) {
        const double x = i - ci, y = j - cj, s = x * ex + y * ey, t = -x * ey + y * ex;
        sMin = std::min(sMin, s), sMax = std::max(sMax, s), tMax = std::max(tMax, std::abs(t));
      }
  const int b0 = static_cast<int>(std::floor(sMin + 0.5)), b1 = static_cast<int>(std::floor(sMax + 0.5));
  const int bins = b1 - b0 + 1;
  std::vector<double> chord(static_cast<size_t>(bins), 0.0), mass(static_cast<size_t>(bins), 0.0);
  const double full = 2 * (level - surroundings);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = i - ci, y = j - cj, s = x * ex + y * ey, t = -x * ey + y * ex;
      const int b = static_cast<int>(std::floor(s + 0.5)) - b0;
      if (b < 0 || b >= bins || std::abs(t) > tMax + 2) continue;
      const int k = i + n * j;
      if (comp[static_cast<size_t>(k)]) chord[static_cast<size_t>(b)] += 1;
      const float v = sc.value[static_cast<size_t>(k)];
      if (!std::isnan(v) && full != 0) mass[static_cast<size_t>(b)] += std::clamp((v - surroundings) / full, 0.0, 1.0);
    }
  // The plateau: the share of the component beyond three quarters of its peak contrast. A lumen several blur
  // widths deep holds most of its area near its peak; two thin tubes blurred into one blob fall off from a ridge.
  double peak = 0;
  for (int k = 0; k < n * n; ++k)
    if (comp[static_cast<size_t>(k)])
      peak = std::max(peak, std::abs(double(sc.value[static_cast<size_t>(k)]) - surroundings));
  double high = 0;
  for (int k = 0; k < n * n; ++k)
    if (comp[static_cast<size_t>(k)] &&
        std::abs(double(sc.value[static_cast<size_t>(k)]) - surroundings) >= 0.75 * peak)
      high += 1;
  out.plateau = high / cnt;
  out.stepMm = h;
  out.lengthMm = (sMax - sMin) * h;
  out.widthMm = *std::max_element(chord.begin(), chord.end()) * h;
  out.waist = profileWaist(chord);
  out.massWaist = profileWaist(mass);
  out.level = level;
  out.ok = true;
  return out;
}

}  // namespace vs
