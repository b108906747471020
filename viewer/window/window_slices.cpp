// The window's three slice views: the slice picture, results on it, the mouse.
#include "window/window_impl.h"

namespace vs::viewer::window_detail {

// ---------------------------------------------------------------- slice views
void ViewerWindow::sliceView(int axis, ImVec2 pos, ImVec2 size) {
  ImGui::SetNextWindowPos(pos, ImGuiCond_Always);
  ImGui::SetNextWindowSize(size, ImGuiCond_Always);
  if (!app_.hasVolume()) return;
  const Index3 cursor = app_.view().cursor;
  const SliceLayout L =
      sliceLayout(app_.geometry(), axis, cursor[static_cast<size_t>(axis)]);  // volume/slice.h's frame
  const std::string title = L.plane + " " + "xyz"[axis] + "=" + std::to_string(cursor[static_cast<size_t>(axis)]) +
                            "###slice" + std::to_string(axis);
  ImGui::Begin(title.c_str(), nullptr, kViewFlags);
  updateSliceTexture(axis, L.index);
  const SliceTexture& t = slices_[axis];
  // The slice at its physical aspect ratio, zoomed and panned (SliceFit: picking follows).
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const ImVec2 v0 = ImGui::GetCursorScreenPos();
  const SliceFit fit = fitSlice(L, std::max(1.f, avail.x), std::max(1.f, avail.y), app_.view().sliceZoom[size_t(axis)],
                                app_.view().slicePan[size_t(axis)]);
  ImGui::InvisibleButton(
      "##slice", ImVec2(std::max(1.f, avail.x), std::max(1.f, avail.y)),
      ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight | ImGuiButtonFlags_MouseButtonMiddle);
  const bool hovered = ImGui::IsItemHovered();
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(v0, ImVec2(v0.x + avail.x, v0.y + avail.y), true);
  const ImVec2 m0(v0.x + float(fit.x0), v0.y + float(fit.y0));
  const ImVec2 imgSize(float(fit.w), float(fit.h));
  auto uvAt = [&](double sx, double sy) {
    const auto a = L.textureAt(sx, sy);
    return ImVec2(float(a[0]), float(a[1]));
  };
  dl->AddImageQuad(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(t.tex)), m0, ImVec2(m0.x + imgSize.x, m0.y),
                   ImVec2(m0.x + imgSize.x, m0.y + imgSize.y), ImVec2(m0.x, m0.y + imgSize.y), uvAt(0, 0), uvAt(1, 0),
                   uvAt(1, 1), uvAt(0, 1));
  auto screen = [&](double u, double v) {
    const auto p = fit.viewOf(u, v);
    return ImVec2(v0.x + float(p[0]), v0.y + float(p[1]));
  };
  const int uAxis = axis == 0 ? 1 : 0, vAxis = axis == 2 ? 1 : 2;
  // Linked crosshair: the lines of the cursor's u and v across the whole slice.
  const double cu = double(cursor[static_cast<size_t>(uAxis)]), cv = double(cursor[static_cast<size_t>(vAxis)]);
  const double uEnd = double(L.width) - 0.5, vEnd = double(L.height) - 0.5;
  dl->AddLine(screen(cu, -0.5), screen(cu, vEnd), rgb(80, 200, 80, 160));
  dl->AddLine(screen(-0.5, cv), screen(uEnd, cv), rgb(80, 200, 80, 160));
  // Anatomical labels on the view's edges (they stay put while the slice is zoomed or panned).
  const ImU32 lc = rgb(255, 200, 60);
  dl->AddText(ImVec2(v0.x + 4, v0.y + avail.y / 2 - 7), lc, L.left.c_str());
  dl->AddText(ImVec2(v0.x + avail.x - 12, v0.y + avail.y / 2 - 7), lc, L.right.c_str());
  dl->AddText(ImVec2(v0.x + avail.x / 2 - 4, v0.y + 2), lc, L.top.c_str());
  dl->AddText(ImVec2(v0.x + avail.x / 2 - 4, v0.y + avail.y - 16), lc, L.bottom.c_str());

  drawResultsOnSlice(axis, fit, v0, dl);
  drawProfileSectionOnSlice(app_, dl, axis, L.index, screen);
  dl->PopClipRect();
  if (hovered) handleSliceMouse(axis, fit, v0);
  if (app_.tool() == ToolKind::LiveWire && (hovered || dragAnchor_)) liveWireMouse(axis, fit, v0, hovered);
  if (app_.tool() == ToolKind::Surface && (hovered || dragCorner_)) surfaceMouse(axis, fit, v0, hovered);
  ImGui::End();
}

