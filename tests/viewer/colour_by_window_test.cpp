// The traced tree coloured by its measured diameter in the real window (Xvfb, Mesa; issue 24):
// trace + measure + `color-by diameter`, screenshots before, with and after (`color-by none`).
// Checked by pixel properties of the 3D view: the tree shows more than one hue of the core's
// ramp (render/colour_legend.h rampColour) away from the legend, the legend's bar (the ramp from
// blue to red) is drawn at the view's right edge, and `color-by none` gives back the single-colour
// picture. The range is the one `render --color-by diameter` reports for the same measured tree.
#ifdef VS_HAVE_VIEWER
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/viewer_app.h"
#include "io/mesh_io.h"
#include "io/png_io.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "render/colour_legend.h"
#include "trace_fixture.h"
#include "xserver.h"

namespace fs = std::filesystem;
using namespace vs;
using namespace vs::viewer;

namespace {

// The layout at --size 980x640: tool panel 340 px wide, then a 2x2 grid; the 3D view top left.
constexpr int kW = 980, kH = 640, kPanel = 340, kCellW = (kW - kPanel) / 2, kCellH = kH / 2;
constexpr int kLegendStrip = 100;  // the right part of the 3D view that holds the legend

struct Box {
  int x0, y0, x1, y1;
};
const Box kView{kPanel + 4, 24, kPanel + kCellW - 4, kCellH - 4};
const Box kTreeArea{kView.x0, kView.y0, kView.x1 - kLegendStrip, kView.y1};
const Box kLegendArea{kView.x1 - kLegendStrip, kView.y0, kView.x1, kView.y1};

// Pixels of the box within `tol` (per channel) of the ramp, per fifth of the ramp (blue, cyan,
// green, yellow, red: the hue bands of rampColour).
std::array<int, 5> rampBands(const RgbaImage& im, const Box& b, int tol) {
  std::array<int, 5> bands{};
  for (int y = b.y0; y < b.y1; ++y)
    for (int x = b.x0; x < b.x1; ++x) {
      const uint8_t* p = im.at(x, y);
      for (int k = 0; k <= 100; ++k) {
        const auto c = rampColour(k / 100.0);
        if (std::abs(p[0] - int(c[0] * 255)) <= tol && std::abs(p[1] - int(c[1] * 255)) <= tol &&
            std::abs(p[2] - int(c[2] * 255)) <= tol) {
          ++bands[size_t(std::min(4, k / 20))];
          break;
        }
      }
    }
  return bands;
}

int countColour(const RgbaImage& im, const Box& b, int r, int g, int bl, int tol) {
  int n = 0;
  for (int y = b.y0; y < b.y1; ++y)
    for (int x = b.x0; x < b.x1; ++x) {
      const uint8_t* p = im.at(x, y);
      n += std::abs(p[0] - r) <= tol && std::abs(p[1] - g) <= tol && std::abs(p[2] - bl) <= tol;
    }
  return n;
}

int differing(const RgbaImage& a, const RgbaImage& b, const Box& box) {
  int n = 0;
  for (int y = box.y0; y < box.y1; ++y)
    for (int x = box.x0; x < box.x1; ++x) n += !std::equal(a.at(x, y), a.at(x, y) + 3, b.at(x, y));
  return n;
}

std::string bandsText(const std::array<int, 5>& b) {
  return std::to_string(b[0]) + "/" + std::to_string(b[1]) + "/" + std::to_string(b[2]) + "/" + std::to_string(b[3]) +
         "/" + std::to_string(b[4]);
}

}  // namespace

