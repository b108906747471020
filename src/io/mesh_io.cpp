// Mesh, tree and polyline files without ITK: OBJ and PLY (mesh_formats.cpp), SWC and JSON here;
// legacy VTK polydata and STL through meshops' VTK readers and writers (meshops/polydata_file.h,
// the one home of those formats; .vtk is written binary, so doubles come back exact). Writers
// validate the input (InvalidArgument), write atomically and keep coordinates as given (world
// mm). Readers throw IoError naming the file.
#include "io/mesh_io.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/io_internal.h"
#include "io/mesh_io_internal.h"
#include "meshops/polydata_file.h"
#include "util/atomic_file.h"

namespace vs {

using namespace mesh_io_detail;
using namespace io_detail;

namespace {

// SWC and JSON trees name parents by node id: map them to node indices (-1 stays a root).
std::vector<int32_t> resolveParentIds(const std::vector<long long>& parentIds,
                                      const std::map<long long, int32_t>& idToIndex, const std::string& path) {
  std::vector<int32_t> parent;
  parent.reserve(parentIds.size());
  for (long long pid : parentIds) {
    if (pid < 0) {
      parent.push_back(-1);
      continue;
    }
    auto it = idToIndex.find(pid);
    if (it == idToIndex.end()) throw IoError(path + ": parent id " + std::to_string(pid) + " does not exist");
    parent.push_back(it->second);
  }
  return parent;
}

// Legacy VTK polydata and STL through meshops' VTK readers and writers (meshops/polydata_file.h).
// Written binary: exact doubles (VTK's ASCII writer keeps 11 significant digits).
PolyDataCells meshCells(const TriMesh& mesh) {
  PolyDataCells cells;
  cells.mesh = mesh;
  return cells;
}

// A tree from line cells (parent -> child, or longer chains) and point arrays "radius" and "type".
Tree treeOfCells(PolyDataCells cells, const std::string& path) {
  Tree t;
  t.points = std::move(cells.mesh.positions);
  t.parent.assign(t.points.size(), -1);
  for (const auto& l : cells.lines)
    for (size_t k = 0; k + 1 < l.size(); ++k) {
      const auto child = static_cast<size_t>(l[k + 1]);
      if (t.parent[child] >= 0 && t.parent[child] != l[k])
        throw IoError(path + ": point " + std::to_string(l[k + 1]) + " has two parents (not a tree)");
      t.parent[child] = l[k];
    }
  if (auto r = cells.pointScalars.find("radius"); r != cells.pointScalars.end()) t.radii = std::move(r->second);
  if (auto ty = cells.pointScalars.find("type"); ty != cells.pointScalars.end())
    for (double v : ty->second) {
      if (!(v >= INT32_MIN && v <= INT32_MAX)) throw IoError(path + ": a node type is not an integer");
      t.types.push_back(static_cast<int32_t>(v));
    }
  return t;
}

void requireExt(const std::string& path, const std::string& ext, const std::string& allowed) {
  throw IoError(path + ": unsupported extension '" + ext + "' (use " + allowed + ")");
}

}  // namespace

void writeTriMesh(const TriMesh& mesh, const std::string& path) {
  mesh.validate();
  const std::string ext = lowerExt(path);
  if (ext == ".obj")
    writeFileAtomically(path, objText(mesh));
  else if (ext == ".ply")
    writeFileAtomically(path, plyBytes(mesh));
  else if (ext == ".stl" || ext == ".vtk")
    writePolyDataCells(meshCells(mesh), path);
  else
    requireExt(path, ext, ".obj, .ply, .stl or .vtk");
}

static TriMesh readTriMeshImpl(const std::string& path) {
  const std::string ext = lowerExt(path);
  TriMesh m;
  if (ext == ".obj")
    m = readObj(path);
  else if (ext == ".ply")
    m = readPly(path);
  else if (ext == ".stl" || ext == ".vtk")
    m = readPolyDataCells(path).mesh;
  else {
    requireExt(path, ext, ".obj, .ply, .stl or .vtk");
  }
  checkIndices(m, path);
  for (const auto& p : m.positions)
    if (!p.allFinite()) throw IoError(path + ": mesh has a non-finite vertex");
  return m;
}

// ------------------------------------------------------------------ trees
void writeTree(const Tree& tree, const std::string& path) {
  tree.validate();
  const std::string ext = lowerExt(path);
  const size_t n = tree.size();
  auto radius = [&](size_t i) { return tree.radii.empty() ? 0.0 : tree.radii[i]; };
  auto type = [&](size_t i) { return tree.types.empty() ? 0 : tree.types[i]; };
  std::ostringstream os;
  if (ext == ".swc") {
    os << "# volscissors tree (world mm)\n# id type x y z radius parent\n";
    for (size_t i = 0; i < n; ++i)
      os << i + 1 << ' ' << type(i) << ' ' << num(tree.points[i].x()) << ' ' << num(tree.points[i].y()) << ' '
         << num(tree.points[i].z()) << ' ' << num(radius(i)) << ' ' << (tree.parent[i] < 0 ? -1 : tree.parent[i] + 1)
         << '\n';
  } else if (ext == ".vtk") {  // each line cell is parent -> child; radius and type are point arrays
    PolyDataCells cells;
    cells.mesh.positions = tree.points;
    std::vector<double>&radii = cells.pointScalars["radius"], &types = cells.pointScalars["type"];
    for (size_t i = 0; i < n; ++i) {
      if (tree.parent[i] >= 0) cells.lines.push_back({tree.parent[i], static_cast<int32_t>(i)});
      radii.push_back(radius(i));
      types.push_back(type(i));
    }
    writePolyDataCells(cells, path);
    return;
  } else if (ext == ".json") {
    nlohmann::json nodes = nlohmann::json::array();
    for (size_t i = 0; i < n; ++i)
      nodes.push_back({{"id", i},
                       {"parent", tree.parent[i]},
                       {"xyz", {tree.points[i].x(), tree.points[i].y(), tree.points[i].z()}},
                       {"radius", radius(i)},
                       {"type", type(i)}});
    os << nlohmann::json{{"nodes", nodes}}.dump(1) << '\n';
  } else {
    requireExt(path, ext, ".swc, .vtk or .json");
  }
  writeFileAtomically(path, os.str());
}

static Tree readTreeImpl(const std::string& path) {
  const std::string ext = lowerExt(path);
  Tree t;
  if (ext == ".swc") {
    const std::string text = readFileBytes(path, false);
    std::istringstream in(text);
    std::string line;
    size_t lineNo = 0;
    std::map<long long, int32_t> idToIndex;
    std::vector<long long> parentIds;
    while (std::getline(in, line)) {
      ++lineNo;
      const auto w = splitWords(line);
      if (w.empty() || w[0][0] == '#') continue;
      if (w.size() < 7) throw IoError(path + ":" + std::to_string(lineNo) + ": SWC line needs 7 fields");
      const long long id = toInt(w[0], path, lineNo);
      if (!idToIndex.emplace(id, static_cast<int32_t>(t.points.size())).second)
        throw IoError(path + ":" + std::to_string(lineNo) + ": duplicate node id " + w[0]);
      t.types.push_back(static_cast<int32_t>(toInt(w[1], path, lineNo)));
      t.points.emplace_back(toDouble(w[2], path, lineNo), toDouble(w[3], path, lineNo), toDouble(w[4], path, lineNo));
      t.radii.push_back(toDouble(w[5], path, lineNo));
      parentIds.push_back(toInt(w[6], path, lineNo));
    }
    t.parent = resolveParentIds(parentIds, idToIndex, path);
  } else if (ext == ".vtk") {
    t = treeOfCells(readPolyDataCells(path), path);
  } else if (ext == ".json") {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(readFileBytes(path, false));
      std::map<long long, int32_t> idToIndex;
      std::vector<long long> parentIds;
      for (const auto& nd : j.at("nodes")) {
        const long long id = nd.contains("id") ? nd.at("id").get<long long>() : static_cast<long long>(t.points.size());
        if (!idToIndex.emplace(id, static_cast<int32_t>(t.points.size())).second)
          throw IoError(path + ": duplicate node id " + std::to_string(id));
        const auto& p = nd.at("xyz");
        t.points.emplace_back(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
        t.radii.push_back(nd.value("radius", 0.0));
        t.types.push_back(nd.value("type", 0));
        parentIds.push_back(nd.value("parent", -1LL));
      }
      t.parent = resolveParentIds(parentIds, idToIndex, path);
    } catch (const nlohmann::json::exception& e) {
      throw IoError(path + ": bad tree JSON: " + oneLine(e.what()));
    }
  } else {
    requireExt(path, ext, ".swc, .vtk or .json");
  }
  try {
    t.validate();
  } catch (const InvalidArgument& e) {
    throw IoError(path + ": " + e.what());
  }
  return t;
}

// ------------------------------------------------------------------ polylines
void writePolylines(const std::vector<Polyline>& lines, const std::string& path) {
  for (size_t i = 0; i < lines.size(); ++i) {
    for (const auto& p : lines[i].points)
      VS_REQUIRE(p.allFinite(), "polyline " + std::to_string(i) + " has a non-finite point");
    VS_REQUIRE(lines[i].radii.empty() || lines[i].radii.size() == lines[i].points.size(),
               "polyline " + std::to_string(i) + ": radius count differs from point count");
  }
  const std::string ext = lowerExt(path);
  std::ostringstream os;
  if (ext == ".vtk") {  // closed lines repeat their first point id
    PolyDataCells cells;
    appendPolylineCells(lines, cells);
    writePolyDataCells(cells, path);
    return;
  } else if (ext == ".json") {
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& l : lines) {
      nlohmann::json pts = nlohmann::json::array();
      for (const auto& p : l.points) pts.push_back({p.x(), p.y(), p.z()});
      nlohmann::json o{{"points", pts}, {"closed", l.closed}};
      if (!l.radii.empty()) o["radii"] = l.radii;
      arr.push_back(o);
    }
    os << nlohmann::json{{"polylines", arr}}.dump(1) << '\n';
  } else {
    requireExt(path, ext, ".vtk or .json");
  }
  writeFileAtomically(path, os.str());
}

