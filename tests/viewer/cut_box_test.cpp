// The cut box moved with handles (app/cut_box.h), GL-free: a face moves along its axis by the
// mouse's motion along the axis' screen direction, stays inside the volume and a voxel from the
// opposite face; `cut-box` sets the box (validated), the session keeps it, a new volume resets it;
// the stylus in cut-box mode hits the moved box's face.
#include "app/cut_box.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <vector>

#include "app/script.h"
#include "app/viewer_app.h"

using namespace vs;
using namespace vs::viewer;

TEST(CutBox, FaceHandlesMoveTheirFaceWithinTheVolume) {
  const CutBox box{2, 3, 4, 20, 30, 40};
  EXPECT_EQ(cutBoxHandle(box, 0), Vec3(2, 16.5, 22));
  EXPECT_EQ(cutBoxHandle(box, 5), Vec3(11, 16.5, 40));
  const Index3 dims{32, 40, 48};
  EXPECT_EQ(movedCutBoxFace(box, 3, 25.5, dims)[3], 25.5);
  EXPECT_EQ(movedCutBoxFace(box, 3, 100, dims)[3], 31) << "inside the volume";
  EXPECT_EQ(movedCutBoxFace(box, 3, 0, dims)[3], 3) << "a voxel beyond the opposite face";
  EXPECT_EQ(movedCutBoxFace(box, 1, 35, dims)[1], 29);
  EXPECT_EQ(movedCutBoxFace(box, 2, -5, dims)[2], 0);
  const CutBox moved = movedCutBoxFace(box, 4, 10, dims);
  for (int f = 0; f < 6; ++f)
    if (f != 4) {
      EXPECT_EQ(moved[size_t(f)], box[size_t(f)]);
    }
  // The axis 4 px a voxel to the right on the screen: 10 px right = 2.5 voxels, 10 px down = 0,
  // 10 px left = -2.5; an axis pointing at the viewer (0.3 px a voxel) moves nothing.
  EXPECT_DOUBLE_EQ(cutBoxFaceShift({100, 100}, {104, 100}, {10, 0}), 2.5);
  EXPECT_DOUBLE_EQ(cutBoxFaceShift({100, 100}, {104, 100}, {0, 10}), 0);
  EXPECT_DOUBLE_EQ(cutBoxFaceShift({100, 100}, {104, 100}, {-10, 0}), -2.5);
  EXPECT_DOUBLE_EQ(cutBoxFaceShift({100, 100}, {100, 103}, {0, 6}), 2);
  EXPECT_DOUBLE_EQ(cutBoxFaceShift({100, 100}, {100.3, 100}, {10, 0}), 0);
}

TEST(CutBox, ScriptSessionAndStylus) {
  ViewerApp app;
  app.loadHeadPhantom(32);
  const Index3 d = app.geometry().dims;
  const CutBox cursorBox = app.cutBox();
  EXPECT_EQ(cursorBox[5], double(app.view().cursor[2])) << "unset: below the cursor's axial plane";
  std::istringstream in("cut-box 4,5,6,20,21,22\nmode cutbox\n");
  runScript(app, in, nullptr, "test");
  EXPECT_EQ(app.cutBox(), (CutBox{4, 5, 6, 20, 21, 22}));
  for (const std::string& bad :
       std::vector<std::string>{"cut-box 5,5,6,4,21,22\n", "cut-box -1,5,6,20,21,22\n", "cut-box 4,5,6,20,21\n",
                                "cut-box 4,5,6,20,21," + std::to_string(d[2]) + "\n"}) {
    std::istringstream b(bad);
    EXPECT_THROW(runScript(app, b, nullptr, "test"), std::exception) << bad;
    EXPECT_EQ(app.cutBox(), (CutBox{4, 5, 6, 20, 21, 22})) << "unchanged by " << bad;
  }
  // The stylus in cut-box mode hits the moved box: a ray along +z through the box's middle enters
  // at its z0 face.
  const Geometry& g = app.geometry();
  const Vec3 o = g.indexToWorld(Vec3(12, 13, -10)), d2 = g.indexToWorld(Vec3(12, 13, 0)) - o;
  const StylusPick p = app.pick(o, d2);
  ASSERT_TRUE(p.hit);
  EXPECT_NEAR(p.surface.z(), 6, 1e-6);
  // The session keeps the box; an older session (none) gives the cursor's box; a new volume resets it.
  const std::string file = (std::filesystem::temp_directory_path() / "vs_cut_box_session.json").string();
  app.saveSession(file);
  ViewerApp b;
  b.loadSession(file);
  EXPECT_EQ(b.cutBox(), (CutBox{4, 5, 6, 20, 21, 22}));
  std::istringstream autoBox("cut-box auto\n");
  runScript(b, autoBox, nullptr, "test");
  EXPECT_EQ(b.cutBox(), cursorBox);
  EXPECT_FALSE(b.sessionJson()["view"].contains("cut_box"));
  app.loadHeadPhantom(40);
  EXPECT_FALSE(app.view().cutBox.has_value());
  std::filesystem::remove(file);
}
