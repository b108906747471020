// The 3D tools' views driven by real X input events (xdotool into the test's own Xvfb, Mesa's
// software OpenGL), checked on the screenshots by measured properties (issue 26 item 3, issue 27
// item 4):
// - the cut's previewed loop is the loop the cut uses (closed, the hovered point's loop is the one
//   after the click, the cut's reported contour lies on the previewed pixels) and the stylus
//   sphere is drawn at the point the cut receives;
// - stereo (side-by-side, anaglyph) draws the tools' results, the slice planes and the stylus in
//   both eyes, and a side-by-side click picks with the camera of the eye under the mouse;
// - the cut box's face handle dragged moves that face.
#ifdef VS_HAVE_VIEWER
#include <cmath>

#include "app/cut_box.h"
#include "app/stereo.h"
#include "app/viewer_app.h"
#include "input_fixture.h"
#include "io/png_io.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"

using namespace vs;
using namespace vs::viewer;
using vs::viewer::testing::kH;
using vs::viewer::testing::kW;
using vs::viewer::testing::ViewerInputTest;

namespace {

constexpr int kPanel = 340, kCellW = (kW - kPanel) / 2, kCellH = kH / 2;

struct Rect {
  int x = 0, y = 0, w = 0, h = 0;
};
// The 3D picture inside its view (top left cell): the bounding box of its background pixels (the
// view's background colour 0.08, 0.08, 0.1; the head leaves background along the four edges).
Rect picture3D(const RgbaImage& shot) {
  int x0 = kW, y0 = kH, x1 = -1, y1 = -1;
  for (int y = 0; y < kCellH; ++y)
    for (int x = kPanel; x < kPanel + kCellW; ++x) {
      const uint8_t* p = shot.at(x, y);
      if (std::abs(p[0] - 20) <= 1 && std::abs(p[1] - 20) <= 1 && std::abs(p[2] - 26) <= 1)
        x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
    }
  return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

struct Pixels {
  std::vector<std::array<int, 2>> at;
  double cx() const {
    double s = 0;
    for (const auto& p : at) s += p[0];
    return at.empty() ? 0 : s / double(at.size());
  }
  double cy() const {
    double s = 0;
    for (const auto& p : at) s += p[1];
    return at.empty() ? 0 : s / double(at.size());
  }
  size_t size() const { return at.size(); }
};

// The pixels of rectangle r where two screenshots differ (any channel by more than 8).
Pixels differing(const RgbaImage& a, const RgbaImage& b, const Rect& r) {
  Pixels out;
  for (int y = r.y; y < r.y + r.h; ++y)
    for (int x = r.x; x < r.x + r.w; ++x) {
      const uint8_t *p = a.at(x, y), *q = b.at(x, y);
      if (std::abs(p[0] - q[0]) > 8 || std::abs(p[1] - q[1]) > 8 || std::abs(p[2] - q[2]) > 8) out.at.push_back({x, y});
    }
  return out;
}

template <class F>
Pixels matching(const RgbaImage& im, const Rect& r, F&& is) {
  Pixels out;
  for (int y = r.y; y < r.y + r.h; ++y)
    for (int x = r.x; x < r.x + r.w; ++x)
      if (is(im.at(x, y))) out.at.push_back({x, y});
  return out;
}
bool magenta(const uint8_t* p) { return p[0] > 200 && p[1] < 90 && p[2] > 200; }
bool green(const uint8_t* p) { return p[0] < 130 && p[1] > 200 && p[2] < 180; }
bool orange(const uint8_t* p) { return p[0] > 200 && p[1] > 100 && p[1] < 180 && p[2] < 60; }  // the points

// VS_VIEWER_TEST_IMAGES=DIR keeps the screenshots (to look at them).
void keepImages(const std::string& dir, const std::string& prefix, const std::vector<std::string>& names) {
  if (const char* keep = std::getenv("VS_VIEWER_TEST_IMAGES"))
    for (const std::string& n : names)
      std::filesystem::copy_file(dir + "/" + n, std::string(keep) + "/" + prefix + n,
                                 std::filesystem::copy_options::overwrite_existing);
}

// The share of a's pixels that lie within `radius` px of one of b's.
double nearShare(const Pixels& a, const Pixels& b, int radius) {
  if (a.at.empty()) return 0;
  std::set<std::pair<int, int>> bs;
  for (const auto& p : b.at) bs.insert({p[0], p[1]});
  size_t near = 0;
  for (const auto& p : a.at) {
    bool found = false;
    for (int dy = -radius; dy <= radius && !found; ++dy)
      for (int dx = -radius; dx <= radius && !found; ++dx) found = bs.count({p[0] + dx, p[1] + dy}) > 0;
    near += found;
  }
  return double(near) / double(a.at.size());
}

// The head phantom the cut tests use (64 x 64 x 48, 2 x 2 x 2.5 mm) and the voxels of its nose loop.
std::vector<Index3> writeNoseCase(const std::string& file) {
  HeadPhantomOptions ho;
  ho.dims = {64, 64, 48};
  ho.spacing = Vec3(2, 2, 2.5);
  const HeadPhantom ph = makeHeadPhantom(ho);
  writeVolume(AnyVolume(ph.volume), file);
  std::vector<Index3> pts;
  for (const Vec3& q : noseBaseLoopMm(ph.truth)) {
    const Index3 v = roundIndex(ph.volume.geometry().worldToIndex(q));
    if (pts.empty() || pts.back() != v) pts.push_back(v);
  }
  return pts;
}
std::string pointCommand(const Index3& p) {
  return "point " + std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]) + "\n";
}
Vec3 lastCutPoint(const nlohmann::json& session) {
  const auto& p = session.at("cut").at("points").back();
  return Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
}

}  // namespace