static std::vector<Polyline> readPolylinesImpl(const std::string& path) {
  const std::string ext = lowerExt(path);
  std::vector<Polyline> out;
  if (ext == ".vtk") {
    out = readPolyDataFile(path).lines;
  } else if (ext == ".json") {
    try {
      const auto j = nlohmann::json::parse(readFileBytes(path, false));
      for (const auto& o : j.at("polylines")) {
        Polyline pl;
        for (const auto& p : o.at("points"))
          pl.points.emplace_back(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
        pl.closed = o.value("closed", false);
        if (o.contains("radii")) pl.radii = o.at("radii").get<std::vector<double>>();
        if (!pl.radii.empty() && pl.radii.size() != pl.points.size())
          throw IoError(path + ": radius count differs from point count");
        out.push_back(std::move(pl));
      }
    } catch (const nlohmann::json::exception& e) {
      throw IoError(path + ": bad polyline JSON: " + oneLine(e.what()));
    }
  } else {
    requireExt(path, ext, ".vtk or .json");
  }
  return out;
}

namespace {
template <class F>
auto guarded(const std::string& path, F&& f) {
  try {
    return f();
  } catch (const std::logic_error& e) {  // std::stoi & co. on a malformed header field
    throw IoError(path + ": malformed file (" + oneLine(e.what()) + ")");
  } catch (const std::bad_alloc&) {
    throw IoError(path + ": out of memory while reading");
  }
}
}  // namespace

TriMesh readTriMesh(const std::string& path) {
  return guarded(path, [&] { return readTriMeshImpl(path); });
}
Tree readTree(const std::string& path) {
  return guarded(path, [&] { return readTreeImpl(path); });
}
std::vector<Polyline> readPolylines(const std::string& path) {
  return guarded(path, [&] { return readPolylinesImpl(path); });
}

}  // namespace vs
