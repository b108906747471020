#include "io/mapped_volume.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/io_internal.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vs {
namespace {

namespace fs = std::filesystem;
using io_detail::Comp;

// Where and how the voxels lie in a file.
struct Layout {
  Geometry g;
  Comp comp = Comp::UInt8;
  bool swap = false;
  uint64_t offset = 0;
  std::string dataFile;
  bool scaled = false;
  double slope = 1, inter = 0;
  ReadInfo info;
};

std::string readHead(const std::string& path, size_t most) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw IoError(path + ": cannot open for reading");
  std::string s(most, '\0');
  f.read(s.data(), std::streamsize(most));
  s.resize(size_t(f.gcount()));
  return s;
}

bool isGzip(const std::string& head) {
  return head.size() >= 2 && (unsigned char)head[0] == 0x1f && (unsigned char)head[1] == 0x8b;
}

template <class T>
T field(const std::string& h, size_t off, bool swap) {
  T v;
  std::memcpy(&v, h.data() + off, sizeof v);
  if (swap) io_detail::byteSwap(&v, sizeof v, 1);
  return v;
}

Comp niftiComp(int dt, const std::string& path) {
  switch (dt) {
    case 2:
      return Comp::UInt8;
    case 4:
      return Comp::Int16;
    case 8:
      return Comp::Int32;
    case 16:
      return Comp::Float32;
    case 64:
      return Comp::Float64;
    case 256:
      return Comp::Int8;
    case 512:
      return Comp::UInt16;
    case 768:
      return Comp::UInt32;
    case 1024:
      return Comp::Int64;
    case 1280:
      return Comp::UInt64;
    default:
      throw IoError(path + ": unsupported NIfTI datatype " + std::to_string(dt));
  }
}

Layout niftiLayout(const std::string& path) {
  const std::string h = readHead(path, 540);
  if (isGzip(h)) throw IoError(path + ": gzip-compressed NIfTI cannot be memory-mapped");
  if (h.size() < 348) throw IoError(path + ": truncated NIfTI header (" + std::to_string(h.size()) + " of 348 bytes)");
  int32_t size = field<int32_t>(h, 0, false);
  const bool swap = !(size == 348 || size == 540);
  if (swap) io_detail::byteSwap(&size, 4, 1);
  if (size != 348 && size != 540) throw IoError(path + ": wrong magic, not a NIfTI file");
  if (size == 540 && h.size() < 540) throw IoError(path + ": truncated NIfTI-2 header");
  Layout L;
  L.swap = swap;
  int64_t dim[8];
  double pix[4], voxOffset;
  int dt;
  if (size == 348) {
    for (int i = 0; i < 8; ++i) dim[i] = field<int16_t>(h, size_t(40 + 2 * i), swap);
    for (int i = 0; i < 4; ++i) pix[i] = field<float>(h, size_t(76 + 4 * i), swap);
    dt = field<int16_t>(h, 70, swap);
    voxOffset = field<float>(h, 108, swap);
    L.slope = field<float>(h, 112, swap);
    L.inter = field<float>(h, 116, swap);
  } else {
    for (int i = 0; i < 8; ++i) dim[i] = field<int64_t>(h, size_t(16 + 8 * i), swap);
    for (int i = 0; i < 4; ++i) pix[i] = field<double>(h, size_t(104 + 8 * i), swap);
    dt = field<int16_t>(h, 12, swap);
    voxOffset = double(field<int64_t>(h, 168, swap));
    L.slope = field<double>(h, 176, swap);
    L.inter = field<double>(h, 184, swap);
  }
  if (dim[0] < 1 || dim[0] > 7) throw IoError(path + ": NIfTI dim[0] " + std::to_string(dim[0]) + " outside 1..7");
  for (int i = 1; i <= dim[0]; ++i)
    if (dim[i] < 1) throw IoError(path + ": NIfTI dim[" + std::to_string(i) + "] is " + std::to_string(dim[i]));
  L.comp = niftiComp(dt, path);
  for (int i = 0; i < 3; ++i) {
    L.g.dims[size_t(i)] = i < dim[0] ? dim[i + 1] : 1;
    L.g.spacing[i] = std::fabs(pix[i + 1]) > 0 ? std::fabs(pix[i + 1]) : 1.0;
  }
  int64_t frames = 1;
  for (int i = 4; i <= dim[0]; ++i) frames *= dim[i];
  if (frames > 1) L.info.notes.push_back("4D NIfTI: the first of " + std::to_string(frames) + " volumes mapped");
  const std::string ext = fileExtension(path);
  if (ext == ".hdr") {
    L.dataFile = path.substr(0, path.size() - 4) + ".img";
    L.offset = 0;  // as the in-memory reader
  } else {
    L.dataFile = path;
    if (!(voxOffset >= 348) || voxOffset != std::floor(voxOffset))
      throw IoError(path + ": NIfTI vox_offset " + std::to_string(voxOffset) + " is not a byte offset past the header");
    L.offset = uint64_t(voxOffset);
  }
  L.scaled = std::isfinite(L.slope) && L.slope != 0 && (L.slope != 1 || L.inter != 0);
  L.info.format = "nifti";
  L.info.sourceType = io_detail::compName(L.comp);
  io_detail::applyNiftiGeometry(path, L.g, L.info);
  L.info.orientationInHeader = io_detail::headerHasOrientation(path, "nifti");
  return L;
}

