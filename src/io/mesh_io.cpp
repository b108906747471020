// Mesh, tree and polyline files without ITK: OBJ, binary PLY, binary STL, legacy VTK
// polydata, SWC and JSON. Writers validate the input (InvalidArgument), write atomically
// and keep coordinates as given (world mm). Readers throw IoError naming the file.
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

// ------------------------------------------------------------------ legacy VTK polydata
struct PolyData {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<int32_t>> polys, lines;
  std::map<std::string, std::vector<double>> scalars;  // point data
  std::vector<Eigen::Vector3d> normals;
};

std::string vtkHeader(const std::string& title) {
  return "# vtk DataFile Version 3.0\n" + title + "\nASCII\nDATASET POLYDATA\n";
}

void appendPoints(std::ostringstream& os, const std::vector<Eigen::Vector3d>& pts) {
  os << "POINTS " << pts.size() << " double\n";
  for (const auto& p : pts) os << num(p.x()) << ' ' << num(p.y()) << ' ' << num(p.z()) << '\n';
}

void appendCells(std::ostringstream& os, const std::string& kw, const std::vector<std::vector<int32_t>>& cells) {
  size_t total = 0;
  for (const auto& c : cells) total += c.size() + 1;
  os << kw << ' ' << cells.size() << ' ' << total << '\n';
  for (const auto& c : cells) {
    os << c.size();
    for (int32_t i : c) os << ' ' << i;
    os << '\n';
  }
}

// The legacy VTK polydata reader's cursor over the file's bytes: lines, words, and numbers in the
// file's encoding (ASCII or big-endian binary), with every count checked against the bytes left.
class PolyDataParser {
 public:
  PolyDataParser(const std::string& path) : path_(path), s_(readFileBytes(path)) {}
  PolyData parse();

 private:
  const std::string& path_;
  const std::string s_;
  size_t pos_ = 0;
  bool binary_ = false;

