// The monoplanar mode's plane moved with real input events (xdotool into the test's own Xvfb):
// `a` over the 3D view turns the plane from z to x, a drag of its handle moves it along x. The
// session after the events says where it is, and the 3D view must show that plane: its pixels
// against the CPU renderer's picture of the same plane (render/renderer.h, same camera).
#ifdef VS_HAVE_VIEWER
#include <gtest/gtest.h>

#include <cmath>

#include "app/viewer_app.h"
#include "input_fixture.h"
#include "io/png_io.h"
#include "render/camera.h"
#include "render/renderer.h"

using namespace vs;
using namespace vs::viewer;
namespace vt = vs::viewer::testing;

namespace {

class ViewerPlaneTest : public vt::InputFixture {};

// The 3D view's picture in the default layout: below the title bar (19 px), inside the padding.
constexpr int kX0 = 348, kY0 = 27, kPW = 304, kPH = 285;
constexpr std::array<int, 3> kBackground{20, 20, 26};  // (0.08, 0.08, 0.1)

bool background(const uint8_t* p) {
  return std::abs(p[0] - kBackground[0]) <= 2 && std::abs(p[1] - kBackground[1]) <= 2 &&
         std::abs(p[2] - kBackground[2]) <= 2;
}
bool overlay(const uint8_t* p) {  // the plane's cyan outline and arrow, the white handle
  return (p[0] < 60 && p[1] > 150 && p[2] > 200) || (p[0] > 240 && p[1] > 240 && p[2] > 240);
}

// Where the plane is drawn (not background) in the window's picture vs a reference picture: the
// intersection over union of the two masks and the mean grey difference on their intersection,
// ignoring the overlay's pixels.
struct Match {
  double iou = 0, meanDiff = 0;
};
Match compare(const RgbaImage& shot, const RgbaImage& ref) {
  int64_t both = 0, either = 0;
  double diff = 0;
  for (int y = 0; y < kPH; ++y)
    for (int x = 0; x < kPW; ++x) {
      const uint8_t* s = shot.at(kX0 + x, kY0 + y);
      const uint8_t* r = ref.at(x, y);
      if (overlay(s)) continue;
      const bool a = !background(s), b = !background(r);
      either += a || b;
      if (a && b) {
        ++both;
        diff += std::abs(int(s[0]) - int(r[0]));
      }
    }
  return {either ? double(both) / double(either) : 0, both ? diff / double(both) : 255};
}

}  // namespace

TEST_F(ViewerPlaneTest, KeyTurnsThePlaneAndItsHandleMovesIt) {
  start("planes 64,64,64\nmode monoplanar\nslice-planes off\nscreenshot " + path("before.png") +
        "\ninteract F12\nsession-save " + path("after.json") + "\nscreenshot " + path("after.png") + "\nquit\n");
  ASSERT_TRUE(waitFor(path("before.png"))) << err();
  ViewerApp app;
  app.loadHeadPhantom(128);
  app.setCursor({64, 64, 64});
  // The x plane's centre and one voxel along +x on the screen (the handle and its direction).
  const CameraFrame cf(app.camera(), kPW, kPH);
  const Geometry& g = app.geometry();
  double cx = 0, cy = 0, x1 = 0, y1 = 0, depth = 0;
  ASSERT_TRUE(cf.project(g.indexToWorld(Vec3(64, 63.5, 63.5)), cx, cy, depth));
  ASSERT_TRUE(cf.project(g.indexToWorld(Vec3(65, 63.5, 63.5)), x1, y1, depth));
  const double ux = x1 - cx, uy = y1 - cy, len = std::hypot(ux, uy);
  ASSERT_GT(len, 0.5) << "the x axis is seen from the side";
  const int hx = kX0 + int(std::lround(cx)), hy = kY0 + int(std::lround(cy));
  // Drag 50 px along the normal's screen direction (10 steps), ending 50 / len voxels further.
  std::string drag = "windowfocus --sync %1 mousemove --window %1 " + std::to_string(hx) + " " + std::to_string(hy) +
                     " key a mousedown 1";
  int ex = hx, ey = hy;
  for (int k = 1; k <= 10; ++k) {
    ex = hx + int(std::lround(5 * k * ux / len));
    ey = hy + int(std::lround(5 * k * uy / len));
    drag += " mousemove --window %1 " + std::to_string(ex) + " " + std::to_string(ey);
  }
  ASSERT_EQ(xdo(drag + " mouseup 1 key F12"), 0);
  ASSERT_EQ(waitExit(), 0) << err();
  const nlohmann::json s = session(path("after.json"));
  EXPECT_EQ(s["view"]["mono_axis"], 0) << "`a` turned the plane from z to x";
  // The handle stays under the mouse: the plane index whose centre projects nearest to where the
  // drag ended (less the grab offset, the handle's rounding to the pixel grid).
  double expected = -1, best = 1e300;
  for (int k = 0; k < 128; ++k) {
    double px = 0, py = 0;
    ASSERT_TRUE(cf.project(g.indexToWorld(Vec3(k, 63.5, 63.5)), px, py, depth));
    const double d = std::hypot(px - (cx + ex - hx), py - (cy + ey - hy));
    if (d < best) best = d, expected = k;
  }
  const int64_t index = s["view"]["cursor"][0].get<int64_t>();
  EXPECT_NEAR(double(index), expected, 1) << "the handle moved the plane along x";
  EXPECT_GT(index, 64 + 10);
  EXPECT_EQ(s["view"]["cursor"][1], 64);
  EXPECT_EQ(s["view"]["cursor"][2], 64);

  // The picture: the x plane at that index, as the CPU renderer draws it; not the z plane.
  Renderer cpu(app.volume());
  cpu.setTransferFunction(app.transferFunction());
  auto reference = [&](int axis, double at) {
    RenderOptions o;
    o.mode = RenderMode::Monoplanar;
    o.planeAxis = axis;
    o.planeIndex = at;
    o.window = app.view().window;
    o.background = {0.08f, 0.08f, 0.1f};
    cpu.setOptions(o);
    return cpu.render(app.camera(), kPW, kPH).image;
  };
  const RgbaImage after = readPng(path("after.png")), before = readPng(path("before.png"));
  const Match moved = compare(after, reference(0, double(index))), oldPlane = compare(after, reference(2, 64)),
              first = compare(before, reference(2, 64));
  EXPECT_GE(first.iou, 0.9) << "the z plane before the events (the test's picture rectangle)";
  EXPECT_GE(moved.iou, 0.9) << "the moved x plane is drawn";
  EXPECT_LE(moved.meanDiff, 12);
  EXPECT_LT(oldPlane.iou, 0.6) << "the z plane is gone";
  std::cout << "[ measured ] plane x=" << index << " (expected " << expected << "): IoU " << moved.iou
            << ", mean grey difference " << moved.meanDiff << "; against the old z plane IoU " << oldPlane.iou
            << "; before the events vs the z plane IoU " << first.iou << '\n';
}
#endif
