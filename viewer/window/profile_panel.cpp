#include "window/profile_panel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace vs::viewer {

namespace {

constexpr float kProfileHeight = 230;

ImU32 colour(const int (&c)[3], int a = 255) { return IM_COL32(c[0], c[1], c[2], a); }

// Tick spacing of 1, 2 or 5 x 10^k giving about `count` ticks over `range`.
double niceStep(double range, int count) {
  const double raw = range / std::max(1, count);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 5.0})
    if (f * p >= raw) return f * p;
  return 10 * p;
}

}  // namespace

float profileWindowHeight(ViewerApp& app) {
  ProfileView& p = app.profile();
  if (p.has() && !p.measuredFrom(app.trace().tree())) p.clear();
  return p.has() ? kProfileHeight : 0;
}

void measureButton(ViewerApp& app, std::string& status) {
  if (!ImGui::Button("Measure (profile)")) return;
  try {
    measureTraceProfile(app);
    status.clear();
  } catch (const std::exception& e) {
    status = std::string("measure: ") + e.what();
  }
  if (!app.profile().has()) return;
  ImGui::SameLine();
  bool on = app.profile().colourByDiameter();
  if (ImGui::Checkbox("colour by diameter", &on)) {
    try {
      setTreeColouring(app, on ? "diameter" : "none");
    } catch (const std::exception& e) {
      status = std::string("colour by diameter: ") + e.what();
    }
  }
}

void drawDiameterLegend(ImDrawList* dl, ImVec2 viewMin, ImVec2 viewSize, const ColouredPieces& coloured) {
  const float barW = 14, barH = std::max(40.f, viewSize.y * 0.5f), textW = ImGui::CalcTextSize("00.0mm").x;
  const float x1 = viewMin.x + viewSize.x - 10 - textW - 6, x0 = x1 - barW;
  const float y0 = viewMin.y + (viewSize.y - barH) / 2;
  const int(&b)[3] = kLegendBackingRgb;
  dl->AddRectFilled(ImVec2(x0 - 6, y0 - 10), ImVec2(viewMin.x + viewSize.x - 4, y0 + barH + 10),
                    IM_COL32(b[0], b[1], b[2], 255));
  auto col = [](double t) {
    const auto c = rampColour(t);
    return IM_COL32(int(c[0] * 255), int(c[1] * 255), int(c[2] * 255), 255);
  };
  constexpr int kSteps = 32;  // the ramp in bands, each a vertical gradient (top: hi)
  for (int k = 0; k < kSteps; ++k) {
    const float ya = y0 + barH * float(k) / kSteps, yb = y0 + barH * float(k + 1) / kSteps;
    const ImU32 top = col(1.0 - double(k) / kSteps), bottom = col(1.0 - double(k + 1) / kSteps);
    dl->AddRectFilledMultiColor(ImVec2(x0, ya), ImVec2(x1, yb), top, top, bottom, bottom);
  }
  const float th = ImGui::GetTextLineHeight();
  for (const LegendTick& t : colourLegendTicks(coloured.loMm, coloured.hiMm)) {
    const float y = y0 + barH * float(1.0 - t.fraction);
    dl->AddLine(ImVec2(x1, y), ImVec2(x1 + 4, y), IM_COL32(255, 255, 255, 255), 1.0f);
    dl->AddText(ImVec2(x1 + 6, std::clamp(y - th / 2, y0 - 8, y0 + barH + 8 - th)), IM_COL32(255, 255, 255, 255),
                t.text.c_str());
  }
}

