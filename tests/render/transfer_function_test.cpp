#include "render/transfer_function.h"

#include <gtest/gtest.h>

#include <cmath>

#include "render/camera.h"
#include "util/error.h"

using namespace vs;

TEST(TransferFunction, PiecewiseLinearAndClamped) {
  TransferFunction tf({{100, {1, 0, 0}, 0.0}, {0, {0, 0, 1}, 0.5}, {200, {0, 1, 0}, 1.0}});
  ASSERT_EQ(tf.points().front().value, 0);  // sorted
  const Rgba a = tf.evaluate(50);
  EXPECT_NEAR(a.r, 0.5, 1e-6);
  EXPECT_NEAR(a.b, 0.5, 1e-6);
  EXPECT_NEAR(a.a, 0.25, 1e-6);
  EXPECT_NEAR(tf.evaluate(-1e9).a, 0.5, 1e-6);
  EXPECT_NEAR(tf.evaluate(1e9).g, 1.0, 1e-6);
  EXPECT_NEAR(tf.evaluate(150).a, 0.5, 1e-6);
}

TEST(TransferFunction, OpaqueRange) {
  TransferFunction tf({{0, {1, 1, 1}, 0.0}, {60, {1, 1, 1}, 0.0}, {200, {1, 1, 1}, 0.8}, {255, {1, 1, 1}, 0.0}});
  auto [lo, hi] = tf.opaqueRange();
  EXPECT_EQ(lo, 60);
  EXPECT_EQ(hi, 255);
  TransferFunction none({{0, {1, 1, 1}, 0.0}, {10, {1, 1, 1}, 0.0}});
  EXPECT_GT(none.opaqueRange().first, none.opaqueRange().second);
}

TEST(TransferFunction, PresetsAndUnknownPreset) {
  ValueRange r{0, 255, 0};
  for (const auto& n : TransferFunction::presetNames()) {
    const auto tf = TransferFunction::preset(n, r);
    EXPECT_FALSE(tf.empty()) << n;
  }
  // CT bone preset: soft tissue (40 HU) transparent, cortical bone (1000 HU) opaque.
  const auto bone = TransferFunction::preset("ct-bone", r);
  EXPECT_EQ(bone.evaluate(40).a, 0.f);
  EXPECT_GT(bone.evaluate(1000).a, 0.8f);
  EXPECT_THROW(TransferFunction::preset("ct-banana", r), InvalidArgument);
}

TEST(TransferFunction, JsonRoundTripAndErrors) {
  const auto tf = TransferFunction::fromJson(
      R"({"points": [{"value": 10, "color": [1, 0.5, 0], "opacity": 0.2}, {"value": 20, "opacity": 1}], "unit_distance": 2})");
  ASSERT_EQ(tf.points().size(), 2u);
  EXPECT_EQ(tf.unitDistance(), 2.0);
  EXPECT_NEAR(tf.evaluate(15).a, 0.6, 1e-6);
  const auto again = TransferFunction::fromJson(tf.toJson());
  EXPECT_NEAR(again.evaluate(15).r, tf.evaluate(15).r, 1e-6);

  EXPECT_THROW(TransferFunction::fromJson("{\"points\": [", "bad.json"), IoError);
  EXPECT_THROW(TransferFunction::fromJson("{\"points\": []}"), IoError);
  EXPECT_THROW(TransferFunction::fromJson("{\"points\": [{\"value\": 1}]}"), IoError);
  EXPECT_THROW(TransferFunction::fromJson("{\"points\": [{\"value\": 1, \"opacity\": 2}]}"), InvalidArgument);
  EXPECT_THROW(TransferFunction::fromJson("{\"points\": [{\"value\": 1, \"color\": [1,2], \"opacity\": 0.5}]}"),
               IoError);
  try {
    TransferFunction::fromJson("[1,2", "my_tf.json");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("my_tf.json"), std::string::npos);
  }
}

TEST(TfTable, OpacityCorrectionAndEmptiness) {
  TransferFunction tf({{0, {1, 1, 1}, 0.0}, {100, {1, 1, 1}, 0.0}, {101, {1, 1, 1}, 0.5}, {255, {1, 1, 1}, 0.5}});
  TfTable t(tf, 0, 255, 0.5, 256);
  // 0.5 per mm, step 0.5 mm: 1 - sqrt(0.5).
  EXPECT_NEAR(t(200).a, 1.0 - std::sqrt(0.5), 1e-5);
  EXPECT_EQ(t(50).a, 0.f);
  EXPECT_TRUE(t.transparent(0, 99));
  EXPECT_FALSE(t.transparent(0, 150));
  EXPECT_FALSE(t.transparent(120, 130));
}

TEST(Camera, OrbitFramesTheVolumeAndProjectsConsistently) {
  Geometry g;
  g.dims = {33, 17, 9};
  g.spacing = Vec3(1, 2, 4);
  g.origin = Vec3(-10, 5, 3);
  for (bool persp : {false, true}) {
    const Camera cam = orbitCamera(g, 30, 20, 1.0, persp);
    const CameraFrame cf(cam, 200, 100);
    // Centre of the volume projects to the image centre.
    double px, py, depth;
    ASSERT_TRUE(cf.project(cam.target, px, py, depth));
    EXPECT_NEAR(px, 100, 1e-6);
    EXPECT_NEAR(py, 50, 1e-6);
    // Every corner is inside the image at zoom 1.
    for (int c = 0; c < 8; ++c) {
      const Vec3 idx((c & 1) ? 32 : 0, (c & 2) ? 16 : 0, (c & 4) ? 8 : 0);
      ASSERT_TRUE(cf.project(g.indexToWorld(idx), px, py, depth));
      EXPECT_GE(py, 0);
      EXPECT_LE(py, 100);
    }
    // A point along the ray through pixel (37, 61) projects back to that pixel centre.
    Vec3 o, d;
    cf.ray(37, 61, o, d);
    ASSERT_TRUE(cf.project(o + 50.0 * d, px, py, depth));
    EXPECT_NEAR(px, 37.5, 1e-6);
    EXPECT_NEAR(py, 61.5, 1e-6);
  }
}

TEST(Camera, DegenerateCamerasThrow) {
  Camera c;
  c.eye = c.target;
  EXPECT_THROW(c.validate(), InvalidArgument);
  Camera d;
  d.up = (d.target - d.eye);
  EXPECT_THROW(d.validate(), InvalidArgument);
  Camera e;
  e.perspective = true;
  e.fovDeg = 0;
  EXPECT_THROW(e.validate(), InvalidArgument);
  Geometry g;
  g.dims = {4, 4, 4};
  EXPECT_THROW(orbitCamera(g, 0, 0, 0.0, false), InvalidArgument);
  // Looking straight down is fine (up is replaced).
  EXPECT_NO_THROW(CameraFrame(orbitCamera(g, 0, 90, 1, false), 10, 10));
}
