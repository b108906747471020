// Volume reading and writing: format dispatch, NIfTI scaling policy, type conversion and
// atomic writes. ITK is reached only through io/itk_bridge.h.
#include "io/volume_io.h"

#include <unistd.h>
#include <zlib.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "io/io_internal.h"
#include "io/itk_bridge.h"
#include "io/zarr_io.h"
#include "util/atomic_file.h"
#include "util/cancel.h"

namespace fs = std::filesystem;

namespace vs {

using namespace io_detail;

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string fmtNum(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// NIfTI-1/2 header facts ITK does not report: datatype and scaling.
struct NiftiPeek {
  bool ok = false;
  bool known = false;  // datatype is one we can read
  std::string type;
  double slope = 0, inter = 0;
  double dataBytes = 0;  // bytes of voxel data the header promises (NIfTI-1 only; 0 = unknown)
  double voxOffset = 0;
  bool swap = false;     // file byte order differs from ours
  int16_t datatype = 0;  // NIfTI datatype code
  std::string problem;   // non-empty: a header field ITK must not see (why, naming the field)
};

// One field of a NIfTI header at a byte offset, in the file's byte order.
template <class T>
T headerField(const unsigned char* h, int offset, bool swap) {
  T v;
  std::memcpy(&v, h + offset, sizeof v);
  if (swap) byteSwap(&v, sizeof v, 1);
  return v;
}

// Dimensions and the fields nifticlib turns into a matrix, checked before ITK: NaN in a used
// sform/qform aborts inside VNL and a huge srow makes its SVD run for minutes.
template <class Dim, class Real, class Code>
std::string niftiHeaderProblem(const unsigned char* h, bool swap, int dimAt, int pixdimAt, int qcodeAt, int scodeAt,
                               int quatAt, int srowAt) {
  auto rd = [&](int off, auto tag) { return headerField<decltype(tag)>(h, off, swap); };
  const int64_t nd = static_cast<int64_t>(rd(dimAt, Dim{}));
  if (nd < 1 || nd > 7) return "dim[0] = " + std::to_string(nd) + " (need 1 to 7 dimensions)";
  for (int i = 1; i <= nd; ++i) {
    const int64_t d = static_cast<int64_t>(rd(dimAt + i * static_cast<int>(sizeof(Dim)), Dim{}));
    if (d < 1) return "dim[" + std::to_string(i) + "] = " + std::to_string(d) + " is not positive";
  }
  auto bad = [](double v) { return !std::isfinite(v) || std::fabs(v) > 1e9; };
  for (int i = 0; i <= 3; ++i)
    if (bad(static_cast<double>(rd(pixdimAt + i * static_cast<int>(sizeof(Real)), Real{}))))
      return "pixdim[" + std::to_string(i) + "] is not a finite size";
  if (rd(qcodeAt, Code{}) > 0)
    for (int i = 0; i < 6; ++i)
      if (bad(static_cast<double>(rd(quatAt + i * static_cast<int>(sizeof(Real)), Real{}))))
        return "qform (quatern/qoffset) holds a non-finite or absurd value";
  if (rd(scodeAt, Code{}) > 0)
    for (int i = 0; i < 12; ++i)
      if (bad(static_cast<double>(rd(srowAt + i * static_cast<int>(sizeof(Real)), Real{}))))
        return "sform (srow_x/y/z) holds a non-finite or absurd value";
  return {};
}

NiftiPeek peekNifti(const std::string& path) {
  NiftiPeek p;
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return p;
  unsigned char h[540];
  const int n = gzread(f, h, sizeof h);
  gzclose(f);
  if (n < 348) return p;
  int32_t sizeofHdr;
  std::memcpy(&sizeofHdr, h, 4);
  const bool swap = !(sizeofHdr == 348 || sizeofHdr == 540);
  if (swap) byteSwap(&sizeofHdr, 4, 1);
  p.swap = swap;
  auto rd16 = [&](int off) { return headerField<int16_t>(h, off, swap); };
  int16_t dt = 0;
  if (sizeofHdr == 348) {
    dt = rd16(70);
    const int nd = rd16(40);
    const int bitpix = rd16(72);
    if (nd >= 1 && nd <= 7 && bitpix > 0) {
      double count = 1;
      for (int i = 1; i <= nd; ++i) count *= std::max<int16_t>(rd16(40 + 2 * i), 1);
      p.dataBytes = count * bitpix / 8.0;
    }
    const float vo = headerField<float>(h, 108, swap);
    p.voxOffset = std::isfinite(vo) ? vo : 0;
    p.slope = headerField<float>(h, 112, swap);
    p.inter = headerField<float>(h, 116, swap);
    p.problem = niftiHeaderProblem<int16_t, float, int16_t>(h, swap, 40, 76, 252, 254, 256, 280);
  } else if (sizeofHdr == 540 && n >= 540) {
    dt = rd16(12);
    p.voxOffset = static_cast<double>(headerField<int64_t>(h, 168, swap));
    p.slope = headerField<double>(h, 176, swap);
    p.inter = headerField<double>(h, 184, swap);
    p.problem = niftiHeaderProblem<int64_t, double, int32_t>(h, swap, 16, 104, 344, 348, 352, 400);
  } else {
    return p;
  }
  static const std::map<int, std::string> names = {
      {2, "uint8"},    {4, "int16"},    {8, "int32"},    {16, "float32"},  {64, "float64"}, {256, "int8"},
      {512, "uint16"}, {768, "uint32"}, {1024, "int64"}, {1280, "uint64"}, {128, "rgb24"},  {2304, "rgba32"}};
  static const std::map<int, std::string> unsupported = {
      {1, "binary"}, {32, "complex64"}, {1536, "float128"}, {1792, "complex128"}, {2048, "complex256"}};
  p.datatype = dt;
  auto it = names.find(dt);
  p.known = it != names.end();
  auto un = unsupported.find(dt);
  p.type = p.known ? it->second : un != unsupported.end() ? un->second : "datatype " + std::to_string(dt);
  p.ok = true;
  return p;
}

// nifticlib (inside ITK) silently replaces NaN and inf voxels of float NIfTI files by 0
// (nifti_read_buffer). Zero is a valid intensity, so that would hide bad data: re-read the
// float voxels of a single-file NIfTI-1 and put the non-finite values back (scaled like the
// rest). Returns how many voxels were restored. Our voxel order equals the file's (x fastest);
// ITK only changes the direction matrix for RAS->LPS.
template <class F>
int64_t restoreNonFinite(const std::string& path, const NiftiPeek& p, VolumeF32& vol, double slope, double inter) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return 0;
  int64_t restored = 0;
  if (gzseek(f, static_cast<z_off_t>(p.voxOffset), SEEK_SET) >= 0) {
    std::vector<F> buf(1 << 16);
    int64_t done = 0;
    const int64_t n = vol.size();
    while (done < n) {
      const int64_t want = std::min<int64_t>(n - done, static_cast<int64_t>(buf.size()));
      const int got = gzread(f, buf.data(), static_cast<unsigned>(want * static_cast<int64_t>(sizeof(F))));
      if (got <= 0) break;
      const int64_t count = got / static_cast<int64_t>(sizeof(F));
      for (int64_t k = 0; k < count; ++k) {
        F v = buf[static_cast<size_t>(k)];
        if (p.swap) byteSwap(&v, sizeof(F), 1);
        if (!std::isfinite(v)) {
          vol.voxels()[static_cast<size_t>(done + k)] = static_cast<float>(static_cast<double>(v) * slope + inter);
          ++restored;
        }
      }
      done += count;
      if (count < want) break;
    }
  }
  gzclose(f);
  return restored;
}

bool isSingleFileNifti(const std::string& ext) { return ext == ".nii" || ext == ".nii.gz"; }

// The voxel data a NIfTI header promises must be in the file: ITK (nifticlib) only warns.
void checkNiftiComplete(const std::string& path, const NiftiPeek& p) {
  if (!p.ok || p.dataBytes <= 0 || p.dataBytes > 4.0e18) return;    // unknown, or absurd (checked later)
  if (static_cast<double>(maxVolumeBytes()) < p.dataBytes) return;  // checkAllocation reports it
  const std::string ext = fileExtension(path);
  double have = 0, need = 0;
  std::error_code ec;
  if (ext == ".nii") {
    have = static_cast<double>(fs::file_size(path, ec));
    need = p.voxOffset + p.dataBytes;
  } else if (ext == ".nii.gz") {
    need = p.voxOffset + p.dataBytes;
    have = gzipInflatedSize(path, need);
  } else if (ext == ".hdr") {
    const fs::path img = fs::path(path).replace_extension(".img");
    have = static_cast<double>(fs::file_size(img, ec));
    if (ec) throw IoError(path + ": image file " + img.string() + " not found");
    need = p.dataBytes;
  } else {
    return;
  }
  if (!ec && have < need)
    throw IoError(path + ": truncated NIfTI file (" + std::to_string(static_cast<int64_t>(have)) + " of " +
                  std::to_string(static_cast<int64_t>(need)) + " bytes)");
}

// MetaImage header, validated before ITK sees it: ITK's MetaIO loops for ever on a negative
// or huge NDims, hands ElementDataFile patterns to printf, reads short data silently and
// turns undecodable compressed data or missing slice files into zeros.
void checkMetaComplete(const std::string& path) {
  std::string bytes = readFileBytes(path, false);
  const bool wholeHeaderSeen = bytes.size() <= (1u << 20);
  bytes.resize(std::min<size_t>(bytes.size(), 1u << 20));
  std::map<std::string, std::string> kv;
  size_t pos = 0, headerEnd = std::string::npos;
  auto trim = [](std::string t) {
    while (!t.empty() && std::isspace(static_cast<unsigned char>(t.back()))) t.pop_back();
    while (!t.empty() && std::isspace(static_cast<unsigned char>(t.front()))) t.erase(0, 1);
    return t;
  };
  while (pos < bytes.size()) {
    size_t e = bytes.find('\n', pos);
    if (e == std::string::npos) e = bytes.size();
    const std::string line = bytes.substr(pos, e - pos);
    pos = std::min(e + 1, bytes.size());
    const size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string key = lower(trim(line.substr(0, eq)));
    kv[key] = trim(line.substr(eq + 1));
    if (key == "elementdatafile") {
      headerEnd = pos;
      break;
    }
  }
  if (headerEnd == std::string::npos) {
    if (!wholeHeaderSeen) throw IoError(path + ": MetaImage header longer than 1 MiB");
    throw IoError(path + ": MetaImage header has no ElementDataFile line (truncated?)");
  }
  auto numbers = [&](const std::string& key, const std::string& what) {
    std::vector<double> v;
    std::istringstream is(kv[key]);
    for (std::string w; is >> w;) {
      char* end = nullptr;
      const double d = std::strtod(w.c_str(), &end);
      if (end != w.c_str() + w.size() || !std::isfinite(d) || std::fabs(d) > 1e15)
        throw IoError(path + ": MetaImage " + what + " '" + kv[key] + "' is not a list of finite numbers");
      v.push_back(d);
    }
    return v;
  };
  const auto ndims = numbers("ndims", "NDims");
  if (ndims.size() != 1 || ndims[0] != std::floor(ndims[0]) || ndims[0] < 1 || ndims[0] > 8)
    throw IoError(path + ": MetaImage NDims '" + kv["ndims"] + "' must be an integer from 1 to 8");
  const auto dimSize = numbers("dimsize", "DimSize");
  if (dimSize.size() != static_cast<size_t>(ndims[0]))
    throw IoError(path + ": MetaImage DimSize does not have NDims entries");
  double count = 1;
  for (double d : dimSize) {
    if (d < 1 || d != std::floor(d) || d > 2147483648.0)
      throw IoError(path + ": MetaImage DimSize '" + kv["dimsize"] + "' is absurd");
    count *= d;
  }
  for (const char* key : {"elementspacing", "elementsize", "offset", "origin", "position", "transformmatrix",
                          "rotation", "orientation", "centerofrotation"})
    if (kv.count(key)) numbers(key, key);
  const double nc =
      kv.count("elementnumberofchannels") ? numbers("elementnumberofchannels", "ElementNumberOfChannels").at(0) : 1.0;
  if (nc < 1 || nc > 64 || nc != std::floor(nc))
    throw IoError(path + ": MetaImage ElementNumberOfChannels '" + kv["elementnumberofchannels"] + "' is absurd");
  if (kv.count("headersize")) {
    const auto hs = numbers("headersize", "HeaderSize");
    if (hs.size() != 1 || hs[0] < -1)
      throw IoError(path + ": MetaImage HeaderSize '" + kv["headersize"] + "' is absurd");
  }
  static const std::map<std::string, double> sizes = {{"met_uchar", 1},  {"met_char", 1},      {"met_short", 2},
                                                      {"met_ushort", 2}, {"met_int", 4},       {"met_uint", 4},
                                                      {"met_float", 4},  {"met_double", 8},    {"met_long", 4},
                                                      {"met_ulong", 4},  {"met_long_long", 8}, {"met_ulong_long", 8}};
  auto it = sizes.find(lower(kv["elementtype"]));
  if (it == sizes.end()) throw IoError(path + ": unsupported MetaImage ElementType '" + kv["elementtype"] + "'");
  const double need = count * it->second * nc;
  if (need > static_cast<double>(maxVolumeBytes()))
    throw DataError(path + ": MetaImage needs " + std::to_string(static_cast<int64_t>(need / 1048576)) +
                    " MiB, more than the " + std::to_string(maxVolumeBytes() >> 20) + " MiB allowed on this machine");
  const std::string df = kv["elementdatafile"];
  const bool compressed = lower(kv["compresseddata"]) == "true";
  const fs::path dir = fs::path(path).parent_path();
  std::error_code ec;
  // Slice files (a pattern or a LIST): each must exist, and together hold the voxels unless compressed.
  auto checkSliceFiles = [&](const std::vector<std::string>& names) {
    double have = 0;
    for (const auto& name : names) {
      const auto size = fs::file_size(dir / name, ec);
      if (ec) throw IoError(path + ": slice file '" + (dir / name).string() + "' not found");
      have += static_cast<double>(size);
    }
    if (!compressed && have < need)
      throw IoError(path + ": truncated MetaImage slice files (" + std::to_string(static_cast<int64_t>(have)) + " of " +
                    std::to_string(static_cast<int64_t>(need)) + " bytes)");
  };
  if (df.find('%') != std::string::npos && df.find_first_of(" \t") != std::string::npos) {
    checkSliceFiles(expandSlicePattern(df, path));
    return;
  }
  if (lower(df).rfind("list", 0) == 0) {
    std::istringstream rest(readFileBytes(path, false).substr(headerEnd));
    std::vector<std::string> names;
    for (std::string name; std::getline(rest, name);)
      if (!trim(name).empty()) names.push_back(trim(name));
    checkSliceFiles(names);
    return;
  }
  std::string where = path;
  uint64_t offset = 0;
  if (lower(df) == "local") {
    offset = headerEnd;
  } else {
    where = (dir / df).string();
    if (!fs::exists(where, ec)) throw IoError(path + ": data file '" + df + "' not found");
  }
  const double fileBytes = static_cast<double>(fs::file_size(where, ec));
  if (ec) throw IoError(where + ": cannot read the file size");
  const double stored = fileBytes - static_cast<double>(offset);
  double have = stored;
  if (compressed) {
    // The whole stream must inflate to the voxel data: ITK fills undecodable data with zeros.
    if (need > std::max(stored, 0.0) * kDeflateExpansion + 64)
      throw IoError(path + ": compressed MetaImage data is too short for the header's " +
                    std::to_string(static_cast<int64_t>(need)) + " bytes");
    have = gzipInflatedSize(where, need, offset, false);
    if (have < need)
      throw IoError(path + ": compressed MetaImage data" + (where != path ? " in " + where : std::string()) +
                    " is corrupt or truncated (inflates to " + std::to_string(static_cast<int64_t>(have)) + " of " +
                    std::to_string(static_cast<int64_t>(need)) + " bytes)");
    return;
  }
  if (have < need)
    throw IoError(path + ": truncated MetaImage data" + (where != path ? " in " + where : std::string()) + " (" +
                  std::to_string(static_cast<int64_t>(have)) + " of " + std::to_string(static_cast<int64_t>(need)) +
                  " bytes)");
}

bool niftiScaled(const NiftiPeek& p) {
  return p.ok && std::isfinite(p.slope) && std::isfinite(p.inter) && p.slope != 0 && (p.slope != 1 || p.inter != 0);
}

// Turns a bridge header into our geometry, sanitising what the file got wrong.
Geometry geometryFromRaw(const RawHeader& h, ReadInfo& info) {
  Geometry g;
  for (int i = 0; i < 3; ++i) {
    g.dims[i] = h.dims[i];
    g.spacing[i] = h.spacing[i];
    g.origin[i] = h.origin[i];
    for (int r = 0; r < 3; ++r) g.direction(r, i) = h.direction[3 * r + i];
  }
  if (h.ndim == 2) {  // keep the in-plane rotation; z is the normal
    g.direction.col(2) = g.direction.col(0).cross(g.direction.col(1));
    if (g.direction.col(2).norm() < 1e-6) g.direction = Mat3::Identity();
  }
  for (int i = 0; i < 3; ++i) {
    if (!(g.spacing[i] > 0) || !std::isfinite(g.spacing[i])) {
      info.notes.push_back("spacing along axis " + std::to_string(i) + " was " + fmtNum(g.spacing[i]) + ", replaced");
      g.spacing[i] = (g.spacing[i] < 0 && std::isfinite(g.spacing[i])) ? -g.spacing[i] : 1.0;
    }
  }
  if (!g.origin.allFinite()) {
    info.notes.push_back("origin was not finite, set to 0");
    g.origin.setZero();
  }
  if (!g.direction.allFinite() || std::fabs(g.direction.determinant()) < 1e-6) {
    info.notes.push_back("direction matrix was degenerate, set to identity");
    g.direction = Mat3::Identity();
  }
  return g;
}

// Reads through the ITK bridge: supported scalar types go straight into the volume's
// buffer (no extra copy), anything else through a temporary buffer and convertBuffer.
// storedBytes (when non-zero): the file's size, so that a tiny file announcing huge
// dimensions is refused before the buffer is allocated.
AnyVolume readViaBridge(const std::string& path, ReadInfo& info,
                        const std::function<void(const Allocator&, RawHeader&)>& read, uint64_t storedBytes = 0) {
  RawHeader h;
  AnyVolume vol;
  std::vector<char> tmp;
  bool direct = false;
  Geometry g;
  auto alloc = [&](const RawHeader& hdr) -> void* {
    ReadInfo scratch;  // notes come from the final header below
    g = geometryFromRaw(hdr, scratch);
    for (int i = 0; i < 3; ++i)
      if (g.dims[i] < 1 || g.dims[i] > (int64_t{1} << 31))
        throw IoError(path + ": absurd dimension " + std::to_string(g.dims[i]) + " along axis " + std::to_string(i));
    checkAllocation(g.dims, compSize(hdr.comp) * static_cast<size_t>(hdr.ncomp), path);
    if (storedBytes > 0)
      checkDataCanHold(static_cast<uint64_t>(g.voxelCount()) * compSize(hdr.comp) * static_cast<uint64_t>(hdr.ncomp),
                       storedBytes, kDeflateExpansion, path);
    if (hdr.ncomp == 1) {
      direct = true;
      switch (hdr.comp) {
        case Comp::UInt8:
          vol = VolumeU8(g);
          return std::get<VolumeU8>(vol).data();
        case Comp::Int16:
          vol = VolumeI16(g);
          return std::get<VolumeI16>(vol).data();
        case Comp::UInt16:
          vol = VolumeU16(g);
          return std::get<VolumeU16>(vol).data();
        case Comp::Float32:
          vol = VolumeF32(g);
          return std::get<VolumeF32>(vol).data();
        default:
          direct = false;
          break;
      }
    }
    tmp.resize(static_cast<size_t>(g.voxelCount()) * compSize(hdr.comp) * static_cast<size_t>(hdr.ncomp));
    return tmp.data();
  };
  read(alloc, h);
  for (auto& n : h.notes) info.notes.push_back(n);
  if (info.sourceType.empty()) info.sourceType = h.sourceType;
  // The reader may refine geometry after allocating (DICOM: slice step and normal).
  g = geometryFromRaw(h, info);
  if (direct) {
    std::visit([&](auto& v) { v.geometry() = g; }, vol);
    return vol;
  }
  return convertBuffer(tmp.data(), h.comp, h.ncomp, g, info, path);
}

enum class Kind { Nifti, Nrrd, Meta, Vtk, Vti, Png, Tiff, Dicom, Unknown };

Kind kindOf(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return Kind::Dicom;
  const std::string ext = fileExtension(path);
  if (ext == ".nii" || ext == ".nii.gz" || ext == ".hdr" || ext == ".img") return Kind::Nifti;
  if (ext == ".nrrd" || ext == ".nhdr") return Kind::Nrrd;
  if (ext == ".mha" || ext == ".mhd") return Kind::Meta;
  if (ext == ".vtk" || ext == ".vtk.gz") return Kind::Vtk;
  if (ext == ".vti") return Kind::Vti;
  if (ext == ".png") return Kind::Png;
  if (ext == ".tif" || ext == ".tiff") return Kind::Tiff;
  if (ext == ".dcm" || ext == ".ima" || ext.empty()) return Kind::Dicom;
  return Kind::Unknown;
}

// Checks the magic number so a mislabelled file gets a clear message (not ITK's).
void checkMagic(const std::string& path, Kind k) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw IoError(path + ": cannot open for reading");
  char h[352] = {};
  const int n = gzread(f, h, sizeof h);
  gzclose(f);
  if (n <= 0) throw IoError(path + ": file is empty");
  const std::string head(h, static_cast<size_t>(n));
  auto bad = [&](const std::string& expect) { throw IoError(path + ": wrong magic, not a " + expect + " file"); };
  switch (k) {
    case Kind::Nifti: {
      if (n < 348) throw IoError(path + ": truncated NIfTI header (" + std::to_string(n) + " of 348 bytes)");
      int32_t s;
      std::memcpy(&s, h, 4);
      int32_t sw = s;
      byteSwap(&sw, 4, 1);
      if (s != 348 && s != 540 && sw != 348 && sw != 540) bad("NIfTI");
      const std::string magic(h + 344, 3);
      if (fileExtension(path) != ".hdr" && magic != "n+1" && magic != "ni1" && std::string(h + 4, 3) != "n+2")
        bad("NIfTI");
      break;
    }
    case Kind::Nrrd:
      if (head.rfind("NRRD", 0) != 0) bad("NRRD");
      break;
    case Kind::Png:
      if (n < 8 || std::memcmp(h, "\x89PNG\r\n\x1a\n", 8) != 0) bad("PNG");
      break;
    case Kind::Tiff:
      if (n < 4 || !(std::memcmp(h, "II*\0", 4) == 0 || std::memcmp(h, "MM\0*", 4) == 0 ||
                     std::memcmp(h, "II+\0", 4) == 0 || std::memcmp(h, "MM\0+", 4) == 0))
        bad("TIFF");
      break;
    case Kind::Meta: {
      const std::string l = lower(head);
      if (l.find("ndims") == std::string::npos && l.find("objecttype") == std::string::npos) bad("MetaImage");
      break;
    }
    default:
      break;
  }
}

}  // namespace

