#include "io/zarr_io.h"

#include <blosc.h>
#include <unistd.h>
#include <zlib.h>

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "util/atomic_file.h"
#include "util/error.h"

namespace fs = std::filesystem;

namespace vs {

namespace {

using json = nlohmann::json;

enum class DType { U1, I1, I2, U2, I4, U4, F4, F8 };

struct DTypeInfo {
  DType t;
  int size;
  bool big;
};

DTypeInfo parseDType(const std::string& s, const std::string& where) {
  if (s.size() < 3) throw IoError(where + ": unsupported dtype '" + s + "'");
  const char order = s[0];
  const std::string k = s.substr(1);
  const bool big = order == '>';
  if (order != '<' && order != '>' && order != '|') throw IoError(where + ": unsupported dtype '" + s + "'");
  if (k == "u1") return {DType::U1, 1, false};
  if (k == "i1") return {DType::I1, 1, false};
  if (k == "i2") return {DType::I2, 2, big};
  if (k == "u2") return {DType::U2, 2, big};
  if (k == "i4") return {DType::I4, 4, big};
  if (k == "u4") return {DType::U4, 4, big};
  if (k == "f4") return {DType::F4, 4, big};
  if (k == "f8") return {DType::F8, 8, big};
  throw IoError(where + ": unsupported dtype '" + s +
                "' (uint8, int8, int16, uint16, int32, uint32, float32, float64)");
}

VoxelType storedType(DType t) {
  switch (t) {
    case DType::U1:
      return VoxelType::UInt8;
    case DType::I1:
    case DType::I2:
      return VoxelType::Int16;
    case DType::U2:
      return VoxelType::UInt16;
    default:
      return VoxelType::Float32;
  }
}

std::string dtypeOf(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8:
      return "|u1";
    case VoxelType::Int16:
      return "<i2";
    case VoxelType::UInt16:
      return "<u2";
    default:
      return "<f4";
  }
}

std::string readText(const fs::path& p, const std::string& what) { return readTextFile(p.string(), what); }

json readJson(const fs::path& p, const std::string& what) {
  const std::string text = readText(p, what);
  try {
    return json::parse(text);
  } catch (const std::exception& e) {
    throw IoError(what + ": " + p.filename().string() + " is not valid JSON");
  }
}

std::string keyText(const Index3& c, char sep) {
  // Zarr keys list the axes as stored: z, y, x.
  return std::to_string(c[2]) + sep + std::to_string(c[1]) + sep + std::to_string(c[0]);
}

double unitToMm(const std::string& u, const std::string& where, std::vector<std::string>* notes) {
  if (u == "millimeter") return 1;
  if (u == "micrometer") return 1e-3;
  if (u == "nanometer") return 1e-6;
  if (u == "centimeter") return 10;
  if (u == "meter") return 1000;
  if (u.empty()) {
    if (notes) notes->push_back("no unit on the spatial axes: millimetres assumed");
    return 1;
  }
  throw IoError(where + ": unsupported axis unit '" + u + "'");
}

// One Zarr v2 array (one pyramid level).
struct ArrayMeta {
  fs::path dir;
  std::string where;  // "<folder>/<level>" in messages
  Index3 dims{};      // x, y, z
  Index3 chunk{};     // x, y, z
  int lead = 0;       // leading singleton axes (t, c)
  DTypeInfo dtype{};
  std::string dtypeText;
  std::string compressor = "none";
  char sep = '.';
  double fill = 0;
};

int64_t positiveInt(const json& v, const std::string& what) {
  if (!v.is_number_integer() || v.get<int64_t>() < 1) throw IoError(what + " must be a positive integer");
  return v.get<int64_t>();
}

ArrayMeta readArrayMeta(const fs::path& dir, const std::string& where) {
  ArrayMeta m;
  m.dir = dir;
  m.where = where;
  if (!fs::is_regular_file(dir / ".zarray")) throw IoError(where + ": no .zarray (not a Zarr v2 array)");
  const json z = readJson(dir / ".zarray", where);
  if (!z.is_object()) throw IoError(where + ": .zarray is not a JSON object");
  if (!z.contains("zarr_format") || z["zarr_format"] != 2) throw IoError(where + ": only zarr_format 2 is supported");
  if (!z.contains("shape") || !z["shape"].is_array() || !z.contains("chunks") || !z["chunks"].is_array())
    throw IoError(where + ": .zarray lacks shape or chunks");
  const json& shape = z["shape"];
  const json& chunks = z["chunks"];
  const size_t nd = shape.size();
  if (nd < 3 || nd > 5 || chunks.size() != nd)
    throw IoError(where + ": shape of " + std::to_string(nd) + " axes with " + std::to_string(chunks.size()) +
                  " chunk sizes (3-5 axes, the last three z, y, x, are supported)");
  m.lead = int(nd) - 3;
  for (int a = 0; a < m.lead; ++a)
    if (positiveInt(shape[size_t(a)], where + ": shape") != 1)
      throw IoError(where + ": leading (time/channel) axis of size " + shape[size_t(a)].dump() +
                    "; only one time point and one channel are supported");
  for (int a = 0; a < 3; ++a) {
    m.dims[size_t(2 - a)] = positiveInt(shape[size_t(m.lead + a)], where + ": shape");
    m.chunk[size_t(2 - a)] = positiveInt(chunks[size_t(m.lead + a)], where + ": chunks");
    if (m.chunk[size_t(2 - a)] > 4096) throw IoError(where + ": chunk size " + chunks.dump() + " above 4096");
  }
  if (m.chunk[0] * m.chunk[1] * m.chunk[2] > (int64_t(1) << 27))
    throw IoError(where + ": chunks of " + std::to_string(m.chunk[0] * m.chunk[1] * m.chunk[2]) +
                  " voxels (more than 2^27: refusing to allocate one)");
  if (!z.contains("dtype") || !z["dtype"].is_string()) throw IoError(where + ": .zarray lacks dtype");
  m.dtypeText = z["dtype"].get<std::string>();
  m.dtype = parseDType(m.dtypeText, where);
  if (z.contains("order") && z["order"] != "C") throw IoError(where + ": only C order is supported");
  if (z.contains("filters") && !z["filters"].is_null() && !(z["filters"].is_array() && z["filters"].empty()))
    throw IoError(where + ": filters are not supported");
  if (z.contains("dimension_separator")) {
    const json& s = z["dimension_separator"];
    if (s == "/")
      m.sep = '/';
    else if (s != ".")
      throw IoError(where + ": dimension_separator " + s.dump() + " (expected \".\" or \"/\")");
  }
  if (z.contains("compressor") && !z["compressor"].is_null()) {
    const json& c = z["compressor"];
    if (!c.is_object() || !c.contains("id") || !c["id"].is_string()) throw IoError(where + ": bad compressor entry");
    const std::string id = c["id"].get<std::string>();
    if (id != "zlib" && id != "gzip" && id != "blosc")
      throw IoError(where + ": unknown compressor '" + id + "' (zlib, gzip, blosc or none are supported)");
    m.compressor = id;
  }
  if (z.contains("fill_value") && z["fill_value"].is_number()) m.fill = z["fill_value"].get<double>();
  return m;
}

size_t chunkBytes(const ArrayMeta& m) { return size_t(m.chunk[0] * m.chunk[1] * m.chunk[2]) * size_t(m.dtype.size); }

// zlib stream of `raw` into `out` (sized compressBound), returning its length. One deflate state
// per thread, reset between chunks: deflateInit's 256 KiB of fresh, zeroed pages per chunk was a
// fifth of the phantom writer's time.
size_t zlibCompress(const std::string& raw, std::string& out, int level, const std::string& where) {
  struct Stream {
    z_stream zs{};
    int level = -2;
    bool open = false;
    ~Stream() {
      if (open) deflateEnd(&zs);
    }
  };
  thread_local Stream st;
  if (st.open && st.level != level) {
    deflateEnd(&st.zs);
    st.open = false;
  }
  if (!st.open) {
    st.zs = z_stream{};
    if (deflateInit(&st.zs, level) != Z_OK) throw IoError(where + ": zlib compression failed");
    st.open = true;
    st.level = level;
  } else if (deflateReset(&st.zs) != Z_OK) {
    throw IoError(where + ": zlib compression failed");
  }
  st.zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(raw.data()));
  st.zs.avail_in = uInt(raw.size());
  st.zs.next_out = reinterpret_cast<Bytef*>(out.data());
  st.zs.avail_out = uInt(out.size());
  if (deflate(&st.zs, Z_FINISH) != Z_STREAM_END) throw IoError(where + ": zlib compression failed");
  return size_t(st.zs.total_out);
}

