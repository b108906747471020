// `volscissors measure` and `trace --measure` on the vessel phantom: outputs written together,
// CSV and JSON schema, SWC radii from the cross-sections; a tree of another volume is exit 1
// with nothing written.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"

namespace fs = std::filesystem;

namespace {

using Result = vs::testing::CliResult;
Result run(const std::string& args) { return vs::testing::runCli(args); }

class MeasureCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("vs_measure_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    Result r = run("phantom vessels --size 64,64,64 --seed 5 --out " + p("v.nii.gz") + " --truth " + p("v.json"));
    ASSERT_EQ(r.status, 0) << r.output;
    r = run("phantom vessels --size 24,24,24 --seed 6 --out " + p("other.nii.gz") + " --truth " + p("other.json"));
    ASSERT_EQ(r.status, 0) << r.output;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string p(const std::string& name) { return (dir_ / name).string(); }
  static fs::path dir_;
};
fs::path MeasureCli::dir_;

TEST_F(MeasureCli, TraceMeasureThenMeasureTheSavedTree) {
  Result r = run("trace " + p("v.nii.gz") + " --targets-file " + p("v.json") + " --out " + p("t.swc") + " --json " +
                 p("t.json") + " --measure " + p("t.csv"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("measure: bright lumen"), std::string::npos) << r.output;
  std::ifstream jf(p("t.json"));
  const nlohmann::json j = nlohmann::json::parse(jf);
  ASSERT_TRUE(j.contains("measure"));
  EXPECT_GT(j["measure"]["sections"]["measured"].get<int>(), 10);
  EXPECT_FALSE(j["measure"]["paths"].empty());
  EXPECT_TRUE(j["seconds"].contains("measure"));
  std::ifstream cf(p("t.csv"));
  std::string header;
  std::getline(cf, header);
  EXPECT_EQ(header.rfind("path,segment,arc_mm,segment_arc_mm,x_mm,y_mm,z_mm,area_mm2,eq_diameter_mm", 0), 0u);

  r = run("measure " + p("t.swc") + " " + p("v.nii.gz") + " --csv " + p("m.csv") + " --json " + p("m.json") +
          " --out " + p("m.swc"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(p("m.csv")) && fs::exists(p("m.json")) && fs::exists(p("m.swc")));
  std::ifstream mf(p("m.json"));
  const nlohmann::json m = nlohmann::json::parse(mf);
  EXPECT_EQ(m["measure"]["polarity"], "bright");
  EXPECT_FALSE(m["measure"]["segments"].empty());

  // The measured tree coloured by diameter, with its colour bar; the range in the report.
  r = run("render " + p("v.nii.gz") + " --overlay " + p("m.swc") + " --color-by diameter --size 160x160 --out " +
          p("c.png") + " --json " + p("c.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream cj(p("c.json"));
  const nlohmann::json c = nlohmann::json::parse(cj);
  EXPECT_EQ(c["color_by"]["quantity"], "diameter_mm");
  EXPECT_LT(c["color_by"]["min"].get<double>(), c["color_by"]["max"].get<double>());
  r = run("render " + p("v.nii.gz") + " --color-by diameter --out " + p("none.png"));
  EXPECT_EQ(r.status, 2) << r.output;  // nothing to colour
  EXPECT_FALSE(fs::exists(p("none.png")));

  const Result help = run("measure --help");
  EXPECT_NE(help.output.find("0.5"), std::string::npos) << help.output;  // --step default shown
}

TEST_F(MeasureCli, TreeOfAnotherVolumeIsExit1AndWritesNothing) {
  Result r = run("trace " + p("v.nii.gz") + " --targets-file " + p("v.json") + " --out " + p("mine.swc"));
  ASSERT_EQ(r.status, 0) << r.output;
  r = run("measure " + p("mine.swc") + " " + p("other.nii.gz") + " --csv " + p("bad.csv") + " --json " + p("bad.json"));
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("does not belong"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(p("bad.csv")));
  EXPECT_FALSE(fs::exists(p("bad.json")));
  r = run("measure " + p("missing.swc") + " " + p("v.nii.gz"));
  EXPECT_EQ(r.status, 1) << r.output;
  r = run("measure " + p("mine.swc") + " " + p("v.nii.gz") + " --polarity purple");
  EXPECT_EQ(r.status, 2) << r.output;
}

}  // namespace
