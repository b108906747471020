#include "tracking/auto_cost.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "features/vesselness.h"

namespace vs {

namespace {
double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Values of `vol` at voxels whose physical distance from `c` lies in [r0, r1] mm.
std::vector<double> ballValues(const VolumeF32& vol, const Index3& c, double r0, double r1) {
  const Geometry& g = vol.geometry();
  std::vector<double> out;
  int64_t ext[3];
  for (int a = 0; a < 3; ++a) ext[a] = static_cast<int64_t>(std::ceil(r1 / g.spacing[a]));
  for (int64_t dz = -ext[2]; dz <= ext[2]; ++dz)
    for (int64_t dy = -ext[1]; dy <= ext[1]; ++dy)
      for (int64_t dx = -ext[0]; dx <= ext[0]; ++dx) {
        const int64_t x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
        if (!g.contains(x, y, z)) continue;
        const double d = g.stepLength(Vec3(static_cast<double>(dx), static_cast<double>(dy), static_cast<double>(dz)));
        if (d >= r0 && d <= r1) out.push_back(vol(x, y, z));
      }
  return out;
}

// Robust noise of the intensities around `c`: 1.4826 x the median absolute difference between
// x-neighbours divided by sqrt(2) (edges are a minority of the pairs; a flat region gives the
// noise, a smoothed one its smoothed noise).
double noiseSpread(const VolumeF32& vol, const Index3& c, double radiusMm) {
  const Geometry& g = vol.geometry();
  std::vector<double> diffs;
  int64_t ext[3];
  for (int a = 0; a < 3; ++a) ext[a] = static_cast<int64_t>(std::ceil(radiusMm / g.spacing[a]));
  for (int64_t z = std::max<int64_t>(0, c[2] - ext[2]); z <= std::min(g.dims[2] - 1, c[2] + ext[2]); ++z)
    for (int64_t y = std::max<int64_t>(0, c[1] - ext[1]); y <= std::min(g.dims[1] - 1, c[1] + ext[1]); ++y)
      for (int64_t x = std::max<int64_t>(0, c[0] - ext[0]); x < std::min(g.dims[0] - 1, c[0] + ext[0]); ++x)
        diffs.push_back(std::abs(static_cast<double>(vol(x + 1, y, z)) - vol(x, y, z)));
  return diffs.empty() ? 0.0 : 1.4826 * median(diffs) / std::sqrt(2.0);
}

std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0, double e = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d, e);
  return buf;
}
}  // namespace

std::string LumenEstimate::describe() const {
  return std::string(polarity == TubePolarity::Bright ? "bright" : "dark") +
         fmt(", lumen %.6g (spread %.3g), surroundings %.6g, window %.6g..%.6g", lumen, spread, surround, windowLo,
             windowHi);
}

LumenEstimate estimateLumen(const VolumeF32& vol, const Index3& root, const AutoCostOptions& o) {
  const Geometry& g = vol.geometry();
  if (!g.contains(root))
    throw InvalidArgument("auto cost: root (" + std::to_string(root[0]) + "," + std::to_string(root[1]) + "," +
                          std::to_string(root[2]) + ") is outside the volume " + g.describe());
  VS_REQUIRE(o.lumenRadiusMm >= 0 && o.shellInnerMm >= 0 && o.shellOuterMm > o.shellInnerMm,
             "auto cost: need 0 <= lumen radius, 0 <= shell inner < shell outer (mm)");
  VS_REQUIRE(o.surroundPercentile >= 0 && o.surroundPercentile <= 100, "auto cost: surround percentile in [0,100]");
  VS_REQUIRE(o.windowFraction > 0 && o.windowFraction <= 1, "auto cost: window fraction in (0,1]");
  // At least the 26 neighbours, whatever the spacing.
  const double ball = std::max(o.lumenRadiusMm, g.stepLength(Vec3(1, 1, 1)));
  std::vector<double> lumenVals = ballValues(vol, root, 0, ball);
  LumenEstimate e;
  e.lumen = median(lumenVals);
  for (double& v : lumenVals) v = std::abs(v - e.lumen);
  // Both are noise estimates with an upward bias (edges inside the ball; texture between
  // neighbours), so the smaller is the better one.
  e.spread = std::min(1.4826 * median(lumenVals), noiseSpread(vol, root, o.shellOuterMm));
  const std::vector<double> shell = ballValues(vol, root, o.shellInnerMm, o.shellOuterMm);
  const auto noContrast = [&](const std::string& why) {
    return DataError("auto cost: no contrast around the root (" + why + "; lumen " + fmt("%.6g", e.lumen) +
                     "): give --cost intensity with --polarity bright|dark and --window lo,hi, or another --cost");
  };
  if (shell.empty()) throw noContrast("no voxel in the surroundings");
  const double shellMedian = median(shell);
  e.polarity = shellMedian > e.lumen ? TubePolarity::Dark : TubePolarity::Bright;
  const double dir = e.polarity == TubePolarity::Dark ? 1.0 : -1.0;  // from the lumen towards the surroundings
  const double tiny = 1e-6 * std::max(1.0, std::abs(e.lumen));
  const double minSep = std::max(3.0 * e.spread, 0.05 * std::abs(shellMedian - e.lumen));
  std::vector<double> beyond;  // signed distance from the lumen towards the surroundings
  for (double v : shell)
    if (dir * (v - e.lumen) > std::max(minSep, tiny)) beyond.push_back(dir * (v - e.lumen));
  if (beyond.empty()) throw noContrast("the surroundings hold the lumen's values");
  const auto k = static_cast<std::ptrdiff_t>(o.surroundPercentile / 100.0 * static_cast<double>(beyond.size() - 1));
  std::nth_element(beyond.begin(), beyond.begin() + k, beyond.end());
  const double contrast = beyond[static_cast<size_t>(k)];
  e.surround = e.lumen + dir * contrast;
  if (contrast <= o.minContrastToNoise * std::max(e.spread, tiny))
    throw noContrast(fmt("surroundings %.6g differ from the lumen by %.3g, under %.3g noise spreads of %.3g",
                         e.surround, contrast, o.minContrastToNoise, e.spread));
  const double edge = e.lumen + dir * o.windowFraction * contrast;
  e.windowLo = std::min(e.lumen, edge);
  e.windowHi = std::max(e.lumen, edge);
  return e;
}

AutoCost computeAutoCost(const VolumeF32& volume, const Index3& root, const AutoCostOptions& o, Progress& progress) {
  VS_REQUIRE(o.smoothMm >= 0 && std::isfinite(o.smoothMm), "auto cost: smoothing must be >= 0 mm");
  AutoCost out;
  out.smoothed = o.smoothMm > 0 ? gaussianSmooth3D(volume, o.smoothMm, progress) : volume;
  out.estimate = estimateLumen(out.smoothed, root, o);
  const LumenEstimate& e = out.estimate;
  Cost3DOptions co;
  co.kind = CostKind3D::Intensity;
  co.polarity = e.polarity;
  co.windowLo = e.windowLo;
  co.windowHi = e.windowHi;
  co.smoothMm = 0;  // already smoothed
  co.power = o.power;
  co.epsilon = o.epsilon;
  out.cost = computeNodeCost3D(out.smoothed, co, nullptr, progress);
  out.cost.description =
      "auto: intensity (" + e.describe() + fmt(", smooth %.3g mm, c = eps + (1-s)^%.3g)", o.smoothMm, o.power);
  return out;
}

}  // namespace vs
