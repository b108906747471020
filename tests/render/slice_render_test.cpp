#include "render/slice_render.h"

#include <gtest/gtest.h>

#include "phantom/phantom.h"
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
  EXPECT_EQ(sa.width, 10);  // y: 10 x 2 mm at 2 mm pixels (min(2, 3))
  EXPECT_EQ(sa.height, 8);  // z: 5 x 3 mm / 2 mm = 7.5 -> 8
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

namespace {
// The same voxels stored in another axis order: new index axis k is old axis perm[k],
// reversed when flip[k]; direction and origin change so every voxel keeps its world position.
template <class T>
Volume<T> restored(const Volume<T>& v, std::array<int, 3> perm, std::array<bool, 3> flip) {
  const Geometry& g = v.geometry();
  Geometry n;
  for (size_t k = 0; k < 3; ++k) {
    const int a = perm[k];
    n.dims[k] = g.dims[static_cast<size_t>(a)];
    n.spacing[static_cast<int>(k)] = g.spacing[a];
    n.direction.col(static_cast<int>(k)) = g.direction.col(a) * (flip[k] ? -1.0 : 1.0);
  }
  auto oldIndex = [&](int64_t i, int64_t j, int64_t l) {
    const int64_t nk[3] = {i, j, l};
    Index3 o{};
    for (size_t k = 0; k < 3; ++k) {
      const size_t a = static_cast<size_t>(perm[k]);
      o[a] = flip[k] ? g.dims[a] - 1 - nk[k] : nk[k];
    }
    return o;
  };
  const Index3 o0 = oldIndex(0, 0, 0);
  n.origin = g.indexToWorld(Vec3(double(o0[0]), double(o0[1]), double(o0[2])));
  Volume<T> out(n);
  for (int64_t l = 0; l < n.dims[2]; ++l)
    for (int64_t j = 0; j < n.dims[1]; ++j)
      for (int64_t i = 0; i < n.dims[0]; ++i) {
        const Index3 o = oldIndex(i, j, l);
        out(i, j, l) = v(o[0], o[1], o[2]);
      }
  return out;
}

// Mean grey of the top and bottom quarter of a picture.
std::pair<double, double> topBottomMeans(const RgbaImage& img) {
  double top = 0, bottom = 0;
  int nt = 0, nb = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (y < img.height / 4) top += img.at(x, y)[0], ++nt;
      if (y >= img.height * 3 / 4) bottom += img.at(x, y)[0], ++nb;
    }
  return {top / nt, bottom / nb};
}
}  // namespace

TEST(SliceRender, AnyStorageOrderGivesTheSamePictureAnteriorUp) {
  HeadPhantomOptions ho;
  ho.dims = {40, 48, 36};
  ho.spacing = Vec3(1.0, 1.0, 1.5);
  ho.seed = 5;
  const HeadPhantom head = makeHeadPhantom(ho);
  const int64_t noseZ = (head.truth.noseBoxMin[2] + head.truth.noseBoxMax[2]) / 2;
  SliceImageOptions so;
  so.window = {400, 0};
  const RgbaImage reference = renderSlice(AnyVolume(head.volume), 2, noseZ, so);
  // Anterior up: the nose (index y = 0 side, anterior in LPS) is the top of the axial picture.
  int noseRow = -1;
  for (int y = 0; y < reference.height && noseRow < 0; ++y)
    if (reference.at(reference.width / 2, y)[0] > 100) noseRow = y;
  // In-plane spacing is 1 mm, so picture rows are y indices; the first tissue from the top is the nose.
  EXPECT_GE(noseRow, head.truth.noseBoxMin[1]);
  EXPECT_LE(noseRow, head.truth.noseBoxMax[1]);

  const std::array<std::array<int, 3>, 4> perms{{{0, 1, 2}, {2, 0, 1}, {1, 2, 0}, {2, 1, 0}}};
  const std::array<std::array<bool, 3>, 3> flips{{{false, false, false}, {true, true, false}, {false, true, true}}};
  for (const auto& perm : perms)
    for (const auto& flip : flips) {
      const VolumeI16 other = restored(head.volume, perm, flip);
      int axis = 0;
      while (perm[static_cast<size_t>(axis)] != 2) ++axis;
      const int64_t index = flip[static_cast<size_t>(axis)] ? ho.dims[2] - 1 - noseZ : noseZ;
      for (bool native : {false, true}) {
        SliceImageOptions o = so;
        o.pixelPerVoxel = native;
        const RgbaImage a = native ? renderSlice(AnyVolume(head.volume), 2, noseZ, o) : reference;
        const RgbaImage b = renderSlice(AnyVolume(other), axis, index, o);
        ASSERT_EQ(a.width, b.width);
        ASSERT_EQ(a.height, b.height);
        int maxDiff = 0;
        for (size_t i = 0; i < a.pixels.size(); ++i)
          maxDiff = std::max(maxDiff, std::abs(int(a.pixels[i]) - int(b.pixels[i])));
        EXPECT_LE(maxDiff, native ? 0 : 1) << "perm " << perm[0] << perm[1] << perm[2] << " flip " << flip[0] << flip[1]
                                           << flip[2] << (native ? " native" : " resampled");
      }
    }
  // Coronal and sagittal pictures put the top of the head (superior, +z) up.
  const int64_t midY = ho.dims[1] / 2, midX = ho.dims[0] / 2;
  for (auto [axis, index] : {std::pair<int, int64_t>{1, midY}, {0, midX}}) {
    const VolumeI16 flipped = restored(head.volume, {0, 1, 2}, {false, false, true});
    const auto [top, bottom] = topBottomMeans(renderSlice(AnyVolume(flipped), axis, index, so));
    const auto [top0, bottom0] = topBottomMeans(renderSlice(AnyVolume(head.volume), axis, index, so));
    EXPECT_NEAR(top, top0, 1e-9);
    EXPECT_NEAR(bottom, bottom0, 1e-9);
  }
}