std::string decompress(const ArrayMeta& m, const std::string& raw, const std::string& name) {
  const size_t want = chunkBytes(m);
  std::string out;
  if (m.compressor == "none") {
    out = raw;
  } else if (m.compressor == "zlib" || m.compressor == "gzip") {
    out.resize(want);
    z_stream zs{};
    if (inflateInit2(&zs, m.compressor == "gzip" ? 16 + MAX_WBITS : MAX_WBITS) != Z_OK)
      throw IoError(name + ": zlib initialisation failed");
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(raw.data()));
    zs.avail_in = uInt(raw.size());
    zs.next_out = reinterpret_cast<Bytef*>(out.data());
    zs.avail_out = uInt(want);
    const int rc = inflate(&zs, Z_FINISH);
    const size_t got = zs.total_out;
    inflateEnd(&zs);
    if (rc != Z_STREAM_END)
      throw IoError(name + ": " + m.compressor + " stream is " +
                    (rc == Z_BUF_ERROR && got == want ? "longer than one chunk" : "truncated or corrupt") +
                    " (expected " + std::to_string(want) + " bytes)");
    out.resize(got);
  } else {  // blosc
    size_t nbytes = 0, cbytes = 0, blocksize = 0;
    if (raw.size() < BLOSC_MIN_HEADER_LENGTH) throw IoError(name + ": blosc chunk shorter than its header");
    blosc_cbuffer_sizes(raw.data(), &nbytes, &cbytes, &blocksize);
    if (cbytes != raw.size())
      throw IoError(name + ": blosc chunk of " + std::to_string(raw.size()) + " bytes, its header says " +
                    std::to_string(cbytes) + " (truncated or corrupt)");
    if (nbytes != want)
      throw IoError(name + ": blosc chunk holds " + std::to_string(nbytes) + " bytes, expected " +
                    std::to_string(want) + " (chunk size disagrees with the metadata)");
    out.resize(want);
    const int got = blosc_decompress_ctx(raw.data(), out.data(), want, 1);
    if (got < 0 || size_t(got) != want) throw IoError(name + ": blosc chunk is corrupt");
  }
  if (out.size() != want)
    throw IoError(name + ": chunk holds " + std::to_string(out.size()) + " bytes, expected " + std::to_string(want) +
                  " (" + (out.size() < want ? "truncated" : "chunk size disagrees with the metadata") + ")");
  return out;
}

