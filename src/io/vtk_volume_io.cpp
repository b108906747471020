// Our own readers for VTK image files (no ITK, no VTK):
//  - legacy VTK DATASET STRUCTURED_POINTS, ASCII or BINARY (big-endian), first SCALARS
//    array of the point data (other arrays such as VECTORS are skipped);
//  - VTK XML ImageData (.vti), one piece, point-data scalars stored appended (raw or base64),
//    inline binary (base64) or ascii, optionally vtkZLibDataCompressor, UInt32/UInt64 headers.
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "io/io_internal.h"

namespace vs::io_detail {

namespace {

bool vtkTypeToComp(std::string t, Comp& c) {
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  static const std::map<std::string, Comp> m = {{"unsigned_char", Comp::UInt8},
                                                {"char", Comp::Int8},
                                                {"signed_char", Comp::Int8},
                                                {"unsigned_short", Comp::UInt16},
                                                {"short", Comp::Int16},
                                                {"unsigned_int", Comp::UInt32},
                                                {"int", Comp::Int32},
                                                {"unsigned_long", Comp::UInt64},
                                                {"long", Comp::Int64},
                                                {"vtktypeint64", Comp::Int64},
                                                {"vtktypeuint64", Comp::UInt64},
                                                {"float", Comp::Float32},
                                                {"double", Comp::Float64},
                                                {"uint8", Comp::UInt8},
                                                {"int8", Comp::Int8},
                                                {"uint16", Comp::UInt16},
                                                {"int16", Comp::Int16},
                                                {"uint32", Comp::UInt32},
                                                {"int32", Comp::Int32},
                                                {"uint64", Comp::UInt64},
                                                {"int64", Comp::Int64},
                                                {"float32", Comp::Float32},
                                                {"float64", Comp::Float64}};
  auto it = m.find(t);
  if (it == m.end()) return false;
  c = it->second;
  return true;
}

template <class T>
void storeAs(double v, char* dst) {
  const T t = static_cast<T>(v);
  std::memcpy(dst, &t, sizeof(T));
}

void storeValue(Comp c, double v, char* dst) {
  switch (c) {
    case Comp::Int8:
      storeAs<int8_t>(v, dst);
      break;
    case Comp::UInt8:
      storeAs<uint8_t>(v, dst);
      break;
    case Comp::Int16:
      storeAs<int16_t>(v, dst);
      break;
    case Comp::UInt16:
      storeAs<uint16_t>(v, dst);
      break;
    case Comp::Int32:
      storeAs<int32_t>(v, dst);
      break;
    case Comp::UInt32:
      storeAs<uint32_t>(v, dst);
      break;
    case Comp::Int64:
      storeAs<int64_t>(v, dst);
      break;
    case Comp::UInt64:
      storeAs<uint64_t>(v, dst);
      break;
    case Comp::Float32:
      storeAs<float>(v, dst);
      break;
    case Comp::Float64:
      storeAs<double>(v, dst);
      break;
  }
}

// ---------------------------------------------------------------- legacy VTK
struct Cursor {
  const std::string& s;
  size_t pos = 0;
  const std::string& path;

