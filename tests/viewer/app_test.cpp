// The viewer's GL-free layer: tools, undo/redo, script interpreter, session, stylus, eye
// matrices; and equality with the CLI for the same points.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "app/cpu_view.h"
#include "app/input_queue.h"
#include "app/script.h"
#include "app/tf_editor.h"
#include "app/viewer_app.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "render/renderer.h"

namespace fs = std::filesystem;
using namespace vs;
using namespace vs::viewer;

namespace {

class ViewerAppTest : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() / ("vs_viewer_app_" + std::to_string(::getpid()));
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  static std::string text(const std::string& p) {
    std::ifstream f(p);
    return {std::istreambuf_iterator<char>(f), {}};
  }
  int cli(const std::string& args) {
    const std::string cmd =
        std::string(VS_CLI_PATH) + " -q " + args + " > " + path("stdout.txt") + " 2> " + path("stderr.txt");
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  void script(ViewerApp& app, const std::string& s) {
    std::istringstream in(s);
    runScript(app, in, nullptr, "test");
  }
};

// Points on a circle around the head phantom's centre of slice z: the skin boundary region.
std::vector<PixelUV> circle(int n, double cx, double cy, double r) {
  std::vector<PixelUV> pts;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * 3.14159265358979 * i / n;
    pts.push_back({std::lround(cx + r * std::cos(a)), std::lround(cy + r * std::sin(a))});
  }
  return pts;
}

}  // namespace

TEST_F(ViewerAppTest, ScriptErrorsNameTheLine) {
  ViewerApp app;
  app.loadHeadPhantom(32);
  try {
    script(app, "# comment\nmode mip\nfrobnicate 3\n");
    FAIL() << "no error";
  } catch (const ScriptError& e) {
    EXPECT_NE(std::string(e.what()).find("test:3:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("unknown command"), std::string::npos) << e.what();
  }
  EXPECT_EQ(app.view().mode, RenderMode::Mip);  // the lines before the error ran
  EXPECT_THROW(script(app, "mode sideways"), ScriptError);
  EXPECT_THROW(script(app, "planes 1,2"), ScriptError);
  EXPECT_THROW(script(app, "planes 1,2,99"), ScriptError);               // outside the 32^3 volume
  EXPECT_THROW(script(app, "screenshot x.png"), ScriptError);            // no window
  EXPECT_THROW(script(app, "tool livewire\npoint 1,2,3"), ScriptError);  // 3D point for a 2D tool
  EXPECT_THROW(script(app, "load /nonexistent/volume.nii"), ScriptError);
  // A polarity the chosen trace cost does not use names the costs that use it (issue 21).
  try {
    script(app, "trace-cost auto dark");
    ADD_FAILURE() << "trace-cost auto dark accepted";
  } catch (const ScriptError& e) {
    EXPECT_NE(std::string(e.what()).find("applies to vesselness or intensity"), std::string::npos) << e.what();
  }
  EXPECT_THROW(script(app, "trace-cost gradient bright"), ScriptError);
  EXPECT_NO_THROW(script(app, "trace-cost intensity dark"));
  EXPECT_EQ(app.geometry().dims[0], 32);  // the failed load kept the volume
}

TEST_F(ViewerAppTest, LiveWireUndoRedoSurvivesNavigation) {
  ViewerApp app;
  app.loadHeadPhantom(64);
  app.setTool(ToolKind::LiveWire);
  app.liveWire().setSlice(2, 32);
  const auto pts = circle(24, 31.5, 31.5, 20);
  for (const auto& p : pts) app.point2(p);
  app.closeContour();
  const LiveWireContour full = app.liveWire().contour();
  ASSERT_TRUE(full.closed);
  // Navigation between edits: none of it touches the history.
  app.setOrbit(120, 30);
  app.setCursor({10, 20, 5});
  app.setWindow(500, 100);
  app.setMode(RenderMode::Triplanar);
  EXPECT_EQ(app.liveWire().undoSteps(), 25u);
  for (int i = 0; i < 25; ++i) ASSERT_TRUE(app.undo()) << "undo step " << i + 1;
  EXPECT_FALSE(app.undo());
  EXPECT_TRUE(app.liveWire().contour().pixels.empty());
  for (int i = 0; i < 25; ++i) ASSERT_TRUE(app.redo()) << "redo step " << i + 1;
  const LiveWireContour again = app.liveWire().contour();
  EXPECT_TRUE(again.closed);
  EXPECT_EQ(again.pixels, full.pixels);
  EXPECT_DOUBLE_EQ(again.lengthMm, full.lengthMm);
  // A new action after undo drops the redo branch.
  app.undo();
  app.undo();
  app.point2(pts[23]);
  EXPECT_EQ(app.liveWire().redoSteps(), 0u);
  // The live path follows the mouse from the last anchor.
  const auto& live = app.liveWire().hover({31, 60});
  ASSERT_FALSE(live.empty());
  EXPECT_EQ(live.front(), pts[23]);
  EXPECT_EQ(live.back(), (PixelUV{31, 60}));
  // The contour pins the tool to its slice.
  EXPECT_THROW(app.liveWire().setSlice(2, 10), InvalidArgument);
}

TEST_F(ViewerAppTest, LiveWireEqualsCli) {
  HeadPhantomOptions o;
  o.dims = {64, 64, 48};
  o.spacing = {1.0, 1.0, 1.5};
  const std::string vol = path("head.nii.gz");
  writeVolume(AnyVolume(makeHeadPhantom(o).volume), vol);
  const auto pts = circle(5, 31.5, 31.5, 22);
  std::string list, scriptText = "load " + vol + "\ntool livewire\nslice z=20\nsnap 2\n";
  for (const auto& p : pts) {
    if (!list.empty()) list += ';';  // (a `"" + string` chain here trips GCC 12's false -Wrestrict)
    list += std::to_string(p[0]) + "," + std::to_string(p[1]);
    scriptText += "point " + std::to_string(p[0]) + "," + std::to_string(p[1]) + "\n";
  }
  scriptText += "close\nsave " + path("viewer.json") + "\n";
  ViewerApp app;
  app.loadHeadPhantom(32);
  script(app, scriptText);
  ASSERT_EQ(
      cli("livewire " + vol + " --slice z=20 --snap 2 --closed --points '" + list + "' --out " + path("cli.json")), 0)
      << text(path("stderr.txt"));
  const auto a = nlohmann::json::parse(text(path("viewer.json"))), b = nlohmann::json::parse(text(path("cli.json")));
  for (const char* key :
       {"points", "points_index", "clicks", "closed", "length_mm", "cost", "area_pixels", "slice", "file"})
    EXPECT_EQ(a.at(key), b.at(key)) << key;
  EXPECT_GT(a.at("points").size(), 50u);
}

TEST_F(ViewerAppTest, TraceEqualsCliAndSessionReopens) {
  VesselPhantomOptions o;
  o.dims = {48, 48, 48};
  o.minTerminals = 3;
  o.maxTerminals = 4;
  const VesselPhantom ph = makeVesselPhantom(o);
  const std::string vol = path("vessels.nii.gz");
  writeVolume(AnyVolume(ph.volume), vol);
  auto str = [](const Index3& p) {
    return std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]);
  };
  std::string s = "load " + vol + "\ntool trace\npoint " + str(ph.truth.rootVoxel) + "\n";
  std::string targets;
  for (const auto& t : ph.truth.terminalVoxels) {
    s += "point " + str(t) + "\n";
    targets += " --target " + str(t);
  }
  s += "run\nsave " + path("viewer.swc") + "\nsession-save " + path("session.json") + "\n";
  ViewerApp app;
  app.loadHeadPhantom(32);
  script(app, s);
  // Both at their defaults (tracking/trace_options.h: the auto cost, snapping into the lumen,
  // refined centrelines): the same SWC, byte for byte.
  EXPECT_EQ(app.trace().costKind(), TraceOptions{}.cost);
  ASSERT_EQ(cli("trace " + vol + " --root " + str(ph.truth.rootVoxel) + targets + " --out " + path("cli.swc")), 0)
      << text(path("stderr.txt"));
  EXPECT_EQ(text(path("viewer.swc")), text(path("cli.swc")));
  EXPECT_EQ(app.trace().paths().size(), ph.truth.terminalVoxels.size());
  // Refined: the SWC holds sub-voxel positions (not only voxel centres mapped to mm).
  EXPECT_EQ(app.trace().usedPoints().size(), ph.truth.terminalVoxels.size() + 1);

  // Automatic terminals from the root alone, as the CLI's --auto-terminals N: the same tree.
  ViewerApp autoApp;
  script(autoApp, "load " + vol + "\ntool trace\npoint " + str(ph.truth.rootVoxel) + "\nauto-terminals 3\nrun\nsave " +
                      path("viewer_auto.swc") + "\n");
  ASSERT_EQ(
      cli("trace " + vol + " --root " + str(ph.truth.rootVoxel) + " --auto-terminals 3 --out " + path("cli_auto.swc")),
      0)
      << text(path("stderr.txt"));
  EXPECT_EQ(text(path("viewer_auto.swc")), text(path("cli_auto.swc")));
  EXPECT_GE(autoApp.trace().paths().size(), 2u);

  // Undo the last target: the next run drops its path; redo brings it back.
  script(app, "undo\nrun\n");
  EXPECT_EQ(app.trace().paths().size(), ph.truth.terminalVoxels.size() - 1);
  script(app, "redo\nrun\n");
  EXPECT_EQ(app.trace().paths().size(), ph.truth.terminalVoxels.size());

  // The session reopens to the same state and recomputes the same tree.
  ViewerApp reopened;
  reopened.loadSession(path("session.json"));
  EXPECT_EQ(reopened.sessionJson(), nlohmann::json::parse(text(path("session.json"))));
  reopened.save(path("reopened.swc"));
  EXPECT_EQ(text(path("reopened.swc")), text(path("cli.swc")));
}

