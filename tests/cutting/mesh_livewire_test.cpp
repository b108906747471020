// Eq. 13 on the surface mesh: the gradient and normal terms steer the live-wire. Two points on a
// curved feature of the surface (a bright ridge seen through the surface; a curved crest among
// concentric creases): with the default weights the path follows the feature, while a length-only
// path (w_g = w_n = 0) cuts across its bow.
#include "cutting/mesh_livewire.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "meshops/isosurface.h"

namespace {

using vs::Vec3;

vs::VolumeF32 volumeOf(const vs::Index3& dims, const std::function<float(const Vec3&)>& value) {
  vs::Geometry g;
  g.dims = dims;
  vs::VolumeF32 v(g);
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x) v(x, y, z) = value(Vec3(double(x), double(y), double(z)));
  return v;
}

int64_t nearestVertex(const vs::TriMesh& m, const Vec3& p) {
  int64_t best = 0;
  for (size_t i = 0; i < m.positions.size(); ++i)
    if ((m.positions[i] - p).squaredNorm() < (m.positions[size_t(best)] - p).squaredNorm()) best = int64_t(i);
  return best;
}

// The largest distance (in x-y) of the path's vertices from the arc of radius r around c.
double farthestFromArc(const vs::TriMesh& m, const vs::Path& path, const Vec3& c, double r) {
  double worst = 0;
  for (int64_t v : path.nodes) {
    const Vec3 d = m.positions[size_t(v)] - c;
    worst = std::max(worst, std::abs(std::hypot(d.x(), d.y()) - r));
  }
  return worst;
}

vs::Path pathBetween(const vs::VolumeF32& v, const vs::TriMesh& m, const vs::MeshCostOptions& cost, int64_t a,
                     int64_t b) {
  const vs::VertexFeatures f = vs::sampleVertexFeatures(v, m);
  const vs::CsrGraph graph = vs::buildMeshGraph(m, f, cost);
  vs::MeshLiveWire wire(graph);
  wire.setSeed(a);
  return wire.pathTo(b);
}

// The top face of a slab (z < 20) with a brighter band under it along an arc (radius 15 mm,
// +-60 degrees): the band's surface has twice the gradient of the rest.
TEST(MeshLiveWire, GradientTermFollowsABrightRidgeALengthOnlyPathCutsAcross) {
  const Vec3 c(8, 30, 20);
  const double r = 15;
  const vs::VolumeF32 v = volumeOf({48, 60, 30}, [&](const Vec3& p) {
    const double inside = std::clamp(20.5 - p.z(), 0.0, 1.0);
    const double band = std::abs(std::hypot(p.x() - c.x(), p.y() - c.y()) - r) < 1.5 && p.z() > 16 ? 1.0 : 0.0;
    return float(inside * (100 + 100 * band));
  });
  vs::IsoSurfaceOptions io;
  io.iso = 50;
  const vs::TriMesh m = vs::extractIsoSurface(v, io);
  const int64_t a = nearestVertex(m, c + Vec3(r * std::cos(-M_PI / 3), r * std::sin(-M_PI / 3), 0.5));
  const int64_t b = nearestVertex(m, c + Vec3(r * std::cos(M_PI / 3), r * std::sin(M_PI / 3), 0.5));
  const vs::Path withImage = pathBetween(v, m, vs::MeshCostOptions{}, a, b);
  vs::MeshCostOptions lengthOnly;
  lengthOnly.wg = lengthOnly.wn = 0;
  lengthOnly.wl = 1;
  const vs::Path plain = pathBetween(v, m, lengthOnly, a, b);
  const double follow = farthestFromArc(m, withImage, c, r), cut = farthestFromArc(m, plain, c, r);
  std::printf("bright ridge: default weights stray %.2f mm from it (%.1f mm long), length only %.2f mm (%.1f mm)\n",
              follow, withImage.lengthMm, cut, plain.lengthMm);
  EXPECT_LT(follow, 1.6);
  EXPECT_GT(cut, 5.0);
  vs::MeshCostOptions gradientOnly = lengthOnly;  // the gradient term alone does it
  gradientOnly.wg = 0.9;
  gradientOnly.wl = 0.1;
  EXPECT_LT(farthestFromArc(m, pathBetween(v, m, gradientOnly, a, b), c, r), 1.6);
}

// A surface of concentric creases (a triangle wave in the radius, period 3 mm, slopes +-0.8)
// with uniform contrast, so that only the normal term sees them: between two points on one crest
// (radius 15 mm, +-60 degrees) a length-only path crosses the creases towards the chord; the
// normal term pulls the path towards the crest (less than half the bow). It does
// not hold the path on the very crest it started on: eq. 13's f_n charges a crease only where an
// edge crosses it, which is little against the length saved over 30 mm.
TEST(MeshLiveWire, NormalTermKeepsThePathOnACrestALengthOnlyPathCutsAcross) {
  const Vec3 c(8, 30, 0);
  const double r = 15, period = 3, slope = 0.8;
  auto height = [&](double x, double y) {
    const double rr = std::hypot(x - c.x(), y - c.y());
    const double phase = std::fmod(std::abs(rr - r), period) / period;  // 0 on the crest
    return 18.0 - slope * period * std::min(phase, 1 - phase);
  };
  const vs::VolumeF32 v = volumeOf({48, 60, 26}, [&](const Vec3& p) {
    return float(100 * std::clamp(height(p.x(), p.y()) + 0.5 - p.z(), 0.0, 1.0));
  });
  vs::IsoSurfaceOptions io;
  io.iso = 50;
  const vs::TriMesh m = vs::extractIsoSurface(v, io);
  auto onCrest = [&](double angle) {
    const double x = c.x() + r * std::cos(angle), y = c.y() + r * std::sin(angle);
    return nearestVertex(m, Vec3(x, y, height(x, y)));
  };
  const int64_t a = onCrest(-M_PI / 3), b = onCrest(M_PI / 3);
  vs::MeshCostOptions normalAndLength;
  normalAndLength.wg = 0;
  const vs::Path withNormal = pathBetween(v, m, normalAndLength, a, b);
  vs::MeshCostOptions lengthOnly;
  lengthOnly.wg = lengthOnly.wn = 0;
  lengthOnly.wl = 1;
  const vs::Path plain = pathBetween(v, m, lengthOnly, a, b);
  // Creases crossed: changes of the half-period band (crest or trough) along the path.
  auto crossings = [&](const vs::Path& path) {
    int count = 0;
    int64_t last = 0;
    for (size_t i = 0; i < path.nodes.size(); ++i) {
      const Vec3 d = m.positions[size_t(path.nodes[i])] - c;
      const int64_t band = int64_t(std::floor((std::hypot(d.x(), d.y()) - r) / (0.5 * period) + 0.5));
      if (i > 0 && band != last) count += int(std::abs(band - last));
      last = band;
    }
    return count;
  };
  const int follow = crossings(withNormal), cut = crossings(plain);
  std::printf(
      "creases: w_n + w_l crosses %d (%.1f mm long, bows %.2f mm from the crest), length only %d (%.1f mm "
      "long, %.2f mm)\n",
      follow, withNormal.lengthMm, farthestFromArc(m, withNormal, c, r), cut, plain.lengthMm,
      farthestFromArc(m, plain, c, r));
  EXPECT_GT(follow + cut, 0);
  EXPECT_LT(farthestFromArc(m, withNormal, c, r), 0.5 * farthestFromArc(m, plain, c, r));
}

}  // namespace
