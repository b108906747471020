// An automatic terminal's end on its vessel's lumen (terminal_end.h).
#include "tracking/terminal_end.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vs {

double shellMedian(const VolumeF32& vol, const Vec3& p, double rIn, double rOut) {
  const Geometry& g = vol.geometry();
  int64_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const int64_t c = std::llround(p[a]), ext = static_cast<int64_t>(std::ceil(rOut / g.spacing[a]));
    lo[a] = std::max<int64_t>(0, c - ext);
    hi[a] = std::min(g.dims[a] - 1, c + ext);
  }
  std::vector<double> shell;
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x)
        if (const double d =
                g.stepLength(Vec3(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)) - p);
            d >= rIn && d <= rOut)
          shell.push_back(vol(x, y, z));
  return shell.empty() ? std::numeric_limits<double>::quiet_NaN() : medianOf(std::move(shell));
}

double shellMedian(const VolumeF32& vol, const Index3& e, double rIn, double rOut) {
  return shellMedian(vol, Vec3(static_cast<double>(e[0]), static_cast<double>(e[1]), static_cast<double>(e[2])), rIn,
                     rOut);
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
