// Internals of the tree measurement (quantify.h), shared by its files:
//   cross_section.cpp   one lumen cross-section: rays, boundary, area and diameters; the lumen contrast
//   quantify.cpp        the tree into segments, sections along them, per-segment, branch-point and path figures
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "quantify/quantify.h"
#include "volume/sample.h"

namespace vs::quantify_detail {

inline constexpr double kPi = std::numbers::pi;

inline double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
  double m = v[h];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h)));
  return m;
}

inline double angleDeg(const Vec3& a, const Vec3& b) {
  const double na = a.norm(), nb = b.norm();
  if (na <= 0 || nb <= 0) return kNaN;
  return std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0)) * 180.0 / kPi;
}

// A segment's centreline: world points with cumulative arc length and hint radii.
struct Curve {
  std::vector<Vec3> p;
  std::vector<double> s, r;
  double length() const { return s.empty() ? 0 : s.back(); }
  size_t locate(double t) const {  // segment k with s[k] <= t <= s[k+1]
    auto it = std::upper_bound(s.begin(), s.end(), t);
    size_t k = it == s.begin() ? 0 : static_cast<size_t>(it - s.begin()) - 1;
    return std::min(k, p.size() >= 2 ? p.size() - 2 : 0);
  }
  Vec3 at(double t) const {
    if (p.size() == 1) return p[0];
    t = std::clamp(t, 0.0, length());
    const size_t k = locate(t);
    const double d = s[k + 1] - s[k];
    const double f = d > 0 ? (t - s[k]) / d : 0;
    return p[k] + f * (p[k + 1] - p[k]);
  }
  double radius(double t) const {
    if (p.size() == 1) return r[0];
    t = std::clamp(t, 0.0, length());
    const size_t k = locate(t);
    const double d = s[k + 1] - s[k];
    const double f = d > 0 ? (t - s[k]) / d : 0;
    return r[k] + f * (r[k + 1] - r[k]);
  }
};

struct SectionContext {
  const VolumeF32& volume;
  TrilinearSampler sampler;
  Mat3 worldToIndex;  // linear part
  Vec3 origin;
  double minSpacing;
  const QuantifyOptions& o;
  SectionContext(const VolumeF32& v, const QuantifyOptions& opt)
      : volume(v), sampler(v), origin(v.geometry().origin), minSpacing(v.geometry().spacing.minCoeff()), o(opt) {
    const Geometry& g = v.geometry();
    worldToIndex = (g.direction * g.spacing.asDiagonal()).inverse();
  }
  Vec3 index(const Vec3& w) const { return worldToIndex * (w - origin); }
};

inline void planeBasis(const Vec3& t, Vec3& u, Vec3& v) {
  const Vec3 a = std::abs(t[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  u = t.cross(a).normalized();
  v = t.cross(u).normalized();
}

// Resample a curve every `step` mm (equal steps, both ends included).
inline std::vector<double> stations(double length, double step) {
  const int n = std::max(1, static_cast<int>(std::lround(length / step)));
  std::vector<double> s(static_cast<size_t>(n) + 1);
  for (int k = 0; k <= n; ++k) s[static_cast<size_t>(k)] = length * k / n;
  return s;
}

// Sum of turning angles per cm along a curve resampled every 1 mm.
inline double sumOfAngles(const Curve& c) {
  const double L = c.length();
  if (L < 2) return 0;
  const auto s = stations(L, 1.0);
  double sum = 0;
  for (size_t k = 1; k + 1 < s.size(); ++k) {
    const double a = angleDeg(c.at(s[k]) - c.at(s[k - 1]), c.at(s[k + 1]) - c.at(s[k]));
    if (!std::isnan(a)) sum += a * kPi / 180;
  }
  return sum / (L / 10.0);
}

// Contrast of the lumen against its surroundings at a section (for the polarity vote): centre
// median minus the median of a ring at 2-3 hint radii. NaN when the ring leaves the volume.
double sectionContrast(const SectionContext& c, const Vec3& p, const Vec3& t, double r);

// One cross-section (see quantify.h). sign: +1 bright lumen, -1 dark lumen.
void measureSection(const SectionContext& c, double sign, double hint, CrossSection& cs);

}  // namespace vs::quantify_detail
