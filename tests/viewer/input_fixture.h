// The fixture of the window tests driven by real X input events (xdotool's XTEST events into a
// private Xvfb): the viewer started as its own process with a script that hands the window to the
// events (`interact F12`), waits for files and the exit status, and xdotool on the viewer's window.
// Skips with a message where Xvfb or xdotool is missing.
#pragma once
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

#include "app/slice_layout.h"
#include "viewer_test_util.h"
#include "xserver.h"

namespace vs::viewer::testing {

namespace fs = std::filesystem;

constexpr int kW = 980, kH = 640;  // --size; panel 340 px, then 2x2 views of 320 x 320

class InputFixture : public ::testing::Test {
 protected:
  fs::path dir;
  std::unique_ptr<XServer> xserver;
  pid_t viewer = -1;

  void SetUp() override {
    if (std::system("command -v xdotool > /dev/null 2>&1") != 0)
      GTEST_SKIP() << "xdotool is not installed (scripts/install-deps.sh installs it)";
    dir = fs::temp_directory_path() / ("vs_viewer_input_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    xserver = std::make_unique<XServer>(dir, 1280, 800);
    if (!xserver->ok()) GTEST_SKIP() << "no X server: " << xserver->why();
  }
  void TearDown() override {
    if (viewer > 0) {
      ::kill(viewer, SIGKILL);
      ::waitpid(viewer, nullptr, 0);
    }
    xserver.reset();
    if (!dir.empty()) fs::remove_all(dir);
  }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  std::string err() const {
    std::ifstream f(path("err.txt"));
    return {std::istreambuf_iterator<char>(f), {}};
  }

  // Starts the viewer (its own process, so that the test can signal it) with the script.
  void start(const std::string& script, const std::string& options = "--renderer gpu") {
    std::ofstream(path("script.txt")) << script;
    const std::string cmd = "exec env " + xserver->env() + " " + std::string(VS_CLI_PATH) + " view --size " +
                            std::to_string(kW) + "x" + std::to_string(kH) + " " + options + " --script " +
                            path("script.txt") + " > " + path("out.txt") + " 2> " + path("err.txt");
    viewer = ::fork();
    if (viewer == 0) {
      ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
  }
  // Waits for a file the script writes (the window is up and drawn); false after `seconds`.
  bool waitFor(const std::string& file, double seconds = 120) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (fs::exists(file)) return true;
      int status = 0;
      if (::waitpid(viewer, &status, WNOHANG) == viewer) {
        viewer = -1;
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  // The viewer's own exit status, or -1 if it did not exit within `seconds`.
  int waitExit(double seconds = 60) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      int status = 0;
      if (::waitpid(viewer, &status, WNOHANG) == viewer) {
        viewer = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return -1;
  }
  // xdotool commands on the viewer's window (coordinates relative to it).
  int xdo(const std::string& commands) const {
    const std::string cmd = "env " + xserver->env() + " xdotool search --sync --name 'volscissors view' " + commands +
                            " > /dev/null 2>> " + path("xdo.txt");
    return std::system(cmd.c_str());
  }
  nlohmann::json session(const std::string& file) const {
    std::ifstream f(file);
    return nlohmann::json::parse(f);
  }
};

// Screen position (window pixels) of slice pixel p on the axial view (top right) of the default
// layout: the view's content starts below ImGui's title bar (19 px) and inside its padding (8 px).
struct AxialScreen {
  SliceFit fit;
  AxialScreen(const Geometry& g, int64_t z) {
    const int cell = (kW - 340) / 2, cellH = kH / 2;
    fit = fitSlice(sliceLayout(g, 2, z), cell - 16, cellH - 27 - 8);
  }
  std::array<int, 2> operator()(PixelUV p) const {
    const auto q = fit.viewOf(double(p[0]), double(p[1]));
    return {int(std::lround(340 + (kW - 340) / 2 + 8 + q[0])), int(std::lround(27 + q[1]))};
  }
  std::string move(PixelUV p) const {
    const auto s = (*this)(p);
    return " mousemove --window %1 " + std::to_string(s[0]) + " " + std::to_string(s[1]);
  }
};

// The input tests of tests/viewer/input_test.cpp and the stereo/cut tests share this name.
class ViewerInputTest : public InputFixture {};

}  // namespace vs::viewer::testing
