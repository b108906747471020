// Correctness of the ray caster against analytic volumes: measured image properties with
// tolerances, never bytes.
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "util/error.h"

using namespace vs;

namespace {

constexpr double kPi = 3.14159265358979323846;

VolumeF32 makeVolume(Index3 dims, Vec3 spacing, const std::function<float(const Vec3& world)>& f) {
  Geometry g;
  g.dims = dims;
  g.spacing = spacing;
  g.origin = Vec3(-3, 7, 11);
  VolumeF32 v(g);
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x) v(x, y, z) = f(g.indexToWorld(Vec3(double(x), double(y), double(z))));
  return v;
}

Vec3 worldCentre(const Geometry& g) {
  return g.indexToWorld(Vec3(double(g.dims[0] - 1) / 2, double(g.dims[1] - 1) / 2, double(g.dims[2] - 1) / 2));
}

int countPixels(const RgbaImage& im, const std::function<bool(const uint8_t*)>& pred, int x0 = 0, int x1 = -1) {
  if (x1 < 0) x1 = im.width;
  int n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = x0; x < x1; ++x) n += pred(im.at(x, y)) ? 1 : 0;
  return n;
}

// Largest per-channel difference between two pictures of the same size.
int maxPixelDiff(const RgbaImage& a, const RgbaImage& b) {
  int d = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) d = std::max(d, std::abs(int(a.pixels[i]) - int(b.pixels[i])));
  return d;
}

}  // namespace

TEST(Renderer, SphereMipSilhouetteRadiusMatchesCameraScale) {
  // Anisotropic spacing: the sphere must stay round in world space.
  const double r = 12.0;
  VolumeF32 v = makeVolume({64, 64, 32}, Vec3(1, 1, 2), [&](const Vec3&) { return 0.f; });
  const Vec3 c = worldCentre(v.geometry());
  for (int64_t z = 0; z < 32; ++z)
    for (int64_t y = 0; y < 64; ++y)
      for (int64_t x = 0; x < 64; ++x)
        v(x, y, z) = (v.geometry().indexToWorld(Vec3(double(x), double(y), double(z))) - c).norm() <= r ? 100.f : 0.f;
  Renderer ren{AnyVolume(v)};
  RenderOptions o;
  o.mode = RenderMode::Mip;
  o.window = {100, 50};
  ren.setOptions(o);
  for (double az : {0.0, 90.0}) {
    const double zoom = 1.5;
    const Camera cam = orbitCamera(v.geometry(), az, 0, zoom, false);
    const int H = 200;
    const RenderResult res = ren.render(cam, H, H);
    const int bright = countPixels(res.image, [](const uint8_t* p) { return p[0] > 127; });
    const double pixelMm = cam.orthoHeight / H;
    const double radiusPx = std::sqrt(bright / kPi);
    EXPECT_NEAR(radiusPx, r / pixelMm, 0.04 * r / pixelMm) << "az " << az;
    // Inside the silhouette MIP shows the sphere's value (100 -> white).
    EXPECT_GT(res.image.at(H / 2, H / 2)[0], 250);
  }
}

TEST(Renderer, ConstantSlabOpacityFollowsCompositing) {
  VolumeF32 v = makeVolume({32, 32, 32}, Vec3(1, 1, 1), [](const Vec3&) { return 1.f; });
  Renderer ren{AnyVolume(v)};
  const double a = 0.02;  // per mm
  ren.setTransferFunction(TransferFunction({{0, {1, 1, 1}, a}, {2, {1, 1, 1}, a}}));
  for (double step : {0.5, 0.25, 1.0}) {
    RenderOptions o;
    o.shading = false;
    o.earlyTermination = 1.0;
    o.sampleStep = step;
    ren.setOptions(o);
    const RenderResult res = ren.render(orbitCamera(v.geometry(), 0, 0, 1.0, false), 64, 64);
    // A ray along +y crosses 31 mm of material: alpha = 1 - (1 - a)^(31 + step) with one sample
    // per step at both ends (n = 31/step + 1 samples of alpha 1 - (1-a)^step).
    const double expected = 1.0 - std::pow(1.0 - a, 31.0 + step);
    EXPECT_NEAR(res.image.at(32, 32)[0] / 255.0, expected, 2.0 / 255) << "step " << step;
    EXPECT_NEAR(res.image.at(32, 32)[0] / 255.0, 1.0 - std::pow(1.0 - a, 31.0), 0.012) << "step " << step;
  }
}

