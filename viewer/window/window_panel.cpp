// The window's side panel: files, display, the tools' controls, transfer function, labels, help.
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

namespace {

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
    "Keys\n";  // then app/key_bindings.h's table

}  // namespace

// ---------------------------------------------------------------- panel
void ViewerWindow::panel(float H) {
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
  if (ImGui::CollapsingHeader("Help (h)", ImGuiTreeNodeFlags_DefaultOpen)) {
    static const std::string help = std::string(kHelp) + keyHelpText();  // the keys from their one table
    ImGui::TextUnformatted(help.c_str());
  }
  if (!status_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", status_.c_str());
  ImGui::End();
}

// Puts the next item (width px) on the current line if it fits in the panel, else on a new one.
void ViewerWindow::flowOnSameLine(float width) {
  const ImGuiStyle& style = ImGui::GetStyle();
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  if (ImGui::GetItemRectMax().x + style.ItemSpacing.x + width <= right) ImGui::SameLine();
}

// Says on stderr (once per item) when the last item runs past the panel's right edge: a control
// the user cannot see (tests look for the message at several window sizes).
void ViewerWindow::checkFits(const char* name) {
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  if (ImGui::GetItemRectMax().x > right + 0.5f && clipped_.insert(name).second)
    std::cerr << "volscissors: warning: the panel's control '" << name << "' is cut off\n";
}

void ViewerWindow::tracePanel() {
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

void ViewerWindow::jobControls() {
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
void ViewerWindow::tfEditorPanel() {
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
    dl->AddRectFilled(ImVec2(p0.x + bw * float(b), yOf(histogram_[b])), ImVec2(p0.x + bw * float(b + 1), p0.y + size.y),
                      rgb(80, 80, 90));
  const auto& pts = ed.tf().points();
  for (size_t i = 1; i < pts.size(); ++i)
    dl->AddLine(ImVec2(xOf(pts[i - 1].value), yOf(pts[i - 1].opacity)), ImVec2(xOf(pts[i].value), yOf(pts[i].opacity)),
                rgb(240, 240, 240), 1.5f);
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

void ViewerWindow::cutPanel() {
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
  ImGui::SetNextItemOpen(true, ImGuiCond_Once);  // shown, with their defaults, until folded
  if (ImGui::CollapsingHeader("weights (as cut --wg ...)")) {
    // The core's weights with their defaults (the CLI's); a new value applies to the next Run.
    const CutWeights defaults = defaultCutWeights();
    CutWeights w = cut.weights();
    for (const CutWeightName& n : cutWeightNames()) {
      double v = w.*n.field;
      ImGui::SetNextItemWidth(90);
      if (ImGui::InputDouble(n.key, &v, 0, 0, "%.4g", ImGuiInputTextFlags_EnterReturnsTrue)) {
        w.*n.field = v;
        act("cut weights", [&] { cut.setWeights(w); });
      }
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", n.description);
      ImGui::SameLine();
      ImGui::TextDisabled("default %.4g", defaults.*n.field);
    }
    if (!(w == defaults) && ImGui::Button("default weights")) act("cut weights", [&] { cut.setWeights(defaults); });
  }
  jobControls();
  if (const auto r = cut.result())
    ImGui::Text("kept %lld voxels, cut away %lld", (long long)r->keptVoxels, (long long)r->cutVoxels);
}

void ViewerWindow::labelsPanel() {
  ImGui::InputText("##labels", labelsPath_, sizeof labelsPath_);
  ImGui::SameLine();
  if (ImGui::Button("Load labels")) act("labels", [&] { app_.loadLabels(labelsPath_); });
  ImGui::InputText("##overlay", overlayPath_, sizeof overlayPath_);
  ImGui::SameLine();
  if (ImGui::Button("Add overlay")) act("overlay", [&] { app_.addOverlay(overlayPath_); });
  const auto& loaded = app_.loadedOverlays();
  for (size_t i = 0; i < loaded.size(); ++i) {
    const auto c = overlayPaletteColor(i);
    ImGui::ColorButton(("##o" + std::to_string(i)).c_str(), ImVec4(c[0], c[1], c[2], 1), ImGuiColorEditFlags_NoTooltip,
                       ImVec2(12, 12));
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

}  // namespace vs::viewer::window_detail
