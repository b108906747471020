#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "phantom/phantom.h"

using namespace vs;

namespace {

Shapes2DOptions opts(uint64_t seed, double noise = 0) {
  Shapes2DOptions o;
  o.seed = seed;
  o.noiseSigma = noise;
  return o;
}

double polygonArea(const std::vector<Vec2>& p) {
  double a = 0;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) a += p[j][0] * p[i][1] - p[i][0] * p[j][1];
  return 0.5 * a;
}

double analyticArea(const Shape2D& s) {
  switch (s.kind) {
    case ShapeKind::Disc:
      return M_PI * s.radius * s.radius;
    case ShapeKind::Ellipse:
      return M_PI * s.semiAxes[0] * s.semiAxes[1];
    case ShapeKind::RoundedRect:
      return 4 * s.semiAxes[0] * s.semiAxes[1] - (4 - M_PI) * s.cornerRadius * s.cornerRadius;
    case ShapeKind::Star:
      return M_PI * s.radius * s.radius * (1 + 0.5 * s.amplitude * s.amplitude);
  }
  return 0;
}

}  // namespace

TEST(Shapes2DPhantom, SameSeedIdenticalDifferentSeedDifferent) {
  const auto a = makeShapes2DPhantom(opts(1, 8));
  const auto b = makeShapes2DPhantom(opts(1, 8));
  const auto c = makeShapes2DPhantom(opts(2, 8));
  EXPECT_EQ(a.image.voxels(), b.image.voxels());
  EXPECT_EQ(a.labels.voxels(), b.labels.voxels());
  EXPECT_EQ(toJson(a.truth).dump(), toJson(b.truth).dump());
  EXPECT_NE(a.image.voxels(), c.image.voxels());
  EXPECT_NE(toJson(a.truth).dump(), toJson(c.truth).dump());
}

TEST(Shapes2DPhantom, BoundaryPolygonsAreDenseClosedAndExact) {
  const auto ph = makeShapes2DPhantom(opts(3));
  const auto& t = ph.truth;
  ASSERT_EQ(t.shapes.size(), 4u);
  EXPECT_EQ(ph.image.dims(), (Index3{256, 256, 1}));
  std::set<ShapeKind> kinds;
  for (const auto& s : t.shapes) {
    kinds.insert(s.kind);
    ASSERT_GE(s.boundary.size(), 16u);
    for (size_t i = 0, j = s.boundary.size() - 1; i < s.boundary.size(); j = i++)
      EXPECT_LE((s.boundary[i] - s.boundary[j]).norm(), 0.25 + 1e-9);
    const double area = polygonArea(s.boundary);
    EXPECT_GT(area, 0);
    EXPECT_NEAR(area, analyticArea(s), 0.002 * analyticArea(s)) << shapeKindName(s.kind);
    // Label image agrees with the polygon: pixel count ~ area (error bounded by the perimeter).
    int64_t n = 0;
    for (int64_t v : ph.labels.voxels()) n += v == s.label;
    EXPECT_NEAR(static_cast<double>(n), area, 0.1 * area);
  }
  EXPECT_EQ(kinds.size(), 4u);
}

TEST(Shapes2DPhantom, ShapesDoNotTouch) {
  for (uint64_t seed : {1, 2, 3, 4}) {
    const auto t = makeShapes2DPhantom(opts(seed)).truth;
    for (size_t a = 0; a < t.shapes.size(); ++a)
      for (size_t b = a + 1; b < t.shapes.size(); ++b) {
        double d = 1e30;
        for (const Vec2& p : t.shapes[a].boundary)
          for (size_t k = 0; k < t.shapes[b].boundary.size(); k += 2)
            d = std::min(d, (p - t.shapes[b].boundary[k]).norm());
        EXPECT_GT(d, 4 * t.blurSigma + 2) << "seed " << seed;
      }
  }
}