template <class T>
T loadLE(const char* p, bool big) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  if (big) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    std::reverse(b, b + sizeof(T));
    std::memcpy(&v, b, sizeof(T));
  }
  return v;
}

std::vector<float> toFloat(const ArrayMeta& m, const std::string& bytes) {
  const size_t n = bytes.size() / size_t(m.dtype.size);
  std::vector<float> out(n);
  const char* p = bytes.data();
  const bool big = m.dtype.big;
  for (size_t i = 0; i < n; ++i, p += m.dtype.size) {
    switch (m.dtype.t) {
      case DType::U1:
        out[i] = float(uint8_t(*p));
        break;
      case DType::I1:
        out[i] = float(int8_t(*p));
        break;
      case DType::I2:
        out[i] = float(loadLE<int16_t>(p, big));
        break;
      case DType::U2:
        out[i] = float(loadLE<uint16_t>(p, big));
        break;
      case DType::I4:
        out[i] = float(loadLE<int32_t>(p, big));
        break;
      case DType::U4:
        out[i] = float(loadLE<uint32_t>(p, big));
        break;
      case DType::F4:
        out[i] = loadLE<float>(p, big);
        break;
      case DType::F8:
        out[i] = float(loadLE<double>(p, big));
        break;
    }
  }
  return out;
}

std::vector<float> loadChunk(const ArrayMeta& m, const Index3& c) {
  std::string key = keyText(c, m.sep);
  for (int a = 0; a < m.lead; ++a) key = std::string("0") + m.sep + key;
  const std::string name = m.where + " chunk " + key;
  const fs::path file = m.dir / key;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw IoError(name + " is missing");
  const std::string raw = readText(file, name);
  return toFloat(m, decompress(m, raw, name));
}

struct Multiscale {
  std::vector<ZarrLevelInfo> levels;
  std::vector<ArrayMeta> arrays;
  std::vector<std::string> notes;
  Mat3 direction = Mat3::Identity();  // volscissors' own key (OME-Zarr 0.4 has no rotation)
  bool hasDirection = false;
};

Vec3 vec3Of(const json& v, int lead, const std::string& what) {
  if (!v.is_array() || v.size() != size_t(lead + 3)) throw IoError(what + " must list one number per axis");
  Vec3 r;
  for (int a = 0; a < 3; ++a) {
    const json& e = v[size_t(lead + a)];
    if (!e.is_number() || !std::isfinite(e.get<double>())) throw IoError(what + " must be finite numbers");
    r[2 - a] = e.get<double>();
  }
  return r;
}

