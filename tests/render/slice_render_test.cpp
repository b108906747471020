#include "render/slice_render.h"

#include <gtest/gtest.h>

#include "util/error.h"

using namespace vs;

namespace {
VolumeI16 ramp() {
  Geometry g;
  g.dims = {20, 10, 5};
  g.spacing = Vec3(1, 2, 3);
  VolumeI16 v(g);
  for (int64_t z = 0; z < 5; ++z)
    for (int64_t y = 0; y < 10; ++y)
      for (int64_t x = 0; x < 20; ++x) v(x, y, z) = static_cast<int16_t>(10 * x + z);
  return v;
}
}  // namespace

TEST(SliceRender, AspectFollowsSpacing) {
  const AnyVolume v = ramp();
  SliceImageOptions o;
  o.window = {200, 100};
  const RgbaImage ax = renderSlice(v, 2, 2, o);
  EXPECT_EQ(ax.width, 20);   // 20 voxels x 1 mm
  EXPECT_EQ(ax.height, 20);  // 10 voxels x 2 mm at 1 mm pixels
  const RgbaImage co = renderSlice(v, 1, 3, o);
  EXPECT_EQ(co.width, 20);
  EXPECT_EQ(co.height, 15);  // 5 x 3 mm
  const RgbaImage sa = renderSlice(v, 0, 3, o);
  EXPECT_EQ(sa.width, 10);   // y: 10 x 2 mm at 2 mm pixels (min(2, 3))
  EXPECT_EQ(sa.height, 8);   // z: 5 x 3 mm / 2 mm = 7.5 -> 8
}

TEST(SliceRender, WindowLevelAndOrientation) {
  const AnyVolume v = ramp();
  SliceImageOptions o;
  o.window = {200, 100};  // grey = value / 200
  const RgbaImage ax = renderSlice(v, 2, 4, o);
  // Pixel column i covers x = i (1 mm pixels): value 10 x + 4.
  EXPECT_NEAR(ax.at(7, 5)[0], (70 + 4) / 200.0 * 255, 1.0);
  // Coronal: z up, so the top row is z = 4 and the bottom row z = 0.
  const RgbaImage co = renderSlice(v, 1, 0, o);
  EXPECT_GT(co.at(3, 0)[0], co.at(3, co.height - 1)[0]);
  // Fit into a box keeps the aspect.
  o.fitWidth = 100;
  o.fitHeight = 100;
  const RgbaImage big = renderSlice(v, 1, 0, o);
  EXPECT_EQ(big.width, 100);
  EXPECT_EQ(big.height, 75);
}

TEST(SliceRender, BadInput) {
  const AnyVolume v = ramp();
  EXPECT_THROW(renderSlice(v, 3, 0), InvalidArgument);
  EXPECT_THROW(renderSlice(v, 2, 5), InvalidArgument);
  EXPECT_THROW(renderSlice(v, 0, -1), InvalidArgument);
  SliceImageOptions o;
  o.fitWidth = 100000;
  o.fitHeight = 100000;
  EXPECT_THROW(renderSlice(v, 2, 0, o), InvalidArgument);
  VolumeU8 lab(Geometry{{3, 3, 3}});
  const AnyVolume l = lab;
  EXPECT_THROW(renderSlice(v, 2, 0, {}, &l), InvalidArgument);
}
