// Memory-mapped NIfTI/NRRD as chunked volumes (issue 25): voxel for voxel and geometry equal to
// the in-memory reader, for every kept type, byte order and NIfTI scaling; what cannot be mapped
// and what is broken is refused with an IoError naming the file.
#include "io/mapped_volume.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "io/volume_io.h"

namespace vs {
namespace {

namespace fs = std::filesystem;

struct Dir {
  fs::path p = fs::temp_directory_path() / ("vs_mapped_" + std::to_string(::getpid()));
  Dir() { fs::create_directories(p); }
  ~Dir() {
    std::error_code ec;
    fs::remove_all(p, ec);
  }
  std::string file(const std::string& n) const { return (p / n).string(); }
};

std::string bytesOf(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
void writeBytes(const std::string& path, const std::string& b) { std::ofstream(path, std::ios::binary) << b; }

Geometry testGeometry() {
  Geometry g;
  g.dims = {23, 17, 13};  // chunk sizes below do not divide them
  g.spacing = {0.7, 0.9, 1.6};
  g.origin = {-12.5, 30.25, 7};
  g.direction = Eigen::AngleAxisd(0.3, Vec3(0.2, 0.5, 1).normalized()).toRotationMatrix();
  return g;
}

template <class V>
V randomVolume(uint32_t seed, double lo, double hi) {
  V v(testGeometry());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  for (int64_t i = 0; i < v.size(); ++i) v.data()[i] = typename V::value_type(u(rng));
  return v;
}

// The mapped volume read through a small cache equals the in-memory reading, voxel for voxel.
void expectSameAsReader(const std::string& path, VoxelType expectType) {
  SCOPED_TRACE(path);
  ASSERT_TRUE(isMappable(path));
  ReadInfo mi;
  ChunkedVolume cv = openMapped(path, &mi, {8, 5, 6});
  const AnyVolume mem = readVolume(path);
  const Geometry& g = geometryOf(mem);
  EXPECT_EQ(cv.geometry.dims, g.dims);
  EXPECT_LT((cv.geometry.spacing - g.spacing).norm(), 1e-6);
  EXPECT_LT((cv.geometry.origin - g.origin).norm(), 1e-4);
  EXPECT_LT((cv.geometry.direction - g.direction).norm(), 1e-6);
  EXPECT_EQ(cv.type, expectType);
  ChunkCache cache(std::move(cv), 8 * 5 * 6 * 4 * 3);  // three chunks: evictions all along
  const VolumeF32 a = toFloat(cache.readAll()), b = toFloat(mem);
  ASSERT_EQ(a.size(), b.size());
  int64_t differ = 0;
  for (int64_t i = 0; i < a.size(); ++i) differ += a.data()[i] != b.data()[i];
  EXPECT_EQ(differ, 0);
}

TEST(MappedVolume, EqualsTheReaderForEveryTypeAndFormat) {
  Dir d;
  const std::vector<std::pair<AnyVolume, VoxelType>> vols = {
      {randomVolume<VolumeU8>(1, 0, 255), VoxelType::UInt8},
      {randomVolume<VolumeI16>(2, -3000, 3000), VoxelType::Int16},
      {randomVolume<VolumeU16>(3, 0, 65000), VoxelType::UInt16},
      {randomVolume<VolumeF32>(4, -1e3, 1e3), VoxelType::Float32}};
  int k = 0;
  for (const auto& [v, t] : vols) {
    const std::string stem = std::string("v").append(std::to_string(k));  // not "v" + ...: GCC 12's -Wrestrict (105329)
    const std::string nii = d.file(stem + ".nii"), nhdr = d.file(stem + ".nhdr");
    writeVolume(v, nii);
    expectSameAsReader(nii, t);
    writeVolume(v, nhdr);
    if (isMappable(nhdr)) expectSameAsReader(nhdr, t);  // (a gzip'd detached file is not mappable)
    ++k;
  }
}

TEST(MappedVolume, BigEndianNrrdAndScaledNifti) {
  Dir d;
  // A raw big-endian int16 NRRD with attached data, written by hand.
  const VolumeI16 v = randomVolume<VolumeI16>(5, -2000, 2000);
  std::string data(size_t(v.size()) * 2, '\0');
  for (int64_t i = 0; i < v.size(); ++i) {
    const uint16_t u = uint16_t(v.data()[i]);
    data[size_t(2 * i)] = char(u >> 8);
    data[size_t(2 * i + 1)] = char(u & 0xff);
  }
  const std::string nrrd = d.file("be.nrrd");
  writeBytes(nrrd,
             "NRRD0004\ntype: short\ndimension: 3\nsizes: 23 17 13\nspace: left-posterior-superior\n"
             "space directions: (0.7,0,0) (0,0.9,0) (0,0,1.6)\nspace origin: (1,2,3)\nendian: big\nencoding: raw\n\n" +
                 data);
  expectSameAsReader(nrrd, VoxelType::Int16);
  // Detached raw float32 data after 16 bytes to skip, and at the end of a file (byte skip -1).
  const VolumeF32 f = randomVolume<VolumeF32>(7, -50, 50);
  const std::string raw(reinterpret_cast<const char*>(f.data()), size_t(f.size()) * 4);
  writeBytes(d.file("f.raw"), std::string(16, 'j') + raw);
  const std::string head =
      "NRRD0004\ntype: float\ndimension: 3\nsizes: 23 17 13\nspacings: 0.5 0.6 2\nendian: little\nencoding: raw\n";
  writeBytes(d.file("f.nhdr"), head + "data file: f.raw\nbyte skip: 16\n");
  expectSameAsReader(d.file("f.nhdr"), VoxelType::Float32);
  writeBytes(d.file("e.nhdr"), head + "data file: f.raw\nbyte skip: -1\n");
  expectSameAsReader(d.file("e.nhdr"), VoxelType::Float32);
  // NIfTI with scl_slope / scl_inter: served as float32 like the reader's scaled values.
  const std::string nii = d.file("s.nii");
  writeVolume(AnyVolume(v), nii);
  std::string b = bytesOf(nii);
  const float slope = 0.25f, inter = -7.5f;
  std::memcpy(&b[112], &slope, 4);
  std::memcpy(&b[116], &inter, 4);
  writeBytes(nii, b);
  expectSameAsReader(nii, VoxelType::Float32);
}

TEST(MappedVolume, RefusesWhatItCannotMapAndBrokenFiles) {
  Dir d;
  const AnyVolume v = randomVolume<VolumeU8>(6, 0, 255);
  const std::string nii = d.file("v.nii"), gz = d.file("v.nii.gz"), nrrd = d.file("v.nrrd");
  writeVolume(v, nii);
  writeVolume(v, gz);
  writeVolume(v, nrrd);  // gzip encoding
  auto refused = [](const std::string& path, const std::string& words) {
    SCOPED_TRACE(path);
    try {
      openMapped(path);
      ADD_FAILURE() << "not refused";
    } catch (const IoError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(path), std::string::npos) << m;
      EXPECT_NE(m.find(words), std::string::npos) << m;
    }
  };
  EXPECT_FALSE(isMappable(gz));
  refused(gz, "gzip");
  if (bytesOf(nrrd).find("encoding: raw") == std::string::npos) {
    EXPECT_FALSE(isMappable(nrrd));
    refused(nrrd, "encoding");
  }
  // Truncated data: refused when opened (sizes against the file's length).
  const std::string full = bytesOf(nii), cut = d.file("cut.nii");
  writeBytes(cut, full.substr(0, full.size() - 100));
  EXPECT_TRUE(isMappable(cut));  // the header is fine: openMapped says what is wrong
  refused(cut, "truncated");
  // Header fields: a zero dimension, an unknown datatype, a vox_offset inside the header.
  auto patched = [&](const std::string& name, size_t at, const void* val, size_t n) {
    std::string b = full;
    std::memcpy(&b[at], val, n);
    writeBytes(d.file(name), b);
    return d.file(name);
  };
  const int16_t zero = 0, badType = 3;
  const float badOffset = 100;
  refused(patched("dim.nii", 42, &zero, 2), "dim[1]");
  refused(patched("type.nii", 70, &badType, 2), "datatype");
  refused(patched("off.nii", 108, &badOffset, 4), "vox_offset");
  // A NRRD whose attached data is short; a missing detached data file.
  const std::string shortNrrd = d.file("short.nrrd");
  writeBytes(shortNrrd, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n" + std::string(60, 'x'));
  refused(shortNrrd, "truncated");
  const std::string lost = d.file("lost.nhdr");
  writeBytes(lost, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: nothere.raw\n");
  try {
    openMapped(lost);
    ADD_FAILURE() << "missing data file not refused";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("nothere.raw"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vs
