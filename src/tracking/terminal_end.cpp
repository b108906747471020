// An automatic terminal's end on its vessel's lumen (terminal_end.h).
#include "tracking/terminal_end.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vs {

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double shellMedian(const VolumeF32& vol, const Index3& e, double rIn, double rOut) {
  const Geometry& g = vol.geometry();
  std::vector<double> shell;
  int64_t ext[3];
  for (int a = 0; a < 3; ++a) ext[a] = static_cast<int64_t>(std::ceil(rOut / g.spacing[a]));
  for (int64_t z = std::max<int64_t>(0, e[2] - ext[2]); z <= std::min(g.dims[2] - 1, e[2] + ext[2]); ++z)
    for (int64_t y = std::max<int64_t>(0, e[1] - ext[1]); y <= std::min(g.dims[1] - 1, e[1] + ext[1]); ++y)
      for (int64_t x = std::max<int64_t>(0, e[0] - ext[0]); x <= std::min(g.dims[0] - 1, e[0] + ext[0]); ++x)
        if (const double d = mmBetween(g, {x, y, z}, e); d >= rIn && d <= rOut) shell.push_back(vol(x, y, z));
  return shell.empty() ? std::numeric_limits<double>::quiet_NaN() : medianOf(std::move(shell));
}

size_t endOnLumen(const VolumeF32& vol, const std::vector<Index3>& chain, double radiusMm) {
  if (chain.size() < 2) return 0;
  const Geometry& g = vol.geometry();
  auto at = [&](const Index3& v) { return static_cast<double>(vol(v[0], v[1], v[2])); };
  // The chain's lumen level: the median over its first 5 mm (a voxel or two of background there do not move it).
  std::vector<double> lumen;
  double arc = 0;
  for (size_t i = 0; i < chain.size() && arc <= 5.0; ++i) {
    if (i > 0) arc += mmBetween(g, chain[i], chain[i - 1]);
    lumen.push_back(at(chain[i]));
  }
  // The end's background: a shell outside the vessel whatever its width.
  const double bg = shellMedian(vol, chain.front(), 2 * radiusMm + 2, 2 * radiusMm + 6);
  if (std::isnan(bg)) return 0;
  const double level = medianOf(lumen);
  // A contrast the lumen's own spread could give is none (the shell in tissue of the lumen's values, a vessel entering
  // a bright organ): 3 x the median absolute deviation of the chain's values.
  for (double& x : lumen) x = std::abs(x - level);
  if (!(std::abs(level - bg) > 3 * medianOf(std::move(lumen)))) return 0;
  // Off the lumen: nearer the background than kOffLumen of the contrast. The voxels a smoothed cost takes in beside a
  // masked vessel are the background itself; a tapering end in noise has voxels round the half-maximum (a half-way cut
  // moved thin family ends 3-4 mm back, off their true ends).
  const double cut = bg + kOffLumen * (level - bg), sign = level > bg ? 1.0 : -1.0;
  auto onLumen = [&](size_t i) { return sign * (at(chain[i]) - cut) >= 0; };
  // The last voxel off the lumen within maxBack of the end: the end's last stretch crosses none (a voxel of background
  // that joins a stub of vessel to the chain is no lumen either); the end is the first voxel on the lumen beyond it,
  // towards the paths.
  const double maxBack = 2 * radiusMm + 2 * g.spacing.maxCoeff();
  size_t lastOff = chain.size();
  arc = 0;
  for (size_t i = 0; i < chain.size(); ++i) {
    if (i > 0) arc += mmBetween(g, chain[i], chain[i - 1]);
    if (arc > maxBack) break;
    if (!onLumen(i)) lastOff = i;
  }
  if (lastOff == chain.size()) return 0;
  for (size_t i = lastOff + 1; i < chain.size(); ++i)
    if (onLumen(i)) return i;
  return 0;
}

}  // namespace vs
