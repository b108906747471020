// The command line as a user meets it: progress on a terminal only, error prefixes, refused
// picture types, orientation reports, and a contour clicked on a slice picture landing where
// it was clicked.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "io/png_io.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"

namespace fs = std::filesystem;
using namespace vs;

namespace {

struct CliRun {
  int status;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

class Cli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("vs_cli_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    // A head phantom (face at index y = 0, anterior in LPS) re-stored "RAS": index x runs to
    // the patient's right, y to anterior; every voxel keeps its world position, so the
    // radiological picture is the storage order flipped left-right and top-bottom.
    HeadPhantomOptions ho;
    ho.dims = {48, 56, 40};
    ho.seed = 2;
    HeadPhantom head = makeHeadPhantom(ho);
    const Geometry& lps = head.volume.geometry();
    Geometry g = lps;
    g.direction = Mat3::Identity();
    g.direction(0, 0) = -1;
    g.direction(1, 1) = -1;
    g.origin = lps.indexToWorld(Vec3(47, 55, 0));
    VolumeI16 ras(g);
    for (int64_t z = 0; z < 40; ++z)
      for (int64_t y = 0; y < 56; ++y)
        for (int64_t x = 0; x < 48; ++x) ras(x, y, z) = head.volume(47 - x, 55 - y, z);
    writeVolume(AnyVolume(ras), p("ras.nrrd"));
    noseBoxMin_ = head.truth.noseBoxMin;
    noseBoxMax_ = head.truth.noseBoxMax;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string p(const std::string& name) { return (dir_ / name).string(); }

  // stdout and stderr apart, stdin closed.
  static CliRun run(const std::string& args) {
    const std::string cmd =
        std::string(VS_CLI_PATH) + " " + args + " > " + p("stdout.txt") + " 2> " + p("stderr.txt") + " < /dev/null";
    const int rc = std::system(cmd.c_str());
    return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(p("stdout.txt")), slurp(p("stderr.txt"))};
  }
  // Under a pseudo-terminal (util-linux `script`): what a user at a terminal sees.
  static CliRun runOnTerminal(const std::string& args) {
    const std::string cmd = "script -qefc '" + std::string(VS_CLI_PATH) + " " + args + "' /dev/null > " + p("tty.txt") +
                            " 2>&1 < /dev/null";
    const int rc = std::system(cmd.c_str());
    return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(p("tty.txt")), {}};
  }
  static fs::path dir_;
  static Index3 noseBoxMin_, noseBoxMax_;
};
fs::path Cli::dir_;
Index3 Cli::noseBoxMin_, Cli::noseBoxMax_;

}  // namespace