TEST(ViewerColourByWindow, TreeColouredByDiameterWithLegend) {
  const fs::path dir = fs::temp_directory_path() / ("vs_viewer_colour_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto path = [&](const std::string& n) { return (dir / n).string(); };
  vs::viewer::testing::XServer xserver(dir, 1280, 800);
  if (!xserver.ok()) GTEST_SKIP() << "no X server: " << xserver.why();
  std::string s = vs::viewer::testing::writeTracePhantom(path("vessels.nii.gz"));
  s += "run\nsave " + path("tree.swc") + "\nmeasure\nscreenshot " + path("single.png") + "\ncolor-by diameter\n" +
       "screenshot " + path("diameter.png") + "\ncolor-by none\nscreenshot " + path("back.png") + "\nquit\n";
  std::ofstream(path("script.txt")) << s;
  const auto run =
      vs::viewer::testing::runViewerScript(xserver, path("vessels.nii.gz"), path("script.txt"), dir.string(), kW, kH);
  if (run.noWindow) GTEST_SKIP() << "no window could be opened: " << run.err;
  ASSERT_EQ(run.rc, 0) << run.err;
  const RgbaImage single = readPng(path("single.png")), coloured = readPng(path("diameter.png")),
                  back = readPng(path("back.png"));
  ASSERT_EQ(coloured.width, kW);
  if (const char* keep = std::getenv("VS_KEEP_SHOTS")) fs::copy_file(path("diameter.png"), keep);

  const auto treeSingle = rampBands(single, kTreeArea, 8), treeColoured = rampBands(coloured, kTreeArea, 8);
  const auto legendSingle = rampBands(single, kLegendArea, 8), legendColoured = rampBands(coloured, kLegendArea, 8);
  auto bandsOver = [](const std::array<int, 5>& b, int n) {
    return int(std::count_if(b.begin(), b.end(), [&](int v) { return v >= n; }));
  };
  const int redSingle = countColour(single, kView, 255, 60, 40, 25),
            redColoured = countColour(coloured, kView, 255, 60, 40, 25);
  std::cout << "[ measured ] tree ramp pixels per band (blue/cyan/green/yellow/red): single " << bandsText(treeSingle)
            << ", coloured " << bandsText(treeColoured) << "; legend strip: single " << bandsText(legendSingle)
            << ", coloured " << bandsText(legendColoured) << "; single-colour tree pixels " << redSingle << " -> "
            << redColoured << "; pixels differing after color-by none " << differing(single, back, kView) << "\n";
  // The tree: more than one hue of the ramp where there was one colour.
  EXPECT_GE(bandsOver(treeColoured, 15), 2) << "the tree shows more than one hue of the map";
  EXPECT_LE(bandsOver(treeSingle, 15), 0) << "no ramp colours before color-by";
  EXPECT_GT(redSingle, 100) << "the single-colour tree is drawn";
  EXPECT_LT(redColoured, redSingle / 5) << "the single colour is replaced";
  // The legend: every band of the ramp at the right edge (a bar at least 20 px high per band).
  for (size_t k = 0; k < 5; ++k) {
    EXPECT_GE(legendColoured[k], 100) << "legend band " << k;
    EXPECT_LT(legendSingle[k], 10) << "no legend before color-by, band " << k;
  }
  // color-by none: the single-colour picture again.
  EXPECT_LT(differing(single, back, kView), 20);

  // The range is `render --color-by diameter`'s for the same tree measured by `measure --out`.
  ViewerApp app;
  app.load(path("vessels.nii.gz"));
  const Tree tree = readTree(path("tree.swc"));
  app.profile().measure(app.floatVolume(), tree);
  app.profile().setColourByDiameter(true);
  const ColouredPieces* cp = app.profile().colouredTree();
  ASSERT_NE(cp, nullptr);
  const std::string cli = std::string(VS_CLI_PATH) + " -q ";
  ASSERT_EQ(std::system((cli + "measure " + path("tree.swc") + " " + path("vessels.nii.gz") + " --out " +
                         path("measured.swc") + " > /dev/null 2>&1")
                            .c_str()),
            0);
  ASSERT_EQ(std::system((cli + "render " + path("vessels.nii.gz") + " --mode mip --overlay " + path("measured.swc") +
                         " --color-by diameter --out " + path("render.png") + " --json " + path("render.json") +
                         " > /dev/null 2>&1")
                            .c_str()),
            0);
  std::ifstream rf(path("render.json"));
  const nlohmann::json r = nlohmann::json::parse(rf);
  std::cout << "[ measured ] diameter range viewer " << cp->loMm << ".." << cp->hiMm << " mm, render "
            << r["color_by"]["min"] << ".." << r["color_by"]["max"] << " mm\n";
  EXPECT_NEAR(cp->loMm, r["color_by"]["min"].get<double>(), 1e-3);
  EXPECT_NEAR(cp->hiMm, r["color_by"]["max"].get<double>(), 1e-3);
  EXPECT_LT(cp->loMm, cp->hiMm);
  // Without a measurement the colouring is refused (nothing silent).
  ViewerApp fresh;
  EXPECT_THROW(fresh.profile().setColourByDiameter(true), InvalidArgument);
  fs::remove_all(dir);
}

#endif  // VS_HAVE_VIEWER