namespace {

AnyVolume readViaItk(const std::string& path, ReadInfo& info, ItkFormat f, uint64_t storedBytes = 0) {
  return readViaBridge(
      path, info, [&](const Allocator& a, RawHeader& h) { itkReadFile(f, path, a, h); }, storedBytes);
}

// NIfTI: ITK's reader (our own for what ITK refuses or scales differently from nibabel), the
// geometry from the header as nibabel reads it, NaN/inf voxels kept, scaling noted.
AnyVolume readNiftiVolume(const std::string& path, ReadInfo& info) {
  AnyVolume vol;
  info.format = "nifti";
  checkMagic(path, Kind::Nifti);
  const NiftiPeek peek = peekNifti(path);
  if (!peek.problem.empty()) throw IoError(path + ": corrupt NIfTI header: " + peek.problem);
  if (peek.ok && !peek.known) throw IoError(path + ": unsupported NIfTI voxel type " + peek.type);
  checkNiftiComplete(path, peek);
  if (peek.ok) {
    info.sourceType = peek.type;
    if (niftiScaled(peek))
      info.sourceType += cat("*", fmtNum(peek.slope),
                             peek.inter != 0 ? cat(peek.inter < 0 ? "" : "+", fmtNum(peek.inter)) : std::string());
  }
  if (peek.ok && peek.inter != 0 && std::isfinite(peek.inter) && (peek.slope == 0 || !std::isfinite(peek.slope))) {
    // nibabel: scl_slope 0 or NaN means no scaling at all; ITK would still add scl_inter.
    vol = readNiftiVoxels(path, 1, 0, info);
    info.notes.push_back("NIfTI scl_slope " + fmtNum(peek.slope) + ": no scaling (scl_inter " + fmtNum(peek.inter) +
                         " ignored, as nibabel does)");
  } else {
    try {
      vol = readViaItk(path, info, ItkFormat::Nifti);
    } catch (const IoError& e) {
      // ITK refuses float32 sforms that are orthonormal only to float precision; the
      // geometry is ours anyway (applyNiftiGeometry), so read the voxels ourselves.
      if (std::string(e.what()).find("orthonormal") == std::string::npos) throw;
      vol = readNiftiVoxels(path, peek.slope, peek.inter, info);
    }
  }
  std::visit([&](auto& v) { applyNiftiGeometry(path, v.geometry(), info); }, vol);
  const std::string ext = lower(fileExtension(path));
  if (peek.ok && isSingleFileNifti(ext) && (peek.datatype == 16 || peek.datatype == 64) &&
      std::holds_alternative<VolumeF32>(vol)) {
    const bool scaled = niftiScaled(peek);
    const double slope = scaled ? peek.slope : 1.0, inter = scaled ? peek.inter : 0.0;
    auto& fv = std::get<VolumeF32>(vol);
    const int64_t restored = peek.datatype == 16 ? restoreNonFinite<float>(path, peek, fv, slope, inter)
                                                 : restoreNonFinite<double>(path, peek, fv, slope, inter);
    if (restored > 0) info.notes.push_back(std::to_string(restored) + " NaN/inf voxel(s) kept as they are in the file");
  }
  if (niftiScaled(peek)) {
    const bool intSrc = peek.type.find("int") != std::string::npos;
    if (intSrc && peek.slope == std::nearbyint(peek.slope) && peek.inter == std::nearbyint(peek.inter))
      vol = narrowIntegral(std::move(vol), info);
    info.notes.push_back("NIfTI scl_slope " + fmtNum(peek.slope) + ", scl_inter " + fmtNum(peek.inter) +
                         " applied -> " + voxelTypeName(voxelType(vol)));
  }
  return vol;
}

// NRRD: ITK's reader, else volscissors' own (ITK refuses spacings + space and slice patterns).
AnyVolume readNrrdVolume(const std::string& path, ReadInfo& info) {
  AnyVolume vol;
  checkMagic(path, Kind::Nrrd);
  checkNrrdComplete(path);
  try {
    vol = readViaItk(path, info, ItkFormat::Nrrd);
  } catch (const IoError& itkError) {
    // ITK refuses some common files (spacings + space, slice patterns): try our own reader.
    ReadInfo own;
    own.format = "nrrd";
    try {
      vol = readNrrdOwn(path, own);
    } catch (const DataError&) {
      throw;
    } catch (const IoError& ownError) {
      const std::string itkMsg = itkError.what();
      throw IoError(std::string(ownError.what()) +
                    " (ITK: " + (itkMsg.rfind(path + ": ", 0) == 0 ? itkMsg.substr(path.size() + 2) : itkMsg) + ")");
    }
    own.notes.insert(own.notes.begin(), "read by volscissors' NRRD reader (ITK: " +
                                            std::string(itkError.what()).substr(path.size() + 2) + ")");
    info = own;
  }
  return vol;
}

}  // namespace

