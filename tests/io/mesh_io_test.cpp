// Mesh, tree and polyline files: write/read round trips for every format (positions,
// connectivity, normals, radii, types, closedness) and malformed-input errors.
#include "io/mesh_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "io/png_io.h"
#include "io/volume_io.h"
#include "io_test_util.h"

using namespace vs;
using namespace vs::test;

namespace {

// A tetrahedron with non-round coordinates and per-vertex normals.
TriMesh tetra() {
  TriMesh m;
  m.positions = {{0.125, -3.5, 10.75}, {20.3, 0.1, 11.0}, {1.7, 15.25, 9.5}, {5.5, 4.0, 30.125}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  for (const auto& p : m.positions) m.normals.push_back((p - Eigen::Vector3d(6, 4, 15)).normalized());
  return m;
}

// Vertex order may change (STL merges duplicates); compare triangles as position triples.
void expectSameMesh(const TriMesh& a, const TriMesh& b, double tol, bool normals) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t t = 0; t < a.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& pa = a.positions[static_cast<size_t>(a.triangles[t][static_cast<size_t>(k)])];
      const auto& pb = b.positions[static_cast<size_t>(b.triangles[t][static_cast<size_t>(k)])];
      EXPECT_LT((pa - pb).norm(), tol) << "triangle " << t << " corner " << k;
    }
  if (normals) {
    ASSERT_EQ(b.normals.size(), b.positions.size());
    for (size_t i = 0; i < a.normals.size(); ++i) EXPECT_LT((a.normals[i] - b.normals[i]).norm(), 1e-6);
  }
}

}  // namespace

TEST(MeshIo, TriMeshRoundTripAllFormats) {
  TempDir dir("mesh");
  const TriMesh m = tetra();
  for (const std::string ext : {".obj", ".ply", ".vtk", ".stl"}) {
    const std::string path = dir.file("m" + ext);
    writeTriMesh(m, path);
    const TriMesh back = readTriMesh(path);
    const bool exactish = ext != ".stl";  // STL stores float32 and no normals
    expectSameMesh(m, back, exactish ? 1e-9 : 1e-5, exactish);
    EXPECT_EQ(back.positions.size(), 4u) << ext;  // STL duplicates are merged again
  }
  // Only the four outputs, no temporaries.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path), fs::directory_iterator()), 4);
}