// The slice's texture, re-made when the volume, slice, window, labels or their display changed.
void ViewerWindow::updateSliceTexture(int axis, int64_t index) {
  SliceTexture& t = slices_[axis];
  const WindowLevel wl = app_.view().window;
  const OverlaySettings& ov = app_.overlays();
  if (t.revision != app_.volumeRevision() || t.index != index || t.window != wl.window || t.level != wl.level ||
      t.labelsRevision != app_.labelsRevision() || t.labelOpacity != ov.labelOpacity || t.hidden != ov.hiddenLabels) {
    const auto labels = app_.labels();
    const RgbaImage img = sliceImage(app_.floatVolume(), axis, index, wl, labels.get(), ov);
    uploadTexture(t.tex, img.width, img.height, img.pixels.data(), GL_NEAREST);
    t.revision = app_.volumeRevision();
    t.index = index;
    t.window = wl.window;
    t.level = wl.level;
    t.labelsRevision = app_.labelsRevision();
    t.labelOpacity = ov.labelOpacity;
    t.hidden = ov.hiddenLabels;
  }
}

// Results on a slice view: the trace, the surface, the trace's points, the live-wire on its
// slice, loaded overlays and the cut's points near the slice.
void ViewerWindow::drawResultsOnSlice(int axis, const SliceFit& fit, ImVec2 v0, ImDrawList* dl) {
  const SliceLayout& L = fit.layout;
  const OverlaySettings& ov = app_.overlays();
  const float scale = float(fit.w / L.screenWidthMm());  // view pixels per mm
  auto screen = [&](double u, double v) {
    const auto p = fit.viewOf(u, v);
    return ImVec2(v0.x + float(p[0]), v0.y + float(p[1]));
  };
  const int uAxis = axis == 0 ? 1 : 0, vAxis = axis == 2 ? 1 : 2;
  auto uvOf = [&](const Index3& i) {
    return std::array<double, 2>{double(i[static_cast<size_t>(uAxis)]), double(i[static_cast<size_t>(vAxis)])};
  };
  const Geometry& geo = app_.geometry();
  const float dot = std::max(2.f, scale * 0.6f);
  // Polylines (world mm) where they run within half a voxel of this slice: their pieces in that slab.
  auto linesOnSlice = [&](const std::vector<Polyline>& lines, ImU32 colour) {
    for (const Polyline& line : lines) {
      std::vector<Vec3> p;
      for (const Vec3& w : line.points) p.push_back(geo.worldToIndex(w) - Vec3::Unit(axis) * double(L.index));
      if (p.size() == 1 && std::abs(p[0][axis]) <= 0.5)
        dl->AddCircleFilled(screen(p[0][uAxis], p[0][vAxis]), dot, colour);
      for (size_t k = 1; k < p.size(); ++k) {
        const double a = p[k - 1][axis], b = p[k][axis];
        double lo = 0, hi = 1;
        if (a != b) {
          const double t1 = (-0.5 - a) / (b - a), t2 = (0.5 - a) / (b - a);
          lo = std::max(0.0, std::min(t1, t2));
          hi = std::min(1.0, std::max(t1, t2));
        } else if (std::abs(a) > 0.5) {
          continue;
        }
        if (lo > hi) continue;
        const Vec3 q0 = p[k - 1] + lo * (p[k] - p[k - 1]), q1 = p[k - 1] + hi * (p[k] - p[k - 1]);
        const ImVec2 s0 = screen(q0[uAxis], q0[vAxis]), s1 = screen(q1[uAxis], q1[vAxis]);
        dl->AddLine(s0, s1, colour, 2 * dot);
        dl->AddCircleFilled(ImVec2((s0.x + s1.x) / 2, (s0.y + s1.y) / 2), dot, colour);
      }
    }
  };
  // Meshes (world mm): where their triangles cross the slice's plane.
  auto meshOnSlice = [&](const TriMesh& mesh, ImU32 colour) {
    std::vector<Vec3> p;
    p.reserve(mesh.positions.size());
    for (const Vec3& w : mesh.positions) p.push_back(geo.worldToIndex(w) - Vec3::Unit(axis) * double(L.index));
    for (const auto& tri : mesh.triangles) {
      ImVec2 ends[2];
      int n = 0;
      for (int e = 0; e < 3 && n < 2; ++e) {
        const Vec3 &a = p[size_t(tri[size_t(e)])], &b = p[size_t(tri[size_t((e + 1) % 3)])];
        if ((a[axis] < 0) == (b[axis] < 0)) continue;
        const Vec3 q = a + (b - a) * (a[axis] / (a[axis] - b[axis]));
        ends[n++] = screen(q[uAxis], q[vAxis]);
      }
      if (n == 2) dl->AddLine(ends[0], ends[1], colour, 2);
    }
  };
  // Trace: the refined centreline once the run ended (what `save` writes), the voxel paths as
  // they are found while it runs.
  if (const ColouredPieces* cp = app_.profile().colouredTree()) {  // color-by diameter
    for (size_t k = 0; k < cp->pieces.size(); ++k) {
      const auto& rgb = cp->colours[k];
      linesOnSlice({cp->pieces[k]}, overlayColour(ov, int(255 * rgb[0]), int(255 * rgb[1]), int(255 * rgb[2])));
    }
  } else if (const Tree tree = app_.trace().tree(); tree.size() > 0) {
    linesOnSlice(tree.toPolylines(), overlayColour(ov, 255, 60, 40));
  } else {
    for (const auto& path : app_.trace().paths())
      for (const auto& v : path.voxels)
        if (v[static_cast<size_t>(axis)] == L.index) {
          const auto uv = uvOf(v);
          dl->AddCircleFilled(screen(uv[0], uv[1]), dot, overlayColour(ov, 255, 60, 40));
        }
  }
  meshOnSlice(app_.surface().mesh(), overlayColour(ov, 120, 190, 255));
  const auto& tpts = app_.trace().points();
  for (size_t k = 0; k < tpts.size(); ++k)
    if (std::abs(tpts[k][static_cast<size_t>(axis)] - L.index) <= 1) {
      const auto uv = uvOf(tpts[k]);
      dl->AddCircle(screen(uv[0], uv[1]), 6, k == 0 ? rgb(255, 255, 255) : rgb(255, 120, 40), 12, 2);
    }
  drawLiveWireOnSlice(axis, fit, v0, dl);
  if (app_.tool() == ToolKind::Surface) drawSurfaceOnSlice(axis, fit, v0, dl);
  // Loaded trees, polylines and meshes in their palette colours.
  const auto& loaded = app_.loadedOverlays();
  for (size_t i = 0; i < loaded.size(); ++i) {
    const auto c = overlayPaletteColor(i);
    const ImU32 colour = overlayColour(ov, int(255 * c[0]), int(255 * c[1]), int(255 * c[2]));
    linesOnSlice(loaded[i].lines, colour);
    meshOnSlice(loaded[i].mesh, colour);
  }
  // The cut's points near this slice.
  for (const Vec3& p : app_.cut().points())
    if (std::abs(p[axis] - double(L.index)) <= 1) {
      const ImVec2 q = screen(p[uAxis], p[vAxis]);
      dl->AddCircleFilled(q, 4, overlayColour(ov, 255, 140, 0));
    }
}