Multiscale openMultiscale(const std::string& path) {
  const fs::path dir(path);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw IoError(path + ": not a folder (an OME-Zarr volume is a folder)");
  Multiscale ms;
  const std::string name = dir.filename().empty() ? path : dir.filename().string();
  if (!fs::is_regular_file(dir / ".zattrs")) {
    if (!fs::is_regular_file(dir / ".zarray"))
      throw IoError(path + ": neither .zattrs nor .zarray (not a Zarr folder)");
    ms.arrays.push_back(readArrayMeta(dir, path));
    ZarrLevelInfo l;
    l.path = ".";
    l.dims = ms.arrays[0].dims;
    l.chunk = ms.arrays[0].chunk;
    ms.levels.push_back(l);
    ms.notes.push_back("bare Zarr array without OME metadata: spacing 1 mm assumed");
    return ms;
  }
  const json attrs = readJson(dir / ".zattrs", path);
  if (!attrs.is_object() || !attrs.contains("multiscales") || !attrs["multiscales"].is_array() ||
      attrs["multiscales"].empty() || !attrs["multiscales"][0].is_object())
    throw IoError(path + ": .zattrs holds no OME-Zarr multiscales");
  const json& m = attrs["multiscales"][0];
  if (attrs.contains("volscissors") && attrs["volscissors"].is_object() && attrs["volscissors"].contains("direction")) {
    // Written by ZarrWriter: the index axes' world directions (columns), 9 numbers column-major.
    const json& d = attrs["volscissors"]["direction"];
    if (!d.is_array() || d.size() != 9) throw IoError(path + ": volscissors.direction must hold 9 numbers");
    for (int i = 0; i < 9; ++i) {
      if (!d[size_t(i)].is_number() || !std::isfinite(d[size_t(i)].get<double>()))
        throw IoError(path + ": volscissors.direction must hold finite numbers");
      ms.direction(i % 3, i / 3) = d[size_t(i)].get<double>();
    }
    if (std::abs(ms.direction.determinant()) < 1e-6) throw IoError(path + ": volscissors.direction is not invertible");
    ms.hasDirection = true;
  }
  if (m.contains("version") && m["version"].is_string() && m["version"] != "0.4")
    ms.notes.push_back("OME-Zarr version " + m["version"].get<std::string>() + " read as 0.4");
  if (!m.contains("datasets") || !m["datasets"].is_array() || m["datasets"].empty())
    throw IoError(path + ": multiscales lists no datasets");
  int lead = -1;
  double toMm = 1;
  if (m.contains("axes")) {
    const json& axes = m["axes"];
    if (!axes.is_array() || axes.size() < 3 || axes.size() > 5) throw IoError(path + ": axes must list 3 to 5 axes");
    lead = int(axes.size()) - 3;
    const char* names[3] = {"z", "y", "x"};
    std::string unit;
    for (int a = 0; a < 3; ++a) {
      const json& ax = axes[size_t(lead + a)];
      const std::string n = ax.is_object() && ax.contains("name") && ax["name"].is_string()
                                ? ax["name"].get<std::string>()
                                : (ax.is_string() ? ax.get<std::string>() : std::string());
      if (n != names[a])
        throw IoError(path + ": the last three axes must be z, y, x (found '" + n + "' for " + names[a] + ")");
      if (ax.is_object() && ax.contains("unit") && ax["unit"].is_string()) {
        const std::string u = ax["unit"].get<std::string>();
        if (!unit.empty() && u != unit) throw IoError(path + ": spatial axes in different units");
        unit = u;
      }
    }
    toMm = unitToMm(unit, path, &ms.notes);
  }
  for (size_t i = 0; i < m["datasets"].size(); ++i) {
    const json& d = m["datasets"][i];
    if (!d.is_object() || !d.contains("path") || !d["path"].is_string())
      throw IoError(path + ": dataset " + std::to_string(i) + " has no path");
    ZarrLevelInfo l;
    l.path = d["path"].get<std::string>();
    if (l.path.empty() || l.path.find("..") != std::string::npos || l.path[0] == '/')
      throw IoError(path + ": dataset path '" + l.path + "' is not a relative folder");
    ArrayMeta a = readArrayMeta(dir / l.path, name + "/" + l.path);
    if (lead >= 0 && a.lead != lead)
      throw IoError(name + "/" + l.path + ": " + std::to_string(a.lead + 3) + " axes, the metadata lists " +
                    std::to_string(lead + 3));
    l.dims = a.dims;
    l.chunk = a.chunk;
    if (d.contains("coordinateTransformations")) {
      const json& ts = d["coordinateTransformations"];
      if (!ts.is_array()) throw IoError(path + ": coordinateTransformations of " + l.path + " is not a list");
      for (const json& t : ts) {
        if (!t.is_object() || !t.contains("type")) throw IoError(path + ": bad coordinate transformation");
        if (t["type"] == "scale" && t.contains("scale")) {
          l.spacing = vec3Of(t["scale"], a.lead, path + ": scale of " + l.path) * toMm;
          for (int k = 0; k < 3; ++k)
            if (!(l.spacing[k] > 0)) throw IoError(path + ": scale of " + l.path + " must be > 0");
        } else if (t["type"] == "translation" && t.contains("translation")) {
          l.origin = vec3Of(t["translation"], a.lead, path + ": translation of " + l.path) * toMm;
        } else if (t["type"] != "identity") {
          throw IoError(path + ": unsupported coordinate transformation " + t["type"].dump());
        }
      }
    }
    ms.levels.push_back(l);
    ms.arrays.push_back(std::move(a));
  }
  // Every level covers level 0's extent to within one of its voxels.
  const ZarrLevelInfo& l0 = ms.levels[0];
  for (size_t i = 1; i < ms.levels.size(); ++i) {
    const ZarrLevelInfo& l = ms.levels[i];
    for (int k = 0; k < 3; ++k) {
      const double e0 = double(l0.dims[size_t(k)]) * l0.spacing[k], e = double(l.dims[size_t(k)]) * l.spacing[k];
      if (std::abs(e - e0) > l.spacing[k] * 1.0001 || l.dims[size_t(k)] > l0.dims[size_t(k)])
        throw IoError(name + "/" + l.path + ": pyramid level of the wrong shape " + std::to_string(l.dims[0]) + "x" +
                      std::to_string(l.dims[1]) + "x" + std::to_string(l.dims[2]) + " for level 0 " +
                      std::to_string(l0.dims[0]) + "x" + std::to_string(l0.dims[1]) + "x" + std::to_string(l0.dims[2]) +
                      " and the scales given");
    }
  }
  return ms;
}

}  // namespace

