#include "render/slice_render.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"

namespace vs {

WindowLevel percentileWindow(const AnyVolume& volume) {
  WindowHistogram histogram(valueRange(volume));
  std::visit(
      [&](const auto& vol) {
        for (auto x : vol.voxels()) histogram.add(static_cast<double>(x));
      },
      volume);
  return histogram.window();
}

RgbaImage renderSlice(const AnyVolume& volume, int axis, int64_t index, const SliceImageOptions& o,
                      const AnyVolume* labels, const std::vector<Polyline>* overlays) {
  const Geometry& g = geometryOf(volume);
  VS_REQUIRE(axis >= 0 && axis <= 2, "slice: axis must be 0 (x, sagittal), 1 (y, coronal) or 2 (z, axial)");
  VS_REQUIRE(index >= 0 && index < g.dims[static_cast<size_t>(axis)],
             std::string("slice: ") + "xyz"[axis] + "=" + std::to_string(index) + " is outside the volume (0.." +
                 std::to_string(g.dims[static_cast<size_t>(axis)] - 1) + ")");
  if (labels)
    VS_REQUIRE(geometryOf(*labels).dims == g.dims, "slice: label volume dims differ from the volume's " + g.describe());
  const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;
  const bool flipV = axis != 2;
  const int64_t nu = g.dims[static_cast<size_t>(ua)], nv = g.dims[static_cast<size_t>(va)];
  const double su = g.spacing[ua], sv = g.spacing[va];
  const double p = std::min(su, sv);
  double W = std::max(1.0, std::round(nu * su / p)), H = std::max(1.0, std::round(nv * sv / p));
  if (o.fitWidth > 0 && o.fitHeight > 0) {
    const double s = std::min(o.fitWidth / W, o.fitHeight / H);
    W = std::max(1.0, std::round(W * s));
    H = std::max(1.0, std::round(H * s));
  }
  VS_REQUIRE(W <= Renderer::kMaxImageSide && H <= Renderer::kMaxImageSide,
             "slice: output image would be larger than " + std::to_string(Renderer::kMaxImageSide) + " pixels a side");
  const int w = static_cast<int>(W), h = static_cast<int>(H);
  const WindowLevel wl = o.window.window > 0 ? o.window : percentileWindow(volume);
  RgbaImage img(w, h);
  auto idx3 = [&](int64_t u, int64_t v) {
    int64_t c[3];
    c[axis] = index;
    c[ua] = u;
    c[va] = v;
    return g.linear(c[0], c[1], c[2]);
  };
  std::visit(
      [&](const auto& vol) {
        const auto* d = vol.data();
        for (int j = 0; j < h; ++j)
          for (int i = 0; i < w; ++i) {
            const double uc = std::clamp((i + 0.5) * nu / w - 0.5, 0.0, double(nu - 1));
            double vc = std::clamp((j + 0.5) * nv / h - 0.5, 0.0, double(nv - 1));
            if (flipV) vc = double(nv - 1) - vc;
            const int64_t u0 = std::min<int64_t>(static_cast<int64_t>(uc), std::max<int64_t>(nu - 2, 0));
            const int64_t v0 = std::min<int64_t>(static_cast<int64_t>(vc), std::max<int64_t>(nv - 2, 0));
            const int64_t u1 = std::min(u0 + 1, nu - 1), v1 = std::min(v0 + 1, nv - 1);
            const double fu = uc - u0, fv = vc - v0;
            const double a = static_cast<double>(d[idx3(u0, v0)]), b = static_cast<double>(d[idx3(u1, v0)]);
            const double c = static_cast<double>(d[idx3(u0, v1)]), e = static_cast<double>(d[idx3(u1, v1)]);
            const double val = (a + fu * (b - a)) * (1 - fv) + (c + fu * (e - c)) * fv;
            const double gv = windowGrey(val, wl);
            double rgb[3] = {gv, gv, gv};
            if (labels) {
              const int64_t li = idx3(std::llround(uc), std::llround(vc));
              const int l = std::visit([&](const auto& lv) { return static_cast<int>(lv.data()[li]); }, *labels);
              blendLabel(rgb, l, o.labelOpacity);
            }
            uint8_t* px = img.at(i, j);
            for (int k = 0; k < 3; ++k) px[k] = static_cast<uint8_t>(std::lrint(rgb[k] * 255));
            px[3] = 255;
          }
      },
      volume);
  if (overlays) {
    // Index (u, v) -> pixel: inverse of the sampling above.
    auto toPixel = [&](const Vec3& ic, double& x, double& y) {
      x = (ic[ua] + 0.5) * w / nu;
      const double v = flipV ? double(nv - 1) - ic[va] : ic[va];
      y = (v + 0.5) * h / nv;
    };
    for (const auto& pl : *overlays) {
      const size_t n = pl.points.size();
      for (size_t s = 0; s + 1 < n + (pl.closed ? 1 : 0) || (n == 1 && s == 0); ++s) {
        const Vec3 a = g.worldToIndex(pl.points[s]), b = g.worldToIndex(pl.points[n == 1 ? 0 : (s + 1) % n]);
        if (std::abs(a[axis] - index) > o.overlayBand && std::abs(b[axis] - index) > o.overlayBand) continue;
        double ax, ay, bx, by;
        toPixel(a, ax, ay);
        toPixel(b, bx, by);
        const int steps = static_cast<int>(std::ceil(std::max(std::abs(bx - ax), std::abs(by - ay)))) + 1;
        for (int k = 0; k <= steps; ++k) {
          const double t = double(k) / steps;
          const int x = static_cast<int>(ax + t * (bx - ax)), y = static_cast<int>(ay + t * (by - ay));
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int xx = x + dx, yy = y + dy;
              if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
              uint8_t* px = img.at(xx, yy);
              for (int c = 0; c < 3; ++c) px[c] = static_cast<uint8_t>(std::lrint(o.overlayColor[static_cast<size_t>(c)] * 255));
            }
        }
        if (n == 1) break;
      }
    }
  }
  return img;
}

}  // namespace vs