// Issue 26 item 3: hover the stylus over the skin, click: the sphere is centred on the point the
// cut receives; the loop previewed through the hovered point is the loop after the click; after
// the cut, its reported contour lies on the previewed loop's pixels (the closing segment included).
TEST_F(ViewerInputTest, CutPreviewIsTheCutsLoopAndTheSphereIsItsPoint) {
  const std::vector<Index3> nose = writeNoseCase(path("head.nii.gz"));
  ASSERT_GE(nose.size(), 6u);
  std::string s = "tf ct-skin\nview 0 10\nzoom 2\nslice-planes off\nsnap 3\nopacity overlays 0\ntool cut\n";
  for (size_t i = 0; i + 1 < nose.size(); ++i) s += pointCommand(nose[i]);
  s += "wait\nsession-save " + path("before.json") + "\nscreenshot " + path("ready.png") + "\ninteract F12\n" +
       "screenshot " + path("hover.png") + "\nopacity overlays 1\nscreenshot " + path("hoverloop.png") +
       "\ninteract F12\nscreenshot " + path("clicked.png") + "\nsession-save " + path("clicked.json") +
       "\nrun\ntool none\nopacity labels 0\nscreenshot " + path("result.png") + "\nquit\n";
  start(s, "--renderer gpu " + path("head.nii.gz"));
  ASSERT_TRUE(waitFor(path("ready.png"))) << err();
  const RgbaImage ready = readPng(path("ready.png"));
  const Rect r = picture3D(ready);
  ASSERT_GT(r.w, 100) << "the 3D picture was not found";
  ViewerApp app;
  app.loadSession(path("before.json"));
  const CameraFrame cf(app.camera(), r.w, r.h);
  // The stylus over the last nose point (its projection; the stylus finds the skin there).
  double px, py, depth;
  const Index3 last = nose.back();
  ASSERT_TRUE(
      cf.project(app.geometry().indexToWorld(Vec3(double(last[0]), double(last[1]), double(last[2]))), px, py, depth));
  const int mx = r.x + int(std::lround(px)), my = r.y + int(std::lround(py));
  ASSERT_EQ(
      xdo("windowfocus --sync %1 mousemove --window %1 " + std::to_string(mx) + " " + std::to_string(my) + " key F12"),
      0);
  // Click there, move off the view (no hover), hand back (once the script waits again: events sent
  // while it takes its screenshots would be drawn by those frames, the F12 with them).
  ASSERT_TRUE(waitFor(path("hoverloop.png"))) << err();
  ASSERT_EQ(xdo("mousemove --window %1 " + std::to_string(mx) + " " + std::to_string(my) +
                " click 1 mousemove --window %1 100 500 key F12"),
            0);
  ASSERT_EQ(waitExit(180), 0) << err() << "hover.png " << std::filesystem::exists(path("hover.png")) << ", clicked.png "
                              << std::filesystem::exists(path("clicked.png"));
  const RgbaImage hover = readPng(path("hover.png")), hoverLoop = readPng(path("hoverloop.png")),
                  clicked = readPng(path("clicked.png")), result = readPng(path("result.png"));
  // The sphere: what the hover added at overlay opacity 0 (the loop and points are at opacity 0).
  const Pixels sphere = differing(hover, ready, r);
  ASSERT_GT(sphere.size(), 50u) << "no stylus sphere drawn";
  const Vec3 received = lastCutPoint(nlohmann::json::parse(std::ifstream(path("clicked.json"))));
  ASSERT_TRUE(cf.project(app.geometry().indexToWorld(received), px, py, depth));
  // Pixel (x, y) covers x..x+1: the drawn disc's centre is the centroid + 0.5.
  const double ex = sphere.cx() + 0.5 - r.x, ey = sphere.cy() + 0.5 - r.y;
  std::cout << "[ measured ] sphere centre " << ex << "," << ey << " px, the cut's point projects to " << px << ","
            << py << " (mouse " << mx - r.x << "," << my - r.y << "), " << sphere.size() << " px\n";
  EXPECT_NEAR(ex, px, 1.0);
  EXPECT_NEAR(ey, py, 1.0);
  // The loop through the hovered point (green) is the loop after the click (magenta).
  const Pixels hoverGreen = matching(hoverLoop, r, green), clickedLoop = matching(clicked, r, magenta);
  ASSERT_GT(hoverGreen.size(), 150u);
  ASSERT_GT(clickedLoop.size(), 150u);
  EXPECT_GE(nearShare(hoverGreen, clickedLoop, 1), 0.97);
  EXPECT_GE(nearShare(clickedLoop, hoverGreen, 1), 0.85) << "(the sphere covers part of the hovered loop)";
  keepImages(dir.string(), "cut_preview_", {"ready.png", "hover.png", "hoverloop.png", "clicked.png", "result.png"});
  // The cut's contour (drawn 2.5 px wide, tool none: no preview) on the previewed loop (where the
  // points' dots do not cover it) and back.
  const Pixels cutLoop = matching(result, r, magenta);
  Pixels previewOrDots = clickedLoop;
  for (const auto& p : matching(clicked, r, orange).at) previewOrDots.at.push_back(p);
  ASSERT_GT(cutLoop.size(), 150u);
  const double cutOnPreview = nearShare(cutLoop, previewOrDots, 2), previewOnCut = nearShare(clickedLoop, cutLoop, 2);
  std::cout << "[ measured ] loop pixels: hovered " << hoverGreen.size() << ", previewed " << clickedLoop.size()
            << ", cut " << cutLoop.size() << "; cut on preview " << cutOnPreview << ", preview on cut " << previewOnCut
            << '\n';
  EXPECT_GE(cutOnPreview, 0.97);
  EXPECT_GE(previewOnCut, 0.97);
}

