#include "quantify/section.h"

#include <Eigen/Dense>
#include <cmath>

#include "volume/plane_basis.h"

namespace vs::quantify_detail {

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
  double m = v[h];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h)));
  return m;
}

double angleDeg(const Vec3& a, const Vec3& b) {
  const double na = a.norm(), nb = b.norm();
  if (na <= 0 || nb <= 0) return kNaN;
  return std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0)) * 180.0 / kPi;
}

namespace {

// Casts the rays from `centre` (world mm) for a lumen radius r: radii[k] the boundary distance
// along dirs[k] (NaN: no crossing). Returns the number of rays without a boundary, -1 when a ray
// leaves the volume, -2 when the lumen shows no contrast to its wall (levels in cs).
int castRays(const SectionContext& c, double sign, const std::vector<Vec3>& dirs, const Vec3& centre, double r,
             CrossSection& cs, std::vector<double>& radii) {
  const QuantifyOptions& o = c.o;
  const int n = static_cast<int>(dirs.size());
  const double vox = c.minSpacing, delta = o.sampleStepVoxels * vox;
  std::vector<std::vector<double>> profiles(static_cast<size_t>(n));
  const double ringOuter = 2 * r + 2 * vox;
  const double rayLen = std::min(o.maxRadiusMm, 2.5 * r + 3 * vox);
  const int J = static_cast<int>(std::ceil(rayLen / delta));
  const Vec3 ci = c.index(centre);
  std::vector<double> lumen, wall;
  for (int k = 0; k < n; ++k) {
    auto& f = profiles[static_cast<size_t>(k)];
    f.resize(static_cast<size_t>(J) + 1);
    const Vec3 di = c.worldToIndex * dirs[static_cast<size_t>(k)] * delta;
    for (int j = 0; j <= J; ++j) {
      const Vec3 q = ci + static_cast<double>(j) * di;
      if (!c.sampler.inside(q)) return -1;
      f[static_cast<size_t>(j)] = c.sampler.at(q);
    }
    // Lumen samples: within half the lumen radius (at least the centre and its neighbour).
    for (int j = 0; j <= J && (j <= 1 || j * delta <= 0.5 * r); ++j) lumen.push_back(f[static_cast<size_t>(j)]);
    // Local wall: the most wall-like value of the profile (moving average over one voxel) out
    // to the ring: the wall peak of an airway, the darkest tissue next to a bright vessel.
    const int w = std::max(1, static_cast<int>(std::lround(0.5 * vox / delta)));
    double best = kNaN;
    for (int j = 1; j <= J && j * delta <= ringOuter; ++j) {
      double sum = 0;
      int cnt = 0;
      for (int q = std::max(0, j - w); q <= std::min(J, j + w); ++q, ++cnt) sum += f[static_cast<size_t>(q)];
      const double m = sum / cnt;
      if (j * delta >= 0.5 * r && (std::isnan(best) || sign * m < sign * best)) best = m;
    }
    if (!std::isnan(best)) wall.push_back(best);
  }
  const double L = median(lumen), W = median(wall);
  cs.lumenLevel = L;
  cs.wallLevel = W;
  if (!(sign * (L - W) > 0)) return -2;
  const double T0 = 0.5 * (L + W);
  // First crossing of level T along profile f (sub-sample, linear), NaN if none.
  auto crossing = [&](const std::vector<double>& f, double T) {
    for (size_t j = 1; j < f.size(); ++j)
      if (sign * (f[j] - T) < 0) {
        const double a = f[j - 1] - T, b = f[j] - T;
        const double frac = a != b ? a / (a - b) : 0.5;
        return delta * (static_cast<double>(j - 1) + std::clamp(frac, 0.0, 1.0));
      }
    return kNaN;
  };
  const int wallSpan = std::max(2, static_cast<int>(std::lround(3 * vox / delta)));
  int failed = 0;
  for (int k = 0; k < n; ++k) {
    const auto& f = profiles[static_cast<size_t>(k)];
    // The ray's own wall: the most wall-like sample within three voxels beyond its crossing of
    // the section's level (a thin airway wall's partial-volume peak, not the vessel or bone
    // behind it); the boundary is the half-maximum between the lumen and that wall.
    double rk = crossing(f, T0);
    if (!std::isnan(rk)) {
      const size_t j0 = static_cast<size_t>(rk / delta);
      double wk = f[std::min(j0 + 1, f.size() - 1)];
      for (size_t j = j0 + 1; j < f.size() && j <= j0 + static_cast<size_t>(wallSpan); ++j)
        if (sign * f[j] < sign * wk) wk = f[j];
      if (sign * (L - wk) > 0 && sign * (wk - W) > 0) rk = crossing(f, 0.5 * (L + wk));
    }
    radii[static_cast<size_t>(k)] = rk;
    failed += std::isnan(rk);
  }
  {
    // A ray that leaks through a gap in the wall (a thin airway wall in partial volume, lung
    // behind it) runs on: rays longer than twice the median are dropped like rays without a
    // crossing (an ellipse of aspect 2.25 keeps every ray).
    std::vector<double> ok;
    for (double x : radii)
      if (!std::isnan(x)) ok.push_back(x);
    const double med = median(ok);
    for (auto& x : radii)
      if (!std::isnan(x) && x > 2 * med) x = kNaN, ++failed;
  }
  return failed;
}

// A measured section: area, equivalent and Feret diameters, the boundary polygon in world mm.
// radii along dirs (plane basis u, v) from `centre`; (cx, cy) the boundary's centroid in the plane.
void storeMeasured(CrossSection& cs, const Vec3& centre, double area, const std::vector<double>& radii,
                   const std::vector<Vec3>& dirs, const Vec3& u, const Vec3& v, double cx, double cy) {
  const int n = static_cast<int>(radii.size());
  cs.centreMm = centre;
  cs.areaMm2 = area;
  cs.equivalentDiameterMm = 2 * std::sqrt(area / kPi);
  double outer = 0;
  std::vector<double> px(static_cast<size_t>(n)), py(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double a = 2 * kPi * k / n;
    px[static_cast<size_t>(k)] = radii[static_cast<size_t>(k)] * std::cos(a) - cx;
    py[static_cast<size_t>(k)] = radii[static_cast<size_t>(k)] * std::sin(a) - cy;
    outer = std::max(outer, std::hypot(px[static_cast<size_t>(k)], py[static_cast<size_t>(k)]));
  }
  cs.outerRadiusMm = outer;
  double minW = 1e300, maxW = -1, minA = 0, maxA = 0;
  for (int d = 0; d < 180; ++d) {
    const double a = d * kPi / 180, ca = std::cos(a), sa = std::sin(a);
    double lo = 1e300, hi = -1e300;
    for (int k = 0; k < n; ++k) {
      const double q = px[static_cast<size_t>(k)] * ca + py[static_cast<size_t>(k)] * sa;
      lo = std::min(lo, q);
      hi = std::max(hi, q);
    }
    const double width = hi - lo;
    if (width < minW) minW = width, minA = a;
    if (width > maxW) maxW = width, maxA = a;
  }
  cs.minDiameterMm = minW;
  cs.maxDiameterMm = maxW;
  cs.minDirection = (std::cos(minA) * u + std::sin(minA) * v).normalized();
  cs.maxDirection = (std::cos(maxA) * u + std::sin(maxA) * v).normalized();
  cs.boundaryMm.resize(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k)
    cs.boundaryMm[static_cast<size_t>(k)] = centre + radii[static_cast<size_t>(k)] * dirs[static_cast<size_t>(k)];
}

}  // namespace

