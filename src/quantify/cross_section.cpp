// One lumen cross-section of a tree's segment (see quantify.h, CrossSection): rays in the plane
// normal to the centreline, each ray's boundary at the half-maximum between the lumen and its own
// wall, recentred once, the radius iterated until it settles; area, equivalent, minimum and maximum
// diameters of the boundary polygon.
#include <cmath>

#include "quantify/quantify_detail.h"

namespace vs::quantify_detail {

double sectionContrast(const SectionContext& c, const Vec3& p, const Vec3& t, double r) {
  Vec3 u, v;
  planeBasis(t, u, v);
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

namespace {

// Each ray's profile from `centre` out to the ray length for radius r, and the section's lumen
// level L (the median of the samples within half the radius) and wall level W (the median of each
// ray's most wall-like value out to the ring). false when a ray leaves the volume.
bool sampleProfiles(const SectionContext& c, double sign, const std::vector<Vec3>& dirs, const Vec3& centre, double r,
                    std::vector<std::vector<double>>& profiles, double& L, double& W) {
  const int n = static_cast<int>(dirs.size());
  const double vox = c.minSpacing, delta = c.o.sampleStepVoxels * vox;
  const double ringOuter = 2 * r + 2 * vox;
  const double rayLen = std::min(c.o.maxRadiusMm, 2.5 * r + 3 * vox);
  const int J = static_cast<int>(std::ceil(rayLen / delta));
  const Vec3 ci = c.index(centre);
  std::vector<double> lumen, wall;
  for (int k = 0; k < n; ++k) {
    auto& f = profiles[static_cast<size_t>(k)];
    f.resize(static_cast<size_t>(J) + 1);
    const Vec3 di = c.worldToIndex * dirs[static_cast<size_t>(k)] * delta;
    for (int j = 0; j <= J; ++j) {
      const Vec3 q = ci + static_cast<double>(j) * di;
      if (!c.sampler.inside(q)) return false;
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
  L = median(lumen);
  W = median(wall);
  return true;
}

// Each ray's boundary radius (NaN where it has none, or where it leaks): returns how many rays
// have none.
int rayRadii(const std::vector<std::vector<double>>& profiles, double sign, double delta, double vox, double L,
             double W, std::vector<double>& radii) {
  const int n = static_cast<int>(profiles.size());
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
  // A ray that leaks through a gap in the wall (a thin airway wall in partial volume, lung
  // behind it) runs on: rays longer than twice the median are dropped like rays without a
  // crossing (an ellipse of aspect 2.25 keeps every ray).
  std::vector<double> ok;
  for (double x : radii)
    if (!std::isnan(x)) ok.push_back(x);
  const double med = median(ok);
  for (auto& x : radii)
    if (!std::isnan(x) && x > 2 * med) x = kNaN, ++failed;
  return failed;
}

// A ray without a crossing: the mean of its nearest neighbours' radii (r when there is none).
void fillMissingRays(std::vector<double>& radii, double r) {
  const int n = static_cast<int>(radii.size());
  for (int k = 0; k < n; ++k) {
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
}

// Twice the signed area of the boundary polygon (ray k at angle 2 pi k / n) and its centroid
// in plane coordinates.
double polygonArea2(const std::vector<double>& radii, double& cx, double& cy) {
  const int n = static_cast<int>(radii.size());
  double area2 = 0;
  cx = cy = 0;
  for (int k = 0; k < n; ++k) {
    const int k1 = (k + 1) % n;
    const double a0 = 2 * kPi * k / n, a1 = 2 * kPi * k1 / n;
    const double x0 = radii[static_cast<size_t>(k)] * std::cos(a0), y0 = radii[static_cast<size_t>(k)] * std::sin(a0);
    const double x1 = radii[static_cast<size_t>(k1)] * std::cos(a1), y1 = radii[static_cast<size_t>(k1)] * std::sin(a1);
    const double cr = x0 * y1 - x1 * y0;
    area2 += cr;
    cx += (x0 + x1) * cr;
    cy += (y0 + y1) * cr;
  }
  return area2;
}

// The settled boundary's figures: area, equivalent diameter, outer radius, and the minimum and
// maximum widths over 180 directions with their directions.
void setShape(CrossSection& cs, const Vec3& centre, const Vec3& u, const Vec3& v, const std::vector<double>& radii,
              double area, double cx, double cy) {
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
}

}  // namespace

void measureSection(const SectionContext& c, double sign, double hint, CrossSection& cs) {
  const QuantifyOptions& o = c.o;
  const int n = o.rays;
  const double vox = c.minSpacing, delta = o.sampleStepVoxels * vox;
  Vec3 u, v;
  planeBasis(cs.tangent, u, v);
  std::vector<Vec3> dirs(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double a = 2 * kPi * k / n;
    dirs[static_cast<size_t>(k)] = std::cos(a) * u + std::sin(a) * v;
  }
  double r = std::max(hint, vox);
  Vec3 centre = cs.centreMm;
  bool recentred = false;
  std::vector<double> radii(static_cast<size_t>(n));
  std::vector<std::vector<double>> profiles(static_cast<size_t>(n));
  cs.outerRadiusMm = r;
  for (int iter = 0; iter < 6; ++iter) {
    double L = kNaN, W = kNaN;
    if (!sampleProfiles(c, sign, dirs, centre, r, profiles, L, W)) {
      cs.flags |= kSectionLeavesVolume;
      return;
    }
    cs.lumenLevel = L;
    cs.wallLevel = W;
    if (!(sign * (L - W) > 0)) {
      cs.flags |= kSectionNoBoundary;
      return;
    }
    const int failed = rayRadii(profiles, sign, delta, vox, L, W, radii);
    if (4 * failed > n) {
      // The ring may still lie in the lumen (hint far too small): widen once or twice.
      if (iter < 3 && 2 * r < o.maxRadiusMm) {
        r *= 2;
        continue;
      }
      cs.flags |= kSectionNoBoundary;
      return;
    }
    if (failed > 0) fillMissingRays(radii, r);
    double cx = 0, cy = 0;
    const double area2 = polygonArea2(radii, cx, cy);
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
    setShape(cs, centre, u, v, radii, area, cx, cy);
    return;
  }
  cs.flags |= kSectionNoBoundary;
}

}  // namespace vs::quantify_detail