// Issue 27 item 4: stereo draws what mono draws, in both eyes, and a side-by-side click picks with
// the camera of the eye under the mouse.
TEST_F(ViewerInputTest, StereoDrawsTheToolsInBothEyesAndPicksPerEye) {
  const std::vector<Index3> nose = writeNoseCase(path("head.nii.gz"));
  std::string s = "tf ct-skin\nview 0 10\nzoom 1.6\ntool cut\nsession-save " + path("mono.json") + "\ninteract F12\n" +
                  "session-save " + path("mono_click.json") + "\nundo\n";
  for (const Index3& p : nose) s += pointCommand(p);
  s += "run\nstereo side-by-side\nslice-planes on\n";
  for (const char* mode : {"sbs", "ana"}) {
    // Anaglyph over a black picture (MIP windowed above every value), so that each eye's channels show.
    if (std::string(mode) == "ana") s += "stereo anaglyph\nmode mip\nwindow 1 100000\n";
    s += "opacity overlays 1\nscreenshot " + path(std::string(mode) + "1.png") + "\nopacity overlays 0\nscreenshot " +
         path(std::string(mode) + "0.png") + "\nslice-planes off\nscreenshot " + path(std::string(mode) + "np.png") +
         "\nslice-planes on\n";
  }
  s += "stereo side-by-side\nmode full\nwindow 2000 0\nsession-save " + path("sbs.json") + "\nscreenshot " +
       path("sbs_ready.png") + "\ninteract F12\nscreenshot " + path("sbs_hover.png") + "\ninteract F12\nsession-save " +
       path("sbs_click.json") + "\nquit\n";
  start(s, "--renderer gpu " + path("head.nii.gz"));
  ASSERT_TRUE(waitFor(path("mono.json"))) << err();
  ViewerApp app;
  app.loadSession(path("mono.json"));
  // The mono click: the middle of the 3D view's picture (the face).
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_EQ(xdo("windowfocus --sync %1 mousemove --window %1 " + std::to_string(kPanel + kCellW / 2) + " " +
                std::to_string(kCellH / 2 + 10) + " click 1 mousemove --window %1 100 500 key F12"),
            0);
  ASSERT_TRUE(waitFor(path("sbs_ready.png"), 240)) << err();
  const Vec3 monoPoint = lastCutPoint(nlohmann::json::parse(std::ifstream(path("mono_click.json"))));
  const RgbaImage ready = readPng(path("sbs_ready.png"));
  const Rect r = picture3D(ready);
  ASSERT_GT(r.w, 100);
  const Rect left{r.x, r.y, r.w / 2, r.h}, right{r.x + r.w / 2, r.y, r.w - r.w / 2, r.h};
  // Where the mono click's point shows in the right eye (its camera, its half of the view).
  app.loadSession(path("sbs.json"));
  const std::vector<StereoEye> eyes = stereoEyes(app, StereoMode::SideBySide, r.w, r.h);
  double ex, ey, depth;
  ASSERT_TRUE(projectToEye(eyes[1], app.geometry().indexToWorld(monoPoint), ex, ey, depth));
  const int cx = r.x + eyes[1].x0 + int(std::lround(ex)), cy = r.y + int(std::lround(ey));
  ASSERT_EQ(xdo("mousemove --window %1 " + std::to_string(cx) + " " + std::to_string(cy) + " key F12"), 0);
  ASSERT_TRUE(waitFor(path("sbs_hover.png"))) << err();
  ASSERT_EQ(xdo("mousemove --window %1 " + std::to_string(cx) + " " + std::to_string(cy) + " click 1 key F12"), 0);
  ASSERT_EQ(waitExit(180), 0) << err();
  const Vec3 eyePoint = lastCutPoint(nlohmann::json::parse(std::ifstream(path("sbs_click.json"))));
  // The mono camera at that pixel of the whole view would pick elsewhere: the test can fail.
  app.setStereo(StereoMode::Off);
  const StylusPick monoThere = app.stylusPick(double(cx - r.x), double(cy - r.y), r.w, r.h);
  std::cout << "[ measured ] mono click " << monoPoint.transpose() << ", right-eye click " << eyePoint.transpose()
            << " (distance " << (eyePoint - monoPoint).norm()
            << " voxels); the mono camera there: " << (monoThere.hit ? (monoThere.surface - monoPoint).norm() : -1)
            << " voxels off\n";
  EXPECT_LE((eyePoint - monoPoint).norm(), 0.75) << "the right eye's click picks the mono click's voxel";
  EXPECT_TRUE(!monoThere.hit || (monoThere.surface - monoPoint).norm() > 5);
  // Each mode: the tools' results (cut contour, preview loop, points: opacity 1 vs 0), the slice
  // planes (on vs off) and the stylus sphere (hover vs not) in both eyes.
  for (const std::string mode : {"sbs", "ana"}) {
    const RgbaImage on = readPng(path(mode + "1.png")), off = readPng(path(mode + "0.png")),
                    noPlanes = readPng(path(mode + "np.png"));
    const Pixels tools = differing(on, off, r), planes = differing(off, noPlanes, r);
    if (mode == "sbs") {
      const Pixels toolsL = differing(on, off, left), toolsR = differing(on, off, right);
      const Pixels planesL = differing(off, noPlanes, left), planesR = differing(off, noPlanes, right);
      std::cout << "[ measured ] side-by-side: results " << toolsL.size() << " | " << toolsR.size() << " px, centroids "
                << toolsL.cx() - left.x << "," << toolsL.cy() << " | " << toolsR.cx() - right.x << "," << toolsR.cy()
                << "; planes " << planesL.size() << " | " << planesR.size() << " px\n";
      EXPECT_GT(toolsL.size(), 100u);
      EXPECT_GT(toolsR.size(), 100u);
      EXPECT_NEAR(toolsL.cx() - left.x, toolsR.cx() - right.x, 6) << "the same results at a small disparity";
      EXPECT_NEAR(toolsL.cy(), toolsR.cy(), 2);
      EXPECT_GT(planesL.size(), 100u);
      EXPECT_GT(planesR.size(), 100u);
    } else {
      // Anaglyph: each eye's overlay in its filter's channels: the left eye's results change the
      // red channel, the right eye's the green and blue ones, at about the same place.
      auto channelChanged = [&](int c0, int c1) {
        Pixels out;
        for (int y = r.y; y < r.y + r.h; ++y)
          for (int x = r.x; x < r.x + r.w; ++x) {
            bool changed = false;
            for (int c = c0; c <= c1; ++c) changed = changed || std::abs(on.at(x, y)[c] - off.at(x, y)[c]) > 40;
            if (changed) out.at.push_back({x, y});
          }
        return out;
      };
      const Pixels leftEye = channelChanged(0, 0), rightEye = channelChanged(1, 2);
      std::cout << "[ measured ] anaglyph: results " << tools.size() << " px; red channel " << leftEye.size()
                << " px at " << leftEye.cx() - r.x << "," << leftEye.cy() << ", green/blue " << rightEye.size()
                << " px at " << rightEye.cx() - r.x << "," << rightEye.cy() << "; planes " << planes.size() << " px\n";
      EXPECT_GT(leftEye.size(), 200u) << "the left eye's results (red)";
      EXPECT_GT(rightEye.size(), 200u) << "the right eye's results (green, blue)";
      EXPECT_NEAR(leftEye.cx(), rightEye.cx(), 6);
      EXPECT_NEAR(leftEye.cy(), rightEye.cy(), 2);
      EXPECT_GT(planes.size(), 200u);
    }
  }
  keepImages(dir.string(), "stereo_", {"sbs1.png", "ana1.png", "sbs_hover.png"});
  const RgbaImage sbsHover = readPng(path("sbs_hover.png"));
  // Overlays at opacity 0 in both: what the hover adds is the stylus sphere (fixed colours).
  const Pixels sphereL = differing(sbsHover, ready, left), sphereR = differing(sbsHover, ready, right);
  std::cout << "[ measured ] side-by-side stylus sphere: " << sphereL.size() << " | " << sphereR.size() << " px\n";
  EXPECT_GT(sphereL.size(), 30u) << "the sphere in the left eye";
  EXPECT_GT(sphereR.size(), 30u) << "the sphere in the right eye";
  EXPECT_NEAR(sphereL.cy(), sphereR.cy(), 2);
}

