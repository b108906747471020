#include "window/viewer_window.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl2.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <set>
#include <thread>
#include <utility>

#include "app/cpu_view.h"
#include "app/input_queue.h"
#include "app/script.h"
#include "app/slice_layout.h"
#include "app/tf_editor.h"
#include "gl/gl.h"
#include "gl/raycaster.h"
#include "io/png_io.h"
#include "render/slice_render.h"
#include "render/window_level.h"
#include "util/atomic_file.h"
#include "util/cancel.h"
#include "util/error.h"
#include "window/profile_panel.h"

namespace vs::viewer {

namespace {

constexpr float kPanelWidth = 340;
constexpr std::array<float, 3> kViewBackground{0.08f, 0.08f, 0.1f};  // planes of air stay visible against it
const ImVec4 kNoteColour(1, 0.7f, 0.3f, 1);
std::string gGlfwError;

void glfwError(int, const char* message) { gGlfwError = message; }

ImU32 rgb(int r, int g, int b, int a = 255) { return IM_COL32(r, g, b, a); }

// A drawn result (contour, tree, mesh, cut) at the overlay opacity.
ImU32 overlayColour(const OverlaySettings& o, int r, int g, int b, int a = 255) {
  return IM_COL32(r, g, b, int(std::lround(a * o.overlayOpacity)));
}

// A colour texture plus a framebuffer that renders into it (the 3D view).
struct RenderTarget {
  GLuint fbo = 0, tex = 0;
  int w = 0, h = 0;
  void ensure(int width, int height) {
    if (width == w && height == h && fbo) return;
    if (!fbo) {
      glGenFramebuffers(1, &fbo);
      glGenTextures(1, &tex);
    }
    w = width;
    h = height;
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  ~RenderTarget() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (tex) glDeleteTextures(1, &tex);
  }
};

struct SliceTexture {
  GLuint tex = 0;
  uint64_t revision = 0, labelsRevision = 0;
  int64_t index = -1;
  double window = 0, level = 0, labelOpacity = -1;
  std::set<int> hidden;
};

const char* kHelp =
    "Slice views\n"
    "  wheel         next/previous slice\n"
    "  ctrl+wheel    zoom about the mouse\n"
    "  middle drag   pan (r resets)\n"
    "  left click    crosshair, or tool point\n"
    "  double click  close the contour\n"
    "  shift+move    crosshair follows mouse\n"
    "  right drag    window / level\n"
    "3D view\n"
    "  left drag     rotate\n"
    "  middle drag   pan (or shift+left drag)\n"
    "  wheel         zoom (or right drag)\n"
    "  hover         stylus (sphere = pick)\n"
    "  left click    3D tool point at the pick\n"
    "Keys\n"
    "  1 live-wire 2 trace 3 surface 4 cut 0 none\n"
    "  z, Ctrl+Z undo  y, Ctrl+Shift+Z redo\n"
    "  c close  Enter run trace/surface/cut\n"
    "  PgUp/PgDn axial slice  m mode\n"
    "  s stereo  r reset view  h help\n";

class ViewerWindow : public ScriptHost {
 public:
  // raycaster null: the CPU renderer draws the 3D view, cpuNote says why. legacy: a legacy
  // context (ImGui's OpenGL 2 backend). measure: software OpenGL (llvmpipe, softpipe, swrast)
  // was found, so the first frames of both renderers are timed and the faster one kept.
  ViewerWindow(ViewerApp& app, GLFWwindow* window, std::unique_ptr<GpuRayCaster> raycaster, std::string cpuNote,
               bool legacy, bool measure, std::string glRenderer)
      : app_(app),
        window_(window),
        raycaster_(std::move(raycaster)),
        cpuNote_(std::move(cpuNote)),
        legacy_(legacy),
        measuring_(measure && raycaster_),
        glRenderer_(std::move(glRenderer)) {
    glGenTextures(3, sliceTexIds_);
    for (int a = 0; a < 3; ++a) slices_[a].tex = sliceTexIds_[a];
    glGenTextures(1, &cpuTex_);
    const uint8_t background[4] = {uint8_t(255 * kViewBackground[0]), uint8_t(255 * kViewBackground[1]),
                                   uint8_t(255 * kViewBackground[2]), 255};
    uploadTexture(cpuTex_, 1, 1, background, GL_LINEAR);
    if (raycaster_) {
      GLboolean stereo = GL_FALSE;
      glGetBooleanv(GL_STEREO, &stereo);
      quadBuffer_ = stereo == GL_TRUE;
      rendererNote_ = "3D: GPU ray caster (" + glRenderer_ + ")";
    } else {
      startCpuView();
      rendererNote_ = cpuNote_;
    }
    installCallbacks();
    loadRecent();
    if (const char* log = std::getenv("VS_VIEWER_FRAME_LOG"); log && *log)
      frameLog_ = std::make_unique<std::ofstream>(log);
    std::snprintf(loadPath_, sizeof loadPath_, "%s", "");
    std::snprintf(savePath_, sizeof savePath_, "%s", "contour.json");
    std::snprintf(sessionPath_, sizeof sessionPath_, "%s", "session.json");
    std::snprintf(labelsPath_, sizeof labelsPath_, "%s", "");
    std::snprintf(tfPath_, sizeof tfPath_, "%s", "tf.json");
    std::snprintf(overlayPath_, sizeof overlayPath_, "%s", "");
  }
  void startCpuView() {
    cpuView_ = std::make_unique<CpuView>();
    cpuView_->setOnFrame([this] {
      cpuFrameReady_ = true;
      glfwPostEmptyEvent();  // wakes glfwWaitEventsTimeout (thread-safe)
    });
  }

  ~ViewerWindow() override {
    cpuView_.reset();  // its worker's callback touches this window
    glDeleteTextures(3, sliceTexIds_);
    if (cpuTex_) glDeleteTextures(1, &cpuTex_);
  }

  // A single Ctrl-C or SIGTERM (cli/signals: the process-wide cancel) closes the window.
  bool quitRequested() const { return quit_ || glfwWindowShouldClose(window_) || globalCancelRequested(); }

  // A script's frame after each command: the views at full resolution, and an interrupt stops it.
  void frame() override {
    drawFrame();
    if (globalCancelRequested()) throw Cancelled();
  }

  // The interactive loop: sleeps in glfwWaitEventsTimeout until something needs a new picture
  // (an input event, a finished CPU frame, a running job's progress, the full-resolution frame
  // after a preview); every queued input event is presented, in order.
  void runEventLoop() {
    interactive_ = true;
    while (!quitRequested() && !stopKeySeen_) {
      if (queue_.empty() && redraw_ <= 0) {
        glfwWaitEventsTimeout(waitSeconds());
        if (!queue_.empty()) redraw_ = kFramesAfterInput;
        if (cpuFrameReady_.exchange(false) || busy() || wasBusy_ || refineDue()) redraw_ = std::max(redraw_, 1);
        if (redraw_ <= 0) continue;
      }
      drawFrame();
      --redraw_;
      ++framesDrawn_;
    }
  }

  uint64_t framesDrawn() const { return framesDrawn_; }

  void screenshot(const std::string& path) override {
    const std::string ext = std::filesystem::path(path).extension().string();
    if (ext != ".png" && ext != ".PNG")
      throw UsageError("screenshot " + path + ": the picture is written as PNG; name it .png");
    settleCpuView();
    // Two frames: ImGui lays windows out on the first one it sees them.
    frame();
    glfwPollEvents();
    draw();
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    glReadBuffer(GL_BACK);
    const RgbaImage img = readFramebuffer(0, 0, w, h);
    glfwSwapBuffers(window_);
    writePng(img, path);
  }

  // The CPU renderer's full-resolution frame of what the window shows now (a script's
  // screenshot waits for it; the mouse never does).
  void settleCpuView() {
    if (!cpuView_) return;
    frame();
    while (!cpuView_->settled() && !quitRequested()) {
      glfwWaitEventsTimeout(0.05);  // the worker wakes it when a frame is done
      frame();
    }
    frame();  // uploads it
  }

  std::array<int, 2> view3DSize() const override {
    VS_REQUIRE(view3DSize_[0] > 0, "the 3D view has not been drawn yet");
    return view3DSize_;
  }

  void interact(const std::string& key) override {
    stopKey_ = glfwKeyFromName(key);
    stopKeySeen_ = false;
    runEventLoop();
    stopKey_ = -1;
    interactive_ = false;  // the script's frames and screenshots: full resolution again
    if (shownScale_ < 1) shownKey_.clear();
    if (globalCancelRequested()) throw Cancelled();
    if (quitRequested()) throw Error("the window was closed");
  }

