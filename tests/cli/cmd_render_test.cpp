// `volscissors render` end to end: outputs, exit codes and messages for bad input.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "io/png_io.h"
#include "io/volume_io.h"

namespace fs = std::filesystem;

namespace {

struct CliRun {
  int status;
  std::string output;  // stdout + stderr
};

CliRun run(const std::string& args) {
  const std::string cmd = std::string(VS_CLI_PATH) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (p && fgets(buf, sizeof buf, p)) out += buf;
  const int rc = p ? pclose(p) : -1;
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, out};
}

class RenderCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("vs_render_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    vs::Geometry g;
    g.dims = {40, 36, 30};
    g.spacing = vs::Vec3(1, 1, 1.5);
    vs::VolumeI16 v(g);
    for (int64_t z = 0; z < 30; ++z)
      for (int64_t y = 0; y < 36; ++y)
        for (int64_t x = 0; x < 40; ++x) {
          const double dx = x - 20, dy = y - 18, dz = (z - 15) * 1.5;
          v(x, y, z) = static_cast<int16_t>(dx * dx + dy * dy + dz * dz < 100 ? 1000 : -1000);
        }
    vs::writeVolume(vs::AnyVolume(v), (dir_ / "vol.nrrd").string());
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string p(const std::string& name) { return (dir_ / name).string(); }
  static void write(const std::string& name, const std::string& text) { std::ofstream(p(name)) << text; }
  static fs::path dir_;
};
fs::path RenderCli::dir_;

}  // namespace

TEST_F(RenderCli, WritesPngsOfEveryModeAtTheRequestedSize) {
  for (const std::string mode : {"full", "cutbox", "triplanar", "monoplanar", "mip"}) {
    const CliRun r =
        run("render " + p("vol.nrrd") + " --tf ct-bone --mode " + mode + " --size 64x48 --out " + p(mode + ".png"));
    ASSERT_EQ(r.status, 0) << mode << ": " << r.output;
    const vs::RgbaImage im = vs::readPng(p(mode + ".png"));
    EXPECT_EQ(im.width, 64);
    EXPECT_EQ(im.height, 48);
  }
  // The bone sphere is in the middle of the full rendering, the corners are background.
  const vs::RgbaImage full = vs::readPng(p("full.png"));
  EXPECT_GT(full.at(32, 24)[0], 100);
  EXPECT_EQ(full.at(0, 0)[0], 0);
  // Slice: aspect from spacing (x 40 mm wide, z 45 mm high) fitted into 200x200.
  const CliRun s = run("render " + p("vol.nrrd") + " --mode slice --plane y=18 --size 200x200 --out " + p("s.png"));
  ASSERT_EQ(s.status, 0) << s.output;
  const vs::RgbaImage si = vs::readPng(p("s.png"));
  EXPECT_EQ(si.height, 200);
  EXPECT_NEAR(si.width, 200.0 * 40 / 45, 1.0);
}