Layout nrrdLayout(const std::string& path) {
  // The header ends at the first empty line: read until one is found (headers are small).
  std::string head = readHead(path, 1 << 16);
  if (head.rfind("NRRD", 0) != 0) throw IoError(path + ": wrong magic, not a NRRD file");
  if (head.find("\n\n") == std::string::npos && head.find("\r\n\r\n") == std::string::npos && head.size() == (1u << 16))
    head = readHead(path, 1 << 24);
  const io_detail::NrrdHeader h = io_detail::parseNrrdHeader(head, path);
  Layout L;
  if (!io_detail::nrrdType(h.get("type"), L.comp))
    throw IoError(path + ": unsupported NRRD type '" + h.get("type") + "'");
  std::string enc = h.get("encoding"), endian = h.get("endian");
  for (auto* t : {&enc, &endian})
    for (char& ch : *t) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (enc != "raw") throw IoError(path + ": NRRD encoding '" + enc + "' cannot be memory-mapped (raw only)");
  const int dim = std::atoi(h.get("dimension").c_str());
  std::istringstream ss(h.get("sizes"));
  std::vector<int64_t> sizes;
  for (int64_t v; ss >> v;) sizes.push_back(v);
  if (dim < 2 || dim > 3 || int(sizes.size()) != dim)
    throw IoError(path + ": NRRD dimension/sizes ('" + h.get("dimension") + "', '" + h.get("sizes") +
                  "') cannot be memory-mapped (2 or 3 spatial axes, one component)");
  for (int64_t s : sizes)
    if (s < 1) throw IoError(path + ": absurd NRRD size " + std::to_string(s));
  if (dim == 3 && sizes[0] <= 4 && !h.get("kinds").empty() && h.get("kinds").find("domain") != 0)
    throw IoError(path + ": NRRD with " + std::to_string(sizes[0]) + " components cannot be memory-mapped");
  L.g.dims = {1, 1, 1};
  for (int i = 0; i < dim; ++i) L.g.dims[size_t(i)] = sizes[size_t(i)];
  io_detail::nrrdGeometry(h, 0, dim, L.g, path);
  const std::vector<std::string> files = io_detail::nrrdDataFiles(h, path);
  if (files.size() > 1) throw IoError(path + ": NRRD data in several files cannot be memory-mapped");
  L.dataFile = files.empty() ? path : files[0];
  uint64_t at = files.empty() ? h.dataStart : 0;
  const long lineSkip = std::atol(h.get("line skip").c_str());
  const long byteSkip = std::atol(h.get("byte skip").c_str());
  if (lineSkip < 0 || byteSkip < -1) throw IoError(path + ": negative NRRD line skip or byte skip");
  if (lineSkip > 0) {  // lines of the data file skipped first
    std::ifstream f(L.dataFile, std::ios::binary);
    if (!f) throw IoError(path + ": data file '" + L.dataFile + "' cannot be opened");
    f.seekg(std::streamoff(at));
    std::string line;
    for (long l = 0; l < lineSkip; ++l)
      if (!std::getline(f, line)) throw IoError(L.dataFile + ": fewer lines than 'line skip'");
    at = uint64_t(f.tellg());
  }
  L.offset = byteSkip == -1 ? ~uint64_t(0) : at + uint64_t(byteSkip);  // -1: the data ends the file
  L.swap = io_detail::compSize(L.comp) > 1 && (endian == "big") == io_detail::hostIsLittleEndian();
  L.info.format = "nrrd";
  L.info.sourceType = io_detail::compName(L.comp);
  L.info.orientationInHeader = io_detail::headerHasOrientation(path, "nrrd");
  return L;
}