// Contrast of the lumen against its surroundings at a section (for the polarity vote): centre
// median minus the median of a ring at 2-3 hint radii. NaN when the ring leaves the volume.
double sectionContrast(const SectionContext& c, const Vec3& p, const Vec3& t, double r) {
  const PlaneBasis basis = unitPlaneBasis(t);
  const Vec3 &u = basis.u, &v = basis.v;
  std::vector<double> centre, ring;
  for (int k = 0; k < 16; ++k) {
    const double a = 2 * kPi * k / 16;
    const Vec3 d = std::cos(a) * u + std::sin(a) * v;
    for (double q : {0.0, 0.25 * r}) centre.push_back(c.sampler.at(c.index(p + q * d)));
    for (double q : {2 * r + c.minSpacing, 3 * r + 2 * c.minSpacing}) {
      const Vec3 i = c.index(p + q * d);
      if (!c.sampler.inside(i)) return kNaN;
      ring.push_back(c.sampler.at(i));
    }
  }
  return median(centre) - median(ring);
}

void measureSection(const SectionContext& c, double sign, double hint, CrossSection& cs) {
  const QuantifyOptions& o = c.o;
  const int n = o.rays;
  const double vox = c.minSpacing;
  const PlaneBasis basis = unitPlaneBasis(cs.tangent);
  const Vec3 &u = basis.u, &v = basis.v;
  std::vector<Vec3> dirs(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double a = 2 * kPi * k / n;
    dirs[static_cast<size_t>(k)] = std::cos(a) * u + std::sin(a) * v;
  }
  double r = std::max(hint, vox);
  Vec3 centre = cs.centreMm;
  bool recentred = false;
  std::vector<double> radii(static_cast<size_t>(n));
  cs.outerRadiusMm = r;
  for (int iter = 0; iter < 6; ++iter) {
    const int failed = castRays(c, sign, dirs, centre, r, cs, radii);
    if (failed == -1) {
      cs.flags |= kSectionLeavesVolume;
      return;
    }
    if (failed == -2) {
      cs.flags |= kSectionNoBoundary;
      return;
    }
    if (4 * failed > n) {
      // The ring may still lie in the lumen (hint far too small): widen once or twice.
      if (iter < 3 && 2 * r < o.maxRadiusMm) {
        r *= 2;
        continue;
      }
      cs.flags |= kSectionNoBoundary;
      return;
    }
    for (int k = 0; k < n && failed > 0; ++k) {  // a ray without a crossing: mean of its neighbours
      if (!std::isnan(radii[static_cast<size_t>(k)])) continue;
      auto nearest = [&](int step) {
        for (int m = 1; m < n; ++m) {
          const double x = radii[static_cast<size_t>(((k + step * m) % n + n) % n)];
          if (!std::isnan(x)) return x;
        }
        return r;
      };
      radii[static_cast<size_t>(k)] = 0.5 * (nearest(1) + nearest(-1));
    }
    // Boundary polygon in plane coordinates.
    double area2 = 0, cx = 0, cy = 0;
    for (int k = 0; k < n; ++k) {
      const int k1 = (k + 1) % n;
      const double a0 = 2 * kPi * k / n, a1 = 2 * kPi * k1 / n;
      const double x0 = radii[static_cast<size_t>(k)] * std::cos(a0), y0 = radii[static_cast<size_t>(k)] * std::sin(a0);
      const double x1 = radii[static_cast<size_t>(k1)] * std::cos(a1),
                   y1 = radii[static_cast<size_t>(k1)] * std::sin(a1);
      const double cr = x0 * y1 - x1 * y0;
      area2 += cr;
      cx += (x0 + x1) * cr;
      cy += (y0 + y1) * cr;
    }
    const double area = 0.5 * area2;
    if (!(area > 0)) {
      cs.flags |= kSectionNoBoundary;
      return;
    }
    cx /= 3 * area2;
    cy /= 3 * area2;
    const double rNew = std::sqrt(area / kPi);
    if (!recentred && std::hypot(cx, cy) > 0.1 * vox) {
      centre += cx * u + cy * v;
      recentred = true;
      r = rNew;
      continue;
    }
    const bool settled = std::abs(rNew - r) <= 0.05 * r;
    r = rNew;
    if (!settled && iter < 5) continue;
    storeMeasured(cs, centre, area, radii, dirs, u, v, cx, cy);
    return;
  }
  cs.flags |= kSectionNoBoundary;
}

