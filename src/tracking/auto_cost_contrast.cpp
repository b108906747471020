// The root's contrast test (auto_cost.h; docs/notes/tracking.md session 16 wall1): the lumen against its
// surroundings measured beyond the lumen's own wall, along rays from the root.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "tracking/auto_cost.h"
#include "util/median.h"
#include "volume/neighbourhood.h"
#include "volume/sample.h"

namespace vs {

namespace {
// Unit directions spread evenly over the sphere (a Fibonacci lattice).
std::vector<Vec3> sphereDirections(int n) {
  std::vector<Vec3> out;
  const double golden = std::numbers::pi * (1 + std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double cz = 1 - 2 * (i + 0.5) / n, sz = std::sqrt(std::max(0.0, 1 - cz * cz)), th = golden * (i + 0.5);
    out.emplace_back(std::cos(th) * sz, std::sin(th) * sz, cz);
  }
  return out;
}
}  // namespace

WallContrast rootContrastBeyondWall(const VolumeF32& vol, const Index3& root, double lumen, double dir, double minSep,
                                    const WallContrastOptions& o) {
  VS_REQUIRE(o.rays > 0 && o.reachMm > 0 && o.skipVoxels >= 0 && o.widthMm > 0,
             "auto cost: the wall contrast needs rays > 0, reach > 0, skip >= 0, width > 0");
  const Geometry& g = vol.geometry();
  const TrilinearSampler sample(vol);
  const double step = 0.5 * g.spacing.minCoeff();
  const int n = static_cast<int>(std::ceil(o.reachMm / step));
  const double skipMm = o.skipVoxels * g.spacing.maxCoeff();
  WallContrast out;
  out.rays = o.rays;
  std::vector<double> perRay, profile, beyond;
  for (const Vec3& d : sphereDirections(o.rays)) {
    // The ray's samples (mm from the root) until it leaves the volume.
    profile.clear();
    for (int k = 0; k <= n; ++k) {
      const double t = k * step;
      const Vec3 p(root[0] + t * d[0] / g.spacing[0], root[1] + t * d[1] / g.spacing[1],
                   root[2] + t * d[2] / g.spacing[2]);
      if (!sample.inside(p)) break;
      profile.push_back(sample.at(p));
    }
    // Its wall: the first sample beyond the lumen's values (more than minSep towards the surroundings) whose
    // surroundings are beyond them too. Its surroundings: the median of its samples from skipVoxels (largest spacings)
    // past the wall (the partial-volume wall) over widthMm; a ray ending sooner takes what it has past the wall. A dip
    // whose surroundings along the ray are back in the lumen's values is the lumen's own (a noisy or dimmer stretch
    // deep in a wide, flat lumen, the root itself such a voxel: every ray's "wall" at its first sample, seed 2004):
    // the ray looks on for its wall past that dip.
    const auto skip = static_cast<size_t>(std::lround(skipMm / step));
    const auto width = static_cast<size_t>(std::lround(o.widthMm / step)) + 1;
    const auto beyondLumen = [&](double v) { return dir * (v - lumen) > minSep; };
    double found = 0;
    bool left = false;
    for (size_t k = 0; k < profile.size() && !left;) {
      if (!beyondLumen(profile[k])) {
        ++k;
        continue;
      }
      const size_t first = k + skip, last = std::min(profile.size(), first + width);
      beyond.assign(profile.begin() + static_cast<std::ptrdiff_t>(first < last ? first : k),
                    profile.begin() + static_cast<std::ptrdiff_t>(first < last ? last : profile.size()));
      found = dir * (medianInPlace(beyond) - lumen);
      left = found > minSep;
      while (k < profile.size() && beyondLumen(profile[k])) ++k;  // past the dip
    }
    if (!left) {
      perRay.push_back(0);  // lumen (or no contrast) as far as it reaches
      continue;
    }
    ++out.leaving;
    perRay.push_back(found);
  }
  out.contrast = medianInPlace(perRay);
  out.surround = lumen + dir * out.contrast;
  return out;
}

std::vector<double> shellOutsideLumen(const VolumeF32& vol, const Index3& root, double innerMm, double outerMm,
                                      double lumen, double dir, double half, int64_t* left) {
  const Geometry& g = vol.geometry();
  const TrilinearSampler sample(vol);
  const double step = 0.5 * g.spacing.minCoeff();
  std::vector<double> out;
  int64_t inside = 0;
  forEachVoxelNear(g, root, outerMm, [&](int64_t x, int64_t y, int64_t z, double d) {
    if (d < innerMm || d > outerMm) return;
    const double v = vol(x, y, z);
    // On the lumen's side of the half-maximum: is it reached from the root along a straight line that stays there?
    bool reached = dir * (v - lumen) < half;
    const Vec3 to(static_cast<double>(x - root[0]), static_cast<double>(y - root[1]), static_cast<double>(z - root[2]));
    const int n = static_cast<int>(std::ceil(d / step));
    for (int k = 1; k < n && reached; ++k) {
      const double t = static_cast<double>(k) / n;
      const Vec3 p(root[0] + t * to[0], root[1] + t * to[1], root[2] + t * to[2]);
      if (dir * (sample.at(p) - lumen) >= half) reached = false;
    }
    if (reached)
      ++inside;
    else
      out.push_back(v);
  });
  if (left != nullptr) *left = inside;
  return out;
}

}  // namespace vs
