// The GPU ray caster against the CPU renderer (render/renderer.h) for the same camera, transfer
// function and mode, on an offscreen EGL context (Mesa's llvmpipe here): SSIM >= 0.95 on the
// foreground. Skips with a message where no OpenGL 3.3 context can be made.
#ifdef VS_HAVE_VIEWER
#include "gl/raycaster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "app/viewer_app.h"
#include "gl/egl_context.h"
#include "io/png_io.h"
#include "phantom/phantom.h"
#include "viewer_test_util.h"

using namespace vs;
using namespace vs::viewer;

namespace {

struct Offscreen {
  std::unique_ptr<EglContext> context;
  std::string why;
  Offscreen() {
    try {
      context = std::make_unique<EglContext>();
    } catch (const std::exception& e) {
      why = e.what();
    }
  }
};

}  // namespace

class GpuVsCpu : public ::testing::TestWithParam<RenderMode> {};

TEST_P(GpuVsCpu, SsimOnTheForeground) {
  Offscreen gl;
  if (!gl.context) GTEST_SKIP() << "no offscreen OpenGL 3.3 context: " << gl.why;
  const RenderMode mode = GetParam();
  HeadPhantomOptions ho;
  ho.dims = {64, 72, 56};
  ho.spacing = {1.0, 0.9, 1.2};
  AnyVolume vol(makeHeadPhantom(ho).volume);
  const ValueRange range = valueRange(vol);
  const TransferFunction tf = TransferFunction::preset("ct-skin", range);
  const int W = 160, H = 128;
  const Geometry& g = geometryOf(vol);
  const Camera cam = orbitCamera(g, 30, 20, 1.0, true);

  RenderOptions ro;
  ro.mode = mode;
  ro.window = {400, 40};
  ro.box = {0, 0, 0, double(g.dims[0] - 1), double(g.dims[1] - 1), 30};
  ro.planes = Vec3(20, 30, 25);
  ro.planeAxis = 1;
  ro.planeIndex = 30;
  Renderer cpu(vol);
  cpu.setTransferFunction(tf);
  cpu.setOptions(ro);
  const RgbaImage ref = cpu.render(cam, W, H).image;

  GpuRayCaster gpu;
  gpu.setVolume(vol);
  gpu.setTransferFunction(tf);
  RayCastSettings s;
  s.mode = mode;
  s.window = ro.window;
  s.box = ro.box;
  s.planes = ro.planes;
  s.planeAxis = ro.planeAxis;
  s.planeIndex = ro.planeIndex;
  s.jitter = false;  // the CPU renderer has a fixed sample lattice
  const RgbaImage img = gpu.renderImage(eyeView(cam, double(W) / H), W, H, s);

  const double fg = foregroundFraction(ref);
  EXPECT_GT(fg, 0.02) << "the reference shows the volume";
  if (const char* dir = std::getenv("VS_VIEWER_TEST_IMAGES")) {  // to look at the pair
    writePng(ref, std::string(dir) + "/cpu_" + renderModeName(mode) + ".png");
    writePng(img, std::string(dir) + "/gpu_" + renderModeName(mode) + ".png");
  }
  EXPECT_NEAR(foregroundFraction(img), fg, 0.03);
  const double ssim = foregroundSsim(img, ref);
  int maxDiff = 0;
  int64_t differing = 0;
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    const int d = std::abs(int(img.pixels[i]) - int(ref.pixels[i]));
    maxDiff = std::max(maxDiff, d);
    differing += d > 2;
  }
  std::printf(
      "[ measure  ] %s: foreground SSIM %.5f, foreground %.3f (CPU) %.3f (GPU), max |diff| %d, %lld channel values "
      "differ by > 2\n",
      renderModeName(mode).c_str(), ssim, fg, foregroundFraction(img), maxDiff, static_cast<long long>(differing));
  EXPECT_GE(ssim, 0.95) << renderModeName(mode) << " on " << gl.context->renderer();
}

INSTANTIATE_TEST_SUITE_P(Modes, GpuVsCpu,
                         ::testing::Values(RenderMode::Full, RenderMode::CutBox, RenderMode::Triplanar,
                                           RenderMode::Monoplanar, RenderMode::Mip),
                         [](const auto& test) { return renderModeName(test.param); });

