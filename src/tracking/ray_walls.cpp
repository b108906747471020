// Each ray's wall at its own level in a wide lumen (ray_walls.h).
#include "tracking/ray_walls.h"

#include <algorithm>

namespace vs::centreline_detail {

void localRayWalls(const TrilinearSampler& sample, const Vec3& ci, const std::vector<Vec3>& dirsIndex, double centre,
                   double level, double step, size_t stride, double minMedianMm, std::vector<double>& radius,
                   std::vector<double>& found) {
  constexpr int nearSteps = 2, farSteps = 5, minSteps = 6;
  if (found.empty()) return;
  std::vector<double> sorted = found;
  const size_t mid = sorted.size() / 2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid), sorted.end());
  if (sorted[mid] < minMedianMm) return;
  const bool bright = centre > level;
  found.clear();
  for (size_t k = 0; k < dirsIndex.size(); k += stride) {
    const double rk = radius[k];
    if (rk < minSteps * step) {
      if (rk >= 0) found.push_back(rk);
      continue;
    }
    const Vec3& d = dirsIndex[k];
    double in = 0, out = 0;
    for (int i = nearSteps; i <= farSteps; ++i)
      in += sample.at(ci + (rk - i * step) * d), out += sample.at(ci + (rk + i * step) * d);
    if (bright ? in > out : in < out) {
      // The crossing of the ray's own level, marched in quarter steps from 2 steps inside its crossing.
      const double own = 0.5 * (in + out) / (farSteps - nearSteps + 1), h = 0.25 * step;
      double prev = sample.at(ci + (rk - nearSteps * step) * d);
      for (double r = rk - nearSteps * step + h; r <= rk + nearSteps * step; r += h) {
        const double val = sample.at(ci + r * d);
        if (bright ? val < own : val > own) {
          const double a = prev - own, b = val - own;
          radius[k] = r - h + h * (a != b ? std::clamp(a / (a - b), 0.0, 1.0) : 0.5);
          break;
        }
        prev = val;
      }
    }
    found.push_back(radius[k]);
  }
}

bool chordsAgree(const std::vector<Vec3>& dirs, const std::vector<double>& radius, const Vec3& u, const Vec3& v,
                 size_t stride, const Eigen::Vector2d& o2, double tolMm) {
  const size_t half = radius.size() / 2;
  double sum = 0;
  size_t n = 0;
  for (size_t k = 0; k < half; k += stride) {
    if (radius[k] < 0 || radius[k + half] < 0) continue;
    const double e = o2[0] * dirs[k].dot(u) + o2[1] * dirs[k].dot(v) - 0.5 * (radius[k] - radius[k + half]);
    sum += e * e, ++n;
  }
  return n > 0 && sum <= tolMm * tolMm * static_cast<double>(n);
}

}  // namespace vs::centreline_detail
