// 2D shapes phantom: disc, ellipse, rounded rectangle and star with Gaussian-blurred
// edges and noise; the truth is each shape's exact boundary as a dense polygon.
#include <algorithm>
#include <cmath>

#include "phantom/phantom.h"
#include "phantom/phantom_internal.h"
#include "util/error.h"

namespace vs {

using namespace phantom_detail;

std::string shapeKindName(ShapeKind k) {
  switch (k) {
    case ShapeKind::Disc:
      return "disc";
    case ShapeKind::Ellipse:
      return "ellipse";
    case ShapeKind::RoundedRect:
      return "rounded_rect";
    case ShapeKind::Star:
      return "star";
  }
  return "disc";
}

ShapeKind shapeKindFromName(const std::string& name) {
  for (ShapeKind k : {ShapeKind::Disc, ShapeKind::Ellipse, ShapeKind::RoundedRect, ShapeKind::Star})
    if (shapeKindName(k) == name) return k;
  throw InvalidArgument("unknown shape kind '" + name + "' (disc, ellipse, rounded_rect, star)");
}

namespace {

constexpr double kMaxVertexGap = 0.25;  // px

Vec2 rotate(const Vec2& v, double a) {
  return Vec2(std::cos(a) * v[0] - std::sin(a) * v[1], std::sin(a) * v[0] + std::cos(a) * v[1]);
}

// Dense closed polygon of the exact boundary (positive signed area).
std::vector<Vec2> buildBoundary(const Shape2D& s) {
  std::vector<Vec2> poly;
  switch (s.kind) {
    case ShapeKind::Disc: {
      const int n = std::max(16, static_cast<int>(std::ceil(2 * M_PI * s.radius / kMaxVertexGap)));
      for (int i = 0; i < n; ++i) {
        const double t = 2 * M_PI * i / n;
        poly.push_back(s.center + s.radius * Vec2(std::cos(t), std::sin(t)));
      }
      break;
    }
    case ShapeKind::Ellipse: {
      const double a = s.semiAxes[0], b = s.semiAxes[1];
      const int n = std::max(16, static_cast<int>(std::ceil(2 * M_PI * std::max(a, b) / kMaxVertexGap)));
      for (int i = 0; i < n; ++i) {
        const double t = 2 * M_PI * i / n;
        poly.push_back(s.center + rotate(Vec2(a * std::cos(t), b * std::sin(t)), s.angle));
      }
      break;
    }
    case ShapeKind::RoundedRect: {
      const double hw = s.semiAxes[0], hh = s.semiAxes[1], cr = s.cornerRadius;
      // Corner arc centres, counter-clockwise from (+x,+y); each corner arc then the edge after it.
      const Vec2 cc[4] = {{hw - cr, hh - cr}, {-(hw - cr), hh - cr}, {-(hw - cr), -(hh - cr)}, {hw - cr, -(hh - cr)}};
      const int na = std::max(4, static_cast<int>(std::ceil(0.5 * M_PI * cr / kMaxVertexGap)));
      for (int c = 0; c < 4; ++c) {
        for (int i = 0; i < na; ++i) {
          const double t = 0.5 * M_PI * (c + static_cast<double>(i) / na);
          poly.push_back(cc[c] + cr * Vec2(std::cos(t), std::sin(t)));
        }
        const double tEnd = 0.5 * M_PI * (c + 1);
        const Vec2 from = cc[c] + cr * Vec2(std::cos(tEnd), std::sin(tEnd));
        const Vec2 to = cc[(c + 1) % 4] + cr * Vec2(std::cos(tEnd), std::sin(tEnd));
        const int ne = std::max(1, static_cast<int>(std::ceil((to - from).norm() / kMaxVertexGap)));
        for (int i = 0; i < ne; ++i) poly.push_back(from + (to - from) * (static_cast<double>(i) / ne));
      }
      for (Vec2& p : poly) p = s.center + rotate(p, s.angle);
      break;
    }
    case ShapeKind::Star: {
      const double rMax = s.radius * (1 + s.amplitude);
      const double len = 2 * M_PI * rMax + 2 * M_PI * s.radius * s.amplitude * s.lobes;  // bound on the perimeter
      const int n = std::max(64, static_cast<int>(std::ceil(len / kMaxVertexGap)));
      for (int i = 0; i < n; ++i) {
        const double t = 2 * M_PI * i / n;
        const double r = s.radius * (1 + s.amplitude * std::sin(s.lobes * t + s.phase));
        poly.push_back(s.center + r * Vec2(std::cos(t), std::sin(t)));
      }
      break;
    }
  }
  return poly;
}

double segmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double ab2 = ab.squaredNorm();
  const double t = ab2 > 0 ? std::clamp((p - a).dot(ab) / ab2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

bool insidePolygon(const std::vector<Vec2>& poly, const Vec2& p) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a[1] > p[1]) != (b[1] > p[1]) && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]) in = !in;
  }
  return in;
}

