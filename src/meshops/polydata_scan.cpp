#include "meshops/polydata_scan.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "util/error.h"

namespace vs::polydata_detail {

namespace {

std::vector<std::string> wordsOf(const std::string& s, size_t begin, size_t end) {
  std::istringstream in(s.substr(begin, end - begin));
  std::vector<std::string> w;
  for (std::string t; in >> t;) w.push_back(t);
  return w;
}

// A count as the header writes it: a whole non-negative decimal integer, else -1 (not a count:
// a binary blob that looks like a keyword line, or a malformed header VTK itself refuses).
double countOf(const std::string& word) {
  if (word.empty() || word.size() > 19 ||
      !std::all_of(word.begin(), word.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }))
    return -1;
  return static_cast<double>(std::strtoull(word.c_str(), nullptr, 10));
}

// Bytes a binary value of VTK's legacy type name takes (0: a name VTK refuses itself).
double binarySize(std::string type) {
  std::transform(type.begin(), type.end(), type.begin(), [](unsigned char c) { return std::tolower(c); });
  if (type == "bit") return 0.125;
  if (type == "char" || type == "unsigned_char" || type == "signed_char" || type == "vtktypeint8" ||
      type == "vtktypeuint8")
    return 1;
  if (type == "short" || type == "unsigned_short" || type == "vtktypeint16" || type == "vtktypeuint16") return 2;
  if (type == "int" || type == "unsigned_int" || type == "float" || type == "vtktypeint32" || type == "vtktypeuint32" ||
      type == "vtktypefloat32")
    return 4;
  if (type == "long" || type == "unsigned_long" || type == "double" || type == "vtkidtype" || type == "vtktypeint64" ||
      type == "vtktypeuint64" || type == "vtktypefloat64" || type == "long_long" || type == "unsigned_long_long")
    return 8;
  return 0;
}

class CountCheck {
 public:
  CountCheck(const std::string& path, bool binary) : path_(path), binary_(binary) {}
  double left = 0;  // bytes after the keyword line being checked

  // `count` items of `valuesPerItem` values of `type` must fit in the bytes left.
  void need(const std::string& what, double count, double valuesPerItem, const std::string& type) const {
    if (count < 0 || valuesPerItem < 0) return;  // not a count: VTK refuses the header itself
    const double perValue = binary_ ? binarySize(type) : 2.0;
    if (count * valuesPerItem * perValue > left + 1)
      throw IoError(path_ + ": " + what + " count " + countText(count) + " is not possible with " + countText(left) +
                    " bytes left (truncated or corrupt)");
  }

 private:
  static std::string countText(double v) {
    std::ostringstream os;
    os.precision(20);
    os << v;
    return os.str();
  }
  const std::string& path_;
  bool binary_;
};

}  // namespace

void checkLegacyVtkCounts(const std::string& path, const std::string& s) {
  if (s.rfind("# vtk DataFile", 0) != 0) throw IoError(path + ": wrong magic, not a legacy VTK file");
  // Lines 1-2: magic and title; line 3: ASCII or BINARY.
  size_t pos = 0;
  std::vector<std::string> mode;
  for (int lineNo = 0; lineNo < 3; ++lineNo) {
    const size_t end = std::min(s.find('\n', pos), s.size());
    if (lineNo == 2) mode = wordsOf(s, pos, end);
    pos = std::min(end + 1, s.size());
  }
  std::string m = mode.empty() ? "" : mode[0];
  std::transform(m.begin(), m.end(), m.begin(), [](unsigned char c) { return std::toupper(c); });
  if (m != "ASCII" && m != "BINARY") throw IoError(path + ": expected ASCII or BINARY on the third line");
  const bool binary = m == "BINARY";
  CountCheck check(path, binary);
  double tuples = -1;  // the count of the current POINT_DATA or CELL_DATA section
  // Every line that starts with a keyword VTK reads counts from (binary data between them may
  // hold newlines: a blob that happens to look like a keyword line is checked the same way).
  while (pos < s.size()) {
    const size_t end = std::min(s.find('\n', pos), s.size());
    const size_t begin = pos;
    pos = std::min(end + 1, s.size());
    check.left = static_cast<double>(s.size() - pos);
    if (end - begin > 256 || !std::isalpha(static_cast<unsigned char>(s[begin]))) continue;
    const auto w = wordsOf(s, begin, end);
    if (w.empty()) continue;
    const std::string& k = w[0];
    auto at = [&](size_t i) { return i < w.size() ? countOf(w[i]) : -1.0; };
    auto word = [&](size_t i) { return i < w.size() ? w[i] : std::string(); };
    if (k == "POINTS") {
      if (at(1) > 2147483647.0) throw IoError(path + ": POINTS count " + w[1] + " is more than 2^31 - 1");
      check.need("POINTS", at(1), 3, word(2));
    } else if (k == "POLYGONS" || k == "LINES" || k == "VERTICES" || k == "TRIANGLE_STRIPS") {
      // Legacy: k cells in SIZE ints; 5.1: k+1 offsets and SIZE connectivity ids (at least 4 bytes).
      check.need(k, std::max(at(1), at(2)), 1, "int");
    } else if (k == "POINT_DATA" || k == "CELL_DATA") {
      tuples = at(1);
    } else if (k == "SCALARS") {
      check.need("SCALARS", tuples, w.size() > 3 ? at(3) : 1, word(2));
    } else if (k == "COLOR_SCALARS") {
      check.need("COLOR_SCALARS", tuples, at(2), binary ? "unsigned_char" : "float");
    } else if (k == "LOOKUP_TABLE" && w.size() > 2) {
      check.need("LOOKUP_TABLE", at(2), 4, binary ? "unsigned_char" : "float");
    } else if (k == "VECTORS" || k == "NORMALS") {
      check.need(k, tuples, 3, word(2));
    } else if (k == "TEXTURE_COORDINATES") {
      check.need(k, tuples, at(2), word(3));
    } else if (k == "TENSORS" || k == "TENSORS6") {
      check.need(k, tuples, k == "TENSORS" ? 9 : 6, word(2));
    } else if (k == "GLOBAL_IDS" || k == "PEDIGREE_IDS") {
      check.need(k, tuples, 1, word(2));
    } else if (w.size() == 4 && at(1) >= 0 && at(2) >= 0 && binarySize(w[3]) > 0) {
      check.need("FIELD array " + k, at(2), at(1), w[3]);  // "NAME COMPONENTS TUPLES TYPE"
    }
  }
}

void checkStlSize(const std::string& path, const std::string& s) {
  uint32_t n = 0;
  if (s.size() >= 84) std::memcpy(&n, s.data() + 80, 4);  // little-endian hosts (as VTK's reader)
  if (s.size() >= 84 && s.size() == 84 + static_cast<uint64_t>(n) * 50) return;
  if (s.rfind("solid", 0) == 0) return;
  if (s.size() < 84) throw IoError(path + ": truncated STL file (" + std::to_string(s.size()) + " bytes)");
  throw IoError(path + ": STL size does not match its triangle count " + std::to_string(n) + " (truncated?)");
}

}  // namespace vs::polydata_detail
