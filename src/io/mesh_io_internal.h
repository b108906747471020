// Internals of the mesh, tree and polyline files (mesh_io.h): the small parsing helpers shared by
// mesh_io.cpp (dispatch, SWC, JSON) and mesh_formats.cpp (OBJ, PLY).
#pragma once

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
#include <string>
#include <vector>

#include "io/io_internal.h"
#include "mesh/tri_mesh.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vs::mesh_io_detail {

using namespace io_detail;

inline std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

inline std::string lowerExt(const std::string& path) { return fileExtension(path); }

inline std::vector<std::string> splitWords(const std::string& line) {
  std::istringstream is(line);
  std::vector<std::string> w;
  for (std::string t; is >> t;) w.push_back(t);
  return w;
}

inline double toDouble(const std::string& s, const std::string& path, size_t lineNo) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0')
    throw IoError(path + ":" + std::to_string(lineNo) + ": '" + s + "' is not a number");
  return v;
}

inline long long toInt(const std::string& s, const std::string& path, size_t lineNo) {
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (end == s.c_str() || (*end != '\0' && *end != '/'))
    throw IoError(path + ":" + std::to_string(lineNo) + ": '" + s + "' is not an integer");
  return v;
}

template <class T>
void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (!hostIsLittleEndian()) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

inline void checkIndices(const TriMesh& m, const std::string& path) {
  const auto n = static_cast<int64_t>(m.positions.size());
  for (const auto& t : m.triangles)
    for (int32_t i : t)
      if (i < 0 || i >= n)
        throw IoError(path + ": face refers to vertex " + std::to_string(i) + " of " + std::to_string(n));
  if (!m.normals.empty() && m.normals.size() != m.positions.size())
    throw IoError(path + ": normal count differs from vertex count");
}

std::string objText(const TriMesh& m);
TriMesh readObj(const std::string& path);
std::string plyBytes(const TriMesh& m);
TriMesh readPly(const std::string& path);

}  // namespace vs::mesh_io_detail
