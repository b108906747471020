#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "phantom/phantom.h"

using namespace vs;
namespace fs = std::filesystem;

namespace {

fs::path tempDir() {
  const fs::path d = fs::temp_directory_path() / ("vs_phantom_json_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

void writeText(const fs::path& p, const std::string& s) { std::ofstream(p) << s; }

}  // namespace

TEST(PhantomTruthJson, VesselRoundTripThroughFile) {
  VesselPhantomOptions o;
  o.dims = {48, 48, 48};
  o.spacing = Vec3(0.8, 0.8, 1.2);
  const auto ph = makeVesselPhantom(o);
  const fs::path f = tempDir() / "vessels.json";
  writeTruthFile(toJson(ph.truth), f.string());
  const VesselTruth back = readVesselTruth(f.string());
  EXPECT_EQ(toJson(back).dump(), toJson(ph.truth).dump());
  EXPECT_EQ(back.branches.size(), ph.truth.branches.size());
  EXPECT_EQ(back.terminalVoxels, ph.truth.terminalVoxels);
  EXPECT_EQ(back.spacing, o.spacing);
  const auto j = nlohmann::json::parse(std::ifstream(f));
  EXPECT_EQ(j.at("kind"), "vessels");
  EXPECT_EQ(j.at("seed"), 1);
  EXPECT_EQ(j.at("branches").at(0).at("parent"), -1);
  fs::remove_all(f.parent_path());
}

TEST(PhantomTruthJson, HeadAndShapesRoundTrip) {
  HeadPhantomOptions ho;
  ho.dims = {40, 40, 40};
  const auto head = makeHeadPhantom(ho);
  EXPECT_EQ(toJson(headTruthFromJson(toJson(head.truth))).dump(), toJson(head.truth).dump());
  Shapes2DOptions so;
  so.width = so.height = 96;
  const auto shapes = makeShapes2DPhantom(so);
  const auto back = shapes2DTruthFromJson(toJson(shapes.truth));
  EXPECT_EQ(toJson(back).dump(), toJson(shapes.truth).dump());
  ASSERT_EQ(back.shapes.size(), shapes.truth.shapes.size());
  EXPECT_EQ(back.shapes[1].boundaryPixels, shapes.truth.shapes[1].boundaryPixels);
}

TEST(PhantomTruthJson, MalformedFilesThrowIoErrorNamingTheProblem) {
  const fs::path d = tempDir();
  EXPECT_THROW(readVesselTruth((d / "missing.json").string()), IoError);
  writeText(d / "bad.json", "{ not json");
  EXPECT_THROW(readVesselTruth((d / "bad.json").string()), IoError);
  HeadPhantomOptions ho;
  ho.dims = {24, 24, 24};
  writeTruthFile(toJson(makeHeadPhantom(ho).truth), (d / "head.json").string());
  try {
    readVesselTruth((d / "head.json").string());
    FAIL() << "wrong kind accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("kind"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("head.json"), std::string::npos);
  }
  writeText(d / "nofield.json", R"({"kind": "vessels", "format_version": 1, "seed": 1})");
  try {
    readVesselTruth((d / "nofield.json").string());
    FAIL() << "missing field accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("dims"), std::string::npos);
  }
  nlohmann::json j = toJson(makeHeadPhantom(ho).truth);
  j["ellipsoids"].erase(3);
  EXPECT_THROW(headTruthFromJson(j), IoError);
  EXPECT_THROW(writeTruthFile(j, (d / "no_such_dir" / "x.json").string()), IoError);
  EXPECT_FALSE(fs::exists(d / "no_such_dir"));
  fs::remove_all(d);
}
