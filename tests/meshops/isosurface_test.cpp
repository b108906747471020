// Iso-surfaces against analytic spheres: vertices on the sphere, outward normals, world mapping
// with anisotropic spacing and a mirroring direction, components, smoothing and decimation.
#include "meshops/isosurface.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>

#include "util/error.h"

namespace {

using vs::Vec3;

// Signed distance (mm, positive inside) to spheres given in world mm: an exact iso-value 0.
vs::VolumeF32 spheres(const vs::Geometry& g, const std::vector<std::pair<Vec3, double>>& balls) {
  vs::VolumeF32 v(g);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const Vec3 w = g.indexToWorld(Vec3(double(x), double(y), double(z)));
        double best = -1e9;
        for (const auto& [c, r] : balls) best = std::max(best, r - (w - c).norm());
        v(x, y, z) = static_cast<float>(best);
      }
  return v;
}

vs::Geometry geometry(vs::Index3 dims, Vec3 spacing, Vec3 origin = Vec3::Zero(), vs::Mat3 dir = vs::Mat3::Identity()) {
  vs::Geometry g;
  g.dims = dims;
  g.spacing = spacing;
  g.origin = origin;
  g.direction = dir;
  return g;
}

TEST(IsoSurface, SphereVerticesOnTheSurfaceWithOutwardNormals) {
  const vs::Geometry g = geometry({40, 40, 40}, Vec3(1, 1, 1));
  const Vec3 c(19.5, 20.2, 19.1);
  const double r = 12;
  const vs::TriMesh mesh = vs::extractIsoSurface(spheres(g, {{c, r}}), {}, vs::Progress::none());
  ASSERT_GT(mesh.triangles.size(), 1000u);
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  EXPECT_NO_THROW(mesh.validate());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_NEAR((mesh.positions[i] - c).norm(), r, 0.05);
    EXPECT_GT(mesh.normals[i].dot((mesh.positions[i] - c).normalized()), 0.95);
  }
  // Counter-clockwise from outside: positive enclosed volume close to 4/3 pi r^3.
  double volume = 0;
  for (const auto& t : mesh.triangles)
    volume += mesh.positions[size_t(t[0])].dot(mesh.positions[size_t(t[1])].cross(mesh.positions[size_t(t[2])])) / 6;
  EXPECT_NEAR(volume, 4.0 / 3.0 * M_PI * r * r * r, 0.01 * volume);
}

TEST(IsoSurface, AnisotropicSpacingAndMirroringDirectionMapToWorld) {
  vs::Mat3 dir;
  dir << -1, 0, 0, 0, 1, 0, 0, 0, 1;  // x mirrored: negative determinant
  const vs::Geometry g = geometry({50, 44, 24}, Vec3(0.8, 0.9, 2.0), Vec3(30, -10, 5), dir);
  const Vec3 c = g.indexToWorld(Vec3(24.3, 21.7, 11.6));
  const double r = 14;
  const vs::TriMesh mesh = vs::extractIsoSurface(spheres(g, {{c, r}}), {}, vs::Progress::none());
  ASSERT_FALSE(mesh.empty());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_NEAR((mesh.positions[i] - c).norm(), r, 0.15);
    EXPECT_GT(mesh.normals[i].dot((mesh.positions[i] - c).normalized()), 0.9);
  }
}

TEST(IsoSurface, LargestComponentAndComponentNearestThePoints) {
  const vs::Geometry g = geometry({60, 30, 30}, Vec3(1, 1, 1));
  const Vec3 big(18, 15, 15), small(46, 15, 15);
  const vs::VolumeF32 v = spheres(g, {{big, 10}, {small, 6}});
  vs::IsoSurfaceOptions all;
  all.largestComponentOnly = false;
  const vs::TriMesh both = vs::extractIsoSurface(v, all, vs::Progress::none());
  int32_t count = 0;
  const std::vector<int32_t> comp = vs::meshComponents(both, &count);
  EXPECT_EQ(count, 2);
  for (size_t i = 0; i < both.positions.size(); ++i) EXPECT_EQ(comp[i], (both.positions[i] - big).norm() < 11 ? 0 : 1);

  const vs::TriMesh largest = vs::extractIsoSurface(v, {}, vs::Progress::none());
  for (const Vec3& p : largest.positions) EXPECT_NEAR((p - big).norm(), 10, 0.05);
  const vs::TriMesh near = vs::keepComponentNearest(both, {Vec3(46, 15, 22), Vec3(40, 15, 15), Vec3(20, 15, 26)});
  ASSERT_FALSE(near.empty());
  for (const Vec3& p : near.positions) EXPECT_NEAR((p - small).norm(), 6, 0.05);
}

TEST(IsoSurface, SmoothingAndDecimationStayOnTheSphere) {
  const vs::Geometry g = geometry({40, 40, 40}, Vec3(1, 1, 1));
  const Vec3 c(20, 20, 20);
  const vs::VolumeF32 v = spheres(g, {{c, 13}});
  const vs::TriMesh plain = vs::extractIsoSurface(v, {}, vs::Progress::none());
  vs::IsoSurfaceOptions o;
  o.smoothIterations = 20;
  o.decimateReduction = 0.75;
  const vs::TriMesh reduced = vs::extractIsoSurface(v, o, vs::Progress::none());
  EXPECT_LT(reduced.triangles.size(), plain.triangles.size() * 0.3);
  EXPECT_GT(reduced.triangles.size(), plain.triangles.size() * 0.2);
  for (size_t i = 0; i < reduced.positions.size(); ++i) {
    EXPECT_NEAR((reduced.positions[i] - c).norm(), 13, 0.3);
    EXPECT_GT(reduced.normals[i].dot((reduced.positions[i] - c).normalized()), 0.7);  // coarse triangles
  }
}

TEST(IsoSurface, NoSurfaceAndBadOptionsAreClearErrors) {
  const vs::Geometry g = geometry({20, 20, 20}, Vec3(1, 1, 1));
  const vs::VolumeF32 v = spheres(g, {{Vec3(10, 10, 10), 5}});
  vs::IsoSurfaceOptions o;
  o.iso = 100;
  try {
    vs::extractIsoSurface(v, o, vs::Progress::none());
    FAIL() << "expected DataError";
  } catch (const vs::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("no surface"), std::string::npos) << e.what();
  }
  o.iso = 0;
  o.decimateReduction = 1;
  EXPECT_THROW(vs::extractIsoSurface(v, o, vs::Progress::none()), vs::InvalidArgument);
  o.decimateReduction = 0;
  o.smoothIterations = -1;
  EXPECT_THROW(vs::extractIsoSurface(v, o, vs::Progress::none()), vs::InvalidArgument);
  o.smoothIterations = 0;
  o.iso = NAN;
  EXPECT_THROW(vs::extractIsoSurface(v, o, vs::Progress::none()), vs::InvalidArgument);
}

TEST(IsoSurface, CancelledThroughProgress) {
  const vs::Geometry g = geometry({20, 20, 20}, Vec3(1, 1, 1));
  vs::Progress p;
  p.cancel();
  EXPECT_THROW(vs::extractIsoSurface(spheres(g, {{Vec3(10, 10, 10), 5}}), {}, p), vs::Cancelled);
}

}  // namespace