TEST_F(ViewerAppTest, SessionRoundTripWithContour) {
  ViewerApp app;
  app.loadHeadPhantom(48);
  script(app,
         "mode cutbox\ntf ct-bone\nview 45 10\nzoom 1.5\nwindow 400 40\nplanes 10,20,30\nstereo anaglyph\n"
         "tool livewire\nslice y=24\npoint 5,5\npoint 40,10\npoint 40,40\nclose\nsession-save " +
             path("s.json") + "\n");
  ViewerApp b;
  b.loadHeadPhantom(32);
  std::istringstream in("session-load " + path("s.json") + "\n");
  runScript(b, in, nullptr, "reload");
  EXPECT_EQ(b.sessionJson(), app.sessionJson());
  EXPECT_EQ(b.liveWire().contour().pixels, app.liveWire().contour().pixels);
  EXPECT_EQ(b.view().mode, RenderMode::CutBox);
  EXPECT_EQ(b.view().stereo, StereoMode::Anaglyph);
  std::ofstream(path("bad.json")) << "{\"volscissors_session\": 1, \"volume\": 3}";
  EXPECT_THROW(b.loadSession(path("bad.json")), IoError);
}

TEST_F(ViewerAppTest, StylusHitsTheSkinAndSnapsToTheEdge) {
  ViewerApp app;
  HeadPhantomOptions o;
  o.dims = {64, 64, 64};
  const HeadTruth truth = makeHeadPhantom(o).truth;
  app.loadHeadPhantom(64);
  ASSERT_EQ(app.view().tf, "ct-skin");
  // A ray along +y (from anterior) through the head's centre hits the skin's front, or the nose.
  const Vec3 c = truth.skin.centerMm;
  const Vec3 hit0(c.x() + 10, -50, c.z() - 10);  // beside the nose
  const StylusPick p = app.pick(hit0, Vec3(0, 1, 0));
  ASSERT_TRUE(p.hit);
  // Ellipsoid front surface at x, z: y = cy - b sqrt(1 - (dx/a)^2 - (dz/c)^2).
  const Vec3& s = truth.skin.semiAxesMm;
  const double dx = 10 / s.x(), dz = -10 / s.z();
  const double yTrue = c.y() - s.y() * std::sqrt(1 - dx * dx - dz * dz);
  EXPECT_NEAR(p.surface.y(), yTrue, 1.0);
  // With a snap radius the voxel moves onto the strongest edge: within a voxel of the surface.
  app.setSnap(3);
  const StylusPick q = app.pick(hit0 + Vec3(0, 0, 0), Vec3(0, 1, 0));
  ASSERT_TRUE(q.hit);
  EXPECT_NEAR(double(q.voxel[1]), yTrue, 1.0);
  // A ray that misses the volume picks nothing.
  EXPECT_FALSE(app.pick(Vec3(-50, -50, -50), Vec3(-1, 0, 0)).hit);
}

// The 3D view's pan moves the picture by the pan in mm at the look-at point, with the camera maths
// both renderers use (app.camera()); the stylus follows: the pixel where a surface point shows
// after the pan picks that point again.
TEST_F(ViewerAppTest, PanMovesThePictureAndTheStylusFollows) {
  ViewerApp app;
  app.loadHeadPhantom(64);
  app.setOrbit(20, 10);
  const int W = 320, H = 240;
  const CameraFrame before(app.camera(), W, H);
  const Vec3 centre = before.camera().target;                // the volume's centre, shown at the view's centre
  std::vector<std::pair<std::array<int, 2>, Vec3>> surface;  // pixel -> first visible point (index)
  for (int y = 40; y < H - 40; y += 8)
    for (int x = 60; x < W - 60; x += 8) {
      Vec3 o, d;
      before.ray(x, y, o, d);
      const StylusPick p = app.pick(o, d);
      if (p.hit) surface.push_back({{x, y}, p.surface});
    }
  ASSERT_GT(surface.size(), 40u);
  script(app, "pan 25 -15\n");
  EXPECT_EQ(app.view().panMm, (std::array<double, 2>{25, -15}));
  const CameraFrame after(app.camera(), W, H);
  double px, py, depth;
  ASSERT_TRUE(after.project(centre, px, py, depth));
  const double mmPerPixel = after.pixelSizeAt(depth);
  EXPECT_NEAR(px - W / 2.0, 25 / mmPerPixel, 1e-6) << "25 mm to the right";
  EXPECT_NEAR(py - H / 2.0, 15 / mmPerPixel, 1e-6) << "15 mm down (rows grow downwards)";
  const Geometry& g = app.geometry();
  int same = 0;
  for (const auto& [pixel, s] : surface) {
    ASSERT_TRUE(after.project(g.indexToWorld(s), px, py, depth));
    Vec3 o, d;
    after.ray(px - 0.5, py - 0.5, o, d);  // pixel centres are at +0.5
    const StylusPick p = app.pick(o, d);
    ASSERT_TRUE(p.hit) << "pixel " << pixel[0] << "," << pixel[1];
    same += (p.surface - s).norm() <= 1.0;
    // Rays grazing the skin move most (a small change of angle slides the hit along it).
    EXPECT_LE((p.surface - s).norm(), 3.0) << "pixel " << pixel[0] << "," << pixel[1];
  }
  EXPECT_GE(same, int(0.95 * double(surface.size()))) << "picks within a voxel of the point shown there";
  std::cout << "[ measured ] after the pan " << same << " of " << surface.size()
            << " picks within a voxel of the point shown there\n";
  // Kept in the session; a new volume is shown centred; out-of-range pans are refused.
  app.saveSession(path("pan.json"));
  ViewerApp b;
  b.loadSession(path("pan.json"));
  EXPECT_EQ(b.view().panMm, app.view().panMm);
  EXPECT_LT((b.camera().eye - app.camera().eye).norm(), 1e-9);
  EXPECT_THROW(b.setPan(1e6, 0), InvalidArgument);
  EXPECT_THROW(b.setPan(std::nan(""), 0), InvalidArgument);
  b.loadHeadPhantom(32);
  EXPECT_EQ(b.view().panMm, (std::array<double, 2>{0, 0}));
}

