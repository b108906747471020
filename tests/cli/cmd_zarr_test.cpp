// OME-Zarr folders through the real binary (issue 25): phantom (chunk by chunk), info, convert,
// render --mode slice, trace (in memory and chunk by chunk, equal costs), bad chunks (exit 1,
// the chunk named, nothing written).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "io/io_test_util.h"

using namespace vs::test;

namespace {

struct CliRun {
  int status = -1;
  std::string out;
};

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

std::string voxel(const nlohmann::json& v) {
  return std::to_string(v[0].get<int>()) + "," + std::to_string(v[1].get<int>()) + "," +
         std::to_string(v[2].get<int>());
}

}  // namespace

TEST(CliZarr, PhantomInfoConvertRenderTrace) {
  TempDir dir("clizarr");
  const std::string z = dir.file("v.zarr"), t = dir.file("t.json");
  CliRun r = cli("-q phantom vessels --size 72,64,56 --seed 5 --out " + q(z) + " --truth " + q(t));
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_TRUE(std::filesystem::exists(z + "/.zattrs"));
  r = cli("info " + q(z));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("ome-zarr"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("72 x 64 x 56"), std::string::npos) << r.out;
  r = cli("-q convert " + q(z) + " " + q(dir.file("v.nii.gz")));
  ASSERT_EQ(r.status, 0) << r.out;
  r = cli("-q convert " + q(dir.file("v.nii.gz")) + " " + q(dir.file("w.zarr")));
  ASSERT_EQ(r.status, 0) << r.out;
  r = cli("-q render " + q(dir.file("w.zarr")) + " --mode slice --out " + q(dir.file("s.png")));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_GT(std::filesystem::file_size(dir.file("s.png")), 1000u);

  const auto truth = nlohmann::json::parse(readBytes(t));
  const std::string root = voxel(truth["root_voxel"]), target = voxel(truth["terminals"][0]["voxel"]);
  const std::string common = " --cost intensity --window 20,220 --root " + root + " --target " + target;
  r = cli("trace " + q(z) + " --chunked-above 0" + common + " --json " + q(dir.file("c.json")));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("blocks"), std::string::npos) << r.out;
  r = cli("trace " + q(dir.file("v.nii.gz")) + common +
          " --smooth 0 --snap 0 --prune none --connectivity 26 --no-refine --json " + q(dir.file("m.json")));
  ASSERT_EQ(r.status, 0) << r.out;
  const auto c = nlohmann::json::parse(readBytes(dir.file("c.json")));
  const auto m = nlohmann::json::parse(readBytes(dir.file("m.json")));
  const double cc = c["paths"][0]["cost"].get<double>(), mc = m["paths"][0]["cost"].get<double>();
  EXPECT_NEAR(cc, mc, 1e-9 * mc);
  // Options the chunked tracer does not have are usage errors, not ignored.
  r = cli("trace " + q(z) + " --chunked-above 0" + common + " --out " + q(dir.file("x.swc")));
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.swc")));
}

TEST(CliZarr, BadChunkExits1NamingItAndWritesNothing) {
  TempDir dir("clizarrbad");
  const std::string z = dir.file("v.zarr");
  ASSERT_EQ(cli("-q phantom vessels --size 40,40,40 --seed 2 --out " + q(z)).status, 0);
  writeBytes(z + "/0/0.0.0", "\x78\x01truncated");
  for (const std::string& cmd :
       {"convert " + q(z) + " " + q(dir.file("o.nii")),
        "render " + q(z) + " --mode slice --out " + q(dir.file("o.png")),
        "trace " + q(z) + " --chunked-above 0 --root 1,1,1 --target 30,30,30 --json " + q(dir.file("o.json"))}) {
    const CliRun r = cli(cmd);
    EXPECT_EQ(r.status, 1) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find("chunk 0.0.0"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("o.nii")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("o.png")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("o.json")));
}
