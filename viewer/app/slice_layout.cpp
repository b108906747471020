#include "app/slice_layout.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"

namespace vs::viewer {

std::string anatomicalLabel(const Vec3& d) {
  int a = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(d[k]) > std::abs(d[a])) a = k;
  static const char* pos[3] = {"L", "P", "S"};
  static const char* neg[3] = {"R", "A", "I"};
  return d[a] >= 0 ? pos[a] : neg[a];
}

SliceLayout sliceLayout(const Geometry& g, int axis, int64_t index) {
  VS_REQUIRE(axis >= 0 && axis <= 2, "slice axis must be 0, 1 or 2");
  VS_REQUIRE(index >= 0 && index < g.dims[axis], "slice index outside the volume");
  SliceLayout L;
  L.axis = axis;
  L.index = index;
  const int uAxis = axis == 0 ? 1 : 0, vAxis = axis == 2 ? 1 : 2;
  L.width = g.dims[uAxis];
  L.height = g.dims[vAxis];
  L.spacingU = g.spacing[uAxis];
  L.spacingV = g.spacing[vAxis];
  const Vec3 du = g.direction.col(uAxis), dv = g.direction.col(vAxis);
  // Wanted: screen right = L (axial, coronal) or P (sagittal); screen down = P (axial) or I.
  const Vec3 wantRight = axis == 0 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
  const Vec3 wantDown = axis == 2 ? Vec3(0, 1, 0) : Vec3(0, 0, -1);
  // Each screen axis takes whichever of u/v points more along it; the layout keeps u horizontal,
  // so only the signs are chosen here and the labels say where the axes really point.
  L.flipU = du.dot(wantRight) < 0;
  L.flipV = dv.dot(wantDown) < 0;
  const Vec3 right = L.flipU ? Vec3(-du) : du, down = L.flipV ? Vec3(-dv) : dv;
  L.right = anatomicalLabel(right);
  L.left = anatomicalLabel(-right);
  L.bottom = anatomicalLabel(down);
  L.top = anatomicalLabel(-down);
  return L;
}

void SliceLayout::toScreen(double u, double v, double& sx, double& sy) const {
  sx = (u + 0.5) / double(width);
  sy = (v + 0.5) / double(height);
  if (flipU) sx = 1 - sx;
  if (flipV) sy = 1 - sy;
}

PixelUV SliceLayout::fromScreen(double sx, double sy) const {
  if (flipU) sx = 1 - sx;
  if (flipV) sy = 1 - sy;
  const int64_t u = std::clamp<int64_t>(static_cast<int64_t>(std::floor(sx * double(width))), 0, width - 1);
  const int64_t v = std::clamp<int64_t>(static_cast<int64_t>(std::floor(sy * double(height))), 0, height - 1);
  return {u, v};
}

SliceFit fitSlice(const SliceLayout& layout, double viewW, double viewH, double zoom, std::array<double, 2> pan) {
  VS_REQUIRE(viewW > 0 && viewH > 0, "slice view: the view has no area");
  VS_REQUIRE(std::isfinite(zoom) && zoom > 0, "slice view: zoom must be > 0");
  SliceFit f;
  f.layout = layout;
  f.viewW = viewW;
  f.viewH = viewH;
  f.zoom = zoom;
  f.pan = pan;
  const double physW = double(layout.width) * layout.spacingU, physH = double(layout.height) * layout.spacingV;
  const double scale = std::min(viewW / physW, viewH / physH);
  f.fitW = physW * scale;
  f.fitH = physH * scale;
  f.w = f.fitW * zoom;
  f.h = f.fitH * zoom;
  f.x0 = (viewW - f.w) / 2 + pan[0] * f.fitW;
  f.y0 = (viewH - f.h) / 2 + pan[1] * f.fitH;
  return f;
}

std::array<double, 2> SliceFit::viewOf(double u, double v) const {
  double sx = 0, sy = 0;
  layout.toScreen(u, v, sx, sy);
  return {x0 + sx * w, y0 + sy * h};
}

std::optional<PixelUV> SliceFit::pickAt(double px, double py) const {
  const double sx = (px - x0) / w, sy = (py - y0) / h;
  if (sx < 0 || sy < 0 || sx >= 1 || sy >= 1) return std::nullopt;
  return layout.fromScreen(sx, sy);
}

std::array<double, 2> SliceFit::panForZoomAbout(double px, double py, double newZoom) const {
  const double fx = (px - x0) / w, fy = (py - y0) / h;  // image fraction under the point
  const double nx0 = px - fx * fitW * newZoom, ny0 = py - fy * fitH * newZoom;
  return {(nx0 - (viewW - fitW * newZoom) / 2) / fitW, (ny0 - (viewH - fitH * newZoom) / 2) / fitH};
}

std::array<double, 2> SliceFit::panAfterDrag(double dx, double dy) const {
  return {pan[0] + dx / fitW, pan[1] + dy / fitH};
}

RgbaImage sliceImage(const VolumeF32& volume, int axis, int64_t index, const WindowLevel& wl, const VolumeU16* labels,
                     const OverlaySettings& overlays) {
  const SliceView<float> s = sliceView(volume, axis, index);
  VS_REQUIRE(!labels || labels->dims() == volume.dims(),
             "slice image: the labels' dimensions differ from the volume's");
  std::optional<SliceView<uint16_t>> ls;
  if (labels) ls.emplace(sliceView(*labels, axis, index));
  RgbaImage img(static_cast<int>(s.width), static_cast<int>(s.height));
  const double lo = wl.level - 0.5 * wl.window, scale = wl.window > 0 ? 255.0 / wl.window : 0;
  for (int64_t v = 0; v < s.height; ++v)
    for (int64_t u = 0; u < s.width; ++u) {
      const auto g = static_cast<uint8_t>(std::lrint(std::clamp((double(s(u, v)) - lo) * scale, 0.0, 255.0)));
      uint8_t* p = img.at(static_cast<int>(u), static_cast<int>(v));
      p[0] = p[1] = p[2] = g;
      p[3] = 255;
      const int label = ls ? int((*ls)(u, v)) : 0;
      if (overlays.labelVisible(label)) {
        double c[3] = {g / 255.0, g / 255.0, g / 255.0};
        blendLabel(c, label, overlays.labelOpacity);
        for (int k = 0; k < 3; ++k) p[k] = static_cast<uint8_t>(std::lrint(std::clamp(c[k], 0.0, 1.0) * 255));
      }
    }
  return img;
}

}  // namespace vs::viewer
