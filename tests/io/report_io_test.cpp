// The trace report: what the writer writes the reader reads back, field by field; malformed
// reports name the field.
#include "io/report_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "util/error.h"

namespace vs {
namespace {

namespace fs = std::filesystem;

TraceReport sample() {
  TraceReport r;
  r.volume = "v.nii.gz";
  r.root = {4, 5, 6};
  r.requestedRoot = {4, 6, 6};
  r.cost = "auto: intensity (bright, ...)";
  r.costEstimate = {{"polarity", "bright"}, {"window", {100.5, 180.25}}};
  TraceReportPath p;
  p.target = {9, 5, 6};
  p.requested = {9, 5, 7};
  p.reached = true;
  p.cost = 1.25;
  p.lengthMm = 7.5;
  p.parentPath = -1;
  p.voxels = {{4, 5, 6}, {5, 5, 6}, {6, 5, 6}};
  p.points = {Vec3(4, 5, 6), Vec3(5.125, 5.25, 6.5), Vec3(6.0625, 5, 6)};
  p.radiiMm = {1.5, 1.25, 1.0};
  r.paths.push_back(p);
  p.points.clear();
  p.radiiMm.clear();
  p.parentPath = 0;
  r.paths.push_back(p);
  r.branchPoints = {{5, 5, 6}};
  r.graph = {{"nodes", 1000}, {"full_search", true}};
  r.seconds = {{"search", 0.5}};
  r.notes = {"note: target #1 re-traced around a crossing"};
  return r;
}

TEST(ReportIo, RoundTrip) {
  const fs::path f = fs::temp_directory_path() / ("vs_report_" + std::to_string(::getpid()) + ".json");
  const TraceReport a = sample();
  writeTraceReport(a, f.string());
  const TraceReport b = readTraceReport(f.string());
  fs::remove(f);
  EXPECT_EQ(b.volume, a.volume);
  EXPECT_EQ(b.root, a.root);
  EXPECT_EQ(b.requestedRoot, a.requestedRoot);
  EXPECT_EQ(b.cost, a.cost);
  EXPECT_EQ(b.costEstimate, a.costEstimate);
  ASSERT_EQ(b.paths.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(b.paths[i].target, a.paths[i].target);
    EXPECT_EQ(b.paths[i].requested, a.paths[i].requested);
    EXPECT_EQ(b.paths[i].reached, a.paths[i].reached);
    EXPECT_EQ(b.paths[i].cost, a.paths[i].cost);
    EXPECT_EQ(b.paths[i].lengthMm, a.paths[i].lengthMm);
    EXPECT_EQ(b.paths[i].parentPath, a.paths[i].parentPath);
    EXPECT_EQ(b.paths[i].voxels, a.paths[i].voxels);
    EXPECT_EQ(b.paths[i].points, a.paths[i].points);
    EXPECT_EQ(b.paths[i].radiiMm, a.paths[i].radiiMm);
  }
  EXPECT_EQ(b.branchPoints, a.branchPoints);
  EXPECT_EQ(b.graph, a.graph);
  EXPECT_EQ(b.seconds, a.seconds);
  EXPECT_EQ(b.notes, a.notes);
  // The documented field names.
  const nlohmann::json j = traceReportToJson(a);
  EXPECT_EQ(j["paths"][0]["length_voxels"], 3);
  EXPECT_EQ(j["paths"][0]["points"][1], nlohmann::json::array({5.125, 5.25, 6.5}));
  EXPECT_FALSE(j["paths"][1].contains("points"));
}

TEST(ReportIo, MalformedReportsNameTheField) {
  auto message = [](const nlohmann::json& j) {
    try {
      traceReportFromJson(j, "r.json");
    } catch (const IoError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  nlohmann::json j = traceReportToJson(sample());
  j.erase("root");
  EXPECT_NE(message(j).find("\"root\""), std::string::npos);
  j = traceReportToJson(sample());
  j["paths"][0]["points"].erase(0);
  EXPECT_NE(message(j).find("paths[0]: \"points\""), std::string::npos) << message(j);
  j = traceReportToJson(sample());
  j["paths"][1]["voxels"][0] = {1.5, 2, 3};
  EXPECT_NE(message(j).find("paths[1]: voxels"), std::string::npos) << message(j);
  j = traceReportToJson(sample());
  j["paths"][0]["reached"] = "yes";
  EXPECT_NE(message(j).find("reached"), std::string::npos) << message(j);
  EXPECT_THROW(readTraceReport("/nonexistent/r.json"), IoError);
}

}  // namespace
}  // namespace vs
