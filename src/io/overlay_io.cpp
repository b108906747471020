#include "io/overlay_io.h"

#include <nlohmann/json.hpp>

#include "io/mesh_io.h"
#include "meshops/polydata_file.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "volume/slice.h"
#include "volume/volume.h"

namespace vs {

namespace {

double number(const nlohmann::json& v, const std::string& where) {
  if (!v.is_number()) throw IoError(where + ": expected a number, got " + v.dump());
  return v.get<double>();
}

Polyline indexPolyline(const nlohmann::json& pts, const Geometry& g, const std::string& where, bool closed) {
  Polyline pl;
  pl.closed = closed;
  if (!pts.is_array()) throw IoError(where + ": expected an array of [x,y,z] points");
  for (const auto& p : pts) {
    if (!p.is_array() || p.size() != 3) throw IoError(where + ": expected [x,y,z] voxel index points");
    pl.points.push_back(g.indexToWorld(Vec3(number(p[0], where), number(p[1], where), number(p[2], where))));
  }
  return pl;
}

// {"points": [[u,v]..], "slice": "z=40" | {"axis": 2 | "z", "index": 40}}
Polyline slicePolyline(const nlohmann::json& j, const Geometry& g, const std::string& path) {
  int axis = 2;
  int64_t index = 0;
  const auto& s = j["slice"];
  try {
    if (s.is_string()) {
      std::tie(axis, index) = parseSliceSpec(s.get<std::string>());
    } else if (s.is_object() && s.contains("axis") && s.contains("index") && s["index"].is_number_integer()) {
      if (s["axis"].is_string())
        std::tie(axis, index) = parseSliceSpec(s["axis"].get<std::string>() + "=0");
      else if (s["axis"].is_number_integer())
        axis = s["axis"].get<int>();
      else
        throw IoError("bad axis");
      index = s["index"].get<int64_t>();
    } else {
      throw IoError("bad slice");
    }
  } catch (const Error&) {
    throw IoError(path + ": \"slice\" must be \"z=40\" or {\"axis\": \"z\" (or 2), \"index\": 40}");
  }
  if (axis < 0 || axis > 2) throw IoError(path + ": slice axis must be x, y, z (0, 1, 2)");
  if (!j["points"].is_array()) throw IoError(path + ": \"points\" must be an array of [u,v] pairs");
  nlohmann::json pts = nlohmann::json::array();
  for (const auto& p : j["points"]) {
    if (p.is_array() && p.size() == 3) {  // already a voxel index
      pts.push_back(p);
      continue;
    }
    if (!p.is_array() || p.size() != 2 || !p[0].is_number_integer() || !p[1].is_number_integer())
      throw IoError(path + ": \"points\" must be [u,v] integer slice pixel pairs (or [x,y,z] voxel indices)");
    const Index3 i = sliceToVolumeIndex(axis, index, p[0].get<int64_t>(), p[1].get<int64_t>());
    pts.push_back({i[0], i[1], i[2]});
  }
  return indexPolyline(pts, g, path, j.value("closed", true));
}

void readJsonOverlay(const std::string& path, const Geometry& g, Overlay& o) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(readTextFile(path, "the overlay file"));
  } catch (const nlohmann::json::exception& e) {
    throw IoError(path + ": malformed JSON: " + e.what());
  }
  if (!j.is_object()) throw IoError(path + ": expected a JSON object");
  if (j.contains("paths")) {
    if (!j["paths"].is_array()) throw IoError(path + ": \"paths\" must be an array");
    size_t i = 0;
    for (const auto& p : j["paths"]) {
      const std::string where = path + ": paths[" + std::to_string(i++) + "]";
      if (!p.is_object() || !p.contains("voxels")) throw IoError(where + ": needs \"voxels\"");
      o.lines.push_back(indexPolyline(p["voxels"], g, where, false));
    }
  } else if (j.contains("points_index")) {
    const bool closed = j.contains("closed") && j["closed"].is_boolean() ? j["closed"].get<bool>() : true;
    o.lines.push_back(indexPolyline(j["points_index"], g, path, closed));
  } else if (j.contains("points") && j.contains("slice")) {
    o.lines.push_back(slicePolyline(j, g, path));
  } else if (j.contains("nodes")) {
    o.lines = readTree(path).toPolylines();
  } else if (j.contains("polylines")) {
    o.lines = readPolylines(path);
  } else {
    throw IoError(path +
                  ": unknown overlay JSON (expected \"paths\", \"points_index\", \"points\"+\"slice\", "
                  "\"nodes\" or \"polylines\")");
  }
}

}  // namespace

const char* overlayExtensions() { return ".obj .ply .stl .vtk .vtp .swc .json"; }

Overlay readOverlay(const std::string& path, const Geometry& g) {
  Overlay o;
  const std::string ext = fileExtension(path);
  if (ext == ".obj" || ext == ".ply" || ext == ".stl") {
    o.mesh = readTriMesh(path);
  } else if (ext == ".vtp" || ext == ".vtk") {
    PolyDataContent c = readPolyDataFile(path);
    if (c.empty()) throw IoError(path + ": the VTK PolyData file holds no polygon and no line");
    o.mesh = std::move(c.mesh);
    o.lines = std::move(c.lines);
  } else if (ext == ".swc") {
    o.lines = readTree(path).toPolylines();
  } else if (ext == ".json") {
    readJsonOverlay(path, g, o);
  } else {
    throw InvalidArgument("overlay " + path + ": unsupported file type '" + ext + "' (use " + overlayExtensions() +
                          ")");
  }
  auto count = [&](const Vec3& w) {
    ++o.points;
    if (!g.nearVolume(w)) ++o.pointsOutside;
  };
  for (const auto& p : o.mesh.positions) count(p);
  for (const auto& l : o.lines)
    for (const auto& p : l.points) count(p);
  return o;
}

}  // namespace vs