// Issue 27 item 4: the cut box's +x face handle dragged 60 px against its axis on the screen moves
// that face (and only it) by 60 px / (px per voxel); the view does not turn; the picture shrinks.
TEST_F(ViewerInputTest, CutBoxFaceHandleDragMovesTheFace) {
  start("tool none\nmode cutbox\nview 30 20\nslice-planes off\nsession-save " + path("before.json") + "\nscreenshot " +
        path("before.png") + "\ninteract F12\nsession-save " + path("after.json") + "\nscreenshot " +
        path("after.png") + "\nquit\n");
  ASSERT_TRUE(waitFor(path("before.png"))) << err();
  const RgbaImage before = readPng(path("before.png"));
  const Rect r = picture3D(before);
  ASSERT_GT(r.w, 100);
  ViewerApp app;
  app.loadSession(path("before.json"));
  const CameraFrame cf(app.camera(), r.w, r.h);
  const CutBox box = app.cutBox();
  auto screen = [&](const Vec3& index) {
    double px, py, depth;
    EXPECT_TRUE(cf.project(app.geometry().indexToWorld(index), px, py, depth));
    return std::array<double, 2>{r.x + px, r.y + py};
  };
  const int face = 3;  // x1
  const auto h = screen(cutBoxHandle(box, face));
  Vec3 along = cutBoxHandle(box, face);
  along[0] += 1;
  const auto a = screen(along);
  const double sx = a[0] - h[0], sy = a[1] - h[1], pxPerVoxel = std::hypot(sx, sy);
  ASSERT_GT(pxPerVoxel, 0.5);
  std::string drag = "windowfocus --sync %1 mousemove --window %1 " + std::to_string(std::lround(h[0])) + " " +
                     std::to_string(std::lround(h[1])) + " mousedown 1";
  const double dragPx = 60;
  for (int k = 1; k <= 10; ++k)
    drag += " mousemove --window %1 " + std::to_string(std::lround(h[0] - dragPx * k / 10 * sx / pxPerVoxel)) + " " +
            std::to_string(std::lround(h[1] - dragPx * k / 10 * sy / pxPerVoxel));
  ASSERT_EQ(xdo(drag + " mouseup 1 key F12"), 0);
  ASSERT_EQ(waitExit(), 0) << err();
  const nlohmann::json b = session(path("before.json")), af = session(path("after.json"));
  ASSERT_TRUE(af["view"].contains("cut_box")) << af["view"];
  const auto moved = af["view"]["cut_box"].get<std::array<double, 6>>();
  const double expected = box[face] - dragPx / pxPerVoxel;
  std::cout << "[ measured ] x1 " << box[face] << " -> " << moved[face] << " (expected " << expected << ", "
            << pxPerVoxel << " px a voxel)\n";
  EXPECT_NEAR(moved[face], expected, 1.5 / pxPerVoxel + 0.05);
  for (int f = 0; f < 6; ++f)
    if (f != face) {
      EXPECT_DOUBLE_EQ(moved[size_t(f)], box[size_t(f)]) << "face " << f;
    }
  EXPECT_EQ(af["view"]["azimuth_deg"], b["view"]["azimuth_deg"]) << "the drag did not turn the view";
  const RgbaImage after = readPng(path("after.png"));
  auto volumePixels = [&](const RgbaImage& im) {
    return matching(im, r,
                    [](const uint8_t* p) {
                      return !(std::abs(p[0] - 20) <= 1 && std::abs(p[1] - 20) <= 1 && std::abs(p[2] - 26) <= 1);
                    })
        .size();
  };
  const size_t n0 = volumePixels(before), n1 = volumePixels(after);
  std::cout << "[ measured ] picture " << n0 << " -> " << n1 << " px\n";
  EXPECT_LT(double(n1), 0.95 * double(n0)) << "the box (the picture) shrank";
}
#endif