bool isZarrPath(const std::string& path) {
  std::error_code ec;
  const fs::path p(path);
  std::string s = path;
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  if (s.size() >= 5 && s.compare(s.size() - 5, 5, ".zarr") == 0) return true;
  return fs::is_directory(p, ec) && (fs::exists(p / ".zattrs", ec) || fs::exists(p / ".zarray", ec));
}

ChunkedVolume openZarr(const std::string& path, int level, ZarrInfo* info) {
  Multiscale ms = openMultiscale(path);
  if (level < 0 || level >= int(ms.levels.size()))
    throw InvalidArgument(path + ": level " + std::to_string(level) + " does not exist (0.." +
                          std::to_string(ms.levels.size() - 1) + ")");
  const ZarrLevelInfo& l = ms.levels[size_t(level)];
  const ArrayMeta a = ms.arrays[size_t(level)];
  if (a.dtype.t == DType::I4 || a.dtype.t == DType::U4 || a.dtype.t == DType::F8)
    ms.notes.push_back(a.dtypeText + " voxels read as float32");
  if (a.dtype.t == DType::I1) ms.notes.push_back("int8 voxels read as int16");
  noteInputFile(path);
  ChunkedVolume v;
  v.geometry.dims = l.dims;
  v.geometry.spacing = l.spacing;
  v.geometry.origin = l.origin;
  v.geometry.direction = ms.direction;
  v.type = storedType(a.dtype.t);
  v.chunk = l.chunk;
  v.load = [a](const Index3& c) { return loadChunk(a, c); };
  if (info) {
    info->levels = ms.levels;
    info->dtype = a.dtypeText;
    info->compressor = a.compressor;
    info->notes = ms.notes;
    info->hasDirection = ms.hasDirection;
  }
  return v;
}

AnyVolume readZarr(const std::string& path, int level, ZarrInfo* info, Progress& progress) {
  ChunkedVolume v = openZarr(path, level, info);
  checkAllocation(v.geometry.dims, 4, path);
  const int64_t chunkBytesF = v.chunk[0] * v.chunk[1] * v.chunk[2] * 4;
  // One z-row of chunks at a time is all readAll needs.
  ChunkCache cache(v, chunkBytesF * v.chunkGrid()[0] * v.chunkGrid()[1]);
  return cache.readAll(progress);
}

