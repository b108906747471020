// Internal to src/quantify: one lumen cross-section measured in the image (quantify.h states the
// rule), the centreline curves the sections are placed on, and small helpers shared by
// quantify.cpp and tree_measures.cpp. Not part of the module's interface.
#pragma once

#include <algorithm>
#include <numbers>
#include <vector>

#include "quantify/quantify.h"
#include "volume/sample.h"

namespace vs::quantify_detail {

constexpr double kPi = std::numbers::pi;

double median(std::vector<double> v);           // NaN when empty
double angleDeg(const Vec3& a, const Vec3& b);  // NaN for a zero vector

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

// The segment's nodes as a curve (duplicate points dropped; radius <= 0 or missing ->
// fallbackRadius).
Curve makeCurve(const Tree& tree, const std::vector<int32_t>& nodes, double fallbackRadius);
// Equal steps of about `step` over [0, length], both ends included.
std::vector<double> stations(double length, double step);
// Sum of turning angles per cm along a curve resampled every 1 mm.
double sumOfAngles(const Curve& c);

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

// A section on curve c at arc s: centre, tangent (chord over +-max(1 mm, r)), no numbers yet.
CrossSection placeSection(const Curve& c, int segment, double s);
// Contrast of the lumen against its surroundings at a section (for the polarity vote): centre
// median minus the median of a ring at 2-3 hint radii. NaN when the ring leaves the volume.
double sectionContrast(const SectionContext& c, const Vec3& p, const Vec3& t, double r);
// Measures one cross-section in place (quantify.h). sign: +1 bright lumen, -1 dark lumen; hint:
// the expected lumen radius (mm).
void measureSection(const SectionContext& c, double sign, double hint, CrossSection& cs);

}  // namespace vs::quantify_detail
