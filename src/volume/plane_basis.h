// The plane normal to a direction, spanned by two vectors: the one basis of every section the tools
// read (the tracker's rays, discs, widths and lobes, quantify's sections, the contact walk).
#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "volume/geometry.h"

namespace vs {

struct PlaneBasis {
  Vec3 u, v;
};

// For a unit t: u = t x a normalised, a the x axis, or the y axis where t lies within about 26
// degrees of x (|t.x| >= 0.9: t x (1,0,0) would be short and its direction ill-conditioned); v = t x u.
// (u, v, t) is orthonormal and right-handed (u x v = t). t must be unit: the test reads t.x as the
// cosine to x (a short t along x would give u = 0), and v is as long as t.
inline PlaneBasis planeBasis(const Vec3& t) {
  PlaneBasis b;
  b.u = std::abs(t[0]) < 0.9 ? t.cross(Vec3(1, 0, 0)) : t.cross(Vec3(0, 1, 0));
  b.u.normalize();
  b.v = t.cross(b.u);
  return b;
}

// The same with v normalised again (the form quantify's sections and the contact walk were written in):
// for a unit t it differs from planeBasis's v by rounding only, but not bit for bit.
inline PlaneBasis unitPlaneBasis(const Vec3& t) {
  PlaneBasis b = planeBasis(t);
  b.v.normalize();
  return b;
}

}  // namespace vs
