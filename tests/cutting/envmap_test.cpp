// The environment-map mesh (thesis 3.1, 5.1) against analytic shapes: a sphere (star-shaped from
// its centroid: vertices on the sphere, wound outwards, and a cut on it), a sphere with a handle
// (rays leave it and meet the handle: refused) and a torus (its centroid is in the hole: refused).
#include "cutting/envmap.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "cutting/cut.h"
#include "util/error.h"

namespace {

using vs::Vec3;

template <class SignedDistance>
vs::VolumeF32 shape(vs::Index3 dims, Vec3 spacing, SignedDistance sd) {
  vs::Geometry g;
  g.dims = dims;
  g.spacing = spacing;
  vs::VolumeF32 v(g);
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x)
        v(x, y, z) = float(100 * std::clamp(0.5 + sd(g.indexToWorld(Vec3(double(x), double(y), double(z)))), 0.0, 1.0));
  return v;
}

std::string errorOf(const vs::VolumeF32& v) {
  try {
    vs::EnvMapOptions o;
    o.iso = 50;
    vs::envMapMesh(v, o);
  } catch (const vs::DataError& e) {
    return e.what();
  }
  return "no error";
}

TEST(EnvMap, SphereVerticesOnTheSurfaceWoundOutwards) {
  const Vec3 c(20.3, 19.8, 21.1);
  const double R = 14;
  const vs::VolumeF32 v = shape({40, 40, 30}, Vec3(1, 1, 1.5), [&](const Vec3& p) { return R - (p - c).norm(); });
  vs::EnvMapOptions o;
  o.iso = 50;
  const vs::TriMesh m = vs::envMapMesh(v, o);
  EXPECT_EQ(m.positions.size(), size_t(2 + 89 * 180));
  double signedVolume = 0;
  for (const auto& t : m.triangles)
    signedVolume += m.positions[size_t(t[0])].dot(m.positions[size_t(t[1])].cross(m.positions[size_t(t[2])])) / 6;
  EXPECT_NEAR(signedVolume, 4.0 / 3.0 * M_PI * R * R * R, 0.03 * 4.0 / 3.0 * M_PI * R * R * R);  // > 0: outwards
  for (const Vec3& p : m.positions) EXPECT_LT(std::abs((p - c).norm() - R), 0.5);

  // A cut on it: ten points on the circle 8 mm above the centre take the cap away.
  vs::CutOptions cut;
  cut.iso = 50;
  cut.meshKind = vs::CutMeshKind::EnvMap;
  const double h = 8, a = std::sqrt(R * R - h * h);
  for (int i = 0; i < 10; ++i)
    cut.pointsIndex.push_back(
        v.geometry().worldToIndex(c + Vec3(a * std::cos(2 * M_PI * i / 10), a * std::sin(2 * M_PI * i / 10), h)));
  const vs::CutResult r = vs::cutVolume(v, cut);
  for (const Vec3& p : r.contourMm) EXPECT_LT(std::abs((p - c).norm() - R), 0.5);
  const double capMm3 = M_PI * (R - h) * (R - h) * (3 * R - (R - h)) / 3;
  EXPECT_NEAR(double(r.split.cutVoxels) * 1.5, capMm3, 0.2 * capMm3);
}

TEST(EnvMap, ASphereWithAHandleIsNotStarShaped) {
  const Vec3 c(22, 20, 20), handle(22 + 16, 20, 20);
  const vs::VolumeF32 v = shape({52, 40, 40}, Vec3(1, 1, 1), [&](const Vec3& p) {
    const Vec3 d = p - handle;  // a ring in the x-z plane around the point beside the sphere
    const double ring = std::hypot(d.x(), d.z()) - 8;
    return std::max(12 - (p - c).norm(), 2.5 - std::hypot(ring, d.y()));
  });
  const std::string e = errorOf(v);
  EXPECT_NE(e.find("not star-shaped"), std::string::npos) << e;
  EXPECT_NE(e.find("meet it again"), std::string::npos) << e;
}

TEST(EnvMap, ATorusCentroidLiesInItsHole) {
  const Vec3 c(21.7, 22.1, 9.6);
  const vs::VolumeF32 v = shape({44, 44, 20}, Vec3(1, 1, 1), [&](const Vec3& p) {
    const Vec3 d = p - c;
    return 5 - std::hypot(std::hypot(d.x(), d.y()) - 13, d.z());
  });
  const std::string e = errorOf(v);
  EXPECT_NE(e.find("outside the object"), std::string::npos) << e;
}

}  // namespace
