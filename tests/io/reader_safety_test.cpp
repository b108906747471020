// Regression tests for the bad-input campaign (issue 11): every small hostile file that once
// crashed, overflowed, hung, allocated gigabytes or was accepted with wrong voxels must now
// end in a clear IoError/DataError naming the file, and valid neighbours must still load.
#include <gtest/gtest.h>
#include <zlib.h>

#include <chrono>
#include <cstring>

#include "io/mesh_io.h"
#include "io/png_io.h"
#include "io/volume_io.h"
#include "io_test_util.h"

using namespace vs;
using namespace vs::test;

namespace {

// Expects `read` to throw vs::Error (IoError or DataError) whose message names `path`
// and contains `words`, within a few seconds (a hang would show as a slow test).
template <class F>
void expectRefused(const std::string& path, F read, const std::string& words = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  try {
    read();
    ADD_FAILURE() << path << ": accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << "message does not name the file: " << msg;
    if (!words.empty()) {
      EXPECT_NE(msg.find(words), std::string::npos) << "expected '" << words << "' in: " << msg;
    }
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0) << path;
}

void expectVolumeRefused(const std::string& path, const std::string& words = {}) {
  expectRefused(
      path, [&] { readVolume(path); }, words);
}

template <class T>
void put(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// A .vti with raw appended zlib data whose block header is given verbatim (UInt64 header).
std::string vtiWithBlockHeader(uint64_t nblocks, uint64_t blockSize, uint64_t lastSize,
                               const std::vector<uint64_t>& csizes, const std::string& payload,
                               const std::string& offset = "0") {
  std::string x =
      "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
      "compressor=\"vtkZLibDataCompressor\">\n<ImageData WholeExtent=\"0 3 0 3 0 3\" Origin=\"0 0 0\" Spacing=\"1 1 "
      "1\">\n"
      "<Piece Extent=\"0 3 0 3 0 3\"><PointData Scalars=\"s\">\n"
      "<DataArray type=\"UInt8\" Name=\"s\" format=\"appended\" offset=\"" +
      offset + "\"/>\n</PointData></Piece></ImageData>\n<AppendedData encoding=\"raw\">\n_";
  put<uint64_t>(x, nblocks);
  put<uint64_t>(x, blockSize);
  put<uint64_t>(x, lastSize);
  for (uint64_t c : csizes) put<uint64_t>(x, c);
  x += payload;
  x += "\n</AppendedData>\n</VTKFile>\n";
  return x;
}

std::string zlibOf(const std::string& raw) {
  uLongf n = compressBound(static_cast<uLong>(raw.size()));
  std::string out(n, '\0');
  compress(reinterpret_cast<Bytef*>(out.data()), &n, reinterpret_cast<const Bytef*>(raw.data()),
           static_cast<uLong>(raw.size()));
  out.resize(n);
  return out;
}

// Minimal NIfTI-1 uint8 4x4x4 file with sform_code 1 and the given srow_x[0].
std::string nifti(int16_t dim0, int16_t dim1, float srowX0) {
  std::string h(352, '\0');
  auto put16 = [&](size_t off, int16_t v) { std::memcpy(&h[off], &v, 2); };
  auto putf = [&](size_t off, float v) { std::memcpy(&h[off], &v, 4); };
  const int32_t size = 348;
  std::memcpy(&h[0], &size, 4);
  put16(40, dim0);
  put16(42, dim1);
  put16(44, 4);
  put16(46, 4);
  for (int i = 4; i < 8; ++i) put16(40 + 2 * static_cast<size_t>(i), 1);
  put16(70, 2);
  put16(72, 8);
  for (int i = 0; i < 4; ++i) putf(76 + 4 * static_cast<size_t>(i), 1.0f);
  putf(108, 352);
  put16(254, 1);
  putf(280, srowX0);
  putf(300, 1);
  putf(320, 1);
  std::memcpy(&h[344], "n+1\0", 4);
  h += std::string(64, '\x07');
  return h;
}

}  // namespace

// ---------------------------------------------------------------- VTI
TEST(ReaderSafety, VtiCompressionHeaderCannotWrapOrOverflow) {
  TempDir dir("safe_vti");
  const std::string raw(64, '\x05');
  const std::string z = zlibOf(raw);
  // The valid file loads.
  writeBytes(dir.file("ok.vti"), vtiWithBlockHeader(1, 64, 0, {z.size()}, z));
  EXPECT_EQ(std::get<VolumeU8>(readVolume(dir.file("ok.vti"))).voxels(), std::vector<uint8_t>(64, 5));
  // (nblocks-1)*blockSize + lastSize wrapped to 64 and let 2^63-byte blocks inflate past it.
  writeBytes(dir.file("wrap.vti"),
             vtiWithBlockHeader(3, uint64_t{1} << 63, 64, {z.size(), z.size(), z.size()}, z + z + z));
  expectVolumeRefused(dir.file("wrap.vti"), "compress");
  // A block bigger than the array (one block of 1 MiB for 64 bytes).
  writeBytes(dir.file("big.vti"), vtiWithBlockHeader(1, 1 << 20, 0, {z.size()}, z));
  expectVolumeRefused(dir.file("big.vti"), "compressed data holds");
  // pos + csize wrapped.
  writeBytes(dir.file("csize.vti"), vtiWithBlockHeader(1, 64, 0, {~uint64_t{0} - 3}, z));
  expectVolumeRefused(dir.file("csize.vti"), "truncated");
  // nblocks of 2^32 in a tiny file: no 32 GiB header vector.
  writeBytes(dir.file("nblocks.vti"), vtiWithBlockHeader(uint64_t{1} << 32, 1, 0, {}, z));
  expectVolumeRefused(dir.file("nblocks.vti"), "corrupt compression header");
  // A negative offset was parsed as 2^64-5 and wrapped to a position inside the header.
  writeBytes(dir.file("neg.vti"), vtiWithBlockHeader(1, 64, 0, {z.size()}, z, "-5"));
  expectVolumeRefused(dir.file("neg.vti"), "offset");
}

TEST(ReaderSafety, VtiAbsurdExtentIsRefusedBeforeAnyCast) {
  TempDir dir("safe_vti_ext");
  for (const std::string ext : {"0 nan 0 3 0 3", "0 1e300 0 3 0 3", "0 3 5 0 0 3", "0 2.5 0 3 0 3"}) {
    std::string x = vtiWithBlockHeader(1, 64, 0, {1}, "x");
    x.replace(x.find("0 3 0 3 0 3"), 11, ext);
    writeBytes(dir.file("e.vti"), x);
    expectVolumeRefused(dir.file("e.vti"), "WholeExtent");
  }
}

// ---------------------------------------------------------------- legacy VTK
TEST(ReaderSafety, LegacyVtkCountsAreCheckedBeforeUse) {
  TempDir dir("safe_vtk");
  const std::string head = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n";
  // A negative CELL_DATA count made the binary skip go backwards for ever.
  writeBytes(dir.file("neg.vtk"),
             head + "DIMENSIONS 2 2 2\nCELL_DATA -1\nSCALARS c float 1\nLOOKUP_TABLE default\nabcd\n");
  expectVolumeRefused(dir.file("neg.vtk"), "CELL_DATA");
  // DIMENSIONS whose product overflows int64.
  writeBytes(dir.file("ovf.vtk"), head +
                                      "DIMENSIONS 2147483648 2147483648 2147483648\nPOINT_DATA 8\nSCALARS s "
                                      "unsigned_char 1\nLOOKUP_TABLE default\n");
  expectVolumeRefused(dir.file("ovf.vtk"));
  // 1000^3 voxels announced in a few bytes: refused before the gigabyte buffer is allocated.
  writeBytes(
      dir.file("short.vtk"),
      head + "DIMENSIONS 1000 1000 1000\nPOINT_DATA 1000000000\nSCALARS s unsigned_char 1\nLOOKUP_TABLE default\nab");
  expectVolumeRefused(dir.file("short.vtk"), "truncated");
  // ASCII: the same check (at least two characters per value).
  std::string ascii = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n";
  writeBytes(
      dir.file("shorta.vtk"),
      ascii + "DIMENSIONS 1000 1000 100\nPOINT_DATA 100000000\nSCALARS s float 1\nLOOKUP_TABLE default\n1 2 3\n");
  expectVolumeRefused(dir.file("shorta.vtk"), "truncated");
}

// ---------------------------------------------------------------- NRRD
TEST(ReaderSafety, NrrdDataFilePatternIsNeverAPrintfFormat) {
  TempDir dir("safe_nrrd_pat");
  writeBytes(dir.file("s001.raw"), std::string(4, '\x01'));
  writeBytes(dir.file("s002.raw"), std::string(4, '\x02'));
  const std::string head = "NRRD0004\ndimension: 3\nsizes: 2 2 2\ntype: uchar\nencoding: raw\ndata file: ";
  writeBytes(dir.file("ok.nhdr"), head + "s%03d.raw 1 2 1\n");
  const auto ok = std::get<VolumeU8>(readVolume(dir.file("ok.nhdr")));
  EXPECT_EQ(ok(0, 0, 0), 1);
  EXPECT_EQ(ok(1, 1, 1), 2);
  // %n writes through a pointer argument, %s reads one; %d%d reads a second argument.
  for (const std::string bad : {"s%n.raw 1 2 1", "s%s.raw 1 2 1", "s%d%d.raw 1 2 1", "s%999999d.raw 1 2 1",
                                "s%x.raw 1 2 1", "s%03d.raw 1 2", "s%03d.raw 1 2 0"}) {
    writeBytes(dir.file("bad.nhdr"), head + bad + "\n");
    expectVolumeRefused(dir.file("bad.nhdr"), "pattern");
  }
}

TEST(ReaderSafety, Nrrd4DReadsTheFirstVolumeWithoutOverflow) {
  TempDir dir("safe_nrrd4d");
  // Four domain axes (a "list" axis would be read as components, which is not this case).
  std::string s = "NRRD0004\ndimension: 4\nsizes: 2 2 2 3\ntype: uchar\nencoding: raw\n\n";
  for (int i = 0; i < 24; ++i) s.push_back(static_cast<char>(i));
  writeBytes(dir.file("a.nrrd"), s);
  const AnyVolume v = readVolume(dir.file("a.nrrd"));
  const auto& vol = std::get<VolumeU8>(v);
  EXPECT_EQ(vol.dims(), (Index3{2, 2, 2}));
  for (int i = 0; i < 8; ++i) EXPECT_EQ(vol.voxels()[static_cast<size_t>(i)], i);
}

// ---------------------------------------------------------------- MetaImage
TEST(ReaderSafety, MetaImageHeaderValidatedBeforeItk) {
  TempDir dir("safe_mha");
  const std::string tail = "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
  for (const std::string nd : {"-1", "1000000", "2147483647", "3.5", "x"}) {
    writeBytes(dir.file("nd.mha"),
               "ObjectType = Image\nNDims = " + nd + "\nDimSize = 2 2 2\n" + tail + std::string(8, 'a'));
    expectVolumeRefused(dir.file("nd.mha"), "NDims");
  }
  writeBytes(dir.file("nan.mha"),
             "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementSpacing = nan 1 1\n" + tail + std::string(8, 'a'));
  expectVolumeRefused(dir.file("nan.mha"));
  // Undecodable compressed data was read as zeros.
  const std::string junk =
      "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nCompressedData = True\nCompressedDataSize = 40\n" + tail;
  writeBytes(dir.file("junk.mha"), junk + std::string(40, 'z'));
  expectVolumeRefused(dir.file("junk.mha"), "corrupt");
  // A pattern naming missing slice files was read as zeros; a printf format is refused.
  writeBytes(dir.file("sl001.raw"), std::string(4, 'a'));
  writeBytes(
      dir.file("miss.mhd"),
      "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = sl%03d.raw 1 2 1\n");
  expectVolumeRefused(dir.file("miss.mhd"), "sl002.raw");
  writeBytes(
      dir.file("fmt.mhd"),
      "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = sl%n.raw 1 2 1\n");
  expectVolumeRefused(dir.file("fmt.mhd"), "pattern");
  // The valid compressed neighbour still loads.
  writeBytes(dir.file("ok.mha"),
             "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nCompressedData = True\nCompressedDataSize = " +
                 std::to_string(zlibOf(std::string(64, '\x09')).size()) + "\n" + tail +
                 zlibOf(std::string(64, '\x09')));
  EXPECT_EQ(std::get<VolumeU8>(readVolume(dir.file("ok.mha"))).voxels(), std::vector<uint8_t>(64, 9));
}

// ---------------------------------------------------------------- NIfTI
TEST(ReaderSafety, NiftiMatrixAndDimsCheckedBeforeItk) {
  TempDir dir("safe_nii");
  writeBytes(dir.file("ok.nii"), nifti(3, 4, 1.0f));
  EXPECT_EQ(geometryOf(readVolume(dir.file("ok.nii"))).dims, (Index3{4, 4, 4}));
  writeBytes(dir.file("nan.nii"), nifti(3, 4, std::nanf("")));
  expectVolumeRefused(dir.file("nan.nii"), "sform");
  writeBytes(dir.file("huge.nii"), nifti(3, 4, 3e38f));
  expectVolumeRefused(dir.file("huge.nii"), "sform");
  writeBytes(dir.file("dim0.nii"), nifti(0, 4, 1.0f));
  expectVolumeRefused(dir.file("dim0.nii"), "dim[0]");
  writeBytes(dir.file("neg.nii"), nifti(3, -4, 1.0f));
  expectVolumeRefused(dir.file("neg.nii"), "dim[1]");
}

// ---------------------------------------------------------------- PNG
TEST(ReaderSafety, CorruptPngIsAnErrorNotAnAbort) {
  TempDir dir("safe_png");
  RgbaImage img(40, 30);
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = static_cast<uint8_t>(i * 7);
  writePng(img, dir.file("ok.png"));
  const std::string good = readBytes(dir.file("ok.png"));
  EXPECT_EQ(geometryOf(readVolume(dir.file("ok.png"))).dims, (Index3{40, 30, 1}));
  // Damaged IDAT (CRC and data) and a truncated file.
  std::string bad = good;
  const size_t idat = bad.find("IDAT");
  for (size_t i = idat + 8; i < idat + 40 && i < bad.size(); ++i) bad[i] = static_cast<char>(bad[i] ^ 0x55);
  writeBytes(dir.file("bad.png"), bad);
  expectVolumeRefused(dir.file("bad.png"), "PNG");
  writeBytes(dir.file("trunc.png"), good.substr(0, good.size() / 2));
  expectVolumeRefused(dir.file("trunc.png"), "PNG");
  // 60000x60000 announced by a 100-byte file: refused before allocating.
  std::string huge = good.substr(0, 33);
  const uint32_t w = __builtin_bswap32(60000);
  std::memcpy(&huge[16], &w, 4);
  std::memcpy(&huge[20], &w, 4);
  const uint32_t crc =
      __builtin_bswap32(static_cast<uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(&huge[12]), 17)));
  std::memcpy(&huge[29], &crc, 4);
  writeBytes(dir.file("huge.png"), huge + good.substr(33, 60));
  expectVolumeRefused(dir.file("huge.png"), "PNG");
  expectRefused(dir.file("huge.png"), [&] { readPng(dir.file("huge.png")); });
}

