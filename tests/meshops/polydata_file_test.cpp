// The one home of .vtk / .vtp / .stl polygonal data (meshops/polydata_file: our legacy reader,
// VTK's other readers and writers): shared-point line cells and point arrays round trip exactly (a tree's parent links,
// radius and type), STL round trips in float32 with duplicates merged, and every count a header
// announces is checked against the bytes after it before anything is allocated (polydata_scan).
#include "meshops/polydata_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "util/error.h"

using namespace vs;
namespace fs = std::filesystem;

namespace {

struct Dir {
  fs::path path = fs::temp_directory_path() / ("vs_polydata_" + std::to_string(::getpid()));
  Dir() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Dir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(file(name), std::ios::binary) << bytes;
    return file(name);
  }
};

// A small tree as cells: 0 -> 1 -> 2, 1 -> 3; radius and type per point; non-round coordinates.
PolyDataCells treeCells() {
  PolyDataCells c;
  c.mesh.positions = {{0.1, -3.3, 10.7}, {20.3, 0.1, 11.0}, {1.7, 15.25, 1e-7}, {5.5, 4.0, -30.125}};
  c.lines = {{0, 1}, {1, 2}, {1, 3}};
  c.pointScalars["radius"] = {2.0, 1.5, 0.3, 0.1};
  c.pointScalars["type"] = {1, 3, 3, 7};
  return c;
}

std::string errorOf(const std::string& path) {
  try {
    readPolyDataCells(path);
  } catch (const IoError& e) {
    return e.what();
  }
  return "accepted";
}

template <class T>
void putBigEndian(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  std::reverse(b, b + sizeof(T));  // little-endian hosts
  s.append(b, sizeof(T));
}

}  // namespace