Layout layoutOf(const std::string& path) {
  const std::string ext = fileExtension(path);
  if (ext == ".nii" || ext == ".hdr") return niftiLayout(path);
  if (ext == ".img") {
    const std::string hdr = path.substr(0, path.size() - 4) + ".hdr";
    return niftiLayout(hdr);
  }
  if (ext == ".nrrd" || ext == ".nhdr") return nrrdLayout(path);
  if (ext.size() > 3 && ext.compare(ext.size() - 3, 3, ".gz") == 0)
    throw IoError(path + ": gzip-compressed data cannot be memory-mapped");
  throw IoError(path + ": only uncompressed NIfTI (.nii, .hdr/.img) and raw NRRD (.nrrd, .nhdr) can be memory-mapped");
}

// A read-only mapping of a whole file, unmapped when the last chunk loader holding it goes.
struct Mapping {
  const unsigned char* data = nullptr;
  size_t size = 0;
  ~Mapping() {
    if (data) ::munmap(const_cast<unsigned char*>(data), size);
  }
};

template <class T>
float valueAt(const unsigned char* p, bool swap) {
  T v;
  std::memcpy(&v, p, sizeof v);
  if (swap) io_detail::byteSwap(&v, sizeof v, 1);
  return float(v);
}

float convert(const unsigned char* p, Comp c, bool swap) {
  switch (c) {
    case Comp::Int8:
      return valueAt<int8_t>(p, swap);
    case Comp::UInt8:
      return valueAt<uint8_t>(p, swap);
    case Comp::Int16:
      return valueAt<int16_t>(p, swap);
    case Comp::UInt16:
      return valueAt<uint16_t>(p, swap);
    case Comp::Int32:
      return valueAt<int32_t>(p, swap);
    case Comp::UInt32:
      return valueAt<uint32_t>(p, swap);
    case Comp::Int64:
      return valueAt<int64_t>(p, swap);
    case Comp::UInt64:
      return valueAt<uint64_t>(p, swap);
    case Comp::Float32:
      return valueAt<float>(p, swap);
    case Comp::Float64:
      return valueAt<double>(p, swap);
  }
  return 0;
}

double rawAt(const unsigned char* p, Comp c, bool swap) {
  if (c == Comp::Float64) {
    double v;
    std::memcpy(&v, p, 8);
    if (swap) io_detail::byteSwap(&v, 8, 1);
    return v;
  }
  return double(convert(p, c, swap));
}

}  // namespace

bool isMappable(const std::string& path) {
  try {
    layoutOf(path);
    return true;
  } catch (const Error&) {
    return false;
  }
}

