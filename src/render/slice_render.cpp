#include "render/slice_render.h"

#include <algorithm>
#include <cmath>

#include "render/view_defaults.h"
#include "util/error.h"

namespace vs {

namespace {

// 5x7 glyphs of the six orientation letters, one row per byte, bit 4 = leftmost column.
const std::array<uint8_t, 7>& glyph(char c) {
  static const std::array<uint8_t, 7> A{0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11},
      I{0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}, L{0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F},
      P{0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}, R{0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11},
      S{0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E};
  switch (c) {
    case 'A':
      return A;
    case 'I':
      return I;
    case 'L':
      return L;
    case 'P':
      return P;
    case 'R':
      return R;
    default:
      return S;
  }
}

const std::array<float, 3> kAnnotation{1.0f, 0.85f, 0.2f};

void setPixel(RgbaImage& img, int x, int y, const std::array<float, 3>& c) {
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  uint8_t* px = img.at(x, y);
  for (size_t k = 0; k < 3; ++k) px[k] = static_cast<uint8_t>(std::lrint(c[k] * 255));
}

// Letter with a dark one-pixel shadow so it reads on bright and dark tissue alike.
void drawLetter(RgbaImage& img, char c, int x0, int y0, int scale) {
  const auto& g = glyph(c);
  for (int pass = 0; pass < 2; ++pass)
    for (int r = 0; r < 7; ++r)
      for (int col = 0; col < 5; ++col)
        if (g[static_cast<size_t>(r)] & (0x10 >> col))
          for (int dy = 0; dy < scale; ++dy)
            for (int dx = 0; dx < scale; ++dx)
              setPixel(img, x0 + col * scale + dx + (pass == 0), y0 + r * scale + dy + (pass == 0),
                       pass == 0 ? std::array<float, 3>{0, 0, 0} : kAnnotation);
}

}  // namespace

std::array<double, 2> SlicePicture::pixelOf(const Vec3& index) const {
  const auto pc = frame.pictureOf(index);
  return {(pc[0] + 0.5) * width / static_cast<double>(frame.width) - 0.5,
          (pc[1] + 0.5) * height / static_cast<double>(frame.height) - 0.5};
}

SlicePicture slicePicture(const Geometry& g, int axis, int64_t index, const SliceImageOptions& o) {
  SlicePicture p;
  p.frame = sliceFrame(g, axis, index);
  const SliceFrame& f = p.frame;
  double W = static_cast<double>(f.width), H = static_cast<double>(f.height);
  if (!o.pixelPerVoxel) {
    const double px = std::min(f.colSpacing, f.rowSpacing);
    W = std::max(1.0, std::round(W * f.colSpacing / px));
    H = std::max(1.0, std::round(H * f.rowSpacing / px));
    if (o.fitWidth > 0 && o.fitHeight > 0) {
      const double s = std::min(o.fitWidth / W, o.fitHeight / H);
      W = std::max(1.0, std::round(W * s));
      H = std::max(1.0, std::round(H * s));
    }
  }
  VS_REQUIRE(W <= Renderer::kMaxImageSide && H <= Renderer::kMaxImageSide,
             "slice: output image would be larger than " + std::to_string(Renderer::kMaxImageSide) + " pixels a side");
  p.width = static_cast<int>(W);
  p.height = static_cast<int>(H);
  const double sc = static_cast<double>(f.width) / W, sr = static_cast<double>(f.height) / H;
  const double c0 = 0.5 * sc - 0.5, r0 = 0.5 * sr - 0.5;
  p.indexAtOrigin = f.indexOf(c0, r0);
  p.indexPerColumn = f.indexOf(c0 + sc, r0) - p.indexAtOrigin;
  p.indexPerRow = f.indexOf(c0, r0 + sr) - p.indexAtOrigin;
  return p;
}

std::array<float, 3> overlayPaletteColor(size_t i) {
  static const std::array<float, 3> palette[] = {
      {1.0f, 0.25f, 0.2f}, {0.2f, 1.0f, 0.3f}, {0.2f, 0.8f, 1.0f}, {1.0f, 0.9f, 0.2f}, {1.0f, 0.4f, 1.0f}};
  return palette[i % std::size(palette)];
}

WindowLevel percentileWindow(const AnyVolume& volume) { return quantileWindow(volume, 0.01, 0.995); }

RgbaImage renderSlice(const AnyVolume& volume, int axis, int64_t index, const SliceImageOptions& o,
                      const AnyVolume* labels, const std::vector<Polyline>* overlays) {
  const Geometry& g = geometryOf(volume);
  const SlicePicture pic = slicePicture(g, axis, index, o);
  const SliceFrame& f = pic.frame;
  if (labels)
    VS_REQUIRE(geometryOf(*labels).dims == g.dims, "slice: label volume dims differ from the volume's " + g.describe());
  if (overlays && !o.polylineColors.empty())
    VS_REQUIRE(o.polylineColors.size() == overlays->size(),
               "slice: polylineColors must give one colour per overlay polyline");
  const int w = pic.width, h = pic.height;
  const int64_t nu = f.width, nv = f.height;  // voxels along the picture's columns and rows
  const WindowLevel wl = o.window.window > 0 ? o.window : percentileWindow(volume);
  RgbaImage img(w, h);
  // Voxel offset of in-plane index (a along colAxis, b along rowAxis).
  auto offset = [&](int64_t a, int64_t b) {
    Index3 c{};
    c[static_cast<size_t>(axis)] = index;
    c[static_cast<size_t>(f.colAxis)] = a;
    c[static_cast<size_t>(f.rowAxis)] = b;
    return g.linear(c[0], c[1], c[2]);
  };
  std::visit(
      [&](const auto& vol) {
        const auto* d = vol.data();
        for (int j = 0; j < h; ++j)
          for (int i = 0; i < w; ++i) {
            const Vec3 at = pic.indexOf(i, j);
            const double uc = std::clamp(at[f.colAxis], 0.0, double(nu - 1));
            const double vc = std::clamp(at[f.rowAxis], 0.0, double(nv - 1));
            const int64_t u0 = std::min<int64_t>(static_cast<int64_t>(uc), std::max<int64_t>(nu - 2, 0));
            const int64_t v0 = std::min<int64_t>(static_cast<int64_t>(vc), std::max<int64_t>(nv - 2, 0));
            const int64_t u1 = std::min(u0 + 1, nu - 1), v1 = std::min(v0 + 1, nv - 1);
            const double fu = uc - u0, fv = vc - v0;
            const double a = static_cast<double>(d[offset(u0, v0)]), b = static_cast<double>(d[offset(u1, v0)]);
            const double c = static_cast<double>(d[offset(u0, v1)]), e = static_cast<double>(d[offset(u1, v1)]);
            const double val = (a + fu * (b - a)) * (1 - fv) + (c + fu * (e - c)) * fv;
            const double gv = windowGrey(val, wl);
            double rgb[3] = {gv, gv, gv};
            if (labels) {
              const int64_t li = offset(std::llround(uc), std::llround(vc));
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
    for (size_t li = 0; li < overlays->size(); ++li) {
      const Polyline& pl = (*overlays)[li];
      const auto& colour = o.polylineColors.empty() ? o.overlayColor : o.polylineColors[li];
      const size_t n = pl.points.size();
      for (size_t s = 0; s + 1 < n + (pl.closed ? 1 : 0) || (n == 1 && s == 0); ++s) {
        const Vec3 a = g.worldToIndex(pl.points[s]), b = g.worldToIndex(pl.points[n == 1 ? 0 : (s + 1) % n]);
        if (std::abs(a[axis] - index) > o.overlayBand && std::abs(b[axis] - index) > o.overlayBand) continue;
        const auto pa = pic.pixelOf(a), pb = pic.pixelOf(b);
        const int steps = static_cast<int>(std::ceil(std::max(std::abs(pb[0] - pa[0]), std::abs(pb[1] - pa[1])))) + 1;
        for (int k = 0; k <= steps; ++k) {
          const double t = double(k) / steps;
          const int x = static_cast<int>(std::lround(pa[0] + t * (pb[0] - pa[0])));
          const int y = static_cast<int>(std::lround(pa[1] + t * (pb[1] - pa[1])));
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) setPixel(img, x + dx, y + dy, colour);
        }
        if (n == 1) break;
      }
    }
  }
  if (o.indexTicks) {
    // Ticks where the index along the column (row) axis is a multiple of 10, at that voxel's centre.
    for (int64_t k = 0; k < nu; k += 10) {
      const int x =
          static_cast<int>(std::lround(pic.pixelOf(f.indexOf(f.colFlipped ? double(nu - 1 - k) : double(k), 0))[0]));
      for (int y = 0; y < (k % 50 == 0 ? 8 : 4); ++y) setPixel(img, x, y, kAnnotation);
    }
    for (int64_t k = 0; k < nv; k += 10) {
      const int y =
          static_cast<int>(std::lround(pic.pixelOf(f.indexOf(0, f.rowFlipped ? double(nv - 1 - k) : double(k)))[1]));
      for (int x = 0; x < (k % 50 == 0 ? 8 : 4); ++x) setPixel(img, x, y, kAnnotation);
    }
  }
  if (o.orientationLetters) {
    const int s = std::max(1, std::min(w, h) / 160), gw = 5 * s, gh = 7 * s, m = 3 * s + 8 * o.indexTicks;
    drawLetter(img, f.edgeLetters[0], m, (h - gh) / 2, s);
    drawLetter(img, f.edgeLetters[1], w - gw - 3 * s, (h - gh) / 2, s);
    drawLetter(img, f.edgeLetters[2], (w - gw) / 2, m, s);
    drawLetter(img, f.edgeLetters[3], (w - gw) / 2, h - gh - 3 * s, s);
  }
  return img;
}

}  // namespace vs
