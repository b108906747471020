// Scripted sessions in the real window under Xvfb with Mesa's software OpenGL: the pictures are
// checked by measured properties (the volume is visible in the 3D view, modes differ, the traced
// path and the contour show in their colours), script errors name their line. Skips with a
// message where xvfb-run is missing.
#ifdef VS_HAVE_VIEWER
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "app/viewer_app.h"
#include "io/mesh_io.h"
#include "io/png_io.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "render/renderer.h"
#include "render/slice_render.h"
#include "trace_fixture.h"
#include "viewer_test_util.h"
#include "xserver.h"

namespace fs = std::filesystem;
using namespace vs;
using namespace vs::viewer;

namespace {

// The layout at --size 980x640: tool panel 340 px wide, then a 2x2 grid of views.
constexpr int kW = 980, kH = 640, kPanel = 340;
constexpr int kCellW = (kW - kPanel) / 2, kCellH = kH / 2;

class ViewerWindowTest : public ::testing::Test {
 protected:
  fs::path dir;
  std::unique_ptr<vs::viewer::testing::XServer> xserver;
  std::string size = std::to_string(kW) + "x" + std::to_string(kH);  // the window's
  void SetUp() override {
    dir = fs::temp_directory_path() / ("vs_viewer_window_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    // The test's own X server (display number and authority file): parallel tests never race.
    xserver = std::make_unique<vs::viewer::testing::XServer>(dir, 1280, 800);
    if (!xserver->ok()) GTEST_SKIP() << "no X server: " << xserver->why();
  }
  void TearDown() override {
    xserver.reset();
    if (!dir.empty()) fs::remove_all(dir);
  }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  // True when the viewer failed only because no window could be made (its own two messages for
  // that); any other failure must fail the test, not skip it.
  bool noWindow(int rc) const {
    return rc != 0 && (err().find("cannot open a window") != std::string::npos ||
                       err().find("cannot create a window") != std::string::npos);
  }
  // options: more `view` options (default: the GPU ray caster, so that pictures do not depend on
  // the measured renderer choice); env: variables for the viewer (e.g. Mesa's). Returns the
  // viewer's own exit status.
  int view(const std::string& script, const std::string& file = "", const std::string& options = "--renderer gpu",
           const std::string& env = "") {
    std::ofstream(path("script.txt")) << script;
    const std::string cmd = "env " + xserver->env() + " " + env + " " + std::string(VS_CLI_PATH) + " view " + file +
                            " --size " + size + " " + options + " --script " + path("script.txt") + " > " +
                            path("out.txt") + " 2> " + path("err.txt");
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  std::string err() const {
    std::ifstream f(path("err.txt"));
    return {std::istreambuf_iterator<char>(f), {}};
  }
  // A rectangle of a screenshot (the views' insides, without title bars).
  static RgbaImage crop(const RgbaImage& im, int x0, int y0, int w, int h) {
    RgbaImage out(w, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) std::copy_n(im.at(x0 + x, y0 + y), 4, out.at(x, y));
    return out;
  }
  static RgbaImage view3D(const RgbaImage& im) { return crop(im, kPanel + 4, 24, kCellW - 8, kCellH - 28); }
  static int countColour(const RgbaImage& im, int r, int g, int b, int tol) {
    int n = 0;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        const uint8_t* p = im.at(x, y);
        n += std::abs(p[0] - r) <= tol && std::abs(p[1] - g) <= tol && std::abs(p[2] - b) <= tol;
      }
    return n;
  }
};

}  // namespace

namespace {

constexpr std::array<int, 3> kBackground{20, 20, 26};  // the 3D view's background (0.08, 0.08, 0.1)

bool isBackground(const uint8_t* p) {
  return std::abs(p[0] - kBackground[0]) <= 1 && std::abs(p[1] - kBackground[1]) <= 1 &&
         std::abs(p[2] - kBackground[2]) <= 1;
}

// The 3D image inside its view (top left cell): the bounding box of its background pixels
// (the head at zoom 1 leaves background along all four edges).
struct Rect {
  int x = 0, y = 0, w = 0, h = 0;
};
Rect picture3D(const RgbaImage& shot) {
  int x0 = kW, y0 = kH, x1 = -1, y1 = -1;
  for (int y = 0; y < kCellH; ++y)
    for (int x = kPanel; x < kPanel + kCellW; ++x)
      if (isBackground(shot.at(x, y)))
        x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
  return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

RgbaImage cropRect(const RgbaImage& im, const Rect& r) {
  RgbaImage out(r.w, r.h);
  for (int y = 0; y < r.h; ++y)
    for (int x = 0; x < r.w; ++x) std::copy_n(im.at(r.x + x, r.y + y), 4, out.at(x, y));
  return out;
}

// Background to black, so that foregroundSsim compares the volume only.
RgbaImage volumeOnly(RgbaImage im) {
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      if (isBackground(im.at(x, y))) std::fill_n(im.at(x, y), 3, uint8_t{0});
  return im;
}

std::array<double, 2> centroid(const RgbaImage& im) {
  double sx = 0, sy = 0, n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      if (!isBackground(im.at(x, y))) sx += x, sy += y, n += 1;
  return {sx / n, sy / n};
}

}  // namespace

TEST_F(ViewerWindowTest, ModesContourAndScreenshots) {
  const int rc =
      view("mode full\nscreenshot " + path("full.png") + "\nmode mip\nscreenshot " + path("mip.png") +
           "\nmode full\ntool livewire\nslice z=64\npoint 30,64\npoint 64,20\npoint 98,64\nclose\n"
           "screenshot " +
           path("wire.png") + "\nsave " + path("wire.json") + "\nsession-save " + path("session.json") + "\nquit\n");
  if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
  ASSERT_EQ(rc, 0) << err();
  const RgbaImage full = readPng(path("full.png")), mip = readPng(path("mip.png")), wire = readPng(path("wire.png"));
  ASSERT_EQ(full.width, kW);
  ASSERT_EQ(full.height, kH);
  // The 3D view's background is (0.08, 0.08, 0.1): count what differs from it.
  const RgbaImage v3 = view3D(full);
  const double fg = 1.0 - double(countColour(v3, 20, 20, 26, 6)) / double(v3.width * v3.height);
  EXPECT_GT(fg, 0.1) << "the head is visible in the 3D view";
  EXPECT_LT(fg, 0.9);
  EXPECT_LT(foregroundSsim(view3D(full), view3D(mip)), 0.9) << "full and MIP look the same";
  // The closed contour in yellow on the axial view (top right) and projected in the 3D view.
  const RgbaImage axial = crop(wire, kPanel + kCellW + 4, 24, kCellW - 8, kCellH - 28);
  EXPECT_GT(countColour(axial, 255, 220, 0, 30), 100);
  EXPECT_GT(countColour(view3D(wire), 255, 220, 0, 30), 50);
  EXPECT_TRUE(fs::exists(path("wire.json")));
  // The session reopens (in another process) to the same picture, pixel for pixel.
  ASSERT_EQ(view("session-load " + path("session.json") + "\nscreenshot " + path("reopened.png") + "\nquit\n"), 0)
      << err();
  EXPECT_EQ(readPng(path("reopened.png")).pixels, wire.pixels);
}

TEST_F(ViewerWindowTest, TraceShowsTheTreeAndErrorsNameTheLine) {
  std::string s = vs::viewer::testing::writeTracePhantom(path("vessels.nii.gz"));
  s += "run\nscreenshot " + path("trace.png") + "\nsave " + path("tree.swc") + "\n";
  const int rc = view(s + "quit\n", path("vessels.nii.gz"));
  if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
  ASSERT_EQ(rc, 0) << err();
  const RgbaImage shot = readPng(path("trace.png"));
  EXPECT_GT(countColour(view3D(shot), 255, 60, 40, 25), 100) << "the tree is drawn";
  ASSERT_TRUE(fs::exists(path("tree.swc")));
  // Drawn along its refined centreline (the saved SWC): the tree's red pixels in the 3D view lie
  // within 3 pixels of the SWC's edges projected with the viewer's camera.
  const Tree swc = readTree(path("tree.swc"));
  ViewerApp app;
  app.load(path("vessels.nii.gz"));
  const Rect r = picture3D(shot);
  const CameraFrame cf(app.camera(), r.w, r.h);
  std::vector<std::array<double, 4>> edges;  // projected segments, pixels of the 3D picture
  for (size_t i = 0; i < swc.size(); ++i)
    if (swc.parent[i] >= 0) {
      double ax, ay, bx, by, d;
      if (cf.project(swc.points[i], ax, ay, d) && cf.project(swc.points[size_t(swc.parent[i])], bx, by, d))
        edges.push_back({ax, ay, bx, by});
    }
  int red = 0, near = 0;
  for (int y = 0; y < r.h; ++y)
    for (int x = 0; x < r.w; ++x) {
      const uint8_t* p = shot.at(r.x + x, r.y + y);
      if (std::abs(p[0] - 255) > 25 || std::abs(p[1] - 60) > 25 || std::abs(p[2] - 40) > 25) continue;
      ++red;
      double best = 1e9;
      const double px = x + 0.5, py = y + 0.5;
      for (const auto& e : edges) {
        const double dx = e[2] - e[0], dy = e[3] - e[1], len2 = dx * dx + dy * dy;
        const double t = len2 > 0 ? std::clamp(((px - e[0]) * dx + (py - e[1]) * dy) / len2, 0.0, 1.0) : 0.0;
        best = std::min(best, std::hypot(px - e[0] - t * dx, py - e[1] - t * dy));
      }
      near += best <= 3;
    }
  EXPECT_GT(red, 100);
  EXPECT_GE(near, int(0.95 * red)) << near << " of " << red << " red pixels along the SWC";
  std::cout << "[ measured ] " << near << " of " << red << " red pixels within 3 px of the SWC's edges\n";
  // A failing command stops the script with exit status 1 and its line number.
  EXPECT_EQ(view("mode full\nwindow -3 5\nquit\n"), 1) << err();
  EXPECT_NE(err().find(":2: window"), std::string::npos) << err();
}

namespace {

// Whether the label's palette colour dominates a pixel: green (label 2, cut away) or red (label 1,
// kept), by `margin` over the other channels (in the 3D view the skin colour and the shading
// weaken the tint, so a smaller margin there).
bool tinted(const uint8_t* p, bool green, int margin = 40) {
  const int r = p[0], g = p[1], b = p[2];
  return green ? (g > r + margin && g > b + margin) : (r > g + margin && r > b + margin);
}

int countTinted(const RgbaImage& im, bool green, int margin = 40) {
  int n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) n += tinted(im.at(x, y), green, margin);
  return n;
}

// Pixels green in `before` and no longer green in `after` (the crosshair, also green, stays).
int greenGone(const RgbaImage& before, const RgbaImage& after) {
  int n = 0;
  for (int y = 0; y < before.height; ++y)
    for (int x = 0; x < before.width; ++x) n += tinted(before.at(x, y), true) && !tinted(after.at(x, y), true);
  return n;
}

}  // namespace

TEST_F(ViewerWindowTest, CutShowsAndHidesItsParts) {
  // The head phantom's nose, cut off along ten points on the skin around it.
  HeadPhantomOptions ho;
  ho.dims = {64, 64, 48};
  ho.spacing = Vec3(2, 2, 2.5);
  const HeadPhantom ph = makeHeadPhantom(ho);
  const Geometry& g = ph.volume.geometry();
  writeVolume(AnyVolume(ph.volume), path("head.nii.gz"));
  const HeadTruth& t = ph.truth;
  std::string s = "tf ct-skin\nview 0 10\nzoom 2\ntool cut\n";
  Vec3 centre(0, 0, 0);
  int n = 0;
  for (const Vec3& q : noseBaseLoopMm(t)) {
    const Index3 v = roundIndex(g.worldToIndex(q));
    s += "point " + std::to_string(v[0]) + "," + std::to_string(v[1]) + "," + std::to_string(v[2]) + "\n";
    centre += Vec3(double(v[0]), double(v[1]), double(v[2]));
    ++n;
  }
  ASSERT_GE(n, 6);
  const Index3 nose = roundIndex(g.worldToIndex(t.nose.centerMm));
  s += "run\nplanes " + std::to_string(nose[0]) + "," + std::to_string(nose[1]) + "," + std::to_string(nose[2]) +
       "\nscreenshot " + path("cut.png") + "\nlabel 2 off\nscreenshot " + path("hidden.png") +
       "\nlabel 2 on\nopacity labels 1\nopacity overlays 0\nscreenshot " + path("opaque.png") + "\nsave " +
       path("labels.nii.gz") + "\nquit\n";
  const int rc = view(s, path("head.nii.gz"));
  if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
  ASSERT_EQ(rc, 0) << err();
  const RgbaImage cut = readPng(path("cut.png")), hidden = readPng(path("hidden.png")),
                  opaque = readPng(path("opaque.png"));
  auto axialOf = [&](const RgbaImage& im) { return crop(im, kPanel + kCellW + 4, 24, kCellW - 8, kCellH - 28); };
  auto sagittalOf = [&](const RgbaImage& im) {
    return crop(im, kPanel + kCellW + 4, kCellH + 24, kCellW - 8, kCellH - 28);
  };
  // The slices through the nose show the cut-away part in green (it goes when the label is
  // hidden; the green crosshair stays) and the kept head in red.
  EXPECT_GT(greenGone(axialOf(cut), axialOf(hidden)), 20) << "the nose (label 2) in the axial view";
  EXPECT_GT(greenGone(sagittalOf(cut), sagittalOf(hidden)), 20) << "the nose (label 2) in the sagittal view";
  EXPECT_GT(countTinted(axialOf(cut), false), 5000) << "the kept head (label 1)";
  EXPECT_NEAR(countTinted(axialOf(cut), false), countTinted(axialOf(hidden), false),
              0.03 * countTinted(axialOf(cut), false))
      << "label 1 is untouched (but for the edges of the points drawn over it)";
  // The 3D view, facing the nose: the cut-away part tinted green; hidden, it is not drawn.
  EXPECT_GT(countTinted(view3D(cut), true, 10), 100);
  EXPECT_LT(countTinted(view3D(hidden), true, 10), 3);
  EXPECT_GT(countTinted(view3D(hidden), false, 10), 1000) << "the kept head stays";
  // At label opacity 1 the slices show the palette colour itself (render/renderer.h labelColor).
  const auto c2 = labelColor(2);
  const RgbaImage opaqueAxial = crop(opaque, kPanel + kCellW + 4, 24, kCellW - 8, kCellH - 28);
  EXPECT_GT(countColour(opaqueAxial, int(std::lround(255 * c2[0])), int(std::lround(255 * c2[1])),
                        int(std::lround(255 * c2[2])), 2),
            20);
  if (const char* keep = std::getenv("VS_VIEWER_TEST_IMAGES")) {  // to look at them
    fs::copy_file(path("cut.png"), std::string(keep) + "/window_cut.png", fs::copy_options::overwrite_existing);
    fs::copy_file(path("hidden.png"), std::string(keep) + "/window_cut_hidden.png",
                  fs::copy_options::overwrite_existing);
  }
  const AnyVolume labels = readVolume(path("labels.nii.gz"));
  ASSERT_TRUE(std::holds_alternative<VolumeU8>(labels));
  const auto& lv = std::get<VolumeU8>(labels).voxels();
  EXPECT_GT(std::count(lv.begin(), lv.end(), uint8_t{2}), 20);
}

TEST_F(ViewerWindowTest, OverlayFilesShowInTheirPaletteColour) {
  // A tree file along the x axis through the head phantom's centre (world mm, 1 mm steps).
  ViewerApp app;
  app.loadHeadPhantom();
  const Geometry& g = app.geometry();
  Tree tree;
  for (int x = 20; x <= 108; ++x) {
    tree.points.push_back(g.indexToWorld(Vec3(x, 64, 64)));
    tree.parent.push_back(int32_t(tree.points.size()) - 2);
    tree.radii.push_back(1);
    tree.types.push_back(x == 20 ? 1 : 3);
  }
  writeTree(tree, path("line.swc"));
  // An octahedron of radius 30 mm about the centre (the second overlay): its outline on the slices.
  TriMesh octahedron;
  const Vec3 centre = g.indexToWorld(Vec3(64, 64, 64));
  for (int k = 0; k < 6; ++k) octahedron.positions.push_back(centre + 30.0 * (k % 2 ? -1 : 1) * Vec3::Unit(k / 2));
  for (int sx : {0, 1})
    for (int sy : {2, 3})
      for (int sz : {4, 5}) octahedron.triangles.push_back({sx, sy, sz});
  writeTriMesh(octahedron, path("octahedron.obj"));
  const int rc = view("mode mip\nview 0 80\nscreenshot " + path("before.png") + "\noverlay " + path("line.swc") +
                      "\nscreenshot " + path("after.png") + "\noverlay " + path("octahedron.obj") + "\nscreenshot " +
                      path("mesh.png") + "\nopacity overlays 0\nscreenshot " + path("off.png") + "\nquit\n");
  if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
  ASSERT_EQ(rc, 0) << err();
  const auto c = overlayPaletteColor(0);
  const int r = int(std::lround(255 * c[0])), gr = int(std::lround(255 * c[1])), b = int(std::lround(255 * c[2]));
  const RgbaImage before = readPng(path("before.png")), after = readPng(path("after.png")),
                  off = readPng(path("off.png"));
  EXPECT_GT(countColour(view3D(after), r, gr, b, 8), 100) << "the tree in the 3D view";
  EXPECT_LT(countColour(view3D(before), r, gr, b, 8), 5);
  const RgbaImage axial = crop(after, kPanel + kCellW + 4, 24, kCellW - 8, kCellH - 28);
  EXPECT_GT(countColour(axial, r, gr, b, 8), 50) << "its points on the axial slice z=64";
  EXPECT_EQ(view3D(off).pixels, view3D(before).pixels) << "overlay opacity 0 hides it";
  // The mesh's outline where it crosses the axial slice z=64: a square (a diamond in mm) of
  // side 30 sqrt(2) mm, drawn in the second palette colour, none of it before.
  const auto c1 = overlayPaletteColor(1);
  const int r1 = int(std::lround(255 * c1[0])), g1 = int(std::lround(255 * c1[1])), b1 = int(std::lround(255 * c1[2]));
  const RgbaImage meshAxial = crop(readPng(path("mesh.png")), kPanel + kCellW + 4, 24, kCellW - 8, kCellH - 28);
  EXPECT_GT(countColour(meshAxial, r1, g1, b1, 8), 100) << "the mesh's outline on the axial slice";
  std::cout << "[ measured ] mesh outline on the axial slice: " << countColour(meshAxial, r1, g1, b1, 8) << " px\n";
  EXPECT_LT(countColour(axial, r1, g1, b1, 8), 5);
}
#endif

// The CPU renderer draws the 3D view when asked (--renderer cpu: a legacy OpenGL context, ImGui's
// OpenGL 2 backend): the picture is the CPU renderer's for the same camera, the note shows in the
// window and on stderr, and the slice views and the live-wire work as with the GPU.
TEST_F(ViewerWindowTest, CpuRendererDrawsTheViewWhenAsked) {
  const std::string s = "view 30 20\nslice-planes off\nscreenshot " + path("cpu.png") +
                        "\ntool livewire\nslice z=64\npoint 30,64\npoint 64,20\npoint 98,64\nclose\nscreenshot " +
                        path("wire.png") + "\nquit\n";
  const int rc = view(s, "", "--renderer cpu");
  if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
  ASSERT_EQ(rc, 0) << err();
  EXPECT_NE(err().find("CPU renderer: requested (--renderer cpu)"), std::string::npos) << err();
  const RgbaImage shot = readPng(path("cpu.png")), wire = readPng(path("wire.png"));
  const Rect r = picture3D(shot);
  EXPECT_NEAR(r.w, kCellW - 16, 2) << "the picture fills its view";
  EXPECT_NEAR(r.h, kCellH - 36, 3);
  ViewerApp app;
  app.loadHeadPhantom();
  app.setOrbit(30, 20);
  Renderer cpu(app.volume());
  cpu.setTransferFunction(app.transferFunction());
  RenderOptions o;
  o.window = app.view().window;
  o.background = {0.08f, 0.08f, 0.1f};
  cpu.setOptions(o);
  const RgbaImage expected = cpu.render(app.camera(), r.w, r.h).image;
  const RgbaImage shown = cropRect(shot, r);
  EXPECT_GT(foregroundFraction(volumeOnly(shown)), 0.1) << "the head is visible";
  const double ssim = foregroundSsim(volumeOnly(shown), volumeOnly(expected));
  EXPECT_GE(ssim, 0.95);
  std::cout << "[ measured ] CPU view in the window vs the CPU renderer: foreground SSIM " << ssim << '\n';
  // The note in the panel, in its orange (ImGui's text antialiasing keeps some pixels exact).
  EXPECT_GT(countColour(crop(shot, 0, 0, kPanel, kH), 255, 179, 77, 12), 20) << "the note in the window";
  // Slice views and the live-wire as with the GPU: the contour on the axial view and in 3D.
  const RgbaImage axial = crop(wire, kPanel + kCellW + 4, 24, kCellW - 8, kCellH - 28);
  EXPECT_GT(countColour(axial, 255, 220, 0, 30), 100);
  EXPECT_GT(countColour(view3D(wire), 255, 220, 0, 30), 50);
  if (const char* keep = std::getenv("VS_VIEWER_TEST_IMAGES"))  // to look at it
    fs::copy_file(path("cpu.png"), std::string(keep) + "/window_cpu.png", fs::copy_options::overwrite_existing);
}

// An old OpenGL (Mesa told to offer 2.1 only, as old drivers and remote X do): `auto` falls back
// to the CPU renderer with the reason; `gpu` is a clear error (exit 1).
TEST_F(ViewerWindowTest, OldOpenGLFallsBackToTheCpuRenderer) {
  const std::string env = "MESA_GL_VERSION_OVERRIDE=2.1";
  const int rc = view("screenshot " + path("old.png") + "\nquit\n", "", "--renderer auto", env);
  if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
  ASSERT_EQ(rc, 0) << err();
  EXPECT_NE(err().find("CPU renderer: OpenGL 3.3 not available"), std::string::npos) << err();
  EXPECT_NE(err().find("OpenGL 2.1"), std::string::npos) << err();
  const RgbaImage shot = readPng(path("old.png"));
  EXPECT_GT(foregroundFraction(volumeOnly(cropRect(shot, picture3D(shot)))), 0.1) << "the head is visible";
  EXPECT_EQ(view("quit\n", "", "--renderer gpu", env), 1);
  EXPECT_NE(err().find("OpenGL 3.3"), std::string::npos) << err();
}

// A pan (`pan X Y`, mm at the volume's centre) moves the picture by that much: the foreground
// centroid moves by X, Y over the size of a pixel at the depth of the volume's centre (the head
// phantom is nearly a sphere about it, so its outline lies near that depth; perspective moves
// nearer points more).
TEST_F(ViewerWindowTest, PanMovesTheVolumeByItsMillimetres) {
  const double panX = 30, panY = -20;
  const int rc = view("view 30 20\nscreenshot " + path("a.png") + "\npan " + std::to_string(panX) + " " +
                      std::to_string(panY) + "\nscreenshot " + path("b.png") + "\nquit\n");
  if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
  ASSERT_EQ(rc, 0) << err();
  const RgbaImage a = readPng(path("a.png")), b = readPng(path("b.png"));
  const Rect r = picture3D(a);
  const auto ca = centroid(cropRect(a, r)), cb = centroid(cropRect(b, r));
  ViewerApp app;
  app.loadHeadPhantom();
  app.setOrbit(30, 20);
  const CameraFrame cf(app.camera(), r.w, r.h);
  const Camera& c = cf.camera();
  const double perMm = 1 / cf.pixelSizeAt((c.target - c.eye).dot(cf.forward()));
  EXPECT_NEAR(cb[0] - ca[0], panX * perMm, 0.03 * std::abs(panX) * perMm) << "to the right";
  EXPECT_NEAR(cb[1] - ca[1], -panY * perMm, 0.03 * std::abs(panY) * perMm) << "down (rows grow downwards)";
  std::cout << "[ measured ] centroid moved " << cb[0] - ca[0] << ", " << cb[1] - ca[1] << " px; expected "
            << panX * perMm << ", " << -panY * perMm << '\n';
}

// With software OpenGL (Mesa's llvmpipe under Xvfb) `auto` times both renderers' first frames and
// keeps the faster one, saying which; the tool buttons fit the panel from 1280 to 1920 wide; a
// screenshot must be named .png (it is written as PNG).
TEST_F(ViewerWindowTest, RendererByMeasurementToolsFitAndScreenshotsArePng) {
  for (const std::string sz : {"1280x720", "1920x1080"}) {
    size = sz;
    const int rc = view("tool cut\nscreenshot " + path("a.png") + "\nquit\n", "", "--renderer auto");
    if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
    ASSERT_EQ(rc, 0) << err();
    EXPECT_NE(err().find("chosen by measurement"), std::string::npos) << err();
    EXPECT_EQ(err().find("is cut off"), std::string::npos) << sz << ": " << err();
    std::cout << "[ measured ] " << sz << ": " << err().substr(0, err().find('\n')) << '\n';
  }
  size = std::to_string(kW) + "x" + std::to_string(kH);
  EXPECT_EQ(view("screenshot " + path("a.jpg") + "\nquit\n"), 1) << err();
  EXPECT_NE(err().find("name it .png"), std::string::npos) << err();
  EXPECT_FALSE(fs::exists(path("a.jpg")));
}

// A file whose header states no orientation: a warning on stderr and in the panel (orange);
// --orientation states it (no warning, the labels follow it).
TEST_F(ViewerWindowTest, MissingOrientationIsShownAndCanBeStated) {
  // A raw NRRD header without space directions (as the shared head CT's), 32^3 int16.
  {
    std::ofstream raw(path("v.raw"), std::ios::binary);
    for (int i = 0; i < 32 * 32 * 32; ++i) {
      const int16_t v = static_cast<int16_t>((i % 32) * 10);
      raw.write(reinterpret_cast<const char*>(&v), 2);
    }
    std::ofstream(path("v.nhdr")) << "NRRD0004\ntype: int16\ndimension: 3\nsizes: 32 32 32\nspacings: 1 1 1\n"
                                     "endian: little\nencoding: raw\ndata file: v.raw\n";
  }
  int rc = view("screenshot " + path("warn.png") + "\nquit\n", path("v.nhdr"));
  if (noWindow(rc)) GTEST_SKIP() << "no window could be opened: " << err();
  ASSERT_EQ(rc, 0) << err();
  EXPECT_NE(err().find("states no orientation"), std::string::npos) << err();
  const RgbaImage warn = readPng(path("warn.png"));
  const int orange = countColour(crop(warn, 0, 0, kPanel, kH), 255, 179, 77, 12);
  EXPECT_GT(orange, 20) << "the warning in the panel";
  rc = view("screenshot " + path("stated.png") + "\nquit\n", path("v.nhdr"), "--renderer gpu --orientation LAS");
  ASSERT_EQ(rc, 0) << err();
  EXPECT_EQ(err().find("states no orientation"), std::string::npos) << err();
  EXPECT_LT(countColour(crop(readPng(path("stated.png")), 0, 0, kPanel, kH), 255, 179, 77, 12), 5);
  EXPECT_EQ(view("quit\n", path("v.nhdr"), "--orientation LRS"), 2) << err();
}