TEST(SliceRender, PictureMappingAndAnnotations) {
  const AnyVolume v = ramp();  // value 10 x + z, spacing 1 x 2 x 3
  SliceImageOptions o;
  o.window = {200, 100};
  o.fitWidth = 60;
  o.fitHeight = 60;
  const SlicePicture pic = slicePicture(geometryOf(v), 2, 1, o);
  EXPECT_EQ(pic.width, 60);  // 20 x 20 mm (10 voxels of 2 mm along y) fitted into 60 x 60
  EXPECT_EQ(pic.height, 60);
  EXPECT_NEAR(pic.indexPerColumn.x(), 1.0 / 3, 1e-12);
  EXPECT_NEAR(pic.indexPerRow.y(), 1.0 / 6, 1e-12);
  for (double i : {0.0, 7.0, 59.0})
    for (double j : {0.0, 13.0, 59.0}) {
      const auto back = pic.pixelOf(pic.indexOf(i, j));
      EXPECT_NEAR(back[0], i, 1e-9);
      EXPECT_NEAR(back[1], j, 1e-9);
    }
  // The value at a picture pixel is the volume's at the mapped index (linear ramp: exact).
  const RgbaImage img = renderSlice(v, 2, 1, o);
  const Vec3 at = pic.indexOf(11, 20);
  EXPECT_NEAR(img.at(11, 20)[0], (10 * at.x() + 1) / 200.0 * 255, 1.0);
  // One pixel per voxel: the picture is the voxel grid.
  o.pixelPerVoxel = true;
  const SlicePicture native = slicePicture(geometryOf(v), 2, 1, o);
  EXPECT_EQ(native.width, 20);
  EXPECT_EQ(native.height, 10);
  EXPECT_EQ(native.indexOf(4, 6), Vec3(4, 6, 1));
  // Ticks and letters change only the border of the picture.
  const RgbaImage plain = renderSlice(v, 2, 1, o);
  o.indexTicks = true;
  const RgbaImage ticks = renderSlice(v, 2, 1, o);
  EXPECT_NE(plain.at(10, 0)[2], ticks.at(10, 0)[2]);  // tick at x = 10
  EXPECT_EQ(plain.at(10, 9)[0], ticks.at(10, 9)[0]);
}

TEST(SliceRender, OverlaysKeepTheirColours) {
  const AnyVolume v = ramp();
  const Geometry& g = geometryOf(v);
  Polyline a, b;
  a.points = {g.indexToWorld(Vec3(2, 2, 1)), g.indexToWorld(Vec3(2, 8, 1))};
  b.points = {g.indexToWorld(Vec3(15, 2, 1)), g.indexToWorld(Vec3(15, 8, 1))};
  const std::vector<Polyline> lines{a, b};
  SliceImageOptions o;
  o.pixelPerVoxel = true;
  o.polylineColors = {{1, 0, 0}, {0, 0, 1}};
  const RgbaImage img = renderSlice(v, 2, 1, o, nullptr, &lines);
  EXPECT_EQ(img.at(2, 5)[0], 255);
  EXPECT_EQ(img.at(2, 5)[2], 0);
  EXPECT_EQ(img.at(15, 5)[0], 0);
  EXPECT_EQ(img.at(15, 5)[2], 255);
  o.polylineColors.pop_back();
  EXPECT_THROW(renderSlice(v, 2, 1, o, nullptr, &lines), InvalidArgument);
}
