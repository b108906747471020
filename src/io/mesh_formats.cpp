// Triangle meshes as OBJ (text) and binary little-endian PLY (mesh_io.h). Readers
// throw IoError naming the file and line or element.
#include "io/mesh_io_internal.h"

namespace vs::mesh_io_detail {

// ------------------------------------------------------------------ OBJ
std::string objText(const TriMesh& m) {
  std::ostringstream os;
  os << std::setprecision(17) << "# volscissors triangle mesh (world mm)\n";
  for (const auto& p : m.positions) os << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& n : m.normals) os << "vn " << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
  const bool hasN = !m.normals.empty();
  for (const auto& t : m.triangles) {
    os << 'f';
    for (int32_t i : t) {
      os << ' ' << i + 1;
      if (hasN) os << "//" << i + 1;
    }
    os << '\n';
  }
  return os.str();
}

TriMesh readObj(const std::string& path) {
  const std::string text = readFileBytes(path, false);
  std::istringstream in(text);
  TriMesh m;
  std::vector<Eigen::Vector3d> vn;
  bool normalsMatch = true;
  std::string line;
  size_t lineNo = 0;
  auto resolve = [&](long long i, size_t count) -> int32_t {
    const long long r = i < 0 ? static_cast<long long>(count) + i : i - 1;
    if (i == 0 || r < 0 || r >= static_cast<long long>(count))
      throw IoError(path + ":" + std::to_string(lineNo) + ": index " + std::to_string(i) + " out of range");
    return static_cast<int32_t>(r);
  };
  while (std::getline(in, line)) {
    ++lineNo;
    const auto w = splitWords(line);
    if (w.empty() || w[0][0] == '#') continue;
    if (w[0] == "v") {
      if (w.size() < 4) throw IoError(path + ":" + std::to_string(lineNo) + ": vertex needs 3 coordinates");
      m.positions.emplace_back(toDouble(w[1], path, lineNo), toDouble(w[2], path, lineNo),
                               toDouble(w[3], path, lineNo));
    } else if (w[0] == "vn") {
      if (w.size() < 4) throw IoError(path + ":" + std::to_string(lineNo) + ": normal needs 3 coordinates");
      vn.emplace_back(toDouble(w[1], path, lineNo), toDouble(w[2], path, lineNo), toDouble(w[3], path, lineNo));
    } else if (w[0] == "f") {
      if (w.size() < 4) throw IoError(path + ":" + std::to_string(lineNo) + ": face needs at least 3 vertices");
      std::vector<int32_t> idx;
      for (size_t k = 1; k < w.size(); ++k) {
        const std::string& tok = w[k];
        const int32_t vi = resolve(toInt(tok.substr(0, tok.find('/')), path, lineNo), m.positions.size());
        idx.push_back(vi);
        const size_t s2 = tok.rfind('/');
        if (s2 != std::string::npos && s2 + 1 < tok.size() && tok.find('/') != s2) {
          const int32_t ni = resolve(toInt(tok.substr(s2 + 1), path, lineNo), vn.size());
          if (ni != vi) normalsMatch = false;
        } else if (!vn.empty()) {
          normalsMatch = false;
        }
      }
      for (size_t k = 1; k + 1 < idx.size(); ++k) m.triangles.push_back({idx[0], idx[k], idx[k + 1]});
    }
  }
  if (!vn.empty() && normalsMatch && vn.size() == m.positions.size()) m.normals = vn;
  return m;
}

// ------------------------------------------------------------------ PLY
std::string plyBytes(const TriMesh& m) {
  const bool hasN = !m.normals.empty();
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment volscissors triangle mesh (world mm)\n"
    << "element vertex " << m.positions.size() << "\nproperty double x\nproperty double y\nproperty double z\n";
  if (hasN) h << "property float nx\nproperty float ny\nproperty float nz\n";
  h << "element face " << m.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::string out = h.str();
  out.reserve(out.size() + m.positions.size() * 36 + m.triangles.size() * 13);
  for (size_t i = 0; i < m.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) put<double>(out, m.positions[i][k]);
    if (hasN)
      for (int k = 0; k < 3; ++k) put<float>(out, static_cast<float>(m.normals[i][k]));
  }
  for (const auto& t : m.triangles) {
    put<uint8_t>(out, 3);
    for (int32_t i : t) put<int32_t>(out, i);
  }
  return out;
}

struct PlyProp {
  std::string name, type, countType;  // countType non-empty: list
};
struct PlyElem {
  std::string name;
  size_t count = 0;
  std::vector<PlyProp> props;
};

size_t plySize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double plyValue(const char* p, const std::string& t, bool swap) {
  char b[8];
  const size_t n = plySize(t);
  std::memcpy(b, p, n);
  if (swap) std::reverse(b, b + n);
  auto as = [&](auto v) {
    std::memcpy(&v, b, sizeof v);
    return static_cast<double>(v);
  };
  if (t == "char" || t == "int8") return as(int8_t{});
  if (t == "uchar" || t == "uint8") return as(uint8_t{});
  if (t == "short" || t == "int16") return as(int16_t{});
  if (t == "ushort" || t == "uint16") return as(uint16_t{});
  if (t == "int" || t == "int32") return as(int32_t{});
  if (t == "uint" || t == "uint32") return as(uint32_t{});
  if (t == "float" || t == "float32") return as(float{});
  return as(double{});
}

