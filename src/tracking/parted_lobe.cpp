// placeParted's lobe centre read from the lobe's own walls (session 49 lobewalls; centreline_junctions.h:
// lobeCentreFromWalls).
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

bool lobeCentreFromWalls(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                         double surroundings, double step, const Vec3& d, double outerMm, double innerMm, double maxMm,
                         Vec3& centre) {
  const Vec3 inv = spacing.cwiseInverse();
  const double value = sample.at(c.cwiseProduct(inv));
  if (std::isnan(surroundings) || value == surroundings || step <= 0 || tangent.norm() <= 0) return false;
  const double level = 0.5 * (value + surroundings);
  const bool bright = value > surroundings;
  auto inside = [&](const Vec3& x) {
    return bright ? sample.at(x.cwiseProduct(inv)) >= level : sample.at(x.cwiseProduct(inv)) <= level;
  };
  // The wall from `from` along unit `dir` (mm, interpolated between samples); 0 where `from` is outside the lumen.
  auto wall = [&](const Vec3& from, const Vec3& dir, double& out) {
    out = 0;
    if (!inside(from)) return true;
    double prev = sample.at(from.cwiseProduct(inv));
    for (double r = step; r <= maxMm + 1e-9; r += step) {
      const Vec3 x = (from + r * dir).cwiseProduct(inv);
      if (!sample.inside(x)) return false;
      const double val = sample.at(x);
      if (bright ? val < level : val > level) {
        out = r - step * (level - val) / (prev - val);
        return true;
      }
      prev = val;
    }
    return false;
  };
  const Vec3 e = tangent.normalized().cross(d).normalized();  // across the widest chord, in the section's plane
  const double toward = innerMm > outerMm ? 1 : -1;
  std::vector<double> at, lo, hi;
  for (double x = outerMm + toward * step; toward * (innerMm - x) > 0; x += toward * step) {
    double a = 0, b = 0;
    if (!wall(c + x * d, e, a) || !wall(c + x * d, -e, b)) return false;
    at.push_back(x), lo.push_back(b), hi.push_back(a);
  }
  // The waist between the two lobes: the chord across that dips deepest below the widest on both sides of it, by more
  // than the step the walls are read at (a shallower dip is the sampling's, not the section's).
  size_t waist = at.size();
  double deepest = step, before = 0;
  for (size_t j = 0; j < at.size(); ++j) {
    double after = 0;
    for (size_t i = j + 1; i < at.size(); ++i) after = std::max(after, lo[i] + hi[i]);
    const double dip = std::min(before, after) - (lo[j] + hi[j]);
    if (dip > deepest) deepest = dip, waist = j;
    before = std::max(before, lo[j] + hi[j]);
  }
  // Two chords across the lobe at least (with its outer wall, five walls: a fit, not three points on a notch).
  if (waist == at.size() || lo[waist] + hi[waist] <= 0 || waist < 2) return false;
  // The circle fitted (least squares, Kasa's linear form) to the lobe's own walls - its outer wall (W, 0) and the ends
  // of every chord across between it and the waist (x, hi) / (x, -lo), in (along d, along e) - not through the waist's
  // two ends: the waist is a notch between two discs, and where the slices are thick the trilinear reading fills it
  // from both lobes across a slice (the family renderer's walls are exact at the half level; the interpolation of
  // max(coverage) across the notch is not), so its ends read wide and the circle through them lay 0.2-0.35 mm in
  // towards the sibling (that rendering on 0.80 x 0.80 x 2.19 mm; 11932's fork, widest chord along its slice axis:
  // 0.25 mm, one point past a voxel). A wall read wider all round still widens the circle about its centre.
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  auto add = [&](double u, double v) {
    const Eigen::Vector3d row(u, v, 1);
    normal += row * row.transpose(), rhs += (u * u + v * v) * row;
  };
  add(outerMm, 0);
  for (size_t j = 0; j < waist; ++j) add(at[j], hi[j]), add(at[j], -lo[j]);
  const Eigen::Vector3d fit = normal.ldlt().solve(rhs);
  if (!fit.allFinite()) return false;
  const double x = 0.5 * fit[0], m = 0.5 * fit[1];
  if (toward * (x - outerMm) <= 0) return false;  // not a disc inside its own outer wall
  centre = c + x * d + m * e;
  return true;
}

}  // namespace vs::centreline_detail