// ---------------------------------------------------------------- meshes
TEST(ReaderSafety, MeshCountsCannotHangOrAllocate) {
  TempDir dir("safe_mesh");
  // 2^64-1 elements with no properties looped for ever.
  writeBytes(dir.file("loop.ply"),
             "ply\nformat binary_little_endian 1.0\nelement junk 18446744073709551615\nend_header\n");
  expectRefused(
      dir.file("loop.ply"), [&] { readTriMesh(dir.file("loop.ply")); }, "count");
  writeBytes(dir.file("big.ply"),
             "ply\nformat binary_little_endian 1.0\nelement vertex 2000000000\nproperty float x\nend_header\nab");
  expectRefused(
      dir.file("big.ply"), [&] { readTriMesh(dir.file("big.ply")); }, "count");
  // A float list count of 1e30 was cast to an integer (undefined behaviour).
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list float int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) put<float>(ply, 0.5f * static_cast<float>(i));
  put<float>(ply, 1e30f);
  writeBytes(dir.file("cast.ply"), ply);
  expectRefused(
      dir.file("cast.ply"), [&] { readTriMesh(dir.file("cast.ply")); }, "list length");
  writeBytes(dir.file("pts.vtk"),
             "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2000000000 float\n1 2 3\n");
  expectRefused(
      dir.file("pts.vtk"), [&] { readTriMesh(dir.file("pts.vtk")); }, "POINTS");
}