  static int glfwKeyFromName(const std::string& name) {
    if (name.size() == 1 && std::isalpha(static_cast<unsigned char>(name[0])))
      return GLFW_KEY_A + (std::toupper(static_cast<unsigned char>(name[0])) - 'A');
    if (name.size() == 1 && std::isdigit(static_cast<unsigned char>(name[0]))) return GLFW_KEY_0 + (name[0] - '0');
    if (name.size() >= 2 && (name[0] == 'F' || name[0] == 'f') && name.size() <= 3 &&
        std::all_of(name.begin() + 1, name.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
      const int n = std::stoi(name.substr(1));
      if (n >= 1 && n <= 12) return GLFW_KEY_F1 + n - 1;
    }
    throw UsageError("interact: key '" + name + "' is not F1..F12, a letter or a digit");
  }

  void waitForJob(BackgroundJob& job) override {
    while (job.running() && !quitRequested()) {
      glfwWaitEventsTimeout(0.05);
      frame();
    }
    job.wait();
  }

 private:
  // ---------------------------------------------------------------- input
  static constexpr int kFramesAfterInput = 3;  // ImGui settles hover/popups a frame after an event
  static ViewerWindow& self(GLFWwindow* w) { return *static_cast<ViewerWindow*>(glfwGetWindowUserPointer(w)); }
  void push(InputEvent e) {
    e.time = std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
    queue_.push(e);
  }
  // The GLFW callbacks only queue the events (ImGui's backend was initialised without its own);
  // each frame presents its share of them (InputQueue::takeFrame).
  void installCallbacks() {
    glfwSetWindowUserPointer(window_, this);
    glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) {
      self(w).push({InputEvent::Kind::Move, x, y, 0, 0, 0, 0});
    });
    // (No glfwGetCursorPos here: it asks the X server where the pointer is now, not where it was
    // when the button went down; the motion events before the press say that.)
    glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int mods) {
      self(w).push({InputEvent::Kind::Button, 0, 0, button, action, mods, 0});
    });
    glfwSetScrollCallback(window_, [](GLFWwindow* w, double dx, double dy) {
      self(w).push({InputEvent::Kind::Wheel, dx, dy, 0, 0, 0, 0});
    });
    glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int scancode, int action, int mods) {
      self(w).push({InputEvent::Kind::Key, 0, 0, key, action, mods, scancode});
    });
    glfwSetCharCallback(window_, [](GLFWwindow* w, unsigned int c) {
      self(w).push({InputEvent::Kind::Char, 0, 0, int(c), 0, 0, 0});
    });
    glfwSetWindowFocusCallback(window_, [](GLFWwindow* w, int focused) {
      self(w).push({InputEvent::Kind::Focus, 0, 0, focused, 0, 0, 0});
    });
    glfwSetCursorEnterCallback(window_, [](GLFWwindow* w, int entered) {
      self(w).push({InputEvent::Kind::Enter, 0, 0, entered, 0, 0, 0});
    });
    glfwSetWindowRefreshCallback(window_, [](GLFWwindow* w) { self(w).redraw_ = std::max(self(w).redraw_, 2); });
    glfwSetFramebufferSizeCallback(window_,
                                   [](GLFWwindow* w, int, int) { self(w).redraw_ = std::max(self(w).redraw_, 2); });
    glfwSetDropCallback(window_, [](GLFWwindow* w, int count, const char** paths) {
      if (count > 0 && paths[0]) self(w).dropped_ = paths[0];
      self(w).redraw_ = std::max(self(w).redraw_, 2);
    });
  }

  // This frame's share of the queued events, given to ImGui (after its backend's NewFrame, whose
  // sampled mouse state it replaces).
  void presentInput() {
    ImGuiIO& io = ImGui::GetIO();
    const std::vector<InputEvent> events = queue_.takeFrame();
    frameInputs_ = events.size();
    frameFirstInput_ = events.empty() ? 0 : events.front().time;
    for (const InputEvent& e : events) {
      if (e.kind == InputEvent::Kind::Key && e.code == stopKey_ && stopKey_ >= 0) {
        if (e.action == 1) stopKeySeen_ = true;  // the script's key: ImGui never sees it
        continue;
      }
      switch (e.kind) {
        case InputEvent::Kind::Key:
          ImGui_ImplGlfw_KeyCallback(window_, e.code, e.scancode, e.action, e.mods);
          break;
        case InputEvent::Kind::Char:
          ImGui_ImplGlfw_CharCallback(window_, static_cast<unsigned>(e.code));
          break;
        case InputEvent::Kind::Wheel:
          io.MouseWheelH += float(e.x);
          io.MouseWheel += float(e.y);
          break;
        case InputEvent::Kind::Focus:
          ImGui_ImplGlfw_WindowFocusCallback(window_, e.code);
          break;
        case InputEvent::Kind::Enter:
          ImGui_ImplGlfw_CursorEnterCallback(window_, e.code);
          if (!e.code) mouse_.x = mouse_.y = -1e30;  // left the window: no hover
          break;
        default:
          mouse_.apply(e);
      }
    }
    if (!events.empty()) redraw_ = std::max(redraw_, kFramesAfterInput);
    io.MousePos = mouse_.x > -1e29 ? ImVec2(float(mouse_.x), float(mouse_.y)) : ImVec2(-FLT_MAX, -FLT_MAX);
    for (int b = 0; b < InputQueue::kButtons; ++b) io.MouseDown[b] = mouse_.down[size_t(b)];
  }

  // Whether pictures may still change without input (a job's progress, a CPU frame on its way).
  bool busy() const { return app_.job().running() || (cpuView_ && !cpuView_->settled()); }
  bool refineDue() const { return refineAt_ && Clock::now() >= *refineAt_; }
  double waitSeconds() const {
    double s = busy() ? 0.1 : 0.25;  // 0.25 s: a Ctrl-C is noticed within it
    if (refineAt_) s = std::min(s, std::max(0.0, std::chrono::duration<double>(*refineAt_ - Clock::now()).count()));
    return s;
  }

  void drawFrame() {
    glfwPollEvents();
    wasBusy_ = busy();
    frame3D_ = "kept";
    frame3DMs_ = 0;
    draw();
    glfwSwapBuffers(window_);
    if (frameLog_) {
      glFinish();  // the picture is on the screen (as far as GL can tell)
      const double now = std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
      const Index3 c = app_.hasVolume() ? app_.view().cursor : Index3{0, 0, 0};
      *frameLog_ << std::fixed << now << ' ' << frameFirstInput_ << ' ' << frameInputs_ << ' ' << frame3D_ << ' '
                 << frame3DMs_ << ' ' << c[0] << ',' << c[1] << ',' << c[2] << ' ' << app_.view().azimuthDeg << '\n';
      frameLog_->flush();
    }
  }

  // ---------------------------------------------------------------- frame
  void draw() {
    syncGpu();
    if (legacy_)
      ImGui_ImplOpenGL2_NewFrame();
    else
      ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    presentInput();
    ImGui::NewFrame();
    if (!dropped_.empty()) {  // a file dropped on the window opens (volume, or a session .json)
      const std::string path = std::exchange(dropped_, "");
      openPath(path);
    }
    int fbW = 0, fbH = 0;
    glfwGetFramebufferSize(window_, &fbW, &fbH);
    const float W = float(fbW), H = float(fbH);
    const float profileH = profileWindowHeight(app_);  // the profile plot below the panel (issue 24)
    panel(H - profileH);
    if (profileH > 0) profileWindow(app_, ImVec2(0, H - profileH), ImVec2(kPanelWidth, profileH), status_);
    const float x0 = kPanelWidth, cw = (W - x0) / 2, ch = H / 2;
    view3D(ImVec2(x0, 0), ImVec2(cw, ch));
    sliceView(2, ImVec2(x0 + cw, 0), ImVec2(cw, ch));
    sliceView(1, ImVec2(x0, ch), ImVec2(cw, ch));
    sliceView(0, ImVec2(x0 + cw, ch), ImVec2(cw, ch));
    keys();
    ImGui::Render();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDrawBuffer(GL_BACK);
    glViewport(0, 0, fbW, fbH);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0.1f, 0.1f, 0.12f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    if (legacy_)
      ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData());
    else
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (quadBuffer_ && app_.view().stereo == StereoMode::Quad && rightEye_.fbo) {
      // The right eye replaces the 3D view's rectangle in the right back buffer.
      glBindFramebuffer(GL_READ_FRAMEBUFFER, rightEye_.fbo);
      glDrawBuffer(GL_BACK_RIGHT);
      const int x = int(view3DMin_.x), y = fbH - int(view3DMin_.y) - rightEye_.h;
      glBlitFramebuffer(0, 0, rightEye_.w, rightEye_.h, x, y, x + rightEye_.w, y + rightEye_.h, GL_COLOR_BUFFER_BIT,
                        GL_NEAREST);
      glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
      glDrawBuffer(GL_BACK);
    }
  }

  void syncGpu() {
    if (!app_.hasVolume()) return;
    if (labelsSeen_ != app_.labelsRevision()) {  // the labels present, for the panel
      const auto labels = app_.labels();
      labelValues_.clear();
      if (labels)
        for (uint16_t l : labels->voxels())
          if (l) labelValues_.insert(l);
      labelsSeen_ = app_.labelsRevision();
    }
    if (!raycaster_) return;  // the CPU view takes what it needs with each request
    if (gpuRevision_ != app_.volumeRevision()) {
      raycaster_->setVolume(app_.volume());
      gpuRevision_ = app_.volumeRevision();
      gpuTf_ = 0;
    }
    if (gpuTf_ != app_.transferFunctionRevision()) {
      raycaster_->setTransferFunction(app_.transferFunction());
      gpuTf_ = app_.transferFunctionRevision();
    }
    if (gpuLabels_ != app_.labelsRevision()) {
      const auto labels = app_.labels();
      raycaster_->setLabels(labels.get());
      gpuLabels_ = app_.labelsRevision();
    }
    if (gpuHidden_ != app_.overlays().hiddenLabels) {
      raycaster_->setLabelPalette(app_.overlays());
      gpuHidden_ = app_.overlays().hiddenLabels;
    }
  }

  // Runs an action, showing its error in the panel instead of stopping the session.
  template <class F>
  void act(const char* what, F&& f) {
    try {
      f();
      status_.clear();
    } catch (const std::exception& e) {
      status_ = std::string(what) + ": " + e.what();
    }
  }

  // Opens a volume file or folder, or a session (.json), and remembers it among the recent files.
  void openPath(const std::string& path) {
    if (path.empty()) return;
    bool ok = false;
    act("open", [&] {
      const std::string ext = std::filesystem::path(path).extension().string();
      if (ext == ".json")
        app_.loadSession(path);
      else
        app_.load(path);
      ok = true;
    });
    if (!ok) return;
    std::snprintf(loadPath_, sizeof loadPath_, "%s", path.c_str());
    recent_.erase(std::remove(recent_.begin(), recent_.end(), path), recent_.end());
    recent_.insert(recent_.begin(), path);
    if (recent_.size() > 10) recent_.resize(10);
    saveRecent();
  }

  // The recent files, kept in $XDG_CONFIG_HOME/volscissors/recent.txt (or ~/.config/...).
  static std::string recentFile() {
    const char* xdg = std::getenv("XDG_CONFIG_HOME");
    const char* home = std::getenv("HOME");
    if (xdg && *xdg) return std::string(xdg) + "/volscissors/recent.txt";
    if (home && *home) return std::string(home) + "/.config/volscissors/recent.txt";
    return "";
  }
  void loadRecent() {
    const std::string f = recentFile();
    if (f.empty()) return;
    std::ifstream in(f);
    for (std::string line; std::getline(in, line) && recent_.size() < 10;)
      if (!line.empty()) recent_.push_back(line);
  }
  void saveRecent() const {
    const std::string f = recentFile();
    if (f.empty()) return;
    std::string text;
    for (const std::string& r : recent_) text += r + "\n";
    try {
      std::filesystem::create_directories(std::filesystem::path(f).parent_path());
      writeFileAtomically(f, text);
    } catch (const std::exception&) {
      // Not being able to remember recent files is no reason to stop the viewer.
    }
  }

  void startRun() {  // the current tool's job (trace, surface or cut), off the UI thread
    act("run", [&] { app_.run(/*wait=*/false); });
  }

  // ---------------------------------------------------------------- panel
  void panel(float H) {
    ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(kPanelWidth, H), ImGuiCond_Always);
    ImGui::Begin("volscissors", nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    if (raycaster_) ImGui::TextWrapped("%s", rendererNote_.c_str());
    if (!raycaster_) {
      ImGui::TextColored(kNoteColour, "%s", rendererNote_.c_str());
      if (app_.view().stereo != StereoMode::Off)
        ImGui::TextColored(kNoteColour, "stereo needs the GPU ray caster: one view shown");
      if (const std::string e = cpuView_->error(); !e.empty())
        ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", e.c_str());
    }
    if (app_.hasVolume()) {
      const Geometry& g = app_.geometry();
      ImGui::TextWrapped("%s", app_.source().c_str());
      ImGui::Text("%lld x %lld x %lld, %.3g x %.3g x %.3g mm", (long long)g.dims[0], (long long)g.dims[1],
                  (long long)g.dims[2], g.spacing.x(), g.spacing.y(), g.spacing.z());
      const Index3& c = app_.view().cursor;
      ImGui::Text("cursor %lld,%lld,%lld", (long long)c[0], (long long)c[1], (long long)c[2]);
      if (!app_.orientationWarning().empty()) ImGui::TextColored(kNoteColour, "%s", app_.orientationWarning().c_str());
      if (!app_.orientationOverride().empty())
        ImGui::Text("orientation %s (stated with --orientation)", app_.orientationOverride().c_str());
    }
    // Open a file: type its path (Enter or Open), pick a recent one, or drop it on the window.
    if (ImGui::InputTextWithHint("##load", "volume or session .json path", loadPath_, sizeof loadPath_,
                                 ImGuiInputTextFlags_EnterReturnsTrue))
      openPath(loadPath_);
    ImGui::SameLine();
    if (ImGui::Button("Open")) openPath(loadPath_);
    if (!recent_.empty() && ImGui::BeginCombo("recent", recent_.front().c_str())) {
      for (const std::string& r : std::vector<std::string>(recent_))
        if (ImGui::Selectable(r.c_str())) openPath(r);
      ImGui::EndCombo();
    }
    if (ImGui::Button("Head phantom")) act("load", [&] { app_.loadHeadPhantom(); });

    if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) {
      static const RenderMode modes[] = {RenderMode::Full, RenderMode::CutBox, RenderMode::Triplanar,
                                         RenderMode::Monoplanar, RenderMode::Mip};
      if (ImGui::BeginCombo("mode", renderModeName(app_.view().mode).c_str())) {
        for (RenderMode m : modes)
          if (ImGui::Selectable(renderModeName(m).c_str(), m == app_.view().mode)) app_.setMode(m);
        ImGui::EndCombo();
      }
      if (ImGui::BeginCombo("transfer fn", app_.view().tf.c_str())) {
        for (const auto& p : TransferFunction::presetNames())
          if (ImGui::Selectable(p.c_str(), p == app_.view().tf))
            act("transfer function", [&] { app_.setTransferFunction(p); });
        ImGui::EndCombo();
      }
      if (ImGui::TreeNode("transfer function editor")) {
        tfEditorPanel();
        ImGui::TreePop();
      }
      float win = float(app_.view().window.window), lev = float(app_.view().window.level);
      const float span = float(std::max(app_.range().max - app_.range().min, 1.0));
      bool changed = ImGui::SliderFloat("window", &win, span / 500, span);
      changed |= ImGui::SliderFloat("level", &lev, float(app_.range().min), float(app_.range().max));
      if (changed) act("window", [&] { app_.setWindow(win, lev); });
      // Radiology's presets (Hounsfield units): one click each.
      for (size_t i = 0; i < windowPresets().size(); ++i) {
        const WindowPreset& p = windowPresets()[i];
        const char* label = p.name + 3;  // without "ct-"
        if (i) flowOnSameLine(ImGui::CalcTextSize(label).x + 2 * ImGui::GetStyle().FramePadding.x);
        if (ImGui::SmallButton(label)) act("window", [&] { app_.setWindow(p.wl.window, p.wl.level); });
        checkFits(p.name);
      }
      float az = float(app_.view().azimuthDeg), el = float(app_.view().elevationDeg), zoom = float(app_.view().zoom);
      if (ImGui::SliderFloat("azimuth", &az, -180, 180) | ImGui::SliderFloat("elevation", &el, -89, 89))
        act("view", [&] { app_.setOrbit(az, el); });
      if (ImGui::SliderFloat("zoom", &zoom, 0.2f, 8, "%.2f", ImGuiSliderFlags_Logarithmic))
        act("zoom", [&] { app_.setZoom(zoom); });
      bool jitter = app_.view().jitter, shading = app_.view().shading;
      if (raycaster_) {  // the CPU renderer has no jittered starts
        if (ImGui::Checkbox("jitter", &jitter)) app_.setJitter(jitter);
        ImGui::SameLine();
      }
      if (ImGui::Checkbox("shading", &shading)) app_.setShading(shading);
      ImGui::SameLine();
      bool planes = app_.view().slicePlanesIn3D;
      if (ImGui::Checkbox("planes in 3D", &planes)) app_.setSlicePlanesIn3D(planes);
      checkFits("planes in 3D");
      static const StereoMode stereos[] = {StereoMode::Off, StereoMode::Anaglyph, StereoMode::SideBySide,
                                           StereoMode::Quad};
      if (ImGui::BeginCombo("stereo", stereoName(app_.view().stereo).c_str())) {
        for (StereoMode m : stereos)
          if (ImGui::Selectable(stereoName(m).c_str(), m == app_.view().stereo)) app_.setStereo(m);
        ImGui::EndCombo();
      }
      if (app_.view().stereo == StereoMode::Quad && !quadBuffer_ && raycaster_)
        ImGui::TextColored(kNoteColour, "no quad-buffered visual: showing anaglyph");
      if (app_.view().stereo != StereoMode::Off) {
        float sep = float(app_.view().eyeSeparation), conv = float(app_.view().convergence);
        if (ImGui::SliderFloat("eye separation", &sep, 0, 0.1f) | ImGui::SliderFloat("convergence", &conv, 0.3f, 3))
          act("stereo", [&] { app_.setStereoParameters(sep, conv); });
      }
    }

    if (ImGui::CollapsingHeader("Tools", ImGuiTreeNodeFlags_DefaultOpen)) {
      int tool = static_cast<int>(app_.tool());
      static const char* toolLabels[] = {"none (0)", "live-wire (1)", "trace (2)", "surface (3)", "cut (4)"};
      for (int t = 0; t < 5; ++t) {
        if (t) flowOnSameLine(radioWidth(toolLabels[t]));
        ImGui::RadioButton(toolLabels[t], &tool, t);
        checkFits(toolLabels[t]);
      }
      app_.setTool(static_cast<ToolKind>(tool));
      if (app_.tool() != savePathTool_) {  // the save box suggests the tool's format
        static const char* defaults[] = {"", "contour.json", "tree.swc", "surface.obj", "labels.nii.gz"};
        std::snprintf(savePath_, sizeof savePath_, "%s", defaults[static_cast<int>(app_.tool())]);
        savePathTool_ = app_.tool();
      }
      float snap = float(app_.snap());
      if (ImGui::SliderFloat("snap radius", &snap, 0, 10, "%.0f")) act("snap", [&] { app_.setSnap(std::round(snap)); });
      if (app_.tool() == ToolKind::LiveWire) liveWirePanel();
      if (app_.tool() == ToolKind::Trace) tracePanel();
      if (app_.tool() == ToolKind::Surface) surfacePanel();
      if (app_.tool() == ToolKind::Cut) cutPanel();
      if (app_.tool() != ToolKind::None) {
        if (ImGui::Button("Undo (z)")) act("undo", [&] { app_.undo(); });
        ImGui::SameLine();
        if (ImGui::Button("Redo (y)")) act("redo", [&] { app_.redo(); });
        ImGui::InputText("##save", savePath_, sizeof savePath_);
        ImGui::SameLine();
        if (ImGui::Button("Save"))
          act("save", [&] {
            app_.save(savePath_);
            status_ = std::string("saved ") + savePath_;
          });
      }
    }
    if (ImGui::CollapsingHeader("Labels and overlays", ImGuiTreeNodeFlags_DefaultOpen)) labelsPanel();
    if (ImGui::CollapsingHeader("Session")) {
      ImGui::InputText("##session", sessionPath_, sizeof sessionPath_);
      if (ImGui::Button("Save session")) act("session", [&] { app_.saveSession(sessionPath_); });
      ImGui::SameLine();
      if (ImGui::Button("Open session")) act("session", [&] { app_.loadSession(sessionPath_); });
    }
    if (toggleHelp_) {
      ImGui::SetNextItemOpen(showHelp_, ImGuiCond_Always);
      toggleHelp_ = false;
    }
    if (ImGui::CollapsingHeader("Help (h)", ImGuiTreeNodeFlags_DefaultOpen)) ImGui::TextUnformatted(kHelp);
    if (!status_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", status_.c_str());
    ImGui::End();
  }

  // Puts the next item (width px) on the current line if it fits in the panel, else on a new one.
  static void flowOnSameLine(float width) {
    const ImGuiStyle& style = ImGui::GetStyle();
    const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
    if (ImGui::GetItemRectMax().x + style.ItemSpacing.x + width <= right) ImGui::SameLine();
  }
  static float radioWidth(const char* label) {
    const ImGuiStyle& style = ImGui::GetStyle();
    return ImGui::GetFrameHeight() + style.ItemInnerSpacing.x + ImGui::CalcTextSize(label).x;
  }
  // Says on stderr (once per item) when the last item runs past the panel's right edge: a control
  // the user cannot see (tests look for the message at several window sizes).
  void checkFits(const char* name) {
    const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
    if (ImGui::GetItemRectMax().x > right + 0.5f && clipped_.insert(name).second)
      std::cerr << "volscissors: warning: the panel's control '" << name << "' is cut off\n";
  }

  void liveWirePanel() {
    const LiveWireTool& lw = app_.liveWire();
    ImGui::Text("slice %c=%lld  anchors %zu", "xyz"[lw.axis()], (long long)lw.index(), lw.clicks().size());
    const LiveWireContour c = lw.contour();
    ImGui::Text("contour %zu px, %.1f mm%s", c.pixels.size(), c.lengthMm, c.closed ? ", closed" : "");
    if (ImGui::Button("Close contour (c)")) act("close", [&] { app_.closeContour(); });
  }

  void tracePanel() {
    const TraceTool& tr = app_.trace();
    const auto& pts = tr.points();
    if (pts.empty()) ImGui::TextWrapped("click the root, then the targets (slice or 3D view)");
    for (size_t i = 0; i < pts.size() && i < 8; ++i)
      ImGui::Text("%s %lld,%lld,%lld", i == 0 ? "root  " : "target", (long long)pts[i][0], (long long)pts[i][1],
                  (long long)pts[i][2]);
    if (pts.size() > 8) ImGui::Text("... %zu targets", pts.size() - 1);
    static const char* kinds[] = {"auto", "gradient", "vesselness", "intensity"};
    BackgroundJob& job = app_.job();
    if (!job.running() && ImGui::BeginCombo("cost", tr.costKind().c_str())) {
      for (const char* k : kinds)
        if (ImGui::Selectable(k, tr.costKind() == k)) act("trace", [&] { app_.trace().setCost(k, tr.polarity()); });
      ImGui::EndCombo();
    }
    bool dark = tr.polarity() == TubePolarity::Dark;
    if (!job.running() && tr.costKind() != "auto" && tr.costKind() != "gradient" &&
        ImGui::Checkbox("dark tubes (airways)", &dark))
      act("trace", [&] { app_.trace().setCost(tr.costKind(), dark ? TubePolarity::Dark : TubePolarity::Bright); });
    int autoT = tr.autoTerminals();
    if (ImGui::InputInt("auto terminals", &autoT))
      act("trace", [&] { app_.trace().setAutoTerminals(std::max(0, autoT)); });
    jobControls();
    ImGui::Text("%zu paths", tr.paths().size());
    if (tr.hasResult() && !app_.job().running()) measureButton(app_, status_);
  }

  void jobControls() {
    BackgroundJob& job = app_.job();
    if (job.running()) {
      ImGui::ProgressBar(float(job.fraction()), ImVec2(-80, 0), job.stage().c_str());
      ImGui::SameLine();
      if (ImGui::Button("Cancel")) job.cancel();
    } else {
      if (ImGui::Button("Run (Enter)")) startRun();
      if (job.state() == BackgroundJob::State::Failed)
        ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", job.error().c_str());
      if (job.state() == BackgroundJob::State::Cancelled) ImGui::Text("cancelled");
    }
  }

  // The opacity curve over the histogram: drag a point, double-click to add one, right-click to
  // remove one; the selected point's colour below. Every edit goes to the views at once.
  void tfEditorPanel() {
    if (!app_.hasVolume()) return;
    if (tfEditorRevision_ != app_.transferFunctionRevision()) {
      tfEditor_ = std::make_unique<TfEditor>(app_.transferFunction());
      tfEditorRevision_ = app_.transferFunctionRevision();
      tfSelected_.reset();
    }
    if (histogramRevision_ != app_.volumeRevision()) {
      histogram_ =
          logHistogram(app_.floatVolume(), app_.range().min, std::max(app_.range().max, app_.range().min + 1), 128);
      histogramRevision_ = app_.volumeRevision();
    }
    TfEditor& ed = *tfEditor_;
    const double lo = app_.range().min, span = std::max(app_.range().max - lo, 1e-6);
    const ImVec2 size(ImGui::GetContentRegionAvail().x, 110);
    const ImVec2 p0 = ImGui::GetCursorScreenPos();
    ImGui::InvisibleButton("##tf", size, ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight);
    const bool hovered = ImGui::IsItemHovered(), active = ImGui::IsItemActive();
    ImDrawList* dl = ImGui::GetWindowDrawList();
    auto xOf = [&](double v) { return p0.x + float((v - lo) / span) * size.x; };
    auto yOf = [&](double a) { return p0.y + float(1 - a) * size.y; };
    dl->AddRectFilled(p0, ImVec2(p0.x + size.x, p0.y + size.y), rgb(25, 25, 30));
    const float bw = size.x / float(histogram_.size());
    for (size_t b = 0; b < histogram_.size(); ++b)
      dl->AddRectFilled(ImVec2(p0.x + bw * float(b), yOf(histogram_[b])),
                        ImVec2(p0.x + bw * float(b + 1), p0.y + size.y), rgb(80, 80, 90));
    const auto& pts = ed.tf().points();
    for (size_t i = 1; i < pts.size(); ++i)
      dl->AddLine(ImVec2(xOf(pts[i - 1].value), yOf(pts[i - 1].opacity)),
                  ImVec2(xOf(pts[i].value), yOf(pts[i].opacity)), rgb(240, 240, 240), 1.5f);
    for (size_t i = 0; i < pts.size(); ++i) {
      const auto& c = pts[i].color;
      const ImVec2 q(xOf(pts[i].value), yOf(pts[i].opacity));
      dl->AddCircleFilled(q, 5, rgb(int(255 * c[0]), int(255 * c[1]), int(255 * c[2])));
      dl->AddCircle(q, 5, tfSelected_ == i ? rgb(255, 220, 0) : rgb(255, 255, 255), 12, tfSelected_ == i ? 2.5f : 1);
    }
    const ImGuiIO& io = ImGui::GetIO();
    const double mv = lo + double((io.MousePos.x - p0.x) / size.x) * span,
                 ma = 1 - double((io.MousePos.y - p0.y) / size.y);
    const double pickRadius = 8.0 / std::max(1.f, size.y);  // about 8 pixels
    bool changed = false;
    if (hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) tfSelected_ = ed.nearest(mv, ma, span, pickRadius);
    if (hovered && ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left) && !ed.nearest(mv, ma, span, pickRadius)) {
      act("transfer function", [&] { tfSelected_ = ed.add(mv, ma); });
      changed = true;
    }
    if (active && tfSelected_ && ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
      act("transfer function", [&] { ed.move(*tfSelected_, mv, ma); });
      changed = true;
    }
    if (hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Right))
      if (const auto i = ed.nearest(mv, ma, span, pickRadius)) {
        act("transfer function", [&] { ed.remove(*i); });
        tfSelected_.reset();
        changed = true;
      }
    if (tfSelected_ && *tfSelected_ < ed.size()) {
      const auto& c = ed.point(*tfSelected_).color;
      float col[3] = {float(c[0]), float(c[1]), float(c[2])};
      ImGui::Text("value %.4g  opacity %.3f", ed.point(*tfSelected_).value, ed.point(*tfSelected_).opacity);
      if (ImGui::ColorEdit3("colour", col)) {
        act("transfer function", [&] { ed.setColour(*tfSelected_, {double(col[0]), double(col[1]), double(col[2])}); });
        changed = true;
      }
    } else {
      ImGui::TextDisabled("drag a point; double-click adds, right-click removes");
    }
    if (changed) {
      app_.setEditedTransferFunction(ed.tf());
      tfEditorRevision_ = app_.transferFunctionRevision();  // the editor already holds it
    }
    ImGui::InputText("##tffile", tfPath_, sizeof tfPath_);
    ImGui::SameLine();
    if (ImGui::Button("Save TF")) act("transfer function", [&] { app_.saveTransferFunction(tfPath_); });
    ImGui::SameLine();
    if (ImGui::Button("Open TF")) act("transfer function", [&] { app_.setTransferFunction(tfPath_); });
  }

  void cutPanel() {
    CutTool& cut = app_.cut();
    app_.prepareCutContour();  // the live contour's mesh, in the background
    ImGui::TextWrapped("click points around the part on the surface (3D view), then Run");
    bool autoIso = cut.isoAutomatic();
    float iso = float(cut.iso());
    if (ImGui::Checkbox("iso from the transfer function", &autoIso))
      act("cut", [&] { app_.setCutIso(autoIso ? std::nullopt : std::optional<double>(cut.iso())); });
    if (!autoIso && ImGui::InputFloat("iso-value", &iso, 0, 0, "%.1f", ImGuiInputTextFlags_EnterReturnsTrue))
      act("cut", [&] { app_.setCutIso(double(iso)); });
    ImGui::Text("%zu points, iso %.4g%s", cut.points().size(), cut.iso(),
                cut.liveContourReady() ? "" : " (preparing the surface)");
    jobControls();
    if (const auto r = cut.result())
      ImGui::Text("kept %lld voxels, cut away %lld", (long long)r->keptVoxels, (long long)r->cutVoxels);
  }

  void labelsPanel() {
    ImGui::InputText("##labels", labelsPath_, sizeof labelsPath_);
    ImGui::SameLine();
    if (ImGui::Button("Load labels")) act("labels", [&] { app_.loadLabels(labelsPath_); });
    ImGui::InputText("##overlay", overlayPath_, sizeof overlayPath_);
    ImGui::SameLine();
    if (ImGui::Button("Add overlay")) act("overlay", [&] { app_.addOverlay(overlayPath_); });
    const auto& loaded = app_.loadedOverlays();
    for (size_t i = 0; i < loaded.size(); ++i) {
      const auto c = overlayPaletteColor(i);
      ImGui::ColorButton(("##o" + std::to_string(i)).c_str(), ImVec4(c[0], c[1], c[2], 1),
                         ImGuiColorEditFlags_NoTooltip, ImVec2(12, 12));
      ImGui::SameLine();
      ImGui::TextUnformatted(loaded[i].path.c_str());
    }
    if (!loaded.empty() && ImGui::Button("Clear overlays")) app_.clearOverlays();
    float lop = float(app_.overlays().labelOpacity), oop = float(app_.overlays().overlayOpacity);
    if (ImGui::SliderFloat("label opacity", &lop, 0, 1)) act("opacity", [&] { app_.setLabelOpacity(lop); });
    if (ImGui::SliderFloat("overlay opacity", &oop, 0, 1)) act("opacity", [&] { app_.setOverlayOpacity(oop); });
    // One checkbox per label present (the cut: 1 kept, 2 cut away).
    int shown = 0;
    for (int l : labelValues_) {
      if (++shown > 24) {
        ImGui::Text("... %zu labels", labelValues_.size());
        break;
      }
      const auto c = labelColor(l);
      bool visible = app_.overlays().labelVisible(l);
      const std::string name = std::to_string(l) + (app_.labelsFromCut() ? cutPartName(l) : "");
      ImGui::ColorButton(("##c" + name).c_str(), ImVec4(c[0], c[1], c[2], 1), ImGuiColorEditFlags_NoTooltip,
                         ImVec2(12, 12));
      ImGui::SameLine();
      if (ImGui::Checkbox(("label " + name).c_str(), &visible)) app_.setLabelVisible(l, visible);
    }
  }

  static std::string cutPartName(int l) { return l == 1 ? " (kept)" : l == 2 ? " (cut away)" : ""; }

  void surfacePanel() {
    SurfaceTool& sf = app_.surface();
    ImGui::TextWrapped("three planes through the cursor (click a point, or move the crosshair)");
    int level = sf.level();
    if (ImGui::SliderInt("level of detail", &level, 0, 6)) act("surface", [&] { sf.setLevel(level); });
    bool closed = sf.closed();
    if (ImGui::Checkbox("closed (8 octants)", &closed)) sf.setClosed(closed);
    jobControls();
    const TriMesh m = sf.mesh();
    ImGui::Text("%zu triangles", m.triangles.size());
  }

  // ---------------------------------------------------------------- 3D view
  RayCastSettings settings() const {
    const ViewSettings& v = app_.view();
    RayCastSettings s;
    s.mode = v.mode;
    s.box = app_.cutBox();
    s.planes = Vec3(double(v.cursor[0]), double(v.cursor[1]), double(v.cursor[2]));
    s.planeAxis = v.monoAxis;
    s.planeIndex = double(v.cursor[static_cast<size_t>(v.monoAxis)]);
    s.window = v.window;
    s.shading = v.shading;
    s.jitter = v.jitter;
    s.sampleStep = v.sampleStep;
    s.background = kViewBackground;
    s.labelOpacity = app_.overlays().labelOpacity;
    return s;
  }

  static void uploadTexture(GLuint tex, int w, int h, const uint8_t* rgba, GLint magFilter) {
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, magFilter);
  }

  // Posts the frame the view needs to the CPU renderer's worker and shows the newest finished one
  // (a preview is stretched to the view); never waits for a render.
  void showCpuFrame(int w, int h) {
    cpuView_->request(cpuFrameRequest(app_, w, h, kViewBackground));
    const auto f = cpuView_->newest();
    if (f && f != cpuShown_) {
      uploadTexture(cpuTex_, f->image.width, f->image.height, f->image.pixels.data(), GL_LINEAR);
      cpuShown_ = f;
      frame3D_ = f->preview ? "cpu-preview" : "cpu-full";
      frame3DMs_ = f->renderMs;
    }
  }

  // Everything the GPU picture depends on: equal keys, equal pictures (no redraw needed).
  std::vector<double> gpuKey(int w, int h) const {
    const ViewSettings& v = app_.view();
    const Camera c = app_.camera();
    const RayCastSettings s = settings();
    std::vector<double> k{double(w),
                          double(h),
                          c.eye.x(),
                          c.eye.y(),
                          c.eye.z(),
                          c.target.x(),
                          c.target.y(),
                          c.target.z(),
                          c.up.x(),
                          c.up.y(),
                          c.up.z(),
                          c.fovDeg,
                          double(c.perspective),
                          double(static_cast<int>(s.mode)),
                          s.planes.x(),
                          s.planes.y(),
                          s.planes.z(),
                          double(s.planeAxis),
                          s.planeIndex,
                          s.window.window,
                          s.window.level,
                          double(s.shading),
                          double(s.jitter),
                          s.sampleStep,
                          s.labelOpacity,
                          double(static_cast<int>(v.stereo)),
                          v.eyeSeparation,
                          v.convergence,
                          double(gpuRevision_),
                          double(gpuTf_),
                          double(gpuLabels_)};
    k.insert(k.end(), s.box.begin(), s.box.end());
    for (int l : gpuHidden_) k.push_back(l);
    return k;
  }

  // The GPU 3D view into target_: redrawn only when its key changed; while the view changes
  // (interactive use, a full frame slower than kPreviewBudgetMs) first at a reduced resolution,
  // then at full resolution once it rests for kRefineDelay. Returns the texture to show.
  GLuint gpuView(int w, int h) {
    const std::vector<double> key = gpuKey(w, h);
    const auto now = Clock::now();
    if (key != shownKey_) {
      const double scale = interactive_ && fullMs_ > kPreviewBudgetMs
                               ? std::clamp(std::sqrt(kPreviewBudgetMs / fullMs_), 0.15, 1.0)
                               : 1.0;
      const int pw = std::max(8, int(std::lround(w * scale))), ph = std::max(8, int(std::lround(h * scale)));
      render3D(scale < 1 ? preview_ : target_, pw, ph, scale == 1);
      shownKey_ = key;
      shownScale_ = scale;
      refineAt_.reset();
      if (scale < 1) refineAt_ = now + kRefineDelay;
    } else if (shownScale_ < 1 && refineDue()) {
      render3D(target_, w, h, true);
      shownScale_ = 1;
      refineAt_.reset();
    }
    return shownScale_ < 1 ? preview_.tex : target_.tex;
  }

  // timed: measure the frame (glFinish) as the full-resolution cost that sizes the previews.
  // Software OpenGL: the GPU ray caster's full frame at the view's size (after a warm-up that
  // compiles and uploads) against the CPU renderer's full frame of the same view (on its worker);
  // the faster one draws from then on, and the panel says which and why.
  void measureRenderers(int w, int h) {
    if (gpuMeasuredMs_ < 0) {
      render3D(preview_, 16, 16, false);
      render3D(target_, w, h, true);
      gpuMeasuredMs_ = fullMs_;
      shownKey_ = gpuKey(w, h);
      shownScale_ = 1;
      startCpuView();
      cpuView_->request(cpuFrameRequest(app_, w, h, kViewBackground));
      return;
    }
    const auto f = cpuView_->newest();
    const bool failed = !cpuView_->error().empty();
    if (!failed && (!f || f->preview)) return;
    const double cpuMs = failed ? INFINITY : f->renderMs;
    measuring_ = false;
    char text[256];
    std::snprintf(text, sizeof text,
                  "software OpenGL (%s): a full frame took %.0f ms on the CPU renderer, %.0f ms on the GPU ray caster",
                  glRenderer_.c_str(), cpuMs, gpuMeasuredMs_);
    if (cpuMs < gpuMeasuredMs_) {
      raycaster_.reset();
      rendererNote_ = std::string("3D: CPU renderer, chosen by measurement: ") + text;
    } else {
      cpuView_.reset();
      rendererNote_ = std::string("3D: GPU ray caster, chosen by measurement: ") + text;
    }
    std::cerr << "volscissors: note: " << rendererNote_ << '\n';
  }

  void render3D(RenderTarget& target, int w, int h, bool timed) {
    const auto t0 = Clock::now();
    const ViewSettings& v = app_.view();
    const Camera cam = app_.camera();
    const RayCastSettings s = settings();
    const double dist = (cam.target - cam.eye).norm() * v.convergence, sep = v.eyeSeparation * dist;
    target.ensure(w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, target.fbo);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    StereoMode mode = v.stereo;
    if (mode == StereoMode::Quad && !quadBuffer_) mode = StereoMode::Anaglyph;
    if (mode == StereoMode::Off) {
      raycaster_->draw(eyeView(cam, double(w) / h), 0, 0, w, h, s);
    } else if (mode == StereoMode::Anaglyph) {
      glColorMask(GL_TRUE, GL_FALSE, GL_FALSE, GL_TRUE);  // left eye: red
      raycaster_->draw(eyeView(cam, double(w) / h, -1, sep, dist), 0, 0, w, h, s);
      glColorMask(GL_FALSE, GL_TRUE, GL_TRUE, GL_TRUE);  // right eye: cyan
      raycaster_->draw(eyeView(cam, double(w) / h, +1, sep, dist), 0, 0, w, h, s);
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    } else if (mode == StereoMode::SideBySide) {
      const int half = w / 2;
      raycaster_->draw(eyeView(cam, double(half) / h, -1, sep, dist), 0, 0, half, h, s);
      raycaster_->draw(eyeView(cam, double(w - half) / h, +1, sep, dist), half, 0, w - half, h, s);
    } else {  // quad: left eye here, right eye into its own target, blitted after ImGui
      raycaster_->draw(eyeView(cam, double(w) / h, -1, sep, dist), 0, 0, w, h, s);
      rightEye_.ensure(w, h);
      glBindFramebuffer(GL_FRAMEBUFFER, rightEye_.fbo);
      raycaster_->draw(eyeView(cam, double(w) / h, +1, sep, dist), 0, 0, w, h, s);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (timed) {
      glFinish();
      fullMs_ = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    }
    frame3D_ = timed ? "gpu-full" : "gpu-preview";
    frame3DMs_ = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }

  void view3D(ImVec2 pos, ImVec2 size) {
    ImGui::SetNextWindowPos(pos, ImGuiCond_Always);
    ImGui::SetNextWindowSize(size, ImGuiCond_Always);
    const std::string title =
        "3D: " + renderModeName(app_.view().mode) + (raycaster_ ? "" : " (CPU renderer)") + "###3d";
    ImGui::Begin(title.c_str(), nullptr, kViewFlags);
    const ImVec2 avail = ImGui::GetContentRegionAvail();
    const int w = std::max(8, int(avail.x)), h = std::max(8, int(avail.y));
    if (!app_.hasVolume()) {
      ImGui::End();
      return;
    }
    GLuint tex = 0;
    ImVec2 uv0(0, 1), uv1(1, 0);  // a framebuffer texture's rows go up
    try {
      if (measuring_) measureRenderers(w, h);
      if (!raycaster_) {
        showCpuFrame(w, h);
        tex = cpuTex_;
        uv0 = ImVec2(0, 0), uv1 = ImVec2(1, 1);  // an image's rows go down
      } else {
        tex = gpuView(w, h);
      }
    } catch (const std::exception& e) {
      status_ = std::string("3D view: ") + e.what();
    }
    view3DMin_ = ImGui::GetCursorScreenPos();
    view3DSize_ = {w, h};
    ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(tex)), ImVec2(float(w), float(h)), uv0, uv1);
    const bool hovered = ImGui::IsItemHovered();
    const ImVec2 m0 = view3DMin_;
    ImDrawList* dl = ImGui::GetWindowDrawList();
    const CameraFrame cf(app_.camera(), w, h);
    const bool mono = app_.view().stereo == StereoMode::Off || !raycaster_;
    auto project = [&](const Vec3& world, ImVec2& out) {
      double px, py, depth;
      if (!cf.project(world, px, py, depth)) return false;
      out = ImVec2(m0.x + float(px), m0.y + float(py));
      return true;
    };
    const Geometry& g = app_.geometry();
    auto worldOf = [&](const Index3& i) { return g.indexToWorld(Vec3(double(i[0]), double(i[1]), double(i[2]))); };
    const OverlaySettings& ov = app_.overlays();
    auto polyline = [&](const std::vector<Vec3>& worldPts, ImU32 colour, float width, bool closed) {
      ImVec2 first, prev;
      bool havePrev = false, haveFirst = false;
      for (const Vec3& pt : worldPts) {
        ImVec2 q;
        if (!project(pt, q)) {
          havePrev = false;
          continue;
        }
        if (havePrev) dl->AddLine(prev, q, colour, width);
        if (&pt == &worldPts.front()) first = q, haveFirst = true;
        prev = q;
        havePrev = true;
      }
      if (closed && havePrev && haveFirst && worldPts.size() > 2) dl->AddLine(prev, first, colour, width);
    };
    if (mono) {
      // Results over the rendering: the trace tree, the cut's contour and the live-wire contour.
      // The trace: its refined centreline once the run ended (the saved tree), the voxel paths
      // while it runs.
      if (const Tree tree = app_.trace().tree(); tree.size() > 0) {
        for (const Polyline& line : tree.toPolylines())
          polyline(line.points, overlayColour(ov, 255, 60, 40), 2.5f, false);
      } else {
        for (const auto& path : app_.trace().paths()) {
          std::vector<Vec3> pts;
          for (const auto& v : path.voxels) pts.push_back(worldOf(v));
          polyline(pts, overlayColour(ov, 255, 60, 40), 2.5f, false);
        }
      }
      if (const auto r = app_.cut().result()) polyline(r->contourMm, overlayColour(ov, 255, 0, 255), 2.5f, true);
      drawProfileSection3D(app_, dl, project);
      // Meshes (the extracted surface, loaded ones): triangles sorted far to near, shaded by the headlight.
      auto drawMesh = [&](const TriMesh& mesh, const std::array<float, 3>& colour) {
        std::vector<std::pair<double, size_t>> order;
        order.reserve(mesh.triangles.size());
        for (size_t k = 0; k < mesh.triangles.size(); ++k) {
          const auto& t = mesh.triangles[k];
          const Vec3 c =
              (mesh.positions[size_t(t[0])] + mesh.positions[size_t(t[1])] + mesh.positions[size_t(t[2])]) / 3;
          order.push_back({(c - cf.camera().eye).dot(cf.forward()), k});
        }
        std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
        for (const auto& [depth, k] : order) {
          const auto& t = mesh.triangles[k];
          const Vec3 &a = mesh.positions[size_t(t[0])], &b = mesh.positions[size_t(t[1])],
                     &c = mesh.positions[size_t(t[2])];
          ImVec2 pa, pb, pc;
          if (!project(a, pa) || !project(b, pb) || !project(c, pc)) continue;
          const Vec3 n = (b - a).cross(c - a).normalized();
          const float shade = float(0.25 + 0.75 * std::abs(n.dot(cf.forward())));
          dl->AddTriangleFilled(pa, pb, pc,
                                overlayColour(ov, int(255 * colour[0] * shade), int(255 * colour[1] * shade),
                                              int(255 * colour[2] * shade), 235));
        }
      };
      drawMesh(app_.surface().mesh(), {120 / 255.f, 190 / 255.f, 1.f});
      if (app_.view().slicePlanesIn3D) {
        // The three slice views' planes through the cursor (sagittal yellow, coronal blue, axial
        // red), as outlines of the volume's cross-sections.
        const Index3& cur = app_.view().cursor;
        static const ImU32 colours[3] = {rgb(220, 200, 80, 200), rgb(100, 140, 230, 200), rgb(220, 90, 90, 200)};
        for (int a = 0; a < 3; ++a) {
          const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
          const double U = double(g.dims[u] - 1), V = double(g.dims[v] - 1);
          std::vector<Vec3> corners;
          const std::pair<double, double> rect[4] = {{0.0, 0.0}, {U, 0.0}, {U, V}, {0.0, V}};
          for (const auto& [cu, cv] : rect) {
            Vec3 i;
            i[a] = double(cur[size_t(a)]);
            i[u] = cu;
            i[v] = cv;
            corners.push_back(g.indexToWorld(i));
          }
          polyline(corners, colours[a], 1.0f, true);
        }
      }
      const auto& loaded = app_.loadedOverlays();
      for (size_t i = 0; i < loaded.size(); ++i) {
        const auto c = overlayPaletteColor(i);
        drawMesh(loaded[i].mesh, c);
        for (const Polyline& line : loaded[i].lines)
          polyline(line.points, overlayColour(ov, int(255 * c[0]), int(255 * c[1]), int(255 * c[2])), 2.0f,
                   line.closed);
      }
      const LiveWireTool& lw = app_.liveWire();
      const auto contour = lw.contour();
      ImVec2 prev;
      for (size_t k = 0; k < contour.pixels.size(); ++k) {
        ImVec2 q;
        if (project(worldOf(sliceToVolumeIndex(lw.axis(), lw.index(), contour.pixels[k])), q)) {
          if (k) dl->AddLine(prev, q, overlayColour(ov, 255, 220, 0), 2.0f);
          prev = q;
        }
      }
    }
    std::optional<Vec3> cutHover;
    if (hovered) {
      ImGuiIO& io = ImGui::GetIO();
      if (io.MouseWheel != 0)
        act("zoom", [&] { app_.setZoom(std::clamp(app_.view().zoom * std::pow(1.1, io.MouseWheel), 0.1, 20.0)); });
      if (ImGui::IsMouseDragging(ImGuiMouseButton_Right))  // zoom in when dragging up (Slicer: right drag)
        act("zoom", [&] { app_.setZoom(std::clamp(app_.view().zoom * std::exp(-io.MouseDelta.y * 0.01), 0.1, 20.0)); });
      if (ImGui::IsMouseDragging(ImGuiMouseButton_Middle) ||
          (io.KeyShift && ImGui::IsMouseDragging(ImGuiMouseButton_Left))) {
        // Pan (Slicer: middle drag, polyscope: shift+left): the picture follows the mouse at the
        // depth of the volume's centre.
        const Camera& c = cf.camera();
        const double mmPerPixel = cf.pixelSizeAt((c.target - c.eye).dot(cf.forward()));
        const auto pan = app_.view().panMm;
        act("pan", [&] { app_.setPan(pan[0] + io.MouseDelta.x * mmPerPixel, pan[1] - io.MouseDelta.y * mmPerPixel); });
        dragged_ = true;
      } else if (ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
        act("view", [&] {
          app_.setOrbit(app_.view().azimuthDeg - io.MouseDelta.x * 0.4,
                        std::clamp(app_.view().elevationDeg + io.MouseDelta.y * 0.4, -89.0, 89.0));
        });
        dragged_ = true;
      }
      // Stylus: the first visible point under the mouse, snapped; drawn as a shaded sphere.
      const double mx = std::clamp(double(io.MousePos.x - m0.x), 0.0, w - 1e-3),
                   my = std::clamp(double(io.MousePos.y - m0.y), 0.0, h - 1e-3);
      const StylusPick pick = app_.stylusPick(mx, my, w, h);
      if (pick.hit) cutHover = pick.surface;
      if (pick.hit && mono) {
        ImVec2 q;
        if (project(worldOf(pick.voxel), q)) {
          double px, py, depth;
          cf.project(worldOf(pick.voxel), px, py, depth);
          const float r =
              std::max(5.f, float(std::max(app_.snap(), 1.5) * g.spacing.minCoeff() / cf.pixelSizeAt(depth)));
          dl->AddCircleFilled(q, r, rgb(40, 160, 255, 200), 24);
          dl->AddCircleFilled(ImVec2(q.x - r * 0.3f, q.y - r * 0.3f), r * 0.35f, rgb(200, 235, 255, 220), 12);
          dl->AddCircle(q, r, rgb(255, 255, 255, 220), 24, 1.5f);
        }
      }
      if (ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
        const ToolKind t = app_.tool();
        if (!dragged_ && pick.hit && (t == ToolKind::Cut || t == ToolKind::Trace || t == ToolKind::Surface)) {
          act("point", [&] {
            app_.stylusClick(mx, my, w, h);  // the script's `pick` does the same
            if (t == ToolKind::Trace && app_.trace().points().size() >= 2) app_.run(false);
          });
        }
        dragged_ = false;
      }
    }
    if (app_.tool() == ToolKind::Cut && mono) {
      // The cut's points and live contour on the surface: committed segments between the points
      // (magenta) and on to the stylus' point (green).
      const CutTool::LiveContour live = app_.cut().liveContour(cutHover);
      for (const auto& seg : live.segments) polyline(seg, overlayColour(ov, 255, 0, 255), 2.0f, false);
      polyline(live.live, overlayColour(ov, 60, 255, 120), 2.0f, false);
      for (const Vec3& p : app_.cut().points()) {
        ImVec2 q;
        if (project(g.indexToWorld(p), q)) dl->AddCircleFilled(q, 4, overlayColour(ov, 255, 140, 0));
      }
    }
    ImGui::End();
  }

  // ---------------------------------------------------------------- slice views
  void sliceView(int axis, ImVec2 pos, ImVec2 size) {
    static const char* names[3] = {"sagittal", "coronal", "axial"};
    ImGui::SetNextWindowPos(pos, ImGuiCond_Always);
    ImGui::SetNextWindowSize(size, ImGuiCond_Always);
    if (!app_.hasVolume()) return;
    const Index3 cursor = app_.view().cursor;
    const std::string title = std::string(names[axis]) + " " + "xyz"[axis] + "=" +
                              std::to_string(cursor[static_cast<size_t>(axis)]) + "###slice" + std::to_string(axis);
    ImGui::Begin(title.c_str(), nullptr, kViewFlags);
    const SliceLayout L = sliceLayout(app_.geometry(), axis, cursor[static_cast<size_t>(axis)]);
    SliceTexture& t = slices_[axis];
    const WindowLevel wl = app_.view().window;
    const OverlaySettings& ov = app_.overlays();
    if (t.revision != app_.volumeRevision() || t.index != L.index || t.window != wl.window || t.level != wl.level ||
        t.labelsRevision != app_.labelsRevision() || t.labelOpacity != ov.labelOpacity || t.hidden != ov.hiddenLabels) {
      const auto labels = app_.labels();
      const RgbaImage img = sliceImage(app_.floatVolume(), axis, L.index, wl, labels.get(), ov);
      uploadTexture(t.tex, img.width, img.height, img.pixels.data(), GL_NEAREST);
      t.revision = app_.volumeRevision();
      t.index = L.index;
      t.window = wl.window;
      t.level = wl.level;
      t.labelsRevision = app_.labelsRevision();
      t.labelOpacity = ov.labelOpacity;
      t.hidden = ov.hiddenLabels;
    }
    // The slice at its physical aspect ratio, zoomed and panned (SliceFit: picking follows).
    const ImVec2 avail = ImGui::GetContentRegionAvail();
    const ImVec2 v0 = ImGui::GetCursorScreenPos();
    const SliceFit fit = fitSlice(L, std::max(1.f, avail.x), std::max(1.f, avail.y),
                                  app_.view().sliceZoom[size_t(axis)], app_.view().slicePan[size_t(axis)]);
    ImGui::InvisibleButton(
        "##slice", ImVec2(std::max(1.f, avail.x), std::max(1.f, avail.y)),
        ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight | ImGuiButtonFlags_MouseButtonMiddle);
    const bool hovered = ImGui::IsItemHovered();
    ImDrawList* dl = ImGui::GetWindowDrawList();
    dl->PushClipRect(v0, ImVec2(v0.x + avail.x, v0.y + avail.y), true);
    const ImVec2 m0(v0.x + float(fit.x0), v0.y + float(fit.y0));
    const ImVec2 imgSize(float(fit.w), float(fit.h));
    const ImVec2 uv0(L.flipU ? 1.f : 0.f, L.flipV ? 1.f : 0.f), uv1(L.flipU ? 0.f : 1.f, L.flipV ? 0.f : 1.f);
    dl->AddImage(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(t.tex)), m0,
                 ImVec2(m0.x + imgSize.x, m0.y + imgSize.y), uv0, uv1);
    const float scale = float(fit.w / (double(L.width) * L.spacingU));  // view pixels per mm
    auto screen = [&](double u, double v) {
      const auto p = fit.viewOf(u, v);
      return ImVec2(v0.x + float(p[0]), v0.y + float(p[1]));
    };
    const int uAxis = axis == 0 ? 1 : 0, vAxis = axis == 2 ? 1 : 2;
    // Linked crosshair.
    const ImVec2 cu0 = screen(double(cursor[static_cast<size_t>(uAxis)]), 0),
                 cv0 = screen(0, double(cursor[static_cast<size_t>(vAxis)]));
    dl->AddLine(ImVec2(cu0.x, m0.y), ImVec2(cu0.x, m0.y + imgSize.y), rgb(80, 200, 80, 160));
    dl->AddLine(ImVec2(m0.x, cv0.y), ImVec2(m0.x + imgSize.x, cv0.y), rgb(80, 200, 80, 160));
    // Anatomical labels on the view's edges (they stay put while the slice is zoomed or panned).
    const ImU32 lc = rgb(255, 200, 60);
    dl->AddText(ImVec2(v0.x + 4, v0.y + avail.y / 2 - 7), lc, L.left.c_str());
    dl->AddText(ImVec2(v0.x + avail.x - 12, v0.y + avail.y / 2 - 7), lc, L.right.c_str());
    dl->AddText(ImVec2(v0.x + avail.x / 2 - 4, v0.y + 2), lc, L.top.c_str());
    dl->AddText(ImVec2(v0.x + avail.x / 2 - 4, v0.y + avail.y - 16), lc, L.bottom.c_str());

    auto uvOf = [&](const Index3& i) {
      return std::array<double, 2>{double(i[static_cast<size_t>(uAxis)]), double(i[static_cast<size_t>(vAxis)])};
    };
    const Geometry& geo = app_.geometry();
    const float dot = std::max(2.f, scale * 0.6f);
    // Polylines (world mm) where they run within half a voxel of this slice: their pieces in that slab.
    auto linesOnSlice = [&](const std::vector<Polyline>& lines, ImU32 colour) {
      for (const Polyline& line : lines) {
        std::vector<Vec3> p;
        for (const Vec3& w : line.points) p.push_back(geo.worldToIndex(w) - Vec3::Unit(axis) * double(L.index));
        if (p.size() == 1 && std::abs(p[0][axis]) <= 0.5)
          dl->AddCircleFilled(screen(p[0][uAxis], p[0][vAxis]), dot, colour);
        for (size_t k = 1; k < p.size(); ++k) {
          const double a = p[k - 1][axis], b = p[k][axis];
          double lo = 0, hi = 1;
          if (a != b) {
            const double t1 = (-0.5 - a) / (b - a), t2 = (0.5 - a) / (b - a);
            lo = std::max(0.0, std::min(t1, t2));
            hi = std::min(1.0, std::max(t1, t2));
          } else if (std::abs(a) > 0.5) {
            continue;
          }
          if (lo > hi) continue;
          const Vec3 q0 = p[k - 1] + lo * (p[k] - p[k - 1]), q1 = p[k - 1] + hi * (p[k] - p[k - 1]);
          const ImVec2 s0 = screen(q0[uAxis], q0[vAxis]), s1 = screen(q1[uAxis], q1[vAxis]);
          dl->AddLine(s0, s1, colour, 2 * dot);
          dl->AddCircleFilled(ImVec2((s0.x + s1.x) / 2, (s0.y + s1.y) / 2), dot, colour);
        }
      }
    };
    // Meshes (world mm): where their triangles cross the slice's plane.
    auto meshOnSlice = [&](const TriMesh& mesh, ImU32 colour) {
      std::vector<Vec3> p;
      p.reserve(mesh.positions.size());
      for (const Vec3& w : mesh.positions) p.push_back(geo.worldToIndex(w) - Vec3::Unit(axis) * double(L.index));
      for (const auto& tri : mesh.triangles) {
        ImVec2 ends[2];
        int n = 0;
        for (int e = 0; e < 3 && n < 2; ++e) {
          const Vec3 &a = p[size_t(tri[size_t(e)])], &b = p[size_t(tri[size_t((e + 1) % 3)])];
          if ((a[axis] < 0) == (b[axis] < 0)) continue;
          const Vec3 q = a + (b - a) * (a[axis] / (a[axis] - b[axis]));
          ends[n++] = screen(q[uAxis], q[vAxis]);
        }
        if (n == 2) dl->AddLine(ends[0], ends[1], colour, 2);
      }
    };
    // Trace: the refined centreline once the run ended (what `save` writes), the voxel paths as
    // they are found while it runs.
    if (const Tree tree = app_.trace().tree(); tree.size() > 0) {
      linesOnSlice(tree.toPolylines(), overlayColour(ov, 255, 60, 40));
    } else {
      for (const auto& path : app_.trace().paths())
        for (const auto& v : path.voxels)
          if (v[static_cast<size_t>(axis)] == L.index) {
            const auto uv = uvOf(v);
            dl->AddCircleFilled(screen(uv[0], uv[1]), dot, overlayColour(ov, 255, 60, 40));
          }
    }
    meshOnSlice(app_.surface().mesh(), overlayColour(ov, 120, 190, 255));
    const auto& tpts = app_.trace().points();
    for (size_t k = 0; k < tpts.size(); ++k)
      if (std::abs(tpts[k][static_cast<size_t>(axis)] - L.index) <= 1) {
        const auto uv = uvOf(tpts[k]);
        dl->AddCircle(screen(uv[0], uv[1]), 6, k == 0 ? rgb(255, 255, 255) : rgb(255, 120, 40), 12, 2);
      }
    // Live-wire on its slice: committed contour, live path, anchors.
    const LiveWireTool& lw = app_.liveWire();
    const bool onWireSlice = lw.axis() == axis && lw.index() == L.index;
    if (onWireSlice) {
      const auto contour = lw.contour();
      for (size_t k = 1; k < contour.pixels.size(); ++k)
        dl->AddLine(screen(double(contour.pixels[k - 1][0]), double(contour.pixels[k - 1][1])),
                    screen(double(contour.pixels[k][0]), double(contour.pixels[k][1])), overlayColour(ov, 255, 220, 0),
                    2);
      if (contour.closed && contour.pixels.size() > 1)
        dl->AddLine(screen(double(contour.pixels.back()[0]), double(contour.pixels.back()[1])),
                    screen(double(contour.pixels[0][0]), double(contour.pixels[0][1])), overlayColour(ov, 255, 220, 0),
                    2);
      const auto& live = lw.livePath();
      for (size_t k = 1; k < live.size(); ++k)
        dl->AddLine(screen(double(live[k - 1][0]), double(live[k - 1][1])),
                    screen(double(live[k][0]), double(live[k][1])), rgb(60, 255, 120), 2);
      for (const auto& a : lw.clicks()) {
        const ImVec2 q = screen(double(a[0]), double(a[1]));
        dl->AddRectFilled(ImVec2(q.x - 3, q.y - 3), ImVec2(q.x + 3, q.y + 3), rgb(255, 140, 0));
      }
    }
    // Loaded trees, polylines and meshes in their palette colours.
    const auto& loaded = app_.loadedOverlays();
    for (size_t i = 0; i < loaded.size(); ++i) {
      const auto c = overlayPaletteColor(i);
      const ImU32 colour = overlayColour(ov, int(255 * c[0]), int(255 * c[1]), int(255 * c[2]));
      linesOnSlice(loaded[i].lines, colour);
      meshOnSlice(loaded[i].mesh, colour);
    }
    // The cut's points near this slice.
    for (const Vec3& p : app_.cut().points())
      if (std::abs(p[axis] - double(L.index)) <= 1) {
        const ImVec2 q = screen(p[uAxis], p[vAxis]);
        dl->AddCircleFilled(q, 4, overlayColour(ov, 255, 140, 0));
      }
    drawProfileSectionOnSlice(app_, dl, axis, L.index, [&](double u, double v) { return screen(u, v); });
    dl->PopClipRect();
    if (hovered) handleSliceMouse(axis, fit, v0);
    ImGui::End();
  }

  void handleSliceMouse(int axis, const SliceFit& fit, ImVec2 v0) {
    ImGuiIO& io = ImGui::GetIO();
    const double px = io.MousePos.x - v0.x, py = io.MousePos.y - v0.y;
    if (io.MouseWheel != 0 && io.KeyCtrl) {  // zoom about the mouse (Slicer: Ctrl+wheel)
      const double z = std::clamp(fit.zoom * std::pow(1.15, io.MouseWheel), 0.25, 40.0);
      act("zoom", [&] { app_.setSliceView(axis, z, fit.panForZoomAbout(px, py, z)); });
      return;
    }
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Middle)) {  // pan (Slicer: middle drag)
      act("pan", [&] { app_.setSliceView(axis, fit.zoom, fit.panAfterDrag(io.MouseDelta.x, io.MouseDelta.y)); });
      return;
    }
    const std::optional<PixelUV> picked = fit.pickAt(px, py);
    if (!picked) return;  // outside the (zoomed) slice
    const SliceLayout& L = fit.layout;
    const PixelUV uv = *picked;
    const Index3 voxel = sliceToVolumeIndex(axis, L.index, uv);
    {  // the value under the mouse, in the view's lower left corner (as Slicer's data probe)
      char text[128];
      std::snprintf(text, sizeof text, "%lld,%lld,%lld: %.6g", (long long)voxel[0], (long long)voxel[1],
                    (long long)voxel[2], double(app_.floatVolume()(voxel[0], voxel[1], voxel[2])));
      const ImVec2 wp = ImGui::GetWindowPos(), ws = ImGui::GetWindowSize();
      ImGui::GetWindowDrawList()->AddText(ImVec2(wp.x + 6, wp.y + ws.y - 34), rgb(255, 255, 255), text);
      hoverValue_ = text;
    }
    if (!ImGui::IsAnyMouseDown()) hoverProfile(app_, voxel);  // a centreline under the mouse: its section
    Index3 cursor = app_.view().cursor;
    if (io.MouseWheel != 0) {  // every notch of the frame's share is one slice
      const int64_t steps = std::lround(io.MouseWheel) != 0 ? std::lround(io.MouseWheel) : (io.MouseWheel > 0 ? 1 : -1);
      cursor[static_cast<size_t>(axis)] =
          std::clamp<int64_t>(cursor[static_cast<size_t>(axis)] + steps, 0, app_.geometry().dims[axis] - 1);
      app_.setCursor(cursor);
    }
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Right)) {
      const WindowLevel wl = app_.view().window;
      act("window", [&] {
        app_.setWindow(std::max(wl.window * std::exp(io.MouseDelta.x * 0.01), 1e-3),
                       wl.level - io.MouseDelta.y * wl.window * 0.005);
      });
    }
    const bool crosshair = io.KeyShift || (app_.tool() == ToolKind::None && ImGui::IsMouseDown(ImGuiMouseButton_Left));
    if (crosshair) app_.setCursor(voxel);
    LiveWireTool& lw = app_.liveWire();
    if (app_.tool() == ToolKind::LiveWire) {
      // The first click of a contour moves the tool to the clicked view's slice.
      if (!lw.hasContour() && (lw.axis() != axis || lw.index() != L.index) &&
          ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift)
        act("live-wire", [&] { lw.setSlice(axis, L.index); });
      if (lw.axis() == axis && lw.index() == L.index) {
        if (uv != lastHover_) {
          act("live-wire", [&] { lw.hover(uv); });
          lastHover_ = uv;
        }
        if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift) act("point", [&] { app_.point2(uv); });
        if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) act("close", [&] { app_.closeContour(); });
      }
    }
    if ((app_.tool() == ToolKind::Trace || app_.tool() == ToolKind::Surface) &&
        ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift)
      act("point", [&] {
        app_.point3(voxel);
        if (app_.tool() == ToolKind::Trace && app_.trace().points().size() >= 2) app_.run(false);
      });
  }

  // ---------------------------------------------------------------- keys
  void keys() {
    ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureKeyboard) return;
    auto pressed = [](int key) { return ImGui::IsKeyPressed(key, false); };
    if (pressed(GLFW_KEY_1)) app_.setTool(ToolKind::LiveWire);
    if (pressed(GLFW_KEY_2)) app_.setTool(ToolKind::Trace);
    if (pressed(GLFW_KEY_3)) app_.setTool(ToolKind::Surface);
    if (pressed(GLFW_KEY_4)) app_.setTool(ToolKind::Cut);
    if (pressed(GLFW_KEY_0) || pressed(GLFW_KEY_ESCAPE)) app_.setTool(ToolKind::None);
    const bool redo = pressed(GLFW_KEY_Y) || (pressed(GLFW_KEY_Z) && io.KeyShift);
    if (redo)
      act("redo", [&] { app_.redo(); });
    else if (pressed(GLFW_KEY_Z))
      act("undo", [&] { app_.undo(); });
    if (pressed(GLFW_KEY_C)) act("close", [&] { app_.closeContour(); });
    if (pressed(GLFW_KEY_ENTER) &&
        (app_.tool() == ToolKind::Trace || app_.tool() == ToolKind::Surface || app_.tool() == ToolKind::Cut) &&
        !app_.computing())
      startRun();
    if (pressed(GLFW_KEY_H)) {
      showHelp_ = !showHelp_;
      toggleHelp_ = true;
    }
    if (pressed(GLFW_KEY_R)) {
      app_.setOrbit(30, 20);
      app_.setZoom(1);
      if (app_.hasVolume()) app_.setPan(0, 0);
      for (int a = 0; a < 3; ++a) app_.setSliceView(a, 1, {0, 0});
    }
    if (pressed(GLFW_KEY_M)) app_.setMode(static_cast<RenderMode>((static_cast<int>(app_.view().mode) + 1) % 5));
    if (pressed(GLFW_KEY_S)) app_.setStereo(static_cast<StereoMode>((static_cast<int>(app_.view().stereo) + 1) % 3));
    if (app_.hasVolume() && (ImGui::IsKeyPressed(GLFW_KEY_PAGE_UP) || ImGui::IsKeyPressed(GLFW_KEY_PAGE_DOWN))) {
      Index3 c = app_.view().cursor;
      c[2] =
          std::clamp<int64_t>(c[2] + (ImGui::IsKeyPressed(GLFW_KEY_PAGE_UP) ? 1 : -1), 0, app_.geometry().dims[2] - 1);
      app_.setCursor(c);
    }
  }

  static constexpr ImGuiWindowFlags kViewFlags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize |
                                                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoScrollbar |
                                                 ImGuiWindowFlags_NoScrollWithMouse;
  ViewerApp& app_;
  GLFWwindow* window_;
  std::unique_ptr<GpuRayCaster> raycaster_;  // null: the CPU renderer draws the 3D view
  std::unique_ptr<CpuView> cpuView_;
  std::string cpuNote_;
  bool legacy_ = false;     // a legacy context: ImGui's OpenGL 2 backend
  bool measuring_ = false;  // timing both renderers' first frames (software OpenGL)
  double gpuMeasuredMs_ = -1;
  std::string glRenderer_, rendererNote_;
  GLuint cpuTex_ = 0;
  std::shared_ptr<const CpuView::Frame> cpuShown_;
  using Clock = std::chrono::steady_clock;
  static constexpr double kPreviewBudgetMs = 50;  // a preview frame's target time while the view changes
  static constexpr std::chrono::milliseconds kRefineDelay{150};
  RenderTarget target_, preview_, rightEye_;
  std::vector<double> shownKey_;  // the GPU picture's key (gpuKey)
  double shownScale_ = 1, fullMs_ = 0;
  std::optional<Clock::time_point> refineAt_;
  bool interactive_ = false;  // the event loop runs (a script's frames are always full resolution)
  InputQueue queue_;
  MouseState mouse_;
  int redraw_ = 2;
  bool wasBusy_ = false;
  std::atomic<bool> cpuFrameReady_{false};
  uint64_t framesDrawn_ = 0;
  std::string dropped_;
  std::vector<std::string> recent_;
  std::set<std::string> clipped_;
  std::string hoverValue_;  // "x,y,z: value" under the mouse in a slice view
  // VS_VIEWER_FRAME_LOG=FILE: one line per drawn frame (bench/viewer_interaction.py): the time it
  // was on the screen, the time of its first input event, how many events, what the 3D view did
  // (kept, gpu-preview, gpu-full, cpu-preview, cpu-full) and in how many ms, the cursor, the azimuth.
  std::unique_ptr<std::ofstream> frameLog_;
  size_t frameInputs_ = 0;
  double frameFirstInput_ = 0;
  const char* frame3D_ = "kept";
  double frame3DMs_ = 0;  // panel controls found cut off (warned once)
  GLuint sliceTexIds_[3] = {0, 0, 0};
  SliceTexture slices_[3];
  uint64_t gpuRevision_ = 0;
  uint64_t gpuTf_ = 0;
  uint64_t gpuLabels_ = 0, labelsSeen_ = 0;
  std::set<int> gpuHidden_;
  std::set<int> labelValues_;  // the labels present in app_.labels(), for the panel
  bool quadBuffer_ = false;
  bool quit_ = false;
  bool showHelp_ = true, toggleHelp_ = false;
  bool dragged_ = false;
  ImVec2 view3DMin_{0, 0};
  std::array<int, 2> view3DSize_{0, 0};
  int stopKey_ = -1;  // interact: the key that hands the window back to the script
  bool stopKeySeen_ = false;
  ToolKind savePathTool_ = ToolKind::None;
  PixelUV lastHover_{-1, -1};
  std::string status_;
  char loadPath_[1024], savePath_[1024], sessionPath_[1024], labelsPath_[1024], tfPath_[1024], overlayPath_[1024];
  std::unique_ptr<TfEditor> tfEditor_;
  uint64_t tfEditorRevision_ = 0, histogramRevision_ = 0;
  std::optional<size_t> tfSelected_;
  std::vector<double> histogram_;
};

}  // namespace