  std::string line() {
    if (pos_ >= s_.size()) throw IoError(path_ + ": unexpected end of file (truncated)");
    size_t e = s_.find('\n', pos_);
    if (e == std::string::npos) e = s_.size();
    std::string l = s_.substr(pos_, e - pos_);
    pos_ = std::min(e + 1, s_.size());
    return l;
  }
  std::vector<std::string> words() {
    while (true) {
      auto w = splitWords(line());
      if (!w.empty()) return w;
    }
  }
  double number(const std::string& type) {
    if (!binary_) {
      while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
      if (pos_ >= s_.size()) throw IoError(path_ + ": truncated ASCII data");
      char* e = nullptr;
      const double v = std::strtod(s_.c_str() + pos_, &e);
      if (e == s_.c_str() + pos_) throw IoError(path_ + ": bad number near byte " + std::to_string(pos_));
      pos_ = static_cast<size_t>(e - s_.c_str());
      return v;
    }
    const size_t n = type == "double" || type == "vtktypeint64" || type == "long" ? 8
                     : type == "short" || type == "unsigned_short"                ? 2
                     : type == "char" || type == "unsigned_char" || type == "bit" ? 1
                                                                                  : 4;
    if (pos_ + n > s_.size()) throw IoError(path_ + ": truncated binary data");
    char b[8];
    std::memcpy(b, s_.data() + pos_, n);
    pos_ += n;
    if (hostIsLittleEndian()) std::reverse(b, b + n);
    auto as = [&](auto v) {
      std::memcpy(&v, b, sizeof v);
      return static_cast<double>(v);
    };
    if (type == "float") return as(float{});
    if (type == "double") return as(double{});
    if (type == "int") return as(int32_t{});
    if (type == "unsigned_int") return as(uint32_t{});
    if (type == "short") return as(int16_t{});
    if (type == "unsigned_short") return as(uint16_t{});
    if (type == "char") return as(int8_t{});
    if (type == "unsigned_char") return as(uint8_t{});
    if (type == "vtktypeint64" || type == "long") return as(int64_t{});
    throw IoError(path_ + ": unsupported binary type '" + type + "'");
  }
  // Counts from the file are checked against the bytes left before anything is allocated:
  // every value takes at least one byte, binary or ASCII.
  void requireValues(int64_t count, int64_t perItem, const std::string& what) {
    const uint64_t left = s_.size() - std::min(pos_, s_.size());
    if (count < 0 || perItem < 0 ||
        (perItem > 0 && static_cast<uint64_t>(count) > (left + 1) / static_cast<uint64_t>(perItem)))
      throw IoError(path_ + ": " + what + " count " + std::to_string(count) + " is not possible with " +
                    std::to_string(left) + " bytes left (truncated or corrupt)");
  }
  int64_t integer(double v, double lo, double hi, const std::string& what) {
    if (!(v >= lo && v <= hi)) throw IoError(path_ + ": " + what + " out of range");
    return static_cast<int64_t>(v);
  }
  // A POLYGONS, LINES, VERTICES or TRIANGLE_STRIPS section whose keyword line is `kw`.
  void readCells(const std::vector<std::string>& kw, PolyData& pd) {
    const std::string& k = kw[0];
    if (kw.size() < 3) throw IoError(path_ + ": malformed " + k + " line");
    const auto n = std::stoll(kw[1]);
    const auto size = std::stoll(kw[2]);
    if (n < 0 || size < 0 || size > (int64_t{1} << 32)) throw IoError(path_ + ": absurd cell count");
    auto pointId = [&](double v) {
      return static_cast<int32_t>(integer(v, 0, static_cast<double>(pd.points.size()) - 1, "point index"));
    };
    // Version 5.1 (current VTK): "k OFFSETS+1 CONNECTIVITY_SIZE", then an OFFSETS and a
    // CONNECTIVITY array; older versions: per cell its size and its point ids.
    std::vector<std::vector<int32_t>> cells;
    const size_t beforeOffsets = pos_;
    std::vector<std::string> next;
    try {
      next = words();
    } catch (const IoError&) {
      next = {""};  // end of file right after an empty cell list
    }
    if (next[0] == "OFFSETS") {
      if (next.size() < 2 || n < 1 || n > size + 1) throw IoError(path_ + ": malformed " + k + " OFFSETS");
      requireValues(n, 1, k + " OFFSETS");
      std::vector<int64_t> offsets(static_cast<size_t>(n));
      for (auto& o : offsets) o = integer(number(next[1]), 0, static_cast<double>(size), "cell offset");
      const auto conn = words();
      if (conn[0] != "CONNECTIVITY" || conn.size() < 2) throw IoError(path_ + ": expected CONNECTIVITY after OFFSETS");
      requireValues(size, 1, k + " CONNECTIVITY");
      std::vector<int32_t> ids(static_cast<size_t>(size));
      for (auto& id : ids) id = pointId(number(conn[1]));
      for (size_t c = 0; c + 1 < offsets.size(); ++c) {
        if (offsets[c + 1] < offsets[c]) throw IoError(path_ + ": cell offsets decrease");
        cells.emplace_back(ids.begin() + offsets[c], ids.begin() + offsets[c + 1]);
      }
    } else {
      pos_ = beforeOffsets;
      requireValues(n, 1, k);
      for (int64_t c = 0; c < n; ++c) {
        const int64_t cnt = integer(number("int"), 0, static_cast<double>(size), "cell size");
        requireValues(cnt, 1, k);
        std::vector<int32_t> ids(static_cast<size_t>(cnt));
        for (auto& id : ids) id = pointId(number("int"));
        cells.push_back(std::move(ids));
      }
    }
    for (auto& ids : cells) {
      if (k == "POLYGONS")
        pd.polys.push_back(std::move(ids));
      else if (k == "LINES")
        pd.lines.push_back(std::move(ids));
      else if (k == "TRIANGLE_STRIPS")
        for (size_t t = 0; t + 2 < ids.size(); ++t)
          pd.polys.push_back(t % 2 == 0 ? std::vector<int32_t>{ids[t], ids[t + 1], ids[t + 2]}
                                        : std::vector<int32_t>{ids[t + 1], ids[t], ids[t + 2]});
    }
  }
};