  bool eof() const { return pos >= s.size(); }
  std::string line() {
    if (eof()) throw IoError(path + ": unexpected end of file (truncated header)");
    size_t e = s.find('\n', pos);
    if (e == std::string::npos) e = s.size();
    std::string l = s.substr(pos, e - pos);
    pos = std::min(e + 1, s.size());
    if (!l.empty() && l.back() == '\r') l.pop_back();
    return l;
  }
  // Next non-blank line split into words.
  std::vector<std::string> words() {
    while (true) {
      std::istringstream is(line());
      std::vector<std::string> w;
      std::string t;
      while (is >> t) w.push_back(t);
      if (!w.empty()) return w;
    }
  }
  double number() {
    while (pos < s.size() && std::isspace(static_cast<unsigned char>(s[pos]))) ++pos;
    if (pos >= s.size()) throw IoError(path + ": truncated ASCII data");
    const char* b = s.c_str() + pos;
    char* e = nullptr;
    const double v = std::strtod(b, &e);
    if (e == b) throw IoError(path + ": bad number in ASCII data near byte " + std::to_string(pos));
    pos += static_cast<size_t>(e - b);
    return v;
  }
};

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

// A non-negative element count from a header word; negative or non-numeric counts are
// corrupt (a negative count once wrapped to a huge size_t and made the skip go backwards).
uint64_t parseCount(const std::string& word, const std::string& path, const char* field) {
  size_t used = 0;
  long long v = 0;
  try {
    v = std::stoll(word, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != word.size() || v < 0) throw IoError(path + ": " + field + " '" + word + "' is not a non-negative count");
  return static_cast<uint64_t>(v);
}

// Checks that `count` values of size `es` can still be in the file before anything is
// allocated: binary needs the bytes, ASCII at least one digit and one separator per value.
void checkValuesFit(const Cursor& cur, bool binary, size_t es, uint64_t count) {
  const uint64_t left = cur.s.size() - std::min(cur.pos, cur.s.size());
  const uint64_t bytes = checkedMul(count, es, cur.path, "data size");
  if (binary ? bytes > left : count > left / 2 + 1)
    throw IoError(cur.path + ": truncated " + (binary ? "binary" : "ASCII") + " data (" + std::to_string(count) +
                  " values announced, " + std::to_string(left) + " bytes left)");
}

// Reads (binary) or parses (ascii) count values of type c into a native-order buffer.
std::vector<char> readValues(Cursor& cur, bool binary, Comp c, uint64_t count) {
  const size_t es = compSize(c);
  checkValuesFit(cur, binary, es, count);
  std::vector<char> buf(static_cast<size_t>(count) * es);
  if (binary) {
    std::memcpy(buf.data(), cur.s.data() + cur.pos, buf.size());
    cur.pos += buf.size();
    if (hostIsLittleEndian()) byteSwap(buf.data(), es, static_cast<size_t>(count));  // legacy VTK binary is big-endian
  } else {
    for (size_t i = 0; i < count; ++i) storeValue(c, cur.number(), buf.data() + i * es);
  }
  return buf;
}

void skipValues(Cursor& cur, bool binary, Comp c, uint64_t count) {
  checkValuesFit(cur, binary, compSize(c), count);
  if (binary) {
    cur.pos += static_cast<size_t>(count) * compSize(c);
  } else {
    for (uint64_t i = 0; i < count; ++i) cur.number();
  }
}

}  // namespace

AnyVolume readVtkLegacyVolume(const std::string& path, ReadInfo& info) {
  const std::string bytes = readFileBytes(path);
  Cursor cur{bytes, 0, path};
  if (bytes.rfind("# vtk DataFile", 0) != 0) throw IoError(path + ": wrong magic, not a legacy VTK file");
  cur.line();
  cur.line();  // title
  const std::string mode = upper(cur.words().at(0));
  if (mode != "ASCII" && mode != "BINARY") throw IoError(path + ": expected ASCII or BINARY, found '" + mode + "'");
  const bool binary = mode == "BINARY";
  auto w = cur.words();
  if (w.size() < 2 || upper(w[0]) != "DATASET") throw IoError(path + ": missing DATASET line");
  if (upper(w[1]) != "STRUCTURED_POINTS")
    throw IoError(path + ": legacy VTK " + w[1] + " is not an image (need STRUCTURED_POINTS)");
  Geometry g;
  bool haveDims = false;
  int64_t pointCount = -1;
  int64_t current = -1;  // tuples in the current attribute section (-1: none yet)
  bool inPointData = false;
  while (!cur.eof()) {
    w = cur.words();
    const std::string key = upper(w[0]);
    auto need = [&](size_t n) {
      if (w.size() < n) throw IoError(path + ": malformed '" + w[0] + "' line");
    };
    if (key == "DIMENSIONS") {
      need(4);
      for (int i = 0; i < 3; ++i) {
        g.dims[i] = static_cast<int64_t>(
            std::min<uint64_t>(parseCount(w[static_cast<size_t>(i) + 1], path, "DIMENSIONS"), uint64_t{1} << 40));
        if (g.dims[i] < 1 || g.dims[i] > (int64_t{1} << 31))
          throw IoError(path + ": absurd DIMENSIONS " + w[static_cast<size_t>(i) + 1]);
      }
      haveDims = true;
    } else if (key == "SPACING" || key == "ASPECT_RATIO") {
      need(4);
      for (int i = 0; i < 3; ++i) g.spacing[i] = std::stod(w[static_cast<size_t>(i) + 1]);
    } else if (key == "ORIGIN") {
      need(4);
      for (int i = 0; i < 3; ++i) g.origin[i] = std::stod(w[static_cast<size_t>(i) + 1]);
    } else if (key == "POINT_DATA") {
      need(2);
      pointCount = current =
          static_cast<int64_t>(std::min<uint64_t>(parseCount(w[1], path, "POINT_DATA"), uint64_t{1} << 62));
      inPointData = true;
    } else if (key == "CELL_DATA") {
      need(2);
      current = static_cast<int64_t>(std::min<uint64_t>(parseCount(w[1], path, "CELL_DATA"), uint64_t{1} << 62));
      inPointData = false;
    } else if (key == "SCALARS" && inPointData) {
      need(3);
      if (!haveDims) throw IoError(path + ": SCALARS before DIMENSIONS");
      Comp c;
      if (!vtkTypeToComp(w[2], c)) throw IoError(path + ": unsupported voxel type '" + w[2] + "'");
      const uint64_t ncomp = w.size() > 3 ? parseCount(w[3], path, "number of scalar components") : 1;
      if (ncomp < 1 || ncomp > 4)
        throw IoError(path + ": unsupported number of scalar components " + std::to_string(ncomp));
      // Each dimension is at most 2^31, so the product fits in 93 bits: check before comparing.
      const uint64_t voxels =
          checkedMul(checkedMul(static_cast<uint64_t>(g.dims[0]), static_cast<uint64_t>(g.dims[1]), path, "DIMENSIONS"),
                     static_cast<uint64_t>(g.dims[2]), path, "DIMENSIONS");
      if (pointCount < 0 || static_cast<uint64_t>(pointCount) != voxels)
        throw IoError(path + ": POINT_DATA " + std::to_string(pointCount) + " does not match DIMENSIONS");
      checkAllocation(g.dims, compSize(c) * static_cast<size_t>(ncomp), path);
      // Optional LOOKUP_TABLE line, then the data.
      const size_t save = cur.pos;
      auto lt = cur.words();
      if (upper(lt[0]) != "LOOKUP_TABLE") cur.pos = save;
      for (int i = 0; i < 3; ++i)
        if (!(g.spacing[i] > 0)) {
          info.notes.push_back("spacing along axis " + std::to_string(i) +
                               " was not positive, set to its absolute value or 1");
          g.spacing[i] = g.spacing[i] < 0 ? -g.spacing[i] : 1.0;
        }
      info.sourceType = compName(c) + (ncomp > 1 ? cat("x", std::to_string(ncomp)) : std::string());
      const auto buf = readValues(cur, binary, c, checkedMul(voxels, ncomp, path, "data size"));
      info.notes.push_back("legacy VTK: read point-data scalars '" + w[1] + "'");
      if (bytes.find("VECTORS", cur.pos) != std::string::npos)
        info.notes.push_back("legacy VTK: other arrays (VECTORS...) ignored");
      return convertBuffer(buf.data(), c, static_cast<int>(ncomp), g, info, path);
    } else if (key == "SCALARS") {
      need(3);
      Comp c;
      if (!vtkTypeToComp(w[2], c)) throw IoError(path + ": unsupported type '" + w[2] + "'");
      const uint64_t ncomp = w.size() > 3 ? parseCount(w[3], path, "number of components") : 1;
      if (current < 0) throw IoError(path + ": SCALARS outside POINT_DATA/CELL_DATA");
      const size_t save = cur.pos;
      if (upper(cur.words()[0]) != "LOOKUP_TABLE") cur.pos = save;
      skipValues(cur, binary, c, checkedMul(static_cast<uint64_t>(current), ncomp, path, "SCALARS size"));
    } else if (key == "VECTORS" || key == "NORMALS" || key == "TENSORS" || key == "TEXTURE_COORDINATES") {
      const size_t typeAt = key == "TEXTURE_COORDINATES" ? 3 : 2;
      need(typeAt + 1);
      Comp c;
      if (!vtkTypeToComp(w[typeAt], c)) throw IoError(path + ": unsupported type '" + w[typeAt] + "'");
      const uint64_t per = key == "TENSORS"               ? 9
                           : key == "TEXTURE_COORDINATES" ? parseCount(w[2], path, "TEXTURE_COORDINATES dimension")
                                                          : 3;
      if (current < 0) throw IoError(path + ": " + key + " outside POINT_DATA/CELL_DATA");
      skipValues(cur, binary, c, checkedMul(static_cast<uint64_t>(current), per, path, "attribute size"));
    } else if (key == "FIELD") {
      need(3);
      const uint64_t arrays = parseCount(w[2], path, "FIELD array count");
      for (uint64_t a = 0; a < arrays; ++a) {
        auto fw = cur.words();
        if (fw.size() < 4) throw IoError(path + ": malformed FIELD array line");
        Comp c;
        if (!vtkTypeToComp(fw[3], c)) throw IoError(path + ": unsupported type '" + fw[3] + "'");
        skipValues(cur, binary, c,
                   checkedMul(parseCount(fw[1], path, "FIELD components"), parseCount(fw[2], path, "FIELD tuples"),
                              path, "FIELD array size"));
      }
    } else if (key == "COLOR_SCALARS") {
      need(3);
      if (current < 0) throw IoError(path + ": COLOR_SCALARS outside POINT_DATA/CELL_DATA");
      skipValues(cur, binary, binary ? Comp::UInt8 : Comp::Float32,
                 checkedMul(static_cast<uint64_t>(current), parseCount(w[2], path, "COLOR_SCALARS components"), path,
                            "COLOR_SCALARS size"));
    } else if (key == "LOOKUP_TABLE") {
      need(3);
      skipValues(cur, binary, binary ? Comp::UInt8 : Comp::Float32,
                 checkedMul(parseCount(w[2], path, "LOOKUP_TABLE size"), 4, path, "LOOKUP_TABLE size"));
    } else if (key == "METADATA" || key == "INFORMATION" || key == "NAME" || key == "DATA") {
      // VTK 5.x metadata blocks end with a blank line; skip line-wise.
      while (!cur.eof() && !cur.line().empty()) {
      }
    } else {
      throw IoError(path + ": unexpected keyword '" + w[0] + "' in legacy VTK file");
    }
  }
  throw IoError(path + ": legacy VTK file has no point-data SCALARS (truncated?)");
}

// ---------------------------------------------------------------- VTK XML .vti
namespace {

struct Tag {
  size_t begin = std::string::npos, end = std::string::npos;  // '<' and one past '>'
  std::map<std::string, std::string> attr;
  bool found() const { return begin != std::string::npos; }
};

Tag findTag(const std::string& s, const std::string& name, size_t from, size_t limit = std::string::npos) {
  Tag t;
  size_t p = from;
  const std::string open = "<" + name;
  while (true) {
    p = s.find(open, p);
    if (p == std::string::npos || p >= limit) return t;
    const char nx = p + open.size() < s.size() ? s[p + open.size()] : '\0';
    if (nx == ' ' || nx == '>' || nx == '/' || nx == '\n' || nx == '\t' || nx == '\r') break;
    p += open.size();
  }
  const size_t close = s.find('>', p);
  if (close == std::string::npos) return t;
  t.begin = p;
  t.end = close + 1;
  size_t q = p + open.size();
  while (q < close) {
    while (q < close && std::isspace(static_cast<unsigned char>(s[q]))) ++q;
    const size_t eq = s.find('=', q);
    if (eq == std::string::npos || eq >= close) break;
    std::string key = s.substr(q, eq - q);
    while (!key.empty() && std::isspace(static_cast<unsigned char>(key.back()))) key.pop_back();
    const size_t qs = s.find_first_of("\"'", eq);
    if (qs == std::string::npos || qs >= close) break;
    const size_t qe = s.find(s[qs], qs + 1);
    if (qe == std::string::npos || qe > close) break;
    t.attr[key] = s.substr(qs + 1, qe - qs - 1);
    q = qe + 1;
  }
  return t;
}

std::vector<double> numbers(const std::string& s) {
  std::istringstream is(s);
  std::vector<double> v;
  double d;
  while (is >> d) v.push_back(d);
  return v;
}

std::string base64Decode(const std::string& in, size_t begin, size_t end) {
  static int8_t table[256];
  static bool init = false;
  if (!init) {
    std::memset(table, -1, sizeof table);
    const char* a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (int i = 0; i < 64; ++i) table[static_cast<unsigned char>(a[i])] = static_cast<int8_t>(i);
    init = true;
  }
  std::string out;
  uint32_t acc = 0;
  int bits = 0;
  for (size_t i = begin; i < end; ++i) {
    const unsigned char ch = static_cast<unsigned char>(in[i]);
    if (ch == '=') {
      acc = 0;
      bits = 0;  // padding ends a base64 block (VTK concatenates blocks)
      continue;
    }
    if (table[ch] < 0) continue;
    acc = (acc << 6) | static_cast<uint32_t>(table[ch]);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((acc >> bits) & 0xff));
    }
  }
  return out;
}

}  // namespace

