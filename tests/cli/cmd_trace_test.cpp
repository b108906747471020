// `volscissors trace` end to end: outputs on the phantom, and every bad-input path with its
// exit status and message (no hang).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "io/volume_io.h"
#include "run_cli.h"
#include "volume/sample.h"

namespace fs = std::filesystem;

namespace {

using Result = vs::testing::CliResult;
Result run(const std::string& args) { return vs::testing::runCli(args); }

class TraceCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("vs_trace_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    const Result r = run("phantom vessels --size 48,48,48 --seed 3 --out " + (dir_ / "v.nii.gz").string() +
                         " --truth " + (dir_ / "v.json").string());
    ASSERT_EQ(r.status, 0) << r.output;
    // A given-cost volume with one negative (invalid) cost at (8,1,1). (Impassable +inf costs
    // are tested on the API: the NIfTI reader does not keep inf voxels.)
    vs::Geometry g;
    g.dims = {16, 8, 8};
    vs::VolumeF32 c(g, 1.0f);
    vs::writeVolume(vs::AnyVolume(c), (dir_ / "ones.nii.gz").string());
    c(8, 1, 1) = -1.0f;
    vs::writeVolume(vs::AnyVolume(c), (dir_ / "neg.nii.gz").string());
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string p(const std::string& name) { return (dir_ / name).string(); }
  static fs::path dir_;
};
fs::path TraceCli::dir_;

TEST_F(TraceCli, TracesThePhantomAndWritesEveryOutput) {
  const Result r =
      run("trace " + p("v.nii.gz") + " --targets-file " + p("v.json") + " --cost intensity --out " + p("t.swc") +
          " --json " + p("r.json") + " --labels " + p("lab.nii.gz") + " --vtk " + p("t.vtk") + " --full");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("graph:"), std::string::npos);
  std::ifstream f(p("r.json"));
  const nlohmann::json j = nlohmann::json::parse(f);
  std::ifstream t(p("v.json"));
  const nlohmann::json truth = nlohmann::json::parse(t);
  ASSERT_EQ(j["paths"].size(), truth["terminals"].size());
  for (const auto& path : j["paths"]) {
    EXPECT_TRUE(path["reached"].get<bool>());
    EXPECT_GT(path["length_mm"].get<double>(), 0);
    EXPECT_EQ(path["voxels"].front(), truth["root_voxel"]);
  }
  EXPECT_EQ(j["root"], truth["root_voxel"]);
  EXPECT_EQ(j["graph"]["nodes"].get<int64_t>(), 48 * 48 * 48);
  EXPECT_EQ(j["graph"]["settled"].get<int64_t>(), 48 * 48 * 48);  // --full
  for (const char* k : {"load", "features", "graph", "search"}) EXPECT_TRUE(j["seconds"].contains(k)) << k;
  EXPECT_TRUE(fs::file_size(p("t.swc")) > 100);
  EXPECT_TRUE(fs::file_size(p("t.vtk")) > 100);
  const vs::AnyVolume lab = vs::readVolume(p("lab.nii.gz"));
  EXPECT_EQ(vs::geometryOf(lab).dims, (vs::Index3{48, 48, 48}));
  EXPECT_GT(vs::valueRange(lab).max, 0);
}