AnyVolume readVolume(const std::string& path, const ReadOptions& options, ReadInfo* infoOut, Progress& progress) {
  ReadInfo local;
  ReadInfo& info = infoOut ? *infoOut : local;
  info = ReadInfo{};
  if (path.empty()) throw IoError("input path is empty");
  std::error_code ec;
  if (!fs::exists(path, ec)) throw IoError(path + ": file not found");
  noteInputFile(path);
  if (isZarrPath(path)) {  // OME-Zarr folder (io/zarr_io.h)
    ZarrInfo z;
    AnyVolume v = readZarr(path, 0, &z, progress);
    info.format = "ome-zarr";
    info.sourceType = z.dtype;
    info.notes = z.notes;
    info.orientationInHeader = z.hasDirection;
    return v;
  }
  if (fileExtension(path) == ".img") {  // Analyze/NIfTI pair: read through the header
    const std::string hdr = fs::path(path).replace_extension(".hdr").string();
    if (fs::exists(hdr, ec)) return readVolume(hdr, options, infoOut, progress);
  }
  Kind kind = kindOf(path);
  if (kind == Kind::Unknown) throw IoError(path + ": unknown volume format '" + fileExtension(path) + "'");

  progress.report(0.0, "read");
  AnyVolume vol;
  try {
    switch (kind) {
      case Kind::Vtk:
        info.format = "vtk";
        vol = readVtkLegacyVolume(path, info);
        break;
      case Kind::Vti:
        info.format = "vti";
        vol = readVtiVolume(path, info);
        break;
      case Kind::Dicom:
        info.format = "dicom";
        vol = readDicomVolume(path, options, info, progress);
        break;
      case Kind::Nifti:
        info.format = "nifti";
        vol = readNiftiVolume(path, info);
        break;
      case Kind::Nrrd:
        info.format = "nrrd";
        vol = readNrrdVolume(path, info);
        break;
      case Kind::Meta:
        info.format = "metaimage";
        checkMagic(path, kind);
        checkMetaComplete(path);
        vol = readViaItk(path, info, ItkFormat::Meta);
        break;
      case Kind::Png:
        info.format = "png";
        checkMagic(path, kind);
        vol = readPngVolume(path, info);
        break;
      case Kind::Tiff:
        info.format = "tiff";
        checkMagic(path, kind);
        vol = readViaItk(path, info, ItkFormat::Tiff, static_cast<uint64_t>(fs::file_size(path, ec)));
        break;
      default:
        throw IoError(path + ": unknown volume format");
    }
  } catch (const std::bad_alloc&) {
    throw IoError(path + ": out of memory while reading");
  } catch (const std::logic_error& e) {  // std::stoll & co. on a malformed header field
    throw IoError(path + ": malformed header (" + oneLine(e.what()) + ")");
  }
  info.orientationInHeader = headerHasOrientation(path, info.format);
  const Geometry& g = geometryOf(vol);
  if (!options.allow2D && g.dims[2] == 1)
    throw IoError(path + ": is a 2D image (" + std::to_string(g.dims[0]) + "x" + std::to_string(g.dims[1]) +
                  "), a 3D volume is needed");
  progress.report(1.0, "read");
  return vol;
}