void ViewerWindow::handleSliceMouse(int axis, const SliceFit& fit, ImVec2 v0) {
  ImGuiIO& io = ImGui::GetIO();
  const double px = io.MousePos.x - v0.x, py = io.MousePos.y - v0.y;
  if (io.MouseWheel != 0 && io.KeyCtrl) {  // zoom about the mouse (Slicer: Ctrl+wheel)
    const double z = std::clamp(fit.zoom * std::pow(1.15, io.MouseWheel), 0.25, 40.0);
    act("zoom", [&] { app_.setSliceView(axis, z, fit.panForZoomAbout(px, py, z)); });
    return;
  }
  if (ImGui::IsMouseDragging(ImGuiMouseButton_Middle)) {  // pan (Slicer: middle drag)
    act("pan", [&] { app_.setSliceView(axis, fit.zoom, fit.panAfterDrag(io.MouseDelta.x, io.MouseDelta.y)); });
    return;
  }
  const std::optional<PixelUV> picked = fit.pickAt(px, py);
  if (!picked) return;  // outside the (zoomed) slice
  const SliceLayout& L = fit.layout;
  const PixelUV uv = *picked;
  const Index3 voxel = sliceToVolumeIndex(axis, L.index, uv);
  {  // the value under the mouse, in the view's lower left corner (as Slicer's data probe)
    char text[128];
    std::snprintf(text, sizeof text, "%lld,%lld,%lld: %.6g", (long long)voxel[0], (long long)voxel[1],
                  (long long)voxel[2], double(app_.floatVolume()(voxel[0], voxel[1], voxel[2])));
    const ImVec2 wp = ImGui::GetWindowPos(), ws = ImGui::GetWindowSize();
    ImGui::GetWindowDrawList()->AddText(ImVec2(wp.x + 6, wp.y + ws.y - 34), rgb(255, 255, 255), text);
    hoverValue_ = text;
  }
  if (!ImGui::IsAnyMouseDown()) hoverProfile(app_, voxel);  // a centreline under the mouse: its section
  Index3 cursor = app_.view().cursor;
  if (io.MouseWheel != 0) {  // every notch of the frame's share is one slice
    const int64_t steps = std::lround(io.MouseWheel) != 0 ? std::lround(io.MouseWheel) : (io.MouseWheel > 0 ? 1 : -1);
    cursor[static_cast<size_t>(axis)] =
        std::clamp<int64_t>(cursor[static_cast<size_t>(axis)] + steps, 0, app_.geometry().dims[axis] - 1);
    app_.setCursor(cursor);
  }
  if (ImGui::IsMouseDragging(ImGuiMouseButton_Right)) {
    const WindowLevel wl = app_.view().window;
    act("window", [&] {
      app_.setWindow(std::max(wl.window * std::exp(io.MouseDelta.x * 0.01), 1e-3),
                     wl.level - io.MouseDelta.y * wl.window * 0.005);
    });
  }
  const bool crosshair = io.KeyShift || (app_.tool() == ToolKind::None && ImGui::IsMouseDown(ImGuiMouseButton_Left));
  if (crosshair) app_.setCursor(voxel);
  if (app_.tool() == ToolKind::Trace && ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !io.KeyShift)
    act("point", [&] {
      app_.point3(voxel);
      if (app_.tool() == ToolKind::Trace && app_.trace().points().size() >= 2) app_.run(false);
    });
}

}  // namespace vs::viewer::window_detail
