// Tests for tracking/dim_points.cpp (issue 21, session 27): a refined point on a partial-volume dip of a thin vessel
// moves onto its vessel's ridge, within half a voxel.
#include "tracking/dim_points.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "tracking/trace_run.h"
#include "volume/sample.h"

using namespace vs;

namespace {

// A masked vessel, 1 mm voxels, 0 outside: a trunk of radius 2 along x from (3, 20, 12) to b, then a thin tube of
// radius `radius` from b to c, each voxel 150 x the share of it the vessel covers (4^3 sub-samples): an oblique vessel
// about a voxel across has voxels it only grazes.
VolumeF32 partialVolumeTube(const Vec3& b, const Vec3& c, double radius) {
  Geometry g;
  g.dims = {48, 40, 24};
  g.spacing = Vec3(1, 1, 1);
  VolumeF32 v(g, 0.0f);
  const Vec3 a(3, 20, 12);
  auto dist = [](const Vec3& p, const Vec3& s0, const Vec3& s1) {
    const Vec3 d = s1 - s0;
    const double t = std::clamp((p - s0).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (p - (s0 + t * d)).norm();
  };
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        int in = 0;
        for (int s = 0; s < 64; ++s) {
          const Vec3 p(x - 0.375 + 0.25 * (s & 3), y - 0.375 + 0.25 * ((s >> 2) & 3), z - 0.375 + 0.25 * (s >> 4));
          in += dist(p, a, b) <= 2.0 || dist(p, b, c) <= radius;
        }
        v(x, y, z) = static_cast<float>(150.0 * in / 64);
      }
  return v;
}

// Per point of one chain: its value reads at least half-way from the background (0) to the median of the chain's
// values within 5 mm (the "in the vessel", bench/trace_measures.py branches).
int pointsOut(const VolumeF32& v, const std::vector<Vec3>& pts) {
  std::vector<double> val, arc{0.0};
  for (size_t i = 0; i < pts.size(); ++i) {
    val.push_back(sampleTrilinear(v, pts[i]));
    if (i > 0) arc.push_back(arc.back() + (pts[i] - pts[i - 1]).norm());
  }
  int out = 0;
  for (size_t k = 0; k < pts.size(); ++k) {
    std::vector<double> near;
    for (size_t j = 0; j < pts.size(); ++j)
      if (std::abs(arc[j] - arc[k]) <= 5.0) near.push_back(val[j]);
    std::nth_element(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(near.size() / 2), near.end());
    out += val[k] < 0.5 * near[near.size() / 2];
  }
  return out;
}

// The dip tests' volume, and their refined chain along y = z = 4 (one point per voxel, 1 .. 14).
Geometry dipGeometry() {
  Geometry g;
  g.dims = {16, 9, 9};
  g.spacing = Vec3(1, 1, 1);
  return g;
}

RefinedCentreline chainAlongX() {
  RefinedCentreline r;
  for (int64_t x = 1; x < 15; ++x) {
    r.points.emplace_back(static_cast<double>(x), 4.0, 4.0);
    r.parent.push_back(static_cast<int32_t>(x) - 2);
    r.radiiMm.push_back(0.5);
  }
  return r;
}

}  // namespace

// A chain through a grazed voxel: the point on it moves to its vessel's ridge; the points on the ridge stay.
TEST(DimPoints, APointOnAGrazedVoxelMovesOntoTheRidge) {
  VolumeF32 v(dipGeometry(), 0.0f);
  // A one-voxel vessel along y = z = 4, its voxel at x = 8 shifted to y = 5 (a diagonal step of the vessel), the
  // voxel the chain takes instead (8, 4, 4) grazed: 20 of 150.
  for (int64_t x = 1; x < 15; ++x) v(x, x == 8 ? 5 : 4, 4) = 150.0f;
  v(8, 4, 4) = 20.0f;
  RefinedCentreline r = chainAlongX();
  const std::vector<Vec3> before = r.points;
  ASSERT_EQ(pointsOut(v, r.points), 1);
  EXPECT_EQ(ridgeDimPoints(v, r, 1), 1u);
  EXPECT_EQ(pointsOut(v, r.points), 0);
  EXPECT_LE((r.points[7] - before[7]).norm(), 0.5 + 1e-9);  // within the voxel it stands for
  EXPECT_GE(sampleTrilinear(v, r.points[7]), 75.0);
  for (size_t i = 0; i < r.points.size(); ++i) {
    if (i != 7) {
      EXPECT_EQ(r.points[i], before[i]) << i;
    }
  }
  // No polarity (no contrast at the root): nothing moves.
  RefinedCentreline same = r;
  same.points = before;
  EXPECT_EQ(ridgeDimPoints(v, same, 0), 0u);
}