ChunkedVolume openMapped(const std::string& path, ReadInfo* info, const Index3& chunk) {
  Layout L = layoutOf(path);
  for (int a = 0; a < 3; ++a)
    if (chunk[size_t(a)] < 1) throw InvalidArgument("openMapped: chunk sizes must be >= 1");
  const std::string& file = L.dataFile;
  const int fd = ::open(file.c_str(), O_RDONLY);
  if (fd < 0) throw IoError(file + ": cannot open for reading");
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    ::close(fd);
    throw IoError(file + ": cannot read its size");
  }
  const uint64_t length = uint64_t(st.st_size);
  const uint64_t es = io_detail::compSize(L.comp);
  uint64_t need = es;
  for (int a = 0; a < 3; ++a) need = io_detail::checkedMul(need, uint64_t(L.g.dims[size_t(a)]), path, "data size");
  if (L.offset == ~uint64_t(0)) L.offset = length >= need ? length - need : 0;  // NRRD byte skip -1
  const uint64_t end = io_detail::checkedAdd(L.offset, need, path, "data end");
  if (end > length) {
    ::close(fd);
    throw IoError(path + ": voxel data is truncated (the header promises " + std::to_string(need) +
                  " bytes from offset " + std::to_string(L.offset) + ", the file " + file + " holds " +
                  std::to_string(length) + ")");
  }
  auto map = std::make_shared<Mapping>();
  void* p = ::mmap(nullptr, size_t(length), PROT_READ, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) throw IoError(file + ": memory mapping failed");
  map->data = static_cast<const unsigned char*>(p);
  map->size = size_t(length);
  ChunkedVolume v;
  v.geometry = L.g;
  const bool kept = !L.scaled && (L.comp == Comp::UInt8 || L.comp == Comp::Int16 || L.comp == Comp::UInt16 ||
                                  L.comp == Comp::Float32);
  v.type = !kept                    ? VoxelType::Float32
           : L.comp == Comp::UInt8  ? VoxelType::UInt8
           : L.comp == Comp::Int16  ? VoxelType::Int16
           : L.comp == Comp::UInt16 ? VoxelType::UInt16
                                    : VoxelType::Float32;
  if (!kept) L.info.notes.push_back(L.info.sourceType + (L.scaled ? " scaled" : "") + " voxels served as float32");
  if (L.scaled) {  // appended piece by piece: `"*" + std::to_string(...)` trips GCC 12's -Wrestrict (bug 105329)
    L.info.sourceType += '*';
    L.info.sourceType += std::to_string(L.slope);
    L.info.sourceType += '+';
    L.info.sourceType += std::to_string(L.inter);
  }
  v.chunk = chunk;
  const Index3 d = L.g.dims;
  v.load = [map, L, d, chunk, es](const Index3& c) {
    std::vector<float> out(size_t(chunk[0] * chunk[1] * chunk[2]), 0.0f);
    const int64_t x0 = c[0] * chunk[0], y0 = c[1] * chunk[1], z0 = c[2] * chunk[2];
    const int64_t nx = std::min(chunk[0], d[0] - x0), ny = std::min(chunk[1], d[1] - y0),
                  nz = std::min(chunk[2], d[2] - z0);
    for (int64_t z = 0; z < nz; ++z)
      for (int64_t y = 0; y < ny; ++y) {
        const unsigned char* row = map->data + L.offset + es * uint64_t(x0 + d[0] * ((y0 + y) + d[1] * (z0 + z)));
        float* dst = out.data() + chunk[0] * (y + chunk[1] * z);
        if (L.scaled)
          for (int64_t x = 0; x < nx; ++x)
            dst[x] = float(rawAt(row + es * uint64_t(x), L.comp, L.swap) * L.slope + L.inter);
        else
          for (int64_t x = 0; x < nx; ++x) dst[x] = convert(row + es * uint64_t(x), L.comp, L.swap);
      }
    return out;
  };
  if (info) *info = L.info;
  return v;
}

}  // namespace vs
