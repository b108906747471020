#include "app/slice_layout.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"
#include "volume/slice.h"

namespace vs::viewer {

SliceLayout sliceLayout(const Geometry& g, int axis, int64_t index) {
  const SliceFrame f = sliceFrame(g, axis, index);  // the core's frame (volume/slice.h)
  SliceLayout L;
  L.axis = axis;
  L.index = index;
  L.plane = anatomicalPlaneName(f.plane);
  const int uAxis = axis == 0 ? 1 : 0, vAxis = axis == 2 ? 1 : 2;
  L.width = g.dims[uAxis];
  L.height = g.dims[vAxis];
  L.spacingU = g.spacing[uAxis];
  L.spacingV = g.spacing[vAxis];
  L.transposed = f.colAxis == vAxis;
  L.flipU = L.transposed ? f.rowFlipped : f.colFlipped;
  L.flipV = L.transposed ? f.colFlipped : f.rowFlipped;
  L.left = std::string(1, f.edgeLetters[0]);
  L.right = std::string(1, f.edgeLetters[1]);
  L.top = std::string(1, f.edgeLetters[2]);
  L.bottom = std::string(1, f.edgeLetters[3]);
  return L;
}

void SliceLayout::toScreen(double u, double v, double& sx, double& sy) const {
  double a = (u + 0.5) / double(width), b = (v + 0.5) / double(height);
  if (flipU) a = 1 - a;
  if (flipV) b = 1 - b;
  sx = transposed ? b : a;
  sy = transposed ? a : b;
}

PixelUV SliceLayout::fromScreen(double sx, double sy) const {
  const auto t = textureAt(sx, sy);
  const int64_t u = std::clamp<int64_t>(static_cast<int64_t>(std::floor(t[0] * double(width))), 0, width - 1);
  const int64_t v = std::clamp<int64_t>(static_cast<int64_t>(std::floor(t[1] * double(height))), 0, height - 1);
  return {u, v};
}

std::array<double, 2> SliceLayout::textureAt(double sx, double sy) const {
  double a = transposed ? sy : sx, b = transposed ? sx : sy;
  if (flipU) a = 1 - a;
  if (flipV) b = 1 - b;
  return {a, b};
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
  const double physW = layout.screenWidthMm(), physH = layout.screenHeightMm();
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
