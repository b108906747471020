// The cut tool's view in the 3D view: the loop the cut will use (CutTool::liveContour: the core's
// cutContour on the cut's mesh, closed), the points, and the stylus sphere at the point a click
// gives the tool (ViewerApp::stylusTarget).
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

// The previewed loop: magenta through the points, green while it runs through the hovered point;
// the points in orange; the core's reason in orange text when the points give no loop.
void ViewerWindow::drawCutContour3D(const Canvas3D& c, const CutTool::LiveContour& live) {
  const OverlaySettings& ov = c.ov;
  const ImU32 colour = live.withHover ? overlayColour(ov, 60, 255, 120) : overlayColour(ov, 255, 0, 255);
  c.polyline(live.path, colour, 2.0f, live.closed);
  for (const Vec3& p : app_.cut().points()) {
    ImVec2 q;
    if (c.project(c.g.indexToWorld(p), q)) c.dl->AddCircleFilled(q, 4, overlayColour(ov, 255, 140, 0));
  }
  if (!live.problem.empty())
    c.dl->AddText(ImVec2(c.m0.x + 6, c.m0.y + 6), overlayColour(ov, 255, 180, 80), live.problem.c_str());
}

// A shaded sphere centred on the point a click would give the current tool; its radius is the
// cut's snap radius (the surface within it is where the point may land), else the snap radius.
void ViewerWindow::drawStylus3D(const Canvas3D& c, const StylusPick& pick) {
  ImVec2 q;
  double depth = 0;
  if (!c.project(c.g.indexToWorld(app_.stylusTarget(pick)), q, depth)) return;
  const double radiusMm =
      app_.tool() == ToolKind::Cut ? app_.cut().snapRadiusMm() : std::max(app_.snap(), 1.5) * c.g.spacing.minCoeff();
  const float r = std::max(5.f, float(radiusMm / c.cf.pixelSizeAt(std::max(depth, 1e-3))));
  c.dl->AddCircleFilled(q, r, rgb(40, 160, 255, 200), 24);
  c.dl->AddCircleFilled(ImVec2(q.x - r * 0.3f, q.y - r * 0.3f), r * 0.35f, rgb(200, 235, 255, 220), 12);
  c.dl->AddCircle(q, r, rgb(255, 255, 255, 220), 24, 1.5f);
}

}  // namespace vs::viewer::window_detail