namespace {

// The integers of a binary data block's header (UInt32 or UInt64, the file's byte order).
struct BlockHeader {
  size_t hs;
  bool bigEndian;
  const std::string& path;
  uint64_t read(const std::string& b, size_t at) const {
    if (at + hs > b.size()) throw IoError(path + ": truncated data block header");
    uint64_t v = 0;
    char tmp[8];
    std::memcpy(tmp, b.data() + at, hs);
    if (bigEndian == hostIsLittleEndian()) byteSwap(tmp, hs, 1);
    if (hs == 8)
      std::memcpy(&v, tmp, 8);
    else {
      uint32_t v32;
      std::memcpy(&v32, tmp, 4);
      v = v32;
    }
    return v;
  }
};

// <ImageData>'s extent, spacing, direction and origin (VTK's Origin is the world position of
// index (0,0,0) of the extent: shifted to our voxel 0); returns the WholeExtent.
std::vector<double> vtiGeometry(const Tag& image, Geometry& g, ReadInfo& info, const std::string& path) {
  if (!image.found() || !image.attr.count("WholeExtent")) throw IoError(path + ": missing <ImageData WholeExtent=...>");
  const auto ext = numbers(image.attr.at("WholeExtent"));
  if (ext.size() != 6) throw IoError(path + ": bad WholeExtent");
  for (int i = 0; i < 3; ++i) {
    // Checked in double before any integer conversion (NaN or 1e300 must not be cast).
    const double lo = ext[2 * i], hi = ext[2 * i + 1];
    if (!(std::fabs(lo) < 1e12 && std::fabs(hi) < 1e12) || lo != std::floor(lo) || hi != std::floor(hi) || hi < lo ||
        hi - lo >= static_cast<double>(int64_t{1} << 31))
      throw IoError(path + ": absurd WholeExtent '" + image.attr.at("WholeExtent") + "'");
    g.dims[i] = static_cast<int64_t>(hi - lo) + 1;
  }
  if (image.attr.count("Spacing")) {
    const auto sp = numbers(image.attr.at("Spacing"));
    if (sp.size() == 3) g.spacing = Vec3(sp[0], sp[1], sp[2]);
    if (!g.spacing.allFinite()) throw IoError(path + ": Spacing is not finite");
  }
  if (image.attr.count("Direction")) {
    const auto d = numbers(image.attr.at("Direction"));  // row-major 3x3
    if (d.size() == 9)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) g.direction(r, c) = d[static_cast<size_t>(3 * r + c)];
  }
  Vec3 origin(0, 0, 0);
  if (image.attr.count("Origin")) {
    const auto o = numbers(image.attr.at("Origin"));
    if (o.size() == 3) origin = Vec3(o[0], o[1], o[2]);
  }
  if (!g.direction.allFinite() || !origin.allFinite()) throw IoError(path + ": Origin or Direction is not finite");
  // VTK's Origin is the world position of index (0,0,0) of the extent; shift to our voxel 0.
  g.origin = origin + g.direction * Vec3(ext[0] * g.spacing[0], ext[2] * g.spacing[1], ext[4] * g.spacing[2]);
  for (int i = 0; i < 3; ++i)
    if (!(g.spacing[i] > 0)) {
      info.notes.push_back("spacing along axis " + std::to_string(i) + " was not positive, set to 1");
      g.spacing[i] = 1;
    }
  return ext;
}