TEST_F(ViewerAppTest, EyeMatricesReproduceTheCameraRays) {
  ViewerApp app;
  app.loadHeadPhantom(32);
  app.setOrbit(37, 21);
  const Camera cam = app.camera();
  const int W = 64, H = 48;
  const CameraFrame cf(cam, W, H);
  const EyeView ev = eyeView(cam, double(W) / H);
  const Eigen::Matrix4d inv = (ev.projection * ev.view).inverse();
  for (int py : {0, 13, 47})
    for (int px : {0, 31, 63}) {
      Vec3 o, d;
      cf.ray(px, py, o, d);
      const Eigen::Vector4d a = inv * Eigen::Vector4d(2 * (px + 0.5) / W - 1, 1 - 2 * (py + 0.5) / H, -1, 1);
      const Eigen::Vector4d b = inv * Eigen::Vector4d(2 * (px + 0.5) / W - 1, 1 - 2 * (py + 0.5) / H, 1, 1);
      const Vec3 rayDir = (b.head<3>() / b.w() - a.head<3>() / a.w()).normalized();
      EXPECT_LT((rayDir - d).norm(), 1e-6) << px << "," << py;
    }
  // Stereo: the convergence point projects to the same place for both eyes, a nearer point does not.
  const double dist = (cam.target - cam.eye).norm();
  const EyeView l = eyeView(cam, 1.0, -1, 0.03 * dist, dist), r = eyeView(cam, 1.0, +1, 0.03 * dist, dist);
  auto ndc = [](const EyeView& e, const Vec3& p) {
    const Eigen::Vector4d c = e.projection * e.view * Eigen::Vector4d(p.x(), p.y(), p.z(), 1);
    return Eigen::Vector2d(c.x() / c.w(), c.y() / c.w());
  };
  EXPECT_LT((ndc(l, cam.target) - ndc(r, cam.target)).norm(), 1e-9);
  const Vec3 nearer = cam.eye + 0.5 * (cam.target - cam.eye);
  EXPECT_GT((ndc(l, nearer) - ndc(r, nearer)).norm(), 1e-3);
}

