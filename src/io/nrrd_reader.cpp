// A small NRRD reader of our own, used when ITK's NrrdImageIO refuses a file that is
// common in the wild, e.g. VTK's headsq "quarter.nhdr" (`spacings` together with `space`,
// and a slice-file pattern `data file: quarter.%d 1 93 1`). Supports: 2-3 dimensions
// (a leading dimension of size <= 4 is taken as components), raw/gzip/ascii encodings,
// one data file, a printf-style file pattern or a LIST of files, line/byte skip,
// spacings or space directions + space origin, RAS/LPS spaces.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "io/io_internal.h"

namespace fs = std::filesystem;

namespace vs::io_detail {

namespace {

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::string lowerStr(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::vector<double> parseVector(const std::string& s) {  // "(1,0,0)"
  std::string t = s;
  for (char& ch : t)
    if (ch == '(' || ch == ')' || ch == ',') ch = ' ';
  std::istringstream is(t);
  std::vector<double> v;
  double d;
  while (is >> d) v.push_back(d);
  return v;
}

std::vector<std::string> parseVectors(const std::string& s) {  // "(1,0,0) (0,1,0) none"
  std::vector<std::string> out;
  size_t p = 0;
  while (p < s.size()) {
    while (p < s.size() && std::isspace(static_cast<unsigned char>(s[p]))) ++p;
    if (p >= s.size()) break;
    if (s[p] == '(') {
      const size_t e = s.find(')', p);
      if (e == std::string::npos) break;
      out.push_back(s.substr(p, e - p + 1));
      p = e + 1;
    } else {
      size_t e = p;
      while (e < s.size() && !std::isspace(static_cast<unsigned char>(s[e]))) ++e;
      out.push_back(s.substr(p, e - p));
      p = e;
    }
  }
  return out;
}

}  // namespace

bool nrrdType(const std::string& t, Comp& c) {
  static const std::map<std::string, Comp> m = {{"signed char", Comp::Int8},
                                                {"int8", Comp::Int8},
                                                {"int8_t", Comp::Int8},
                                                {"uchar", Comp::UInt8},
                                                {"unsigned char", Comp::UInt8},
                                                {"uint8", Comp::UInt8},
                                                {"uint8_t", Comp::UInt8},
                                                {"short", Comp::Int16},
                                                {"short int", Comp::Int16},
                                                {"signed short", Comp::Int16},
                                                {"signed short int", Comp::Int16},
                                                {"int16", Comp::Int16},
                                                {"int16_t", Comp::Int16},
                                                {"ushort", Comp::UInt16},
                                                {"unsigned short", Comp::UInt16},
                                                {"unsigned short int", Comp::UInt16},
                                                {"uint16", Comp::UInt16},
                                                {"uint16_t", Comp::UInt16},
                                                {"int", Comp::Int32},
                                                {"signed int", Comp::Int32},
                                                {"int32", Comp::Int32},
                                                {"int32_t", Comp::Int32},
                                                {"uint", Comp::UInt32},
                                                {"unsigned int", Comp::UInt32},
                                                {"uint32", Comp::UInt32},
                                                {"uint32_t", Comp::UInt32},
                                                {"longlong", Comp::Int64},
                                                {"long long", Comp::Int64},
                                                {"int64", Comp::Int64},
                                                {"int64_t", Comp::Int64},
                                                {"ulonglong", Comp::UInt64},
                                                {"unsigned long long", Comp::UInt64},
                                                {"uint64", Comp::UInt64},
                                                {"uint64_t", Comp::UInt64},
                                                {"float", Comp::Float32},
                                                {"double", Comp::Float64}};
  auto it = m.find(lowerStr(t));
  if (it == m.end()) return false;
  c = it->second;
  return true;
}

void checkNrrdComplete(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(1 << 16, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  size_t pos = head.find('\n');
  if (head.rfind("NRRD", 0) != 0 || pos == std::string::npos) return;
  ++pos;
  std::map<std::string, std::string> f;
  bool ended = false;
  const bool wholeFile = in.eof();
  while (pos < head.size()) {
    size_t e = head.find('\n', pos);
    if (e == std::string::npos) {
      // ITK sees the whole header: one we cannot see whole could hide a printf pattern.
      if (!wholeFile) throw IoError(path + ": NRRD header longer than 64 KiB");
      e = head.size();
    }
    const std::string t = trim(head.substr(pos, e - pos));
    pos = std::min(e + 1, head.size());
    if (t.empty()) {
      ended = true;
      break;
    }
    if (t[0] == '#' || t.find(":=") != std::string::npos) continue;
    const size_t c = t.find(':');
    if (c == std::string::npos) return;
    const std::string key = lowerStr(trim(t.substr(0, c)));
    f[key] = trim(t.substr(c + 1));
    if ((key == "data file" || key == "datafile") && f[key].find('%') != std::string::npos &&
        f[key].find_first_of(" \t") != std::string::npos)
      expandSlicePattern(f[key], path);  // throws on a pattern ITK must not see
  }
  Comp comp;
  if (!nrrdType(f["type"], comp)) return;
  if (!f["line skip"].empty() || !f["byte skip"].empty() || !f["lineskip"].empty() || !f["byteskip"].empty()) return;
  std::istringstream ss(f["sizes"]);
  double need = static_cast<double>(compSize(comp));
  for (double v; ss >> v;) need *= v;
  if (!(need > 0) || need > static_cast<double>(maxVolumeBytes())) return;  // absurd: reported later
  const std::string enc = lowerStr(f["encoding"]);
  const bool gz = enc == "gzip" || enc == "gz";
  if (!gz && enc != "raw") return;
  std::string df = f.count("data file") ? f["data file"] : f["datafile"];
  if (isSlicePattern(df)) {
    // ITK's teem hands the pattern to printf: validate it and check every slice file first.
    double have = 0;
    for (const auto& name : expandSlicePattern(df, path)) {
      const fs::path slice = fs::path(path).parent_path() / name;
      std::error_code ec;
      const auto size = fs::file_size(slice, ec);
      if (ec) throw IoError(path + ": data file '" + slice.string() + "' not found");
      have += static_cast<double>(size);
    }
    if (!gz && have < need)
      throw IoError(path + ": truncated NRRD data in the slice files (" + std::to_string(static_cast<int64_t>(have)) +
                    " of " + std::to_string(static_cast<int64_t>(need)) + " bytes)");
    return;
  }
  std::string dataPath = path;
  uint64_t offset = 0;
  if (df.empty()) {
    if (!ended) return;
    offset = pos;
  } else {
    if (df.find(' ') != std::string::npos || df.find('%') != std::string::npos || df.rfind("LIST", 0) == 0) return;
    dataPath = (fs::path(path).parent_path() / df).string();
    std::error_code ec;
    if (!fs::exists(dataPath, ec)) throw IoError(path + ": data file '" + df + "' not found");
  }
  std::error_code ec;
  const double fileSize = static_cast<double>(fs::file_size(dataPath, ec));
  if (ec) return;
  const double have = gz ? gzipInflatedSize(dataPath, need, offset) : fileSize - static_cast<double>(offset);
  if (have < need)
    throw IoError(path + ": truncated NRRD data" + (dataPath != path ? " in " + dataPath : std::string()) + " (" +
                  std::to_string(static_cast<int64_t>(have)) + " of " + std::to_string(static_cast<int64_t>(need)) +
                  " bytes)");
}

NrrdHeader parseNrrdHeader(const std::string& bytes, const std::string& path) {
  if (bytes.rfind("NRRD", 0) != 0) throw IoError(path + ": wrong magic, not a NRRD file");
  NrrdHeader h;
  size_t pos = bytes.find('\n');
  if (pos == std::string::npos) throw IoError(path + ": truncated NRRD header");
  ++pos;
  bool inList = false;
  while (pos < bytes.size()) {
    size_t e = bytes.find('\n', pos);
    if (e == std::string::npos) e = bytes.size();
    const std::string line = bytes.substr(pos, e - pos);
    pos = std::min(e + 1, bytes.size());
    const std::string t = trim(line);
    if (inList) {
      if (!t.empty()) h.listFiles.push_back(t);
      continue;
    }
    if (t.empty()) break;  // end of header; attached data follows
    if (t[0] == '#') continue;
    size_t c = t.find(":=");
    if (c != std::string::npos) continue;  // key/value pairs: ignored
    c = t.find(':');
    if (c == std::string::npos) throw IoError(path + ": malformed NRRD header line '" + t + "'");
    const std::string key = lowerStr(trim(t.substr(0, c)));
    const std::string val = trim(t.substr(c + 1));
    h.fields[key] = val;
    if ((key == "data file" || key == "datafile") && val.rfind("LIST", 0) == 0) inList = true;
  }
  h.dataStart = pos;
  return h;
}

// Spacing, direction and origin: space directions (+ origin) or spacings; RAS turned to LPS as ITK does.
void nrrdGeometry(const NrrdHeader& h, int first, int dim, Geometry& g, const std::string& path) {
  const std::string space = lowerStr(h.get("space"));
  const bool ras = space == "right-anterior-superior" || space == "ras" || space == "right_anterior_superior";
  const std::string dirs = h.get("space directions");
  if (!dirs.empty()) {
    const auto v = parseVectors(dirs);
    int axis = 0;
    for (size_t i = 0; i < v.size() && axis < 3; ++i) {
      if (static_cast<int>(i) < first) continue;
      if (v[i] == "none") continue;
      const auto d = parseVector(v[i]);
      if (d.size() < 3) continue;
      Vec3 col(d[0], d[1], d[2]);
      const double len = col.norm();
      if (!(len > 0)) throw IoError(path + ": zero-length space direction");
      g.spacing[axis] = len;
      g.direction.col(axis) = col / len;
      ++axis;
    }
  } else if (!h.get("spacings").empty()) {
    std::istringstream sp(h.get("spacings"));
    std::vector<double> s;
    std::string tok;
    while (sp >> tok) s.push_back(tok == "nan" || tok == "NaN" ? 1.0 : std::atof(tok.c_str()));
    for (int i = first; i < dim && i < static_cast<int>(s.size()); ++i)
      if (s[static_cast<size_t>(i)] > 0) g.spacing[i - first] = s[static_cast<size_t>(i)];
  }
  if (!h.get("space origin").empty()) {
    const auto o = parseVector(h.get("space origin"));
    if (o.size() >= 3) g.origin = Vec3(o[0], o[1], o[2]);
  }
  if (ras) {  // to LPS like ITK
    g.origin[0] = -g.origin[0];
    g.origin[1] = -g.origin[1];
    g.direction.row(0) *= -1;
    g.direction.row(1) *= -1;
  }
}

// The detached data files ("data file": one name, a slice pattern or LIST); empty: attached data.
std::vector<std::string> nrrdDataFiles(const NrrdHeader& h, const std::string& path) {
  const std::string df = h.get("data file").empty() ? h.get("datafile") : h.get("data file");
  const fs::path base = fs::path(path).parent_path();
  std::vector<std::string> files;
  if (df.empty()) {
    // attached data
  } else if (df.rfind("LIST", 0) == 0) {
    for (auto& l : h.listFiles) files.push_back((base / l).string());
  } else if (isSlicePattern(df)) {
    for (const auto& name : expandSlicePattern(df, path)) files.push_back((base / name).string());
  } else {
    files.push_back((base / df).string());
  }
  return files;
}

namespace {

// ASCII samples into `need` bytes of components of type comp.
std::vector<char> nrrdAsciiData(const std::string& data, Comp comp, size_t need, const std::string& path) {
  std::vector<char> buf;
  std::istringstream vs(data);
  buf.resize(need);
  const size_t es = compSize(comp);
  for (size_t i = 0; i < need / es; ++i) {
    double v;
    if (!(vs >> v)) throw IoError(path + ": ASCII data is truncated");
    switch (comp) {
      case Comp::Float32: {
        const float x = static_cast<float>(v);
        std::memcpy(&buf[i * es], &x, es);
        break;
      }
      case Comp::Float64:
        std::memcpy(&buf[i * es], &v, es);
        break;
      default: {
        const int64_t x = static_cast<int64_t>(std::llround(v));
        std::memcpy(&buf[i * es], &x, es);  // little-endian host: low bytes first
      }
    }
  }
  return buf;
}

}  // namespace

AnyVolume readNrrdOwn(const std::string& path, ReadInfo& info) {
  const std::string bytes = readFileBytes(path, false);
  const NrrdHeader h = parseNrrdHeader(bytes, path);
  auto get = [&](const std::string& k) { return h.get(k); };
  Comp comp;
  if (!nrrdType(get("type"), comp)) throw IoError(path + ": unsupported NRRD type '" + get("type") + "'");
  const int dim = std::atoi(get("dimension").c_str());
  std::istringstream ss(get("sizes"));
  std::vector<int64_t> sizes;
  for (int64_t v; ss >> v;) sizes.push_back(v);
  if (dim < 2 || dim > 4 || static_cast<int>(sizes.size()) != dim)
    throw IoError(path + ": unsupported NRRD dimension/sizes ('" + get("dimension") + "', '" + get("sizes") + "')");
  for (int64_t s : sizes)
    if (s < 1) throw IoError(path + ": absurd NRRD size " + std::to_string(s));
  int ncomp = 1;
  int first = 0;
  if (dim == 4 || (dim == 3 && sizes[0] <= 4 && get("kinds").find("domain") != 0 && !get("kinds").empty())) {
    ncomp = static_cast<int>(sizes[0]);
    first = 1;
  }
  if (dim - first > 3) throw IoError(path + ": NRRD with more than 3 spatial dimensions is not supported");
  Geometry g;
  g.dims = {1, 1, 1};
  for (int i = first; i < dim; ++i) g.dims[static_cast<size_t>(i - first)] = sizes[static_cast<size_t>(i)];
  checkAllocation(g.dims, compSize(comp) * static_cast<size_t>(ncomp), path);
  nrrdGeometry(h, first, dim, g, path);

  // Data.
  const std::string enc = lowerStr(get("encoding"));
  const bool gz = enc == "gzip" || enc == "gz";
  const bool ascii = enc == "ascii" || enc == "text" || enc == "txt";
  if (!gz && !ascii && enc != "raw") throw IoError(path + ": unsupported NRRD encoding '" + enc + "'");
  const std::vector<std::string> files = nrrdDataFiles(h, path);
  const long lineSkip = std::atol(get("line skip").c_str());
  const long byteSkip = std::atol(get("byte skip").c_str());
  const size_t need = static_cast<size_t>(g.voxelCount()) * compSize(comp) * static_cast<size_t>(ncomp);
  std::string data;
  auto addChunk = [&](std::string chunk, const std::string& name) {
    size_t at = 0;
    for (long l = 0; l < lineSkip; ++l) {
      const size_t e = chunk.find('\n', at);
      if (e == std::string::npos) throw IoError(name + ": fewer lines than 'line skip'");
      at = e + 1;
    }
    if (byteSkip == -1 && !ascii) {
      // -1: the data is at the end of the file (raw only); take the per-file share
      const size_t share = need / std::max<size_t>(files.size(), 1);
      if (chunk.size() < share) throw IoError(name + ": data is truncated");
      at = chunk.size() - share;
    } else if (byteSkip > 0) {
      at += static_cast<size_t>(byteSkip);
    }
    if (at > chunk.size()) throw IoError(name + ": data is truncated");
    data.append(chunk, at, std::string::npos);
  };
  if (files.empty()) {
    std::string attached = bytes.substr(h.dataStart);
    if (gz) attached = gunzip(attached, path);
    addChunk(std::move(attached), path);
  } else {
    for (const auto& file : files) {
      std::error_code ec;
      if (!fs::exists(file, ec)) throw IoError(path + ": data file '" + file + "' not found");
      addChunk(readFileBytes(file, gz), file);
    }
    if (files.size() > 1) info.notes.push_back("NRRD data read from " + std::to_string(files.size()) + " files");
  }
  std::vector<char> buf;
  if (ascii) {
    buf = nrrdAsciiData(data, comp, need, path);
  } else {
    if (data.size() < need)
      throw IoError(path + ": NRRD data is truncated (" + std::to_string(data.size()) + " of " + std::to_string(need) +
                    " bytes)");
    buf.assign(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(need));
    const std::string endian = lowerStr(get("endian"));
    const bool big = endian == "big";
    if (compSize(comp) > 1 && big == hostIsLittleEndian()) byteSwap(buf.data(), compSize(comp), need / compSize(comp));
  }
  info.sourceType = compName(comp) + (ncomp > 1 ? cat("x", std::to_string(ncomp)) : std::string());
  return convertBuffer(buf.data(), comp, ncomp, g, info, path);
}

}  // namespace vs::io_detail
