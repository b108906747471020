#include "volume/slice.h"

#include <gtest/gtest.h>

#include "util/error.h"

using namespace vs;

namespace {
Geometry withDirection(const Mat3& d, Index3 dims = {10, 20, 30}) {
  Geometry g;
  g.dims = dims;
  g.spacing = Vec3(1, 2, 3);
  g.direction = d;
  return g;
}
}  // namespace

TEST(Slice, InPlaneAxesAndIndex) {
  EXPECT_EQ(sliceInPlaneAxes(0), (std::array<int, 2>{1, 2}));
  EXPECT_EQ(sliceInPlaneAxes(1), (std::array<int, 2>{0, 2}));
  EXPECT_EQ(sliceInPlaneAxes(2), (std::array<int, 2>{0, 1}));
  EXPECT_EQ(sliceToVolumeIndex(0, 5, 1, 2), (Index3{5, 1, 2}));
  EXPECT_EQ(sliceToVolumeIndex(1, 5, 1, 2), (Index3{1, 5, 2}));
  EXPECT_EQ(sliceToVolumeIndex(2, 5, 1, 2), (Index3{1, 2, 5}));
  EXPECT_THROW(sliceInPlaneAxes(3), InvalidArgument);
  EXPECT_EQ(sliceName(1, 7), "y=7");
}

TEST(Slice, OrientationCodes) {
  EXPECT_EQ(orientationCode(withDirection(Mat3::Identity())), "LPS");
  Mat3 ras = Mat3::Identity();
  ras(0, 0) = -1, ras(1, 1) = -1;  // a NIfTI in RAS as ITK reports it in LPS
  EXPECT_EQ(orientationCode(withDirection(ras)), "RAS");
  Mat3 sag;        // stored sagittally: index x runs posterior->anterior, y inferior->superior...
  sag << 0, 0, 1,  // world x (L) <- index z
      -1, 0, 0,    // world y (P) <- -index x (index x points anterior)
      0, 1, 0;     // world z (S) <- index y
  EXPECT_EQ(orientationCode(withDirection(sag)), "ASL");
  // A small oblique tilt keeps the dominant axes.
  Mat3 tilt;
  tilt << 0.98, -0.2, 0, 0.2, 0.98, 0, 0, 0, 1;
  EXPECT_EQ(orientationCode(withDirection(tilt)), "LPS");
}

TEST(Slice, FramesOfIdentityVolumeFollowTheRadiologicalConvention) {
  const Geometry g = withDirection(Mat3::Identity());
  const SliceFrame ax = sliceFrame(g, 2, 4);
  EXPECT_EQ(ax.plane, AnatomicalPlane::Axial);
  EXPECT_EQ(ax.colAxis, 0);
  EXPECT_EQ(ax.rowAxis, 1);
  EXPECT_FALSE(ax.colFlipped);
  EXPECT_FALSE(ax.rowFlipped);
  EXPECT_EQ(std::string(ax.edgeLetters.begin(), ax.edgeLetters.end()), "RLAP");
  const SliceFrame co = sliceFrame(g, 1, 4);
  EXPECT_EQ(co.plane, AnatomicalPlane::Coronal);
  EXPECT_EQ(co.rowAxis, 2);
  EXPECT_TRUE(co.rowFlipped);  // superior up
  EXPECT_EQ(std::string(co.edgeLetters.begin(), co.edgeLetters.end()), "RLSI");
  const SliceFrame sa = sliceFrame(g, 0, 4);
  EXPECT_EQ(sa.plane, AnatomicalPlane::Sagittal);
  EXPECT_EQ(sa.colAxis, 1);
  EXPECT_EQ(std::string(sa.edgeLetters.begin(), sa.edgeLetters.end()), "APSI");
  EXPECT_THROW(sliceFrame(g, 2, 30), InvalidArgument);
}

TEST(Slice, RasVolumeIsFlippedToAnteriorUpAndRightOnTheLeft) {
  Mat3 ras = Mat3::Identity();
  ras(0, 0) = -1, ras(1, 1) = -1;
  const Geometry g = withDirection(ras);
  const SliceFrame ax = sliceFrame(g, 2, 0);
  EXPECT_TRUE(ax.colFlipped);
  EXPECT_TRUE(ax.rowFlipped);
  // Picture column 0 is the patient's right: world x smallest.
  const Vec3 left = g.indexToWorld(ax.indexOf(0, 5)), right = g.indexToWorld(ax.indexOf(9, 5));
  EXPECT_LT(left.x(), right.x());
  const Vec3 top = g.indexToWorld(ax.indexOf(3, 0)), bottom = g.indexToWorld(ax.indexOf(3, 19));
  EXPECT_LT(top.y(), bottom.y());  // anterior (-y) at the top
}

