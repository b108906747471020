// Volume I/O: write/read round trips for every writable format and voxel type (geometry
// and voxels), hand-made files for the formats we only read (legacy VTK, VTI, scaled NIfTI,
// NRRD slice patterns, PNG/TIFF), and every failure path the readers promise.
#include "io/volume_io.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <zlib.h>

#include <csignal>
#include <cstring>

#include "io/png_io.h"
#include "io_test_util.h"

using namespace vs;
using namespace vs::test;

namespace {

template <class T>
void roundTrip(const std::string& ext) {
  TempDir dir("rt" + std::to_string(sizeof(T)) + ext.substr(1));
  const Geometry g = testGeometry({9, 7, 5});
  const Volume<T> vol = rampVolume<T>(g);
  const std::string path = dir.file("vol" + ext);
  writeVolume(AnyVolume(vol), path);
  ReadInfo info;
  const AnyVolume back = readVolume(path, {}, &info);
  ASSERT_EQ(voxelType(back), VoxelTypeOf<T>::value) << ext;
  const auto& b = std::get<Volume<T>>(back);
  expectSameGeometry(b.geometry(), g);
  EXPECT_EQ(b.voxels(), vol.voxels()) << ext;
  // Nothing but the output (and its data file) is left behind.
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir.path)) {
    ++files;
    EXPECT_EQ(e.path().filename().string().rfind(".", 0), std::string::npos) << "left-over " << e.path();
  }
  EXPECT_EQ(files, (ext == ".nhdr" || ext == ".mhd") ? 2u : 1u);
}

}  // namespace

class RoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(RoundTrip, AllVoxelTypesKeepGeometryAndValues) {
  roundTrip<uint8_t>(GetParam());
  roundTrip<int16_t>(GetParam());
  roundTrip<uint16_t>(GetParam());
  roundTrip<float>(GetParam());
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip, ::testing::Values(".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd"),
                         [](const auto& test) {
                           return test.param.substr(1) == "nii.gz" ? std::string("niigz") : test.param.substr(1);
                         });

TEST(VolumeIo, LabelMapStaysUInt8AndConvertChainKeepsGeometry) {
  TempDir dir("labels");
  Geometry g = testGeometry({4, 5, 6});
  VolumeU8 labels(g, 0);
  labels(1, 2, 3) = 2;
  labels(3, 4, 5) = 1;
  writeVolume(AnyVolume(labels), dir.file("a.nii.gz"));
  const AnyVolume a = readVolume(dir.file("a.nii.gz"));
  writeVolume(a, dir.file("b.nrrd"));
  const AnyVolume b = readVolume(dir.file("b.nrrd"));
  writeVolume(b, dir.file("c.mha"));
  const AnyVolume c = readVolume(dir.file("c.mha"));
  ASSERT_EQ(voxelType(c), VoxelType::UInt8);
  expectSameGeometry(geometryOf(c), g);
  EXPECT_EQ(std::get<VolumeU8>(c).voxels(), labels.voxels());
}

// ---------------------------------------------------------------- NIfTI scaling policy
namespace {

// Minimal NIfTI-1 single file: uint8 or int16 data, sform (RAS) with given spacing/origin.
std::string niftiFile(int16_t datatype, const std::vector<int16_t>& values, Index3 dims, float slope, float inter) {
  std::string h(352, '\0');
  auto put32 = [&](size_t off, int32_t v) { std::memcpy(&h[off], &v, 4); };
  auto put16 = [&](size_t off, int16_t v) { std::memcpy(&h[off], &v, 2); };
  auto putf = [&](size_t off, float v) { std::memcpy(&h[off], &v, 4); };
  put32(0, 348);
  put16(40, 3);
  for (int i = 0; i < 3; ++i)
    put16(42 + 2 * static_cast<size_t>(i), static_cast<int16_t>(dims[static_cast<size_t>(i)]));
  for (int i = 3; i < 8; ++i) put16(42 + 2 * static_cast<size_t>(i), 1);
  put16(70, datatype);
  put16(72, datatype == 2 ? 8 : 16);
  putf(76, 1);
  putf(80, 2.0f);
  putf(84, 3.0f);
  putf(88, 4.0f);
  putf(108, 352);
  putf(112, slope);
  putf(116, inter);
  put16(254, 1);  // sform_code
  // srow: x = 2*i + 10, y = 3*j - 20, z = 4*k + 5 (RAS)
  putf(280, 2);
  putf(292, 10);
  putf(300, 3);
  putf(308, -20);
  putf(320, 4);
  putf(324, 5);
  std::memcpy(&h[344], "n+1\0", 4);
  for (int16_t v : values) {
    if (datatype == 2)
      h.push_back(static_cast<char>(v));
    else
      h.append(reinterpret_cast<const char*>(&v), 2);
  }
  return h;
}

}  // namespace

