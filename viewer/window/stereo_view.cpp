// What is drawn over the 3D picture, in mono and in stereo: the tools' results, the cut's previewed
// loop and the stylus sphere, once per eye through that eye's camera (app/stereo.h, the matrices
// the ray caster drew the eye with) inside that eye's viewport; in anaglyph each eye's overlay in
// its filter's colours (left red, right cyan) and channels, so both eyes see every result at its
// own disparity.
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

// Anaglyph: each eye's overlay writes only its filter's channels (as the ray caster's eyes do), so
// the right eye's overlay does not paint over the left eye's red. ImGui's OpenGL 3 backend leaves
// the colour mask alone, so the last callback restores it.
void writeRedOnly(const ImDrawList*, const ImDrawCmd*) { glColorMask(GL_TRUE, GL_FALSE, GL_FALSE, GL_TRUE); }
void writeCyanOnly(const ImDrawList*, const ImDrawCmd*) { glColorMask(GL_FALSE, GL_TRUE, GL_TRUE, GL_TRUE); }
void writeAll(const ImDrawList*, const ImDrawCmd*) { glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE); }

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
    const bool anaglyph = mode == StereoMode::Anaglyph;
    if (anaglyph) dl->AddCallback(e.eye < 0 ? writeRedOnly : writeCyanOnly, nullptr);
    const int first = dl->VtxBuffer.Size;
    drawEye(c);
    if (anaglyph) {
      tintForEye(dl, first, e.eye);
      dl->AddCallback(writeAll, nullptr);
    }
    dl->PopClipRect();
  }
}

}  // namespace vs::viewer::window_detail