TEST(Renderer, TriplanarShowsTheRightSliceValuesAtTheRightPixels) {
  const Index3 dims{40, 30, 20};
  VolumeF32 v = makeVolume(dims, Vec3(1, 1.5, 2), [](const Vec3&) { return 0.f; });
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x) v(x, y, z) = float(x + 2 * y + 3 * z);  // linear: trilinear is exact
  Renderer ren{AnyVolume(v)};
  RenderOptions o;
  o.mode = RenderMode::Triplanar;
  o.planes = Vec3(12, 9, 7);
  o.window = {200, 100};  // grey = value / 200
  ren.setOptions(o);
  const Camera cam = orbitCamera(v.geometry(), 35, 25, 1.2, true);
  const int W = 160, H = 120;
  const RenderResult res = ren.render(cam, W, H);
  const CameraFrame cf(cam, W, H);
  const Geometry& g = v.geometry();
  int hits[3] = {0, 0, 0}, checked = 0;
  for (int py = 0; py < H; ++py)
    for (int px = 0; px < W; ++px) {
      const float d = res.depth[static_cast<size_t>(py) * W + px];
      if (!std::isfinite(d)) {
        EXPECT_EQ(res.image.at(px, py)[0], 0);
        continue;
      }
      Vec3 o3, dir;
      cf.ray(px, py, o3, dir);
      const Vec3 p = g.worldToIndex(o3 + dir * (d / dir.dot(cf.forward())));
      int plane = -1;
      for (int a = 0; a < 3; ++a)
        if (std::abs(p[a] - o.planes[a]) < 1e-3) plane = a;
      ASSERT_GE(plane, 0) << "pixel " << px << "," << py << " hit no plane: " << p.transpose();
      ++hits[plane];
      const double value = p.x() + 2 * p.y() + 3 * p.z();
      EXPECT_NEAR(res.image.at(px, py)[0], value / 200.0 * 255.0, 1.5);
      ++checked;
    }
  EXPECT_GT(hits[0], 100);
  EXPECT_GT(hits[1], 100);
  EXPECT_GT(hits[2], 100);

  // Monoplanar: only the z plane; looking straight down, pixel of voxel (x, y, 7) shows its value.
  o.mode = RenderMode::Monoplanar;
  o.planeAxis = 2;
  o.planeIndex = 7;
  ren.setOptions(o);
  const Camera top = orbitCamera(g, 0, 90, 1.0, false);
  const RenderResult r2 = ren.render(top, 100, 100);
  const CameraFrame tf(top, 100, 100);
  for (Vec3 idx : {Vec3(5, 5, 7), Vec3(30, 20, 7), Vec3(20, 10, 7)}) {
    double px, py, dd;
    ASSERT_TRUE(tf.project(g.indexToWorld(idx), px, py, dd));
    const uint8_t val = r2.image.at(int(px), int(py))[0];
    // The pixel centre is within half a pixel (0.5 * pixel mm) of the voxel: allow the local gradient.
    EXPECT_NEAR(val, (idx.x() + 2 * idx.y() + 21) / 200.0 * 255.0, 4.0);
  }
}