// ---------------------------------------------------------------- writer

struct ZarrWriter::Impl {
  fs::path target, tmp;
  Geometry geom;
  VoxelType type;
  ZarrWriteOptions opt;
  bool done = false;

  std::string zarray(const Index3& dims) const {
    json z;
    z["zarr_format"] = 2;
    z["shape"] = {dims[2], dims[1], dims[0]};
    z["chunks"] = {opt.chunk, opt.chunk, opt.chunk};
    z["dtype"] = dtypeOf(type);
    z["order"] = "C";
    z["fill_value"] = 0;
    z["filters"] = nullptr;
    z["dimension_separator"] = ".";
    if (opt.compressor == "zlib")
      z["compressor"] = {{"id", "zlib"}, {"level", opt.compressionLevel}};
    else if (opt.compressor == "blosc")
      z["compressor"] = {{"id", "blosc"}, {"cname", "lz4"}, {"clevel", 5}, {"shuffle", 1}, {"blocksize", 0}};
    else
      z["compressor"] = nullptr;
    return z.dump(2);
  }

  static void writeFile(const fs::path& p, const std::string& bytes) {
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
    f.close();
    if (!f) throw IoError(p.string() + ": write failed (disk full?)");
  }

  void writeChunkAt(const fs::path& levelDir, const Index3& c, const float* vox) const {
    const size_t n = size_t(opt.chunk) * size_t(opt.chunk) * size_t(opt.chunk);
    const size_t es = voxelTypeSize(type);
    thread_local std::string raw, out;  // reused: no fresh pages per chunk
    raw.assign(n * es, '\0');
    for (size_t i = 0; i < n; ++i) {
      const float v = vox[i];
      switch (type) {
        case VoxelType::UInt8: {
          const uint8_t b = uint8_t(std::clamp(std::nearbyint(std::isnan(v) ? 0.f : v), 0.f, 255.f));
          raw[i] = char(b);
          break;
        }
        case VoxelType::Int16: {
          const int16_t b = int16_t(std::clamp(std::nearbyint(std::isnan(v) ? 0.f : v), -32768.f, 32767.f));
          std::memcpy(&raw[i * 2], &b, 2);
          break;
        }
        case VoxelType::UInt16: {
          const uint16_t b = uint16_t(std::clamp(std::nearbyint(std::isnan(v) ? 0.f : v), 0.f, 65535.f));
          std::memcpy(&raw[i * 2], &b, 2);
          break;
        }
        default:
          std::memcpy(&raw[i * 4], &v, 4);
      }
    }
    if (opt.compressor == "zlib") {
      out.resize(compressBound(uLong(raw.size())));
      out.resize(zlibCompress(raw, out, opt.compressionLevel, target.string()));
    } else if (opt.compressor == "blosc") {
      out.resize(raw.size() + BLOSC_MAX_OVERHEAD);
      const int len =
          blosc_compress_ctx(5, BLOSC_SHUFFLE, es, raw.size(), raw.data(), out.data(), out.size(), "lz4", 0, 1);
      if (len <= 0) throw IoError(target.string() + ": blosc compression failed");
      out.resize(size_t(len));
    } else {
      out = raw;
    }
    writeFile(levelDir / keyText(c, '.'), out);
  }

  static Index3 gridOf(const Index3& dims, int chunk) {
    return {(dims[0] + chunk - 1) / chunk, (dims[1] + chunk - 1) / chunk, (dims[2] + chunk - 1) / chunk};
  }
};