// The point-data array to read: the one PointData names as Scalars, else the first.
Tag vtiPointArray(const std::string& s, const Tag& piece, const std::string& path) {
  const Tag pd = findTag(s, "PointData", piece.end);
  if (!pd.found()) throw IoError(path + ": no <PointData> (cell data images are not supported)");
  const size_t pdEnd = s.find("</PointData>", pd.end);
  const std::string wanted = pd.attr.count("Scalars") ? pd.attr.at("Scalars") : "";
  Tag arr;
  for (size_t p = pd.end;;) {
    Tag t = findTag(s, "DataArray", p, pdEnd);
    if (!t.found()) break;
    if (!arr.found() || (!wanted.empty() && t.attr.count("Name") && t.attr.at("Name") == wanted)) arr = t;
    if (!wanted.empty() && t.attr.count("Name") && t.attr.at("Name") == wanted) break;
    p = t.end;
  }
  if (!arr.found()) throw IoError(path + ": no point-data DataArray");
  return arr;
}

// The binary block stream of an array: appended (raw or base64) or inline base64.
std::string vtiBlockStream(const std::string& s, const Tag& arr, const std::string& format, const std::string& path) {
  std::string stream;
  // The block stream: either at the appended offset or inline base64.
  bool base64Blocks = false;
  size_t b64Begin = 0, b64End = 0;
  if (format == "appended") {
    const Tag app = findTag(s, "AppendedData", arr.end);
    if (!app.found()) throw IoError(path + ": no <AppendedData>");
    const std::string enc = app.attr.count("encoding") ? app.attr.at("encoding") : "raw";
    const size_t us = s.find('_', app.end);
    if (us == std::string::npos) throw IoError(path + ": appended data has no '_' marker");
    const uint64_t off = arr.attr.count("offset") ? parseCount(arr.attr.at("offset"), path, "DataArray offset") : 0;
    if (off > s.size() - (us + 1)) throw IoError(path + ": appended data offset beyond end of file (truncated)");
    if (enc == "raw") {
      stream = s.substr(us + 1 + off);
    } else if (enc == "base64") {
      base64Blocks = true;
      b64Begin = us + 1 + off;
      b64End = s.find('<', b64Begin);
      if (b64End == std::string::npos) b64End = s.size();
    } else {
      throw IoError(path + ": unsupported AppendedData encoding '" + enc + "'");
    }
  } else if (format == "binary") {
    base64Blocks = true;
    b64Begin = arr.end;
    b64End = s.find("</DataArray>", arr.end);
    if (b64End == std::string::npos) throw IoError(path + ": unterminated DataArray");
  } else {
    throw IoError(path + ": unsupported DataArray format '" + format + "'");
  }
  if (base64Blocks) {
    // VTK encodes the header and the data as separate base64 runs when compressed; when
    // uncompressed a single run. Decoding with padding resets handles both.
    stream = base64Decode(s, b64Begin, b64End);
  }
  return stream;
}