TriMesh readPly(const std::string& path) {
  const std::string s = readFileBytes(path, false);
  if (s.rfind("ply", 0) != 0) throw IoError(path + ": wrong magic, not a PLY file");
  const size_t endH = s.find("end_header");
  if (endH == std::string::npos) throw IoError(path + ": PLY header has no end_header (truncated)");
  size_t pos = s.find('\n', endH);
  if (pos == std::string::npos) throw IoError(path + ": truncated PLY file");
  ++pos;
  std::istringstream hs(s.substr(0, endH));
  std::string line, format;
  std::vector<PlyElem> elems;
  while (std::getline(hs, line)) {
    const auto w = splitWords(line);
    if (w.empty()) continue;
    if (w[0] == "format" && w.size() >= 2)
      format = w[1];
    else if (w[0] == "element" && w.size() >= 3) {
      // Every element with a property takes at least one byte of the file: a larger count is
      // corrupt (and a count of 2^64 with no properties would loop for ever).
      char* end = nullptr;
      errno = 0;
      const long long count = std::strtoll(w[2].c_str(), &end, 10);
      if (errno != 0 || end != w[2].c_str() + w[2].size() || count < 0 || static_cast<uint64_t>(count) > s.size())
        throw IoError(path + ": PLY element '" + w[1] + "' count '" + w[2] + "' is not possible in a file of " +
                      std::to_string(s.size()) + " bytes");
      elems.push_back({w[1], static_cast<size_t>(count), {}});
    } else if (w[0] == "property" && !elems.empty()) {
      if (w.size() >= 5 && w[1] == "list")
        elems.back().props.push_back({w[4], w[3], w[2]});
      else if (w.size() >= 3)
        elems.back().props.push_back({w[2], w[1], ""});
    }
  }
  const bool ascii = format == "ascii";
  if (!ascii && format != "binary_little_endian" && format != "binary_big_endian")
    throw IoError(path + ": unsupported PLY format '" + format + "'");
  const bool swap = !ascii && ((format == "binary_big_endian") == hostIsLittleEndian());
  TriMesh m;
  std::istringstream as(ascii ? s.substr(pos) : std::string());
  auto next = [&](const std::string& type) -> double {
    if (ascii) {
      double v;
      if (!(as >> v)) throw IoError(path + ": truncated PLY data");
      return v;
    }
    const size_t n = plySize(type);
    if (n == 0) throw IoError(path + ": unsupported PLY property type '" + type + "'");
    if (pos + n > s.size()) throw IoError(path + ": truncated PLY data");
    const double v = plyValue(s.data() + pos, type, swap);
    pos += n;
    return v;
  };
  for (const auto& e : elems) {
    const bool isV = e.name == "vertex", isF = e.name == "face";
    if (isV) {
      if (e.count > (size_t{1} << 31)) throw IoError(path + ": absurd vertex count");
      m.positions.assign(e.count, Eigen::Vector3d::Zero());
    }
    bool hasN = false;
    for (const auto& p : e.props) hasN |= isV && p.name == "nx";
    if (hasN) m.normals.assign(e.count, Eigen::Vector3d::Zero());
    if (e.props.empty()) continue;  // nothing stored per element
    for (size_t i = 0; i < e.count; ++i) {
      for (const auto& p : e.props) {
        if (!p.countType.empty()) {
          const double cntValue = next(p.countType);  // range-checked before any integer cast
          if (!(cntValue >= 0 && cntValue <= 1000000)) throw IoError(path + ": bad PLY list length");
          std::vector<int32_t> idx(static_cast<size_t>(cntValue));
          for (auto& v : idx) {
            const double index = next(p.type);
            if (!(index >= -2147483648.0 && index <= 2147483647.0))
              throw IoError(path + ": PLY vertex index out of range");
            v = static_cast<int32_t>(index);
          }
          if (isF && (p.name == "vertex_indices" || p.name == "vertex_index"))
            for (size_t k = 1; k + 1 < idx.size(); ++k) m.triangles.push_back({idx[0], idx[k], idx[k + 1]});
        } else {
          const double v = next(p.type);
          if (isV) {
            if (p.name == "x")
              m.positions[i].x() = v;
            else if (p.name == "y")
              m.positions[i].y() = v;
            else if (p.name == "z")
              m.positions[i].z() = v;
            else if (p.name == "nx")
              m.normals[i].x() = v;
            else if (p.name == "ny")
              m.normals[i].y() = v;
            else if (p.name == "nz")
              m.normals[i].z() = v;
          }
        }
      }
    }
  }
  checkIndices(m, path);
  return m;
}

}  // namespace vs::mesh_io_detail
