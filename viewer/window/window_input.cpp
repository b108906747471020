// The window's input: GLFW callbacks into the queue, each frame's share given to ImGui, the keys.
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

// The GLFW callbacks only queue the events (ImGui's backend was initialised without its own);
// each frame presents its share of them (InputQueue::takeFrame).
void ViewerWindow::installCallbacks() {
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
void ViewerWindow::presentInput() {
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

double ViewerWindow::waitSeconds() const {
  double s = busy() ? 0.1 : 0.25;  // 0.25 s: a Ctrl-C is noticed within it
  if (refineAt_) s = std::min(s, std::max(0.0, std::chrono::duration<double>(*refineAt_ - Clock::now()).count()));
  return s;
}

void ViewerWindow::drawFrame() {
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

// ---------------------------------------------------------------- keys
namespace {
struct KeyChord {
  int code = 0;
  bool shift = false;
};
KeyChord keyChord(std::string name, int (*fromName)(const std::string&)) {
  KeyChord k;
  if (name.rfind("Shift+", 0) == 0) k.shift = true, name = name.substr(6);
  static const std::pair<const char*, int> named[] = {
      {"Esc", GLFW_KEY_ESCAPE}, {"Enter", GLFW_KEY_ENTER}, {"PgUp", GLFW_KEY_PAGE_UP}, {"PgDn", GLFW_KEY_PAGE_DOWN}};
  for (const auto& [n, code] : named)
    if (name == n) k.code = code;
  if (!k.code) k.code = fromName(name);  // a letter or a digit
  return k;
}
}  // namespace

// The keys of app/key_bindings.h's table: a shifted row needs Shift, a plain one refuses it only
// where the same key also has a shifted row (z undo, Shift+z redo).
void ViewerWindow::keys() {
  ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureKeyboard) return;
  std::vector<std::pair<KeyChord, const KeyBinding*>> rows;
  for (const KeyBinding& b : keyBindings()) rows.push_back({keyChord(b.key, &glfwKeyFromName), &b});
  for (const auto& [k, b] : rows) {
    const bool shiftedRow = std::any_of(
        rows.begin(), rows.end(), [&, code = k.code](const auto& r) { return r.first.code == code && r.first.shift; });
    if (k.shift ? !io.KeyShift : (io.KeyShift && shiftedRow)) continue;
    if (ImGui::IsKeyPressed(k.code, b->repeat)) keyAction(b->action);
  }
}

void ViewerWindow::keyAction(const std::string& a) {
  if (a == "help") {
    showHelp_ = !showHelp_;
    toggleHelp_ = true;
  } else if (a == "reset-view") {
    app_.setOrbit(30, 20);
    app_.setZoom(1);
    if (app_.hasVolume()) app_.setPan(0, 0);
    for (int ax = 0; ax < 3; ++ax) app_.setSliceView(ax, 1, {0, 0});
  } else if (a == "next-mode") {
    app_.setMode(static_cast<RenderMode>((static_cast<int>(app_.view().mode) + 1) % 5));
  } else if (a == "next-stereo") {
    app_.setStereo(static_cast<StereoMode>((static_cast<int>(app_.view().stereo) + 1) % 3));
  } else if (a == "slice+1" || a == "slice-1") {
    if (!app_.hasVolume()) return;
    Index3 c = app_.view().cursor;
    c[2] = std::clamp<int64_t>(c[2] + (a == "slice+1" ? 1 : -1), 0, app_.geometry().dims[2] - 1);
    app_.setCursor(c);
  } else if (a == "run") {  // the job starts; the window keeps drawing (the script's run waits)
    const ToolKind t = app_.tool();
    if ((t == ToolKind::Trace || t == ToolKind::Surface || t == ToolKind::Cut) && !app_.computing()) startRun();
  } else {  // a command line of the script's command table
    const size_t sp = a.find(' ');
    const std::string name = a.substr(0, sp);
    const std::vector<std::string> args =
        sp == std::string::npos ? std::vector<std::string>{} : std::vector<std::string>{a.substr(sp + 1)};
    act(name.c_str(), [&] { findScriptCommand(name)->action(ScriptCall{app_, nullptr, name, args}); });
  }
}

}  // namespace vs::viewer::window_detail