TEST_F(TraceCli, AutoTerminalsPrunedGraphAndRoi) {
  std::ifstream t(p("v.json"));
  const nlohmann::json truth = nlohmann::json::parse(t);
  const auto r0 = truth["root_voxel"];
  const std::string root = std::to_string(r0[0].get<int>()) + "," + std::to_string(r0[1].get<int>()) + "," +
                           std::to_string(r0[2].get<int>());
  const Result r = run("trace " + p("v.nii.gz") + " --root " + root +
                       " --auto-terminals 4 --min-length 6 --cost intensity --prune isoregion --prune-on intensity "
                       "--threshold 100 --json " +
                       p("a.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream f(p("a.json"));
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_GE(j["paths"].size(), 2u);
  EXPECT_LT(j["graph"]["nodes"].get<int64_t>(), j["graph"]["voxels"].get<int64_t>());
  // ROI: coordinates stay in the full volume's index space (a target in the background: no snapping).
  const Result q = run("trace " + p("v.nii.gz") + " --root " + root + " --target " + root.substr(0, root.find(',')) +
                       ",0,0 --snap 0 --roi 0,0,0,47,47,47 --json " + p("roi.json"));
  EXPECT_EQ(q.status, 0) << q.output;
}

// --labels with --roi: the label volume has the whole volume's geometry, the path pasted at its
// place in it (it was once built on the cropped-away volume's empty geometry: exit 2).
TEST_F(TraceCli, LabelsOfAnRoiTraceCoverTheWholeVolume) {
  const Result r = run("trace " + p("ones.nii.gz") + " --cost given --root 2,2,2 --target 7,2,2 --roi 1,1,1,10,6,6 " +
                       "--labels " + p("roi_labels.nii.gz"));
  ASSERT_EQ(r.status, 0) << r.output;
  const vs::VolumeF32 labels = vs::toFloat(vs::readVolume(p("roi_labels.nii.gz")));
  EXPECT_EQ(labels.dims(), (vs::Index3{16, 8, 8}));
  for (int64_t x = 2; x <= 7; ++x) EXPECT_EQ(labels(x, 2, 2), 1.0f) << "path voxel x=" << x;
  double total = 0;
  for (float v : labels.voxels()) total += v;
  EXPECT_EQ(total, 6.0);  // the straight path's six voxels, nothing else
}

TEST_F(TraceCli, PruningOnTheCostFieldIsTheDefaultAndPrunesAWindowedCost) {
  std::ifstream t(p("v.json"));
  const nlohmann::json truth = nlohmann::json::parse(t);
  const auto r0 = truth["root_voxel"];
  const std::string root = std::to_string(r0[0].get<int>()) + "," + std::to_string(r0[1].get<int>()) + "," +
                           std::to_string(r0[2].get<int>());
  // Window 100..101 with no smoothing: everything below 100 (the whole background) has one cost.
  const std::string common = "trace " + p("v.nii.gz") + " --root " + root + " --targets-file " + p("v.json") +
                             " --cost intensity --window 100,101 --smooth 0 ";
  const Result full = run(common + "--json " + p("cf_full.json"));
  const Result cost = run(common + "--prune isoregion --json " + p("cf_cost.json"));
  const Result inten = run(common + "--prune isoregion --prune-on intensity --json " + p("cf_int.json"));
  ASSERT_EQ(full.status, 0) << full.output;
  ASSERT_EQ(cost.status, 0) << cost.output;
  ASSERT_EQ(inten.status, 0) << inten.output;
  EXPECT_NE(cost.output.find("prune isoregion on cost"), std::string::npos) << cost.output;
  auto load = [&](const std::string& f) {
    std::ifstream in(p(f));
    return nlohmann::json::parse(in);
  };
  const nlohmann::json jf = load("cf_full.json"), jc = load("cf_cost.json"), ji = load("cf_int.json");
  EXPECT_EQ(jc["graph"]["prune_on"], "cost");
  EXPECT_EQ(ji["graph"]["prune_on"], "intensity");
  const int64_t nc = jc["graph"]["nodes"].get<int64_t>(), ni = ji["graph"]["nodes"].get<int64_t>();
  std::printf("[cli prune-on] nodes: full %lld, intensity field %lld, cost field %lld\n",
              static_cast<long long>(jf["graph"]["nodes"].get<int64_t>()), static_cast<long long>(ni),
              static_cast<long long>(nc));
  EXPECT_LT(nc, ni / 2);  // the noisy background is flat in cost, not in intensity
  ASSERT_EQ(jc["paths"].size(), jf["paths"].size());
  for (size_t i = 0; i < jf["paths"].size(); ++i)
    EXPECT_GE(jc["paths"][i]["cost"].get<double>(), jf["paths"][i]["cost"].get<double>() * (1 - 1e-6)) << "path " << i;
}

TEST_F(TraceCli, WorldCoordinatesMapToTheSameVoxels) {
  const vs::AnyVolume v = vs::readVolume(p("ones.nii.gz"));
  const vs::Geometry g = vs::geometryOf(v);
  auto world = [&](double x, double y, double z) {
    const vs::Vec3 w = g.indexToWorld(vs::Vec3(x, y, z));
    return std::to_string(w[0]) + "," + std::to_string(w[1]) + "," + std::to_string(w[2]);
  };
  const Result r = run("trace " + p("ones.nii.gz") + " --cost given --world --root " + world(1, 1, 1) + " --target " +
                       world(6, 2, 1) + " --json " + p("w.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream f(p("w.json"));
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_EQ(j["root"], nlohmann::json::array({1, 1, 1}));
  EXPECT_EQ(j["paths"][0]["target"], nlohmann::json::array({6, 2, 1}));
  // Without --world, fractional coordinates are a usage error.
  EXPECT_EQ(run("trace " + p("ones.nii.gz") + " --cost given --root 1.5,1,1 --target 6,2,1").status, 2);
}

TEST_F(TraceCli, BadInputGivesClearErrors) {
  const std::string v = p("v.nii.gz");
  struct Case {
    std::string args;
    int status;
    std::string message;
  };
  const Case cases[] = {
      {"trace " + v + " --root 99,1,1 --target 2,2,2", 2, "outside the volume"},
      {"trace " + v + " --root 1,1,1 --target 2,2,200", 2, "outside the volume"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --target 3,3,3 --target 2,2,2", 2, "duplicates target #1"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --roi 10,10,10,5,40,40", 2, "--roi"},
      {"trace " + v + " --root 1,1,1 --target 30,30,30 --roi 0,0,0,20,20,20", 2, "outside the --roi"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --prune isoregion --prune-on intensity --threshold 1000", 1,
       "removes every voxel"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --prune isoregion --threshold 50", 2, "--prune-on intensity"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --prune isoregion --prune-on intensity --cost-tolerance 0.1", 2,
       "--cost-tolerance"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --prune isoregion --prune-on voxels", 2, "--prune-on"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --prune isoregion --cost-tolerance -1", 2, "--cost-tolerance"},
      {"trace " + v + " --root 1,1,1", 2, "--auto-terminals"},
      {"trace " + v + " --root 1,1 --target 2,2,2", 2, "--root"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --cost magic", 2, "cost"},
      {"trace " + p("missing.nii.gz") + " --root 1,1,1 --target 2,2,2", 1, "missing.nii.gz"},
      {"trace " + p("neg.nii.gz") + " --cost given --root 1,1,1 --target 14,2,2", 1, "(8,1,1)"},
      // Options the chosen cost does not use: usage errors naming the cost that uses them.
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --polarity dark", 2, "--polarity applies to --cost vesselness"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --wg 0.5", 2, "--wg applies to --cost gradient"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --cost intensity --wz 0.1", 2, "--wz applies to --cost gradient"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --scales 1,2", 2, "--scales applies to --cost vesselness"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --cost gradient --power 2", 2, "--power applies to --cost auto"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --window 1,2", 2, "--window applies to --cost intensity"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --cost intensity --upper-edge 2", 2,
       "--upper-edge applies to --cost auto"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --upper-edge -1", 2, "--upper-edge"},
  };
  for (const auto& c : cases) {
    const Result r = run(c.args);
    EXPECT_EQ(r.status, c.status) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
  }
  // Given unit costs: the path cost is its length (MCP_Geometric).
  const Result ok =
      run("trace " + p("ones.nii.gz") + " --cost given --root 1,1,1 --target 6,1,1 --json " + p("ones.json"));
  ASSERT_EQ(ok.status, 0) << ok.output;
  std::ifstream f(p("ones.json"));
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_NEAR(j["paths"][0]["cost"].get<double>(), 5.0, 1e-9);
  EXPECT_EQ(run("trace --help").status, 0);
}

}  // namespace

namespace {

// README: the airway example exactly as printed (default auto cost): at least 6 distinct
// terminals, every path voxel air (< -900 HU), refined points and radii in the report.
TEST_F(TraceCli, ReadmeAirwayExampleAsPrinted) {
  const std::string ct = std::string(VS_SHARED_DATA_DIR) + "/chest_cta_totalseg/ct_cropped.nii.gz";
  if (!fs::exists(ct)) GTEST_SKIP() << "shared data missing: " << ct;
  const Result r = run("trace " + ct + " --root 46,59,150 --auto-terminals 6 --min-length 20 --out " + p("tree.swc") +
                       " --json " + p("tree.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("cost: auto: connected root window + local contrast (dark"), std::string::npos) << r.output;
  std::ifstream f(p("tree.json"));
  const nlohmann::json j = nlohmann::json::parse(f);
  const vs::VolumeF32 hu = vs::toFloat(vs::readVolume(ct));
  std::set<std::vector<int64_t>> terminals;
  for (const auto& path : j["paths"]) {
    terminals.insert(path["target"].get<std::vector<int64_t>>());
    ASSERT_EQ(path["points"].size(), path["voxels"].size());
    ASSERT_EQ(path["radii_mm"].size(), path["voxels"].size());
    for (const auto& v : path["voxels"])
      EXPECT_LT(hu(v[0].get<int64_t>(), v[1].get<int64_t>(), v[2].get<int64_t>()), -900.0f) << v;
    // The refined points stay in the air too (trilinear HU; the airway criterion).
    for (const auto& q : path["points"])
      EXPECT_LT(vs::sampleTrilinear(hu, vs::Vec3(q[0].get<double>(), q[1].get<double>(), q[2].get<double>())), -900.0)
          << q;
  }
  EXPECT_GE(terminals.size(), 6u);
  EXPECT_EQ(j["cost_estimate"]["polarity"], "dark");
  // The lower edge of the dark lumen (its upper edge mirrored): beyond the lumen, away from the surroundings.
  ASSERT_EQ(j["cost_estimate"]["upper_edge"].size(), 2u);
  EXPECT_LT(j["cost_estimate"]["upper_edge"][0].get<double>(), j["cost_estimate"]["lumen"].get<double>());
  EXPECT_LT(j["cost_estimate"]["upper_edge"][1].get<double>(), j["cost_estimate"]["upper_edge"][0].get<double>());
  // The terminal scan searched the airway lumen only, not the 2.5 M voxels of the volume.
  EXPECT_FALSE(j["graph"]["full_search"].get<bool>());
  EXPECT_GT(j["graph"]["terminal_search_settled"].get<int64_t>(), 1000);
  EXPECT_LT(j["graph"]["terminal_search_settled"].get<int64_t>(), 100000);
  EXPECT_GT(fs::file_size(p("tree.swc")), 100u);
}

// Bad input keeps its contract with the default cost (issue 21): a flat volume (no contrast near
// the root), NaN voxels, a root or target outside the volume: exit 1 (data) or 2 (usage), a message
// naming the problem, and no output file.
TEST_F(TraceCli, BadInputWithTheDefaultCostWritesNothing) {
  vs::Geometry g;
  g.dims = {16, 8, 8};
  vs::VolumeF32 flat(g, 100.0f);
  vs::writeVolume(vs::AnyVolume(flat), p("flat.mha"));
  flat(3, 3, 3) = std::numeric_limits<float>::quiet_NaN();
  vs::writeVolume(vs::AnyVolume(flat), p("nan.mha"));
  struct Case {
    std::string args;
    int status;
    std::string message;
  };
  const std::string v = p("v.nii.gz");
  const Case cases[] = {
      {"trace " + p("flat.mha") + " --root 8,4,4 --target 12,4,4", 1, "no contrast around the root"},
      {"trace " + p("nan.mha") + " --root 8,4,4 --target 12,4,4", 1, "NaN"},
      {"trace " + v + " --root -1,1,1 --target 2,2,2", 2, "outside the volume"},
      {"trace " + v + " --root 1,1,1 --target 2,2,2 --target 2,-3,2", 2, "outside the volume"},
  };
  for (const auto& c : cases) {
    const Result r = run(c.args + " --out " + p("bad.swc") + " --json " + p("bad.json"));
    EXPECT_EQ(r.status, c.status) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_FALSE(fs::exists(p("bad.swc"))) << c.args;
    EXPECT_FALSE(fs::exists(p("bad.json"))) << c.args;
  }
}

// Nothing traced is a failure: exit 1, the reason, and no output file.
TEST_F(TraceCli, NothingTracedWritesNothing) {
  std::ifstream t(p("v.json"));
  const auto r0 = nlohmann::json::parse(t)["root_voxel"];
  const std::string root = std::to_string(r0[0].get<int>()) + "," + std::to_string(r0[1].get<int>()) + "," +
                           std::to_string(r0[2].get<int>());
  const Result r = run("trace " + p("v.nii.gz") + " --root " + root + " --auto-terminals 3 --min-length 5000 --out " +
                       p("none.swc") + " --json " + p("none.json"));
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("no terminal found"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(p("none.swc")));
  EXPECT_FALSE(fs::exists(p("none.json")));
  // --full alone: the complete map, every reachable node settled.
  const Result m = run("trace " + p("ones.nii.gz") + " --cost given --root 1,1,1 --full --json " + p("map.json"));
  ASSERT_EQ(m.status, 0) << m.output;
  std::ifstream f(p("map.json"));
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_TRUE(j["graph"]["full_search"].get<bool>());
  EXPECT_EQ(j["graph"]["settled"].get<int64_t>(), 16 * 8 * 8);
  EXPECT_EQ(run("trace " + p("ones.nii.gz") + " --cost given --root 1,1,1 --full --out " + p("m.swc")).status, 2);
  EXPECT_EQ(run("trace " + p("v.nii.gz") + " --cost intensity --window 5,5 --root 1,1,1 --target 2,2,2").status, 2);
  // --continue-dim changes only the terminal scan: with targets it would change nothing, so it is refused.
  const Result dim = run("trace " + p("v.nii.gz") + " --root 1,1,1 --target 2,2,2 --continue-dim");
  EXPECT_EQ(dim.status, 2);
  EXPECT_NE(dim.output.find("--continue-dim applies to --auto-terminals"), std::string::npos) << dim.output;
  // Off by default, so there is no --no-continue-dim (it would change nothing): an unknown option.
  EXPECT_EQ(run("trace " + p("v.nii.gz") + " --root 1,1,1 --auto-terminals 2 --no-continue-dim").status, 2);
}

}  // namespace

// Issue 11: a bad --targets-file is a data error (exit 1) whose message names the file and says
// what is wrong (the line for text files), and nothing is written.
TEST_F(TraceCli, BadTargetsFileNamesTheFileAndTheProblem) {
  struct Case {
    std::string name, content, message;
  };
  const Case cases[] = {
      {"words.txt", "10 10 10\n12 twelve 12\n", "line 2: expected three numbers"},
      {"two.txt", "# root first\n10,10\n", "line 2: expected three numbers"},
      {"empty.txt", "# nothing here\n\n", "holds no target"},
      {"broken.json", "{\"terminals\": [[1,2,3],", "invalid JSON"},
      {"strings.json", "{\"terminals\": [[\"1\",2,3]]}", "target #1 is not [x,y,z]"},
      {"nolist.json", "{\"points\": [[1,2,3]]}", "no \"terminals\" or \"targets\" array"},
      {"badroot.json", "{\"root\": [1,2], \"targets\": [[1,2,3]]}", "\"root\" is not [x,y,z]"},
  };
  for (const auto& c : cases) {
    std::ofstream(p(c.name)) << c.content;
    const Result r =
        run("trace " + p("v.nii.gz") + " --root 5,5,5 --targets-file " + p(c.name) + " --out " + p("bad_targets.swc"));
    EXPECT_EQ(r.status, 1) << c.name << "\n" << r.output;
    EXPECT_NE(r.output.find("targets file '" + p(c.name) + "'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.name << "\n" << r.output;
    EXPECT_FALSE(fs::exists(p("bad_targets.swc")));
  }
  const Result missing = run("trace " + p("v.nii.gz") + " --root 5,5,5 --targets-file " + p("missing.txt"));
  EXPECT_EQ(missing.status, 1) << missing.output;
  EXPECT_NE(missing.output.find(p("missing.txt")), std::string::npos) << missing.output;
}
