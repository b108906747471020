#include "io/report_io.h"

#include "util/atomic_file.h"
#include "util/error.h"

namespace vs {

namespace {
using json = nlohmann::json;

json arr(const Index3& v) { return json::array({v[0], v[1], v[2]}); }
json arr(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }

const json& field(const json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw IoError(where + ": missing \"" + key + "\"");
  return j[key];
}

template <class T>
T number(const json& j, const std::string& where) {
  if (!j.is_number()) throw IoError(where + ": expected a number");
  return j.get<T>();
}

Index3 index3(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) throw IoError(where + ": expected [x,y,z]");
  Index3 v;
  for (size_t a = 0; a < 3; ++a) {
    if (!j[a].is_number_integer()) throw IoError(where + ": expected integer voxel indices");
    v[a] = j[a].get<int64_t>();
  }
  return v;
}

Vec3 vec3(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) throw IoError(where + ": expected [x,y,z]");
  return Vec3(number<double>(j[0], where), number<double>(j[1], where), number<double>(j[2], where));
}
}  // namespace

json traceReportToJson(const TraceReport& r) {
  json j;
  j["volume"] = r.volume;
  j["root"] = arr(r.root);
  j["requested_root"] = arr(r.requestedRoot);
  j["cost"] = r.cost;
  if (!r.costEstimate.is_null()) j["cost_estimate"] = r.costEstimate;
  j["paths"] = json::array();
  for (const TraceReportPath& p : r.paths) {
    json jp;
    jp["target"] = arr(p.target);
    jp["requested"] = arr(p.requested);
    jp["reached"] = p.reached;
    jp["cost"] = p.cost;
    jp["length_mm"] = p.lengthMm;
    jp["length_voxels"] = p.voxels.size();
    jp["parent_path"] = p.parentPath;
    json vox = json::array();
    for (const auto& v : p.voxels) vox.push_back(arr(v));
    jp["voxels"] = std::move(vox);
    if (!p.points.empty()) {
      json pts = json::array();
      for (const auto& v : p.points) pts.push_back(arr(v));
      jp["points"] = std::move(pts);
      jp["radii_mm"] = p.radiiMm;
    }
    j["paths"].push_back(std::move(jp));
  }
  j["branch_points"] = json::array();
  for (const auto& b : r.branchPoints) j["branch_points"].push_back(arr(b));
  j["graph"] = r.graph;
  j["seconds"] = r.seconds;
  j["notes"] = r.notes;
  return j;
}

TraceReport traceReportFromJson(const json& j, const std::string& where) {
  TraceReport r;
  if (!j.is_object()) throw IoError(where + ": a trace report is a JSON object");
  if (j.contains("volume") && j["volume"].is_string()) r.volume = j["volume"].get<std::string>();
  r.root = index3(field(j, "root", where), where + ": root");
  r.requestedRoot = j.contains("requested_root") ? index3(j["requested_root"], where + ": requested_root") : r.root;
  if (j.contains("cost") && j["cost"].is_string()) r.cost = j["cost"].get<std::string>();
  if (j.contains("cost_estimate")) r.costEstimate = j["cost_estimate"];
  const json& paths = field(j, "paths", where);
  if (!paths.is_array()) throw IoError(where + ": \"paths\" must be an array");
  for (size_t i = 0; i < paths.size(); ++i) {
    const std::string w = where + ": paths[" + std::to_string(i) + "]";
    const json& jp = paths[i];
    TraceReportPath p;
    const json& vox = field(jp, "voxels", w);
    if (!vox.is_array()) throw IoError(w + ": \"voxels\" must be an array");
    for (const auto& v : vox) p.voxels.push_back(index3(v, w + ": voxels"));
    p.target = jp.contains("target") ? index3(jp["target"], w + ": target")
                                     : (p.voxels.empty() ? Index3{0, 0, 0} : p.voxels.back());
    p.requested = jp.contains("requested") ? index3(jp["requested"], w + ": requested") : p.target;
    if (jp.contains("reached") && !jp["reached"].is_boolean()) throw IoError(w + ": \"reached\" must be true or false");
    p.reached = jp.contains("reached") ? jp["reached"].get<bool>() : !p.voxels.empty();
    if (jp.contains("cost")) p.cost = number<double>(jp["cost"], w + ": cost");
    if (jp.contains("length_mm")) p.lengthMm = number<double>(jp["length_mm"], w + ": length_mm");
    if (jp.contains("parent_path")) p.parentPath = number<int>(jp["parent_path"], w + ": parent_path");
    if (jp.contains("points")) {
      if (!jp["points"].is_array() || jp["points"].size() != p.voxels.size())
        throw IoError(w + ": \"points\" must hold one [x,y,z] per voxel");
      for (const auto& v : jp["points"]) p.points.push_back(vec3(v, w + ": points"));
      const json& radii = field(jp, "radii_mm", w);
      if (!radii.is_array() || radii.size() != p.points.size())
        throw IoError(w + ": \"radii_mm\" must hold one radius per point");
      for (const auto& x : radii) p.radiiMm.push_back(number<double>(x, w + ": radii_mm"));
    }
    r.paths.push_back(std::move(p));
  }
  if (j.contains("branch_points"))
    for (const auto& b : j["branch_points"]) r.branchPoints.push_back(index3(b, where + ": branch_points"));
  if (j.contains("graph")) r.graph = j["graph"];
  if (j.contains("seconds")) r.seconds = j["seconds"];
  if (j.contains("notes")) {
    if (!j["notes"].is_array()) throw IoError(where + ": \"notes\" must be an array of strings");
    for (const auto& n : j["notes"]) {
      if (!n.is_string()) throw IoError(where + ": \"notes\" must be an array of strings");
      r.notes.push_back(n.get<std::string>());
    }
  }
  return r;
}

void writeTraceReport(const TraceReport& r, const std::string& path) {
  writeFileAtomically(path, traceReportToJson(r).dump(1) + "\n");
}

TraceReport readTraceReport(const std::string& path) {
  const std::string text = readTextFile(path, "the trace report");
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw IoError(path + ": malformed JSON: " + e.what());
  }
  return traceReportFromJson(j, path);
}

}  // namespace vs
