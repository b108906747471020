// CLI conventions for `volscissors phantom`: exit 0 / 2 (usage) / 1 (I/O), atomic outputs.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/volume_io.h"
#include "phantom/head_family.h"
#include "phantom/phantom.h"

using namespace vs;
namespace fs = std::filesystem;

namespace {

int runCli(const std::string& args) {
  const std::string cmd = std::string(VS_CLI_PATH) + " " + args + " >/dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class PhantomCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("vs_phantom_cli_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string p(const std::string& name) const { return (dir / name).string(); }
  size_t fileCount() const {
    return static_cast<size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
  }
  fs::path dir;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST_F(PhantomCli, VesselsWritesVolumeAndTruthMatchingTheCoreApi) {
  ASSERT_EQ(runCli("phantom vessels --seed 9 --size 48,40,32 --spacing 1,1,1.5 --noise 5 --out " + p("v.mha") +
                   " --truth " + p("v.json")),
            0);
  const AnyVolume vol = readVolume(p("v.mha"));
  ASSERT_EQ(voxelType(vol), VoxelType::UInt8);
  const auto& got = std::get<VolumeU8>(vol);
  EXPECT_EQ(got.dims(), (Index3{48, 40, 32}));
  EXPECT_NEAR(got.geometry().spacing[2], 1.5, 1e-6);
  VesselPhantomOptions o;
  o.seed = 9;
  o.dims = {48, 40, 32};
  o.spacing = Vec3(1, 1, 1.5);
  o.noiseSigma = 5;
  const auto ref = makeVesselPhantom(o);
  EXPECT_EQ(got.voxels(), ref.volume.voxels());
  const VesselTruth t = readVesselTruth(p("v.json"));
  EXPECT_EQ(t.terminalVoxels, ref.truth.terminalVoxels);
  EXPECT_EQ(t.seed, 9u);
}

TEST_F(PhantomCli, SameSeedSameBytes) {
  ASSERT_EQ(runCli("phantom vessels --size 32,32,32 --out " + p("a.mha") + " --truth " + p("a.json")), 0);
  ASSERT_EQ(runCli("phantom vessels --size 32,32,32 --out " + p("b.mha") + " --truth " + p("b.json")), 0);
  ASSERT_EQ(runCli("phantom vessels --seed 2 --size 32,32,32 --out " + p("c.mha")), 0);
  EXPECT_EQ(slurp(p("a.mha")), slurp(p("b.mha")));
  EXPECT_EQ(slurp(p("a.json")), slurp(p("b.json")));
  EXPECT_NE(slurp(p("a.mha")), slurp(p("c.mha")));
}

TEST_F(PhantomCli, HeadAndShapes2D) {
  ASSERT_EQ(runCli("phantom head --size 40,40,40 --out " + p("h.nrrd") + " --truth " + p("h.json")), 0);
  const AnyVolume h = readVolume(p("h.nrrd"));
  EXPECT_EQ(voxelType(h), VoxelType::Int16);
  EXPECT_EQ(readHeadTruth(p("h.json")).isoSkin, -480.0);
  ASSERT_EQ(runCli("phantom shapes2d --size 96,80 --out " + p("s.mha") + " --truth " + p("s.json") + " --labels " +
                   p("l.mha")),
            0);
  const AnyVolume s = readVolume(p("s.mha"));
  EXPECT_EQ(geometryOf(s).dims, (Index3{96, 80, 1}));
  const AnyVolume l = readVolume(p("l.mha"));
  const auto ref = makeShapes2DPhantom([] {
    Shapes2DOptions o;
    o.width = 96;
    o.height = 80;
    return o;
  }());
  EXPECT_EQ(std::get<VolumeU8>(l).voxels(), ref.labels.voxels());
  EXPECT_EQ(readShapes2DTruth(p("s.json")).shapes.size(), 4u);
}

TEST_F(PhantomCli, UsageErrorsExitTwoAndWriteNothing) {
  const std::string out = " --out " + p("o.nii") + " --truth " + p("o.json");
  for (const char* size : {"0,32,32", "-4,32,32", "abc,32,32", "32,32", "32,32,32,32", "32,,32", "32.5,32,32",
                           "100000,100000,100000", "8192,8192,8192", "10,10,10"})
    EXPECT_EQ(runCli(std::string("phantom vessels --size ") + size + out), 2) << size;
  EXPECT_EQ(runCli("phantom blobs" + out), 2);
  EXPECT_EQ(runCli("phantom" + out), 2);
  EXPECT_EQ(runCli("phantom vessels --spacing 0,1,1" + out), 2);
  EXPECT_EQ(runCli("phantom vessels --spacing 1,x,1" + out), 2);
  EXPECT_EQ(runCli("phantom vessels --noise -1" + out), 2);
  EXPECT_EQ(runCli("phantom vessels --seed -3" + out), 2);
  EXPECT_EQ(runCli("phantom vessels --seed x" + out), 2);
  EXPECT_EQ(runCli("phantom shapes2d --size 64,64,2" + out), 2);
  EXPECT_EQ(runCli("phantom vessels --labels " + p("l.nii") + out), 2);
  EXPECT_EQ(runCli("phantom vessels --out " + p("o.png")), 2);
  EXPECT_EQ(runCli("phantom vessels --out " + p("o.nii") + " --truth " + p("o.nii")), 2);
  EXPECT_EQ(runCli("phantom vessels --truth " + p("o.json")), 2);  // --out missing
  EXPECT_EQ(fileCount(), 0u);
  EXPECT_EQ(runCli("phantom --help"), 0);
}

TEST_F(PhantomCli, MissingOutputDirectoryExitsOneWithoutPartialFiles) {
  EXPECT_EQ(runCli("phantom vessels --size 32,32,32 --out " + p("nodir/v.nii") + " --truth " + p("t.json")), 1);
  EXPECT_EQ(runCli("phantom vessels --size 32,32,32 --out " + p("v.mha") + " --truth " + p("nodir/t.json")), 1);
  EXPECT_EQ(runCli("phantom shapes2d --out " + p("s.nii") + " --labels " + p("nodir/l.nii")), 1);
  EXPECT_EQ(fileCount(), 0u);  // nothing written, no temporaries left
}

// The randomised head family for cutting (issue 26): the same volume and labels as the core's,
// the truth's nose loop usable as `cut --points`, and no size/spacing/noise options (drawn).
TEST_F(PhantomCli, HeadFamilyWritesVolumeLabelsAndLoops) {
  ASSERT_EQ(runCli("phantom head-family --seed 4 --out " + p("h.nrrd") + " --labels " + p("l.nrrd") + " --truth " +
                   p("h.json")),
            0);
  HeadFamilyOptions o;
  o.seed = 4;
  const HeadFamilyPhantom ref = makeHeadFamilyPhantom(o);
  EXPECT_EQ(std::get<VolumeI16>(readVolume(p("h.nrrd"))).voxels(), ref.volume.voxels());
  EXPECT_EQ(std::get<VolumeU8>(readVolume(p("l.nrrd"))).voxels(), ref.labels.voxels());
  const nlohmann::json j = nlohmann::json::parse(slurp(p("h.json")));
  EXPECT_EQ(j.at("kind"), "head-family");
  EXPECT_NEAR(j.at("iso").get<double>(), ref.truth.iso, 1e-9);
  for (const char* loop : {"nose", "ear", "forehead", "cheek"}) {
    EXPECT_EQ(j.at("loops").at(loop).at("points").size(), 12u) << loop;
    EXPECT_FALSE(j.at("loops").at(loop).at("cut_points").get<std::string>().empty()) << loop;
  }
  EXPECT_EQ(runCli("phantom head-family --seed 4 --size 10,10,10 --out " + p("x.nrrd")), 2);
  EXPECT_EQ(runCli("phantom head-family --seed 4 --noise 3 --out " + p("x.nrrd")), 2);
  EXPECT_FALSE(fs::exists(p("x.nrrd")));
}

// The vessel family (issue 21): the seed's variant as the core draws it; --size only for a seed
// that draws the thin tree (the other variants are sized to their geometry).
TEST_F(PhantomCli, VesselFamilyWritesTheSeedsVariantAndRefusesASizeItCannotUse) {
  uint64_t wide = 1;
  while (vesselFamilyVariantOf(wide) != VesselFamilyVariant::WideLumen) ++wide;
  uint64_t thin = 1;
  while (vesselFamilyVariantOf(thin) != VesselFamilyVariant::Thin) ++thin;
  ASSERT_EQ(runCli("phantom vessel-family --seed " + std::to_string(wide) + " --out " + p("w.nrrd")), 0);
  const VesselFamilyCase ref = makeVesselFamilyCase(wide);
  EXPECT_EQ(std::get<VolumeF32>(readVolume(p("w.nrrd"))).voxels(), ref.volume.voxels());
  EXPECT_EQ(runCli("phantom vessel-family --seed " + std::to_string(wide) + " --size 40,40,30 --out " + p("x.nrrd")),
            2);
  EXPECT_FALSE(fs::exists(p("x.nrrd")));
  ASSERT_EQ(runCli("phantom vessel-family --seed " + std::to_string(thin) + " --size 64,64,40 --out " + p("t.nrrd")),
            0);
  EXPECT_EQ(std::get<VolumeF32>(readVolume(p("t.nrrd"))).geometry().dims, (Index3{64, 64, 40}));
}