TEST(Renderer, OverlayLineInFrontIsVisibleAndBehindIsHidden) {
  // An opaque slab y in [20, 30] (index), looked at from -y (az = 0).
  VolumeF32 v = makeVolume({48, 48, 48}, Vec3(1, 1, 1), [](const Vec3&) { return 0.f; });
  for (int64_t z = 0; z < 48; ++z)
    for (int64_t y = 20; y <= 30; ++y)
      for (int64_t x = 0; x < 48; ++x) v(x, y, z) = 100.f;
  const Geometry& g = v.geometry();
  Renderer ren{AnyVolume(v)};
  ren.setTransferFunction(TransferFunction({{0, {1, 0, 0}, 0.0}, {50, {1, 0, 0}, 0.0}, {60, {1, 0, 0}, 1.0}}));
  RenderOptions o;
  o.shading = false;
  ren.setOptions(o);
  const Camera cam = orbitCamera(g, 0, 0, 1.0, false);
  const CameraFrame cf(cam, 128, 128);
  auto lineAt = [&](double yIndex) {
    Polyline pl;
    pl.points = {g.indexToWorld(Vec3(5, yIndex, 24)), g.indexToWorld(Vec3(42, yIndex, 24))};
    return std::vector<Polyline>{pl};
  };
  double px, py, d;
  ASSERT_TRUE(cf.project(g.indexToWorld(Vec3(24, 10, 24)), px, py, d));
  for (double yIndex : {10.0, 40.0}) {
    ren.clearOverlays();
    ren.addPolylines(lineAt(yIndex), {0, 1, 0}, 0.5);
    const RenderResult res = ren.render(cam, 128, 128);
    const uint8_t* p = res.image.at(int(px), int(py));
    if (yIndex < 20) {
      EXPECT_GT(p[1], 100) << "line in front of the slab must be visible";
      EXPECT_LT(p[0], 30);
    } else {
      EXPECT_LT(p[1], 30) << "line behind the opaque slab must be hidden";
      EXPECT_GT(p[0], 200);
    }
    // Away from the line the slab is red either way.
    EXPECT_GT(res.image.at(int(px), int(py) - 20)[0], 200);
  }
  // A triangle mesh behind the slab is hidden, in front it is visible (z-buffered).
  for (double yIndex : {5.0, 45.0}) {
    ren.clearOverlays();
    TriMesh m;
    m.positions = {g.indexToWorld(Vec3(10, yIndex, 10)), g.indexToWorld(Vec3(38, yIndex, 10)),
                   g.indexToWorld(Vec3(24, yIndex, 38))};
    m.triangles = {{0, 1, 2}};
    ren.addMesh(m, {0, 0, 1});
    const RenderResult res = ren.render(cam, 128, 128);
    double qx, qy, qd;
    ASSERT_TRUE(cf.project(g.indexToWorld(Vec3(24, yIndex, 20)), qx, qy, qd));
    const uint8_t* p = res.image.at(int(qx), int(qy));
    if (yIndex < 20)
      EXPECT_GT(p[2], 150);
    else
      EXPECT_LT(p[2], 30);
  }
  // Overlays far outside the volume are reported.
  ren.clearOverlays();
  Polyline far;
  far.points = {Vec3(1e4, 0, 0), Vec3(1e4, 10, 0)};
  ren.addPolylines({far}, {1, 1, 1});
  EXPECT_EQ(ren.overlayFractionOutside(), 1.0);
}

TEST(Renderer, EmptySpaceSkippingGivesTheSameImage) {
  // Noisy background below the TF threshold plus a few blobs; shading on.
  uint32_t seed = 12345;
  auto rnd = [&]() {
    seed = seed * 1664525u + 1013904223u;
    return (seed >> 8) / double(1 << 24);
  };
  VolumeF32 v = makeVolume({64, 56, 40}, Vec3(1, 1.2, 1.5), [&](const Vec3&) { return float(30 + 20 * rnd()); });
  const Geometry& g = v.geometry();
  const Vec3 c = worldCentre(g);
  for (int64_t z = 0; z < 40; ++z)
    for (int64_t y = 0; y < 56; ++y)
      for (int64_t x = 0; x < 64; ++x) {
        const Vec3 p = g.indexToWorld(Vec3(double(x), double(y), double(z)));
        if ((p - c - Vec3(10, 0, 0)).norm() < 9 || (p - c + Vec3(12, 5, 3)).norm() < 6)
          v(x, y, z) = 180.f + float(20 * rnd());
      }
  Renderer ren{AnyVolume(v)};
  ren.setTransferFunction(TransferFunction::preset("vessels", {0, 255, 0}));
  for (RenderMode mode : {RenderMode::Full, RenderMode::Mip}) {
    for (bool persp : {false, true}) {
      RenderOptions o;
      o.mode = mode;
      o.emptySpaceSkipping = false;
      ren.setOptions(o);
      const Camera cam = orbitCamera(g, 40, 30, 1.3, persp);
      const RenderResult a = ren.render(cam, 96, 96);
      o.emptySpaceSkipping = true;
      ren.setOptions(o);
      const RenderResult b = ren.render(cam, 96, 96);
      const int maxDiff = maxPixelDiff(a.image, b.image);
      EXPECT_LE(maxDiff, 1) << renderModeName(mode);
      EXPECT_LT(double(b.samples), (mode == RenderMode::Full ? 0.5 : 0.99) * double(a.samples)) << renderModeName(mode);
      EXPECT_GT(countPixels(b.image, [](const uint8_t* p) { return p[0] > 60; }), 200);
    }
  }
}