TEST_F(ViewerAppTest, BackgroundJobCancels) {
  // A job that only ends when cancelled: without a working cancel the wait times out.
  BackgroundJob job;
  std::atomic<bool> started{false};
  job.start("spin", [&](Progress& p) {
    for (;;) {
      started = true;
      p.report(0.5, "spin");
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_FALSE(job.wait(std::chrono::milliseconds(50))) << "it runs until cancelled";
  job.cancel();
  ASSERT_TRUE(job.wait(std::chrono::seconds(20))) << "cancel stops it";
  EXPECT_EQ(job.state(), BackgroundJob::State::Cancelled);

  // A trace cancelled as it starts: its first progress report stops it, with no result.
  ViewerApp app;
  app.loadHeadPhantom(96);
  app.setTool(ToolKind::Trace);
  app.trace().setCost("gradient", TubePolarity::Bright);  // the brain has no lumen for the auto cost
  app.point3({48, 48, 48});
  app.trace().setAutoTerminals(50);
  app.run(/*wait=*/false);
  app.job().cancel();
  ASSERT_TRUE(app.job().wait(std::chrono::seconds(60)));
  EXPECT_EQ(app.job().state(), BackgroundJob::State::Cancelled);
  EXPECT_FALSE(app.trace().hasResult());
  EXPECT_TRUE(app.trace().paths().empty());
  // The tool stays usable after a cancelled run.
  app.point3({20, 48, 48});
  app.trace().setAutoTerminals(0);
  app.run(/*wait=*/true);
  EXPECT_EQ(app.trace().paths().size(), 1u);
  EXPECT_TRUE(app.trace().paths()[0].reached);
  // Undo after the trace: the tree, its paths and the result go with the removed target.
  ASSERT_TRUE(app.trace().hasResult());
  ASSERT_TRUE(app.undo());
  EXPECT_FALSE(app.trace().hasResult());
  EXPECT_TRUE(app.trace().paths().empty());
  EXPECT_EQ(app.trace().tree().size(), 0u);
  EXPECT_EQ(app.trace().points().size(), 1u);
}

// The queued input events are presented in order, and no frame's share loses one: a button
// pressed and released between two frames, a double click, a key tapped twice and a burst of
// wheel notches all arrive (ImGui 1.86 sees per-frame states, so the queue splits them).
TEST(InputQueue, EveryEventReachesAFrameInOrder) {
  using K = InputEvent::Kind;
  InputQueue q;
  // A click shorter than a frame, at its own position, then a move.
  q.push({K::Move, 10, 20, 0, 0, 0, 0});
  q.push({K::Button, 0, 0, 0, 1, 0, 0});
  q.push({K::Button, 0, 0, 0, 0, 0, 0});
  q.push({K::Move, 30, 40, 0, 0, 0, 0});
  MouseState m;
  auto f0 = q.takeFrame();
  ASSERT_EQ(f0.size(), 1u) << "the move, then the press";
  for (const auto& e : f0) m.apply(e);
  EXPECT_FALSE(m.down[0]);
  auto f1 = q.takeFrame();
  ASSERT_EQ(f1.size(), 1u) << "the press ends the frame's share before its release";
  for (const auto& e : f1) m.apply(e);
  EXPECT_TRUE(m.down[0]);
  EXPECT_EQ(m.x, 10);
  auto f2 = q.takeFrame();
  ASSERT_EQ(f2.size(), 1u) << "the release, not the move after it";
  for (const auto& e : f2) m.apply(e);
  EXPECT_FALSE(m.down[0]);
  EXPECT_EQ(m.x, 10) << "released where it was pressed";
  auto f3 = q.takeFrame();
  ASSERT_EQ(f3.size(), 1u);
  EXPECT_EQ(f3[0].x, 30);
  EXPECT_TRUE(q.empty());
  // Ten wheel notches together; a move after them waits for the next frame.
  for (int i = 0; i < 10; ++i) q.push({K::Wheel, 0, 1, 0, 0, 0, 0});
  q.push({K::Move, 50, 50, 0, 0, 0, 0});
  EXPECT_EQ(q.takeFrame().size(), 10u);
  EXPECT_EQ(q.takeFrame().size(), 1u);
  // A key tapped twice: four frames (press and its repeat, release, press and its repeat, release).
  for (int i = 0; i < 2; ++i) {
    q.push({K::Key, 0, 0, 77, 1, 0, 0});
    q.push({K::Key, 0, 0, 77, 2, 0, 0});
    q.push({K::Key, 0, 0, 77, 0, 0, 0});
  }
  std::vector<size_t> shares;
  while (!q.empty()) shares.push_back(q.takeFrame().size());
  EXPECT_EQ(shares, (std::vector<size_t>{2, 1, 2, 1}));
  // A drag: the press, its moves merged into one frame (the delta is their sum) with the button
  // still down, then the release.
  q.push({K::Button, 0, 0, 0, 1, 0, 0});
  for (int i = 0; i < 20; ++i) q.push({K::Move, double(i), 0, 0, 0, 0, 0});
  q.push({K::Button, 0, 0, 0, 0, 0, 0});
  shares.clear();
  while (!q.empty()) shares.push_back(q.takeFrame().size());
  EXPECT_EQ(shares, (std::vector<size_t>{1, 20, 1}));
}

// Script `slice z=K` moves the axial view (the linked cursor) with the live-wire tool, so the
// wire is drawn on the slice shown; `pick PX,PY WxH` gives the stylus' point to the 3D tool.
TEST_F(ViewerAppTest, SliceMovesTheViewAndPickGivesTheStylusPoint) {
  ViewerApp app;
  app.loadHeadPhantom(64);
  script(app, "tool livewire\nslice z=40\n");
  EXPECT_EQ(app.view().cursor[2], 40);
  EXPECT_EQ(app.liveWire().index(), 40);
  script(app, "slice x=10\n");
  EXPECT_EQ(app.view().cursor[0], 10);
  EXPECT_EQ(app.view().cursor[2], 40);
  // The stylus through the centre of a 200x160 view hits the head and adds a trace root there.
  script(app, "tool trace\npick 100,80 200x160\n");
  ASSERT_EQ(app.trace().points().size(), 1u);
  const StylusPick p = app.stylusPick(100, 80, 200, 160);
  ASSERT_TRUE(p.hit);
  EXPECT_EQ(app.trace().points()[0], p.voxel);
  // The cut tool gets the first visible point (on its surface).
  script(app, "tool cut\npick 100,80 200x160\n");
  EXPECT_EQ(app.cut().points().size(), 1u);
  // Nothing under the stylus (a corner of the view), or no 3D tool: errors naming why.
  std::istringstream miss("pick 0,0 200x160\n");
  EXPECT_THROW(runScript(app, miss, nullptr, "t"), ScriptError);
  std::istringstream none("tool none\npick 100,80 200x160\n");
  try {
    runScript(app, none, nullptr, "t");
    FAIL() << "no 3D tool";
  } catch (const ScriptError& e) {
    EXPECT_NE(std::string(e.what()).find("takes no 3D points"), std::string::npos) << e.what();
  }
  std::istringstream noWindow("tool cut\npick 100,80\n");
  EXPECT_THROW(runScript(app, noWindow, nullptr, "t"), ScriptError);
  // A script naming a folder is an error, not an empty script.
  EXPECT_THROW(runScriptFile(app, dir.string(), nullptr), IoError);
}

// The surface tool at its defaults works on the README's head CT and planes (as `volscissors
// surface cranium.nhdr --planes 128,128,54`), and a failure names the viewer's controls.
TEST_F(ViewerAppTest, SurfaceDefaultsWorkOnTheHeadCtAndErrorsNameTheViewersControls) {
  const std::string ct = std::string(VS_SHARED_DATA_DIR) + "/head_ct_cranium_invesalius/cranium.nhdr";
  if (!fs::exists(ct)) GTEST_SKIP() << "shared data missing: " << ct;
  ViewerApp app;
  app.load(ct);
  script(app, "tool surface\nsurface-level 2\npoint 128,128,54\nrun\n");
  ASSERT_TRUE(app.surface().hasResult());
  EXPECT_GT(app.surface().mesh().triangles.size(), 10u);
  // Planes through air: no crossing; the message says what to do in the viewer.
  std::istringstream bad("point 2,2,2\nrun\n");
  try {
    runScript(app, bad, nullptr, "t");
    FAIL() << "a surface from the corner of the volume";
  } catch (const ScriptError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find("--"), std::string::npos) << m;
    EXPECT_NE(m.find("crosshair"), std::string::npos) << m;
  }
}

TEST_F(ViewerAppTest, SurfaceToolEqualsTheCoreAndUndoes) {
  ViewerApp app;
  app.loadHeadPhantom(48);
  // The default is the CLI's: one octant (SurfaceOptions{}), level 4.
  EXPECT_EQ(app.surface().closed(), SurfaceOptions{}.closed);
  EXPECT_EQ(app.surface().level(), SurfaceOptions{}.level);
  script(app, "tool surface\npoint 24,24,24\nsurface-level 2\nsurface-closed on\nrun\nsave " + path("head.obj") + "\n");
  ASSERT_TRUE(app.surface().hasResult());
  SurfaceOptions o;
  o.planes = {24, 24, 24};
  o.level = 2;
  o.closed = true;
  const SurfaceResult direct = extractSurface(app.floatVolume(), o);
  const TriMesh m = app.surface().mesh();
  ASSERT_EQ(m.triangles, direct.mesh.triangles);
  ASSERT_EQ(m.positions.size(), direct.mesh.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) EXPECT_EQ(m.positions[i], direct.mesh.positions[i]);
  EXPECT_TRUE(fs::exists(path("head.obj")));
  // A second extraction at a finer level, then undo back to the first mesh and redo.
  script(app, "surface-level 3\nrun\n");
  EXPECT_GT(app.surface().mesh().triangles.size(), m.triangles.size());
  script(app, "undo\n");
  EXPECT_EQ(app.surface().mesh().triangles, m.triangles);
  script(app, "redo\n");
  EXPECT_GT(app.surface().mesh().triangles.size(), m.triangles.size());
  // The session keeps the surface tool's settings and recomputes its mesh.
  app.saveSession(path("s.json"));
  ViewerApp b;
  b.loadSession(path("s.json"));
  EXPECT_EQ(b.surface().mesh().triangles.size(), app.surface().mesh().triangles.size());
  EXPECT_EQ(b.sessionJson(), app.sessionJson());
}

namespace {

// A head phantom written to disk and ten voxels around its nose on the skin (as the cutting
// module's test places them), for the cut tool against `volscissors cut`.
struct NoseCase {
  std::string volume;
  std::vector<Index3> points;
  std::string pointList;  // "x,y,z;x,y,z;..." for the CLI
};

NoseCase noseCase(const std::string& file) {
  HeadPhantomOptions ho;
  ho.dims = {64, 64, 48};
  ho.spacing = Vec3(2, 2, 2.5);
  const HeadPhantom ph = makeHeadPhantom(ho);
  const HeadTruth& t = ph.truth;
  const Geometry& g = ph.volume.geometry();
  NoseCase c;
  c.volume = file;
  writeVolume(AnyVolume(ph.volume), file);
  for (const Vec3& q : noseBaseLoopMm(t)) {
    const Index3 v = roundIndex(g.worldToIndex(q));
    if (c.points.empty() || c.points.back() != v) c.points.push_back(v);
  }
  for (const Index3& p : c.points) {
    if (!c.pointList.empty()) c.pointList += ';';
    c.pointList += std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]);
  }
  return c;
}

}  // namespace

