#include "render/colour_legend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "util/error.h"

namespace vs {

std::array<float, 3> rampColour(double t) {
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
  static const std::array<std::array<float, 3>, 5> stops{
      {{0.1f, 0.2f, 1.0f}, {0.0f, 0.9f, 1.0f}, {0.1f, 0.9f, 0.1f}, {1.0f, 0.95f, 0.1f}, {1.0f, 0.1f, 0.05f}}};
  const double x = t * 4;
  const size_t i = std::min<size_t>(3, static_cast<size_t>(x));
  const double f = x - static_cast<double>(i);
  std::array<float, 3> c{};
  for (size_t k = 0; k < 3; ++k) c[k] = static_cast<float>(stops[i][k] + f * (stops[i + 1][k] - stops[i][k]));
  return c;
}

ColouredPieces colourByDiameter(const std::vector<Polyline>& lines) {
  ColouredPieces out;
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& l : lines)
    for (double r : l.radii)
      if (std::isfinite(r) && r > 0) lo = std::min(lo, 2 * r), hi = std::max(hi, 2 * r);
  if (!(hi >= lo)) throw InvalidArgument("colour by diameter: the overlay lines carry no radii (use a measured tree)");
  out.loMm = lo;
  out.hiMm = hi;
  for (const auto& l : lines) {
    if (l.radii.size() != l.points.size()) continue;
    for (size_t i = 0; i + 1 < l.points.size(); ++i) {
      Polyline p;
      p.points = {l.points[i], l.points[i + 1]};
      p.radii = {l.radii[i], l.radii[i + 1]};
      const double d = l.radii[i] + l.radii[i + 1];  // mean diameter
      const bool measured = std::isfinite(d) && l.radii[i] > 0 && l.radii[i + 1] > 0;
      out.pieces.push_back(std::move(p));
      out.colours.push_back(!measured ? kUnmeasuredColour : rampColour(hi > lo ? (d - lo) / (hi - lo) : 0.5));
    }
  }
  return out;
}

namespace {
// 3x5 glyphs, rows top to bottom, 3 bits each (MSB left): 0-9, '.', 'm'.
const char* kGlyphChars = "0123456789.m";
const uint16_t kGlyphs[] = {
    0x7B6F, 0x2C97, 0x73E7, 0x73CF, 0x5BC9, 0x79CF, 0x79EF, 0x7249, 0x7BEF, 0x7BCF, 0x0002, 0x01BD,
};

void put(RgbaImage& img, int x, int y, const std::array<uint8_t, 3>& c) {
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  uint8_t* p = img.at(x, y);
  p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
}

void text(RgbaImage& img, int x, int y, const std::string& s, int scale) {
  for (char ch : s) {
    const char* g = std::strchr(kGlyphChars, ch);
    if (ch != ' ' && g && *g) {
      const uint16_t bits = kGlyphs[g - kGlyphChars];
      for (int r = 0; r < 5; ++r)
        for (int cI = 0; cI < 3; ++cI)
          if (bits >> (14 - (r * 3 + cI)) & 1)
            for (int dy = 0; dy < scale; ++dy)
              for (int dx = 0; dx < scale; ++dx) put(img, x + cI * scale + dx, y + r * scale + dy, {255, 255, 255});
    }
    x += 4 * scale;
  }
}

}  // namespace

std::vector<LegendTick> colourLegendTicks(double lo, double hi) {
  auto label = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, v < 10 ? "%.1fmm" : "%.0fmm", v);
    return std::string(b);
  };
  const double mid = 0.5 * (lo + hi);
  return {{lo, 0.0, label(lo)}, {mid, 0.5, label(mid)}, {hi, 1.0, label(hi)}};
}

void drawColourLegend(RgbaImage& img, double lo, double hi) {
  if (img.width < 40 || img.height < 40) return;
  const int scale = img.height >= 400 ? 2 : 1;
  const int barH = img.height / 2, barW = 6 * scale;
  const int textW = 4 * scale * 6;
  const int x1 = img.width - 4 * scale - textW - 2 * scale, x0 = x1 - barW;
  const int y0 = (img.height - barH) / 2;
  for (int y = y0 - 4 * scale; y < y0 + barH + 4 * scale; ++y)  // dark backing
    for (int x = x0 - 2 * scale; x < img.width - 2 * scale; ++x) put(img, x, y, {20, 20, 20});
  for (int y = 0; y < barH; ++y) {
    const auto c = rampColour(1.0 - static_cast<double>(y) / (barH - 1));
    for (int x = x0; x < x1; ++x)
      put(img, x, y0 + y,
          {static_cast<uint8_t>(c[0] * 255), static_cast<uint8_t>(c[1] * 255), static_cast<uint8_t>(c[2] * 255)});
  }
  const int tx = x1 + 2 * scale;
  for (const LegendTick& t : colourLegendTicks(lo, hi)) {  // text centred on its place, inside the bar
    const int y = y0 + static_cast<int>(std::lround((1.0 - t.fraction) * (barH - 1))) - 2 * scale;
    text(img, tx, std::clamp(y, y0, y0 + barH - 5 * scale), t.text, scale);
  }
}

}  // namespace vs
