#include "window/window_impl.h"

namespace vs::viewer {

namespace {

std::string gGlfwError;

void glfwError(int, const char* message) { gGlfwError = message; }

}  // namespace

namespace window_detail {

// raycaster null: the CPU renderer draws the 3D view, cpuNote says why. legacy: a legacy
// context (ImGui's OpenGL 2 backend). measure: software OpenGL (llvmpipe, softpipe, swrast)
// was found, so the first frames of both renderers are timed and the faster one kept.
ViewerWindow::ViewerWindow(ViewerApp& app, GLFWwindow* window, std::unique_ptr<GpuRayCaster> raycaster,
                           std::string cpuNote, bool legacy, bool measure, std::string glRenderer)
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

void ViewerWindow::startCpuView() {
  cpuView_ = std::make_unique<CpuView>();
  cpuView_->setOnFrame([this] {
    cpuFrameReady_ = true;
    glfwPostEmptyEvent();  // wakes glfwWaitEventsTimeout (thread-safe)
  });
}

ViewerWindow::~ViewerWindow() {
  cpuView_.reset();  // its worker's callback touches this window
  glDeleteTextures(3, sliceTexIds_);
  if (cpuTex_) glDeleteTextures(1, &cpuTex_);
}

// The interactive loop: sleeps in glfwWaitEventsTimeout until something needs a new picture
// (an input event, a finished CPU frame, a running job's progress, the full-resolution frame
// after a preview); every queued input event is presented, in order.
void ViewerWindow::runEventLoop() {
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

void ViewerWindow::screenshot(const std::string& path) {
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
void ViewerWindow::settleCpuView() {
  if (!cpuView_) return;
  frame();
  while (!cpuView_->settled() && !quitRequested()) {
    glfwWaitEventsTimeout(0.05);  // the worker wakes it when a frame is done
    frame();
  }
  frame();  // uploads it
}

void ViewerWindow::interact(const std::string& key) {
  stopKey_ = glfwKeyFromName(key);
  stopKeySeen_ = false;
  runEventLoop();
  stopKey_ = -1;
  interactive_ = false;  // the script's frames and screenshots: full resolution again
  if (shownScale_ < 1) shownKey_.clear();
  if (globalCancelRequested()) throw Cancelled();
  if (quitRequested()) throw Error("the window was closed");
}

int ViewerWindow::glfwKeyFromName(const std::string& name) {
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

void ViewerWindow::waitForJob(BackgroundJob& job) {
  while (job.running() && !quitRequested()) {
    glfwWaitEventsTimeout(0.05);
    frame();
  }
  job.wait();
}

// ---------------------------------------------------------------- frame
void ViewerWindow::draw() {
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

void ViewerWindow::syncGpu() {
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

// Opens a volume file or folder, or a session (.json), and remembers it among the recent files.
void ViewerWindow::openPath(const std::string& path) {
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
std::string ViewerWindow::recentFile() {
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  const char* home = std::getenv("HOME");
  if (xdg && *xdg) return std::string(xdg) + "/volscissors/recent.txt";
  if (home && *home) return std::string(home) + "/.config/volscissors/recent.txt";
  return "";
}

void ViewerWindow::loadRecent() {
  const std::string f = recentFile();
  if (f.empty()) return;
  std::ifstream in(f);
  for (std::string line; std::getline(in, line) && recent_.size() < 10;)
    if (!line.empty()) recent_.push_back(line);
}

void ViewerWindow::saveRecent() const {
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

}  // namespace window_detail

using window_detail::ViewerWindow;

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
