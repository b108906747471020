// The monoplanar mode's plane in the 3D view (thesis ch. 5: the four display modes; issue 27: the
// plane was fixed to z): its outline and a handle at its centre with an arrow along its normal.
// Dragging the handle moves the plane along its axis (the linked cursor, so the slice views
// follow); `a` over the 3D view turns the plane to the next axis. Script: `mono-plane x|y|z[=K]`.
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

namespace {
constexpr float kHandlePx = 8;  // the handle's radius on the screen
}

bool ViewerWindow::monoPlaneHandle(const Canvas3D& c, bool hovered) {
  if (app_.view().mode != RenderMode::Monoplanar) {
    planeDrag_.reset();
    return false;
  }
  ImGuiIO& io = ImGui::GetIO();
  const Geometry& g = c.g;
  const int a = app_.view().monoAxis;
  Index3 cursor = app_.view().cursor;
  if (hovered && !io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_A, false)) {
    act("plane", [&] { app_.setMonoAxis((a + 1) % 3); });
    return false;
  }
  // The plane's centre, and one voxel along its normal, on the screen.
  Vec3 centre(double(g.dims[0] - 1) / 2, double(g.dims[1] - 1) / 2, double(g.dims[2] - 1) / 2);
  centre[a] = double(cursor[size_t(a)]);
  ImVec2 q, q1;
  if (!c.project(g.indexToWorld(centre), q) || !c.project(g.indexToWorld(centre + Vec3::Unit(a)), q1)) return false;
  const ImVec2 perVoxel(q1.x - q.x, q1.y - q.y);
  // Outline and handle: the plane's rectangle, the normal as an arrow of a tenth of the volume.
  const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
  std::vector<Vec3> corners;
  for (const auto& [cu, cv] : {std::pair{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}}) {
    Vec3 i = centre;
    i[u] = cu * double(g.dims[u] - 1);
    i[v] = cv * double(g.dims[v] - 1);
    corners.push_back(g.indexToWorld(i));
  }
  const ImU32 cyan = rgb(0, 220, 255);
  c.polyline(corners, cyan, 1.5f, true);
  const float arrow = float(0.1 * double(g.dims[a]));
  c.dl->AddLine(q, ImVec2(q.x + perVoxel.x * arrow, q.y + perVoxel.y * arrow), cyan, 2);
  const float dx = io.MousePos.x - q.x, dy = io.MousePos.y - q.y;
  const bool overHandle = hovered && dx * dx + dy * dy <= kHandlePx * kHandlePx * 2;
  c.dl->AddCircleFilled(q, kHandlePx, overHandle || planeDrag_ ? rgb(255, 255, 255) : cyan, 16);
  if (!planeDrag_ && overHandle && ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift)
    planeDrag_ = PlaneDrag{io.MousePos.x - q.x, io.MousePos.y - q.y};
  if (!planeDrag_) return false;
  // Dragged: the plane goes to the index whose handle is nearest to the mouse (less where on the
  // handle it was grabbed), so the handle stays under the mouse whatever the perspective.
  const ImVec2 want(io.MousePos.x - planeDrag_->grabX, io.MousePos.y - planeDrag_->grabY);
  double best = 1e300;
  for (int64_t k = 0; k < g.dims[a]; ++k) {
    Vec3 i = centre;
    i[a] = double(k);
    ImVec2 s;
    if (!c.project(g.indexToWorld(i), s)) continue;
    const double d = double(s.x - want.x) * (s.x - want.x) + double(s.y - want.y) * (s.y - want.y);
    if (d < best) {
      best = d;
      cursor[size_t(a)] = k;
    }
  }
  if (cursor != app_.view().cursor) act("plane", [&] { app_.setCursor(cursor); });
  if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) planeDrag_.reset();
  return true;
}

}  // namespace vs::viewer::window_detail
