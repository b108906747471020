#include "volume/volume.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace vs;

TEST(Geometry, IndexWorldRoundTripWithDirectionAndSpacing) {
  Geometry g;
  g.dims = {10, 20, 30};
  g.spacing = {0.5, 1.0, 2.5};
  g.origin = {-10, 5, 100};
  g.direction << 0, 1, 0, -1, 0, 0, 0, 0, 1;  // 90 degree rotation about z
  const Vec3 idx(3, 4, 5);
  const Vec3 w = g.indexToWorld(idx);
  // x index axis maps to -y world, y index axis to +x world.
  EXPECT_NEAR(w[0], -10 + 4 * 1.0, 1e-12);
  EXPECT_NEAR(w[1], 5 - 3 * 0.5, 1e-12);
  EXPECT_NEAR(w[2], 100 + 5 * 2.5, 1e-12);
  EXPECT_TRUE(g.worldToIndex(w).isApprox(idx, 1e-12));
  EXPECT_NEAR(g.stepLength(Vec3(1, 1, 1)), std::sqrt(0.25 + 1 + 6.25), 1e-12);
}

TEST(Geometry, ValidateRejectsBadSpacing) {
  Geometry g;
  g.dims = {2, 2, 2};
  g.spacing = {1, 0, 1};
  EXPECT_THROW(g.validate(), InvalidArgument);
  g.spacing = {1, NAN, 1};
  EXPECT_THROW(g.validate(), InvalidArgument);
}

TEST(Volume, RefusesAbsurdSizeBeforeAllocating) {
  Geometry g;
  g.dims = {100000, 100000, 100000};
  EXPECT_THROW(VolumeF32 v(g), DataError);
}

TEST(Volume, SliceViewsAddressTheRightVoxels) {
  Geometry g;
  g.dims = {4, 5, 6};
  g.spacing = {1, 2, 3};
  VolumeI16 v(g);
  for (int64_t z = 0; z < 6; ++z)
    for (int64_t y = 0; y < 5; ++y)
      for (int64_t x = 0; x < 4; ++x) v(x, y, z) = static_cast<int16_t>(100 * z + 10 * y + x);
  auto axial = sliceView(v, 2, 3);
  EXPECT_EQ(axial.width, 4);
  EXPECT_EQ(axial.height, 5);
  EXPECT_EQ(axial(2, 4), 342);
  auto coronal = sliceView(v, 1, 2);
  EXPECT_EQ(coronal(3, 5), 523);
  EXPECT_DOUBLE_EQ(coronal.spacingV, 3);
  auto sag = sliceView(v, 0, 1);
  EXPECT_EQ(sag(4, 2), 241);
  EXPECT_THROW(sliceView(v, 2, 6), InvalidArgument);
  auto img = extractSlice(v, 1, 2);
  EXPECT_EQ(img.dims()[0], 4);
  EXPECT_EQ(img.dims()[1], 6);
  EXPECT_EQ(img(3, 5, 0), 523);
  // Pixel (u,v) of the extracted slice sits at the same world point as its voxel.
  EXPECT_TRUE(img.geometry().indexToWorld(Vec3(3, 5, 0)).isApprox(g.indexToWorld(Vec3(3, 2, 5))));
}

TEST(Volume, RangeAndFiniteness) {
  Geometry g;
  g.dims = {3, 1, 1};
  VolumeF32 v(g);
  v(0, 0, 0) = -1;
  v(1, 0, 0) = NAN;
  v(2, 0, 0) = 7;
  AnyVolume any = v;
  auto r = valueRange(any);
  EXPECT_EQ(r.min, -1);
  EXPECT_EQ(r.max, 7);
  EXPECT_EQ(r.nonFinite, 1);
  EXPECT_THROW(requireFinite(any, "test"), DataError);
}

TEST(Volume, ParseSliceSpec) {
  EXPECT_EQ(parseSliceSpec("z=40"), (std::pair<int, int64_t>{2, 40}));
  EXPECT_EQ(parseSliceSpec("sagittal=3"), (std::pair<int, int64_t>{0, 3}));
  EXPECT_THROW(parseSliceSpec("q=1"), InvalidArgument);
  EXPECT_THROW(parseSliceSpec("z=1x"), InvalidArgument);
}
