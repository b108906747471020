// The trace report (`volscissors trace --json`): one schema, one writer, one reader.
//   {"volume": str, "root": [x,y,z], "requested_root": [x,y,z], "cost": str,
//    "cost_estimate": {...} (auto cost only), "paths": [{"target": [x,y,z], "requested": [x,y,z],
//    "reached": b, "cost": c, "length_mm": l, "length_voxels": n, "parent_path": i,
//    "voxels": [[x,y,z]..] (int, 0-based index), "points": [[x,y,z]..] (float index, refined
//    centreline, one per voxel), "radii_mm": [r..]}], "branch_points": [[x,y,z]..],
//    "graph": {...}, "seconds": {...}}
// Index coordinates are 0-based voxel indices of the traced volume (x,y,z). "points" and
// "radii_mm" are optional (absent in reports of older versions); "graph", "seconds" and
// "cost_estimate" are free-form objects carried through unchanged.
// Errors: IoError naming the file and the malformed field. Writes are atomic.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "volume/geometry.h"

namespace vs {

struct TraceReportPath {
  Index3 target{0, 0, 0}, requested{0, 0, 0};
  bool reached = false;
  double cost = 0, lengthMm = 0;
  int parentPath = -1;
  std::vector<Index3> voxels;
  std::vector<Vec3> points;     // refined centreline (empty: not refined)
  std::vector<double> radiiMm;  // per point (empty: not refined)
};

struct TraceReport {
  std::string volume;
  Index3 root{0, 0, 0}, requestedRoot{0, 0, 0};
  std::string cost;
  nlohmann::json costEstimate;  // null unless the cost was estimated
  std::vector<TraceReportPath> paths;
  std::vector<Index3> branchPoints;
  nlohmann::json graph = nlohmann::json::object();
  nlohmann::json seconds = nlohmann::json::object();
  std::vector<std::string> notes;  // what the trace moved, re-routed or took with a warning (the CLI's notes)
};

nlohmann::json traceReportToJson(const TraceReport& report);
// `where` names the source in errors.
TraceReport traceReportFromJson(const nlohmann::json& json, const std::string& where);
void writeTraceReport(const TraceReport& report, const std::string& path);
TraceReport readTraceReport(const std::string& path);

}  // namespace vs
