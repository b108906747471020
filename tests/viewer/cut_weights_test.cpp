// The cut's weights in the viewer (issue 26): the core's defaults (CutOptions{}, those of
// `volscissors cut` and `vs.cut`), set by the script's `cut-weights`, checked by the core, kept in
// the session; a changed weight changes the viewer's cut labels, and the labels equal the CLI's
// `cut` with the same weights voxel for voxel.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/script.h"
#include "app/viewer_app.h"
#include "cutting/cut.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"

namespace fs = std::filesystem;
using namespace vs;
using namespace vs::viewer;

namespace {

class CutWeightsTest : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() / ("vs_viewer_cutw_" + std::to_string(::getpid()));
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  int cli(const std::string& args) {
    const std::string cmd = std::string(VS_CLI_PATH) + " -q " + args + " > /dev/null 2> " + path("stderr.txt");
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  static void script(ViewerApp& app, const std::string& s) {
    std::istringstream in(s);
    runScript(app, in, nullptr, "test");
  }
  static std::vector<uint8_t> read(const std::string& p) {
    const AnyVolume v = readVolume(p);
    return std::get<VolumeU8>(v).voxels();
  }
};

// The head phantom's nose (the cutting module's loop at the nose's base), its points as voxels.
struct Nose {
  std::string volume, points, commands;  // CLI --points, script `point` lines
};

Nose nose(const std::string& file) {
  HeadPhantomOptions ho;
  ho.dims = {64, 64, 48};
  ho.spacing = Vec3(2, 2, 2.5);
  const HeadPhantom ph = makeHeadPhantom(ho);
  writeVolume(AnyVolume(ph.volume), file);
  Nose n{file, "", ""};
  Index3 last{-1, -1, -1};
  for (const Vec3& q : noseBaseLoopMm(ph.truth)) {
    const Index3 v = roundIndex(ph.volume.geometry().worldToIndex(q));
    if (v == last) continue;
    last = v;
    const std::string p = std::to_string(v[0]) + "," + std::to_string(v[1]) + "," + std::to_string(v[2]);
    n.points += (n.points.empty() ? "" : ";") + p;
    n.commands += "point " + p + "\n";
  }
  return n;
}

size_t differing(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  size_t n = 0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) n += a[i] != b[i];
  return n;
}

}  // namespace

TEST_F(CutWeightsTest, DefaultsAreTheCoresAndTheScriptChecksThem) {
  const CutOptions core;
  ViewerApp app;
  const CutWeights w = app.cut().weights();
  EXPECT_EQ(w, defaultCutWeights());
  EXPECT_EQ(w.wg, core.surface.wg);
  EXPECT_EQ(w.wc, core.surface.wc);
  EXPECT_EQ(w.wp, core.surface.wp);
  EXPECT_EQ(w.wd, core.surface.wd);
  EXPECT_EQ(w.contourWg, core.cost.wg);
  EXPECT_EQ(w.contourWn, core.cost.wn);
  EXPECT_EQ(w.contourWl, core.cost.wl);
  script(app, "cut-weights wg=3 contour-wl=0.5\n");
  EXPECT_EQ(app.cut().weights().wg, 3);
  EXPECT_EQ(app.cut().weights().contourWl, 0.5);
  EXPECT_EQ(app.cut().weights().wc, core.surface.wc) << "the weights not named stay";
  // The core's check (checkCutWeights), nothing changed on a refusal; bad keys are usage errors.
  for (const char* bad : {"cut-weights wc=0\n", "cut-weights wd=1.5\n", "cut-weights wg=-1\n", "cut-weights wg=x\n",
                          "cut-weights foo=1\n", "cut-weights wg\n", "cut-weights\n"}) {
    const CutWeights before = app.cut().weights();
    EXPECT_THROW(script(app, bad), ScriptError) << bad;
    EXPECT_EQ(app.cut().weights(), before) << bad;
  }
  try {
    script(app, "cut-weights wc=0\n");
  } catch (const ScriptError& e) {
    EXPECT_NE(std::string(e.what()).find("w_c"), std::string::npos) << e.what();
  }
  script(app, "cut-weights defaults\n");
  EXPECT_EQ(app.cut().weights(), defaultCutWeights());
}

TEST_F(CutWeightsTest, AWeightChangesTheLabelsAsTheCli) {
  const Nose n = nose(path("head.nii.gz"));
  ViewerApp app;
  app.loadHeadPhantom(32);  // its transfer function (ct-skin) stays for the loaded head: the skin's iso
  script(app, "load " + n.volume + "\ntool cut\n" + n.commands + "run\nsave " + path("v_default.nii.gz") + "\n");
  char iso[64];  // the viewer's iso-value (from its transfer function), given to the CLI
  std::snprintf(iso, sizeof iso, "%.17g", app.cut().iso());
  // One weight of the cutting surface (eq. 15's image term) and one of the contour (eq. 13's length),
  // each against the CLI with the same weight.
  size_t diff[2] = {0, 0};
  const char* viewerArgs[2] = {"wg=20", "contour-wl=5"};
  const char* cliArgs[2] = {"--wg 20", "--contour-wl 5"};
  for (int k = 0; k < 2; ++k) {
    const std::string v = path("v" + std::to_string(k) + ".nii.gz"), c = path("c" + std::to_string(k) + ".nii.gz");
    script(app, std::string("cut-weights defaults\ncut-weights ") + viewerArgs[k] + "\nrun\nsave " + v + "\n");
    ASSERT_EQ(
        cli("cut " + n.volume + " --iso " + iso + " --points '" + n.points + "' " + cliArgs[k] + " --labels " + c), 0)
        << path("stderr.txt");
    const auto def = read(path("v_default.nii.gz")), changed = read(v);
    diff[k] = differing(def, changed);
    EXPECT_GT(diff[k], 0u) << viewerArgs[k] << " changes the viewer's cut";
    EXPECT_EQ(changed, read(c)) << "the viewer's cut with " << viewerArgs[k] << " equals `volscissors cut "
                                << cliArgs[k] << "`";
  }
  std::cout << "[ measured ] labels differing from the default weights' cut: wg=20 " << diff[0]
            << " voxels, contour-wl=5 " << diff[1] << " voxels\n";
  const std::vector<uint8_t> changed = read(path("v1.nii.gz"));
  // The session keeps the weights: a reopened session recomputes the same cut.
  app.saveSession(path("s.json"));
  ViewerApp b;
  b.loadSession(path("s.json"));
  EXPECT_EQ(b.cut().weights(), app.cut().weights());
  ASSERT_TRUE(b.cut().hasResult());
  EXPECT_EQ(b.cut().result()->labels.voxels(), changed);
}