TEST(Renderer, MipFloorSkippingKeepsTheImage) {
  // Noise 30..50 under a window / TF that maps it to black: MIP may skip it without changing a pixel.
  uint32_t seed = 99;
  auto rnd = [&]() {
    seed = seed * 1664525u + 1013904223u;
    return (seed >> 8) / double(1 << 24);
  };
  VolumeF32 v = makeVolume({48, 48, 48}, Vec3(1, 1, 1), [&](const Vec3&) { return float(30 + 20 * rnd()); });
  for (int64_t z = 20; z < 28; ++z)
    for (int64_t y = 10; y < 40; ++y)
      for (int64_t x = 20; x < 26; ++x) v(x, y, z) = 150.f + float(50 * rnd());
  Renderer ren{AnyVolume(v)};
  ren.setTransferFunction(TransferFunction::preset("vessels", {0, 255, 0}));
  for (bool viaTf : {false, true}) {
    RenderOptions o;
    o.mode = RenderMode::Mip;
    o.window = {140, 130};  // 60..200
    o.mipTransferFunction = viaTf;
    o.emptySpaceSkipping = false;
    ren.setOptions(o);
    const Camera cam = orbitCamera(v.geometry(), 25, 15, 1.2, true);
    const RenderResult a = ren.render(cam, 80, 80);
    o.emptySpaceSkipping = true;
    ren.setOptions(o);
    const RenderResult b = ren.render(cam, 80, 80);
    const int maxDiff = maxPixelDiff(a.image, b.image);
    EXPECT_EQ(maxDiff, 0) << "tf " << viaTf;
    EXPECT_LT(double(b.samples), 0.3 * double(a.samples)) << "tf " << viaTf;
    EXPECT_GT(countPixels(b.image, [](const uint8_t* p) { return p[0] > 100; }), 100);
    // Centre of the bar: 150..200 -> TF colour (1, 0.9, 0.8) x opacity, or grey through the window.
    EXPECT_EQ(b.image.at(0, 0)[0], 0);
  }
}

TEST(Renderer, PerspectiveEnlargesNearObjectsOrthographicDoesNot) {
  // Two equal spheres: left one near the camera (small y, camera at -y), right one far.
  VolumeF32 v = makeVolume({64, 64, 32}, Vec3(1, 1, 1), [](const Vec3&) { return 0.f; });
  const Geometry& g = v.geometry();
  const Vec3 near = g.indexToWorld(Vec3(16, 8, 16)), far = g.indexToWorld(Vec3(48, 56, 16));
  for (int64_t z = 0; z < 32; ++z)
    for (int64_t y = 0; y < 64; ++y)
      for (int64_t x = 0; x < 64; ++x) {
        const Vec3 p = g.indexToWorld(Vec3(double(x), double(y), double(z)));
        if ((p - near).norm() <= 6 || (p - far).norm() <= 6) v(x, y, z) = 100.f;
      }
  Renderer ren{AnyVolume(v)};
  RenderOptions o;
  o.mode = RenderMode::Mip;
  o.window = {100, 50};
  ren.setOptions(o);
  auto areas = [&](bool persp) {
    const RenderResult r = ren.render(orbitCamera(g, 0, 0, 1.0, persp), 200, 200);
    auto bright = [](const uint8_t* p) { return p[0] > 127; };
    return std::pair<int, int>(countPixels(r.image, bright, 0, 100), countPixels(r.image, bright, 100, 200));
  };
  const auto [on, of] = areas(false);
  const auto [pn, pf] = areas(true);
  ASSERT_GT(on, 50);
  EXPECT_NEAR(double(on) / of, 1.0, 0.05);
  EXPECT_GT(double(pn) / pf, 1.15);
}

