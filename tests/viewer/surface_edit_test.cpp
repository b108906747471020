// The surface tool's editing (app/surface_tool.cpp; thesis 5.2), GL-free: a via point on a chosen
// side re-subdivides only that side's octant (SurfaceExtraction::editSide) and gives the mesh of a
// fresh extraction with that via point; a moved corner gives the mesh of a fresh extraction with
// that corner; each run is one undo step that also restores the corners and via points; the
// script commands and the session carry them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>

#include "app/script.h"
#include "app/viewer_app.h"
#include "surface/surface.h"

namespace fs = std::filesystem;
using namespace vs;
using namespace vs::viewer;

namespace {

void script(ViewerApp& app, const std::string& s) {
  std::istringstream in(s);
  runScript(app, in, nullptr, "test");
}

std::string str(const Index3& p) {
  return std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]);
}

}  // namespace

TEST(SurfaceEditTool, ViaPointsAndCornersEqualFreshExtractionsAndUndo) {
  ViewerApp app;
  app.loadHeadPhantom(64);
  script(app, "tool surface\nsurface-level 2\nplanes 32,32,32\nrun\n");
  SurfaceTool& sf = app.surface();
  const TriMesh first = sf.mesh();
  EXPECT_EQ(sf.lastRun(), "extracted");
  const auto corners = sf.corners();
  for (const int h : {0, 2, 4}) EXPECT_TRUE(corners[size_t(h)].has_value()) << SurfaceTool::halfLineName(h);
  const auto sides = sf.sides();
  ASSERT_EQ(sides.size(), 3u);
  std::vector<Index3> side;
  for (const auto& [name, path] : sides)
    if (name == "z+x+y") side = path;
  ASSERT_GT(side.size(), 6u);
  // A via point two voxels inside the side's middle (towards the centre, in plane z = 32).
  Index3 via = side[side.size() / 2];
  via[0] = std::max<int64_t>(32, via[0] - 2);
  via[1] = std::max<int64_t>(32, via[1] - 2);
  script(app, "surface-side z+x+y\nsurface-via " + str(via) + "\nrun\n");
  EXPECT_EQ(sf.lastRun().rfind("side z+x+y edited: 1 octant re-subdivided", 0), 0u) << sf.lastRun();
  SurfaceOptions o;
  o.planes = {32, 32, 32};
  o.level = 2;
  o.via = {{"z+x+y", {via}}};
  const SurfaceResult fresh = extractSurface(app.floatVolume(), o);
  EXPECT_EQ(sf.mesh().positions, fresh.mesh.positions) << "the incremental edit equals a fresh extraction";
  EXPECT_EQ(sf.mesh().triangles, fresh.mesh.triangles);
  EXPECT_NE(sf.mesh().positions, first.positions) << "the via point changed the surface";

  // A corner moved three voxels in along +x: a fresh extraction with that corner.
  Index3 corner = *corners[0];
  corner[0] -= 3;
  script(app, "surface-via clear\nsurface-corner +x " + str(corner) + "\nrun\n");
  EXPECT_EQ(sf.lastRun(), "extracted");
  EXPECT_EQ(sf.corners()[0], std::optional<Index3>(corner));
  SurfaceOptions oc;
  oc.planes = {32, 32, 32};
  oc.level = 2;
  oc.corners[0] = corner;
  EXPECT_EQ(sf.mesh().positions, extractSurface(app.floatVolume(), oc).mesh.positions);

  // The session keeps the corner and the side.
  const fs::path file = fs::temp_directory_path() / ("vs_surface_edit_" + std::to_string(::getpid()) + ".json");
  app.saveSession(file.string());
  ViewerApp b;
  b.loadSession(file.string());
  fs::remove(file);
  EXPECT_EQ(b.surface().cornerOverrides()[0], std::optional<Index3>(corner));
  EXPECT_EQ(b.surface().selectedSide(), "z+x+y");

  // Undo: the via edit's mesh, its via point pending again; then the first extraction.
  ASSERT_TRUE(app.undo());
  EXPECT_EQ(sf.mesh().positions, fresh.mesh.positions);
  EXPECT_EQ(sf.via("z+x+y"), std::vector<Index3>{via});
  EXPECT_FALSE(sf.cornerOverrides()[0].has_value());
  ASSERT_TRUE(app.undo());
  EXPECT_EQ(sf.mesh().positions, first.positions);
  EXPECT_TRUE(sf.via("z+x+y").empty());
  ASSERT_TRUE(app.redo());
  EXPECT_EQ(sf.mesh().positions, fresh.mesh.positions);

  EXPECT_THROW(script(app, "surface-side q+x+y\n"), ScriptError);
  EXPECT_THROW(script(app, "surface-corner +w 1,2,3\n"), ScriptError);
  EXPECT_THROW(script(app, "surface-via 1,2\n"), ScriptError);
}