TEST_F(RenderCli, TransferFunctionFileTurntableAndTimingReport) {
  write(
      "tf.json",
      R"({"points": [{"value": 0, "color": [0, 1, 0], "opacity": 0}, {"value": 500, "color": [0, 1, 0], "opacity": 1}]})");
  CliRun r =
      run("render " + p("vol.nrrd") + " --tf " + p("tf.json") + " --size 32x32 --turntable 3 --out " + p("tt.png"));
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* f : {"tt_000.png", "tt_001.png", "tt_002.png"}) {
    const vs::RgbaImage im = vs::readPng(p(f));
    EXPECT_GT(im.at(16, 16)[1], 100) << f;  // green sphere (plus a white specular highlight)
    EXPECT_GT(im.at(16, 16)[1], im.at(16, 16)[0] + 50) << f;
  }
  r = run("render " + p("vol.nrrd") + " --size 32x32 --repeat 3 --json " + p("rep.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(std::ifstream(p("rep.json")));
  EXPECT_EQ(j["image"], nlohmann::json::array({32, 32}));
  EXPECT_GT(j["threads"].get<int>(), 0);
  for (const char* k : {"load", "prepare", "frame_median"}) EXPECT_GE(j["seconds"][k].get<double>(), 0.0) << k;
  EXPECT_EQ(j["seconds"]["frames"].size(), 3u);
}

TEST_F(RenderCli, TrackingAndContourJsonOverlaysAreIndexCoordinates) {
  // A path through the middle of the volume in voxel index coordinates: drawn in colour in
  // front of a transparent volume (TF opacity zero).
  write("clear.json", R"({"points": [{"value": 0, "opacity": 0}]})");
  write("paths.json", R"({"paths": [{"voxels": [[2, 18, 15], [38, 18, 15]]}]})");
  CliRun r = run("render " + p("vol.nrrd") + " --tf " + p("clear.json") + " --overlay " + p("paths.json") +
                 " --overlay-radius 1 --size 64x64 --out " + p("ov.png"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  vs::RgbaImage im = vs::readPng(p("ov.png"));
  int redRows = 0;  // the line crosses the image centre horizontally (within a pixel or two)
  for (int y = 26; y < 38; ++y) redRows += im.at(32, y)[0] > 100 ? 1 : 0;
  EXPECT_GE(redRows, 1);
  EXPECT_LE(redRows, 4);
  EXPECT_EQ(im.at(32, 5)[0], 0);
  EXPECT_EQ(im.at(2, 32)[0], 0);  // beyond the line's ends
  write("contour.json", R"({"points": [[5, 5], [30, 5], [30, 25]], "slice": "z=15"})");
  r = run("render " + p("vol.nrrd") + " --mode slice --plane z=15 --size 40x36 --overlay " + p("contour.json") +
          " --out " + p("c.png"));
  ASSERT_EQ(r.status, 0) << r.output;
  im = vs::readPng(p("c.png"));
  EXPECT_GT(im.at(20, 5)[0], 200);  // on the contour's first edge (y = 5 row, 1 mm pixels)
  EXPECT_LT(im.at(20, 5)[1], 100);
  // An overlay in another frame (far away) is drawn nowhere but warned about.
  write("far.json", R"({"paths": [{"voxels": [[5000, 0, 0], [5001, 0, 0]]}]})");
  r = run("render " + p("vol.nrrd") + " --overlay " + p("far.json") + " --size 16x16 --out " + p("far.png"));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("outside the volume bounds"), std::string::npos) << r.output;
}

TEST_F(RenderCli, BadInputGivesClearErrors) {
  const std::string v = p("vol.nrrd") + " --out " + p("x.png") + " ";
  struct Case {
    std::string args;
    int status;
    std::string message;
  };
  write("bad_tf.json", "{\"points\": [{\"value\": 1, ");
  write("bad_tf2.json", R"({"points": [{"value": 1, "opacity": 3}]})");
  const Case cases[] = {
      {v + "--tf ct-banana", 2, "unknown transfer function preset"},
      {v + "--tf " + p("bad_tf.json"), 1, "malformed JSON"},
      {v + "--tf " + p("bad_tf2.json"), 2, "outside [0,1]"},
      {v + "--tf " + p("missing_tf.json"), 1, "cannot open"},
      {v + "--mode cutbox --box 10,10,10,10,20,20", 2, "cut box is empty"},
      {v + "--mode cutbox --box 100,100,100,120,120,120", 2, "outside the volume"},
      {v + "--mode cutbox --box 1,2,3", 2, "expected 6"},
      {v + "--mode monoplanar --plane z=99", 2, "outside the volume"},
      {v + "--mode triplanar --planes 1,2,300", 2, "outside the volume"},
      {v + "--mode slice --plane x=40", 2, "outside the volume"},
      // A negative plane is not "the default plane" (issue 11): every mode that takes --plane.
      {v + "--mode slice --plane z=-1", 2, "--plane z=-1 is outside the volume (z 0.."},
      {v + "--mode monoplanar --plane z=-1", 2, "--plane z=-1 is outside the volume (z 0.."},
      {v + "--mode monoplanar --plane y=-7", 2, "--plane y=-7 is outside the volume (y 0.."},
      {v + "--mode slice --plane z=-500 --world", 2, "is outside the volume"},
      {v + "--mode slice --plane q=3", 2, "axis must be x, y, z"},
      {v + "--size 0x10", 2, "--size"},
      {v + "--size 9000x9000", 2, "8192"},
      {v + "--size big", 2, "expected WxH"},
      {v + "--mode xray", 2, "unknown render mode"},
      {v + "--lighting 0.3,0.8,0.2", 2, "expected 4"},
      {v + "--lighting 2,0.8,0.2,10", 2, "must be in [0, 1]"},
      {v + "--overlay " + p("thing.xyz"), 2, "unsupported file type"},
      {p("nonexistent.nii.gz") + " --out " + p("x.png"), 1, "nonexistent.nii.gz"},
  };
  for (const auto& c : cases) {
    const CliRun r = run("render " + c.args);
    EXPECT_EQ(r.status, c.status) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(p("x.png")));
}
