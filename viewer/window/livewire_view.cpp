// The live-wire tool's view (issue 23: one file per tool view): its panel, its contour on the
// slice, and its mouse, including the anchor editing of thesis 5.2 (insert, move, delete; each
// re-wires the contour between the neighbours, app/livewire_edit.cpp).
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

namespace {
constexpr float kGrabPx = 7;  // screen pixels around an anchor or the contour that pick it
}

void ViewerWindow::liveWirePanel() {
  LiveWireTool& lw = app_.liveWire();
  ImGui::Text("slice %c=%lld  anchors %zu", "xyz"[lw.axis()], (long long)lw.index(), lw.clicks().size());
  const LiveWireContour c = lw.contour();
  ImGui::Text("contour %zu px, %.1f mm%s", c.pixels.size(), c.lengthMm, c.closed ? ", closed" : "");
  if (ImGui::Button("Close contour (c)")) act("close", [&] { app_.closeContour(); });
  int cooling = lw.cooling();
  ImGui::SetNextItemWidth(120);
  if (ImGui::SliderInt("path cooling (moves)", &cooling, 0, 20, cooling == 0 ? "off" : "%d"))
    act("path cooling", [&] { lw.setCooling(cooling); });
  checkFits("path cooling");
  ImGui::TextWrapped(
      "Ctrl+click on the contour: insert an anchor; drag an anchor: move it; right-click or Del on "
      "an anchor: delete it");
}

void ViewerWindow::drawLiveWireOnSlice(int axis, const SliceFit& fit, ImVec2 v0, ImDrawList* dl) {
  const LiveWireTool& lw = app_.liveWire();
  if (lw.axis() != axis || lw.index() != fit.layout.index) return;
  const OverlaySettings& ov = app_.overlays();
  auto screen = [&](const PixelUV& p) {
    const auto q = fit.viewOf(double(p[0]), double(p[1]));
    return ImVec2(v0.x + float(q[0]), v0.y + float(q[1]));
  };
  const auto contour = lw.contour();
  const ImU32 yellow = overlayColour(ov, 255, 220, 0);
  for (size_t k = 1; k < contour.pixels.size(); ++k)
    dl->AddLine(screen(contour.pixels[k - 1]), screen(contour.pixels[k]), yellow, 2);
  if (contour.closed && contour.pixels.size() > 1)
    dl->AddLine(screen(contour.pixels.back()), screen(contour.pixels[0]), yellow, 2);
  const auto& live = lw.livePath();
  for (size_t k = 1; k < live.size(); ++k) dl->AddLine(screen(live[k - 1]), screen(live[k]), rgb(60, 255, 120), 2);
  const auto& anchors = lw.clicks();
  for (size_t k = 0; k < anchors.size(); ++k) {
    const bool dragged = dragAnchor_ && *dragAnchor_ == k;
    const ImVec2 q = screen(dragged ? dragTo_ : anchors[k]);
    if (dragged)
      dl->AddRect(ImVec2(q.x - 5, q.y - 5), ImVec2(q.x + 5, q.y + 5), rgb(255, 140, 0), 0, 0, 2);
    else
      dl->AddRectFilled(ImVec2(q.x - 3, q.y - 3), ImVec2(q.x + 3, q.y + 3), rgb(255, 140, 0));
  }
}

void ViewerWindow::liveWireMouse(int axis, const SliceFit& fit, ImVec2 v0, bool hovered) {
  ImGuiIO& io = ImGui::GetIO();
  LiveWireTool& lw = app_.liveWire();
  const SliceLayout& L = fit.layout;
  const double px = io.MousePos.x - v0.x, py = io.MousePos.y - v0.y;
  const std::optional<PixelUV> picked = fit.pickAt(px, py);
  const bool onWireSlice = lw.axis() == axis && lw.index() == L.index;
  if (dragAnchor_) {  // an anchor follows the mouse; released: it moves there (one undo step)
    if (!onWireSlice) return;
    if (picked) dragTo_ = *picked;
    if (!ImGui::IsMouseReleased(ImGuiMouseButton_Left)) return;
    const size_t k = *std::exchange(dragAnchor_, std::nullopt);
    if (k < lw.clicks().size() && dragTo_ != lw.clicks()[k])
      act("move anchor", [&] { lw.moveAnchor(k, dragTo_); });
    else if (k + 1 == lw.clicks().size() || lw.contour().closed)
      status_.clear();  // a click on the current end (or a closed contour's anchor) adds nothing
    else
      act("point", [&] { app_.point2(dragTo_); });  // a plain click on an earlier anchor: a point there
    return;
  }
  if (!hovered || !picked) return;
  const PixelUV uv = *picked;
  const bool click = ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift;
  // The first click of a contour moves the tool to the clicked view's slice.
  if (!lw.hasContour() && !onWireSlice && click) act("live-wire", [&] { lw.setSlice(axis, L.index); });
  if (lw.axis() != axis || lw.index() != L.index) return;
  const double grab = std::max(1.0, kGrabPx * double(L.width) / fit.w);  // in slice pixels
  if (uv != lastHover_) {
    act("live-wire", [&] { lw.hover(uv); });
    lastHover_ = uv;
  }
  const std::optional<size_t> anchor = lw.anchorNear(uv, grab);
  if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) {
    act("close", [&] { app_.closeContour(); });
  } else if (click && io.KeyCtrl) {
    const std::optional<size_t> segment = lw.segmentNear(uv, grab);
    if (segment)
      act("insert anchor", [&] { lw.insertAnchor(*segment, uv); });
    else
      status_ = "insert anchor: Ctrl+click on the contour (none within " + std::to_string(int(kGrabPx)) + " px)";
  } else if (click && anchor) {
    dragAnchor_ = anchor;  // a drag moves it; a click without a move is an ordinary point
    dragTo_ = lw.clicks()[*anchor];
  } else if (click) {
    act("point", [&] { app_.point2(uv); });
  }
  // Right-click (no drag: a right drag is window/level) or Delete on an anchor removes it.
  const bool rightClick = ImGui::IsMouseReleased(ImGuiMouseButton_Right) && io.MouseDragMaxDistanceSqr[1] < 16;
  const bool deleteKey = !io.WantCaptureKeyboard && (ImGui::IsKeyPressed(GLFW_KEY_DELETE, false) ||
                                                     ImGui::IsKeyPressed(GLFW_KEY_BACKSPACE, false));
  if ((rightClick || deleteKey) && anchor) act("delete anchor", [&] { lw.removeAnchor(*anchor); });
}

}  // namespace vs::viewer::window_detail