// Resample a curve every `step` mm (equal steps, both ends included).
std::vector<double> stations(double length, double step) {
  const int n = std::max(1, static_cast<int>(std::lround(length / step)));
  std::vector<double> s(static_cast<size_t>(n) + 1);
  for (int k = 0; k <= n; ++k) s[static_cast<size_t>(k)] = length * k / n;
  return s;
}

// Sum of turning angles per cm along a curve resampled every 1 mm.
double sumOfAngles(const Curve& c) {
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

Curve makeCurve(const Tree& tree, const std::vector<int32_t>& nodes, double fallbackRadius) {
  Curve c;
  for (int32_t i : nodes) {
    const Vec3& q = tree.points[static_cast<size_t>(i)];
    if (!c.p.empty() && (q - c.p.back()).norm() < 1e-9) continue;  // duplicate point
    c.s.push_back(c.p.empty() ? 0 : c.s.back() + (q - c.p.back()).norm());
    c.p.push_back(q);
    const double r = tree.radii.empty() ? 0 : tree.radii[static_cast<size_t>(i)];
    c.r.push_back(std::isfinite(r) && r > 0 ? r : fallbackRadius);
  }
  return c;
}

CrossSection placeSection(const Curve& c, int segment, double s) {
  CrossSection cs;
  cs.segment = segment;
  cs.arcMm = s;
  cs.centreMm = c.at(s);
  const double h = std::max(1.0, c.radius(s));
  Vec3 t = c.at(std::min(c.length(), s + h)) - c.at(std::max(0.0, s - h));
  if (t.norm() <= 0) t = c.p.back() - c.p.front();
  cs.tangent = t.normalized();
  return cs;
}

}  // namespace vs::quantify_detail
