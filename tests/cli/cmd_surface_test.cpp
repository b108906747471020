// CLI tests for `volscissors surface`: outputs, report, exit statuses, no output on failure.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/progress_check.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "surface/shapes.h"

namespace fs = std::filesystem;
using namespace vs;

namespace {

class CmdSurface : public ::testing::Test {
 protected:
  fs::path dir;
  std::string vol, out, json;

  void SetUp() override {
    dir = fs::temp_directory_path() / ("vs_surface_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    Geometry g;
    g.dims = {40, 40, 36};
    g.spacing = {1.0, 1.0, 1.25};
    g.origin = {-10, 5, 20};
    const Vec3 c = g.indexToWorld(Vec3(19.6, 20.2, 17.3));
    vol = (dir / "ball.nii.gz").string();
    writeVolume(AnyVolume(test::makeStarVolume(g, c, [](const Vec3& d) { return 14.0 + 1.5 * d[1]; })), vol);
    out = (dir / "mesh.ply").string();
    json = (dir / "report.json").string();
  }
  void TearDown() override { fs::remove_all(dir); }

  int run(const std::string& args) {
    const std::string cmd = std::string(VS_CLI_PATH) + " -q surface " + vol + " " + args + " > " +
                            (dir / "stdout.txt").string() + " 2> " + (dir / "stderr.txt").string();
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  std::string err() {
    std::ifstream f(dir / "stderr.txt");
    return {std::istreambuf_iterator<char>(f), {}};
  }
  bool noOutput() { return !fs::exists(out) && !fs::exists(json); }
};

}  // namespace

TEST_F(CmdSurface, OctantPatchAndReport) {
  ASSERT_EQ(run("--planes 20,20,17 --octant -x+y-z --level 3 --out " + out + " --json " + json), 0) << err();
  const TriMesh m = readTriMesh(out);
  EXPECT_EQ(m.triangles.size(), 64u);
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_EQ(j["mesh"]["triangles"], 64);
  EXPECT_EQ(j["mesh"]["euler_characteristic"], 1);
  EXPECT_EQ(j["levels"].size(), 3u);
  EXPECT_EQ(j["levels"][2]["triangles"], 64);
  EXPECT_GT(j["levels"][0]["nodes_settled"].get<int64_t>(), 0);
  EXPECT_TRUE(j["corners"].contains("-x") && j["corners"].contains("+y") && j["corners"].contains("-z"));
  EXPECT_FALSE(j["corners"].contains("+x"));
  EXPECT_NEAR(j["iso"].get<double>(), 500, 80);  // Otsu's threshold of the 0 / 1000 step
}

TEST_F(CmdSurface, ClosedIsWatertight) {
  ASSERT_EQ(run("--planes 20,20,17 --closed --level 2 --iso 500 --out " + out + " --json " + json), 0) << err();
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_EQ(j["mesh"]["triangles"], 8 * 16);
  EXPECT_EQ(j["mesh"]["euler_characteristic"], 2);
  EXPECT_TRUE(j["mesh"]["watertight"].get<bool>());
}

TEST_F(CmdSurface, BadInputFailsWithoutOutput) {
  const std::string outs = " --out " + out + " --json " + json;
  EXPECT_EQ(run("--planes 20,50,17" + outs), 2);
  EXPECT_NE(err().find("outside the volume"), std::string::npos) << err();
  EXPECT_EQ(run("--planes 20,20" + outs), 2);
  EXPECT_EQ(run("--planes 20,20,17 --octant +y+x+z" + outs), 2);
  EXPECT_EQ(run("--planes 20,20,17 --corners \"33,20,17;20,33,17;21,20,30\"" + outs), 2);
  EXPECT_NE(err().find("corner +z (21,20,30) is not on its half-line"), std::string::npos) << err();
  EXPECT_EQ(run("--planes 20,20,17 --iso 5000" + outs), 1);
  EXPECT_NE(err().find("no surface crossing on the half-line +x"), std::string::npos) << err();
  EXPECT_EQ(run("--planes 20,20,17 --level 9" + outs), 2);  // "too deep for the object": surface_test.cpp
  EXPECT_EQ(run("--planes 20,20,17 --via \"z+x+y:2,2,17\"" + outs), 2);
  EXPECT_NE(err().find("side z+x+y"), std::string::npos) << err();
  EXPECT_EQ(run("--planes 20,20,17 --out " + (dir / "mesh.png").string()), 2);
  EXPECT_TRUE(noOutput());
  EXPECT_EQ(run("--planes 20,20,17 --out " + (dir / "missing_dir" / "m.ply").string()), 1);
}

// --edit re-routes a side through points after extracting, re-subdividing only the two octants
// sharing it; the mesh equals extracting with --via from the start. --every-voxel keeps the
// closed surface watertight.
TEST_F(CmdSurface, EditEqualsViaAndEveryVoxelStaysWatertight) {
  const std::string common = "--planes 20,20,17 --closed --level 2 --iso 500";
  ASSERT_EQ(run(common + " --edit \"z+x+y:28,28,17\" --out " + out + " --json " + json), 0) << err();
  const TriMesh edited = readTriMesh(out);
  {
    std::ifstream f(json);
    const nlohmann::json j = nlohmann::json::parse(f);
    ASSERT_EQ(j["edits"].size(), 1u);
    EXPECT_EQ(j["edits"][0]["side"], "z+x+y");
    EXPECT_EQ(j["edits"][0]["octants_recomputed"], nlohmann::json::array({"+x+y+z", "+x+y-z"}));
    EXPECT_TRUE(j["mesh"]["watertight"].get<bool>());
  }
  const std::string viaOut = (dir / "via.ply").string();
  ASSERT_EQ(run(common + " --via \"z+x+y:28,28,17\" --out " + viaOut), 0) << err();
  const TriMesh via = readTriMesh(viaOut);
  EXPECT_EQ(edited.triangles, via.triangles);
  ASSERT_EQ(edited.positions.size(), via.positions.size());
  for (size_t i = 0; i < via.positions.size(); ++i) EXPECT_LT((edited.positions[i] - via.positions[i]).norm(), 1e-4);
  EXPECT_EQ(run(common + " --edit \"z+x+q:28,28,17\" --out " + viaOut), 2);
  EXPECT_NE(err().find("side 'z+x+q'"), std::string::npos) << err();

  ASSERT_EQ(run(common + " --every-voxel --out " + out + " --json " + json), 0) << err();
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_TRUE(j["mesh"]["watertight"].get<bool>());
  EXPECT_EQ(j["mesh"]["euler_characteristic"], 2);
  EXPECT_GT(j["mesh"]["vertices"].get<int64_t>(), edited.positions.size());
}

// A ball with a mushroom on its +x+y+z diagonal (an overhang): the closed surface fails, naming
// that octant alone and writing nothing; --allow-folds writes it and the report marks the octant.
TEST_F(CmdSurface, FoldedOctantFailsUnlessAllowed) {
  Geometry g;
  g.dims = {56, 56, 56};
  const Vec3 c(27, 28, 26);
  vol = (dir / "mushroom.nii.gz").string();
  writeVolume(AnyVolume(test::makeImplicitVolume(g, test::mushroomBall(c, 18, Vec3(1, 1, 1).normalized()))), vol);
  const std::string common = "--planes 27,28,26 --closed --level 3 --iso 500 --out " + out + " --json " + json;
  EXPECT_EQ(run(common), 1);
  EXPECT_NE(err().find("folds back over itself along rays from the centre in octant +x+y+z ("), std::string::npos)
      << err();
  EXPECT_EQ(err().find("-x"), std::string::npos) << err();  // no other octant named
  EXPECT_TRUE(noOutput());
  ASSERT_EQ(run(common + " --allow-folds"), 0) << err();
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f);
  ASSERT_EQ(j["octants"].size(), 8u);
  for (const auto& o : j["octants"]) {
    EXPECT_EQ(o["folded"].get<bool>(), o["octant"] == "+x+y+z") << o.dump();
    EXPECT_EQ(o["first_fold_voxel"].is_null(), o["octant"] != "+x+y+z") << o.dump();
  }
  EXPECT_TRUE(j["mesh"]["watertight"].get<bool>());
}

TEST_F(CmdSurface, ProgressLineOnATerminalOnly) {
  if (!test::haveScriptCommand()) GTEST_SKIP() << "util-linux `script` not available";
  test::expectProgressOnTerminalOnly(VS_CLI_PATH, "surface",
                                     "surface " + vol + " --planes 20,20,17 --level 2 --out " + out + " --json " + json,
                                     (dir / "transcript.txt").string());
}

// `--iso nan` (or inf) is refused as bad usage, never taken for "no --iso" (the Otsu default).
TEST_F(CmdSurface, NonFiniteIsoIsRefused) {
  for (const char* iso : {"nan", "inf", "-inf"}) {
    EXPECT_EQ(run(std::string("--planes 20,20,17 --level 1 --iso ") + iso + " --out " + out + " --json " + json), 2)
        << iso;
    EXPECT_NE(err().find("--iso must be a finite value"), std::string::npos) << err();
    EXPECT_TRUE(noOutput());
  }
}