TEST(GpuRayCaster, ModesDifferAndJitterKeepsTheImage) {
  Offscreen gl;
  if (!gl.context) GTEST_SKIP() << "no offscreen OpenGL 3.3 context: " << gl.why;
  HeadPhantomOptions ho;
  ho.dims = {48, 48, 48};
  AnyVolume vol(makeHeadPhantom(ho).volume);
  GpuRayCaster gpu;
  gpu.setVolume(vol);
  gpu.setTransferFunction(TransferFunction::preset("ct-skin", valueRange(vol)));
  const EyeView ev = eyeView(orbitCamera(geometryOf(vol), 0, 0, 1, true), 1.0);
  RayCastSettings s;
  s.window = {400, 40};
  s.jitter = false;
  const RgbaImage full = gpu.renderImage(ev, 96, 96, s);
  s.jitter = true;
  const RgbaImage jittered = gpu.renderImage(ev, 96, 96, s);
  EXPECT_GE(foregroundSsim(jittered, full), 0.9);
  s.mode = RenderMode::Mip;
  const RgbaImage mip = gpu.renderImage(ev, 96, 96, s);
  EXPECT_LT(foregroundSsim(mip, full), 0.9) << "MIP and full look the same";
}

// Labels over the volume: blended as the CPU renderer blends them (same palette and opacity, the
// nearest voxel's label), in the shaded full mode and on the triplanar planes; a hidden label's
// voxels are not drawn at all.
TEST(GpuRayCaster, LabelsAsTheCpuRendererAndHiddenParts) {
  Offscreen gl;
  if (!gl.context) GTEST_SKIP() << "no offscreen OpenGL 3.3 context: " << gl.why;
  HeadPhantomOptions ho;
  ho.dims = {64, 72, 56};
  ho.spacing = {1.0, 0.9, 1.2};
  AnyVolume vol(makeHeadPhantom(ho).volume);
  const Geometry& g = geometryOf(vol);
  VolumeU16 labels(g, 0);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < 36; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) labels(x, y, z) = x < 32 ? 1 : 2;
  const TransferFunction tf = TransferFunction::preset("ct-skin", valueRange(vol));
  const int W = 160, H = 128;
  const Camera cam = orbitCamera(g, 30, 20, 1.0, true);
  Renderer cpu(vol);
  cpu.setTransferFunction(tf);
  cpu.setLabels(AnyVolume(labels));
  GpuRayCaster gpu;
  gpu.setVolume(vol);
  gpu.setTransferFunction(tf);
  gpu.setLabels(&labels);
  auto greenish = [](const RgbaImage& im) {
    int n = 0;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) n += im.at(x, y)[1] > im.at(x, y)[0] + 30;
    return n;
  };
  for (RenderMode mode : {RenderMode::Full, RenderMode::Triplanar}) {
    RenderOptions ro;
    ro.mode = mode;
    ro.window = {400, 40};
    ro.planes = Vec3(20, 30, 25);
    ro.labelOpacity = 0.5;
    cpu.setOptions(ro);
    const RgbaImage ref = cpu.render(cam, W, H).image;
    RayCastSettings s;
    s.mode = mode;
    s.window = ro.window;
    s.planes = ro.planes;
    s.jitter = false;
    s.labelOpacity = 0.5;
    gpu.setLabelPalette({});
    const RgbaImage img = gpu.renderImage(eyeView(cam, double(W) / H), W, H, s);
    const double ssim = foregroundSsim(img, ref);
    int64_t close = 0, fg = 0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        if (!isForeground(ref.at(x, y))) continue;
        ++fg;
        int d = 0;
        for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int(img.at(x, y)[k]) - int(ref.at(x, y)[k])));
        close += d <= 3;
      }
    std::printf("[ measure  ] labels, %s: foreground SSIM %.5f, %.4f of foreground pixels within 3 of the CPU's\n",
                renderModeName(mode).c_str(), ssim, double(close) / double(fg));
    EXPECT_GE(ssim, 0.95) << renderModeName(mode);
    EXPECT_GE(double(close) / double(fg), 0.95) << renderModeName(mode);
    EXPECT_GT(greenish(ref), 200) << "label 2 shows in green";
    if (mode == RenderMode::Full) {
      OverlaySettings hide;
      hide.hiddenLabels = {2};
      gpu.setLabelPalette(hide);
      const RgbaImage hidden = gpu.renderImage(eyeView(cam, double(W) / H), W, H, s);
      EXPECT_LT(greenish(hidden), greenish(img) / 20) << "label 2 hidden";
      EXPECT_LT(foregroundSsim(hidden, img), 0.9) << "its voxels are not drawn: the head behind them shows";
      gpu.setLabelPalette({});
    }
  }
}
#endif
