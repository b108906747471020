// The window's parts (viewer_window.h), one file each, around one class:
//   viewer_window.cpp   the window's life: construction, the event loop, the script host, a frame, files
//   window_input.cpp    GLFW callbacks into the input queue, each frame's share of it, the keys
//   window_panel.cpp    the side panel: files, display, the tools' controls, transfer function, labels
//   window_view3d.cpp   the 3D view: GPU or CPU picture, results drawn over it, camera and stylus
//   window_slices.cpp   the three slice views: picture, overlays, mouse
#pragma once

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
#include "app/key_bindings.h"
#include "app/script.h"
#include "app/slice_layout.h"
#include "app/stereo.h"
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

namespace vs::viewer::window_detail {

inline constexpr float kPanelWidth = 340;
inline constexpr std::array<float, 3> kViewBackground{0.08f, 0.08f, 0.1f};  // planes of air stay visible against it
inline const ImVec4 kNoteColour(1, 0.7f, 0.3f, 1);
inline ImU32 rgb(int r, int g, int b, int a = 255) { return IM_COL32(r, g, b, a); }

// A drawn result (contour, tree, mesh, cut) at the overlay opacity.
inline ImU32 overlayColour(const OverlaySettings& o, int r, int g, int b, int a = 255) {
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

// Drawing over the 3D view's picture: world mm projected through the camera onto ImGui's draw list.
struct Canvas3D {
  const CameraFrame& cf;
  ImVec2 m0;  // the picture's top left corner on the screen
  ImDrawList* dl;
  const Geometry& g;
  const OverlaySettings& ov;
  const StereoEye* eye = nullptr;  // stereo: this eye's camera and viewport (m0 is the viewport's corner)
  bool project(const Vec3& world, ImVec2& out) const;
  bool project(const Vec3& world, ImVec2& out, double& depth) const;
  Vec3 worldOf(const Index3& i) const;
  void polyline(const std::vector<Vec3>& worldPts, ImU32 colour, float width, bool closed) const;
  void mesh(const TriMesh& mesh, const std::array<float, 3>& colour) const;
};

class ViewerWindow : public ScriptHost {
 public:
  // raycaster null: the CPU renderer draws the 3D view, cpuNote says why. legacy: a legacy
  // context (ImGui's OpenGL 2 backend). measure: software OpenGL (llvmpipe, softpipe, swrast)
  // was found, so the first frames of both renderers are timed and the faster one kept.
  ViewerWindow(ViewerApp& app, GLFWwindow* window, std::unique_ptr<GpuRayCaster> raycaster, std::string cpuNote,
               bool legacy, bool measure, std::string glRenderer);
  void startCpuView();

  ~ViewerWindow() override;

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
  void runEventLoop();

  uint64_t framesDrawn() const { return framesDrawn_; }

  void screenshot(const std::string& path) override;

  // The CPU renderer's full-resolution frame of what the window shows now (a script's
  // screenshot waits for it; the mouse never does).
  void settleCpuView();

  std::array<int, 2> view3DSize() const override {
    VS_REQUIRE(view3DSize_[0] > 0, "the 3D view has not been drawn yet");
    return view3DSize_;
  }

  void interact(const std::string& key) override;

  static int glfwKeyFromName(const std::string& name);

  void waitForJob(BackgroundJob& job) override;

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
  void installCallbacks();

  // This frame's share of the queued events, given to ImGui (after its backend's NewFrame, whose
  // sampled mouse state it replaces).
  void presentInput();

  // Whether pictures may still change without input (a job's progress, a CPU frame on its way).
  bool busy() const { return app_.job().running() || (cpuView_ && !cpuView_->settled()); }
  bool refineDue() const { return refineAt_ && Clock::now() >= *refineAt_; }
  double waitSeconds() const;

  void drawFrame();

  // ---------------------------------------------------------------- frame
  void draw();

  void syncGpu();

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
  void openPath(const std::string& path);

  // The recent files, kept in $XDG_CONFIG_HOME/volscissors/recent.txt (or ~/.config/...).
  static std::string recentFile();
  void loadRecent();
  void saveRecent() const;

  void startRun() {  // the current tool's job (trace, surface or cut), off the UI thread
    act("run", [&] { app_.run(/*wait=*/false); });
  }

  // ---------------------------------------------------------------- panel
  void panel(float H);

  // Puts the next item (width px) on the current line if it fits in the panel, else on a new one.
  static void flowOnSameLine(float width);
  static float radioWidth(const char* label) {
    const ImGuiStyle& style = ImGui::GetStyle();
    return ImGui::GetFrameHeight() + style.ItemInnerSpacing.x + ImGui::CalcTextSize(label).x;
  }
  // Says on stderr (once per item) when the last item runs past the panel's right edge: a control
  // the user cannot see (tests look for the message at several window sizes).
  void checkFits(const char* name);

  void liveWirePanel();

  void tracePanel();

  void jobControls();

  // The opacity curve over the histogram: drag a point, double-click to add one, right-click to
  // remove one; the selected point's colour below. Every edit goes to the views at once.
  void tfEditorPanel();

  void cutPanel();

  void labelsPanel();

  static std::string cutPartName(int l) { return l == 1 ? " (kept)" : l == 2 ? " (cut away)" : ""; }

  void surfacePanel();

  // ---------------------------------------------------------------- 3D view
  RayCastSettings settings() const;

  static void uploadTexture(GLuint tex, int w, int h, const uint8_t* rgba, GLint magFilter);

  // Posts the frame the view needs to the CPU renderer's worker and shows the newest finished one
  // (a preview is stretched to the view); never waits for a render.
  void showCpuFrame(int w, int h);

  // Everything the GPU picture depends on: equal keys, equal pictures (no redraw needed).
  std::vector<double> gpuKey(int w, int h) const;

  // The GPU 3D view into target_: redrawn only when its key changed; while the view changes
  // (interactive use, a full frame slower than kPreviewBudgetMs) first at a reduced resolution,
  // then at full resolution once it rests for kRefineDelay. Returns the texture to show.
  GLuint gpuView(int w, int h);

  // timed: measure the frame (glFinish) as the full-resolution cost that sizes the previews.
  // Software OpenGL: the GPU ray caster's full frame at the view's size (after a warm-up that
  // compiles and uploads) against the CPU renderer's full frame of the same view (on its worker);
  // the faster one draws from then on, and the panel says which and why.
  void measureRenderers(int w, int h);

  void render3D(RenderTarget& target, int w, int h, bool timed);

  void view3D(ImVec2 pos, ImVec2 size);
  void drawResults3D(const Canvas3D& c);
  StylusPick mouse3D(const Canvas3D& c, int w, int h);
  // Everything drawn over the 3D picture (stereo_view.cpp), once per eye with that eye's camera:
  // results, the cut's contour, the stylus sphere.
  void drawOverlays3D(const CameraFrame& cf, int w, int h, const StylusPick& pick);
  // cut_view.cpp: the cut's previewed loop and points; the stylus sphere at the point a click gives.
  void drawCutContour3D(const Canvas3D& c, const CutTool::LiveContour& live);
  void drawStylus3D(const Canvas3D& c, const StylusPick& pick);
  // cut_box_view.cpp: the cut box's face handles (cut-box mode) and their drags; cutBoxDrag is true
  // while a handle is held (the drag then moves the face instead of turning the view).
  void drawCutBoxHandles(const Canvas3D& c);
  bool cutBoxDrag(const Canvas3D& c);
  // Monoplanar mode: the plane's outline and handle (plane_view.cpp); a drag of the handle moves
  // the plane, `a` turns it to the next axis. True while the handle is dragged (no orbit then).
  bool monoPlaneHandle(const Canvas3D& c, bool hovered);
  struct PlaneDrag {
    float grabX, grabY;  // where on the handle it was grabbed (mouse - handle centre)
  };
  std::optional<PlaneDrag> planeDrag_;

  // ---------------------------------------------------------------- slice views
  void sliceView(int axis, ImVec2 pos, ImVec2 size);
  void updateSliceTexture(int axis, int64_t index);
  void drawResultsOnSlice(int axis, const SliceFit& fit, ImVec2 v0, ImDrawList* dl);

  void handleSliceMouse(int axis, const SliceFit& fit, ImVec2 v0);

  // ---------------------------------------------------------------- the surface tool's view (surface_view.cpp)
  // Corner handles, the chosen side and its via points on a slice; the mouse there (drag a corner
  // along its half-line, Ctrl+click a via point, a click moves the planes' centre); the corner
  // handles in the 3D view (true while one is dragged there: no orbit).
  void drawSurfaceOnSlice(int axis, const SliceFit& fit, ImVec2 v0, ImDrawList* dl);
  void surfaceMouse(int axis, const SliceFit& fit, ImVec2 v0, bool hovered);
  bool surfaceHandles3D(const Canvas3D& c, bool hovered);
  std::optional<int> dragCorner_, dragCorner3D_;  // the half-line whose corner is dragged
  int64_t dragCornerTo_ = 0;                      // where along it (voxel index on its axis)

  // ---------------------------------------------------------------- the live-wire tool's view (livewire_view.cpp)
  // Its contour, live path and anchors on its slice (a dragged anchor where the mouse is).
  void drawLiveWireOnSlice(int axis, const SliceFit& fit, ImVec2 v0, ImDrawList* dl);
  // Its mouse on a slice view: clicks add points, Ctrl+click on the contour inserts an anchor, a
  // drag moves one, right-click or Delete removes one, double-click closes. Called while the view
  // is hovered or an anchor drag (which may end outside it) is under way.
  void liveWireMouse(int axis, const SliceFit& fit, ImVec2 v0, bool hovered);
  std::optional<size_t> dragAnchor_;  // the anchor being dragged
  PixelUV dragTo_{0, 0};

  // ---------------------------------------------------------------- keys
  void keys();
  void keyAction(const std::string& action);  // a row of app/key_bindings.h

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
  int boxFace_ = -1;  // the cut box's face whose handle is held (-1: none)
  std::array<double, 6> boxAtGrab_{};
  ImVec2 mouseAtGrab_{0, 0};
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

}  // namespace vs::viewer::window_detail