TEST(VolumeIo, NiftiNonIntegralSlopeGivesFloat) {
  TempDir dir("nislope");
  std::vector<int16_t> vals(2 * 3 * 4);
  for (size_t i = 0; i < vals.size(); ++i) vals[i] = static_cast<int16_t>(i * 10);
  writeBytes(dir.file("s.nii"), niftiFile(2, vals, {2, 3, 4}, 2.5f, 1.0f));
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("s.nii"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::Float32);
  const auto& f = std::get<VolumeF32>(v);
  for (size_t i = 0; i < vals.size(); ++i) EXPECT_FLOAT_EQ(f.voxels()[i], vals[i] * 2.5f + 1.0f);
  EXPECT_EQ(info.sourceType, "uint8*2.5+1");
  // RAS sform -> LPS: x and y flip sign.
  const Geometry& g = f.geometry();
  EXPECT_NEAR(g.spacing[0], 2, 1e-6);
  EXPECT_NEAR(g.spacing[1], 3, 1e-6);
  EXPECT_NEAR(g.spacing[2], 4, 1e-6);
  EXPECT_NEAR(g.origin[0], -10, 1e-6);
  EXPECT_NEAR(g.origin[1], 20, 1e-6);
  EXPECT_NEAR(g.origin[2], 5, 1e-6);
  EXPECT_NEAR(g.direction(0, 0), -1, 1e-6);
  EXPECT_NEAR(g.direction(1, 1), -1, 1e-6);
  EXPECT_NEAR(g.direction(2, 2), 1, 1e-6);
}

TEST(VolumeIo, NiftiIntegralSlopeOnIntegersStaysInteger) {
  TempDir dir("niint");
  std::vector<int16_t> vals(2 * 2 * 2);
  for (size_t i = 0; i < vals.size(); ++i) vals[i] = static_cast<int16_t>(i * 300);
  writeBytes(dir.file("s.nii"), niftiFile(4, vals, {2, 2, 2}, 1.0f, -1024.0f));
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("s.nii"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::Int16);
  for (size_t i = 0; i < vals.size(); ++i) EXPECT_EQ(std::get<VolumeI16>(v).voxels()[i], vals[i] - 1024);
  ASSERT_FALSE(info.notes.empty());
}

