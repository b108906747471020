// The profile plot in the real window (Xvfb, Mesa): a traced tree measured (`measure`), a path
// and a section selected by script; the screenshot shows the plot below the tool panel (its line
// and the selected section's marker) and the section's contour on the slice views and in the 3D
// view, none of which is there before `measure`. The app-level selection is checked against the
// core's measureTree of the saved tree.
#ifdef VS_HAVE_VIEWER
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "app/script.h"
#include "app/viewer_app.h"
#include "io/mesh_io.h"
#include "io/png_io.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "quantify/quantify.h"
#include "trace_fixture.h"
#include "window/profile_panel.h"
#include "xserver.h"

namespace fs = std::filesystem;
using namespace vs;
using namespace vs::viewer;

namespace {

// The layout at --size 980x640: tool panel 340 px wide (the profile window at its bottom, 230 px
// high once measured), then a 2x2 grid of views.
constexpr int kW = 980, kH = 640, kPanel = 340, kProfileH = 230;

struct Box {
  int x0, y0, x1, y1;
};

int count(const RgbaImage& im, const Box& b, const int (&c)[3], int tol, int* xMin = nullptr, int* xMax = nullptr) {
  int n = 0;
  for (int y = b.y0; y < b.y1; ++y)
    for (int x = b.x0; x < b.x1; ++x) {
      const uint8_t* p = im.at(x, y);
      if (std::abs(p[0] - c[0]) <= tol && std::abs(p[1] - c[1]) <= tol && std::abs(p[2] - c[2]) <= tol) {
        ++n;
        if (xMin) *xMin = std::min(*xMin, x);
        if (xMax) *xMax = std::max(*xMax, x);
      }
    }
  return n;
}

}  // namespace

TEST(ViewerProfileWindow, PlotAndSectionAreDrawn) {
  const fs::path dir = fs::temp_directory_path() / ("vs_viewer_profile_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto path = [&](const std::string& n) { return (dir / n).string(); };
  vs::viewer::testing::XServer xserver(dir, 1280, 800);
  if (!xserver.ok()) GTEST_SKIP() << "no X server: " << xserver.why();
  std::string s = vs::viewer::testing::writeTracePhantom(path("vessels.nii.gz"));
  s += "run\nsave " + path("tree.swc") + "\nscreenshot " + path("before.png") +
       "\nmeasure\nprofile-path 0\nprofile-arc 12\nscreenshot " + path("profile.png") + "\nquit\n";
  std::ofstream(path("script.txt")) << s;
  const auto run =
      vs::viewer::testing::runViewerScript(xserver, path("vessels.nii.gz"), path("script.txt"), dir.string(), kW, kH);
  if (run.noWindow) GTEST_SKIP() << "no window could be opened: " << run.err;
  ASSERT_EQ(run.rc, 0) << run.err;
  const RgbaImage before = readPng(path("before.png")), shot = readPng(path("profile.png"));
  ASSERT_EQ(shot.width, kW);
  const Box plot{4, kH - kProfileH + 40, kPanel - 4, kH - 4};
  const Box views{kPanel, 0, kW, kH};
  const int(&line)[3] = kProfileLineRgb;
  const int(&section)[3] = kProfileSectionRgb;
  EXPECT_EQ(count(before, plot, line, 20), 0) << "no plot before `measure`";
  EXPECT_EQ(count(before, views, section, 20), 0) << "no section before `measure`";
  int x0 = kW, x1 = -1;
  const int linePixels = count(shot, plot, line, 20, &x0, &x1);
  std::cout << "[ measured ] plot line " << linePixels << " px over x " << x0 << ".." << x1 << ", marker "
            << count(shot, plot, section, 20) << " px, section in the views " << count(shot, views, section, 20)
            << " px\n";
  EXPECT_GT(linePixels, 100) << "the diameter curve is drawn";
  EXPECT_GT(x1 - x0, (kPanel - 60) / 2) << "the curve runs along the arc axis";
  EXPECT_GT(count(shot, plot, section, 20), 20) << "the selected section is marked on the plot";
  EXPECT_GT(count(shot, views, section, 20), 30) << "the selected section's contour is drawn in the views";
  // The selection `profile-arc 12` makes: path 0's section nearest 12 mm from the root.
  const Tree tree = readTree(path("tree.swc"));
  ViewerApp app;
  app.load(path("vessels.nii.gz"));
  ProfileView p;
  p.measure(app.floatVolume(), tree);
  p.selectArc(12);
  ASSERT_NE(p.selected(), nullptr);
  EXPECT_LE(std::abs(p.selectedArcMm() - 12), QuantifyOptions{}.stepMm);
  fs::remove_all(dir);
}

#endif  // VS_HAVE_VIEWER
