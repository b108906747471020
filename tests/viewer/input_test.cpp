// The window driven by real X input events (xdotool's XTEST events into a private Xvfb), not by
// script commands: a short click registers, ten wheel notches move ten slices, a drag rotates,
// two key taps are two actions, and one Ctrl-C (SIGINT) or SIGTERM closes an idle viewer. The
// script hands the window to the events with `interact F12` and reads the state back after F12
// (events are processed in order, so everything sent before F12 has been). Skips with a message
// where Xvfb or xdotool is missing.
#ifdef VS_HAVE_VIEWER
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "input_fixture.h"
#include "viewer_test_util.h"

namespace fs = std::filesystem;

namespace {
class ViewerInputTest : public vs::viewer::testing::InputFixture {};
using vs::viewer::testing::kW;
}  // namespace

TEST_F(ViewerInputTest, ClicksWheelNotchesDragAndKeysAllCount) {
  start("tool none\nplanes 64,64,64\nscreenshot " + path("ready.png") + "\nsession-save " + path("before.json") +
        "\ninteract F12\nsession-save " + path("after.json") + "\nquit\n");
  ASSERT_TRUE(waitFor(path("before.json"))) << err();
  const nlohmann::json before = session(path("before.json"));
  // A click (press and release at once: shorter than any frame) on the axial view (top right).
  ASSERT_EQ(xdo("windowfocus --sync %1 mousemove --window %1 780 130 click 1"), 0);
  // Ten wheel notches over the axial view, 10 ms apart (many within one frame).
  ASSERT_EQ(xdo("mousemove --window %1 820 200 click --repeat 10 --delay 10 4"), 0);
  // A drag of 100 px to the right in the 3D view (top left), in 10 px steps.
  std::string drag = "mousemove --window %1 450 160 mousedown 1";
  for (int dx = 10; dx <= 100; dx += 10) drag += " mousemove --window %1 " + std::to_string(450 + dx) + " 160";
  ASSERT_EQ(xdo(drag + " mouseup 1"), 0);
  // Two taps of `m` (next render mode) in quick succession, then the script's key.
  ASSERT_EQ(xdo("mousemove --window %1 820 500 key --delay 5 m m F12"), 0);
  ASSERT_EQ(waitExit(), 0) << err();
  const nlohmann::json after = session(path("after.json"));
  const auto c0 = before["view"]["cursor"], c1 = after["view"]["cursor"];
  // The click moved the crosshair in x and y to the clicked voxel (the axial slice of 128 mm fills
  // about 285 px from x = 677, y = 27: about (46, 46)).
  EXPECT_NEAR(c1[0].get<double>(), 46, 5) << c1;
  EXPECT_NEAR(c1[1].get<double>(), 46, 5) << c1;
  // Ten notches, ten slices.
  EXPECT_EQ(c1[2].get<int>() - c0[2].get<int>(), 10) << c0 << " -> " << c1;
  // The drag turned the view by 0.4 degrees a pixel, less what ImGui's drag threshold keeps.
  const double turned = after["view"]["azimuth_deg"].get<double>() - before["view"]["azimuth_deg"].get<double>();
  EXPECT_LT(turned, -30) << "the drag rotated by " << turned << " degrees";
  EXPECT_GT(turned, -42);
  // Two taps, two modes on: full -> cut box -> triplanar.
  EXPECT_EQ(after["view"]["mode"], "triplanar") << after["view"]["mode"];
  std::cout << "[ measured ] cursor " << c0 << " -> " << c1 << ", azimuth turned " << turned << " deg\n";
}

TEST_F(ViewerInputTest, OneInterruptClosesAnIdleViewer) {
  for (const int sig : {SIGINT, SIGTERM}) {
    fs::remove(path("ready.png"));
    start("screenshot " + path("ready.png") + "\ninteract F12\nquit\n");
    ASSERT_TRUE(waitFor(path("ready.png"))) << err();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // idle: waiting for events
    ::kill(viewer, sig);
    const int rc = waitExit(20);
    EXPECT_EQ(rc, 130) << "signal " << sig << ": " << err();
    EXPECT_NE(err().find("closed (interrupted)"), std::string::npos) << err();
  }
}

// A script that ends without `quit` leaves the window open (for the user), says so, and one
// SIGTERM (what `timeout` sends) closes it.
TEST_F(ViewerInputTest, ScriptWithoutQuitStaysOpenUntilTerminated) {
  start("screenshot " + path("ready.png") + "\n");
  ASSERT_TRUE(waitFor(path("ready.png"))) << err();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(waitExit(0.1), -1) << "the window stays open";
  EXPECT_NE(err().find("ended without `quit`"), std::string::npos) << err();
  ::kill(viewer, SIGTERM);
  EXPECT_EQ(waitExit(20), 130) << err();
}
#endif