// The array's `need` voxel bytes from its block stream: one uncompressed block, or zlib blocks
// checked against the exact byte count before any is inflated.
std::string vtiBlockData(const std::string& stream, const BlockHeader& header, bool compressed, size_t need,
                         const std::string& path) {
  const size_t hs = header.hs;
  size_t at = 0;
  std::string raw;
  if (!compressed) {
    const uint64_t n = header.read(stream, at);
    at += hs;
    if (n < need)
      throw IoError(path + ": data block holds " + std::to_string(n) + " bytes, need " + std::to_string(need));
    if (need > stream.size() - at) throw IoError(path + ": data is truncated");
    raw = stream.substr(at, need);
  } else {
    // Header: nblocks, blockSize, lastSize, then nblocks compressed sizes. Every size is
    // checked against the array's exact byte count and the stream before use, so no sum
    // can wrap and no block can inflate past the buffer.
    const uint64_t nblocks = header.read(stream, 0);
    const uint64_t blockSize = header.read(stream, hs);
    const uint64_t lastSize = header.read(stream, 2 * hs);
    if (nblocks == 0 || blockSize == 0 || lastSize > blockSize || nblocks > stream.size() / hs)
      throw IoError(path + ": corrupt compression header (" + std::to_string(nblocks) + " blocks of " +
                    std::to_string(blockSize) + " bytes, last " + std::to_string(lastSize) + ")");
    const uint64_t total = checkedAdd(checkedMul(nblocks - 1, blockSize, path, "compressed block sizes"),
                                      lastSize ? lastSize : blockSize, path, "compressed block sizes");
    if (total != need)
      throw IoError(path + ": compressed data holds " + std::to_string(total) + " bytes, the array needs " +
                    std::to_string(need));
    checkDataCanHold(need, stream.size(), kDeflateExpansion, path);
    std::vector<uint64_t> csize(static_cast<size_t>(nblocks));
    for (uint64_t b = 0; b < nblocks; ++b) csize[b] = header.read(stream, static_cast<size_t>(3 + b) * hs);
    size_t pos = static_cast<size_t>(3 + nblocks) * hs;
    raw.resize(static_cast<size_t>(need));
    size_t outPos = 0;
    for (uint64_t b = 0; b < nblocks; ++b) {
      const uint64_t usize = (b + 1 == nblocks && lastSize) ? lastSize : blockSize;
      if (csize[b] > stream.size() - pos) throw IoError(path + ": compressed data is truncated");
      uLongf dlen = static_cast<uLongf>(usize);
      const int rc = uncompress(reinterpret_cast<Bytef*>(&raw[outPos]), &dlen,
                                reinterpret_cast<const Bytef*>(stream.data() + pos), static_cast<uLong>(csize[b]));
      if (rc != Z_OK || dlen != usize) throw IoError(path + ": zlib block " + std::to_string(b) + " is corrupt");
      pos += static_cast<size_t>(csize[b]);
      outPos += static_cast<size_t>(usize);
    }
  }
  return raw;
}

}  // namespace