TEST_F(ViewerAppTest, CutEqualsCliAndUndoes) {
  const NoseCase c = noseCase(path("head.nii.gz"));
  ASSERT_GE(c.points.size(), 6u);
  ViewerApp app;
  app.loadHeadPhantom(32);  // the CT preset ct-skin stays for the loaded head
  std::string s = "load " + c.volume + "\ntool cut\n";
  for (const Index3& p : c.points)
    s += "point " + std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]) + "\n";
  s += "run\nsave " + path("viewer_labels.nii.gz") + "\n";
  script(app, s);
  // The default iso-value is the surface the 3D view shows: half the transfer function's largest opacity.
  EXPECT_TRUE(app.cut().isoAutomatic());
  EXPECT_DOUBLE_EQ(app.cut().iso(), visibleIso(TransferFunction::preset("ct-skin", app.range())));
  char iso[64];
  std::snprintf(iso, sizeof iso, "%.17g", app.cut().iso());
  ASSERT_EQ(cli("cut " + c.volume + " --iso " + iso + " --points '" + c.pointList + "' --labels " +
                path("cli_labels.nii.gz")),
            0)
      << text(path("stderr.txt"));
  const AnyVolume viewer = readVolume(path("viewer_labels.nii.gz")), cliLabels = readVolume(path("cli_labels.nii.gz"));
  ASSERT_TRUE(std::holds_alternative<VolumeU8>(viewer));
  ASSERT_TRUE(std::holds_alternative<VolumeU8>(cliLabels));
  EXPECT_EQ(std::get<VolumeU8>(viewer).voxels(), std::get<VolumeU8>(cliLabels).voxels());
  const auto r = app.cut().result();
  ASSERT_TRUE(r);
  EXPECT_GT(r->cutVoxels, 20);
  EXPECT_GT(r->keptVoxels, 10 * r->cutVoxels);
  // The cut's parts are what the views show, in the label colours.
  ASSERT_TRUE(app.labelsFromCut());
  EXPECT_EQ(app.labels()->voxels().size(), r->labels.voxels().size());
  EXPECT_TRUE(std::equal(r->labels.voxels().begin(), r->labels.voxels().end(), app.labels()->voxels().begin()));
  // Undo the cut (the labels go), then a point; redo both.
  script(app, "undo\n");
  EXPECT_FALSE(app.cut().hasResult());
  EXPECT_FALSE(app.labels());
  script(app, "undo\n");
  EXPECT_EQ(app.cut().points().size(), c.points.size() - 1);
  script(app, "redo\nredo\n");
  EXPECT_TRUE(app.cut().hasResult());
  EXPECT_EQ(app.cut().points().size(), c.points.size());
  // The session keeps the points and recomputes the same cut.
  app.saveSession(path("s.json"));
  ViewerApp b;
  b.loadSession(path("s.json"));
  ASSERT_TRUE(b.cut().hasResult());
  EXPECT_EQ(b.cut().result()->labels.voxels(), r->labels.voxels());
  EXPECT_EQ(b.sessionJson(), app.sessionJson());
  // Fewer than 3 points: the core's message, with the script line.
  ViewerApp few;
  few.load(c.volume);
  try {
    script(few, "tool cut\npoint 10,10,10\npoint 20,20,20\nrun\n");
    FAIL() << "a cut with 2 points ran";
  } catch (const ScriptError& e) {
    EXPECT_NE(std::string(e.what()).find(":4: run"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at least 3 points"), std::string::npos) << e.what();
  }
}

// Issue 26 item 3: the preview is the contour the cut uses. With the stylus on a fourth point the
// loop runs through it (closed, on the iso-surface); with that point clicked and no hover the
// previewed loop is, vertex for vertex, the contour the cut reports; with 2 points one segment.
TEST_F(ViewerAppTest, CutPreviewIsTheLoopTheCutUses) {
  const NoseCase c = noseCase(path("head.nii.gz"));
  ViewerApp app;
  app.load(c.volume);
  app.setTool(ToolKind::Cut);
  app.setCutIso(-300.0);
  EXPECT_FALSE(app.cut().isoAutomatic());
  for (size_t i = 0; i < 2; ++i) app.point3(c.points[i]);
  EXPECT_TRUE(app.cut().liveContour(std::nullopt).path.empty()) << "no mesh yet";
  app.prepareCutContour();
  ASSERT_TRUE(app.job().wait());
  ASSERT_TRUE(app.cut().liveContourReady());
  const Geometry& g = app.geometry();
  auto world = [&](const Index3& p) { return g.indexToWorld(Vec3(double(p[0]), double(p[1]), double(p[2]))); };
  const double snapMm = app.cut().snapRadiusMm();
  const CutTool::LiveContour two = app.cut().liveContour(std::nullopt);
  EXPECT_FALSE(two.closed);
  ASSERT_FALSE(two.path.empty());
  EXPECT_LE((two.path.front() - world(c.points[0])).norm(), snapMm);
  EXPECT_LE((two.path.back() - world(c.points[1])).norm(), snapMm);
  app.point3(c.points[2]);
  const Vec3 hover(double(c.points[3][0]), double(c.points[3][1]), double(c.points[3][2]));
  const CutTool::LiveContour live = app.cut().liveContour(hover);
  ASSERT_TRUE(live.closed) << live.problem;
  EXPECT_TRUE(live.withHover);
  ASSERT_GE(live.path.size(), 4u);
  for (size_t k = 0; k < 4; ++k) {  // the loop passes each point (and the hovered one) within the snap radius
    double nearest = 1e30;
    for (const Vec3& w : live.path) nearest = std::min(nearest, (w - world(c.points[k])).norm());
    EXPECT_LE(nearest, snapMm) << "point " << k;
  }
  for (const Vec3& w : live.path) {
    const Vec3 i = g.worldToIndex(w);
    const Index3 lo{int64_t(std::floor(i.x())), int64_t(std::floor(i.y())), int64_t(std::floor(i.z()))};
    // A vertex of the iso-surface lies in a cell whose corners straddle the iso-value.
    float mn = 1e30f, mx = -1e30f;
    for (int dz = 0; dz <= 1; ++dz)
      for (int dy = 0; dy <= 1; ++dy)
        for (int dx = 0; dx <= 1; ++dx) {
          const float v = app.floatVolume()(std::min(lo[0] + dx, g.dims[0] - 1), std::min(lo[1] + dy, g.dims[1] - 1),
                                            std::min(lo[2] + dz, g.dims[2] - 1));
          mn = std::min(mn, v), mx = std::max(mx, v);
        }
    EXPECT_LE(mn, -300.f);
    EXPECT_GE(mx, -300.f);
  }
  // All the points clicked: the previewed loop (no hover) is the contour the cut reports.
  for (size_t i = 3; i < c.points.size(); ++i) app.point3(c.points[i]);
  const CutTool::LiveContour all = app.cut().liveContour(std::nullopt);
  ASSERT_TRUE(all.closed) << all.problem;
  EXPECT_FALSE(all.withHover);
  app.run(/*wait=*/true);
  const auto r = app.cut().result();
  ASSERT_TRUE(r);
  ASSERT_EQ(all.path.size(), r->contourMm.size());
  for (size_t k = 0; k < all.path.size(); ++k) EXPECT_EQ(all.path[k], r->contourMm[k]) << "vertex " << k;
  // The hovered point clicked gives the loop that was previewed with it.
  ViewerApp b;
  b.load(c.volume);
  b.setTool(ToolKind::Cut);
  b.setCutIso(-300.0);
  for (size_t i = 0; i < 4; ++i) b.point3(c.points[i]);
  b.prepareCutContour();
  ASSERT_TRUE(b.job().wait());
  EXPECT_EQ(b.cut().liveContour(std::nullopt).path, live.path);
  // Hovers, a click and undos (the core's incremental preview starts over): still cutContour's loop.
  b.cut().liveContour(Vec3(double(c.points[4][0]), double(c.points[4][1]), double(c.points[4][2])));
  b.point3(c.points[4]);
  b.cut().liveContour(std::nullopt);
  ASSERT_TRUE(b.undo());
  ASSERT_TRUE(b.undo());
  EXPECT_EQ(b.cut().liveContour(hover).path, live.path);
  // A new iso-value drops the mesh (it is rebuilt for the new surface).
  app.setCutIso(std::nullopt);
  EXPECT_FALSE(app.cut().liveContourReady());
}

TEST_F(ViewerAppTest, LabelsBlendInTheSliceViewsWithOpacityAndVisibility) {
  ViewerApp app;
  app.loadHeadPhantom(32);
  VolumeU16 labels(app.geometry(), 0);
  for (int64_t y = 0; y < 32; ++y)
    for (int64_t x = 0; x < 32; ++x) labels(x, y, 16) = x < 16 ? 1 : 7;
  writeVolume(AnyVolume(labels), path("labels.nii.gz"));
  script(app, "labels " + path("labels.nii.gz") + "\nopacity labels 0.25\nopacity overlays 0.5\nwindow 400 40\n");
  ASSERT_TRUE(app.labels());
  EXPECT_FALSE(app.labelsFromCut());
  EXPECT_DOUBLE_EQ(app.overlays().overlayOpacity, 0.5);
  const RgbaImage grey = sliceImage(app.floatVolume(), 2, 16, app.view().window);
  auto blended = [&](const RgbaImage& img) {
    int ok = 0;
    for (int64_t y = 0; y < 32; ++y)
      for (int64_t x = 0; x < 32; ++x) {
        const auto lc = labelColor(x < 16 ? 1 : 7);
        const uint8_t* g = grey.at(int(x), int(y));
        const uint8_t* p = img.at(int(x), int(y));
        bool same = true;
        for (int k = 0; k < 3; ++k)
          same = same && std::abs(int(p[k]) - int(std::lrint(255 * (0.75 * g[k] / 255.0 + 0.25 * lc[size_t(k)])))) <= 1;
        ok += same;
      }
    return ok;
  };
  const RgbaImage shown = sliceImage(app.floatVolume(), 2, 16, app.view().window, app.labels().get(), app.overlays());
  EXPECT_EQ(blended(shown), 32 * 32) << "every labelled pixel is grey * 0.75 + colour * 0.25";
  // Label 7 hidden: its half is plain grey, label 1's half stays blended.
  script(app, "label 7 off\n");
  const RgbaImage half = sliceImage(app.floatVolume(), 2, 16, app.view().window, app.labels().get(), app.overlays());
  EXPECT_EQ(blended(half), 16 * 32);
  EXPECT_EQ(std::vector<uint8_t>(half.at(20, 5), half.at(20, 5) + 3),
            std::vector<uint8_t>(grey.at(20, 5), grey.at(20, 5) + 3));
  // A slice without labels is unchanged.
  EXPECT_EQ(sliceImage(app.floatVolume(), 2, 3, app.view().window, app.labels().get(), app.overlays()).pixels,
            sliceImage(app.floatVolume(), 2, 3, app.view().window).pixels);
  // Bad label maps are refused with the file's name; the labels shown stay.
  Geometry smallGeometry;
  smallGeometry.dims = {16, 16, 16};
  VolumeU16 small(smallGeometry, 1);
  writeVolume(AnyVolume(small), path("small.nii.gz"));
  EXPECT_THROW(app.loadLabels(path("small.nii.gz")), DataError);
  VolumeF32 fractional(app.geometry(), 0.5f);
  writeVolume(AnyVolume(fractional), path("frac.nii.gz"));
  try {
    app.loadLabels(path("frac.nii.gz"));
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("frac.nii.gz"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(app.labels());
  EXPECT_THROW(script(app, "opacity labels 1.5\n"), ScriptError);
  // The session keeps the label map, the opacities and the hidden labels.
  app.saveSession(path("s.json"));
  ViewerApp b;
  b.loadSession(path("s.json"));
  EXPECT_EQ(b.sessionJson(), app.sessionJson());
  EXPECT_EQ(b.labels()->voxels(), app.labels()->voxels());
}

TEST_F(ViewerAppTest, ZoomAndPanKeepPickingOnTheVoxelShown) {
  ViewerApp app;
  app.loadHeadPhantom(48);
  for (int axis = 0; axis < 3; ++axis) {
    const SliceLayout L = sliceLayout(app.geometry(), axis, 20);
    for (const double zoom : {1.0, 2.5, 7.0})
      for (const std::array<double, 2> pan : {std::array<double, 2>{0, 0}, {0.3, -0.2}}) {
        const SliceFit f = fitSlice(L, 300, 220, zoom, pan);
        // Every pixel centre shown in the view picks that pixel back.
        for (int64_t v = 0; v < L.height; v += 3)
          for (int64_t u = 0; u < L.width; u += 3) {
            const auto p = f.viewOf(double(u), double(v));
            if (p[0] < 0 || p[1] < 0 || p[0] >= 300 || p[1] >= 220) continue;
            const auto picked = f.pickAt(p[0], p[1]);
            ASSERT_TRUE(picked);
            EXPECT_EQ(*picked, (PixelUV{u, v})) << "axis " << axis << " zoom " << zoom;
          }
      }
    // Wheel zoom about the mouse keeps the pixel under it; a drag moves the image with the mouse.
    const SliceFit f = fitSlice(L, 300, 220, 1.5, {0.1, 0.05});
    const double mx = 200, my = 70;
    const auto before = f.pickAt(mx, my);
    ASSERT_TRUE(before);
    const SliceFit zoomed = fitSlice(L, 300, 220, 6, f.panForZoomAbout(mx, my, 6));
    EXPECT_EQ(zoomed.pickAt(mx, my), before);
    const SliceFit dragged = fitSlice(L, 300, 220, 1.5, f.panAfterDrag(40, -25));
    EXPECT_EQ(dragged.pickAt(mx + 40, my - 25), before);
  }
  // A known case: the axial view's centre at zoom 4 shows the slice's centre voxel; panned by half
  // a quarter of the fitted image to the right, the view centre shows the voxel a quarter of the way across.
  const SliceLayout L = sliceLayout(app.geometry(), 2, 10);
  const SliceFit z4 = fitSlice(L, 200, 200, 4, {0, 0});
  const auto c = z4.pickAt(100.2, 100.2);
  ASSERT_TRUE(c);
  EXPECT_NEAR(double((*c)[0]), double(L.width) / 2, 1.0);
  EXPECT_NEAR(double((*c)[1]), double(L.height) / 2, 1.0);
  const SliceFit panned = fitSlice(L, 200, 200, 1, {0.25, 0});
  const auto q = panned.pickAt(100.2, 100.2);
  ASSERT_TRUE(q);
  EXPECT_NEAR(double((*q)[0]), L.flipU ? 3.0 * double(L.width) / 4 : double(L.width) / 4, 1.0);
  EXPECT_FALSE(panned.pickAt(5, 100)) << "left of the panned image: nothing to pick";
  // The zoom and pan are part of the session; out-of-range zoom is refused.
  app.setSliceView(1, 3, {0.2, -0.1});
  EXPECT_THROW(app.setSliceView(1, 100, {0, 0}), InvalidArgument);
  app.saveSession(path("s.json"));
  ViewerApp b;
  b.loadSession(path("s.json"));
  EXPECT_EQ(b.view().sliceZoom, app.view().sliceZoom);
  EXPECT_EQ(b.view().slicePan, app.view().slicePan);
}

TEST_F(ViewerAppTest, TransferFunctionEdits) {
  ViewerApp app;
  app.loadHeadPhantom(32);
  TfEditor ed(TransferFunction({{0, {1, 0, 0}, 0.0}, {100, {0, 0, 1}, 1.0}}));
  // A new point takes the curve's colour at its value and keeps the order.
  const size_t i = ed.add(25, 0.8);
  ASSERT_EQ(i, 1u);
  ASSERT_EQ(ed.size(), 3u);
  EXPECT_NEAR(ed.point(1).color[0], 0.75, 1e-6);
  EXPECT_NEAR(ed.point(1).color[2], 0.25, 1e-6);
  EXPECT_DOUBLE_EQ(ed.point(1).opacity, 0.8);
  // Dragging past a neighbour stops just before it; the opacity stays within [0, 1].
  const TfPoint& moved = ed.move(1, 500, 1.7);
  EXPECT_LT(moved.value, 100);
  EXPECT_GT(moved.value, 99.99);
  EXPECT_DOUBLE_EQ(moved.opacity, 1.0);
  EXPECT_EQ(ed.size(), 3u);
  ed.move(1, 50, 0.5);
  EXPECT_EQ(ed.tf().evaluate(50).a, 0.5f);
  EXPECT_EQ(ed.nearest(49, 0.52, 100, 0.05), std::optional<size_t>(1));
  EXPECT_FALSE(ed.nearest(20, 0.9, 100, 0.05));
  ed.setColour(1, {0, 1, 0});
  EXPECT_EQ(ed.tf().evaluate(50).g, 1.0f);
  EXPECT_THROW(ed.setColour(1, {0, 2, 0}), InvalidArgument);
  ed.remove(0);
  EXPECT_EQ(ed.size(), 2u);
  EXPECT_THROW(ed.remove(0), InvalidArgument) << "a curve keeps two points";
  // The edited function goes to the views, is saved in the renderer's format and read back by `tf FILE`.
  app.setEditedTransferFunction(ed.tf());
  EXPECT_EQ(app.view().tf, "edited");
  EXPECT_DOUBLE_EQ(app.cut().iso(), visibleIso(ed.tf())) << "the cut's automatic iso follows the curve";
  script(app, "tf-save " + path("tf.json") + "\n");
  const TransferFunction read = TransferFunction::fromJson(text(path("tf.json")), "tf.json");
  ASSERT_EQ(read.points().size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_DOUBLE_EQ(read.points()[k].value, ed.point(k).value);
    EXPECT_DOUBLE_EQ(read.points()[k].opacity, ed.point(k).opacity);
    EXPECT_EQ(read.points()[k].color, ed.point(k).color);
  }
  ViewerApp other;
  other.loadHeadPhantom(32);
  script(other, "tf " + path("tf.json") + "\n");
  EXPECT_EQ(other.transferFunction().toJson(), ed.tf().toJson());
  // The session keeps the edited curve.
  app.saveSession(path("s.json"));
  ViewerApp b;
  b.loadSession(path("s.json"));
  EXPECT_EQ(b.transferFunction().toJson(), ed.tf().toJson());
  EXPECT_EQ(b.sessionJson(), app.sessionJson());
  // The histogram: log counts scaled to 1 at the fullest bin.
  Geometry g;
  g.dims = {10, 1, 1};
  VolumeF32 v(g, 0.f);
  for (int64_t x = 0; x < 3; ++x) v(x, 0, 0) = 9.f;
  const std::vector<double> h = logHistogram(v, 0, 10, 10);
  EXPECT_DOUBLE_EQ(h[0], 1.0);
  EXPECT_NEAR(h[9], std::log1p(3.0) / std::log1p(7.0), 1e-12);
  EXPECT_DOUBLE_EQ(h[5], 0.0);
}

TEST_F(ViewerAppTest, OverlayFilesLoadAndStayInTheSession) {
  ViewerApp app;
  app.loadHeadPhantom(32);
  TriMesh tet;
  tet.positions = {{0, 0, 0}, {20, 0, 0}, {0, 20, 0}, {0, 0, 20}};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  writeTriMesh(tet, path("tet.ply"));
  Tree tree;
  tree.points = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {10, 0, 10}};
  tree.parent = {-1, 0, 1, 1};
  tree.radii = {1, 1, 1, 1};
  tree.types = {1, 3, 3, 3};
  writeTree(tree, path("tree.swc"));
  Polyline loop;
  loop.points = {{0, 0, 5}, {5, 0, 5}, {5, 5, 5}};
  loop.closed = true;
  writePolylines({loop}, path("loop.json"));
  script(app, "overlay " + path("tet.ply") + "\noverlay " + path("tree.swc") + "\noverlay " + path("loop.json") + "\n");
  const auto& o = app.loadedOverlays();
  ASSERT_EQ(o.size(), 3u);
  EXPECT_EQ(o[0].mesh.triangles.size(), 4u);
  EXPECT_TRUE(o[0].lines.empty());
  EXPECT_EQ(o[1].lines.size(), 3u) << "root -> branch point, and its two branches";
  ASSERT_EQ(o[2].lines.size(), 1u);
  EXPECT_TRUE(o[2].lines[0].closed);
  // A file of another kind, or a missing one: an error naming it; the overlays stay.
  std::ofstream(path("notes.txt")) << "hello";
  try {
    script(app, "overlay " + path("notes.txt") + "\n");
    FAIL();
  } catch (const ScriptError& e) {
    EXPECT_NE(std::string(e.what()).find("notes.txt"), std::string::npos) << e.what();
  }
  EXPECT_THROW(script(app, "overlay " + path("missing.ply") + "\n"), ScriptError);
  EXPECT_EQ(app.loadedOverlays().size(), 3u);
  app.saveSession(path("s.json"));
  ViewerApp b;
  b.loadSession(path("s.json"));
  ASSERT_EQ(b.loadedOverlays().size(), 3u);
  EXPECT_EQ(b.loadedOverlays()[1].lines.size(), o[1].lines.size());
  EXPECT_EQ(b.sessionJson(), app.sessionJson());
  script(app, "overlay clear\n");
  EXPECT_TRUE(app.loadedOverlays().empty());
  // The live-wire's own contour JSON (what `save` writes for the live-wire tool) is an overlay:
  // a closed polyline on its slice, in world mm.
  script(app, "tool livewire\nslice z=16\npoint 8,16\npoint 16,8\npoint 24,16\nclose\nsave " + path("wire.json") +
                  "\noverlay " + path("wire.json") + "\n");
  ASSERT_EQ(app.loadedOverlays().size(), 1u);
  ASSERT_EQ(app.loadedOverlays()[0].lines.size(), 1u);
  const Polyline& wire = app.loadedOverlays()[0].lines[0];
  EXPECT_TRUE(wire.closed);
  EXPECT_EQ(wire.points.size(), app.liveWire().contour().pixels.size());
  for (const Vec3& q : wire.points) EXPECT_NEAR(app.geometry().worldToIndex(q).z(), 16, 1e-6);
}

// The 3D view without OpenGL 3.3 (app/cpu_view.h): its settled frame is the CPU renderer's
// picture (`volscissors render`'s renderer, set up here by hand) of what the app shows, pixel for
// pixel, in the full and triplanar modes (the cursor's planes); the newest of a burst of
// requests is the one drawn; a worker busy with a frame is stopped when the view goes.
TEST_F(ViewerAppTest, CpuViewDrawsTheAppsViewOffTheUiThread) {
  ViewerApp app;
  app.loadHeadPhantom(64);
  app.setOrbit(40, 15);
  app.setPan(10, 5);
  const std::array<float, 3> background{0.08f, 0.08f, 0.1f};
  const int W = 200, H = 150;
  CpuView view;
  auto settle = [&] {
    while (!view.settled()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  };
  Renderer reference(app.volume());
  reference.setTransferFunction(app.transferFunction());
  RenderOptions o;
  o.window = app.view().window;
  o.background = background;
  auto expectSame = [&](const char* what) {
    settle();
    EXPECT_EQ(view.error(), "") << what;
    const auto f = view.newest();
    ASSERT_TRUE(f) << what;
    EXPECT_FALSE(f->preview) << what;
    EXPECT_EQ(f->serial, view.lastRequest()) << what;
    reference.setOptions(o);
    const RgbaImage ref = reference.render(app.camera(), W, H).image;
    ASSERT_EQ(f->image.width, W);
    ASSERT_EQ(f->image.height, H);
    EXPECT_EQ(f->image.pixels, ref.pixels) << what;
  };
  ASSERT_TRUE(view.request(cpuFrameRequest(app, W, H, background)));
  EXPECT_FALSE(view.request(cpuFrameRequest(app, W, H, background))) << "the same view is not drawn again";
  expectSame("full");
  for (int az = 0; az < 100; az += 10) {  // a drag: one request per UI frame, none waited for
    app.setOrbit(az, 25);
    view.request(cpuFrameRequest(app, W, H, background));
  }
  expectSame("the last of a burst");
  app.setMode(RenderMode::Triplanar);
  app.setCursor({20, 40, 30});
  o.mode = RenderMode::Triplanar;
  o.planes = Vec3(20, 40, 30);
  view.request(cpuFrameRequest(app, W, H, background));
  expectSame("triplanar");
  // Labels at their opacity; a hidden label loses its colour (the CPU renderer cannot skip voxels).
  VolumeU16 labels(app.geometry(), 0);
  for (int64_t z = 0; z < 64; ++z)
    for (int64_t y = 0; y < 64; ++y)
      for (int64_t x = 0; x < 64; ++x) labels(x, y, z) = x < 32 ? 1 : 2;
  writeVolume(AnyVolume(labels), path("cpu_labels.nii.gz"));
  script(app, "labels " + path("cpu_labels.nii.gz") + "\nopacity labels 0.6\n");
  o.labelOpacity = 0.6;
  reference.setLabels(AnyVolume(labels));
  view.request(cpuFrameRequest(app, W, H, background));
  expectSame("labels");
  const auto coloured = view.newest();
  app.setLabelVisible(2, false);
  for (uint16_t& l : labels.voxels()) l = l == 2 ? 0 : l;
  reference.setLabels(AnyVolume(labels));
  view.request(cpuFrameRequest(app, W, H, background));
  expectSame("label 2 hidden");
  EXPECT_NE(view.newest()->image.pixels, coloured->image.pixels);
  CpuView leaving;
  leaving.request(cpuFrameRequest(app, 640, 480, background));
}

#ifdef VS_HAVE_VIEWER
// `view --help` documents the renderer choice with its default and the `pan` script command.
TEST_F(ViewerAppTest, HelpListsTheRendererAndPan) {
  ASSERT_EQ(cli("view --help"), 0) << text(path("stderr.txt"));
  const std::string help = text(path("stdout.txt"));
  EXPECT_NE(help.find("--renderer TEXT:{auto,gpu,cpu}=auto"), std::string::npos) << help;
  EXPECT_NE(help.find(", pan"), std::string::npos) << help;
}
#endif

// Orientation: a file with none in its header warns; a stated code sets the direction and stays
// in the session.
TEST_F(ViewerAppTest, OrientationStatedForAFileWithoutOne) {
  {
    std::ofstream raw(path("v.raw"), std::ios::binary);
    const std::vector<int16_t> v(8 * 8 * 8, 5);
    raw.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * 2));
    std::ofstream(path("v.nhdr")) << "NRRD0004\ntype: int16\ndimension: 3\nsizes: 8 8 8\nspacings: 1 1 1\n"
                                     "endian: little\nencoding: raw\ndata file: v.raw\n";
  }
  ViewerApp app;
  app.load(path("v.nhdr"));
  EXPECT_NE(app.orientationWarning().find("states no orientation"), std::string::npos);
  EXPECT_TRUE(app.geometry().direction.isApprox(Mat3::Identity()));
  app.load(path("v.nhdr"), "LAS");
  EXPECT_TRUE(app.orientationWarning().empty());
  EXPECT_TRUE(app.geometry().direction.isApprox(Eigen::Vector3d(1, -1, 1).asDiagonal().toDenseMatrix()));
  app.saveSession(path("s.json"));
  ViewerApp b;
  b.loadSession(path("s.json"));
  EXPECT_EQ(b.orientationOverride(), "LAS");
  EXPECT_TRUE(b.geometry().direction.isApprox(app.geometry().direction));
  EXPECT_THROW(app.load(path("v.nhdr"), "LPX"), InvalidArgument);
  EXPECT_EQ(app.orientationOverride(), "LAS") << "a bad code keeps the volume";
}
