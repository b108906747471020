// The surface tool's view (issue 23: one file per tool view; thesis 5.2): its panel, the corner
// handles (three per octant, one per half-line from the planes' centre) in the slice views and
// the 3D view, the chosen side contour with its via points, and the mouse: drag a corner along
// its half-line (a new extraction), Ctrl+click on the chosen side's plane adds a via point (only
// the octants sharing that side are re-subdivided, app/surface_tool.cpp), a click elsewhere moves
// the planes' centre as before.
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

namespace {
constexpr float kCornerPx = 7;  // a corner handle's radius on the screen
const ImU32 kCornerColour = IM_COL32(255, 80, 200, 255);
const ImU32 kSideColour = IM_COL32(255, 170, 60, 255);

// The corner dragged to voxel-index coordinate t along its half-line (the centre elsewhere).
Index3 alongHalfLine(const Index3& centre, int h, int64_t t) {
  Index3 p = centre;
  p[size_t(h / 2)] = t;
  return p;
}
}  // namespace

void ViewerWindow::surfacePanel() {
  SurfaceTool& sf = app_.surface();
  ImGui::TextWrapped("three planes through the cursor (click a point, or move the crosshair)");
  int level = sf.level();
  if (ImGui::SliderInt("level of detail", &level, 0, 6)) act("surface", [&] { sf.setLevel(level); });
  bool closed = sf.closed();
  if (ImGui::Checkbox("closed (8 octants)", &closed)) sf.setClosed(closed);
  jobControls();
  const TriMesh m = sf.mesh();
  ImGui::Text("%zu triangles", m.triangles.size());
  if (!sf.lastRun().empty()) ImGui::TextWrapped("%s", sf.lastRun().c_str());
  const auto sides = sf.sides();
  if (!sides.empty() && ImGui::BeginCombo("side to edit", sf.selectedSide().c_str())) {
    for (const auto& [name, path] : sides)
      if (ImGui::Selectable(name.c_str(), name == sf.selectedSide())) act("surface", [&] { sf.selectSide(name); });
    ImGui::EndCombo();
  }
  ImGui::Text("%zu via points on %s", sf.via(sf.selectedSide()).size(), sf.selectedSide().c_str());
  flowOnSameLine(radioWidth("Clear via"));
  if (ImGui::SmallButton("Clear via")) sf.clearVia();
  flowOnSameLine(radioWidth("Reset corners"));
  if (ImGui::SmallButton("Reset corners")) sf.clearCorners();
  checkFits("Reset corners");
  ImGui::TextWrapped(
      "drag a corner (magenta) along its axis; Ctrl+click on the side's plane: a via point; "
      "Enter runs again");
}

// Corners on this slice (those lying in its plane), the chosen side and its via points.
void ViewerWindow::drawSurfaceOnSlice(int axis, const SliceFit& fit, ImVec2 v0, ImDrawList* dl) {
  const SurfaceTool& sf = app_.surface();
  if (!sf.hasResult()) return;
  const int64_t index = fit.layout.index;
  const int uAxis = axis == 0 ? 1 : 0, vAxis = axis == 2 ? 1 : 2;
  auto screen = [&](const Index3& p) {
    const auto q = fit.viewOf(double(p[size_t(uAxis)]), double(p[size_t(vAxis)]));
    return ImVec2(v0.x + float(q[0]), v0.y + float(q[1]));
  };
  for (const auto& [name, path] : sf.sides())
    if (name == sf.selectedSide() && name[0] == "xyz"[axis] && !path.empty() && path[0][size_t(axis)] == index)
      for (size_t k = 1; k < path.size(); ++k) dl->AddLine(screen(path[k - 1]), screen(path[k]), kSideColour, 3);
  for (const Index3& p : sf.via(sf.selectedSide()))
    if (p[size_t(axis)] == index) dl->AddCircle(screen(p), 5, rgb(255, 255, 255), 12, 2);
  const auto corners = sf.corners();
  const Index3 centre = sf.planes();
  for (int h = 0; h < 6; ++h) {
    if (!corners[size_t(h)]) continue;
    const bool dragged = dragCorner_ && *dragCorner_ == h;
    const Index3 p = dragged ? alongHalfLine(centre, h, dragCornerTo_) : *corners[size_t(h)];
    if (p[size_t(axis)] != index) continue;
    const ImVec2 q = screen(p);
    dl->AddCircleFilled(q, dragged ? kCornerPx - 2 : kCornerPx - 2, kCornerColour, 16);
    if (dragged) dl->AddCircle(q, kCornerPx + 1, rgb(255, 255, 255), 16, 2);
  }
}

