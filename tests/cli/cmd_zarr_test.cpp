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
  // The slice of the folder (only its chunks read) is the slice of the whole volume, pixel for
  // pixel, with the same picture -> voxel mapping; on every axis, on a chunk face and inside.
  for (const std::string plane : {"x=0", "y=31", "z=33", "z=55"}) {
    const std::string opts = " --mode slice --plane " + plane + " --window 200,110 --ticks --out ";
    r = cli("render " + q(z) + opts + q(dir.file("c.png")) + " --json " + q(dir.file("c.json")));
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("chunks read"), std::string::npos) << r.out;
    ASSERT_EQ(
        cli("-q render " + q(dir.file("v.nii.gz")) + opts + q(dir.file("m.png")) + " --json " + q(dir.file("m.json")))
            .status,
        0);
    EXPECT_EQ(readBytes(dir.file("c.png")), readBytes(dir.file("m.png"))) << plane;
    const auto cj = nlohmann::json::parse(readBytes(dir.file("c.json")));
    const auto mj = nlohmann::json::parse(readBytes(dir.file("m.json")));
    EXPECT_EQ(cj["slice"], mj["slice"]) << plane;
    EXPECT_EQ(cj["pixel_to_index"], mj["pixel_to_index"]) << plane;
  }
  // info reads the metadata and the coarsest level: it says so, and the range it gives is that level's.
  r = cli("info " + q(z) + " --json " + q(dir.file("i.json")));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("only the metadata and the coarsest level"), std::string::npos) << r.out;
  const auto ij = nlohmann::json::parse(readBytes(dir.file("i.json")));
  EXPECT_EQ(ij["dims"], nlohmann::json({72, 64, 56}));
  EXPECT_NE(ij["range_of"].get<std::string>().find("of level 1"), std::string::npos);
  EXPECT_EQ(ij["bytes"].get<int64_t>(), 72 * 64 * 56);

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
  // An uncompressed NIfTI is traced chunk by chunk through a memory mapping: the same path cost.
  ASSERT_EQ(cli("-q convert " + q(z) + " " + q(dir.file("v.nii"))).status, 0);
  r = cli("trace " + q(dir.file("v.nii")) + " --chunked-above 0" + common + " --json " + q(dir.file("n.json")));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("chunks read"), std::string::npos) << r.out;
  EXPECT_EQ(nlohmann::json::parse(readBytes(dir.file("n.json")))["paths"][0]["cost"].get<double>(), cc);
  // The chunked trace refines its path (one point and radius per voxel).
  EXPECT_EQ(c["paths"][0]["points"].size(), c["paths"][0]["voxels"].size());
  EXPECT_EQ(c["paths"][0]["radii_mm"].size(), c["paths"][0]["voxels"].size());
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