TEST_F(Cli, ProgressLineOnATerminalOnly) {
  if (std::system("script -qefc true /dev/null > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "util-linux `script` not available";
  const std::string args = "render " + p("ras.nrrd") + " --size 48x48 --out " + p("pr.png");
  const CliRun tty = runOnTerminal(args);
  ASSERT_EQ(tty.status, 0) << tty.out;
  EXPECT_NE(tty.out.find("render: "), std::string::npos) << tty.out;
  EXPECT_NE(tty.out.find('%'), std::string::npos) << tty.out;
  EXPECT_NE(tty.out.find("\r\033[K"), std::string::npos) << tty.out;  // the line is redrawn and erased
  // In a pipe or file: no progress line, only the final note.
  const CliRun pipe = run(args);
  ASSERT_EQ(pipe.status, 0) << pipe.err;
  EXPECT_EQ(pipe.err.find('%'), std::string::npos) << pipe.err;
  EXPECT_EQ(pipe.err.find('\r'), std::string::npos) << pipe.err;
  // --quiet, before or after the command name: nothing but errors, even on a terminal.
  for (const std::string& q : {"-q " + args, args + " --quiet"}) {
    const CliRun quiet = runOnTerminal(q);
    ASSERT_EQ(quiet.status, 0) << quiet.out;
    EXPECT_EQ(quiet.out.find("render"), std::string::npos) << q << ": " << quiet.out;
  }
}

TEST_F(Cli, ParseErrorsAndUnsupportedOutputsAreUsageErrors) {
  CliRun r = run("render " + p("ras.nrrd") + " --bogus --out " + p("x.png"));
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("volscissors: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("render --help"), std::string::npos) << r.err;
  r = run("livewire");  // missing required options
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("volscissors: error: ", 0), 0u) << r.err;
  // No PNG bytes in a .jpg: refused before any work, no file written.
  for (const char* ext : {".jpg", ".jpeg", ".tif", ""}) {
    const std::string out = p(std::string("pic") + ext);
    r = run("render " + p("ras.nrrd") + " --mode slice --out " + out);
    EXPECT_EQ(r.status, 2) << ext << ": " << r.err;
    EXPECT_NE(r.err.find(".png"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << out;
  }
  r = run("render " + p("ras.nrrd") + " --ticks --out " + p("x.png"));  // slice-only option in a 3D mode
  EXPECT_EQ(r.status, 2) << r.err;
}

TEST_F(Cli, InfoReportsTheOrientationAndWarnsWhenTheHeaderHasNone) {
  CliRun r = run("info " + p("ras.nrrd") + " --json " + p("info.json"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("orientation: RAS"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(slurp(p("info.json")));
  EXPECT_EQ(j["orientation"], "RAS");
  EXPECT_EQ(j["orientation_in_header"], true);
  // The same data in a NRRD without a space field: ITK assumes identity; info says so.
  std::ofstream(p("nospace.nhdr")) << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 3 2\nspacings: 1 1 1\n"
                                      "encoding: raw\ndata file: nospace.raw\n\n";
  std::ofstream(p("nospace.raw"), std::ios::binary) << std::string(24, '\x07');
  r = run("info " + p("nospace.nhdr") + " --json " + p("info2.json"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("states no orientation"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("NOT in the header"), std::string::npos) << r.out;
  EXPECT_EQ(nlohmann::json::parse(slurp(p("info2.json")))["orientation_in_header"], false);
}

// Picture -> command: a slice picture at one pixel per voxel, its mapping in the report, and a
// contour clicked on it with `livewire --picture` passes through the clicked pixels.
TEST_F(Cli, ContourClickedOnASlicePictureLandsWhereItWasClicked) {
  const int64_t z = (noseBoxMin_[2] + noseBoxMax_[2]) / 2;
  const std::string plane = "z=" + std::to_string(z);
  CliRun r = run("render " + p("ras.nrrd") + " --mode slice --plane " + plane +
                 " --voxel-pixels --ticks --letters --json " + p("slice.json") + " --out " + p("slice.png"));
  ASSERT_EQ(r.status, 0) << r.err;
  const RgbaImage pic = readPng(p("slice.png"));
  EXPECT_EQ(pic.width, 48);
  EXPECT_EQ(pic.height, 56);
  const auto rep = nlohmann::json::parse(slurp(p("slice.json")));
  EXPECT_EQ(rep["slice"]["plane"], "axial");
  EXPECT_EQ(rep["edges"]["left"], "R");
  EXPECT_EQ(rep["edges"]["top"], "A");
  EXPECT_EQ(rep["orientation"], "RAS");
  // RAS storage: picture column c is index x = 47 - c, row r is index y = 55 - r.
  auto mapped = [&](double c, double rr) {
    Vec3 v;
    for (int k = 0; k < 3; ++k)
      v[k] = rep["pixel_to_index"]["origin"][k].get<double>() +
             c * rep["pixel_to_index"]["per_column"][k].get<double>() +
             rr * rep["pixel_to_index"]["per_row"][k].get<double>();
    return v;
  };
  EXPECT_EQ(mapped(0, 0), Vec3(47, 55, double(z)));
  EXPECT_EQ(mapped(10, 20), Vec3(37, 35, double(z)));
  // Anterior up: the nose (index y near 55 here, since index y points anterior) is at the top.
  int firstTissueRow = -1;
  for (int y = 10; y < pic.height && firstTissueRow < 0; ++y)  // below the ticks
    if (pic.at(pic.width / 2, y)[0] > 120) firstTissueRow = y;
  EXPECT_GE(firstTissueRow, 0);
  EXPECT_LT(firstTissueRow, pic.height / 4);

  // Four clicks on the picture, the contour through them, back on the picture.
  const std::vector<std::array<int, 2>> clicks{{24, 12}, {36, 28}, {24, 44}, {12, 28}};
  std::string pts;
  for (const auto& c : clicks) pts += std::to_string(c[0]) + "," + std::to_string(c[1]) + ";";
  r = run("livewire " + p("ras.nrrd") + " --slice " + plane + " --picture --points \"" + pts + "\" --closed --out " +
          p("c.json"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto c = nlohmann::json::parse(slurp(p("c.json")));
  EXPECT_EQ(c["plane"], "axial");
  const auto& pp = c["points_picture"];
  ASSERT_EQ(pp.size(), c["points_index"].size());
  for (const auto& click : clicks) {
    bool found = false;
    for (const auto& q : pp) found = found || (q[0].get<double>() == click[0] && q[1].get<double>() == click[1]);
    EXPECT_TRUE(found) << "click " << click[0] << "," << click[1] << " is not on the contour";
  }
  for (size_t i = 0; i < pp.size(); ++i) {  // picture and index agree with the render report
    const Vec3 m = mapped(pp[i][0].get<double>(), pp[i][1].get<double>());
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m[k], c["points_index"][i][static_cast<size_t>(k)].get<double>());
  }
  // The same clicks as voxel indices give the same contour; one off the plane says so.
  std::string idx;
  for (const auto& cl : clicks) {
    const Vec3 v = mapped(cl[0], cl[1]);
    idx += std::to_string(int(v.x())) + "," + std::to_string(int(v.y())) + "," + std::to_string(int(v.z())) + ";";
  }
  r = run("livewire " + p("ras.nrrd") + " --slice " + plane + " --points \"" + idx + "\" --closed --out " +
          p("c2.json"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(p("c2.json")))["points_index"], c["points_index"]);
  r = run("livewire " + p("ras.nrrd") + " --slice " + plane + " --points \"10,10," + std::to_string(z) + ";20,20," +
          std::to_string(z + 3) + "\" --out " + p("c3.json"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("not on slice " + plane + " (axial)"), std::string::npos) << r.err;
  r = run("livewire " + p("ras.nrrd") + " --slice " + plane + " --picture --points \"5,5;60,5\" --out " + p("c3.json"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("picture pixel (60,5)"), std::string::npos) << r.err;
}

TEST_F(Cli, LivewireCostOptionsAreHonouredOrRefused) {
  const std::string base = "livewire " + p("ras.nrrd") + " --slice z=20 --points \"10,10;30,25\" --out " + p("w.json");
  CliRun r = run(base + " --cost gradient --weights 0.5 0.3 0.2");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--weights"), std::string::npos) << r.err;
  r = run(base + " --cost gradient");
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(slurp(p("w.json")));
  EXPECT_FALSE(j.contains("weights"));
  EXPECT_EQ(j["cost_kind"], "gradient");
  r = run(base + " --weights 0.2 0.6 0.2 --connectivity 4 --gradient-quantile 0.95");
  ASSERT_EQ(r.status, 0) << r.err;
  j = nlohmann::json::parse(slurp(p("w.json")));
  EXPECT_EQ(j["weights"]["gradient"], 0.6);
  EXPECT_EQ(j["connectivity"], 4);
  EXPECT_EQ(j["gradient_quantile"], 0.95);
  const auto& pts = j["points"];
  for (size_t i = 1; i < pts.size(); ++i) {  // 4-connected: one axis step at a time
    const int64_t du = std::abs(pts[i][0].get<int64_t>() - pts[i - 1][0].get<int64_t>());
    const int64_t dv = std::abs(pts[i][1].get<int64_t>() - pts[i - 1][1].get<int64_t>());
    EXPECT_EQ(du + dv, 1) << i;
  }
  EXPECT_EQ(run(base + " --connectivity 6").status, 2);
  EXPECT_EQ(run(base + " --gradient-quantile 0").status, 2);
  EXPECT_EQ(run(base + " --weights 1 2").status, 2);
}
