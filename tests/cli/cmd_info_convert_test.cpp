// `volscissors info` and `volscissors convert` through the real binary (VS_CLI_PATH):
// exit status 0 / 1 (data or I/O error) / 2 (usage error), the --json report, and
// `info` on one file of every shared data set.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "io/io_test_util.h"
#include "io/volume_io.h"

using namespace vs;
using namespace vs::test;

namespace {

struct CliRun {
  int status = -1;
  std::string out;
};

// Runs the CLI with arguments (already quoted), capturing stdout+stderr.
CliRun cli(const std::string& args) {
  const std::string cmd = std::string("'") + VS_CLI_PATH + "' " + args + " 2>&1";
  CliRun r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

std::string q(const std::string& s) { return "'" + s + "'"; }

}  // namespace

TEST(CliIo, InfoJsonHasTheAgreedKeys) {
  TempDir dir("cliinfo");
  const Geometry g = testGeometry({6, 5, 4});
  VolumeI16 v = rampVolume<int16_t>(g);
  writeVolume(AnyVolume(v), dir.file("v.nrrd"));
  const CliRun r = cli("info " + q(dir.file("v.nrrd")) + " --json " + q(dir.file("r.json")));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("6 x 5 x 4"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(readBytes(dir.file("r.json")));
  EXPECT_EQ(j.at("dims"), nlohmann::json({6, 5, 4}));
  EXPECT_EQ(j.at("type"), "int16");
  EXPECT_EQ(j.at("bytes"), 6 * 5 * 4 * 2);
  ASSERT_EQ(j.at("direction").size(), 9u);
  for (int r2 = 0; r2 < 3; ++r2)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(j["direction"][static_cast<size_t>(3 * r2 + c)].get<double>(), g.direction(r2, c), 1e-9);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(j["spacing"][static_cast<size_t>(i)].get<double>(), g.spacing[i], 1e-9);
    EXPECT_NEAR(j["origin"][static_cast<size_t>(i)].get<double>(), g.origin[i], 1e-9);
  }
  const ValueRange vr = valueRange(AnyVolume(v));
  EXPECT_EQ(j.at("range"), nlohmann::json({vr.min, vr.max}));
  EXPECT_EQ(j.at("format"), "nrrd");
  EXPECT_TRUE(j.at("notes").is_array());
}

TEST(CliIo, InfoReportsNaNVoxels) {
  TempDir dir("clinan");
  VolumeF32 v(testGeometry({3, 3, 3}), 2.0f);
  v(0, 1, 2) = std::nanf("");
  writeVolume(AnyVolume(v), dir.file("n.mha"));
  const CliRun r = cli("info " + q(dir.file("n.mha")) + " --json " + q(dir.file("n.json")));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("1 NaN/inf"), std::string::npos) << r.out;
  EXPECT_EQ(nlohmann::json::parse(readBytes(dir.file("n.json"))).at("non_finite"), 1);
}

TEST(CliIo, ExitStatusForDataAndUsageErrors) {
  TempDir dir("cliexit");
  EXPECT_EQ(cli("info " + q(dir.file("missing.nii"))).status, 1);
  writeBytes(dir.file("bad.nii"), std::string(400, 'z'));
  const CliRun bad = cli("info " + q(dir.file("bad.nii")));
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.out.find("bad.nii"), std::string::npos) << bad.out;
  EXPECT_EQ(cli("info").status, 2);                       // missing argument
  EXPECT_EQ(cli("info a b c --no-such-flag").status, 2);  // unknown option
  EXPECT_EQ(cli("info --help").status, 0);
  EXPECT_EQ(cli("convert --help").status, 0);
  writeVolume(AnyVolume(VolumeU8(testGeometry({2, 2, 2}), 3)), dir.file("ok.nii.gz"));
  EXPECT_EQ(cli("convert " + q(dir.file("ok.nii.gz")) + " " + q(dir.file("out.png"))).status,
            2);  // not a volume format
  EXPECT_EQ(cli("convert " + q(dir.file("ok.nii.gz"))).status, 2);
  EXPECT_EQ(cli("convert " + q(dir.file("ok.nii.gz")) + " " + q(dir.file("no/such/dir/out.nrrd"))).status, 1);
  EXPECT_EQ(cli("convert " + q(dir.file("missing.nii")) + " " + q(dir.file("out.nrrd"))).status, 1);
  EXPECT_FALSE(fs::exists(dir.file("out.nrrd")));
  EXPECT_EQ(cli("info " + q(dir.file("ok.nii.gz")) + " --json " + q(dir.file("nodir/x.json"))).status, 1);
}

