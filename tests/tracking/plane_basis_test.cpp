// The section plane's basis (volume/plane_basis.h, session 44 basis): the one home of the basis the
// tracker's sections (rays, discs, widths, lobes, the contact walk, a daughter's opening) and
// quantify's sections span. Orthonormal and right-handed for a unit tangent, the y axis taken as
// the fallback where the tangent lies near x, and v normalised again by unitPlaneBasis.
#include "volume/plane_basis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tracking/contact_walk.h"

namespace vs {
namespace {

// Unit directions over the sphere (a latitude-longitude grid, both poles and every axis with both
// signs) plus directions just either side of the fallback's switch (|t.x| = 0.9).
std::vector<Vec3> directions() {
  std::vector<Vec3> out;
  for (int i = 0; i <= 12; ++i)
    for (int j = 0; j < 24; ++j) {
      const double th = M_PI * i / 12, ph = 2 * M_PI * j / 24;
      out.emplace_back(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
    }
  for (double x : {0.8999, 0.9, 0.9001, 0.999999, 1.0})
    for (double sx : {1.0, -1.0})
      for (double a : {0.0, 0.7, 2.1}) {
        const double r = std::sqrt(std::max(0.0, 1 - x * x));
        out.emplace_back(sx * x, r * std::cos(a), r * std::sin(a));
      }
  return out;
}

TEST(PlaneBasis, OrthonormalAndRightHandedForEveryUnitTangent) {
  for (const Vec3& t : directions()) {
    const PlaneBasis b = planeBasis(t);
    ASSERT_TRUE(b.u.allFinite() && b.v.allFinite()) << t.transpose();
    EXPECT_NEAR(b.u.norm(), 1, 1e-12) << t.transpose();
    EXPECT_NEAR(b.v.norm(), 1, 1e-12) << t.transpose();
    EXPECT_NEAR(b.u.dot(t), 0, 1e-12) << t.transpose();
    EXPECT_NEAR(b.v.dot(t), 0, 1e-12) << t.transpose();
    EXPECT_NEAR(b.u.dot(b.v), 0, 1e-12) << t.transpose();
    EXPECT_LT((b.u.cross(b.v) - t).norm(), 1e-12) << t.transpose();  // (u, v, t) right-handed
  }
}

TEST(PlaneBasis, FallbackAxisNearX) {
  // t x (1,0,0) has no x component, t x (0,1,0) no y component: which one is exactly zero tells the axis used.
  for (const Vec3& t : directions()) {
    const PlaneBasis b = planeBasis(t);
    if (std::abs(t[0]) < 0.9)
      EXPECT_EQ(b.u[0], 0.0) << t.transpose();
    else
      EXPECT_EQ(b.u[1], 0.0) << t.transpose();
  }
  // Along x itself (where the x axis would give a zero u) the y axis: u = x cross y = z, v = x cross z = -y.
  const PlaneBasis x = planeBasis(Vec3(1, 0, 0));
  EXPECT_EQ(x.u, Vec3(0, 0, 1));
  EXPECT_EQ(x.v, Vec3(0, -1, 0));
  const PlaneBasis z = planeBasis(Vec3(0, 0, 1));  // away from x: u = z cross x = y, v = z cross y = -x
  EXPECT_EQ(z.u, Vec3(0, 1, 0));
  EXPECT_EQ(z.v, Vec3(-1, 0, 0));
}

TEST(PlaneBasis, UnitPlaneBasisNormalisesV) {
  // A tangent normalised with rounding (length 1 +- a few ulp) and one 1e-9 off: planeBasis's v is as long as t,
  // unitPlaneBasis's is t x u normalised, its u planeBasis's.
  for (const Vec3& d : directions())
    for (double len : {1.0, 1 + 1e-9, 1 - 1e-9}) {
      const Vec3 t = len * d;
      const PlaneBasis plain = planeBasis(t), unit = unitPlaneBasis(t);
      EXPECT_NEAR(plain.v.norm(), len, 1e-14) << t.transpose();
      EXPECT_EQ(unit.u, plain.u) << t.transpose();
      EXPECT_EQ(unit.v, Vec3(t.cross(plain.u).normalized())) << t.transpose();
      EXPECT_NEAR(unit.v.norm(), 1, 1e-15) << t.transpose();
      EXPECT_LT((unit.u.cross(unit.v) - d).norm(), 1e-12) << t.transpose();
    }
}

TEST(PlaneBasis, ContactWalkNormalsAreTheUnitBasis) {
  for (const Vec3& d : directions()) {
    Vec3 u, w;
    walk::normals(d, u, w);
    const PlaneBasis b = unitPlaneBasis(d);
    EXPECT_EQ(u, b.u);
    EXPECT_EQ(w, b.v);
  }
}

}  // namespace
}  // namespace vs