double boundingRadius(const Shape2D& s) {
  switch (s.kind) {
    case ShapeKind::Disc:
      return s.radius;
    case ShapeKind::Ellipse:
      return s.semiAxes.maxCoeff();
    case ShapeKind::RoundedRect:
      return s.semiAxes.norm();
    case ShapeKind::Star:
      return s.radius * (1 + s.amplitude);
  }
  return s.radius;
}

}  // namespace

double signedDistanceToShape(const Shape2D& shape, const Vec2& p) {
  if (shape.boundary.size() < 3) return std::numeric_limits<double>::infinity();
  double d = std::numeric_limits<double>::infinity();
  for (size_t i = 0, j = shape.boundary.size() - 1; i < shape.boundary.size(); j = i++)
    d = std::min(d, segmentDistance(p, shape.boundary[j], shape.boundary[i]));
  return insidePolygon(shape.boundary, p) ? -d : d;
}

BoundaryDistance distanceToBoundary(const Shapes2DTruth& truth, const Vec2& point) {
  BoundaryDistance best;
  for (size_t i = 0; i < truth.shapes.size(); ++i) {
    const double sd = signedDistanceToShape(truth.shapes[i], point);
    if (std::abs(sd) < best.distance) {
      best.distance = std::abs(sd);
      best.shape = static_cast<int>(i);
      best.inside = sd < 0;
    }
  }
  return best;
}