TEST(VolumeIo, Nifti4DReadsTheFirstVolumeWithANote) {
  TempDir dir("ni4d");
  std::vector<int16_t> vals(2 * 2 * 2 * 3);
  for (size_t i = 0; i < vals.size(); ++i) vals[i] = static_cast<int16_t>(i);
  std::string f = niftiFile(4, vals, {2, 2, 2}, 0, 0);
  const int16_t four = 4, t = 3;
  std::memcpy(&f[40], &four, 2);
  std::memcpy(&f[48], &t, 2);
  writeBytes(dir.file("t.nii"), f);
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("t.nii"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::Int16);
  EXPECT_EQ(geometryOf(v).dims, (Index3{2, 2, 2}));
  EXPECT_EQ(std::get<VolumeI16>(v).voxels(), std::vector<int16_t>(vals.begin(), vals.begin() + 8));
  bool noted = false;
  for (const auto& n : info.notes) noted |= n.find("first 3D volume") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(VolumeIo, NiftiHeaderImagePair) {
  TempDir dir("nipair");
  std::vector<int16_t> vals(2 * 2 * 2);
  for (size_t i = 0; i < vals.size(); ++i) vals[i] = static_cast<int16_t>(100 + i);
  std::string f = niftiFile(4, vals, {2, 2, 2}, 0, 0);
  const float zero = 0;
  std::memcpy(&f[108], &zero, 4);  // vox_offset 0 in the .img
  std::memcpy(&f[344], "ni1\0", 4);
  writeBytes(dir.file("p.hdr"), f.substr(0, 348));
  writeBytes(dir.file("p.img"), f.substr(352));
  for (const char* name : {"p.hdr", "p.img"}) {
    const AnyVolume v = readVolume(dir.file(name));
    ASSERT_EQ(voxelType(v), VoxelType::Int16) << name;
    EXPECT_EQ(std::get<VolumeI16>(v).voxels(), vals) << name;
  }
  writeBytes(dir.file("p.img"), f.substr(352, 6));  // short image file
  EXPECT_THROW(readVolume(dir.file("p.hdr")), IoError);
}

// ---------------------------------------------------------------- legacy VTK (own reader)
namespace {

template <class T>
void putBE(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  std::reverse(b, b + sizeof(T));
  s.append(b, sizeof(T));
}

}  // namespace

TEST(VolumeIo, LegacyVtkBinaryBigEndianWithVectors) {
  TempDir dir("vtk");
  std::string s =
      "# vtk DataFile Version 3.0\ntest\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 2 2\n"
      "SPACING 0.5 1 2\nORIGIN 100 80 1\nPOINT_DATA 12\n";
  // VECTORS first (must be skipped), then the scalars.
  s += "VECTORS flow float\n";
  for (int i = 0; i < 36; ++i) putBE<float>(s, static_cast<float>(i));
  s += "\nSCALARS density short 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < 12; ++i) putBE<int16_t>(s, static_cast<int16_t>(i * 100 - 300));
  s += "\n";
  writeBytes(dir.file("a.vtk"), s);
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("a.vtk"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::Int16);
  const auto& vol = std::get<VolumeI16>(v);
  EXPECT_EQ(vol.dims(), (Index3{3, 2, 2}));
  EXPECT_EQ(vol(2, 1, 1), 11 * 100 - 300);
  EXPECT_EQ(vol(0, 0, 0), -300);
  EXPECT_NEAR(vol.geometry().spacing[0], 0.5, 1e-12);
  EXPECT_NEAR(vol.geometry().spacing[2], 2, 1e-12);
  EXPECT_NEAR(vol.geometry().origin[0], 100, 1e-12);
  EXPECT_EQ(info.format, "vtk");

  // Truncated data -> IoError naming the file.
  writeBytes(dir.file("t.vtk"), s.substr(0, s.size() - 10));
  try {
    readVolume(dir.file("t.vtk"));
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("t.vtk"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  // The same file gzip-compressed as .vtk.gz.
  gzFile gz = gzopen(dir.file("a.vtk.gz").c_str(), "wb");
  gzwrite(gz, s.data(), static_cast<unsigned>(s.size()));
  gzclose(gz);
  const AnyVolume vz = readVolume(dir.file("a.vtk.gz"));
  EXPECT_EQ(std::get<VolumeI16>(vz).voxels(), vol.voxels());
  // POLYDATA is not an image.
  writeBytes(dir.file("p.vtk"), "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 0 float\n");
  EXPECT_THROW(readVolume(dir.file("p.vtk")), IoError);
}

TEST(VolumeIo, LegacyVtkAsciiUnsignedChar) {
  TempDir dir("vtka");
  writeBytes(dir.file("a.vtk"),
             "# vtk DataFile Version 2.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\nASPECT_RATIO 1 1 1\n"
             "ORIGIN 0 0 0\nPOINT_DATA 4\nSCALARS s unsigned_char\nLOOKUP_TABLE default\n1 2 3 250\n");
  const AnyVolume v = readVolume(dir.file("a.vtk"));
  ASSERT_EQ(voxelType(v), VoxelType::UInt8);
  EXPECT_EQ(std::get<VolumeU8>(v).voxels(), (std::vector<uint8_t>{1, 2, 3, 250}));
  ReadOptions no2d;
  no2d.allow2D = false;
  EXPECT_THROW(readVolume(dir.file("a.vtk"), no2d), IoError);
}

// ---------------------------------------------------------------- VTK XML .vti (own reader)
namespace {

std::string vtiCompressed(const std::vector<int16_t>& vals, Index3 dims, size_t blockSize) {
  const std::string raw(reinterpret_cast<const char*>(vals.data()), vals.size() * 2);
  std::vector<std::string> blocks;
  for (size_t at = 0; at < raw.size(); at += blockSize) {
    const std::string part = raw.substr(at, blockSize);
    uLongf clen = compressBound(static_cast<uLong>(part.size()));
    std::string c(clen, '\0');
    compress(reinterpret_cast<Bytef*>(c.data()), &clen, reinterpret_cast<const Bytef*>(part.data()),
             static_cast<uLong>(part.size()));
    c.resize(clen);
    blocks.push_back(c);
  }
  std::string hdr;
  auto put64 = [&](uint64_t v) { hdr.append(reinterpret_cast<const char*>(&v), 8); };
  put64(blocks.size());
  put64(blockSize);
  put64(raw.size() % blockSize);
  for (const auto& b : blocks) put64(b.size());
  std::string x =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n  <ImageData WholeExtent=\"0 " +
      std::to_string(dims[0] - 1) + " 0 " + std::to_string(dims[1] - 1) + " 0 " + std::to_string(dims[2] - 1) +
      "\" Origin=\"5 6 7\" Spacing=\"0.5 0.25 2\">\n    <Piece Extent=\"0 " + std::to_string(dims[0] - 1) + " 0 " +
      std::to_string(dims[1] - 1) + " 0 " + std::to_string(dims[2] - 1) +
      "\">\n      <PointData Scalars=\"density\">\n"
      "        <DataArray type=\"Float32\" Name=\"other\" format=\"appended\" offset=\"0\"/>\n"
      "        <DataArray type=\"Int16\" Name=\"density\" format=\"appended\" offset=\"OFF\"/>\n"
      "      </PointData>\n    </Piece>\n  </ImageData>\n  <AppendedData encoding=\"raw\">\n   _";
  // A dummy first array (one tiny uncompressed-looking block) so the offset matters.
  std::string dummy;
  {
    const float f = 1.0f;
    uLongf clen = compressBound(4);
    std::string c(clen, '\0');
    compress(reinterpret_cast<Bytef*>(c.data()), &clen, reinterpret_cast<const Bytef*>(&f), 4);
    c.resize(clen);
    uint64_t h3[4] = {1, 4, 4, clen};
    dummy.append(reinterpret_cast<const char*>(h3), 32);
    dummy += c;
  }
  x.replace(x.find("OFF"), 3, std::to_string(dummy.size()));
  x += dummy + hdr;
  for (const auto& b : blocks) x += b;
  x += "\n  </AppendedData>\n</VTKFile>\n";
  return x;
}

}  // namespace

TEST(VolumeIo, VtiZlibAppendedUInt64MultiBlock) {
  TempDir dir("vti");
  const Index3 dims{5, 4, 3};
  std::vector<int16_t> vals(60);
  for (size_t i = 0; i < vals.size(); ++i) vals[i] = static_cast<int16_t>(static_cast<int>(i) * 37 - 900);
  writeBytes(dir.file("a.vti"), vtiCompressed(vals, dims, 32));  // 120 bytes -> 4 blocks, last partial
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("a.vti"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::Int16);
  EXPECT_EQ(std::get<VolumeI16>(v).voxels(), vals);
  const Geometry& g = geometryOf(v);
  EXPECT_EQ(g.dims, dims);
  EXPECT_NEAR(g.spacing[1], 0.25, 1e-12);
  EXPECT_NEAR(g.origin[2], 7, 1e-12);
  EXPECT_EQ(info.format, "vti");

  // Corrupt a compressed block -> IoError, not a crash.
  std::string bad = vtiCompressed(vals, dims, 32);
  bad[bad.size() - 40] ^= 0x5a;
  bad[bad.size() - 41] ^= 0x5a;
  writeBytes(dir.file("bad.vti"), bad);
  EXPECT_THROW(readVolume(dir.file("bad.vti")), IoError);
  // Truncated.
  writeBytes(dir.file("trunc.vti"), bad.substr(0, bad.size() / 2));
  EXPECT_THROW(readVolume(dir.file("trunc.vti")), IoError);
}

TEST(VolumeIo, VtiUncompressedBase64InlineFloat) {
  TempDir dir("vti64");
  const std::vector<float> vals{0.5f, -1.0f, 2.0f, 1e6f, 3.25f, -7.0f};
  std::string payload;
  const uint32_t n = static_cast<uint32_t>(vals.size() * 4);
  payload.append(reinterpret_cast<const char*>(&n), 4);
  payload.append(reinterpret_cast<const char*>(vals.data()), n);
  static const char* a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (size_t i = 0; i < payload.size(); i += 3) {
    uint32_t v = static_cast<uint8_t>(payload[i]) << 16;
    if (i + 1 < payload.size()) v |= static_cast<uint8_t>(payload[i + 1]) << 8;
    if (i + 2 < payload.size()) v |= static_cast<uint8_t>(payload[i + 2]);
    b64 += a[(v >> 18) & 63];
    b64 += a[(v >> 12) & 63];
    b64 += i + 1 < payload.size() ? a[(v >> 6) & 63] : '=';
    b64 += i + 2 < payload.size() ? a[v & 63] : '=';
  }
  writeBytes(dir.file("b.vti"),
             "<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"0 2 0 "
             "1 0 0\" "
             "Origin=\"0 0 0\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 2 0 1 0 0\">\n<PointData Scalars=\"s\">\n"
             "<DataArray type=\"Float32\" Name=\"s\" format=\"binary\">\n" +
                 b64 + "\n</DataArray>\n</PointData>\n</Piece>\n</ImageData>\n</VTKFile>\n");
  const AnyVolume v = readVolume(dir.file("b.vti"));
  ASSERT_EQ(voxelType(v), VoxelType::Float32);
  EXPECT_EQ(std::get<VolumeF32>(v).voxels(), vals);
  writeBytes(dir.file("c.vti"), "<VTKFile type=\"PolyData\"></VTKFile>");
  EXPECT_THROW(readVolume(dir.file("c.vti")), IoError);
}

// ---------------------------------------------------------------- NRRD specifics
TEST(VolumeIo, NrrdSliceFilePatternWithSpacingsAndSpace) {
  // Same layout as VTK's quarter.nhdr, which ITK refuses (spacings together with space).
  TempDir dir("nrrdpat");
  for (int k = 1; k <= 3; ++k) {
    std::string slice;
    for (int i = 0; i < 4; ++i) {
      const int16_t v = static_cast<int16_t>(k * 1000 + i);
      slice.append(reinterpret_cast<const char*>(&v), 2);
    }
    writeBytes(dir.file("sl." + std::to_string(k)), slice);
  }
  writeBytes(dir.file("p.nhdr"),
             "NRRD0004\ndimension: 3\nsizes: 2 2 3\nspacings: 3.2 3.2 1.5\nendian: little\n"
             "type: short\nencoding: raw\nspace: 3D-left-handed\ndata file: sl.%d 1 3 1\n");
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("p.nhdr"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::Int16);
  const auto& vol = std::get<VolumeI16>(v);
  EXPECT_EQ(vol.dims(), (Index3{2, 2, 3}));
  EXPECT_EQ(vol(1, 1, 2), 3003);
  EXPECT_EQ(vol(0, 0, 0), 1000);
  EXPECT_NEAR(vol.geometry().spacing[0], 3.2, 1e-12);
  EXPECT_NEAR(vol.geometry().spacing[2], 1.5, 1e-12);
  // A missing slice file is reported by name.
  fs::remove(dir.file("sl.2"));
  try {
    readVolume(dir.file("p.nhdr"));
    FAIL() << "missing slice accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("sl.2"), std::string::npos) << e.what();
  }
}

TEST(VolumeIo, Int32IsNarrowedWithNoteAndDoubleBecomesFloat) {
  TempDir dir("int32");
  std::string s = "NRRD0004\ntype: int\ndimension: 3\nsizes: 2 2 2\nendian: little\nencoding: raw\n\n";
  for (int32_t v : {-5, 0, 7, 30000, -30000, 1, 2, 3}) s.append(reinterpret_cast<const char*>(&v), 4);
  writeBytes(dir.file("a.nrrd"), s);
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("a.nrrd"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::Int16);
  EXPECT_EQ(std::get<VolumeI16>(v).voxels(), (std::vector<int16_t>{-5, 0, 7, 30000, -30000, 1, 2, 3}));
  EXPECT_EQ(info.sourceType, "int32");
  ASSERT_FALSE(info.notes.empty());

  std::string d = "NRRD0004\ntype: double\ndimension: 3\nsizes: 2 1 1\nendian: little\nencoding: raw\n\n";
  for (double x : {0.125, -2.5}) d.append(reinterpret_cast<const char*>(&x), 8);
  writeBytes(dir.file("d.nrrd"), d);
  const AnyVolume dv = readVolume(dir.file("d.nrrd"));
  ASSERT_EQ(voxelType(dv), VoxelType::Float32);
  EXPECT_EQ(std::get<VolumeF32>(dv).voxels(), (std::vector<float>{0.125f, -2.5f}));

  std::string u = "NRRD0004\ntype: uint\ndimension: 3\nsizes: 2 1 1\nendian: little\nencoding: raw\n\n";
  for (uint32_t x : {0u, 100000u}) u.append(reinterpret_cast<const char*>(&x), 4);
  writeBytes(dir.file("u.nrrd"), u);
  const AnyVolume uv = readVolume(dir.file("u.nrrd"));
  ASSERT_EQ(voxelType(uv), VoxelType::Float32);
  EXPECT_EQ(std::get<VolumeF32>(uv).voxels(), (std::vector<float>{0.0f, 100000.0f}));
}

// ---------------------------------------------------------------- 2D images
TEST(VolumeIo, RgbPngIsOneSliceLuminanceAndRefusedWhen2DNotAllowed) {
  TempDir dir("png");
  RgbaImage img(3, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      uint8_t* p = img.at(x, y);
      p[0] = static_cast<uint8_t>(x * 100);
      p[1] = static_cast<uint8_t>(y * 200);
      p[2] = 50;
      p[3] = 255;
    }
  writePng(img, dir.file("a.png"));
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("a.png"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::UInt8);
  const auto& vol = std::get<VolumeU8>(v);
  EXPECT_EQ(vol.dims(), (Index3{3, 2, 1}));
  EXPECT_EQ(info.format, "png");
  EXPECT_FALSE(info.notes.empty());  // colour reduced to luminance
  const double lum = 0.299 * 200 + 0.587 * 200 + 0.114 * 50;
  EXPECT_NEAR(vol(2, 1, 0), lum, 1.0);
  EXPECT_NEAR(vol(0, 0, 0), 0.114 * 50, 1.0);
  ReadOptions no2d;
  no2d.allow2D = false;
  try {
    readVolume(dir.file("a.png"), no2d);
    FAIL() << "2D accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("2D"), std::string::npos) << e.what();
  }
}

TEST(VolumeIo, GrayTiffIsReadAsOneSlice) {
  // Minimal little-endian baseline TIFF, 4x3 8-bit grey, one strip.
  TempDir dir("tif");
  std::string t = "II*";
  t.push_back('\0');
  auto p16 = [&](uint16_t v) { t.append(reinterpret_cast<const char*>(&v), 2); };
  auto p32 = [&](uint32_t v) { t.append(reinterpret_cast<const char*>(&v), 4); };
  p32(8);
  const uint16_t entries = 8;
  p16(entries);
  const uint32_t dataOff = 8 + 2 + entries * 12 + 4;
  auto tag = [&](uint16_t id, uint16_t type, uint32_t count, uint32_t value) {
    p16(id);
    p16(type);
    p32(count);
    p32(value);
  };
  tag(256, 3, 1, 4);        // width
  tag(257, 3, 1, 3);        // height
  tag(258, 3, 1, 8);        // bits per sample
  tag(259, 3, 1, 1);        // no compression
  tag(262, 3, 1, 1);        // black is zero
  tag(273, 4, 1, dataOff);  // strip offset
  tag(278, 3, 1, 3);        // rows per strip
  tag(279, 4, 1, 12);       // strip byte count
  p32(0);
  for (int i = 0; i < 12; ++i) t.push_back(static_cast<char>(i * 20));
  writeBytes(dir.file("g.tif"), t);
  ReadInfo info;
  const AnyVolume v = readVolume(dir.file("g.tif"), {}, &info);
  ASSERT_EQ(voxelType(v), VoxelType::UInt8);
  const auto& vol = std::get<VolumeU8>(v);
  EXPECT_EQ(vol.dims(), (Index3{4, 3, 1}));
  EXPECT_EQ(vol(3, 2, 0), 11 * 20);
  EXPECT_EQ(info.format, "tiff");
}

// ---------------------------------------------------------------- failure paths
namespace {

void expectIoErrorNaming(const std::string& path, const std::string& fragment = {}) {
  try {
    readVolume(path);
    FAIL() << "no error for " << path;
  } catch (const IoError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(fs::path(path).filename().string()), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "multi-line message: " << msg;
    if (!fragment.empty()) {
      EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
    }
  } catch (const std::exception& e) {
    FAIL() << "wrong exception type for " << path << ": " << e.what();
  }
}

}  // namespace

TEST(VolumeIoErrors, MissingFileAndUnknownFormat) {
  TempDir dir("err1");
  expectIoErrorNaming(dir.file("nope.nii.gz"), "not found");
  writeBytes(dir.file("x.xyz"), "hello");
  expectIoErrorNaming(dir.file("x.xyz"), "unknown");
  EXPECT_THROW(readVolume(""), IoError);
  // A directory without DICOM files.
  fs::create_directories(dir.path / "empty");
  writeBytes((dir.path / "empty" / "readme.txt").string(), "no dicom here");
  EXPECT_THROW(readVolume((dir.path / "empty").string()), IoError);
}

TEST(VolumeIoErrors, TruncatedAndWrongMagic) {
  TempDir dir("err2");
  const Geometry g = testGeometry({16, 16, 8});
  writeVolume(AnyVolume(rampVolume<int16_t>(g)), dir.file("ok.nii"));
  writeVolume(AnyVolume(rampVolume<int16_t>(g)), dir.file("ok.nii.gz"));
  writeVolume(AnyVolume(rampVolume<int16_t>(g)), dir.file("ok.mha"));
  writeVolume(AnyVolume(rampVolume<int16_t>(g)), dir.file("ok.nrrd"));
  const std::string nii = readBytes(dir.file("ok.nii"));
  writeBytes(dir.file("trunc.nii"), nii.substr(0, nii.size() / 2));
  expectIoErrorNaming(dir.file("trunc.nii"));
  writeBytes(dir.file("hdr.nii"), nii.substr(0, 200));
  expectIoErrorNaming(dir.file("hdr.nii"), "truncated");
  const std::string gz = readBytes(dir.file("ok.nii.gz"));
  writeBytes(dir.file("trunc.nii.gz"), gz.substr(0, gz.size() / 2));
  expectIoErrorNaming(dir.file("trunc.nii.gz"));
  const std::string mha = readBytes(dir.file("ok.mha"));
  writeBytes(dir.file("trunc.mha"), mha.substr(0, mha.size() - 100));
  expectIoErrorNaming(dir.file("trunc.mha"), "truncated");
  const std::string nrrd = readBytes(dir.file("ok.nrrd"));
  writeBytes(dir.file("trunc.nrrd"), nrrd.substr(0, nrrd.size() - 100));
  expectIoErrorNaming(dir.file("trunc.nrrd"), "truncated");

  std::string garbage(600, 'x');
  writeBytes(dir.file("magic.nii"), garbage);
  expectIoErrorNaming(dir.file("magic.nii"), "magic");
  writeBytes(dir.file("magic.nrrd"), garbage);
  expectIoErrorNaming(dir.file("magic.nrrd"), "magic");
  writeBytes(dir.file("magic.png"), garbage);
  expectIoErrorNaming(dir.file("magic.png"), "magic");
  writeBytes(dir.file("magic.vtk"), garbage);
  expectIoErrorNaming(dir.file("magic.vtk"), "magic");
  writeBytes(dir.file("magic.vti"), garbage);
  expectIoErrorNaming(dir.file("magic.vti"), "magic");
  writeBytes(dir.file("magic.mha"), garbage);
  expectIoErrorNaming(dir.file("magic.mha"), "magic");
  writeBytes(dir.file("empty.nii"), "");
  expectIoErrorNaming(dir.file("empty.nii"));
}

TEST(VolumeIoErrors, AbsurdDimensionsAreRefusedBeforeAllocating) {
  TempDir dir("err3");
  // 2^21 cubed int16 voxels: 16 EiB, far above any machine.
  writeBytes(
      dir.file("huge.nrrd"),
      "NRRD0004\ntype: short\ndimension: 3\nsizes: 2097152 2097152 2097152\nendian: little\nencoding: raw\n\n1234");
  EXPECT_THROW(readVolume(dir.file("huge.nrrd")), Error);
  writeBytes(dir.file("huge.vtk"),
             "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 100000\n"
             "SPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 1000000000000000\nSCALARS s float\nLOOKUP_TABLE default\n");
  EXPECT_THROW(readVolume(dir.file("huge.vtk")), DataError);
  writeBytes(
      dir.file("huge.vti"),
      "<VTKFile type=\"ImageData\" byte_order=\"LittleEndian\"><ImageData WholeExtent=\"0 99999 0 99999 0 99999\">"
      "<Piece Extent=\"0 99999 0 99999 0 99999\"><PointData><DataArray type=\"Float32\" format=\"appended\" "
      "offset=\"0\"/>"
      "</PointData></Piece></ImageData><AppendedData encoding=\"raw\">_xxxx</AppendedData></VTKFile>");
  EXPECT_THROW(readVolume(dir.file("huge.vti")), DataError);
  // NIfTI header with 30000^3 float voxels.
  std::vector<int16_t> none;
  std::string n = niftiFile(4, none, {30000, 30000, 30000}, 0, 0);
  writeBytes(dir.file("huge.nii"), n);
  EXPECT_THROW(readVolume(dir.file("huge.nii")), Error);
}

TEST(VolumeIoErrors, UnsupportedVoxelType) {
  TempDir dir("err4");
  writeBytes(dir.file("block.nrrd"),
             "NRRD0004\ntype: block\nblock size: 4\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\nabcd");
  expectIoErrorNaming(dir.file("block.nrrd"));
  writeBytes(dir.file("bit.vtk"),
             "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 1 1 1\nSPACING 1 1 1\n"
             "ORIGIN 0 0 0\nPOINT_DATA 1\nSCALARS s bit\nLOOKUP_TABLE default\n1\n");
  expectIoErrorNaming(dir.file("bit.vtk"), "unsupported");
  // Complex NIfTI (datatype 32).
  std::vector<int16_t> vals(4, 1);
  std::string c = niftiFile(4, vals, {1, 1, 1}, 0, 0);
  const int16_t complexType = 32, bitpix = 64;
  std::memcpy(&c[70], &complexType, 2);
  std::memcpy(&c[72], &bitpix, 2);
  writeBytes(dir.file("complex.nii"), c);
  expectIoErrorNaming(dir.file("complex.nii"));
}

TEST(VolumeIoErrors, NaNVoxelsAreReadAndCounted) {
  TempDir dir("nan");
  Geometry g = testGeometry({3, 3, 3});
  VolumeF32 v(g, 1.0f);
  v(1, 1, 1) = std::nanf("");
  v(2, 2, 2) = INFINITY;
  // nifticlib zeroes NaN/inf on read; the reader must restore them (a 0 would hide bad data).
  for (const char* name : {"nan.nrrd", "nan.mha", "nan.nii", "nan.nii.gz"}) {
    writeVolume(AnyVolume(v), dir.file(name));
    ReadInfo info;
    const AnyVolume back = readVolume(dir.file(name), {}, &info);
    const ValueRange r = valueRange(back);
    EXPECT_EQ(r.nonFinite, 2) << name;
    EXPECT_TRUE(std::isnan(std::get<VolumeF32>(back)(1, 1, 1))) << name;
    EXPECT_EQ(std::get<VolumeF32>(back)(2, 2, 2), INFINITY) << name;
    EXPECT_EQ(std::get<VolumeF32>(back)(0, 0, 0), 1.0f) << name;
    EXPECT_THROW(requireFinite(back, name), DataError);
  }
}

TEST(VolumeIoErrors, UnwritableOutputLeavesNoFile) {
  TempDir dir("err5");
  const AnyVolume v(rampVolume<uint8_t>(testGeometry({4, 4, 4})));
  EXPECT_THROW(writeVolume(v, (dir.path / "missing" / "out.nii.gz").string()), IoError);
  EXPECT_FALSE(fs::exists(dir.path / "missing"));
  EXPECT_THROW(writeVolume(v, dir.file("out.png")), IoError);  // not a volume format
  EXPECT_THROW(writeVolume(v, dir.file("out.mhd") + "/x.mhd"), IoError);
  EXPECT_TRUE(fs::is_empty(dir.path));
  // /proc refuses new files even for root, so this checks the failure path honestly.
  EXPECT_THROW(writeVolume(v, "/proc/vs_io_test_out.nii"), IoError);
  EXPECT_THROW(writeVolume(v, "/proc/vs_io_test_out.mhd"), IoError);
  EXPECT_FALSE(fs::exists("/proc/vs_io_test_out.nii"));
  // A read-only directory only stops non-root users.
  fs::create_directories(dir.path / "ro");
  fs::permissions(dir.path / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  if (::geteuid() == 0) {
    fs::permissions(dir.path / "ro", fs::perms::owner_all);
    GTEST_SKIP() << "running as root: a read-only directory is still writable, checked /proc instead";
  }
  EXPECT_THROW(writeVolume(v, (dir.path / "ro" / "out.nii").string()), IoError);
  EXPECT_TRUE(fs::is_empty(dir.path / "ro"));
  fs::permissions(dir.path / "ro", fs::perms::owner_all);
}

// A full disk (write(2) failing with EFBIG past 16 KiB, as with ENOSPC): every multi-file
// format leaves no header and no data file, and the write is an IoError (issue 22: .nhdr gave
// exit 0 and a 0-byte header). Run in a child process so the limit does not touch the tests.
TEST(VolumeIo, FullDiskLeavesNoPartOfAMultiFileOutput) {
  TempDir dir("fulldisk");
  const Geometry g = testGeometry({64, 64, 32});
  VolumeF32 noise(g);  // incompressible: .nrrd/.nhdr gzip cannot fit it under the limit
  uint32_t state = 12345;
  for (float& x : noise.voxels()) x = static_cast<float>((state = state * 1664525u + 1013904223u) >> 8);
  const AnyVolume v(std::move(noise));
  for (const char* name : {"o.nhdr", "o.mhd", "o.nii", "o.nrrd"}) {
    SCOPED_TRACE(name);
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      std::signal(SIGXFSZ, SIG_IGN);
      const rlimit lim{16384, 16384};
      ::setrlimit(RLIMIT_FSIZE, &lim);
      try {
        writeVolume(v, dir.file(name));
      } catch (const IoError&) {
        ::_exit(1);
      } catch (...) {
        ::_exit(3);
      }
      ::_exit(0);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1) << "the write did not fail with an IoError";
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path), fs::directory_iterator()), 0)
        << "something was left in the output folder";
    for (const auto& e : fs::directory_iterator(dir.path)) fs::remove_all(e.path());
  }
}
