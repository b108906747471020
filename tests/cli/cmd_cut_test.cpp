// CLI tests for `volscissors cut` through the real binary: the outputs and report on a sphere,
// and the bad inputs of issue 14 (clear error, exit status, no output file).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/progress_check.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"

namespace fs = std::filesystem;
using namespace vs;

namespace {

class CmdCut : public ::testing::Test {
 protected:
  fs::path dir;
  std::string vol;
  // Five points on the circle 6 mm above the centre of a sphere of radius 14 mm (voxel index).
  std::string points = "32.65,20,26;23.91,32.03,26;9.77,27.44,26;9.77,12.56,26;23.91,7.97,26";

  void SetUp() override {
    dir = fs::temp_directory_path() / ("vs_cut_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    Geometry g;
    g.dims = {40, 40, 40};
    VolumeF32 v(g, 0.0f);
    for (int64_t z = 0; z < 40; ++z)
      for (int64_t y = 0; y < 40; ++y)
        for (int64_t x = 0; x < 40; ++x) {
          const double d = 14 - std::sqrt(double((x - 20) * (x - 20) + (y - 20) * (y - 20) + (z - 20) * (z - 20)));
          v(x, y, z) = float(100 * std::clamp(0.5 + d, 0.0, 1.0));
        }
    vol = (dir / "sphere.nii.gz").string();
    writeVolume(AnyVolume(v), vol);
  }
  void TearDown() override { fs::remove_all(dir); }

  int run(const std::string& args) {
    const std::string cmd = std::string(VS_CLI_PATH) + " -q cut " + args + " > " + (dir / "stdout.txt").string() +
                            " 2> " + (dir / "stderr.txt").string();
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  std::string text(const std::string& name) {
    std::ifstream f(dir / name);
    return {std::istreambuf_iterator<char>(f), {}};
  }
  std::string outputs() {
    return " --labels " + (dir / "labels.nii.gz").string() + " --json " + (dir / "r.json").string() + " --contour " +
           (dir / "c.json").string() + " --cut-surface " + (dir / "s.ply").string();
  }
  bool anyOutput() {
    for (const char* f : {"labels.nii.gz", "r.json", "c.json", "s.ply"})
      if (fs::exists(dir / f)) return true;
    return false;
  }
};

}  // namespace

TEST_F(CmdCut, CutsTheCapAndReports) {
  ASSERT_EQ(run(vol + " --iso 50 --points \"" + points + "\"" + outputs()), 0) << text("stderr.txt");
  const auto j = nlohmann::json::parse(text("r.json"));
  EXPECT_GT(j["mesh"]["triangles"].get<int64_t>(), 1000);
  EXPECT_EQ(j["points"].size(), 5u);
  // The contour runs around the sphere at about 6 mm above the centre: radius ~12.6 mm.
  EXPECT_NEAR(j["contour"]["length_mm"].get<double>(), 2 * M_PI * std::sqrt(14.0 * 14 - 36), 8);
  const AnyVolume labels = readVolume((dir / "labels.nii.gz").string());
  const auto& L = std::get<VolumeU8>(labels);
  int64_t cut = 0, kept = 0;
  for (uint8_t l : L.voxels()) cut += l == 2, kept += l == 1;
  EXPECT_EQ(cut, j["parts"]["cut"]["voxels"].get<int64_t>());
  EXPECT_EQ(kept, j["parts"]["kept"]["voxels"].get<int64_t>());
  EXPECT_GT(cut, 500);
  EXPECT_LT(cut, kept);
  EXPECT_EQ(L(20, 20, 31), 2);  // the cap
  EXPECT_EQ(L(20, 20, 10), 1);  // the rest
  EXPECT_TRUE(fs::exists(dir / "s.ply"));
  EXPECT_TRUE(fs::exists(dir / "c.json"));
}

TEST_F(CmdCut, BadInputIsAClearErrorWithNoOutput) {
  EXPECT_EQ(run(vol + " --iso 50 --points \"32.65,20,26;23.91,32.03,26\"" + outputs()), 2);
  EXPECT_NE(text("stderr.txt").find("at least 3 points"), std::string::npos) << text("stderr.txt");
  EXPECT_EQ(run(vol + " --iso 50 --points \"1,2;3,4;5,6\"" + outputs()), 2);
  EXPECT_EQ(run(vol + " --iso 50 --points \"" + points + ";80,20,20\"" + outputs()), 2);
  EXPECT_NE(text("stderr.txt").find("outside the volume"), std::string::npos) << text("stderr.txt");
  EXPECT_EQ(run(vol + " --iso 50 --points \"" + points + ";20,20,1\"" + outputs()), 1);
  EXPECT_NE(text("stderr.txt").find("mm from the surface"), std::string::npos) << text("stderr.txt");
  EXPECT_EQ(run(vol + " --iso 500 --points \"" + points + "\"" + outputs()), 1);
  EXPECT_NE(text("stderr.txt").find("no surface"), std::string::npos) << text("stderr.txt");
  EXPECT_EQ(run(vol + " --iso 50 --points \"" + points + "\" --seed 1,1,1" + outputs()), 1);
  EXPECT_NE(text("stderr.txt").find("outside the object"), std::string::npos) << text("stderr.txt");
  EXPECT_EQ(run((dir / "missing.nii.gz").string() + " --iso 50 --points \"" + points + "\"" + outputs()), 1);
  EXPECT_FALSE(anyOutput());
}

// The weights: every one is shown with its default in --help, reported in the JSON, and a weight
// out of range is a usage error (exit 2) with nothing written.
TEST_F(CmdCut, WeightsShowTheirDefaultsAndAreChecked) {
  const std::string help = std::string(VS_CLI_PATH) + " cut --help > " + (dir / "stdout.txt").string();
  ASSERT_EQ(std::system(help.c_str()), 0);
  const std::string h = text("stdout.txt");
  for (const char* option : {"--wg", "--wc", "--wp", "--wd", "--contour-wg", "--contour-wn", "--contour-wl"}) {
    EXPECT_NE(h.find(std::string(option) + " FLOAT="), std::string::npos) << option << " shows no default";
  }
  ASSERT_EQ(run(vol + " --iso 50 --points \"" + points + "\" --wg 2 --contour-wl 0.2" + outputs()), 0)
      << text("stderr.txt");
  const auto j = nlohmann::json::parse(text("r.json"));
  EXPECT_EQ(j["cutting_surface"]["weights"]["wg"].get<double>(), 2.0);
  EXPECT_EQ(j["contour"]["weights"]["wl"].get<double>(), 0.2);
  EXPECT_TRUE(j["cutting_surface"]["energy"].contains("share_image"));
  EXPECT_TRUE(j["cutting_surface"]["energy"].contains("edge_within_reach"));
  fs::remove_all(dir / "r.json"), fs::remove_all(dir / "labels.nii.gz"), fs::remove_all(dir / "c.json"),
      fs::remove_all(dir / "s.ply");
  for (const char* bad : {" --wg -1", " --wc 0", " --wp nan", " --wd 1.5", " --contour-wn -2", " --contour-wl 0"}) {
    EXPECT_EQ(run(vol + " --iso 50 --points \"" + points + "\"" + bad + outputs()), 2) << bad;
    EXPECT_FALSE(text("stderr.txt").empty()) << bad;
  }
  EXPECT_FALSE(anyOutput());
}

// A seed on the cutting surface or outside the object: exit 1, a message saying which, and no
// output file (the bad input, through the CLI).
TEST_F(CmdCut, SeedOnTheCuttingSurfaceOrOutsideTheObjectIsRefused) {
  ASSERT_EQ(run(vol + " --iso 50 --points \"" + points + "\"" + outputs()), 0) << text("stderr.txt");
  // The cutting surface's vertex nearest the sphere's axis (world mm = voxel index here).
  const TriMesh surface = readTriMesh((dir / "s.ply").string());
  ASSERT_FALSE(surface.positions.empty());
  Vec3 onCut = surface.positions[0];
  for (const Vec3& p : surface.positions)
    if (std::hypot(p.x() - 20, p.y() - 20) < std::hypot(onCut.x() - 20, onCut.y() - 20)) onCut = p;
  for (const char* f : {"labels.nii.gz", "r.json", "c.json", "s.ply"}) fs::remove(dir / f);
  const std::string seed = std::to_string(std::lround(onCut.x())) + "," + std::to_string(std::lround(onCut.y())) + "," +
                           std::to_string(std::lround(onCut.z()));
  EXPECT_EQ(run(vol + " --iso 50 --points \"" + points + "\" --seed " + seed + outputs()), 1) << seed;
  EXPECT_NE(text("stderr.txt").find("--seed lies on the cutting surface"), std::string::npos) << text("stderr.txt");
  EXPECT_FALSE(anyOutput());
  EXPECT_EQ(run(vol + " --iso 50 --points \"" + points + "\" --seed 2,3,20" + outputs()), 1);
  EXPECT_NE(text("stderr.txt").find("--seed lies outside the object"), std::string::npos) << text("stderr.txt");
  EXPECT_FALSE(anyOutput());
}

namespace {

// --mesh envmap: the sphere is star-shaped from its centroid and cuts as with the iso-surface; a
// sphere with a handle beside it is not (a clear error, exit 1, no output); an unknown kind is usage.
TEST_F(CmdCut, EnvironmentMapMesh) {
  ASSERT_EQ(run(vol + " --iso 50 --mesh envmap --points \"" + points + "\"" + outputs()), 0) << text("stderr.txt");
  const auto j = nlohmann::json::parse(text("r.json"));
  EXPECT_EQ(j["mesh"]["kind"], "envmap");
  EXPECT_GT(j["parts"]["cut"]["voxels"].get<int64_t>(), 500);
  for (const char* f : {"labels.nii.gz", "r.json", "c.json", "s.ply"}) fs::remove(dir / f);

  Geometry g;
  g.dims = {52, 40, 40};
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < 40; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 52; ++x) {
        const double ring = std::hypot(double(x) - 38, double(z) - 20) - 8;
        const double d =
            std::max(12 - std::sqrt(double((x - 22) * (x - 22) + (y - 20) * (y - 20) + (z - 20) * (z - 20))),
                     2.5 - std::hypot(ring, double(y) - 20));
        v(x, y, z) = float(100 * std::clamp(0.5 + d, 0.0, 1.0));
      }
  const std::string handle = (dir / "handle.nii.gz").string();
  writeVolume(AnyVolume(v), handle);
  EXPECT_EQ(run(handle + " --iso 50 --mesh envmap --points \"22,20,32;30,20,28;22,28,28\"" + outputs()), 1);
  EXPECT_NE(text("stderr.txt").find("not star-shaped"), std::string::npos) << text("stderr.txt");
  EXPECT_FALSE(anyOutput());
  EXPECT_EQ(run(vol + " --iso 50 --mesh sphere --points \"" + points + "\"" + outputs()), 2);
}

}  // namespace

TEST_F(CmdCut, ProgressLineOnATerminalOnly) {
  if (!test::haveScriptCommand()) GTEST_SKIP() << "util-linux `script` not available";
  test::expectProgressOnTerminalOnly(VS_CLI_PATH, "cut",
                                     "cut " + vol + " --iso 50 --points \"" + points + "\"" + outputs(),
                                     (dir / "transcript.txt").string());
}