TEST(Slice, SagittallyStoredSliceIsASagittalPicture) {
  Mat3 sag;
  sag << 0, 0, 1, -1, 0, 0, 0, 1, 0;
  const Geometry g = withDirection(sag);
  const SliceFrame f = sliceFrame(g, 2, 3);  // index z runs along world x: a sagittal slice
  EXPECT_EQ(f.plane, AnatomicalPlane::Sagittal);
  // Anterior on the left, superior up.
  const Vec3 l = g.indexToWorld(f.indexOf(0, 5)), r = g.indexToWorld(f.indexOf(double(f.width - 1), 5));
  EXPECT_LT(l.y(), r.y());
  const Vec3 t = g.indexToWorld(f.indexOf(2, 0)), b = g.indexToWorld(f.indexOf(2, double(f.height - 1)));
  EXPECT_GT(t.z(), b.z());
}

TEST(Slice, PictureIndexRoundTrip) {
  Mat3 sag;
  sag << 0, 0, 1, -1, 0, 0, 0, 1, 0;
  const Geometry g = withDirection(sag);
  for (int axis = 0; axis < 3; ++axis) {
    const SliceFrame f = sliceFrame(g, axis, 2);
    for (double c : {0.0, 3.0, 7.5})
      for (double r : {0.0, 4.0, 8.25}) {
        const Vec3 i = f.indexOf(c, r);
        EXPECT_DOUBLE_EQ(i[axis], 2.0);
        const auto back = f.pictureOf(i);
        EXPECT_DOUBLE_EQ(back[0], c);
        EXPECT_DOUBLE_EQ(back[1], r);
      }
  }
}

TEST(SliceMaskVolume, PaintsTheSlicePixelsIntoTheirVoxels) {
  vs::Geometry g;
  g.dims = {4, 3, 5};
  // Slice y=2: u = x (4 wide), v = z (5 high); mask pixels (1,0) and (3,4).
  std::vector<uint8_t> mask(20, 0);
  mask[1] = 1;
  mask[3 + 4 * 4] = 1;
  const vs::VolumeU8 m = vs::sliceMaskVolume(g, 1, 2, mask, 4, 5);
  int64_t count = 0;
  for (uint8_t v : m.voxels()) count += v;
  EXPECT_EQ(count, 2);
  EXPECT_EQ(m(1, 2, 0), 1);
  EXPECT_EQ(m(3, 2, 4), 1);
  EXPECT_THROW(vs::sliceMaskVolume(g, 1, 2, mask, 5, 4), vs::InvalidArgument);
  EXPECT_THROW(vs::sliceMaskVolume(g, 1, 3, mask, 4, 5), vs::InvalidArgument);
}

TEST(OrientationCode, DirectionFromTheCodeIsOrientationCodesInverse) {
  EXPECT_TRUE(directionFromOrientationCode("LPS").isApprox(Mat3::Identity()));
  const Mat3 ras = directionFromOrientationCode("ras");
  EXPECT_TRUE(ras.isApprox(Eigen::Vector3d(-1, -1, 1).asDiagonal().toDenseMatrix()));
  // Every valid code round-trips through orientationCode.
  const std::string pairs[3] = {"LR", "PA", "SI"};
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int n = 0;
  for (const auto& p : perms)
    for (int signs = 0; signs < 8; ++signs) {
      std::string code;
      for (int i = 0; i < 3; ++i) code += pairs[p[i]][(signs >> i) & 1];
      Geometry g;
      g.dims = {4, 5, 6};
      setOrientation(g, code);
      EXPECT_EQ(orientationCode(g), code);
      ++n;
    }
  EXPECT_EQ(n, 48);
  EXPECT_THROW(directionFromOrientationCode("LP"), InvalidArgument);
  EXPECT_THROW(directionFromOrientationCode("LRS"), InvalidArgument);
  EXPECT_THROW(directionFromOrientationCode("LPX"), InvalidArgument);
}
