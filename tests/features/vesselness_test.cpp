// Frangi vesselness (features/vesselness.h): eigenvalues, tube vs. blob vs. plate, polarity,
// anisotropic spacing.
#include "features/vesselness.h"

#include <gtest/gtest.h>

#include <cmath>

namespace vs {
namespace {

TEST(Vesselness, EigenvaluesOfKnownMatrices) {
  double l[3];
  symmetricEigenvalues3(3, -1, 0.5, 0, 0, 0, l);
  EXPECT_NEAR(l[0], 0.5, 1e-12);
  EXPECT_NEAR(l[1], -1, 1e-12);
  EXPECT_NEAR(l[2], 3, 1e-12);
  // [[2,1,0],[1,2,0],[0,0,5]] -> 1, 3, 5
  symmetricEigenvalues3(2, 2, 5, 1, 0, 0, l);
  EXPECT_NEAR(l[0], 1, 1e-9);
  EXPECT_NEAR(l[1], 3, 1e-9);
  EXPECT_NEAR(l[2], 5, 1e-9);
}

// A Gaussian-profile bright tube along x (radius ~2 mm), a blob, and a plate.
VolumeF32 scene(Vec3 spacing, bool tube, bool blob, bool plate) {
  Geometry g;
  g.dims = {40, 40, 40};
  g.spacing = spacing;
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < 40; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 40; ++x) {
        const double X = x * spacing[0], Y = y * spacing[1], Z = z * spacing[2];
        const double cy = 20 * spacing[1], cz = 20 * spacing[2];
        double val = 0;
        if (tube) val += 100 * std::exp(-((Y - cy) * (Y - cy) + (Z - cz) * (Z - cz)) / (2 * 2.0 * 2.0));
        if (blob) val += 100 * std::exp(-((X - cy) * (X - cy) + (Y - cy) * (Y - cy) + (Z - cz) * (Z - cz)) / 8.0);
        if (plate) val += 100 * std::exp(-((Z - cz) * (Z - cz)) / 8.0);
        v(x, y, z) = static_cast<float>(val);
      }
  return v;
}

TEST(Vesselness, TubeBeatsBlobAndPlateAndPolarityMatters) {
  VesselnessOptions o;
  o.scalesMm = {1.5, 2.0, 3.0};
  o.c = 10;  // fixed structureness scale so the three scenes compare on one scale
  const auto tube = computeVesselness(scene(Vec3(1, 1, 1), true, false, false), o);
  const auto blob = computeVesselness(scene(Vec3(1, 1, 1), false, true, false), o);
  const auto plate = computeVesselness(scene(Vec3(1, 1, 1), false, false, true), o);
  Geometry g;
  g.dims = {40, 40, 40};
  const size_t c = static_cast<size_t>(g.linear(20, 20, 20));
  EXPECT_GT(tube[c], 0.5f);
  EXPECT_LT(blob[c], 0.5f * tube[c]);
  EXPECT_LT(plate[c], 0.5f * tube[c]);
  // Off the tube, the response falls.
  EXPECT_LT(tube[static_cast<size_t>(g.linear(20, 30, 20))], 0.1f * tube[c]);
  o.polarity = TubePolarity::Dark;
  const auto dark = computeVesselness(scene(Vec3(1, 1, 1), true, false, false), o);
  EXPECT_EQ(dark[c], 0.0f);
}

TEST(Vesselness, AnisotropicSpacingKeepsTheTube) {
  VesselnessOptions o;
  o.scalesMm = {2.0};
  const auto v = computeVesselness(scene(Vec3(0.8, 0.8, 1.6), true, false, false), o);
  Geometry g;
  g.dims = {40, 40, 40};
  const size_t centre = static_cast<size_t>(g.linear(20, 20, 20));
  EXPECT_GT(v[centre], 0.3f);
  EXPECT_GT(v[centre], 5 * v[static_cast<size_t>(g.linear(20, 20, 27))]);
}

TEST(Vesselness, SmoothingPreservesMeanAndRejectsBadScales) {
  Geometry g;
  g.dims = {10, 10, 10};
  VolumeF32 v(g, 5.0f);
  const VolumeF32 s = gaussianSmooth3D(v, 2.0);
  for (float x : s.voxels()) EXPECT_NEAR(x, 5.0f, 1e-4);
  VesselnessOptions o;
  o.scalesMm = {-1};
  EXPECT_THROW(computeVesselness(v, o), InvalidArgument);
}

}  // namespace
}  // namespace vs