namespace {

void writeVolumeItk(const AnyVolume& volume, const std::string& path, const std::string& target) {
  const std::string ext = fileExtension(target);
  ItkFormat fmt;
  bool compress = false;
  if (ext == ".nii" || ext == ".nii.gz") {
    fmt = ItkFormat::Nifti;
    compress = ext == ".nii.gz";
  } else if (ext == ".nrrd" || ext == ".nhdr") {
    fmt = ItkFormat::Nrrd;
    compress = true;
  } else if (ext == ".mha" || ext == ".mhd") {
    fmt = ItkFormat::Meta;
    compress = true;
  } else {
    throw IoError(target + ": cannot write volumes as '" + ext + "' (use .nii, .nii.gz, .nrrd, .nhdr, .mha or .mhd)");
  }
  const Geometry& g = geometryOf(volume);
  RawHeader h;
  for (int i = 0; i < 3; ++i) {
    h.dims[i] = g.dims[i];
    h.spacing[i] = g.spacing[i];
    h.origin[i] = g.origin[i];
    for (int r = 0; r < 3; ++r) h.direction[3 * r + i] = g.direction(r, i);
  }
  switch (voxelType(volume)) {
    case VoxelType::UInt8:
      h.comp = Comp::UInt8;
      break;
    case VoxelType::Int16:
      h.comp = Comp::Int16;
      break;
    case VoxelType::UInt16:
      h.comp = Comp::UInt16;
      break;
    case VoxelType::Float32:
      h.comp = Comp::Float32;
      break;
  }
  const void* data = std::visit([](const auto& v) -> const void* { return v.data(); }, volume);
  itkWriteFile(fmt, path, h, data, compress);
}

// ITK does not report short writes (a full disk gave exit 0 and a truncated NIfTI or
// MetaImage): check that what was written holds the whole volume, decoding compressed data.
void verifyWrittenVolume(const AnyVolume& volume, const std::string& written, const std::string& target) {
  const std::string ext = fileExtension(target);
  const double need = static_cast<double>(byteSize(volume));
  std::error_code ec;
  try {
    if (ext == ".nii") {
      const double have = static_cast<double>(fs::file_size(written, ec));
      if (ec || have < need + 348) throw IoError("");
    } else if (ext == ".nii.gz") {
      if (gzipInflatedSize(written, need + 348, 0, false) < need + 348) throw IoError("");
    } else if (ext == ".nrrd" || ext == ".nhdr") {
      // A header cut short (0 bytes on a full disk) is not "a layout checkNrrdComplete does
      // not understand": it must at least be a whole NRRD header naming its data.
      std::ifstream in(written, std::ios::binary);
      std::string head(65536, '\0');
      in.read(head.data(), static_cast<std::streamsize>(head.size()));
      head.resize(static_cast<size_t>(std::max<std::streamsize>(in.gcount(), 0)));
      if (head.rfind("NRRD", 0) != 0 || (ext == ".nhdr" && head.find("data file:") == std::string::npos &&
                                         head.find("datafile:") == std::string::npos))
        throw IoError("");
      checkNrrdComplete(written);
    } else if (ext == ".mha" || ext == ".mhd") {
      checkMetaComplete(written);
    }
  } catch (const IoError&) {
    throw IoError(target + ": the written file is incomplete (disk full?)");
  }
}

}  // namespace