RendererChoice rendererFromName(const std::string& name) {
  if (name == "auto") return RendererChoice::Auto;
  if (name == "gpu") return RendererChoice::Gpu;
  if (name == "cpu") return RendererChoice::Cpu;
  throw UsageError("unknown renderer '" + name + "' (auto, gpu, cpu)");
}

namespace {

// core: OpenGL 3.3 core (the GPU ray caster); otherwise the driver's default (legacy) context.
GLFWwindow* createWindow(const WindowOptions& options, bool core, bool stereo) {
  glfwDefaultWindowHints();
  if (core) {
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  }
  if (stereo) {
    glfwWindowHint(GLFW_STEREO, GLFW_TRUE);
    if (GLFWwindow* w = glfwCreateWindow(options.width, options.height, "volscissors view", nullptr, nullptr)) return w;
    glfwWindowHint(GLFW_STEREO, GLFW_FALSE);  // no stereo visual: the window falls back to anaglyph
  }
  return glfwCreateWindow(options.width, options.height, "volscissors view", nullptr, nullptr);
}

}  // namespace

int runViewerWindow(ViewerApp& app, const WindowOptions& options) {
  glfwSetErrorCallback(glfwError);
  if (!glfwInit())
    throw Error("cannot open a window: " + gGlfwError + " (no display? set DISPLAY or run under xvfb-run)");
  struct Terminate {
    ~Terminate() { glfwTerminate(); }
  } terminate;
  // Why the CPU renderer draws the 3D view ("": the GPU ray caster does).
  std::string cpuReason = options.renderer == RendererChoice::Cpu ? "requested (--renderer cpu)" : "";
  GLFWwindow* window = nullptr;
  std::unique_ptr<GpuRayCaster> raycaster;
  if (cpuReason.empty()) {
    window = createWindow(options, /*core=*/true, app.view().stereo == StereoMode::Quad);
    if (window) {
      glfwMakeContextCurrent(window);
      try {
        raycaster = std::make_unique<GpuRayCaster>();
      } catch (const std::exception& e) {
        cpuReason = std::string("the GPU ray caster's shaders failed: ") + e.what();
        if (options.renderer == RendererChoice::Gpu) throw Error(cpuReason);
        glfwDestroyWindow(window);  // the CPU view's legacy context takes ImGui's OpenGL 2 backend
        window = nullptr;
      }
    } else {
      if (options.renderer == RendererChoice::Gpu)
        throw Error("cannot create a window with an OpenGL 3.3 core context: " + gGlfwError);
      cpuReason = "OpenGL 3.3 not available: " + gGlfwError;
    }
  }
  if (!window) {
    window = createWindow(options, /*core=*/false, false);
    if (!window) throw Error("cannot create a window with any OpenGL context: " + gGlfwError);
    glfwMakeContextCurrent(window);
  }
  const auto* rendererString = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string glRenderer = rendererString ? rendererString : "?";
  // Software OpenGL passes the 3.3 check, but the CPU renderer may well be faster there: measure.
  const bool software = glRenderer.find("llvmpipe") != std::string::npos ||
                        glRenderer.find("softpipe") != std::string::npos ||
                        glRenderer.find("swrast") != std::string::npos;
  const bool measure = options.renderer == RendererChoice::Auto && raycaster && software;
  std::string cpuNote;
  if (!cpuReason.empty()) {
    const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    cpuNote = "CPU renderer: " + cpuReason;
    std::cerr << "volscissors: note: " << cpuNote << " (this context: OpenGL " << (version ? version : "?")
              << "); the 3D view is drawn by the CPU renderer\n";
  }
  glfwSwapInterval(options.script.empty() ? 1 : 0);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside the user's files
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, false);  // the window queues the events itself
  const bool legacy = !raycaster;
  if (legacy)
    ImGui_ImplOpenGL2_Init();
  else
    ImGui_ImplOpenGL3_Init("#version 330 core");
  int rc = 0;
  {
    ViewerWindow w(app, window, std::move(raycaster), cpuNote, legacy, measure, glRenderer);
    bool quit = false;
    if (!options.script.empty()) {
      try {
        quit = runScriptFile(app, options.script, &w);
        if (!quit)
          std::cerr << "volscissors: note: the script " << options.script
                    << " ended without `quit`: the window stays open (close it, or Ctrl-C)\n";
      } catch (const Error& e) {
        if (!globalCancelRequested()) std::cerr << "volscissors: error: " << e.what() << '\n';
        rc = 1;
        quit = true;
      }
    }
    if (!quit) w.runEventLoop();
    app.job().cancel();
    app.job().wait();
    if (globalCancelRequested()) {
      std::cerr << "volscissors: closed (interrupted)\n";
      rc = 130;
    }
  }
  if (legacy)
    ImGui_ImplOpenGL2_Shutdown();
  else
    ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  return rc;
}

}  // namespace vs::viewer
