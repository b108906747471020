// The cut box's handles in the 3D view (cut-box mode): a disc at the centre of each face, drawn in
// the axis' colour (x red, y green, z blue); pressing the left button on one and dragging moves that
// face along its axis by the mouse's motion along the axis' direction on the screen
// (app/cut_box.h). Released, the box stays (the session keeps it; `cut-box auto` returns to the
// box below the cursor).
#include "app/cut_box.h"
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

namespace {
constexpr float kHandleRadius = 6, kGrabRadius = 10;
const ImU32 kAxisColour[3] = {IM_COL32(230, 80, 70, 230), IM_COL32(90, 210, 90, 230), IM_COL32(80, 140, 240, 230)};
}  // namespace

void ViewerWindow::drawCutBoxHandles(const Canvas3D& c) {
  if (app_.view().mode != RenderMode::CutBox) return;
  const CutBox box = app_.cutBox();
  for (int f = 0; f < 6; ++f) {
    ImVec2 q;
    if (!c.project(c.g.indexToWorld(cutBoxHandle(box, f)), q)) continue;
    const bool held = f == boxFace_;
    c.dl->AddCircleFilled(q, held ? kHandleRadius + 2 : kHandleRadius, kAxisColour[f % 3], 16);
    c.dl->AddCircle(q, held ? kHandleRadius + 2 : kHandleRadius, IM_COL32(255, 255, 255, 230), 16, 1.5f);
  }
}

bool ViewerWindow::cutBoxDrag(const Canvas3D& c) {
  ImGuiIO& io = ImGui::GetIO();
  if (app_.view().mode != RenderMode::CutBox) {
    boxFace_ = -1;
    return false;
  }
  const CutBox box = app_.cutBox();
  if (boxFace_ < 0 && ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift) {
    float best = kGrabRadius;
    for (int f = 0; f < 6; ++f) {
      ImVec2 q;
      if (!c.project(c.g.indexToWorld(cutBoxHandle(box, f)), q)) continue;
      const float d = std::hypot(q.x - io.MousePos.x, q.y - io.MousePos.y);
      if (d <= best) best = d, boxFace_ = f;
    }
    if (boxFace_ < 0) return false;
    boxAtGrab_ = box;
    mouseAtGrab_ = io.MousePos;
  }
  if (boxFace_ < 0) return false;
  const int f = boxFace_;
  Vec3 along = cutBoxHandle(boxAtGrab_, f);
  along[f % 3] += 1;
  ImVec2 h, a;
  if (c.project(c.g.indexToWorld(cutBoxHandle(boxAtGrab_, f)), h) && c.project(c.g.indexToWorld(along), a)) {
    const double shift =
        cutBoxFaceShift({h.x, h.y}, {a.x, a.y}, {io.MousePos.x - mouseAtGrab_.x, io.MousePos.y - mouseAtGrab_.y});
    act("cut box",
        [&] { app_.setCutBox(movedCutBoxFace(boxAtGrab_, f, boxAtGrab_[size_t(f)] + shift, app_.geometry().dims)); });
  }
  if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
    boxFace_ = -1;
    dragged_ = false;  // the release ends the drag; it is no click for the tools
  }
  return true;
}

}  // namespace vs::viewer::window_detail