Shapes2DPhantom makeShapes2DPhantom(const Shapes2DOptions& o, Progress& progress) {
  requireDims(Index3{o.width, o.height, 1}, 48, 1, "shapes2d phantom");
  requireSpacing(Vec3(o.spacing[0], o.spacing[1], 1.0), "shapes2d phantom");
  requireFiniteIn(o.noiseSigma, 0, 1000, "shapes2d phantom: noise sigma");
  requireFiniteIn(o.background, 0, 255, "shapes2d phantom: background");
  requireFiniteIn(o.blurSigma, 0, 10, "shapes2d phantom: blur sigma");
  if (o.shapeCount < 1 || o.shapeCount > 8) throw InvalidArgument("shapes2d phantom: shape count must be 1..8");
  Geometry geom;
  geom.dims = {o.width, o.height, 1};
  geom.spacing = Vec3(o.spacing[0], o.spacing[1], 1.0);
  checkAllocation(geom.dims, 2 * sizeof(uint8_t) + sizeof(float), "shapes2d phantom");

  PhantomRng rng(PhantomRng::derive(o.seed, 21));
  const double m = static_cast<double>(std::min(o.width, o.height));
  const double gap = 6 * o.blurSigma + 4;
  const double border = 3 * o.blurSigma + 4;
  // Shape grey levels: well apart from the background and from each other.
  const double levels[] = {200, 150, 235, 120, 180, 215, 135, 165};

  Shapes2DTruth T;
  T.seed = o.seed;
  T.dims = geom.dims;
  T.spacing = geom.spacing;
  T.background = o.background;
  T.noiseSigma = o.noiseSigma;
  T.blurSigma = o.blurSigma;

  // Size scale: the shapes' bounding discs cover roughly a third of the image.
  double scale = std::sqrt(0.33 * o.width * o.height / (M_PI * o.shapeCount)) / 1.1;
  scale = std::min(scale, 0.3 * m);
  for (int round = 0;; ++round) {
    if (round == 60) throw DataError("shapes2d phantom: cannot place the shapes without touching");
    T.shapes.clear();
    bool ok = true;
    for (int i = 0; i < o.shapeCount && ok; ++i) {
      Shape2D s;
      s.kind = static_cast<ShapeKind>(i % 4);
      s.label = i + 1;
      s.value = levels[i];
      s.iso = 0.5 * (o.background + s.value);
      const double R = scale * rng.uniform(0.8, 1.1);
      switch (s.kind) {
        case ShapeKind::Disc:
          s.radius = R;
          break;
        case ShapeKind::Ellipse:
          s.semiAxes = Vec2(R, R * rng.uniform(0.45, 0.75));
          s.angle = rng.uniform(0, M_PI);
          break;
        case ShapeKind::RoundedRect:
          s.semiAxes = Vec2(0.78 * R, R * rng.uniform(0.35, 0.6));
          s.cornerRadius = s.semiAxes.minCoeff() * rng.uniform(0.25, 0.5);
          s.angle = rng.uniform(0, M_PI);
          break;
        case ShapeKind::Star:
          s.amplitude = rng.uniform(0.15, 0.3);
          s.radius = R / (1 + s.amplitude);
          s.lobes = static_cast<int>(rng.integer(3, 6));
          s.phase = rng.uniform(0, 2 * M_PI);
          break;
      }
      const double br = boundingRadius(s);
      bool placed = false;
      for (int attempt = 0; attempt < 300 && !placed; ++attempt) {
        s.center = Vec2(rng.uniform(br + border, static_cast<double>(o.width - 1) - br - border),
                        rng.uniform(br + border, static_cast<double>(o.height - 1) - br - border));
        placed = s.center[0] >= br + border && s.center[1] >= br + border;
        for (const Shape2D& t : T.shapes)
          if ((t.center - s.center).norm() < br + boundingRadius(t) + gap) placed = false;
      }
      ok = placed;
      if (placed) T.shapes.push_back(s);
    }
    if (ok) break;
    scale *= 0.93;
  }

  // Render: per shape, the signed distance of each pixel near it.
  std::vector<float> intensity(static_cast<size_t>(geom.voxelCount()), static_cast<float>(o.background));
  Shapes2DPhantom out;
  out.labels = VolumeU8(geom, 0);
  const double reach = std::max(4 * o.blurSigma, 1.0) + 2;
  for (size_t si = 0; si < T.shapes.size(); ++si) {
    progress.report(0.8 * static_cast<double>(si) / static_cast<double>(T.shapes.size()), "phantom shapes");
    Shape2D& s = T.shapes[si];
    s.boundary = buildBoundary(s);
    const double br = boundingRadius(s) + reach;
    const int64_t x0 = std::max<int64_t>(0, static_cast<int64_t>(std::floor(s.center[0] - br)));
    const int64_t x1 = std::min<int64_t>(o.width - 1, static_cast<int64_t>(std::ceil(s.center[0] + br)));
    const int64_t y0 = std::max<int64_t>(0, static_cast<int64_t>(std::floor(s.center[1] - br)));
    const int64_t y1 = std::min<int64_t>(o.height - 1, static_cast<int64_t>(std::ceil(s.center[1] + br)));
    for (int64_t y = y0; y <= y1; ++y)
      for (int64_t x = x0; x <= x1; ++x) {
        const double sd = signedDistanceToShape(s, Vec2(static_cast<double>(x), static_cast<double>(y)));
        const double f =
            o.blurSigma > 0 ? 0.5 * std::erfc(sd / (std::sqrt(2.0) * o.blurSigma)) : std::clamp(0.5 - sd, 0.0, 1.0);
        intensity[static_cast<size_t>(geom.linear(x, y, 0))] += static_cast<float>((s.value - o.background) * f);
        if (sd < 0) out.labels(x, y, 0) = static_cast<uint8_t>(s.label);
      }
  }
  for (Shape2D& s : T.shapes) {
    const int64_t lab = s.label;
    for (int64_t y = 0; y < o.height; ++y)
      for (int64_t x = 0; x < o.width; ++x) {
        if (out.labels(x, y, 0) != lab) continue;
        const bool edge = x == 0 || y == 0 || x == o.width - 1 || y == o.height - 1 || out.labels(x - 1, y, 0) != lab ||
                          out.labels(x + 1, y, 0) != lab || out.labels(x, y - 1, 0) != lab ||
                          out.labels(x, y + 1, 0) != lab;
        if (edge) s.boundaryPixels.push_back({x, y});
      }
  }

  out.image = VolumeU8(geom, 0);
  PhantomRng noise(PhantomRng::derive(o.seed, 22));
  for (int64_t i = 0; i < geom.voxelCount(); ++i) {
    double v = intensity[static_cast<size_t>(i)];
    if (o.noiseSigma > 0) v += o.noiseSigma * noise.normal();
    out.image.data()[i] = static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
  }
  out.truth = std::move(T);
  progress.report(1.0, "phantom shapes");
  return out;
}

}  // namespace vs