TEST(CliIo, ConvertKeepsGeometryAndVoxels) {
  TempDir dir("cliconv");
  const Geometry g = testGeometry({7, 3, 2});
  const VolumeU16 v = rampVolume<uint16_t>(g);
  writeVolume(AnyVolume(v), dir.file("in.mha"));
  for (const std::string ext : {".nii.gz", ".nrrd", ".nhdr", ".mhd", ".nii"}) {
    const CliRun r = cli("convert " + q(dir.file("in.mha")) + " " + q(dir.file("out" + ext)));
    ASSERT_EQ(r.status, 0) << r.out;
    const AnyVolume back = readVolume(dir.file("out" + ext));
    ASSERT_EQ(voxelType(back), VoxelType::UInt16) << ext;
    expectSameGeometry(geometryOf(back), g);
    EXPECT_EQ(std::get<VolumeU16>(back).voxels(), v.voxels()) << ext;
  }
}

TEST(CliIo, InfoOnEverySharedDataSet) {
  const std::string root = sharedData();
  if (!fs::exists(root)) GTEST_SKIP() << "shared data missing: " << root;
  const char* files[] = {"chest_cta_totalseg/ct_cropped.nii.gz",
                         "chest_ct_lidc2/LIDC2.mha",
                         "head_cta_avm/AVM.nii.gz",
                         "head_3dra_aneurism/aneurism.vti",
                         "neck_mra_carotid_vtk/carotid.vtk",
                         "abdomen_mra_aorta_vmtk/aorta.mha",
                         "head_ct_cranium_invesalius/cranium.nhdr",
                         "head_ct_headsq_vtk/quarter.nhdr",
                         "head_mr_t1_face/chris_t1.nii.gz",
                         "head_mr_seg3d/MR.nii.gz",
                         "head_mr_small_vtk/HeadMRVolume.mhd",
                         "engine_ct_scivis/engine.nii.gz",
                         "abdomen_ct_dicom_j2k_totalseg/example_ct_dicom"};
  TempDir dir("clidata");
  size_t checked = 0;
  for (const char* f : files) {
    const std::string path = root + "/" + f;
    if (!fs::exists(path)) {
      ADD_FAILURE() << "data set file missing from an existing shared folder: " << path;
      continue;
    }
    const CliRun r = cli("info " + q(path) + " --json " + q(dir.file("i.json")));
    EXPECT_EQ(r.status, 0) << f << ": " << r.out;
    const auto j = nlohmann::json::parse(readBytes(dir.file("i.json")));
    EXPECT_EQ(j.at("dims").size(), 3u);
    EXPECT_GT(j.at("bytes").get<int64_t>(), 0);
    ++checked;
  }
  // The DICOM .tar.gz data set: unpack and run on the folder.
  const std::string tgz = root + "/chest_ct_4dct_dicom/chest_ct_4dct_dicom_00.tar.gz";
  if (fs::exists(tgz) && std::system(("tar xzf " + q(tgz) + " -C " + q(dir.path.string())).c_str()) == 0) {
    const CliRun r = cli("info " + q((dir.path / "chest_ct_4dct_dicom_00").string()));
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("512 x 512 x 141"), std::string::npos) << r.out;
    ++checked;
  } else {
    ADD_FAILURE() << "could not unpack " << tgz;
  }
  EXPECT_EQ(checked, 14u);
}
