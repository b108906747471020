// What is drawn over the 3D picture, in mono and in stereo: the tools' results, the cut's previewed
// loop and the stylus sphere, once per eye through that eye's camera (app/stereo.h, the matrices
// the ray caster drew the eye with) inside that eye's viewport; in anaglyph each eye's overlay in
// its filter's colours (left red, right cyan), so both eyes see every result at its own disparity.
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

namespace {

// The overlay vertices from `first` on in one eye's anaglyph colours: the brightest channel in red
// (left) or in green and blue (right), alpha kept.
void tintForEye(ImDrawList* dl, int first, int eye) {
  for (int i = first; i < dl->VtxBuffer.Size; ++i) {
    ImU32& col = dl->VtxBuffer[i].col;
    const ImU32 r = col & 0xff, g = (col >> 8) & 0xff, b = (col >> 16) & 0xff, a = col & 0xff000000u;
    const ImU32 l = std::max(r, std::max(g, b));
    col = a | (eye < 0 ? l : (l << 8) | (l << 16));
  }
}

}  // namespace

void ViewerWindow::drawOverlays3D(const CameraFrame& cf, int w, int h, const StylusPick& pick) {
  StereoMode mode = raycaster_ ? app_.view().stereo : StereoMode::Off;  // the CPU renderer draws one view
  if (mode == StereoMode::Quad) mode = quadBuffer_ ? StereoMode::Off : StereoMode::Anaglyph;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  CutTool::LiveContour live;
  if (app_.tool() == ToolKind::Cut)
    live = app_.cut().liveContour(pick.hit ? std::optional<Vec3>(app_.stylusTarget(pick)) : std::nullopt);
  auto drawEye = [&](const Canvas3D& c) {
    drawResults3D(c);
    if (app_.tool() == ToolKind::Cut) drawCutContour3D(c, live);
    if (pick.hit) drawStylus3D(c, pick);
    drawCutBoxHandles(c);
  };
  if (mode == StereoMode::Off) {
    drawEye(Canvas3D{cf, view3DMin_, dl, app_.geometry(), app_.overlays()});
    return;
  }
  const std::vector<StereoEye> eyes = stereoEyes(app_, mode, w, h);
  for (const StereoEye& e : eyes) {
    const Canvas3D c{cf, ImVec2(view3DMin_.x + float(e.x0), view3DMin_.y), dl, app_.geometry(), app_.overlays(), &e};
    dl->PushClipRect(c.m0, ImVec2(c.m0.x + float(e.width), c.m0.y + float(e.height)), true);
    const int first = dl->VtxBuffer.Size;
    drawEye(c);
    if (mode == StereoMode::Anaglyph) tintForEye(dl, first, e.eye);
    dl->PopClipRect();
  }
}

}  // namespace vs::viewer::window_detail
