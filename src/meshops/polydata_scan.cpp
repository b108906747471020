#include "meshops/polydata_scan.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "util/error.h"

namespace vs::polydata_detail {

namespace {

std::vector<std::string> wordsOf(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  for (std::string t; in >> t;) w.push_back(t);
  return w;
}

struct PolyData {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<int32_t>> polys, lines;
  std::map<std::string, std::vector<double>> scalars;  // point data
  std::vector<Eigen::Vector3d> normals;
};

// The legacy VTK polydata reader's cursor over the file's bytes: lines, words, and numbers in the
// file's encoding (ASCII or big-endian binary), with every count checked against the bytes left.
class LegacyParser {
 public:
  LegacyParser(const std::string& path, const std::string& bytes) : path_(path), s_(bytes) {}
  PolyData parse();

 private:
  const std::string& path_;
  const std::string& s_;
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
      auto w = wordsOf(line());
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
    if ((std::endian::native == std::endian::little)) std::reverse(b, b + n);
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

PolyData LegacyParser::parse() {
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

}  // namespace

PolyDataCells readLegacyVtk(const std::string& path, const std::string& bytes) {
  PolyData pd = LegacyParser(path, bytes).parse();
  PolyDataCells c;
  c.mesh.positions = std::move(pd.points);
  for (const auto& p : c.mesh.positions)
    if (!p.allFinite()) throw IoError(path + ": a point coordinate is not finite");
  // Polygons are fanned from their first point (strips were split into triangles above).
  for (const auto& p : pd.polys)
    for (size_t k = 1; k + 1 < p.size(); ++k) c.mesh.triangles.push_back({p[0], p[k], p[k + 1]});
  if (pd.normals.size() == c.mesh.positions.size()) c.mesh.normals = std::move(pd.normals);
  c.lines = std::move(pd.lines);
  for (auto& [name, values] : pd.scalars)
    if (values.size() == c.mesh.positions.size()) c.pointScalars[name] = std::move(values);
  return c;
}

void checkStlSize(const std::string& path, const std::string& s) {
  uint32_t n = 0;
  if (s.size() >= 84) std::memcpy(&n, s.data() + 80, 4);  // little-endian hosts (as VTK's reader)
  if (s.size() >= 84 && s.size() == 84 + static_cast<uint64_t>(n) * 50) return;
  // ASCII only when every byte is printable, a newline, a return or a tab: VTK's reader takes a
  // "solid" file with other bytes (a vertical tab too) for binary and allocates the count its
  // header announces.
  if (s.rfind("solid", 0) == 0 && std::all_of(s.begin(), s.end(), [](char ch) {
        const auto c = static_cast<unsigned char>(ch);
        return (c >= 32 && c < 127) || c == '\n' || c == '\r' || c == '\t';
      }))
    return;
  if (s.size() < 84) throw IoError(path + ": truncated STL file (" + std::to_string(s.size()) + " bytes)");
  throw IoError(path + ": STL size does not match its triangle count " + std::to_string(n) + " (truncated?)");
}

}  // namespace vs::polydata_detail
