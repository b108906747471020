// Tests for app/slice_layout on the core's picture frame (volume/slice.h sliceFrame): a volume
// stored sagittally shows its index-z slices as a sagittal view with the frame's letters and
// orientation, a transposed slice still picks the pixel shown, and a plainly stored volume keeps
// the usual layout.
#include "app/slice_layout.h"

#include <gtest/gtest.h>

#include "volume/slice.h"

using namespace vs;
using namespace vs::viewer;

namespace {
Geometry storedSagittally() {
  Geometry g;
  g.dims = {30, 20, 12};
  g.spacing = {0.7, 0.9, 1.5};
  g.direction.setZero();
  g.direction(2, 0) = 1;  // index x runs superior
  g.direction(1, 1) = 1;  // index y runs posterior
  g.direction(0, 2) = 1;  // index z runs left: its slices are sagittal
  return g;
}
}  // namespace

TEST(SliceLayout, FollowsTheCoresFrameForAVolumeStoredSagittally) {
  const Geometry g = storedSagittally();
  const SliceLayout L = sliceLayout(g, 2, 5);
  const SliceFrame f = sliceFrame(g, 2, 5);
  EXPECT_EQ(L.plane, "sagittal");
  EXPECT_EQ(L.plane, anatomicalPlaneName(f.plane));
  EXPECT_TRUE(L.transposed) << "index x runs superior-inferior: down the screen";
  EXPECT_EQ(L.left + L.right + L.top + L.bottom, std::string(f.edgeLetters.begin(), f.edgeLetters.end()));
  EXPECT_EQ(L.top, "S");
  EXPECT_EQ(L.bottom, "I");
  // Every slice pixel is shown where the core's frame puts it, and picks itself back.
  const SliceFit fit = fitSlice(L, 400, 300);
  for (int64_t v = 0; v < L.height; ++v)
    for (int64_t u = 0; u < L.width; ++u) {
      double sx = 0, sy = 0;
      L.toScreen(double(u), double(v), sx, sy);
      const Vec3 index(double(u), double(v), 5.0);
      const auto pic = f.pictureOf(index);
      EXPECT_NEAR(sx, (pic[0] + 0.5) / double(f.width), 1e-12);
      EXPECT_NEAR(sy, (pic[1] + 0.5) / double(f.height), 1e-12);
      const auto p = fit.viewOf(double(u), double(v));
      EXPECT_EQ(fit.pickAt(p[0], p[1]), (PixelUV{u, v}));
    }
  // The fitted picture has the slice's physical aspect as the screen shows it (rows along u).
  EXPECT_NEAR(fit.fitW / fit.fitH, (20 * 0.9) / (30 * 0.7), 1e-9);
}

TEST(SliceLayout, APlainVolumeKeepsTheUsualViews) {
  Geometry g;
  g.dims = {16, 16, 16};
  const char* planes[3] = {"sagittal", "coronal", "axial"};
  for (int axis = 0; axis < 3; ++axis) {
    const SliceLayout L = sliceLayout(g, axis, 3);
    EXPECT_EQ(L.plane, planes[axis]);
    EXPECT_FALSE(L.transposed);
    EXPECT_FALSE(L.flipU);
    EXPECT_EQ(L.flipV, axis != 2) << "superior up in sagittal and coronal views";
  }
  const SliceLayout axial = sliceLayout(g, 2, 3);
  EXPECT_EQ(axial.left + axial.right + axial.top + axial.bottom, "RLAP");
}
