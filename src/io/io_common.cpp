// Shared conversion helpers for the volume readers (see io_internal.h).
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "io/io_internal.h"
#include "io/volume_io.h"
#include "io/zarr_io.h"
#include "util/atomic_file.h"

namespace vs::io_detail {

size_t compSize(Comp c) {
  switch (c) {
    case Comp::Int8:
    case Comp::UInt8:
      return 1;
    case Comp::Int16:
    case Comp::UInt16:
      return 2;
    case Comp::Int32:
    case Comp::UInt32:
    case Comp::Float32:
      return 4;
    case Comp::Int64:
    case Comp::UInt64:
    case Comp::Float64:
      return 8;
  }
  return 1;
}

std::string compName(Comp c) {
  switch (c) {
    case Comp::Int8:
      return "int8";
    case Comp::UInt8:
      return "uint8";
    case Comp::Int16:
      return "int16";
    case Comp::UInt16:
      return "uint16";
    case Comp::Int32:
      return "int32";
    case Comp::UInt32:
      return "uint32";
    case Comp::Int64:
      return "int64";
    case Comp::UInt64:
      return "uint64";
    case Comp::Float32:
      return "float32";
    case Comp::Float64:
      return "float64";
  }
  return "?";
}

uint64_t checkedMul(uint64_t a, uint64_t b, const std::string& what, const char* field) {
  uint64_t r;
  if (__builtin_mul_overflow(a, b, &r)) throw IoError(what + ": " + field + " overflows (corrupt header)");
  return r;
}

uint64_t checkedAdd(uint64_t a, uint64_t b, const std::string& what, const char* field) {
  uint64_t r;
  if (__builtin_add_overflow(a, b, &r)) throw IoError(what + ": " + field + " overflows (corrupt header)");
  return r;
}

void checkScratchBytes(uint64_t bytes, const std::string& what) {
  if (bytes > maxVolumeBytes())
    throw DataError(what + ": reading it needs " + std::to_string(bytes >> 20) + " MiB, more than the " +
                    std::to_string(maxVolumeBytes() >> 20) + " MiB allowed on this machine");
}

void checkDataCanHold(uint64_t need, uint64_t available, double expansion, const std::string& what) {
  if (static_cast<double>(need) > static_cast<double>(available) * expansion + 64.0)
    throw IoError(what + ": header promises " + std::to_string(need) + " bytes of voxel data but the file holds only " +
                  std::to_string(available) + " bytes (truncated or corrupt)");
}

namespace {

// Parses an integer word; false on anything else (no exceptions, no wrap).
bool parseLong(const std::string& w, long& out) {
  if (w.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtol(w.c_str(), &end, 10);
  return errno == 0 && end == w.c_str() + w.size();
}

// Formats `fmt` (already validated: one %[0][width](d|i|u), "%%" escapes) with `value`
// without handing a file-controlled string to printf.
std::string formatValidatedPattern(const std::string& fmt, long value) {
  std::string out;
  for (size_t i = 0; i < fmt.size(); ++i) {
    if (fmt[i] != '%') {
      out += fmt[i];
      continue;
    }
    if (fmt[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    size_t j = i + 1;
    const bool zero = fmt[j] == '0';
    if (zero) ++j;
    int width = 0;
    while (std::isdigit(static_cast<unsigned char>(fmt[j]))) width = width * 10 + (fmt[j++] - '0');
    std::string digits = std::to_string(value < 0 ? -value : value);
    const std::string sign = value < 0 ? "-" : "";
    const size_t len = sign.size() + digits.size();
    if (static_cast<size_t>(width) > len) {
      const std::string pad(static_cast<size_t>(width) - len, zero ? '0' : ' ');
      out += zero ? sign + pad + digits : pad + sign + digits;
    } else {
      out += sign + digits;
    }
    i = j;  // at the conversion letter
  }
  return out;
}

}  // namespace

bool isSlicePattern(const std::string& field) {
  std::istringstream is(field);
  std::vector<std::string> w;
  for (std::string t; is >> t;) w.push_back(t);
  return w.size() >= 4 && w[0].find('%') != std::string::npos;
}

std::vector<std::string> expandSlicePattern(const std::string& field, const std::string& path) {
  std::istringstream is(field);
  std::vector<std::string> w;
  for (std::string t; is >> t;) w.push_back(t);
  if (w.size() < 4 || w.size() > 5)
    throw IoError(path + ": bad data file pattern '" + field + "' (need: format first last step)");
  const std::string& fmt = w[0];
  int conversions = 0;
  for (size_t i = 0; i < fmt.size(); ++i) {
    if (fmt[i] != '%') continue;
    if (i + 1 < fmt.size() && fmt[i + 1] == '%') {
      ++i;
      continue;
    }
    size_t j = i + 1;
    if (j < fmt.size() && fmt[j] == '0') ++j;
    size_t digits = 0;
    while (j < fmt.size() && std::isdigit(static_cast<unsigned char>(fmt[j]))) ++j, ++digits;
    if (digits > 2 || j >= fmt.size() || (fmt[j] != 'd' && fmt[j] != 'i' && fmt[j] != 'u'))
      throw IoError(path + ": data file pattern '" + fmt + "' may hold only one %d-style number (found '" +
                    fmt.substr(i, std::min<size_t>(j + 1, fmt.size()) - i) + "')");
    ++conversions;
    i = j;
  }
  if (conversions != 1) throw IoError(path + ": data file pattern '" + fmt + "' must hold exactly one %d-style number");
  long first = 0, last = 0, step = 0;
  if (!parseLong(w[1], first) || !parseLong(w[2], last) || !parseLong(w[3], step) || step == 0 ||
      std::labs(first) > 1000000000L || std::labs(last) > 1000000000L || (last - first) / step < 0 ||
      (last - first) / step >= 100000)
    throw IoError(path + ": bad data file pattern range '" + field + "'");
  std::vector<std::string> names;
  for (long k = first; step > 0 ? k <= last : k >= last; k += step) names.push_back(formatValidatedPattern(fmt, k));
  return names;
}

std::string oneLine(const std::string& s) {
  std::string out;
  bool space = false;
  for (char ch : s) {
    if (ch == '\n' || ch == '\r' || ch == '\t' || ch == ' ') {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += ch;
  }
  return out;
}

bool hostIsLittleEndian() {
  const uint16_t one = 1;
  uint8_t b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

void byteSwap(void* data, size_t elemSize, size_t count) {
  if (elemSize <= 1) return;
  auto* p = static_cast<uint8_t*>(data);
  for (size_t i = 0; i < count; ++i, p += elemSize) std::reverse(p, p + elemSize);
}

std::string readFileBytes(const std::string& path, bool allowGzip) {
  std::string bytes = readTextFile(path);
  if (!allowGzip || bytes.size() < 2 || static_cast<uint8_t>(bytes[0]) != 0x1f ||
      static_cast<uint8_t>(bytes[1]) != 0x8b)
    return bytes;
  return gunzip(bytes, path);
}

std::string gunzip(const std::string& bytes, const std::string& path) {
  // gzip or zlib: inflate with automatic header detection (possibly several members).
  std::string out;
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 32) != Z_OK) throw IoError(path + ": zlib init failed");
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  zs.avail_in = static_cast<uInt>(bytes.size());
  std::vector<char> chunk(1 << 20);
  int rc = Z_OK;
  if (bytes.empty()) throw IoError(path + ": compressed data is empty");
  while (true) {
    zs.next_out = reinterpret_cast<Bytef*>(chunk.data());
    zs.avail_out = static_cast<uInt>(chunk.size());
    rc = inflate(&zs, Z_NO_FLUSH);
    out.append(chunk.data(), chunk.size() - zs.avail_out);
    if (rc == Z_STREAM_END) {
      if (zs.avail_in == 0) break;
      inflateReset(&zs);  // concatenated gzip members
      continue;
    }
    if (rc != Z_OK) break;
  }
  inflateEnd(&zs);
  if (rc != Z_STREAM_END) throw IoError(path + ": gzip data is truncated or corrupt");
  return out;
}

double gzipInflatedSize(const std::string& path, double expect, uint64_t offset, bool trustTrailer) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (trustTrailer && !ec && size >= offset + 18) {
    std::ifstream in(path, std::ios::binary);
    in.seekg(static_cast<std::streamoff>(size - 4));
    uint32_t isize = 0;
    in.read(reinterpret_cast<char*>(&isize), 4);
    if (!hostIsLittleEndian()) byteSwap(&isize, 4, 1);
    if (in && static_cast<double>(isize) == std::fmod(expect, 4294967296.0)) return expect;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return 0;
  in.seekg(static_cast<std::streamoff>(offset));
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 32) != Z_OK) return 0;
  std::vector<char> src(1 << 16), dst(1 << 20);
  double total = 0;
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    in.read(src.data(), static_cast<std::streamsize>(src.size()));
    const auto got = in.gcount();
    if (got <= 0) break;
    zs.next_in = reinterpret_cast<Bytef*>(src.data());
    zs.avail_in = static_cast<uInt>(got);
    while (zs.avail_in > 0) {
      zs.next_out = reinterpret_cast<Bytef*>(dst.data());
      zs.avail_out = static_cast<uInt>(dst.size());
      rc = inflate(&zs, Z_NO_FLUSH);
      total += static_cast<double>(dst.size() - zs.avail_out);
      if (rc == Z_STREAM_END) {
        if (zs.avail_in == 0) break;
        inflateReset(&zs);  // next gzip member
        rc = Z_OK;
        continue;
      }
      if (rc != Z_OK) break;
    }
    if (rc != Z_OK && rc != Z_STREAM_END) break;
  }
  inflateEnd(&zs);
  return total;
}

namespace {

template <class S>
double lum(const S* p, int ncomp) {
  if (ncomp >= 3) return 0.299 * double(p[0]) + 0.587 * double(p[1]) + 0.114 * double(p[2]);
  return double(p[0]);
}

template <class D>
Volume<D> emptyLike(const Geometry& g) {
  Volume<D> v;
  v.geometry() = g;
  return v;
}

// Copies/casts scalar source values into a Volume<D> (values known to fit).
template <class D, class S>
AnyVolume castTo(const S* src, const Geometry& g) {
  Volume<D> out(g);
  const int64_t n = g.voxelCount();
  D* d = out.data();
  for (int64_t i = 0; i < n; ++i) d[i] = static_cast<D>(src[i]);
  return out;
}

template <class S>
AnyVolume convertTyped(const S* src, int ncomp, const Geometry& g, ReadInfo& info, Comp c) {
  const int64_t n = g.voxelCount();
  if (ncomp > 1) {
    // Reduce to one scalar per voxel, then convert that.
    std::vector<S> scalar(static_cast<size_t>(n));
    const bool rgb = (ncomp == 3 || ncomp == 4);
    for (int64_t i = 0; i < n; ++i) {
      const S* p = src + i * ncomp;
      if (rgb) {
        const double l = lum(p, ncomp);
        scalar[static_cast<size_t>(i)] =
            std::numeric_limits<S>::is_integer ? static_cast<S>(std::lround(l)) : static_cast<S>(l);
      } else {
        scalar[static_cast<size_t>(i)] = p[0];
      }
    }
    info.notes.push_back(rgb ? std::to_string(ncomp) +
                                   "-component (colour) voxels reduced to luminance 0.299R+0.587G+0.114B"
                             : std::to_string(ncomp) + "-component voxels: kept the first component only");
    return convertTyped<S>(scalar.data(), 1, g, info, c);
  }
  if constexpr (std::is_same_v<S, uint8_t> || std::is_same_v<S, int16_t> || std::is_same_v<S, uint16_t> ||
                std::is_same_v<S, float>) {
    Volume<S> out(g);
    std::memcpy(out.data(), src, static_cast<size_t>(n) * sizeof(S));
    return out;
  } else if constexpr (std::is_same_v<S, double>) {
    info.notes.push_back("float64 voxels converted to float32");
    return castTo<float>(src, g);
  } else {
    // Integer types we do not keep: choose the smallest supported type holding the range.
    double lo = 0, hi = 0;
    if (n > 0) {
      auto [mn, mx] = std::minmax_element(src, src + n);
      lo = double(*mn);
      hi = double(*mx);
    }
    if (lo >= 0 && hi <= 255) {
      info.notes.push_back(compName(c) + " voxels converted to uint8 (range " + std::to_string(int64_t(lo)) + ".." +
                           std::to_string(int64_t(hi)) + ")");
      return castTo<uint8_t>(src, g);
    }
    if (lo >= -32768 && hi <= 32767) {
      info.notes.push_back(compName(c) + " voxels converted to int16 (range fits)");
      return castTo<int16_t>(src, g);
    }
    if (lo >= 0 && hi <= 65535) {
      info.notes.push_back(compName(c) + " voxels converted to uint16 (range fits)");
      return castTo<uint16_t>(src, g);
    }
    const bool exact = std::max(std::fabs(lo), std::fabs(hi)) <= 16777216.0;
    info.notes.push_back(compName(c) + " voxels converted to float32" +
                         (exact ? " (exact)" : " (values above 2^24 lose precision)"));
    return castTo<float>(src, g);
  }
}

}  // namespace

AnyVolume convertBuffer(const void* src, Comp c, int ncomp, const Geometry& g, ReadInfo& info,
                        const std::string& what) {
  if (ncomp < 1) throw IoError(what + ": voxels have no components");
  switch (c) {
    case Comp::Int8:
      return convertTyped(static_cast<const int8_t*>(src), ncomp, g, info, c);
    case Comp::UInt8:
      return convertTyped(static_cast<const uint8_t*>(src), ncomp, g, info, c);
    case Comp::Int16:
      return convertTyped(static_cast<const int16_t*>(src), ncomp, g, info, c);
    case Comp::UInt16:
      return convertTyped(static_cast<const uint16_t*>(src), ncomp, g, info, c);
    case Comp::Int32:
      return convertTyped(static_cast<const int32_t*>(src), ncomp, g, info, c);
    case Comp::UInt32:
      return convertTyped(static_cast<const uint32_t*>(src), ncomp, g, info, c);
    case Comp::Int64:
      return convertTyped(static_cast<const int64_t*>(src), ncomp, g, info, c);
    case Comp::UInt64:
      return convertTyped(static_cast<const uint64_t*>(src), ncomp, g, info, c);
    case Comp::Float32:
      return convertTyped(static_cast<const float*>(src), ncomp, g, info, c);
    case Comp::Float64:
      return convertTyped(static_cast<const double*>(src), ncomp, g, info, c);
  }
  throw IoError(what + ": unsupported voxel type");
}

AnyVolume narrowIntegral(AnyVolume vol, ReadInfo& info) {
  auto* f = std::get_if<VolumeF32>(&vol);
  if (!f || f->empty()) return vol;
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (float v : f->voxels()) {
    if (!std::isfinite(v) || v != std::nearbyint(v)) return vol;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  const Geometry& g = f->geometry();
  if (lo >= 0 && hi <= 255) {
    info.notes.push_back("scaled values are integers 0..255: stored as uint8");
    return castTo<uint8_t>(f->data(), g);
  }
  if (lo >= -32768 && hi <= 32767) {
    info.notes.push_back("scaled values are integers in int16 range: stored as int16");
    return castTo<int16_t>(f->data(), g);
  }
  if (lo >= 0 && hi <= 65535) {
    info.notes.push_back("scaled values are integers in uint16 range: stored as uint16");
    return castTo<uint16_t>(f->data(), g);
  }
  return vol;
}

}  // namespace vs::io_detail

namespace vs {

const std::vector<std::string>& volumeWriteExtensions() {
  static const std::vector<std::string> exts{".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd", ".zarr"};
  return exts;
}

bool isVolumeWritePath(const std::string& path) {
  const std::string ext = fileExtension(path);
  const auto& exts = volumeWriteExtensions();
  return std::find(exts.begin(), exts.end(), ext) != exts.end() || isZarrPath(path);
}

}  // namespace vs
