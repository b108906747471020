// ROI crops and pastes: voxel values and world positions survive the round trip.
#include "volume/crop.h"

#include <gtest/gtest.h>

namespace vs {
namespace {

Volume<int16_t> ramp() {
  Geometry g;
  g.dims = {7, 6, 5};
  g.spacing = Vec3(0.5, 1.0, 2.0);
  g.origin = Vec3(-10, 4, 30);
  g.direction << 0, 1, 0, -1, 0, 0, 0, 0, 1;  // rotated: the origin shift must follow the direction
  Volume<int16_t> v(g);
  for (int64_t z = 0; z < 5; ++z)
    for (int64_t y = 0; y < 6; ++y)
      for (int64_t x = 0; x < 7; ++x) v(x, y, z) = static_cast<int16_t>(x + 10 * y + 100 * z);
  return v;
}

TEST(Crop, ValuesAndWorldPositionsAreKept) {
  const Volume<int16_t> v = ramp();
  const VoxelBox box = clampBox(v.geometry(), Vec3(1.2, 2, -3), Vec3(4, 4.9, 3));
  EXPECT_EQ(box.lo, (Index3{2, 2, 0}));
  EXPECT_EQ(box.hi, (Index3{4, 4, 3}));
  const Volume<int16_t> c = cropVolume(v, box);
  EXPECT_EQ(c.dims(), (Index3{3, 3, 4}));
  for (int64_t z = 0; z < 4; ++z)
    for (int64_t y = 0; y < 3; ++y)
      for (int64_t x = 0; x < 3; ++x) {
        const Index3 gl = box.toGlobal(Index3{x, y, z});
        EXPECT_EQ(c(x, y, z), v(gl[0], gl[1], gl[2]));
        const Vec3 a = c.geometry().indexToWorld(Vec3(double(x), double(y), double(z)));
        const Vec3 b = v.geometry().indexToWorld(Vec3(double(gl[0]), double(gl[1]), double(gl[2])));
        EXPECT_LT((a - b).norm(), 1e-12);
      }
  EXPECT_EQ(box.toLocal(box.toGlobal(Index3{1, 2, 3})), (Index3{1, 2, 3}));
  EXPECT_TRUE(box.contains({3, 3, 3}));
  EXPECT_FALSE(box.contains({3, 5, 3}));
}

TEST(Crop, PasteIsTheInverse) {
  const Volume<int16_t> v = ramp();
  const VoxelBox box{{1, 0, 2}, {5, 3, 4}};
  Volume<int16_t> whole(v.geometry(), -1);
  pasteVolume(cropVolume(v, box), box, whole);
  for (int64_t z = 0; z < 5; ++z)
    for (int64_t y = 0; y < 6; ++y)
      for (int64_t x = 0; x < 7; ++x)
        EXPECT_EQ(whole(x, y, z), box.contains({x, y, z}) ? v(x, y, z) : -1) << x << "," << y << "," << z;
  EXPECT_EQ(cropVolume(v, wholeBox(v.geometry())).voxels(), v.voxels());
}

TEST(Crop, BadBoxes) {
  const Volume<int16_t> v = ramp();
  EXPECT_THROW(clampBox(v.geometry(), Vec3(5, 0, 0), Vec3(4, 5, 4)), InvalidArgument);
  EXPECT_THROW(clampBox(v.geometry(), Vec3(8, 0, 0), Vec3(20, 5, 4)), InvalidArgument);
  EXPECT_THROW(cropVolume(v, VoxelBox{{0, 0, 0}, {7, 5, 4}}), InvalidArgument);
  Volume<int16_t> whole(v.geometry());
  EXPECT_THROW(pasteVolume(cropVolume(v, VoxelBox{{0, 0, 0}, {2, 2, 2}}), VoxelBox{{0, 0, 0}, {3, 2, 2}}, whole),
               InvalidArgument);
}

}  // namespace
}  // namespace vs