TEST(Renderer, ShadingDarkensTheRimOfASphere) {
  VolumeF32 v = makeVolume({48, 48, 48}, Vec3(1, 1, 1), [](const Vec3&) { return 0.f; });
  const Vec3 c = worldCentre(v.geometry());
  for (int64_t z = 0; z < 48; ++z)
    for (int64_t y = 0; y < 48; ++y)
      for (int64_t x = 0; x < 48; ++x) {
        const double d = (v.geometry().indexToWorld(Vec3(double(x), double(y), double(z))) - c).norm();
        v(x, y, z) = float(std::clamp(100.0 * (15.0 - d), 0.0, 200.0));  // smooth edge
      }
  Renderer ren{AnyVolume(v)};
  ren.setTransferFunction(TransferFunction({{0, {1, 1, 1}, 0.0}, {100, {1, 1, 1}, 1.0}}));
  RenderOptions o;
  o.specular = 0;
  ren.setOptions(o);
  const Camera cam = orbitCamera(v.geometry(), 20, 10, 1.0, false);
  const RenderResult r = ren.render(cam, 100, 100);
  const CameraFrame cf(cam, 100, 100);
  const double radiusPx = 14.5 / (cam.orthoHeight / 100);
  const int centre = r.image.at(50, 50)[0];
  const int rim = r.image.at(50 + int(radiusPx * 0.93), 50)[0];
  EXPECT_GT(centre, 200);  // facing the headlight: ambient + diffuse ~ 1.1
  EXPECT_LT(rim, centre - 60);
  EXPECT_GT(rim, 30);  // ambient keeps it visible
  // The depth image puts the front of the sphere at ~radius in front of the centre.
  double px, py, dc;
  cf.project(c, px, py, dc);
  EXPECT_NEAR(r.depth[50 * 100 + 50], dc - 14.5, 1.5);
}

TEST(Renderer, LightingFollowsBlinnPhongWithAHeadlight) {
  // A ramp along y: every gradient is (0, 1, 0), so every sample has the same n.l and
  // shaded colour s = c (ka + kd n.l) + ks (n.l)^p; the TF gives every sample the same colour c
  // and opacity, so the pixel is A s where A (the accumulated opacity) is the unshaded pixel / c.
  VolumeF32 v = makeVolume({32, 32, 32}, Vec3(1, 1, 1), [](const Vec3&) { return 0.f; });
  for (int64_t z = 0; z < 32; ++z)
    for (int64_t y = 0; y < 32; ++y)
      for (int64_t x = 0; x < 32; ++x) v(x, y, z) = float(y);
  Renderer ren{AnyVolume(v)};
  const double c = 0.4;
  ren.setTransferFunction(TransferFunction({{-1, {c, c, c}, 0.05}, {100, {c, c, c}, 0.05}}));
  struct Light {
    double ka, kd, ks, p;
  };
  for (const double az : {0.0, 45.0}) {  // az 0 looks along +y (n.l = 1), az 45 at 45 degrees
    const Camera cam = orbitCamera(v.geometry(), az, 0, 1.0, false);
    RenderOptions o;
    o.shading = false;
    ren.setOptions(o);
    const double alpha = ren.render(cam, 64, 64).image.at(32, 32)[0] / 255.0 / c;
    ASSERT_GT(alpha, 0.5);
    const double ndl = std::cos(az * kPi / 180);
    for (const Light l :
         {Light{0.3, 0.8, 0.2, 10}, Light{0, 0.8, 0.2, 10}, Light{0.5, 0.5, 0, 1}, Light{0.1, 0.6, 0.3, 3}}) {
      o.shading = true;
      o.ambient = l.ka, o.diffuse = l.kd, o.specular = l.ks, o.specularPower = l.p;
      ren.setOptions(o);
      const double expected = alpha * (c * (l.ka + l.kd * ndl) + l.ks * std::pow(ndl, l.p));
      EXPECT_NEAR(ren.render(cam, 64, 64).image.at(32, 32)[0] / 255.0, expected, 2.5 / 255)
          << "az " << az << " ka " << l.ka << " kd " << l.kd << " ks " << l.ks << " p " << l.p;
    }
  }
}