TEST(MeshIo, ObjPolygonsAndNegativeIndicesAndAsciiPly) {
  TempDir dir("obj");
  writeBytes(dir.file("q.obj"), "# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1 4/1\nf -4 -2 -1\n");
  const TriMesh q = readTriMesh(dir.file("q.obj"));
  ASSERT_EQ(q.triangles.size(), 3u);
  EXPECT_EQ(q.triangles[1], (std::array<int32_t, 3>{0, 2, 3}));
  EXPECT_EQ(q.triangles[2], (std::array<int32_t, 3>{0, 2, 3}));
  writeBytes(dir.file("a.ply"),
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 2 0\n3 0 1 2\n");
  const TriMesh a = readTriMesh(dir.file("a.ply"));
  ASSERT_EQ(a.triangles.size(), 1u);
  EXPECT_DOUBLE_EQ(a.positions[2].y(), 2.0);
}

TEST(MeshIo, BadMeshFiles) {
  TempDir dir("badmesh");
  EXPECT_THROW(readTriMesh(dir.file("missing.obj")), IoError);
  writeBytes(dir.file("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
  EXPECT_THROW(readTriMesh(dir.file("bad.obj")), IoError);
  writeBytes(dir.file("bad2.obj"), "v 0 zero 0\n");
  EXPECT_THROW(readTriMesh(dir.file("bad2.obj")), IoError);
  writeTriMesh(tetra(), dir.file("t.ply"));
  const std::string ply = readBytes(dir.file("t.ply"));
  writeBytes(dir.file("trunc.ply"), ply.substr(0, ply.size() - 7));
  EXPECT_THROW(readTriMesh(dir.file("trunc.ply")), IoError);
  writeBytes(dir.file("magic.ply"), "plx\n");
  EXPECT_THROW(readTriMesh(dir.file("magic.ply")), IoError);
  writeTriMesh(tetra(), dir.file("t.stl"));
  const std::string stl = readBytes(dir.file("t.stl"));
  writeBytes(dir.file("trunc.stl"), stl.substr(0, stl.size() - 10));
  EXPECT_THROW(readTriMesh(dir.file("trunc.stl")), IoError);
  EXPECT_THROW(writeTriMesh(tetra(), dir.file("m.xyz")), IoError);
  EXPECT_THROW(writeTriMesh(tetra(), (dir.path / "nodir" / "m.obj").string()), IoError);
  TriMesh broken = tetra();
  broken.triangles.push_back({0, 1, 9});
  EXPECT_THROW(writeTriMesh(broken, dir.file("b.obj")), InvalidArgument);
  EXPECT_FALSE(fs::exists(dir.file("b.obj")));
}

namespace {

Tree sampleTree() {
  // root 0 -> 1 -> 2, 1 -> 3 (branch), 3 -> 4; second root 5 -> 6.
  Tree t;
  t.points = {{0, 0, 0}, {1.5, 0.25, -2}, {3, 1, -4}, {2, -1.125, -3}, {2.5, -2, -5}, {10, 10, 10}, {11, 10.5, 9}};
  t.parent = {-1, 0, 1, 1, 3, -1, 5};
  t.radii = {2.0, 1.5, 1.0, 0.75, 0.5, 1.25, 0.3};
  t.types = {1, 3, 3, 3, 3, 1, 3};
  return t;
}

}  // namespace

TEST(MeshIo, TreeRoundTripSwcVtkJson) {
  TempDir dir("tree");
  const Tree t = sampleTree();
  for (const std::string ext : {".swc", ".vtk", ".json"}) {
    const std::string path = dir.file("t" + ext);
    writeTree(t, path);
    const Tree b = readTree(path);
    ASSERT_EQ(b.size(), t.size()) << ext;
    EXPECT_EQ(b.parent, t.parent) << ext;
    EXPECT_EQ(b.types, t.types) << ext;
    for (size_t i = 0; i < t.size(); ++i) {
      EXPECT_LT((b.points[i] - t.points[i]).norm(), 1e-12) << ext;
      EXPECT_DOUBLE_EQ(b.radii[i], t.radii[i]) << ext;
    }
  }
}

TEST(MeshIo, SwcWithArbitraryIdsAndErrors) {
  TempDir dir("swc");
  writeBytes(dir.file("a.swc"), "# header\n10 1 0 0 0 1 -1\n20 3 1 0 0 0.5 10\n15 3 0 1 0 0.5 20\n");
  const Tree t = readTree(dir.file("a.swc"));
  EXPECT_EQ(t.parent, (std::vector<int32_t>{-1, 0, 1}));
  writeBytes(dir.file("b.swc"), "1 1 0 0 0 1 -1\n2 3 1 0 0 0.5 7\n");
  EXPECT_THROW(readTree(dir.file("b.swc")), IoError);
  writeBytes(dir.file("c.swc"), "1 1 0 0 0 1 2\n2 3 1 0 0 0.5 1\n");  // cycle
  EXPECT_THROW(readTree(dir.file("c.swc")), IoError);
  writeBytes(dir.file("d.swc"), "1 1 0 0\n");
  EXPECT_THROW(readTree(dir.file("d.swc")), IoError);
  writeBytes(dir.file("e.json"), "{\"nodes\": [ {\"id\": 1, \"xyz\": [0, 0]} ]}");
  EXPECT_THROW(readTree(dir.file("e.json")), IoError);
  writeBytes(dir.file("f.json"), "{ not json");
  EXPECT_THROW(readTree(dir.file("f.json")), IoError);
}

TEST(MeshIo, PolylinesRoundTripVtkJson) {
  TempDir dir("poly");
  std::vector<Polyline> lines(3);
  lines[0].points = {{0, 0, 0}, {1, 2, 3}, {4, 5, 6.5}};
  lines[0].radii = {1, 2, 3};
  lines[1].points = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  lines[1].radii = {0.5, 0.5, 0.5, 0.5};
  lines[1].closed = true;
  lines[2].points = {{7.25, 8, 9}, {7.5, 8, 9}};
  lines[2].radii = {0.1, 0.2};
  for (const std::string ext : {".vtk", ".json"}) {
    writePolylines(lines, dir.file("p" + ext));
    const auto back = readPolylines(dir.file("p" + ext));
    ASSERT_EQ(back.size(), lines.size()) << ext;
    for (size_t i = 0; i < lines.size(); ++i) {
      EXPECT_EQ(back[i].closed, lines[i].closed) << ext << " line " << i;
      ASSERT_EQ(back[i].points.size(), lines[i].points.size()) << ext;
      for (size_t k = 0; k < lines[i].points.size(); ++k)
        EXPECT_LT((back[i].points[k] - lines[i].points[k]).norm(), 1e-12);
      EXPECT_EQ(back[i].radii, lines[i].radii) << ext;
    }
  }
  std::vector<Polyline> bad(1);
  bad[0].points = {{0, 0, 0}, {1, 1, 1}};
  bad[0].radii = {1};
  EXPECT_THROW(writePolylines(bad, dir.file("bad.json")), InvalidArgument);
  EXPECT_THROW(writePolylines(lines, dir.file("p.obj")), IoError);
}

TEST(PngIo, RoundTripAndErrors) {
  TempDir dir("png");
  RgbaImage img(5, 3);
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = static_cast<uint8_t>(i * 7);
  writePng(img, dir.file("a.png"));
  const RgbaImage back = readPng(dir.file("a.png"));
  EXPECT_EQ(back.width, 5);
  EXPECT_EQ(back.height, 3);
  EXPECT_EQ(back.pixels, img.pixels);
  const std::string bytes = readBytes(dir.file("a.png"));
  writeBytes(dir.file("trunc.png"), bytes.substr(0, bytes.size() / 2));
  EXPECT_THROW(readPng(dir.file("trunc.png")), IoError);
  writeBytes(dir.file("magic.png"), "not a png at all");
  EXPECT_THROW(readPng(dir.file("magic.png")), IoError);
  EXPECT_THROW(readPng(dir.file("missing.png")), IoError);
  EXPECT_THROW(writePng(RgbaImage(), dir.file("empty.png")), InvalidArgument);
  EXPECT_THROW(writePng(img, (dir.path / "no" / "a.png").string()), IoError);
}

TEST(MeshIo, MalformedNumbersInHeadersAreIoErrors) {
  TempDir dir("malformed");
  writeBytes(dir.file("h.ply"), "ply\nformat binary_little_endian 1.0\nelement vertex many\nend_header\n");
  EXPECT_THROW(readTriMesh(dir.file("h.ply")), IoError);
  writeBytes(dir.file("h.vtk"), "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS lots float\n");
  EXPECT_THROW(readPolylines(dir.file("h.vtk")), IoError);
  writeBytes(dir.file("v.vtk"),
             "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS a b c\nSPACING 1 1 1\n");
  EXPECT_THROW(vs::readVolume(dir.file("v.vtk")), IoError);
}

namespace {
template <class T>
void appendBigEndian(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  std::reverse(b, b + sizeof(T));  // the test machines are little-endian hosts
  s.append(b, sizeof(T));
}
}  // namespace

// Current VTK (9.x) writes legacy version 5.1: cells as OFFSETS + CONNECTIVITY arrays.
TEST(MeshIo, LegacyVtk51CellsAsciiAndBinary) {
  TempDir dir("vtk51");
  // As written by VTK 9.1's vtkPolyDataWriter for a 4x3 vtkSphereSource (8 triangles).
  writeBytes(dir.file("sphere.vtk"),
             "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET POLYDATA\nPOINTS 6 float\n"
             "0 0 0.5 0 0 -0.5 0.5 0 3.06162e-17 \n3.06162e-17 0.5 3.06162e-17 -0.5 6.12323e-17 3.06162e-17 "
             "-9.18485e-17 -0.5 3.06162e-17 \n\nPOLYGONS 9 24\nOFFSETS vtktypeint64\n0 3 6 9 12 15 18 21 24 \n\n"
             "CONNECTIVITY vtktypeint64\n2 3 0 3 4 0 4 5 0 \n5 2 0 2 1 3 3 1 4 \n4 1 5 5 1 2 \n");
  const TriMesh m = readTriMesh(dir.file("sphere.vtk"));
  ASSERT_EQ(m.positions.size(), 6u);
  ASSERT_EQ(m.triangles.size(), 8u);
  EXPECT_EQ(m.triangles[0], (std::array<int32_t, 3>{2, 3, 0}));
  EXPECT_EQ(m.triangles[7], (std::array<int32_t, 3>{5, 1, 2}));
  for (const auto& p : m.positions) EXPECT_NEAR(p.norm(), 0.5, 1e-6);

  // The same layout in binary (big-endian), with a polyline.
  std::string b = "# vtk DataFile Version 5.1\nvtk output\nBINARY\nDATASET POLYDATA\nPOINTS 3 float\n";
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 2.f, 0.f}) appendBigEndian(b, v);
  b += "\nLINES 2 3\nOFFSETS vtktypeint64\n";
  for (int64_t v : {0, 3}) appendBigEndian(b, v);
  b += "\nCONNECTIVITY vtktypeint64\n";
  for (int64_t v : {0, 1, 2}) appendBigEndian(b, v);
  b += "\n";
  writeBytes(dir.file("line.vtk"), b);
  const auto lines = readPolylines(dir.file("line.vtk"));
  ASSERT_EQ(lines.size(), 1u);
  ASSERT_EQ(lines[0].points.size(), 3u);
  EXPECT_EQ(lines[0].points[2], Eigen::Vector3d(1, 2, 0));

  // A connectivity id past the points is an error naming it.
  writeBytes(dir.file("bad.vtk"),
             "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\n"
             "POLYGONS 2 3\nOFFSETS vtktypeint64\n0 3\nCONNECTIVITY vtktypeint64\n0 1 7\n");
  EXPECT_THROW(readTriMesh(dir.file("bad.vtk")), IoError);
}