PolyData PolyDataParser::parse() {
  const std::string& s = s_;
  const std::string& path = path_;
  size_t& pos = pos_;
  if (s.rfind("# vtk DataFile", 0) != 0) throw IoError(path + ": wrong magic, not a legacy VTK file");
  line();
  line();
  const auto modeW = words();
  std::string mode = modeW[0];
  std::transform(mode.begin(), mode.end(), mode.begin(), ::toupper);
  binary_ = mode == "BINARY";
  if (!binary_ && mode != "ASCII") throw IoError(path + ": expected ASCII or BINARY");
  auto w = words();
  if (w.size() < 2 || w[1] != "POLYDATA") throw IoError(path + ": legacy VTK dataset is not POLYDATA");
  PolyData pd;
  int64_t section = -1;
  bool pointSection = false;
  while (pos < s.size()) {
    const size_t save = pos;
    std::vector<std::string> kw;
    try {
      kw = words();
    } catch (const IoError&) {
      break;  // trailing blank lines
    }
    (void)save;
    const std::string k = kw[0];
    if (k == "POINTS") {
      if (kw.size() < 3) throw IoError(path + ": malformed POINTS line");
      const auto n = std::stoll(kw[1]);
      if (n < 0 || n > (int64_t{1} << 31)) throw IoError(path + ": absurd point count");
      requireValues(n, 3, "POINTS");
      pd.points.resize(static_cast<size_t>(n));
      for (auto& p : pd.points)
        for (int c = 0; c < 3; ++c) p[c] = number(kw[2]);
    } else if (k == "POLYGONS" || k == "LINES" || k == "VERTICES" || k == "TRIANGLE_STRIPS") {
      readCells(kw, pd);
    } else if (k == "POINT_DATA" || k == "CELL_DATA") {
      section = std::stoll(kw.at(1));
      if (section < 0) throw IoError(path + ": negative " + k + " count");
      pointSection = k == "POINT_DATA";
    } else if (k == "SCALARS") {
      if (kw.size() < 3 || section < 0) throw IoError(path + ": malformed SCALARS");
      const int nc = kw.size() > 3 ? std::stoi(kw[3]) : 1;
      if (nc < 1 || nc > 16) throw IoError(path + ": bad number of SCALARS components");
      const size_t save2 = pos;
      const auto lt = words();
      if (lt[0] != "LOOKUP_TABLE") pos = save2;
      requireValues(section, nc, "SCALARS");
      std::vector<double> v(static_cast<size_t>(section) * static_cast<size_t>(nc));
      for (auto& x : v) x = number(kw[2]);
      if (pointSection && nc == 1) pd.scalars[kw[1]] = std::move(v);
    } else if (k == "NORMALS" || k == "VECTORS") {
      if (kw.size() < 3 || section < 0) throw IoError(path + ": malformed " + k);
      requireValues(section, 3, k);
      std::vector<Eigen::Vector3d> v(static_cast<size_t>(section));
      for (auto& p : v)
        for (int c = 0; c < 3; ++c) p[c] = number(kw[2]);
      if (pointSection && k == "NORMALS") pd.normals = std::move(v);
    } else if (k == "FIELD") {
      const int arrays = std::stoi(kw.at(2));
      for (int a = 0; a < arrays; ++a) {
        const auto fw = words();
        if (fw.size() < 4) throw IoError(path + ": malformed FIELD array");
        const int64_t comps = std::stoll(fw[1]), tuples = std::stoll(fw[2]);
        if (comps < 0 || tuples < 0 || comps > 64) throw IoError(path + ": malformed FIELD array size");
        requireValues(tuples, comps, "FIELD array");
        const int64_t cnt = comps * tuples;
        std::vector<double> v(static_cast<size_t>(cnt));
        for (auto& x : v) x = number(fw[3]);
        if (pointSection && std::stoll(fw[1]) == 1) pd.scalars[fw[0]] = std::move(v);
      }
    } else if (k == "METADATA") {
      while (pos < s.size() && !line().empty()) {
      }
    } else {
      throw IoError(path + ": unexpected keyword '" + k + "'");
    }
  }
  return pd;
}

PolyData readPolyData(const std::string& path) { return PolyDataParser(path).parse(); }

void requireExt(const std::string& path, const std::string& ext, const std::string& allowed) {
  throw IoError(path + ": unsupported extension '" + ext + "' (use " + allowed + ")");
}

}  // namespace

void writeTriMesh(const TriMesh& mesh, const std::string& path) {
  mesh.validate();
  const std::string ext = lowerExt(path);
  std::string bytes;
  if (ext == ".obj")
    bytes = objText(mesh);
  else if (ext == ".ply")
    bytes = plyBytes(mesh);
  else if (ext == ".stl")
    bytes = stlBytes(mesh);
  else if (ext == ".vtk") {
    std::ostringstream os;
    os << vtkHeader("volscissors triangle mesh (world mm)");
    appendPoints(os, mesh.positions);
    std::vector<std::vector<int32_t>> cells;
    cells.reserve(mesh.triangles.size());
    for (const auto& t : mesh.triangles) cells.push_back({t[0], t[1], t[2]});
    appendCells(os, "POLYGONS", cells);
    if (!mesh.normals.empty()) {
      os << "POINT_DATA " << mesh.positions.size() << "\nNORMALS normals double\n";
      for (const auto& n : mesh.normals) os << num(n.x()) << ' ' << num(n.y()) << ' ' << num(n.z()) << '\n';
    }
    bytes = os.str();
  } else {
    requireExt(path, ext, ".obj, .ply, .stl or .vtk");
  }
  writeFileAtomically(path, bytes);
}