TEST(Renderer, SkippingKeepsTheImageAtGridFacesAndThinVolumes) {
  // Dims with n - 1 a multiple of 4 put the volume's far faces exactly on block faces (the
  // block walk ends there); bright voxels on faces, edges and corners; plus volumes one voxel
  // thick along an axis. Skipping must not change a pixel (composite, cut box and MIP).
  for (const Index3 dims : {Index3{33, 29, 17}, Index3{40, 30, 1}, Index3{1, 24, 20}, Index3{9, 9, 9}}) {
    VolumeF32 v = makeVolume(dims, Vec3(1, 1.25, 0.8), [](const Vec3&) { return 20.f; });
    for (int64_t z = 0; z < dims[2]; ++z)
      for (int64_t y = 0; y < dims[1]; ++y)
        for (int64_t x = 0; x < dims[0]; ++x) {
          const int onFace = (x == 0 || x == dims[0] - 1) + (y == 0 || y == dims[1] - 1) + (z == 0 || z == dims[2] - 1);
          if (onFace >= 2 || (x * 7 + y * 3 + z * 5) % 23 == 0) v(x, y, z) = 220.f;
        }
    Renderer ren{AnyVolume(v)};
    ren.setTransferFunction(TransferFunction::preset("vessels", {0, 255, 0}));
    for (RenderMode mode : {RenderMode::Full, RenderMode::CutBox, RenderMode::Mip}) {
      int visible = 0;  // thin volumes are invisible edge-on; some view must show them
      for (const double az : {0.0, 33.0, 90.0, 200.0}) {
        RenderOptions o;
        o.mode = mode;
        o.faceOpacity = 0;  // cut box: only the ray-cast inside
        if (mode == RenderMode::CutBox && dims[0] > 8 && dims[1] > 8 && dims[2] > 8)
          o.box = {4, 4, 4, double(dims[0] - 1), double(dims[1] - 1), double(dims[2] - 1)};
        o.emptySpaceSkipping = false;
        ren.setOptions(o);
        const Camera cam = orbitCamera(v.geometry(), az, az == 0 || az == 90 ? 0 : 35, 1.1, az == 33.0);
        const RenderResult a = ren.render(cam, 48, 40);
        o.emptySpaceSkipping = true;
        ren.setOptions(o);
        const RenderResult b = ren.render(cam, 48, 40);
        const int maxDiff = maxPixelDiff(a.image, b.image);
        EXPECT_LE(maxDiff, 1) << renderModeName(mode) << " az " << az << " dims " << dims[0] << "x" << dims[1] << "x"
                              << dims[2];
        visible += countPixels(b.image, [](const uint8_t* q) { return q[0] > 20; });
      }
      EXPECT_GT(visible, 50) << renderModeName(mode) << " dims " << dims[0] << "x" << dims[1] << "x" << dims[2];
    }
  }
}

TEST(Renderer, CutBoxShowsDataOnItsFacesOnlyInsideTheBox) {
  VolumeF32 v = makeVolume({40, 40, 40}, Vec3(1, 1, 1), [](const Vec3&) { return 0.f; });
  for (int64_t z = 0; z < 40; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 40; ++x) v(x, y, z) = float(5 * x);
  const Geometry& g = v.geometry();
  Renderer ren{AnyVolume(v)};
  RenderOptions o;
  o.mode = RenderMode::CutBox;
  o.box = {10, 10, 10, 30, 25, 30};
  o.window = {200, 100};
  ren.setOptions(o);
  const Camera cam = orbitCamera(g, 0, 0, 1.0, false);  // sees the y = 10 face
  const RenderResult r = ren.render(cam, 120, 120);
  const CameraFrame cf(cam, 120, 120);
  double px, py, d;
  ASSERT_TRUE(cf.project(g.indexToWorld(Vec3(20, 10, 20)), px, py, d));
  EXPECT_NEAR(r.image.at(int(px), int(py))[0], 100 / 200.0 * 255, 4);
  EXPECT_NEAR(r.depth[size_t(int(py)) * 120 + size_t(int(px))], d, 0.5);
  ASSERT_TRUE(cf.project(g.indexToWorld(Vec3(36, 10, 36)), px, py, d));
  EXPECT_EQ(r.image.at(int(px), int(py))[0], 0);  // outside the box: background
}

