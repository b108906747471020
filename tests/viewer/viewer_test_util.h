// Image measures for the viewer's tests: foreground fraction and SSIM restricted to the
// foreground (pixels that are not background black in either image).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "util/image.h"

namespace vs::viewer {

inline bool isForeground(const uint8_t* p) { return p[0] + p[1] + p[2] > 6; }

// True when a pixel within `radius` of `at` has colour rgb, each channel within tol (a handle or
// a contour drawn there).
inline bool colourNear(const RgbaImage& im, std::array<int, 2> at, int radius, std::array<int, 3> rgb, int tol) {
  for (int y = at[1] - radius; y <= at[1] + radius; ++y)
    for (int x = at[0] - radius; x <= at[0] + radius; ++x) {
      if (x < 0 || y < 0 || x >= im.width || y >= im.height) continue;
      const uint8_t* p = im.at(x, y);
      if (std::abs(p[0] - rgb[0]) <= tol && std::abs(p[1] - rgb[1]) <= tol && std::abs(p[2] - rgb[2]) <= tol)
        return true;
    }
  return false;
}

inline double foregroundFraction(const RgbaImage& im) {
  int64_t n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) n += isForeground(im.at(x, y)) ? 1 : 0;
  return double(n) / double(int64_t(im.width) * im.height);
}

// Mean SSIM (Wang et al. 2004, luminance, 7x7 windows, C1 = (0.01 L)^2, C2 = (0.03 L)^2) over the
// windows whose centre pixel is foreground in either image.
inline double foregroundSsim(const RgbaImage& a, const RgbaImage& b) {
  if (a.width != b.width || a.height != b.height) return 0;
  const int W = a.width, H = a.height, r = 3;
  auto lum = [](const RgbaImage& im, int x, int y) {
    const uint8_t* p = im.at(x, y);
    return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
  };
  const double C1 = std::pow(0.01 * 255, 2), C2 = std::pow(0.03 * 255, 2);
  double sum = 0;
  int64_t count = 0;
  for (int y = r; y < H - r; ++y)
    for (int x = r; x < W - r; ++x) {
      if (!isForeground(a.at(x, y)) && !isForeground(b.at(x, y))) continue;
      double ma = 0, mb = 0, va = 0, vb = 0, cov = 0;
      const int n = (2 * r + 1) * (2 * r + 1);
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) ma += lum(a, x + dx, y + dy), mb += lum(b, x + dx, y + dy);
      ma /= n;
      mb /= n;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const double da = lum(a, x + dx, y + dy) - ma, db = lum(b, x + dx, y + dy) - mb;
          va += da * da, vb += db * db, cov += da * db;
        }
      va /= n - 1;
      vb /= n - 1;
      cov /= n - 1;
      sum += ((2 * ma * mb + C1) * (2 * cov + C2)) / ((ma * ma + mb * mb + C1) * (va + vb + C2));
      ++count;
    }
  return count ? sum / double(count) : 0;
}

}  // namespace vs::viewer
