#include "tracking/neck_section.h"

#include <cmath>
#include <cstddef>

namespace vs {

int climbedPeak(const std::vector<double>& val, int n, int m, int reach) {
  const auto at = [&](int x, int y) { return val[static_cast<size_t>(y * n + x)]; };
  int px = m, py = m;
  for (bool moved = true; moved;) {  // until the climb stays put
    moved = false;
    const int fx = px, fy = py;
    for (int y = fy - 1; y <= fy + 1; ++y)
      for (int x = fx - 1; x <= fx + 1; ++x)
        if ((x - m) * (x - m) + (y - m) * (y - m) <= reach * reach && std::isfinite(at(x, y)) && at(x, y) > at(px, py))
          px = x, py = y, moved = true;
  }
  return py * n + px;
}

bool rimIsBackground(const std::vector<double>& val, const std::vector<int>& lab, int n, double bg, double level,
                     int own, int other) {
  int above = 0, below = 0;  // rim samples at the level in a third component; as far below the rim's median
  for (int q = 0; q < n * n; ++q) {
    const int x = q % n, y = q / n;
    if (!(x == 0 || y == 0 || x == n - 1 || y == n - 1)) continue;
    const double v = val[static_cast<size_t>(q)];
    const int l = lab[static_cast<size_t>(q)];
    above += v >= level && l != own && l != other;
    below += v <= 2 * bg - level;
  }
  return above == 0 || above > below;
}

}  // namespace vs