// A dark lumen (an airway): the same dip, inverted, moves the same way.
TEST(DimPoints, ADarkLumensGrazedVoxelMovesToo) {
  VolumeF32 v(dipGeometry(), 150.0f);
  for (int64_t x = 1; x < 15; ++x) v(x, x == 8 ? 5 : 4, 4) = 0.0f;
  v(8, 4, 4) = 130.0f;
  RefinedCentreline r = chainAlongX();
  EXPECT_EQ(ridgeDimPoints(v, r, -1), 1u);
  EXPECT_LT(sampleTrilinear(v, r.points[7]), 75.0);
}

// End to end: thin oblique vessels (radius 0.4 and 0.6 voxel) with partial-volume voxels, traced with defaults from
// a wider trunk: every refined point reads in the vessel by the half-maximum (one did not before, in each of the
// three).
TEST(DimPoints, AThinObliqueVesselsRefinedPointsAllReadInsideIt) {
  for (const auto& [radius, end] :
       {std::pair{0.4, Vec3(44, 30, 20)}, {0.6, Vec3(44, 30, 20)}, {0.4, Vec3(40, 36, 8)}}) {
    const VolumeF32 v = partialVolumeTube(Vec3(12, 20, 12), end, radius);
    const Vec3 t = end - (end - Vec3(12, 20, 12)).normalized();  // a voxel short of the tube's tip
    TraceRequest rq;
    rq.root = {5, 20, 12};
    rq.targets = {{std::llround(t[0]), std::llround(t[1]), std::llround(t[2])}};
    const TraceResult r = runTrace(v, rq);
    ASSERT_EQ(r.points.size(), 1u);
    ASSERT_GT(r.points[0].size(), 30u);
    EXPECT_EQ(pointsOut(v, r.points[0]), 0) << radius << " " << end.transpose();
  }
}

// A point off its voxel's centre, towards a brighter background: its background is the shell round the point itself
// (the criterion), not round its nearest voxel, which here reads lower and would leave the point just below
// the half-maximum (the aorta MRA's renal path from root 71,325,17, session 28).
TEST(DimPoints, ABackgroundIsReadRoundThePointNotItsVoxel) {
  Geometry g;
  g.dims = {24, 21, 21};
  g.spacing = Vec3(1, 1, 1);
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) v(x, y, z) = static_cast<float>(20 * y);  // a background ramp in y
  for (int64_t x = 1; x < 23; ++x) v(x, 10, 10) = 1000.0f;  // a one-voxel vessel along y = z = 10
  RefinedCentreline r;
  for (int64_t x = 2; x < 22; ++x) {
    r.points.emplace_back(static_cast<double>(x), x == 12 ? 10.45 : 10.0, 10.0);
    r.parent.push_back(static_cast<int32_t>(x) - 3);
    r.radiiMm.push_back(0.5);
  }
  const size_t k = 10;               // the point at (12, 10.45, 10)
  auto shell = [&](const Vec3& c) {  // the median of the voxels 3 .. 7 mm from c (2 r + 2 .. 2 r + 6)
    std::vector<double> s;
    for (int64_t z = 0; z < g.dims[2]; ++z)
      for (int64_t y = 0; y < g.dims[1]; ++y)
        for (int64_t x = 0; x < g.dims[0]; ++x)
          if (const double d = (Vec3(x, y, z) - c).norm(); d >= 3 && d <= 7) s.push_back(v(x, y, z));
    std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(s.size() / 2), s.end());
    return s[s.size() / 2];
  };
  const double halfAtPoint = 0.5 * (1000 + shell(r.points[k])), halfAtVoxel = 0.5 * (1000 + shell(Vec3(12, 10, 10)));
  ASSERT_GT(halfAtPoint, halfAtVoxel + 2);
  // The vessel dims at x = 12 (a grazed voxel) so that the point reads between the two half-maxima.
  v(12, 10, 10) = static_cast<float>((0.5 * (halfAtPoint + halfAtVoxel) - 0.45 * v(12, 11, 10)) / 0.55);
  ASSERT_LT(sampleTrilinear(v, r.points[k]), halfAtPoint);
  ASSERT_GT(sampleTrilinear(v, r.points[k]), halfAtVoxel);
  EXPECT_GE(ridgeDimPoints(v, r, 1), 1u);
  EXPECT_GE(sampleTrilinear(v, r.points[k]), halfAtPoint);
  EXPECT_LE((r.points[k] - Vec3(12, 10.45, 10)).norm(), 0.5 + 1e-9);
}
