// The window's 3D view: the GPU ray caster's or the CPU renderer's picture, results over it, camera and stylus.
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

// ---------------------------------------------------------------- 3D view
RayCastSettings ViewerWindow::settings() const {
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

void ViewerWindow::uploadTexture(GLuint tex, int w, int h, const uint8_t* rgba, GLint magFilter) {
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, magFilter);
}

// Posts the frame the view needs to the CPU renderer's worker and shows the newest finished one
// (a preview is stretched to the view); never waits for a render.
void ViewerWindow::showCpuFrame(int w, int h) {
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
std::vector<double> ViewerWindow::gpuKey(int w, int h) const {
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
GLuint ViewerWindow::gpuView(int w, int h) {
  const std::vector<double> key = gpuKey(w, h);
  const auto now = Clock::now();
  if (key != shownKey_) {
    const double scale =
        interactive_ && fullMs_ > kPreviewBudgetMs ? std::clamp(std::sqrt(kPreviewBudgetMs / fullMs_), 0.15, 1.0) : 1.0;
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
void ViewerWindow::measureRenderers(int w, int h) {
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

void ViewerWindow::render3D(RenderTarget& target, int w, int h, bool timed) {
  const auto t0 = Clock::now();
  const ViewSettings& v = app_.view();
  const RayCastSettings s = settings();
  target.ensure(w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, target.fbo);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  StereoMode mode = v.stereo;
  if (mode == StereoMode::Quad && !quadBuffer_) mode = StereoMode::Anaglyph;
  const std::vector<StereoEye> eyes = stereoEyes(app_, mode, w, h);  // the overlays and the stylus use the same
  if (mode == StereoMode::Off || mode == StereoMode::SideBySide) {
    for (const StereoEye& e : eyes) raycaster_->draw(e.view, e.x0, 0, e.width, h, s);
  } else if (mode == StereoMode::Anaglyph) {
    glColorMask(GL_TRUE, GL_FALSE, GL_FALSE, GL_TRUE);  // left eye: red
    raycaster_->draw(eyes[0].view, 0, 0, w, h, s);
    glColorMask(GL_FALSE, GL_TRUE, GL_TRUE, GL_TRUE);  // right eye: cyan
    raycaster_->draw(eyes[1].view, 0, 0, w, h, s);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  } else {  // quad: left eye here, right eye into its own target, blitted after ImGui
    raycaster_->draw(eyes[0].view, 0, 0, w, h, s);
    rightEye_.ensure(w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, rightEye_.fbo);
    raycaster_->draw(eyes[1].view, 0, 0, w, h, s);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (timed) {
    glFinish();
    fullMs_ = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }
  frame3D_ = timed ? "gpu-full" : "gpu-preview";
  frame3DMs_ = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

bool Canvas3D::project(const Vec3& world, ImVec2& out) const {
  double depth;
  return project(world, out, depth);
}

bool Canvas3D::project(const Vec3& world, ImVec2& out, double& depth) const {
  double px, py;
  if (eye ? !projectToEye(*eye, world, px, py, depth) : !cf.project(world, px, py, depth)) return false;
  out = ImVec2(m0.x + float(px), m0.y + float(py));
  return true;
}

Vec3 Canvas3D::worldOf(const Index3& i) const { return g.indexToWorld(Vec3(double(i[0]), double(i[1]), double(i[2]))); }

void Canvas3D::polyline(const std::vector<Vec3>& worldPts, ImU32 colour, float width, bool closed) const {
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
}

// Triangles sorted far to near, shaded by the headlight.
void Canvas3D::mesh(const TriMesh& m, const std::array<float, 3>& colour) const {
  std::vector<std::pair<double, size_t>> order;
  order.reserve(m.triangles.size());
  for (size_t k = 0; k < m.triangles.size(); ++k) {
    const auto& t = m.triangles[k];
    const Vec3 c = (m.positions[size_t(t[0])] + m.positions[size_t(t[1])] + m.positions[size_t(t[2])]) / 3;
    order.push_back({(c - cf.camera().eye).dot(cf.forward()), k});
  }
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [depth, k] : order) {
    const auto& t = m.triangles[k];
    const Vec3 &a = m.positions[size_t(t[0])], &b = m.positions[size_t(t[1])], &c = m.positions[size_t(t[2])];
    ImVec2 pa, pb, pc;
    if (!project(a, pa) || !project(b, pb) || !project(c, pc)) continue;
    const Vec3 n = (b - a).cross(c - a).normalized();
    const float shade = float(0.25 + 0.75 * std::abs(n.dot(cf.forward())));
    dl->AddTriangleFilled(pa, pb, pc,
                          overlayColour(ov, int(255 * colour[0] * shade), int(255 * colour[1] * shade),
                                        int(255 * colour[2] * shade), 235));
  }
}

void ViewerWindow::view3D(ImVec2 pos, ImVec2 size) {
  ImGui::SetNextWindowPos(pos, ImGuiCond_Always);
  ImGui::SetNextWindowSize(size, ImGuiCond_Always);
  const std::string title = "3D: " + renderModeName(app_.view().mode) + (raycaster_ ? "" : " (CPU renderer)") + "###3d";
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
  bool hovered = ImGui::IsItemHovered();
  const CameraFrame cf(app_.camera(), w, h);
  const Canvas3D canvas{cf, view3DMin_, ImGui::GetWindowDrawList(), app_.geometry(), app_.overlays()};
  const bool mono = app_.view().stereo == StereoMode::Off || !raycaster_;
  // Handles (plane_view.cpp, surface_view.cpp): while one is dragged the mouse does nothing else.
  const bool planeDragged = mono && monoPlaneHandle(canvas, hovered);
  const bool cornerDragged = mono && surfaceHandles3D(canvas, hovered);
  if (planeDragged || cornerDragged) hovered = false;
  StylusPick pick;
  if (hovered) pick = mouse3D(canvas, w, h);
  drawOverlays3D(cf, w, h, pick);
  ImGui::End();
}

// Results over the rendering: the trace tree, the cut's contour and the live-wire contour.
void ViewerWindow::drawResults3D(const Canvas3D& c) {
  const OverlaySettings& ov = c.ov;
  const Geometry& g = c.g;
  // The trace: its refined centreline once the run ended (the saved tree), the voxel paths
  // while it runs.
  // Coloured by the measured diameter (color-by diameter), the legend at the view's right edge.
  if (const ColouredPieces* cp = app_.profile().colouredTree()) {
    for (size_t k = 0; k < cp->pieces.size(); ++k) {
      const auto& rgb = cp->colours[k];
      c.polyline(cp->pieces[k].points, overlayColour(ov, int(255 * rgb[0]), int(255 * rgb[1]), int(255 * rgb[2])), 3.0f,
                 false);
    }
    drawDiameterLegend(c.dl, c.m0, ImVec2(float(view3DSize_[0]), float(view3DSize_[1])), *cp);
  } else if (const Tree tree = app_.trace().tree(); tree.size() > 0) {
    for (const Polyline& line : tree.toPolylines())
      c.polyline(line.points, overlayColour(ov, 255, 60, 40), 2.5f, false);
  } else {
    for (const auto& path : app_.trace().paths()) {
      std::vector<Vec3> pts;
      for (const auto& v : path.voxels) pts.push_back(c.worldOf(v));
      c.polyline(pts, overlayColour(ov, 255, 60, 40), 2.5f, false);
    }
  }
  if (const auto r = app_.cut().result()) c.polyline(r->contourMm, overlayColour(ov, 255, 0, 255), 2.5f, true);
  drawProfileSection3D(app_, c.dl, [&](const Vec3& w, ImVec2& o) { return c.project(w, o); });
  c.mesh(app_.surface().mesh(), {120 / 255.f, 190 / 255.f, 1.f});
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
      c.polyline(corners, colours[a], 1.0f, true);
    }
  }
  const auto& loaded = app_.loadedOverlays();
  for (size_t i = 0; i < loaded.size(); ++i) {
    const auto col = overlayPaletteColor(i);
    c.mesh(loaded[i].mesh, col);
    for (const Polyline& line : loaded[i].lines)
      c.polyline(line.points, overlayColour(ov, int(255 * col[0]), int(255 * col[1]), int(255 * col[2])), 2.0f,
                 line.closed);
  }
  const LiveWireTool& lw = app_.liveWire();
  const auto contour = lw.contour();
  ImVec2 prev;
  for (size_t k = 0; k < contour.pixels.size(); ++k) {
    ImVec2 q;
    if (c.project(c.worldOf(sliceToVolumeIndex(lw.axis(), lw.index(), contour.pixels[k])), q)) {
      if (k) c.dl->AddLine(prev, q, overlayColour(ov, 255, 220, 0), 2.0f);
      prev = q;
    }
  }
}

// The mouse in the 3D view: zoom, pan, rotate; the stylus (the first visible point under the
// mouse, snapped, drawn as a shaded sphere) and a click giving it to the 3D tool. Returns the
// stylus' surface point for the cut's live contour.
StylusPick ViewerWindow::mouse3D(const Canvas3D& c, int w, int h) {
  const CameraFrame& cf = c.cf;
  const ImVec2 m0 = c.m0;
  ImGuiIO& io = ImGui::GetIO();
  if (cutBoxDrag(c)) return {};
  if (io.MouseWheel != 0)
    act("zoom", [&] { app_.setZoom(std::clamp(app_.view().zoom * std::pow(1.1, io.MouseWheel), 0.1, 20.0)); });
  if (ImGui::IsMouseDragging(ImGuiMouseButton_Right))  // zoom in when dragging up (Slicer: right drag)
    act("zoom", [&] { app_.setZoom(std::clamp(app_.view().zoom * std::exp(-io.MouseDelta.y * 0.01), 0.1, 20.0)); });
  if (ImGui::IsMouseDragging(ImGuiMouseButton_Middle) ||
      (io.KeyShift && ImGui::IsMouseDragging(ImGuiMouseButton_Left))) {
    // Pan (Slicer: middle drag, polyscope: shift+left): the picture follows the mouse at the
    // depth of the volume's centre.
    const Camera& cam = cf.camera();
    const double mmPerPixel = cf.pixelSizeAt((cam.target - cam.eye).dot(cf.forward()));
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
  // Stylus: the first visible point under the mouse (side-by-side: through the camera of the eye
  // under it), snapped; drawOverlays3D draws it as a shaded sphere.
  const double mx = std::clamp(double(io.MousePos.x - m0.x), 0.0, w - 1e-3),
               my = std::clamp(double(io.MousePos.y - m0.y), 0.0, h - 1e-3);
  const StylusPick pick = app_.stylusPick(mx, my, w, h);
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
  return pick;
}

}  // namespace vs::viewer::window_detail