TEST(Shapes2DPhantom, BoundaryPixelsLieOnTheIntensityEdge) {
  const auto ph = makeShapes2DPhantom(opts(4));  // noise-free
  for (const auto& s : ph.truth.shapes) {
    ASSERT_FALSE(s.boundaryPixels.empty());
    for (const Index2& p : s.boundaryPixels) {
      const Vec2 c(static_cast<double>(p[0]), static_cast<double>(p[1]));
      const double sd = signedDistanceToShape(s, c);
      EXPECT_LE(sd, 0.0);
      EXPECT_GE(sd, -1.0);
      EXPECT_EQ(ph.labels(p[0], p[1], 0), s.label);
      // Inside but within a pixel of the edge: between the iso level and the plateau.
      const int v = ph.image(p[0], p[1], 0);
      EXPECT_GE(v, s.iso - 1);
      EXPECT_LE(v, ph.truth.background + 0.85 * (s.value - ph.truth.background) + 1);
    }
  }
}

TEST(Shapes2DPhantom, NoisyEdgesStillCarryTheGradient) {
  const auto ph = makeShapes2DPhantom(opts(5, 8));
  auto grad = [&](int64_t x, int64_t y) {
    const double gx = 0.5 * (ph.image(x + 1, y, 0) - ph.image(x - 1, y, 0));
    const double gy = 0.5 * (ph.image(x, y + 1, 0) - ph.image(x, y - 1, 0));
    return std::hypot(gx, gy);
  };
  for (const auto& s : ph.truth.shapes) {
    double edge = 0, flat = 0;
    int64_t ne = 0, nf = 0;
    for (const Index2& p : s.boundaryPixels) {
      edge += grad(p[0], p[1]);
      ++ne;
    }
    for (int64_t y = 1; y < 255; ++y)
      for (int64_t x = 1; x < 255; ++x)
        if (ph.labels(x, y, 0) == s.label &&
            signedDistanceToShape(s, Vec2(static_cast<double>(x), static_cast<double>(y))) < -4) {
          flat += grad(x, y);
          ++nf;
        }
    ASSERT_GT(nf, 20);
    EXPECT_GT(edge / static_cast<double>(ne), 3 * flat / static_cast<double>(nf)) << shapeKindName(s.kind);
  }
}

TEST(Shapes2DPhantom, DistanceToBoundary) {
  const auto t = makeShapes2DPhantom(opts(6)).truth;
  const Shape2D& disc = t.shapes[0];
  ASSERT_EQ(disc.kind, ShapeKind::Disc);
  const auto atCentre = distanceToBoundary(t, disc.center);
  EXPECT_EQ(atCentre.shape, 0);
  EXPECT_TRUE(atCentre.inside);
  EXPECT_NEAR(atCentre.distance, disc.radius, 0.01);
  const Vec2 onEdge = disc.center + Vec2(disc.radius, 0);
  EXPECT_NEAR(distanceToBoundary(t, onEdge).distance, 0.0, 0.01);
  const auto out = distanceToBoundary(t, disc.center + Vec2(disc.radius + 2, 0));
  EXPECT_FALSE(out.inside);
  EXPECT_NEAR(out.distance, 2.0, 0.01);
  EXPECT_EQ(distanceToBoundary(Shapes2DTruth{}, Vec2(0, 0)).shape, -1);
}

TEST(Shapes2DPhantom, OtherSizesAndBadOptions) {
  Shapes2DOptions o = opts(1);
  o.width = 100;
  o.height = 64;
  o.shapeCount = 5;
  const auto ph = makeShapes2DPhantom(o);
  EXPECT_EQ(ph.truth.shapes.size(), 5u);
  EXPECT_EQ(ph.image.dims(), (Index3{100, 64, 1}));
  for (const auto& s : ph.truth.shapes)
    for (const Vec2& p : s.boundary) {
      EXPECT_GT(p[0], 2.0);
      EXPECT_GT(p[1], 2.0);
      EXPECT_LT(p[0], 97.0);
      EXPECT_LT(p[1], 61.0);
    }
  o.width = 20;
  EXPECT_THROW(makeShapes2DPhantom(o), InvalidArgument);
  o = opts(1);
  o.shapeCount = 0;
  EXPECT_THROW(makeShapes2DPhantom(o), InvalidArgument);
  o = opts(1);
  o.blurSigma = -1;
  EXPECT_THROW(makeShapes2DPhantom(o), InvalidArgument);
  EXPECT_EQ(shapeKindFromName("star"), ShapeKind::Star);
  EXPECT_THROW(shapeKindFromName("hexagon"), InvalidArgument);
}