void ViewerWindow::surfaceMouse(int axis, const SliceFit& fit, ImVec2 v0, bool hovered) {
  ImGuiIO& io = ImGui::GetIO();
  SurfaceTool& sf = app_.surface();
  const int64_t index = fit.layout.index;
  const std::optional<PixelUV> picked = fit.pickAt(io.MousePos.x - v0.x, io.MousePos.y - v0.y);
  const Index3 centre = sf.planes();
  if (dragCorner_) {  // the corner follows the mouse along its half-line; released: a new run
    const int h = *dragCorner_;
    if (centre[size_t(axis)] != index || axis == h / 2) return;  // another view
    if (picked) dragCornerTo_ = sliceToVolumeIndex(axis, index, *picked)[size_t(h / 2)];
    if (!ImGui::IsMouseReleased(ImGuiMouseButton_Left)) return;
    dragCorner_.reset();
    const Index3 to = alongHalfLine(centre, h, dragCornerTo_);
    if (sf.corners()[size_t(h)] != std::optional<Index3>(to))
      act("corner", [&] {
        sf.setCorner(h, to);
        if (!app_.computing()) app_.run(false);
      });
    return;
  }
  if (!hovered || !picked || !ImGui::IsMouseClicked(ImGuiMouseButton_Left) || io.KeyShift) return;
  const Index3 voxel = sliceToVolumeIndex(axis, index, *picked);
  // A corner handle under the mouse: start dragging it.
  const int uAxis = axis == 0 ? 1 : 0, vAxis = axis == 2 ? 1 : 2;
  const auto corners = sf.corners();
  for (int h = 0; h < 6 && !io.KeyCtrl; ++h) {
    const auto& c = corners[size_t(h)];
    if (!c || (*c)[size_t(axis)] != index) continue;
    const auto q = fit.viewOf(double((*c)[size_t(uAxis)]), double((*c)[size_t(vAxis)]));
    const double dx = io.MousePos.x - v0.x - q[0], dy = io.MousePos.y - v0.y - q[1];
    if (dx * dx + dy * dy <= double(kCornerPx * kCornerPx) * 2) {
      dragCorner_ = h;
      dragCornerTo_ = (*c)[size_t(h / 2)];
      return;
    }
  }
  if (io.KeyCtrl) {  // a via point of the chosen side, on its plane
    const std::string& side = sf.selectedSide();
    if (!sf.hasResult() || side[0] != "xyz"[axis] || centre[size_t(axis)] != index) {
      status_ = "via point: Ctrl+click on the plane of side " + side + " (the " + std::string(1, side[0]) +
                " slice through the planes' centre)";
      return;
    }
    act("via point", [&] {
      sf.addVia(voxel);
      if (!app_.computing()) app_.run(false);
    });
    return;
  }
  act("point", [&] { app_.point3(voxel); });  // the planes' centre, as before
}

// The corners in the 3D view; a drag moves the one grabbed along its half-line (the index whose
// projection is nearest to the mouse, as the monoplanar plane's handle). True while dragging.
bool ViewerWindow::surfaceHandles3D(const Canvas3D& c, bool hovered) {
  SurfaceTool& sf = app_.surface();
  if (app_.tool() != ToolKind::Surface || !sf.hasResult()) return false;
  ImGuiIO& io = ImGui::GetIO();
  const Index3 centre = sf.planes();
  const auto corners = sf.corners();
  std::optional<int> under;
  for (int h = 0; h < 6; ++h) {
    if (!corners[size_t(h)]) continue;
    const bool dragged = dragCorner3D_ && *dragCorner3D_ == h;
    ImVec2 q;
    if (!c.project(c.worldOf(dragged ? alongHalfLine(centre, h, dragCornerTo_) : *corners[size_t(h)]), q)) continue;
    c.dl->AddCircleFilled(q, kCornerPx, kCornerColour, 16);
    c.dl->AddCircle(q, kCornerPx, rgb(255, 255, 255), 16, dragged ? 2.5f : 1.0f);
    const float dx = io.MousePos.x - q.x, dy = io.MousePos.y - q.y;
    if (hovered && dx * dx + dy * dy <= kCornerPx * kCornerPx * 2) under = h;
  }
  if (!dragCorner3D_ && under && !dragCorner_ && ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift) {
    dragCorner3D_ = *under;
    dragCornerTo_ = (*corners[size_t(*under)])[size_t(*under / 2)];
  }
  if (!dragCorner3D_) return false;
  const int h = *dragCorner3D_, a = h / 2;
  double best = 1e300;
  for (int64_t t = 0; t < c.g.dims[a]; ++t) {
    ImVec2 s;
    if (!c.project(c.worldOf(alongHalfLine(centre, h, t)), s)) continue;
    const double d =
        double(s.x - io.MousePos.x) * (s.x - io.MousePos.x) + double(s.y - io.MousePos.y) * (s.y - io.MousePos.y);
    if (d < best) best = d, dragCornerTo_ = t;
  }
  if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
    dragCorner3D_.reset();
    const Index3 to = alongHalfLine(centre, h, dragCornerTo_);
    if (sf.corners()[size_t(h)] != std::optional<Index3>(to))
      act("corner", [&] {
        sf.setCorner(h, to);
        if (!app_.computing()) app_.run(false);
      });
  }
  return true;
}

}  // namespace vs::viewer::window_detail