void writeVolume(const AnyVolume& volume, const std::string& path) {
  const std::string ext = fileExtension(path);
  const Geometry& g = geometryOf(volume);
  if (g.voxelCount() <= 0 || byteSize(volume) == 0) throw IoError(path + ": refusing to write an empty volume");
  if (isZarrPath(path)) return writeZarr(volume, path);  // OME-Zarr folder with a pyramid (io/zarr_io.h)
  try {
    if (ext == ".nhdr" || ext == ".mhd") {
      // Header + detached data file: write both into a private temporary folder beside the
      // target (so the header names the final data file), then move the data file first and
      // the header last. A failure leaves no file under the final names.
      checkOutputPath(path);
      const fs::path target(resolveOutputTarget(path));  // through a symbolic link, never over it
      const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
      const fs::path tmpDir = dir / (".vs_tmp_" + std::to_string(::getpid()) + "_" + target.filename().string());
      std::error_code ec;
      fs::remove_all(tmpDir, ec);
      if (!fs::create_directory(tmpDir, ec)) throw IoError(path + ": cannot create temporary folder: " + ec.message());
      const int slot = registerTemporary((tmpDir / target.filename()).c_str());  // removed on an abrupt cancel
      try {
        const fs::path tmpHeader = tmpDir / target.filename();
        writeVolumeItk(volume, tmpHeader.string(), path);
        verifyWrittenVolume(volume, tmpHeader.string(), path);
        if (globalCancelRequested()) throw Cancelled();
        std::vector<fs::path> dataFiles;
        for (const auto& e : fs::directory_iterator(tmpDir))
          if (e.path().filename() != target.filename()) dataFiles.push_back(e.path());
        for (const auto& f : dataFiles) {
          fs::rename(f, dir / f.filename(), ec);
          if (ec) throw IoError(path + ": cannot move data file into place: " + ec.message());
        }
        fs::rename(tmpHeader, target, ec);
        if (ec) throw IoError(path + ": cannot move header into place: " + ec.message());
        fs::remove_all(tmpDir, ec);
      } catch (...) {
        fs::remove_all(tmpDir, ec);
        unregisterTemporary(slot);
        throw;
      }
      unregisterTemporary(slot);
      return;
    }
    writeAtomically(path, [&](const std::string& tmp) {
      writeVolumeItk(volume, tmp, path);
      verifyWrittenVolume(volume, tmp, path);
    });
  } catch (const std::bad_alloc&) {
    throw IoError(path + ": out of memory while writing");
  }
}

}  // namespace vs