static TriMesh readTriMeshImpl(const std::string& path) {
  const std::string ext = lowerExt(path);
  TriMesh m;
  if (ext == ".obj")
    m = readObj(path);
  else if (ext == ".ply")
    m = readPly(path);
  else if (ext == ".stl")
    m = readStl(path);
  else if (ext == ".vtk") {
    PolyData pd = readPolyData(path);
    m.positions = std::move(pd.points);
    for (const auto& p : pd.polys)
      for (size_t k = 1; k + 1 < p.size(); ++k) m.triangles.push_back({p[0], p[k], p[k + 1]});
    if (pd.normals.size() == m.positions.size()) m.normals = std::move(pd.normals);
  } else {
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
  } else if (ext == ".vtk") {
    os << vtkHeader("volscissors tree (world mm); each line is parent -> child");
    appendPoints(os, tree.points);
    std::vector<std::vector<int32_t>> cells;
    for (size_t i = 0; i < n; ++i)
      if (tree.parent[i] >= 0) cells.push_back({tree.parent[i], static_cast<int32_t>(i)});
    appendCells(os, "LINES", cells);
    os << "POINT_DATA " << n << "\nSCALARS radius double 1\nLOOKUP_TABLE default\n";
    for (size_t i = 0; i < n; ++i) os << num(radius(i)) << '\n';
    os << "SCALARS type int 1\nLOOKUP_TABLE default\n";
    for (size_t i = 0; i < n; ++i) os << type(i) << '\n';
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
    PolyData pd = readPolyData(path);
    t.points = std::move(pd.points);
    t.parent.assign(t.points.size(), -1);
    for (const auto& l : pd.lines)
      for (size_t k = 0; k + 1 < l.size(); ++k) {
        if (t.parent[static_cast<size_t>(l[k + 1])] >= 0 && t.parent[static_cast<size_t>(l[k + 1])] != l[k])
          throw IoError(path + ": point " + std::to_string(l[k + 1]) + " has two parents (not a tree)");
        t.parent[static_cast<size_t>(l[k + 1])] = l[k];
      }
    if (pd.scalars.count("radius") && pd.scalars["radius"].size() == t.points.size()) t.radii = pd.scalars["radius"];
    if (pd.scalars.count("type") && pd.scalars["type"].size() == t.points.size())
      for (double v : pd.scalars["type"]) t.types.push_back(static_cast<int32_t>(v));
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
  if (ext == ".vtk") {
    os << vtkHeader("volscissors polylines (world mm); closed lines repeat their first point id");
    std::vector<Eigen::Vector3d> pts;
    std::vector<std::vector<int32_t>> cells;
    bool allRadii = !lines.empty();
    for (const auto& l : lines) {
      std::vector<int32_t> ids;
      for (const auto& p : l.points) {
        ids.push_back(static_cast<int32_t>(pts.size()));
        pts.push_back(p);
      }
      if (l.closed && ids.size() > 2) ids.push_back(ids.front());
      cells.push_back(std::move(ids));
      allRadii = allRadii && l.radii.size() == l.points.size() && !l.points.empty();
    }
    appendPoints(os, pts);
    appendCells(os, "LINES", cells);
    if (allRadii) {
      os << "POINT_DATA " << pts.size() << "\nSCALARS radius double 1\nLOOKUP_TABLE default\n";
      for (const auto& l : lines)
        for (double r : l.radii) os << num(r) << '\n';
    }
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
    PolyData pd = readPolyData(path);
    const auto* radius =
        pd.scalars.count("radius") && pd.scalars["radius"].size() == pd.points.size() ? &pd.scalars["radius"] : nullptr;
    for (const auto& l : pd.lines) {
      Polyline pl;
      std::vector<int32_t> ids = l;
      if (ids.size() > 3 && ids.front() == ids.back()) {
        pl.closed = true;
        ids.pop_back();
      }
      for (int32_t id : ids) {
        pl.points.push_back(pd.points[static_cast<size_t>(id)]);
        if (radius) pl.radii.push_back((*radius)[static_cast<size_t>(id)]);
      }
      out.push_back(std::move(pl));
    }
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