TEST(Renderer, LabelsTintPlanes) {
  VolumeF32 v = makeVolume({20, 20, 20}, Vec3(1, 1, 1), [](const Vec3&) { return 50.f; });
  VolumeU8 lab(v.geometry(), 0);
  for (int64_t y = 0; y < 10; ++y)
    for (int64_t x = 0; x < 20; ++x) lab(x, y, 10) = 2;
  Renderer ren{AnyVolume(v)};
  ren.setLabels(AnyVolume(lab));
  RenderOptions o;
  o.mode = RenderMode::Monoplanar;
  o.planeAxis = 2;
  o.planeIndex = 10;
  o.window = {100, 50};
  ren.setOptions(o);
  const Camera top = orbitCamera(v.geometry(), 0, 90, 1.0, false);
  const RenderResult r = ren.render(top, 80, 80);
  const CameraFrame cf(top, 80, 80);
  double px, py, d;
  cf.project(v.geometry().indexToWorld(Vec3(10, 4, 10)), px, py, d);
  const uint8_t* lp = r.image.at(int(px), int(py));
  cf.project(v.geometry().indexToWorld(Vec3(10, 15, 10)), px, py, d);
  const uint8_t* np = r.image.at(int(px), int(py));
  EXPECT_GT(lp[1], lp[0] + 40);  // label 2 is green
  EXPECT_NEAR(np[0], np[1], 1);  // unlabelled: grey
  VolumeU8 wrong(Geometry{{4, 4, 4}});
  EXPECT_THROW(ren.setLabels(AnyVolume(wrong)), InvalidArgument);
}

TEST(Renderer, BadInputIsRejectedClearly) {
  VolumeF32 v = makeVolume({16, 16, 16}, Vec3(1, 1, 1), [](const Vec3&) { return 1.f; });
  Renderer ren{AnyVolume(v)};
  const Camera cam = orbitCamera(v.geometry(), 0, 0, 1, false);
  EXPECT_THROW(ren.render(cam, 0, 10), InvalidArgument);
  EXPECT_THROW(ren.render(cam, 10000, 10), InvalidArgument);
  RenderOptions o;
  o.mode = RenderMode::CutBox;
  o.box = {5, 5, 5, 5, 10, 10};  // empty along x
  EXPECT_THROW(ren.setOptions(o), InvalidArgument);
  o.box = {20, 20, 20, 30, 30, 30};  // outside
  EXPECT_THROW(ren.setOptions(o), InvalidArgument);
  o = {};
  o.mode = RenderMode::Triplanar;
  o.planes = Vec3(3, 16, 2);
  EXPECT_THROW(ren.setOptions(o), InvalidArgument);
  o = {};
  o.mode = RenderMode::Monoplanar;
  o.planeAxis = 3;
  EXPECT_THROW(ren.setOptions(o), InvalidArgument);
  o.planeAxis = 0;
  o.planeIndex = 99;
  EXPECT_THROW(ren.setOptions(o), InvalidArgument);
  o = {};
  o.sampleStep = 0;
  EXPECT_THROW(ren.setOptions(o), InvalidArgument);
  o = {};
  o.ambient = 1.5;
  EXPECT_THROW(ren.setOptions(o), InvalidArgument);
  o = {};
  o.specularPower = -1;
  EXPECT_THROW(ren.setOptions(o), InvalidArgument);
  EXPECT_THROW(renderModeFromName("xray"), InvalidArgument);
  VolumeF32 bad = v;
  bad(1, 1, 1) = std::nanf("");
  EXPECT_THROW(Renderer(AnyVolume(bad)), DataError);
}