ZarrWriter::ZarrWriter(const std::string& path, const Geometry& geometry, VoxelType type,
                       const ZarrWriteOptions& options)
    : impl_(std::make_unique<Impl>()) {
  geometry.validate();
  if (options.chunk < 4 || options.chunk > 1024)
    throw InvalidArgument("OME-Zarr chunk size " + std::to_string(options.chunk) + " outside 4..1024");
  if (options.compressor != "zlib" && options.compressor != "blosc" && options.compressor != "none")
    throw InvalidArgument("unknown compressor '" + options.compressor + "' (zlib, blosc or none)");
  if (options.levels < 0 || options.levels > 16)
    throw InvalidArgument("pyramid levels " + std::to_string(options.levels) + " outside 0..16");
  std::string p = path;
  while (p.size() > 1 && p.back() == '/') p.pop_back();
  Impl& m = *impl_;
  m.target = fs::path(p);
  m.geom = geometry;
  m.type = type;
  m.opt = options;
  std::error_code ec;
  const fs::path parent = m.target.has_parent_path() ? m.target.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, ec)) throw IoError(path + ": the folder " + parent.string() + " does not exist");
  if (fs::exists(m.target, ec) && !fs::is_directory(m.target, ec)) throw IoError(path + ": exists and is not a folder");
  if (fs::exists(m.target, ec) && !fs::exists(m.target / ".zattrs", ec) && !fs::is_empty(m.target, ec))
    throw IoError(path + ": exists and is not an OME-Zarr folder (refusing to replace it)");
  static std::atomic<int> counter{0};
  m.tmp = parent /
          ("." + m.target.filename().string() + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  fs::create_directories(m.tmp / "0", ec);
  if (ec) throw IoError(path + ": cannot create " + m.tmp.string() + ": " + ec.message());
  try {
    Impl::writeFile(m.tmp / "0" / ".zarray", m.zarray(geometry.dims));
  } catch (...) {
    fs::remove_all(m.tmp, ec);
    throw;
  }
}

ZarrWriter::~ZarrWriter() {
  if (impl_ && !impl_->done) {
    std::error_code ec;
    fs::remove_all(impl_->tmp, ec);
  }
}

Index3 ZarrWriter::chunkGrid() const { return Impl::gridOf(impl_->geom.dims, impl_->opt.chunk); }
int ZarrWriter::chunkSize() const { return impl_->opt.chunk; }

void ZarrWriter::writeChunk(const Index3& c, const float* voxels) const {
  const Index3 g = chunkGrid();
  for (int a = 0; a < 3; ++a)
    if (c[a] < 0 || c[a] >= g[a]) throw InvalidArgument("OME-Zarr writer: chunk outside the chunk grid");
  impl_->writeChunkAt(impl_->tmp / "0", c, voxels);
}

