// Overlays written by current VTK (9.x): XML PolyData (.vtp, appended/compressed and ASCII)
// read through meshops' VTK reader, and legacy files in VTK's 5.1 layout (binary and ASCII) read by
// io's own reader: same triangles, lines, radii and closedness as written; bad files are IoErrors
// naming the file.
#include <gtest/gtest.h>

#include "io/overlay_io.h"
#include "io_test_util.h"
#include "meshops/polydata_file.h"
#include "util/error.h"

using namespace vs;
using namespace vs::test;

namespace {

PolyDataContent sample() {
  PolyDataContent c;
  c.mesh.positions = {{0.125, -3.5, 10.75}, {20.3, 0.1, 11.0}, {1.7, 15.25, 9.5}, {5.5, 4.0, 30.125}};
  c.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  Polyline open, loop;
  open.points = {{1, 2, 3}, {4, 5, 6.5}, {7, 8, 9}};
  open.radii = {0.5, 0.75, 1.25};
  loop.points = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}};
  loop.radii = {1, 1, 1, 1};
  loop.closed = true;
  c.lines = {open, loop};
  return c;
}

Geometry box() {
  Geometry g;
  g.dims = {40, 40, 40};
  return g;
}

void expectSameOverlay(const PolyDataContent& want, const Overlay& got) {
  ASSERT_EQ(got.mesh.triangles.size(), want.mesh.triangles.size());
  for (size_t t = 0; t < want.mesh.triangles.size(); ++t)
    for (size_t k = 0; k < 3; ++k) {
      const Vec3& a = want.mesh.positions[size_t(want.mesh.triangles[t][k])];
      const Vec3& b = got.mesh.positions[size_t(got.mesh.triangles[t][k])];
      EXPECT_LT((a - b).norm(), 1e-6) << "triangle " << t;
    }
  ASSERT_EQ(got.lines.size(), want.lines.size());
  for (size_t l = 0; l < want.lines.size(); ++l) {
    EXPECT_EQ(got.lines[l].closed, want.lines[l].closed) << "line " << l;
    ASSERT_EQ(got.lines[l].points.size(), want.lines[l].points.size()) << "line " << l;
    for (size_t k = 0; k < want.lines[l].points.size(); ++k)
      EXPECT_LT((got.lines[l].points[k] - want.lines[l].points[k]).norm(), 1e-6);
  }
}

TEST(OverlayVtkFiles, VtpWrittenByVtkIsReadWithMeshAndLines) {
  TempDir d("ovl_vtp");
  for (bool binary : {true, false}) {
    const std::string f = d.file(binary ? "appended.vtp" : "ascii.vtp");
    writePolyDataFile(sample(), f, {binary, binary});
    EXPECT_NE(readBytes(f).find("<VTKFile type=\"PolyData\""), std::string::npos);
    const Overlay o = readOverlay(f, box());
    expectSameOverlay(sample(), o);
    EXPECT_EQ(o.lines[0].radii, sample().lines[0].radii);
  }
}

TEST(OverlayVtkFiles, LegacyVersion51WrittenByVtkIsReadByTheOwnReader) {
  TempDir d("ovl_vtk51");
  PolyDataContent meshOnly = sample(), linesOnly = sample();
  meshOnly.lines.clear();
  linesOnly.mesh = TriMesh();
  for (bool binary : {true, false}) {
    const std::string m = d.file(binary ? "mesh_bin.vtk" : "mesh_ascii.vtk");
    const std::string l = d.file(binary ? "lines_bin.vtk" : "lines_ascii.vtk");
    writePolyDataFile(meshOnly, m, {binary, false});
    writePolyDataFile(linesOnly, l, {binary, false});
    EXPECT_EQ(readBytes(m).rfind("# vtk DataFile Version 5.1", 0), 0u) << "VTK no longer writes 5.1?";
    expectSameOverlay(meshOnly, readOverlay(m, box()));
    expectSameOverlay(linesOnly, readOverlay(l, box()));
  }
}

TEST(OverlayVtkFiles, MeshopsReadsBothKindsBack) {
  TempDir d("ovl_rt");
  for (const char* name : {"a.vtp", "b.vtk"}) {
    writePolyDataFile(sample(), d.file(name));
    const PolyDataContent c = readPolyDataFile(d.file(name));
    EXPECT_EQ(c.mesh.triangles.size(), 4u) << name;
    ASSERT_EQ(c.lines.size(), 2u) << name;
    EXPECT_TRUE(c.lines[1].closed) << name;
    EXPECT_EQ(c.lines[1].radii, sample().lines[1].radii) << name;
  }
}

TEST(OverlayVtkFiles, BadVtpIsAnIoErrorNamingTheFile) {
  TempDir d("ovl_bad");
  const std::string good = d.file("good.vtp");
  writePolyDataFile(sample(), good, {false, false});
  const std::string text = readBytes(good);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"garbage.vtp", "this is not XML at all\n"},
      {"truncated.vtp", text.substr(0, text.size() / 2)},
      {"image.vtp", "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\"></VTKFile>\n"},
      {"empty.vtp",
       "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData>"
       "</PolyData></VTKFile>\n"}};
  for (const auto& [name, bytes] : bad) {
    writeBytes(d.file(name), bytes);
    try {
      readOverlay(d.file(name), box());
      ADD_FAILURE() << name << " was accepted";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(readOverlay(d.file("missing.vtp"), box()), IoError);
}

}  // namespace