AnyVolume readVtiVolume(const std::string& path, ReadInfo& info) {
  const std::string s = readFileBytes(path, false);
  const Tag file = findTag(s, "VTKFile", 0, 4096);
  if (!file.found()) throw IoError(path + ": wrong magic, not a VTK XML file");
  if (file.attr.count("type") && file.attr.at("type") != "ImageData")
    throw IoError(path + ": VTK XML type '" + file.attr.at("type") + "' is not ImageData");
  const bool bigEndian = file.attr.count("byte_order") && file.attr.at("byte_order") == "BigEndian";
  const std::string headerType = file.attr.count("header_type") ? file.attr.at("header_type") : "UInt32";
  if (headerType != "UInt32" && headerType != "UInt64") throw IoError(path + ": unsupported header_type " + headerType);
  const size_t hs = headerType == "UInt64" ? 8 : 4;
  std::string compressor = file.attr.count("compressor") ? file.attr.at("compressor") : "";
  if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
    throw IoError(path + ": unsupported compressor " + compressor + " (only vtkZLibDataCompressor)");

  const Tag image = findTag(s, "ImageData", file.end);
  Geometry g;
  const std::vector<double> ext = vtiGeometry(image, g, info, path);

  const Tag piece = findTag(s, "Piece", image.end);
  if (!piece.found()) throw IoError(path + ": no <Piece>");
  if (findTag(s, "Piece", piece.end).found()) throw IoError(path + ": multi-piece .vti files are not supported");
  if (piece.attr.count("Extent") && numbers(piece.attr.at("Extent")) != ext)
    throw IoError(path + ": piece extent differs from WholeExtent (not supported)");
  const Tag arr = vtiPointArray(s, piece, path);
  Comp c;
  const std::string typeName = arr.attr.count("type") ? arr.attr.at("type") : "";
  if (!vtkTypeToComp(typeName, c)) throw IoError(path + ": unsupported voxel type '" + typeName + "'");
  const uint64_t ncompWord = arr.attr.count("NumberOfComponents")
                                 ? parseCount(arr.attr.at("NumberOfComponents"), path, "NumberOfComponents")
                                 : 1;
  if (ncompWord < 1 || ncompWord > 4)
    throw IoError(path + ": unsupported NumberOfComponents " + std::to_string(ncompWord));
  const int ncomp = static_cast<int>(ncompWord);
  checkAllocation(g.dims, compSize(c) * static_cast<size_t>(ncomp), path);
  const size_t need = static_cast<size_t>(g.voxelCount()) * compSize(c) * static_cast<size_t>(ncomp);
  const std::string format = arr.attr.count("format") ? arr.attr.at("format") : "ascii";
  info.sourceType = compName(c) + (ncomp > 1 ? cat("x", std::to_string(ncomp)) : std::string());

  std::string raw;  // decoded voxel bytes
  if (format == "ascii") {
    const size_t close = s.find("</DataArray>", arr.end);
    const std::string text = s.substr(arr.end, close - arr.end);
    Cursor cur{text, 0, path};
    const auto buf = readValues(cur, false, c, need / compSize(c));
    raw.assign(buf.data(), buf.size());
  } else {
    const std::string stream = vtiBlockStream(s, arr, format, path);
    raw = vtiBlockData(stream, BlockHeader{hs, bigEndian, path}, !compressor.empty(), need, path);
    if (bigEndian == hostIsLittleEndian()) byteSwap(raw.data(), compSize(c), raw.size() / compSize(c));
  }
  const std::string name = arr.attr.count("Name") ? arr.attr.at("Name") : "";
  info.notes.push_back("VTK XML image: read point-data array '" + name + "'");
  return convertBuffer(raw.data(), c, ncomp, g, info, path);
}

}  // namespace vs::io_detail
