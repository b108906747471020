// OME-Zarr reader and writer (issue 25): round trips, the chunk cache, python3-zarr as the
// reference reader and writer, and bad input (every message names the chunk or the level).
#include "io/zarr_io.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "io/io_test_util.h"
#include "io/volume_io.h"
#include "util/error.h"

namespace vs {
namespace {

using test::TempDir;

float pattern(int64_t x, int64_t y, int64_t z) { return float((x * 7 + y * 13 + z * 29) % 251); }

template <class T>
Volume<T> patterned(const Index3& d, Vec3 spacing = {0.5, 0.75, 2.0}) {
  Geometry g;
  g.dims = d;
  g.spacing = spacing;
  g.origin = {1, -2, 3};
  Volume<T> v(g);
  for (int64_t z = 0; z < d[2]; ++z)
    for (int64_t y = 0; y < d[1]; ++y)
      for (int64_t x = 0; x < d[0]; ++x) v(x, y, z) = T(pattern(x, y, z));
  return v;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

bool pythonZarr() { return std::system("/usr/bin/python3 -c 'import zarr, numcodecs' >/dev/null 2>&1") == 0; }

TEST(Zarr, RoundTripEveryTypeAndCompressor) {
  TempDir dir("zarr_rt");
  for (const std::string comp : {"zlib", "blosc", "none"}) {
    ZarrWriteOptions o;
    o.chunk = 8;
    o.compressor = comp;
    const std::string p = dir.file("v_" + comp + ".zarr");
    writeZarr(patterned<uint16_t>({21, 17, 9}), p, o);
    ZarrInfo info;
    const AnyVolume back = readZarr(p, 0, &info);
    ASSERT_TRUE(std::holds_alternative<VolumeU16>(back));
    const auto& v = std::get<VolumeU16>(back);
    EXPECT_EQ(v.dims(), (Index3{21, 17, 9}));
    EXPECT_NEAR(v.geometry().spacing[2], 2.0, 1e-12);
    EXPECT_NEAR(v.geometry().origin[1], -2.0, 1e-12);
    for (int64_t z = 0; z < 9; ++z)
      for (int64_t y = 0; y < 17; ++y)
        for (int64_t x = 0; x < 21; ++x) ASSERT_EQ(v(x, y, z), uint16_t(pattern(x, y, z))) << comp;
    // Pyramid: 21 -> 11 -> 6 (largest side within one 8-voxel chunk after two halvings).
    ASSERT_EQ(info.levels.size(), 3u);
    EXPECT_EQ(info.levels[1].dims, (Index3{11, 9, 5}));
    EXPECT_NEAR(info.levels[1].spacing[0], 1.0, 1e-12);
    const AnyVolume l1 = readZarr(p, 1);
    const auto& v1 = std::get<VolumeU16>(l1);
    const double mean = (pattern(2, 2, 2) + pattern(3, 2, 2) + pattern(2, 3, 2) + pattern(3, 3, 2) + pattern(2, 2, 3) +
                         pattern(3, 2, 3) + pattern(2, 3, 3) + pattern(3, 3, 3)) /
                        8.0;
    EXPECT_NEAR(v1(1, 1, 1), mean, 0.5);
  }
  for (auto vol : {AnyVolume(patterned<uint8_t>({5, 6, 7})), AnyVolume(patterned<int16_t>({5, 6, 7})),
                   AnyVolume(patterned<float>({5, 6, 7}))}) {
    const std::string p = dir.file("t.zarr");
    writeVolume(vol, p);  // the dispatch by name
    ReadInfo ri;
    const AnyVolume back = readVolume(p, {}, &ri);
    EXPECT_EQ(ri.format, "ome-zarr");
    EXPECT_EQ(back.index(), vol.index());
  }
  // The direction (OME-Zarr 0.4 has none) survives our own round trip.
  VolumeF32 rot = patterned<float>({6, 5, 4});
  rot.geometry().direction << 0, 1, 0, -1, 0, 0, 0, 0, 1;
  writeVolume(AnyVolume(rot), dir.file("rot.zarr"));
  ReadInfo ri;
  const AnyVolume back = readVolume(dir.file("rot.zarr"), {}, &ri);
  EXPECT_TRUE(ri.orientationInHeader);
  EXPECT_TRUE(geometryOf(back).direction.isApprox(rot.geometry().direction));
}

TEST(Zarr, ChunkCacheHoldsAtMostItsCap) {
  TempDir dir("zarr_cache");
  ZarrWriteOptions o;
  o.chunk = 4;
  writeZarr(patterned<float>({16, 16, 16}), dir.file("c.zarr"), o);
  ChunkCache cache(openZarr(dir.file("c.zarr")), 3 * 4 * 4 * 4 * 4);
  std::vector<float> box(size_t(10 * 9 * 8));
  cache.readRegion({3, 2, 5}, {10, 9, 8}, box.data(), -1);
  for (int64_t z = 0; z < 8; ++z)
    for (int64_t y = 0; y < 9; ++y)
      for (int64_t x = 0; x < 10; ++x) {
        const float want = z + 5 < 16 ? pattern(x + 3, y + 2, z + 5) : -1.0f;
        ASSERT_EQ(box[size_t(x + 10 * (y + 9 * z))], want);
      }
  EXPECT_LE(cache.stats().peakBytes, 3 * 4 * 4 * 4 * 4);
  EXPECT_EQ(cache.at(15, 15, 15), pattern(15, 15, 15));
}

TEST(Zarr, PythonZarrReadsOurFolders) {
  if (!pythonZarr()) GTEST_SKIP() << "python3-zarr not installed (scripts/install-deps.sh installs it)";
  TempDir dir("zarr_py1");
  std::string folders;
  for (const std::string comp : {"zlib", "blosc"}) {
    ZarrWriteOptions o;
    o.chunk = 8;
    o.compressor = comp;
    const std::string p = dir.file("o_" + comp + ".zarr");
    writeZarr(patterned<int16_t>({13, 10, 9}), p, o);
    folders += " " + p;
  }
  // One interpreter start for both folders (python3 + zarr take seconds to import on a loaded machine).
  const std::string cmd =
      "/usr/bin/python3 -c \"import zarr, numpy as np, sys\n"
      "for p in sys.argv[1:]:\n"
      "  g = zarr.open_group(p, mode='r')\n"
      "  a = g['0'][:]\n"
      "  z, y, x = np.indices(a.shape)\n"
      "  ok = a.shape == (9, 10, 13) and a.dtype == np.int16 and "
      "(a == (x * 7 + y * 13 + z * 29) % 251).all() and "
      "g.attrs['multiscales'][0]['datasets'][0]['coordinateTransformations'][0]['scale'] == "
      "[2.0, 0.75, 0.5]\n"
      "  assert ok, p\"" +
      folders;
  EXPECT_EQ(std::system(cmd.c_str()), 0);
}

TEST(Zarr, WeReadPythonZarrFolders) {
  if (!pythonZarr()) GTEST_SKIP() << "python3-zarr not installed (scripts/install-deps.sh installs it)";
  TempDir dir("zarr_py2");
  const std::string script = dir.file("w.py");
  std::ofstream(script) << R"(import sys, zarr, numcodecs, numpy as np, json
out = sys.argv[1]
z, y, x = np.indices((11, 9, 14))
base = (x * 7 + y * 13 + z * 29) % 251
cases = {'u1': (np.uint8, numcodecs.Zlib(level=3), '.'), 'i2': (np.int16, numcodecs.GZip(level=5), '/'),
         'u2': (np.uint16, numcodecs.Blosc(cname='zstd', clevel=3, shuffle=numcodecs.Blosc.BITSHUFFLE), '.'),
         'f4': (np.float32, numcodecs.Blosc(cname='lz4'), '.'), 'raw': (np.uint16, None, '.')}
for name, (dt, comp, sep) in cases.items():
    store = zarr.DirectoryStore(out + '/' + name + '.zarr')
    root = zarr.group(store=store, overwrite=True)
    a = root.create_dataset('0', shape=base.shape, chunks=(4, 5, 6), dtype=dt, compressor=comp,
                            dimension_separator=sep)
    a[:] = (base * 0.5 if dt == np.float32 else base).astype(dt)
    root.attrs['multiscales'] = [{'version': '0.4', 'axes': [{'name': n, 'type': 'space', 'unit': 'micrometer'}
        for n in 'zyx'], 'datasets': [{'path': '0', 'coordinateTransformations': [{'type': 'scale', 'scale': [4.0, 2.0, 1.0]}]}]}]
)";
  ASSERT_EQ(std::system(("/usr/bin/python3 " + script + " " + dir.path.string()).c_str()), 0);
  for (const std::string name : {"u1", "i2", "u2", "f4", "raw"}) {
    ZarrInfo info;
    const AnyVolume v = readZarr(dir.file(name + ".zarr"), 0, &info);
    std::visit(
        [&](const auto& vol) {
          EXPECT_EQ(vol.dims(), (Index3{14, 9, 11})) << name;
          EXPECT_NEAR(vol.geometry().spacing[0], 1e-3, 1e-15) << name;  // micrometre -> mm
          EXPECT_NEAR(vol.geometry().spacing[2], 4e-3, 1e-15) << name;
          for (int64_t z = 0; z < 11; ++z)
            for (int64_t y = 0; y < 9; ++y)
              for (int64_t x = 0; x < 14; ++x)
                ASSERT_EQ(double(vol(x, y, z)), pattern(x, y, z) * (name == "f4" ? 0.5 : 1.0)) << name;
        },
        v);
  }
}

TEST(Zarr, BadInputNamesTheChunkOrLevel) {
  TempDir dir("zarr_bad");
  ZarrWriteOptions o;
  o.chunk = 4;
  const auto fresh = [&](const std::string& name) {
    const std::string p = dir.file(name + ".zarr");
    writeZarr(patterned<uint16_t>({9, 8, 8}), p, o);
    return p;
  };
  std::string p = fresh("missing");
  std::filesystem::remove(p + "/0/1.0.2");
  EXPECT_NE(errorOf([&] { readVolume(p); }).find("chunk 1.0.2 is missing"), std::string::npos);
  p = fresh("trunc");
  {
    const std::string bytes = test::readBytes(p + "/0/0.1.1");
    test::writeBytes(p + "/0/0.1.1", bytes.substr(0, bytes.size() / 2));
  }
  EXPECT_NE(errorOf([&] { readVolume(p); }).find("chunk 0.1.1"), std::string::npos);
  p = fresh("size");  // chunk sizes that disagree with the metadata
  {
    std::string meta = test::readBytes(p + "/0/.zarray");
    const size_t at = meta.find("\"chunks\"");
    meta.replace(meta.find('4', at), 1, "5");
    test::writeBytes(p + "/0/.zarray", meta);
  }
  EXPECT_NE(errorOf([&] { readVolume(p); }).find("expected"), std::string::npos);
  EXPECT_NE(errorOf([&] { readVolume(p); }).find("chunk 0.0.0"), std::string::npos);
  p = fresh("comp");
  {
    std::string meta = test::readBytes(p + "/0/.zarray");
    meta.replace(meta.find("\"zlib\""), 6, "\"lzma\"");
    test::writeBytes(p + "/0/.zarray", meta);
  }
  EXPECT_NE(errorOf([&] { readVolume(p); }).find("unknown compressor 'lzma'"), std::string::npos);
  p = fresh("huge");  // a chunk size that would allocate gigabytes is refused before reading
  {
    std::string meta = test::readBytes(p + "/0/.zarray");
    const size_t at = meta.find("\"chunks\"");
    meta.replace(at, 8, "\"chunks\": [4000, 4000, 4000], \"old\"");
    test::writeBytes(p + "/0/.zarray", meta);
  }
  EXPECT_NE(errorOf([&] { readVolume(p); }).find("refusing to allocate"), std::string::npos);
  p = fresh("level");
  {
    std::string meta = test::readBytes(p + "/1/.zarray");
    meta.replace(meta.find("\"shape\""), 7, "\"shape\": [8, 8, 8], \"old\"");
    test::writeBytes(p + "/1/.zarray", meta);
  }
  EXPECT_NE(errorOf([&] { readVolume(p); }).find("pyramid level of the wrong shape"), std::string::npos);
  EXPECT_NE(errorOf([&] { readVolume(p); }).find("/1"), std::string::npos);
  test::writeBytes(p + "/.zattrs", "{not json");
  EXPECT_NE(errorOf([&] { readVolume(p); }).find(".zattrs is not valid JSON"), std::string::npos);
  // The writer refuses to replace a folder that is not an OME-Zarr.
  std::filesystem::create_directories(dir.file("other.zarr"));
  test::writeBytes(dir.file("other.zarr/keep.txt"), "x");
  EXPECT_THROW(writeZarr(patterned<uint8_t>({4, 4, 4}), dir.file("other.zarr")), IoError);
  EXPECT_TRUE(std::filesystem::exists(dir.file("other.zarr/keep.txt")));
}

TEST(Zarr, RandomCorruptionIsRefusedOrRead) {
  // A poor man's fuzzer in the test suite (the libFuzzer target `zarr` goes further): random byte
  // edits of the metadata and of a chunk either read or throw vs::Error, nothing else.
  TempDir dir("zarr_fuzz");
  ZarrWriteOptions o;
  o.chunk = 4;
  for (const std::string comp : {"zlib", "blosc", "none"}) {
    o.compressor = comp;
    const std::string p = dir.file("f.zarr");
    writeZarr(patterned<uint16_t>({9, 8, 8}), p, o);
    const std::string meta = test::readBytes(p + "/0/.zarray"), attrs = test::readBytes(p + "/.zattrs");
    const std::string chunk = test::readBytes(p + "/0/1.1.1");
    std::mt19937 rng(2501);
    for (int i = 0; i < 150; ++i) {
      std::string m = meta, a = attrs, c = chunk;
      std::string& t = i % 3 == 0 ? m : i % 3 == 1 ? a : c;
      for (int k = 0; k < 1 + int(rng() % 4); ++k) {
        if (t.empty()) break;
        const size_t at = rng() % t.size();
        switch (rng() % 3) {
          case 0:
            t[at] = char(rng());
            break;
          case 1:
            t.erase(at, 1 + rng() % 8);
            break;
          default:
            t.insert(at, 1, "0123456789-.,[]{}\"e"[rng() % 19]);
        }
      }
      test::writeBytes(p + "/0/.zarray", m);
      test::writeBytes(p + "/.zattrs", a);
      test::writeBytes(p + "/0/1.1.1", c);
      try {
        readVolume(p);
      } catch (const Error&) {
      }
    }
  }
}

}  // namespace
}  // namespace vs