TEST(PolyDataFile, SharedPointLineCellsAndPointArraysRoundTripExactly) {
  Dir d;
  const PolyDataCells want = treeCells();
  for (const char* name : {"bin.vtk", "a.vtp"}) {
    writePolyDataCells(want, d.file(name));
    const PolyDataCells got = readPolyDataCells(d.file(name));
    EXPECT_EQ(got.mesh.positions, want.mesh.positions) << name;  // binary doubles: exact
    EXPECT_EQ(got.lines, want.lines) << name;
    EXPECT_EQ(got.pointScalars, want.pointScalars) << name;
    EXPECT_TRUE(got.mesh.triangles.empty()) << name;
  }
  // ASCII legacy: VTK writes 11 significant digits.
  writePolyDataCells(want, d.file("ascii.vtk"), {false, false});
  const PolyDataCells ascii = readPolyDataCells(d.file("ascii.vtk"));
  ASSERT_EQ(ascii.mesh.positions.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_LT((ascii.mesh.positions[i] - want.mesh.positions[i]).norm(), 1e-9);
  EXPECT_EQ(ascii.lines, want.lines);
  // Only the outputs, no temporaries.
  EXPECT_EQ(std::distance(fs::directory_iterator(d.path), fs::directory_iterator()), 3);
}

// The layout io's own writer gave trees before VTK's: two SCALARS sections in one POINT_DATA.
TEST(PolyDataFile, EverySCALARSSectionIsReadAsAnArray) {
  Dir d;
  const std::string f =
      d.write("old_tree.vtk",
              "# vtk DataFile Version 3.0\nvolscissors tree (world mm); each line is parent -> child\n"
              "ASCII\nDATASET POLYDATA\nPOINTS 3 double\n0 0 0\n1 0.5 0\n2 0 0.25\nLINES 2 6\n2 0 1\n"
              "2 1 2\nPOINT_DATA 3\nSCALARS radius double 1\nLOOKUP_TABLE default\n2\n1.5\n0.75\n"
              "SCALARS type int 1\nLOOKUP_TABLE default\n1\n3\n3\n");
  const PolyDataCells c = readPolyDataCells(f);
  EXPECT_EQ(c.lines, (std::vector<std::vector<int32_t>>{{0, 1}, {1, 2}}));
  EXPECT_EQ(c.pointScalars.at("radius"), (std::vector<double>{2, 1.5, 0.75}));
  EXPECT_EQ(c.pointScalars.at("type"), (std::vector<double>{1, 3, 3}));
}

TEST(PolyDataFile, StlRoundTripInFloatWithSharedPointsMerged) {
  Dir d;
  PolyDataCells c;
  c.mesh.positions = {{0.125, -3.5, 10.75}, {20.3, 0.1, 11.0}, {1.7, 15.25, 9.5}, {5.5, 4.0, 30.125}};
  c.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  for (bool binary : {true, false}) {
    const std::string f = d.file(binary ? "b.stl" : "a.stl");
    writePolyDataCells(c, f, {binary, false});
    const PolyDataCells got = readPolyDataCells(f);
    ASSERT_EQ(got.mesh.positions.size(), 4u) << f;
    ASSERT_EQ(got.mesh.triangles.size(), 4u) << f;
    for (size_t t = 0; t < 4; ++t)
      for (size_t k = 0; k < 3; ++k)
        EXPECT_LT(
            (got.mesh.positions[size_t(got.mesh.triangles[t][k])] - c.mesh.positions[size_t(c.mesh.triangles[t][k])])
                .norm(),
            1e-5)
            << f;
  }
  EXPECT_NE(errorOf(d.write("trunc.stl", std::string(84, '\0') + "abc")).find("trunc.stl"), std::string::npos);
  EXPECT_NE(errorOf(d.write("short.stl", "abc")).find("truncated STL"), std::string::npos);
}

TEST(PolyDataFile, LegacyHeaderCountsAreCheckedAgainstTheBytesLeftBeforeAllocating) {
  Dir d;
  const std::string ascii = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n";
  const std::string threePoints = "POINTS 3 float\n0 0 0 1 0 0 0 1 0\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"POINTS", ascii + "POINTS 2000000000 float\n1 2 3\n"},
      {"POLYGONS", ascii + threePoints + "POLYGONS 400000000 4\n3 0 1 2\n"},
      {"LINES", ascii + threePoints + "LINES 300000000 2\n2 0 1\n"},
      {"SCALARS", ascii + threePoints + "POINT_DATA 50000000\nSCALARS s float 1\nLOOKUP_TABLE default\n1 2 3\n"},
      {"NORMALS", ascii + threePoints + "POINT_DATA 100000000\nNORMALS n float\n0 0 1\n"},
      {"FIELD array", ascii + threePoints + "POINT_DATA 3\nFIELD f 1\nbig 3 90000000 double\n1 2 3\n"},
  };
  for (const auto& [word, bytes] : cases) {
    const std::string f = d.write(word.substr(0, word.find(' ')) + ".vtk", bytes);
    const std::string e = errorOf(f);
    EXPECT_NE(e.find(f), std::string::npos) << e;
    EXPECT_NE(e.find(word + " count"), std::string::npos) << e;
    EXPECT_NE(e.find("not possible"), std::string::npos) << e;
  }
  // Binary: 12 bytes per float point, 36 given for 4 points.
  std::string b = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET POLYDATA\nPOINTS 4 float\n";
  for (int i = 0; i < 9; ++i) putBigEndian(b, float(i));
  EXPECT_NE(errorOf(d.write("bin.vtk", b)).find("truncated"), std::string::npos);
}

TEST(PolyDataFile, BadFilesAreIoErrorsNamingTheFile) {
  Dir d;
  const std::string head = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"magic.vtk", "# vtx nothing\n"},
      {"mode.vtk", "# vtk DataFile Version 3.0\nt\nTEXT\nDATASET POLYDATA\n"},
      {"image.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n"},
      {"id.vtk", head + "0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 9\n"},
      {"lineid.vtk", head + "0 0 0 1 0 0 0 1 0\nLINES 1 3\n2 0 3\n"},
      {"nan.vtk", head + "0 0 0 1 nan 0 0 1 0\nPOLYGONS 1 4\n3 0 1 2\n"},
      {"short.vtk", head + "0 0 0 1 0\n"},
      {"count.vtk", head.substr(0, head.size() - 9) + "lots float\n0 0 0\n"},
  };
  for (const auto& [name, bytes] : bad) {
    const std::string e = errorOf(d.write(name, bytes));
    EXPECT_NE(e.find(name), std::string::npos) << name << ": " << e;
  }
  EXPECT_NE(errorOf(d.file("missing.vtk")).find("not found"), std::string::npos);
  EXPECT_THROW(readPolyDataCells(d.file("m.obj")), InvalidArgument);
  EXPECT_THROW(writePolyDataCells(treeCells(), (d.path / "nodir" / "t.vtk").string()), IoError);
  EXPECT_THROW(writePolyDataCells(treeCells(), (d.path / "nodir" / "t.stl").string()), IoError);
}
