#include "tracking/path_support.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "util/text.h"

namespace vs {

namespace {

// The node cost stores eps + (1 - s)^power as float: s below this is none.
constexpr double kNoMembership = 1e-6;

double stepMm(const Geometry& g, const Index3& a, const Index3& b) {
  return g.stepLength(
      Vec3(static_cast<double>(b[0] - a[0]), static_cast<double>(b[1] - a[1]), static_cast<double>(b[2] - a[2])));
}

std::string offsetText(const Index3& v, const Index3& o) {
  return indexText(Index3{v[0] + o[0], v[1] + o[1], v[2] + o[2]});
}

}  // namespace

std::vector<VoxelSupport> pathSupport(const std::vector<Index3>& voxels, const NodeCost3D& cost,
                                      const AutoCostOptions& co, const VolumeF32& smoothed,
                                      const LocalBackground& background, const LumenEstimate& estimate,
                                      const PathSupportOptions& options) {
  const Geometry& g = smoothed.geometry();
  std::vector<VoxelSupport> out;
  out.reserve(voxels.size());
  for (const Index3& v : voxels) {
    VoxelSupport s;
    const double c = cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))];
    const double q = std::max(0.0, c - co.epsilon);
    s.membership = std::clamp(1.0 - std::pow(q, 1.0 / co.power), 0.0, 1.0);
    const LocalContrast lc = localContrastAt(smoothed, background, estimate, v, false);
    s.intensity = lc.intensity;
    s.contrast = lc.contrast;
    s.noise = std::max(estimate.spread, lc.spread);
    s.supported = s.membership > kNoMembership || s.contrast > options.noiseSpreads * s.noise;
    out.push_back(s);
  }
  return out;
}

std::vector<UnsupportedStretch> unsupportedStretches(const Geometry& g, const std::vector<Index3>& voxels,
                                                     const std::vector<VoxelSupport>& support,
                                                     const PathSupportOptions& options) {
  std::vector<UnsupportedStretch> out;
  const double minMm = std::max(options.minLengthMm, options.minSpacings * g.spacing.maxCoeff());
  const size_t n = std::min(voxels.size(), support.size());
  for (size_t i = 0; i < n;) {
    if (support[i].supported) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < n && !support[j + 1].supported) ++j;
    UnsupportedStretch s;
    s.first = i, s.last = j;
    std::vector<double> contrasts;
    s.minIntensity = s.maxIntensity = support[i].intensity;
    s.maxContrast = support[i].contrast;
    for (size_t k = i; k <= j; ++k) {
      if (k > i) s.lengthMm += stepMm(g, voxels[k - 1], voxels[k]);
      s.minIntensity = std::min(s.minIntensity, support[k].intensity);
      s.maxIntensity = std::max(s.maxIntensity, support[k].intensity);
      s.maxContrast = std::max(s.maxContrast, support[k].contrast);
      s.noise = std::max(s.noise, support[k].noise);
      contrasts.push_back(support[k].contrast);
    }
    std::nth_element(contrasts.begin(), contrasts.begin() + static_cast<std::ptrdiff_t>(contrasts.size() / 2),
                     contrasts.end());
    s.medianContrast = contrasts[contrasts.size() / 2];
    if (s.lengthMm >= minMm) out.push_back(s);
    i = j + 1;
  }
  return out;
}

std::vector<std::string> pathSupportNotes(const std::vector<TracedPath>& paths, size_t givenTargets,
                                          const NodeCost3D& cost, const AutoCostOptions& costOptions,
                                          const VolumeF32& smoothed, const LocalBackground& background,
                                          const LumenEstimate& estimate, const Index3& messageOffset,
                                          const PathSupportOptions& options) {
  std::vector<std::string> notes;
  const Geometry& g = smoothed.geometry();
  for (size_t i = 0; i < paths.size(); ++i) {
    const TracedPath& p = paths[i];
    if (!p.reached || p.voxels.empty()) continue;
    const std::vector<VoxelSupport> support =
        pathSupport(p.voxels, cost, costOptions, smoothed, background, estimate, options);
    const std::vector<UnsupportedStretch> stretches = unsupportedStretches(g, p.voxels, support, options);
    const size_t shared = p.parentPath >= 0 ? p.junctionIndex : 0;  // voxels [0, shared] are an earlier path's
    const std::string name = i < givenTargets ? "target #" + std::to_string(i + 1)
                                              : "automatic terminal #" + std::to_string(i + 1 - givenTargets);
    for (const UnsupportedStretch& s : stretches) {
      if (p.parentPath >= 0 && s.last <= shared) continue;
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    ": its path crosses %.1f mm without lumen from %s to %s (path voxels %zu-%zu of %zu): no lumen "
                    "in the cost's model and intensity %.4g..%.4g, contrast to the local background %.3g (median) "
                    "to %.3g (most), not beyond the noise spread %.3g; the path may not follow a vessel there",
                    s.lengthMm, offsetText(p.voxels[s.first], messageOffset).c_str(),
                    offsetText(p.voxels[s.last], messageOffset).c_str(), s.first, s.last, p.voxels.size(),
                    s.minIntensity, s.maxIntensity, s.medianContrast, s.maxContrast, s.noise);
      notes.push_back(name + " " + offsetText(p.target, messageOffset) + buf);
    }
  }
  return notes;
}

}  // namespace vs