void ZarrWriter::finish(Progress& progress) {
  Impl& m = *impl_;
  const int ch = m.opt.chunk;
  // Pyramid: level k+1 = 2x2x2 means of level k (odd edges: the last voxel alone), read back
  // chunk by chunk from the level just written.
  int levels = m.opt.levels;
  if (levels == 0) {
    levels = 1;
    Index3 d = m.geom.dims;
    while (std::max({d[0], d[1], d[2]}) > ch && levels < 16) {
      for (auto& v : d) v = (v + 1) / 2;
      ++levels;
    }
  }
  std::vector<Index3> dims{m.geom.dims};
  std::vector<Vec3> spacing{m.geom.spacing};
  for (int l = 1; l < levels; ++l) {
    Index3 d = dims.back();
    for (auto& v : d) v = (v + 1) / 2;
    dims.push_back(d);
    spacing.push_back(spacing.back() * 2);
  }
  // Write the level metadata and the pyramid.
  for (int l = 1; l < levels; ++l) {
    const fs::path prevDir = m.tmp / std::to_string(l - 1), dir = m.tmp / std::to_string(l);
    fs::create_directories(dir);
    Impl::writeFile(dir / ".zarray", m.zarray(dims[size_t(l)]));
    ArrayMeta prev = readArrayMeta(prevDir, m.target.string() + "/" + std::to_string(l - 1));
    ChunkedVolume pv;
    pv.geometry.dims = dims[size_t(l - 1)];
    pv.chunk = prev.chunk;
    pv.load = [prev](const Index3& c) { return loadChunk(prev, c); };
    ChunkCache cache(pv, int64_t(ch) * ch * ch * 4 * 16);
    const Index3 g = Impl::gridOf(dims[size_t(l)], ch);
    std::vector<float> src(size_t(8) * ch * ch * ch), out(size_t(ch) * ch * ch);
    const Index3& pd = dims[size_t(l - 1)];
    for (int64_t cz = 0; cz < g[2]; ++cz) {
      progress.report(double(l - 1 + double(cz) / double(g[2])) / double(levels), "pyramid");
      for (int64_t cy = 0; cy < g[1]; ++cy)
        for (int64_t cx = 0; cx < g[0]; ++cx) {
          const Index3 o{cx * 2 * ch, cy * 2 * ch, cz * 2 * ch};
          cache.readRegion(o, {2 * ch, 2 * ch, 2 * ch}, src.data(), std::numeric_limits<float>::quiet_NaN());
          for (int64_t z = 0; z < ch; ++z)
            for (int64_t y = 0; y < ch; ++y)
              for (int64_t x = 0; x < ch; ++x) {
                double sum = 0;
                int cnt = 0;
                for (int dz = 0; dz < 2; ++dz)
                  for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx) {
                      const int64_t sx = 2 * x + dx, sy = 2 * y + dy, sz = 2 * z + dz;
                      if (o[0] + sx >= pd[0] || o[1] + sy >= pd[1] || o[2] + sz >= pd[2]) continue;
                      sum += src[size_t(sx + 2 * ch * (sy + 2 * ch * sz))];
                      ++cnt;
                    }
                out[size_t(x + ch * (y + ch * z))] = cnt ? float(sum / cnt) : 0.f;
              }
          m.writeChunkAt(dir, {cx, cy, cz}, out.data());
        }
    }
  }
  json ms;
  ms["version"] = "0.4";
  ms["name"] = m.target.filename().string();
  ms["axes"] = json::array({{{"name", "z"}, {"type", "space"}, {"unit", "millimeter"}},
                            {{"name", "y"}, {"type", "space"}, {"unit", "millimeter"}},
                            {{"name", "x"}, {"type", "space"}, {"unit", "millimeter"}}});
  ms["datasets"] = json::array();
  for (int l = 0; l < levels; ++l) {
    const Vec3& s = spacing[size_t(l)];
    // Level l's voxel centres: the mean of 2^l level-0 voxels, so its origin moves by half a
    // level-0 voxel per halving.
    const Vec3 o = m.geom.origin + m.geom.direction * (0.5 * (s - m.geom.spacing));
    ms["datasets"].push_back(
        {{"path", std::to_string(l)},
         {"coordinateTransformations", json::array({{{"type", "scale"}, {"scale", {s[2], s[1], s[0]}}},
                                                    {{"type", "translation"}, {"translation", {o[2], o[1], o[0]}}}})}});
  }
  ms["type"] = "mean";
  json attrs;
  attrs["multiscales"] = json::array({ms});
  json dir = json::array();
  for (int i = 0; i < 9; ++i) dir.push_back(m.geom.direction(i % 3, i / 3));
  attrs["volscissors"] = {{"direction", dir}};  // OME-Zarr 0.4 has no rotation: kept for our own reader
  Impl::writeFile(m.tmp / ".zattrs", attrs.dump(2));
  Impl::writeFile(m.tmp / ".zgroup", "{\n  \"zarr_format\": 2\n}");
  if (progress.cancelled()) throw Cancelled();
  // Move into place: an existing output folder is replaced only now.
  std::error_code ec;
  fs::path old;
  if (fs::exists(m.target, ec)) {
    old = m.tmp;
    old += ".old";
    fs::rename(m.target, old, ec);
    if (ec) throw IoError(m.target.string() + ": cannot replace the existing folder: " + ec.message());
  }
  fs::rename(m.tmp, m.target, ec);
  if (ec) {
    if (!old.empty()) fs::rename(old, m.target, ec);
    throw IoError(m.target.string() + ": cannot move the written folder into place");
  }
  m.done = true;
  if (!old.empty()) fs::remove_all(old, ec);
}

void writeZarr(const AnyVolume& volume, const std::string& path, const ZarrWriteOptions& options, Progress& progress) {
  std::visit(
      [&](const auto& v) {
        const Geometry& g = v.geometry();
        ZarrWriter w(path, g, voxelType(volume), options);
        const int ch = w.chunkSize();
        const Index3 grid = w.chunkGrid();
        std::vector<float> buf(size_t(ch) * ch * ch);
        for (int64_t cz = 0; cz < grid[2]; ++cz) {
          progress.report(0.5 * double(cz) / double(grid[2]), "write");
          for (int64_t cy = 0; cy < grid[1]; ++cy)
            for (int64_t cx = 0; cx < grid[0]; ++cx) {
              std::fill(buf.begin(), buf.end(), 0.f);
              for (int64_t z = 0; z < ch && cz * ch + z < g.dims[2]; ++z)
                for (int64_t y = 0; y < ch && cy * ch + y < g.dims[1]; ++y)
                  for (int64_t x = 0; x < ch && cx * ch + x < g.dims[0]; ++x)
                    buf[size_t(x + ch * (y + ch * z))] = float(v(cx * ch + x, cy * ch + y, cz * ch + z));
              w.writeChunk({cx, cy, cz}, buf.data());
            }
        }
        w.finish(progress);
      },
      volume);
}

}  // namespace vs
