// The monoplanar mode's plane chosen by script (`mono-plane x|y|z[=K]`), GL-free: the axis and the
// plane's index (the linked cursor it goes through), errors that leave both unchanged, and the
// session that keeps them. The window's handle and key are tested in plane_window_test.cpp.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>

#include "app/script.h"
#include "app/viewer_app.h"

namespace fs = std::filesystem;
using namespace vs;
using namespace vs::viewer;

TEST(MonoPlane, ScriptChoosesTheAxisAndTheIndex) {
  ViewerApp app;
  app.loadHeadPhantom(48);
  auto run = [&](const std::string& s) {
    std::istringstream in(s);
    runScript(app, in, nullptr, "test");
  };
  run("planes 10,20,30\nmode monoplanar\nmono-plane x=40\n");
  EXPECT_EQ(app.view().monoAxis, 0);
  EXPECT_EQ(app.view().cursor, (Index3{40, 20, 30}));
  run("mono-plane y\n");
  EXPECT_EQ(app.view().monoAxis, 1);
  EXPECT_EQ(app.view().cursor, (Index3{40, 20, 30})) << "no index: the plane stays through the cursor";
  for (const char* bad : {"mono-plane w\n", "mono-plane x40\n", "mono-plane z=48\n", "mono-plane z=1.5\n"}) {
    EXPECT_THROW(run(bad), ScriptError) << bad;
    EXPECT_EQ(app.view().monoAxis, 1) << bad;
    EXPECT_EQ(app.view().cursor, (Index3{40, 20, 30})) << bad;
  }
  const fs::path file = fs::temp_directory_path() / ("vs_mono_" + std::to_string(::getpid()) + ".json");
  app.saveSession(file.string());
  ViewerApp b;
  b.loadSession(file.string());
  fs::remove(file);
  EXPECT_EQ(b.view().monoAxis, 1);
  EXPECT_EQ(b.view().cursor, (Index3{40, 20, 30}));
}
