// CLI tests for `volscissors livewire`: outputs (JSON, mask volume) and exit statuses.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "io/volume_io.h"

namespace fs = std::filesystem;
using namespace vs;

namespace {

class CmdLiveWire : public ::testing::Test {
 protected:
  fs::path dir;
  std::string vol;

  void SetUp() override {
    dir = fs::temp_directory_path() / ("vs_livewire_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    // 64 x 64 x 5, 0.8 x 0.8 x 2 mm: a bright disc (radius 15 px, centre 32,32) on every slice.
    Geometry g;
    g.dims = {64, 64, 5};
    g.spacing = {0.8, 0.8, 2.0};
    g.origin = {10, -20, 5};
    VolumeF32 v(g, 20.0f);
    for (int64_t z = 0; z < 5; ++z)
      for (int64_t y = 0; y < 64; ++y)
        for (int64_t x = 0; x < 64; ++x)
          if (std::hypot(double(x) - 32, double(y) - 32) <= 15) v(x, y, z) = 200.0f;
    vol = (dir / "disc.nii.gz").string();
    writeVolume(AnyVolume(v), vol);
    writeVolume(AnyVolume(VolumeF32(g, 7.0f)), (dir / "flat.nii.gz").string());
    v(5, 5, 3) = std::numeric_limits<float>::quiet_NaN();
    writeVolume(AnyVolume(v), (dir / "nan.nii.gz").string());
  }
  void TearDown() override { fs::remove_all(dir); }

  int run(const std::string& args) {
    const std::string cmd = std::string(VS_CLI_PATH) + " -q livewire " + args + " > " + (dir / "stdout.txt").string() +
                            " 2> " + (dir / "stderr.txt").string();
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  std::string text(const std::string& name) {
    std::ifstream f(dir / name);
    return {std::istreambuf_iterator<char>(f), {}};
  }
};

}  // namespace

TEST_F(CmdLiveWire, ClosedContourWithMask) {
  const std::string out = (dir / "c.json").string(), mask = (dir / "m.nii.gz").string();
  ASSERT_EQ(
      run(vol + " --slice z=2 --points \"32,17;47,32;32,47;17,32\" --closed --snap 2 --out " + out + " --mask " + mask),
      0)
      << text("stderr.txt");
  EXPECT_NE(text("stdout.txt").find("length"), std::string::npos);
  const auto j = nlohmann::json::parse(text("c.json"));
  EXPECT_TRUE(j["closed"].get<bool>());
  EXPECT_EQ(j["slice"]["axis"], "z");
  EXPECT_EQ(j["slice"]["index"], 2);
  const auto& pts = j["points"];
  ASSERT_GT(pts.size(), 60u);
  // Every contour pixel lies on the disc's edge (within a pixel of radius 15), and the chain is 8-connected.
  for (size_t i = 0; i < pts.size(); ++i) {
    const double r = std::hypot(pts[i][0].get<double>() - 32, pts[i][1].get<double>() - 32);
    EXPECT_NEAR(r, 15.0, 1.2) << i;
    const auto& n = pts[(i + 1) % pts.size()];
    EXPECT_LE(
        std::max(std::abs(n[0].get<int>() - pts[i][0].get<int>()), std::abs(n[1].get<int>() - pts[i][1].get<int>())),
        1);
  }
  // Length: about the circumference 2 pi 15 px * 0.8 mm.
  EXPECT_NEAR(j["length_mm"].get<double>(), 2 * M_PI * 15 * 0.8, 8.0);
  EXPECT_GT(j["cost"].get<double>(), 0.0);
  ASSERT_EQ(j["points_index"].size(), pts.size());
  ASSERT_EQ(j["points_world"].size(), pts.size());
  ASSERT_EQ(j["clicks"].size(), 4u);
  const Geometry g = geometryOf(readVolume(vol));
  for (size_t i = 0; i < pts.size(); i += 7) {
    const auto& idx = j["points_index"][i];
    EXPECT_EQ(idx[0], pts[i][0]);
    EXPECT_EQ(idx[1], pts[i][1]);
    EXPECT_EQ(idx[2], 2);
    const Vec3 w = g.indexToWorld(Vec3(idx[0].get<double>(), idx[1].get<double>(), 2.0));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(j["points_world"][i][a].get<double>(), w[a], 1e-6);
  }
  // Mask: full volume size, uint8, only slice z = 2, area = filled disc (~ pi 15^2 = 707 px).
  const AnyVolume m = readVolume(mask);
  ASSERT_EQ(voxelType(m), VoxelType::UInt8);
  const auto& mv = std::get<VolumeU8>(m);
  ASSERT_EQ(mv.dims(), (Index3{64, 64, 5}));
  int64_t count = 0, offSlice = 0;
  for (int64_t z = 0; z < 5; ++z)
    for (int64_t y = 0; y < 64; ++y)
      for (int64_t x = 0; x < 64; ++x)
        if (mv(x, y, z)) (z == 2 ? count : offSlice)++;
  EXPECT_EQ(offSlice, 0);
  EXPECT_EQ(count, j["area_pixels"].get<int64_t>());
  EXPECT_NEAR(double(count), M_PI * 15.5 * 15.5, 60.0);
  EXPECT_NEAR(j["area_mm2"].get<double>(), double(count) * 0.64, 1e-4);  // NIfTI stores spacing as float32
}

TEST_F(CmdLiveWire, CoronalSliceAndOpenContour) {
  const std::string out = (dir / "c.json").string();
  // Coronal y = 32: u = x, v = z (5 rows). An open path across the slice.
  ASSERT_EQ(run(vol + " --slice y=32 --points \"3,1;60,3\" --cost gradient --smooth 1.0 --out " + out), 0)
      << text("stderr.txt");
  const auto j = nlohmann::json::parse(text("c.json"));
  EXPECT_FALSE(j["closed"].get<bool>());
  EXPECT_EQ(j["slice"]["axis"], "y");
  EXPECT_EQ(j["cost_kind"], "gradient");
  EXPECT_EQ(j["points"].front(), nlohmann::json({3, 1}));
  EXPECT_EQ(j["points"].back(), nlohmann::json({60, 3}));
  for (const auto& idx : j["points_index"]) EXPECT_EQ(idx[1], 32);
  EXPECT_FALSE(j.contains("area_pixels"));
}

TEST_F(CmdLiveWire, FlatImageGivesStraightPaths) {
  // No gradient anywhere: uniform cost per mm, so the contour is the straight (shortest) polygon.
  const std::string out = (dir / "f.json").string();
  ASSERT_EQ(run((dir / "flat.nii.gz").string() + " --slice z=1 --points \"10,10;40,10;40,30\" --closed --out " + out),
            0)
      << text("stderr.txt");
  const auto j = nlohmann::json::parse(text("f.json"));
  // 30 + 20 px sides plus the diagonal back (20 diagonal steps + 10 straight): 0.8 mm pixels.
  EXPECT_NEAR(j["length_mm"].get<double>(), 0.8 * (30 + 20 + 20 * std::sqrt(2.0) + 10), 1e-4);  // float32 spacing
  EXPECT_TRUE(std::isfinite(j["cost"].get<double>()));
  EXPECT_EQ(j["segments"].size(), 3u);
}

TEST_F(CmdLiveWire, UsageErrorsExitWith2) {
  const std::string out = " --out " + (dir / "x.json").string();
  EXPECT_EQ(run(vol + " --slice z=2 --points \"3,3;70,3\"" + out), 2);  // outside the slice
  EXPECT_NE(text("stderr.txt").find("outside"), std::string::npos);
  EXPECT_EQ(run(vol + " --slice z=2 --points \"3,3;3,3;9,9\"" + out), 2);  // seed equal to target
  EXPECT_NE(text("stderr.txt").find("same pixel"), std::string::npos);
  EXPECT_EQ(run(vol + " --slice z=9 --points \"3,3;9,9\"" + out), 2);            // slice out of range
  EXPECT_EQ(run(vol + " --slice w=2 --points \"3,3;9,9\"" + out), 2);            // bad slice syntax
  EXPECT_EQ(run(vol + " --points \"3,3;a,9\"" + out), 2);                        // bad point syntax
  EXPECT_NE(text("stderr.txt").find("'a,9'"), std::string::npos);                // names the item
  EXPECT_EQ(run(vol + " --slice z=2 --world --points \"1,2,3;4,5\"" + out), 2);  // world needs x,y,z
  EXPECT_NE(text("stderr.txt").find("'4,5'"), std::string::npos);
  EXPECT_EQ(run(vol + " --points \"3,3\"" + out), 2);                      // one point
  EXPECT_EQ(run(vol + " --points \"3,3;9,9\" --closed" + out), 2);         // closed needs 3
  EXPECT_EQ(run(vol + " --points \"3,3;9,9\" --mask m.nii.gz" + out), 2);  // mask needs closed
  EXPECT_EQ(run(vol + " --points \"3,3;9,9\" --cost canny" + out), 2);
  EXPECT_FALSE(fs::exists(dir / "x.json"));
}

TEST_F(CmdLiveWire, DataErrorsExitWith1) {
  const std::string out = " --out " + (dir / "x.json").string();
  EXPECT_EQ(run((dir / "missing.nii.gz").string() + " --points \"3,3;9,9\"" + out), 1);
  // NaN voxels: a DataError naming the slice (exit 1) - if the reader keeps them. (The NIfTI
  // reader may replace non-finite voxels on load; then the slice is finite and the run succeeds.)
  const bool keepsNaN = valueRange(readVolume((dir / "nan.nii.gz").string())).nonFinite > 0;
  if (keepsNaN) {
    EXPECT_EQ(run((dir / "nan.nii.gz").string() + " --slice z=3 --points \"3,3;9,9\"" + out), 1);
    EXPECT_NE(text("stderr.txt").find("slice z=3"), std::string::npos) << text("stderr.txt");
  } else {
    EXPECT_EQ(run((dir / "nan.nii.gz").string() + " --slice z=3 --points \"3,3;9,9\"" + out), 0) << text("stderr.txt");
  }
  EXPECT_EQ(run((dir / "nan.nii.gz").string() + " --slice z=2 --points \"3,3;9,9\"" + out),
            0);  // other slices are fine
  EXPECT_FALSE(fs::exists(dir / "nope" / "x.json"));
}

TEST_F(CmdLiveWire, WorldPointsEqualPixelPoints) {
  // The same four clicks as pixels on z=2 and as world mm (from the file's own geometry).
  const Geometry g = geometryOf(readVolume(vol));
  std::string world;
  for (const auto& uv : {std::array<double, 2>{32, 17}, {47, 32}, {32, 47}, {17, 32}}) {
    const Vec3 w = g.indexToWorld(Vec3(uv[0], uv[1], 2));
    world += std::to_string(w.x()) + "," + std::to_string(w.y()) + "," + std::to_string(w.z()) + ";";
  }
  const std::string a = (dir / "a.json").string(), b = (dir / "b.json").string();
  ASSERT_EQ(run(vol + " --slice z=2 --points \"32,17;47,32;32,47;17,32\" --closed --out " + a), 0)
      << text("stderr.txt");
  // No --slice: the axial slice through the first world point.
  ASSERT_EQ(run(vol + " --world --points \"" + world + "\" --closed --out " + b), 0) << text("stderr.txt");
  const auto ja = nlohmann::json::parse(text("a.json")), jb = nlohmann::json::parse(text("b.json"));
  EXPECT_EQ(jb["slice"]["index"], 2);
  EXPECT_EQ(ja["points"], jb["points"]);
  // A world point one slice away (2 mm along z) is not on the slice: usage error naming it.
  const Vec3 off = g.indexToWorld(Vec3(40, 40, 3));
  const std::string bad =
      world + std::to_string(off.x()) + "," + std::to_string(off.y()) + "," + std::to_string(off.z());
  EXPECT_EQ(run(vol + " --slice z=2 --world --points \"" + bad + "\" --out " + b), 2);
  EXPECT_NE(text("stderr.txt").find("not on slice z=2"), std::string::npos) << text("stderr.txt");
  EXPECT_EQ(run(vol + " --world --points \"1,2;3,4\" --out " + b), 2);
}