void profileWindow(ViewerApp& app, ImVec2 pos, ImVec2 size, std::string& status) {
  ProfileView& prof = app.profile();
  if (!prof.has()) return;
  const TreeMeasurement& m = prof.measurement();
  ImGui::SetNextWindowPos(pos, ImGuiCond_Always);
  ImGui::SetNextWindowSize(size, ImGuiCond_Always);
  ImGui::Begin("profile: diameter along the path", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  const PathMeasure& path = m.paths[static_cast<size_t>(prof.path())];
  char label[160];
  std::snprintf(label, sizeof label, "path %d: %.1f mm", prof.path(), path.lengthMm);
  if (ImGui::BeginCombo("##path", label)) {
    for (size_t k = 0; k < m.paths.size(); ++k) {
      std::snprintf(label, sizeof label, "path %zu: %.1f mm, min d %.2f mm", k, m.paths[k].lengthMm,
                    m.paths[k].minDiameterMm);
      if (ImGui::Selectable(label, static_cast<int>(k) == prof.path())) prof.selectPath(static_cast<int>(k));
    }
    ImGui::EndCombo();
  }
  std::vector<double> arc, d;
  prof.plotData(arc, d);
  double dMax = 0;
  for (double x : d)
    if (std::isfinite(x)) dMax = std::max(dMax, x);
  const double xMax = std::max(path.lengthMm, 1e-3), yMax = dMax > 0 ? 1.15 * dMax : 1.0;
  // The plot: axes with ticks labelled in mm (left 42 px for the diameter, bottom 16 px for the arc).
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const float textH = ImGui::GetTextLineHeightWithSpacing();
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  const ImVec2 box(std::max(60.f, avail.x), std::max(60.f, avail.y - 2 * textH));
  ImGui::InvisibleButton("##profileplot", box);
  const bool hovered = ImGui::IsItemHovered(), clicked = ImGui::IsItemClicked(ImGuiMouseButton_Left);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float left = p0.x + 42, right = p0.x + box.x - 6, top = p0.y + 14, bottom = p0.y + box.y - 16;
  auto sx = [&](double a) { return left + float(a / xMax) * (right - left); };
  auto sy = [&](double v) { return bottom - float(v / yMax) * (bottom - top); };
  const ImU32 axis = IM_COL32(200, 200, 200, 255), grid = IM_COL32(80, 80, 90, 255);
  dl->AddRectFilled(ImVec2(left, top), ImVec2(right, bottom), IM_COL32(25, 25, 32, 255));
  const double xs = niceStep(xMax, 5), ys = niceStep(yMax, 4);
  char t[32];
  for (double a = 0; a <= xMax + 1e-9; a += xs) {
    dl->AddLine(ImVec2(sx(a), top), ImVec2(sx(a), bottom), grid);
    std::snprintf(t, sizeof t, "%g", a);
    dl->AddText(ImVec2(sx(a) - 4, bottom + 1), axis, t);
  }
  for (double v = 0; v <= yMax + 1e-9; v += ys) {
    dl->AddLine(ImVec2(left, sy(v)), ImVec2(right, sy(v)), grid);
    std::snprintf(t, sizeof t, "%g", v);
    dl->AddText(ImVec2(p0.x + 2, sy(v) - 7), axis, t);
  }
  dl->AddLine(ImVec2(left, bottom), ImVec2(right, bottom), axis);
  dl->AddLine(ImVec2(left, top), ImVec2(left, bottom), axis);
  dl->AddText(ImVec2(p0.x + 2, p0.y - 2), axis, "d (mm)");
  const char* xTitle = "arc from the root (mm)";
  dl->AddText(ImVec2(right - ImGui::CalcTextSize(xTitle).x, p0.y - 2), axis, xTitle);
  // The curve: consecutive measured sections joined, flagged ones left as gaps.
  for (size_t k = 1; k < d.size(); ++k)
    if (std::isfinite(d[k - 1]) && std::isfinite(d[k]))
      dl->AddLine(ImVec2(sx(arc[k - 1]), sy(d[k - 1])), ImVec2(sx(arc[k]), sy(d[k])), colour(kProfileLineRgb), 2);
  for (size_t k = 0; k < d.size(); ++k) {
    const CrossSection& cs = m.sections[static_cast<size_t>(path.sections[k])];
    if (cs.branchPoint >= 0 && std::isfinite(d[k]))
      dl->AddCircleFilled(ImVec2(sx(arc[k]), sy(d[k])), 3, IM_COL32(255, 255, 255, 255));
  }
  if (std::isfinite(path.stenosisArcMm))  // the reported stenosis
    dl->AddLine(ImVec2(sx(path.stenosisArcMm), top), ImVec2(sx(path.stenosisArcMm), bottom),
                IM_COL32(255, 60, 60, 255));
  if (const double a = prof.selectedArcMm(); std::isfinite(a)) {
    dl->AddLine(ImVec2(sx(a), top), ImVec2(sx(a), bottom), colour(kProfileSectionRgb), 2);
    const CrossSection* cs = prof.selected();
    if (cs && cs->measured())
      dl->AddCircle(ImVec2(sx(a), sy(cs->equivalentDiameterMm)), 5, colour(kProfileSectionRgb), 12, 2);
  }
  const ImVec2 mouse = ImGui::GetIO().MousePos;
  const double mouseArc = std::clamp(double(mouse.x - left) / double(right - left), 0.0, 1.0) * xMax;
  if (hovered) ImGui::SetTooltip("arc %.1f mm (click: this section)", mouseArc);
  if (clicked) {
    try {
      selectProfileArc(app, mouseArc);
      status.clear();
    } catch (const std::exception& e) {
      status = std::string("profile: ") + e.what();
    }
  }
  // The selected section's numbers.
  if (const CrossSection* cs = prof.selected()) {
    if (cs->measured())
      ImGui::Text("%.1f mm: d %.2f mm (min %.2f, max %.2f), %.2f mm2", prof.selectedArcMm(), cs->equivalentDiameterMm,
                  cs->minDiameterMm, cs->maxDiameterMm, cs->areaMm2);
    else
      ImGui::Text("%.1f mm: not measured (%s)", prof.selectedArcMm(), crossSectionFlagsText(cs->flags).c_str());
  } else {
    ImGui::TextDisabled("click the plot or hover a centreline in a slice");
  }
  if (std::isfinite(path.stenosis))
    ImGui::Text("stenosis %.0f%% at %.1f mm, min d %.2f mm", 100 * path.stenosis, path.stenosisArcMm,
                path.minDiameterMm);
  else
    ImGui::Text("mean d %.2f mm, min %.2f mm at %.1f mm", path.meanDiameterMm, path.minDiameterMm, path.minArcMm);
  ImGui::End();
}

void drawProfileSection3D(const ViewerApp& app, ImDrawList* dl,
                          const std::function<bool(const Vec3&, ImVec2&)>& project) {
  const CrossSection* cs = app.profile().selected();
  if (!cs) return;
  ImVec2 c;
  if (project(cs->centreMm, c)) dl->AddCircleFilled(c, 3, colour(kProfileSectionRgb));
  const auto& b = cs->boundaryMm;
  for (size_t k = 0; k < b.size(); ++k) {
    ImVec2 a, q;
    if (project(b[k], a) && project(b[(k + 1) % b.size()], q)) dl->AddLine(a, q, colour(kProfileSectionRgb), 2);
  }
}

void drawProfileSectionOnSlice(const ViewerApp& app, ImDrawList* dl, int axis, int64_t index,
                               const std::function<ImVec2(double, double)>& screen) {
  const CrossSection* cs = app.profile().selected();
  if (!cs) return;
  const Geometry& g = app.geometry();
  const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
  const Vec3 c = g.worldToIndex(cs->centreMm);
  const double radiusVoxels = std::max(1.0, cs->outerRadiusMm / g.spacing[axis]);
  if (std::abs(c[axis] - double(index)) > radiusVoxels) return;
  // The contour projected onto the slice (it lies in the plane across the centreline).
  const auto& b = cs->boundaryMm;
  for (size_t k = 0; k < b.size(); ++k) {
    const Vec3 p = g.worldToIndex(b[k]), q = g.worldToIndex(b[(k + 1) % b.size()]);
    dl->AddLine(screen(p[u], p[v]), screen(q[u], q[v]), colour(kProfileSectionRgb), 2);
  }
  dl->AddCircleFilled(screen(c[u], c[v]), 3, colour(kProfileSectionRgb));
}

void hoverProfile(ViewerApp& app, const Index3& voxel) {
  ProfileView& p = app.profile();
  if (!p.has()) return;
  const Geometry& g = app.geometry();
  p.selectNear(g.indexToWorld(Vec3(double(voxel[0]), double(voxel[1]), double(voxel[2]))), 2 * g.spacing.maxCoeff());
}

}  // namespace vs::viewer
