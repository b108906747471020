// An automatic terminal's end on its vessel's lumen (terminal_end.h).
#include "tracking/terminal_end.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/path_support.h"

namespace vs {

namespace {

// shellMedian's box: the voxels within rOut mm of p along each axis, clipped to the volume.
void shellBox(const Geometry& g, const Vec3& p, double rOut, int64_t lo[3], int64_t hi[3]) {
  for (int a = 0; a < 3; ++a) {
    const int64_t c = std::llround(p[a]), ext = static_cast<int64_t>(std::ceil(rOut / g.spacing[a]));
    lo[a] = std::max<int64_t>(0, c - ext);
    hi[a] = std::min(g.dims[a] - 1, c + ext);
  }
}

// Geometry::stepLength's length, its body inlined (session 45 speedE: the out-of-line call per shell voxel was 1.5 % of
// the carotid trace's instructions).
inline double stepMm(const Geometry& g, const Vec3& d) { return g.spacing.cwiseProduct(d).norm(); }

// Calls visit(x, y, z) for each voxel of the shell rIn..rOut mm round p, in shellMedian's order, until it returns
// false; false if it stopped. Inlined into both callers (a template, not a std::function: the loop is hot in
// ridgeDimPoints).
template <class Visit>
bool forEachShellVoxel(const Geometry& g, const Vec3& p, double rIn, double rOut, Visit&& visit) {
  int64_t lo[3], hi[3];
  shellBox(g, p, rOut, lo, hi);
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x)
        if (const double d =
                stepMm(g, Vec3(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)) - p);
            d >= rIn && d <= rOut && !visit(x, y, z))
          return false;
  return true;
}

// Whether shellMedian's shell holds a voxel (its median is not NaN): the first one found answers it.
bool shellHasVoxel(const Geometry& g, const Vec3& p, double rIn, double rOut) {
  return !forEachShellVoxel(g, p, rIn, rOut, [](int64_t, int64_t, int64_t) { return false; });
}

// fadedStretch's background shell round the chain, read again once k lies a lumen radius from where it was read or
// where that read found no voxel; its median measured only when asked for (session 41 cpu144: the shells were 0.38 of
// the 0.45 G instructions the scan added to head_3dra 144,90,118's auto trace, and most of them were never used).
class LazyShell {
 public:
  explicit LazyShell(const VolumeF32& vol) : vol_(vol) {}
  // The shell at chain voxel v with the lumen radius r there: moved to v where the original reading rule moves it.
  void follow(const Index3& v, double r) {
    if (placed_ && !(mmBetween(vol_.geometry(), v, at_) > r) && !empty()) return;
    placed_ = true, read_ = false, emptyKnown_ = false, at_ = v, r_ = r;
  }
  double median() {
    if (!read_) value_ = shellMedian(vol_, at_, 2 * r_ + 2, 2 * r_ + 6), read_ = true, ++reads_;
    return value_;
  }
  size_t reads() const { return reads_; }

 private:
  bool empty() {  // no voxel in the shell (its median NaN): the first voxel found answers it
    if (read_) return std::isnan(value_);
    if (!emptyKnown_) empty_ = !shellHasVoxel(vol_.geometry(), toVec(at_), 2 * r_ + 2, 2 * r_ + 6), emptyKnown_ = true;
    return empty_;
  }
  static Vec3 toVec(const Index3& e) {
    return Vec3(static_cast<double>(e[0]), static_cast<double>(e[1]), static_cast<double>(e[2]));
  }
  const VolumeF32& vol_;
  bool placed_ = false, read_ = false, emptyKnown_ = false, empty_ = false;
  size_t reads_ = 0;
  Index3 at_{0, 0, 0};
  double r_ = 0, value_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace

double shellMedian(const VolumeF32& vol, const Vec3& p, double rIn, double rOut) {
  std::vector<double> shell;
  forEachShellVoxel(vol.geometry(), p, rIn, rOut, [&](int64_t x, int64_t y, int64_t z) {
    shell.push_back(vol(x, y, z));
    return true;
  });
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

FadedStretch fadedStretch(const VolumeF32& vol, const std::vector<Index3>& chain, size_t free,
                          const std::function<double(const Index3&)>& radiusMm,
                          const std::function<double(const Index3&)>& background) {
  const Geometry& g = vol.geometry();
  const PathSupportOptions run;
  const double runMm = std::max(run.minLengthMm, run.minSpacings * g.spacing.maxCoeff());
  free = std::min(free, chain.size());
  std::vector<double> arc(chain.size(), 0.0), value(chain.size());  // arc: from the end
  for (size_t i = 0; i < chain.size(); ++i) {
    if (i > 0) arc[i] = arc[i - 1] + mmBetween(g, chain[i], chain[i - 1]);
    value[i] = vol(chain[i][0], chain[i][1], chain[i][2]);
  }
  LazyShell shell(vol);
  for (size_t k = free; k-- > 0;) {  // from the paths outward
    if (arc[k] < runMm) break;
    // The feeding tube: the 5 mm of free chain before k (its level read as endOnLumen reads an end's).
    std::vector<double> lumen;
    size_t j = k + 1;
    for (; j < free && arc[j] - arc[k + 1] <= 5.0; ++j) lumen.push_back(value[j]);
    if (j == free || lumen.empty()) continue;  // less than 5 mm of its own tube before k
    // The local background, read again once k lies a lumen radius from where it was read.
    shell.follow(chain[k], radiusMm(chain[k]));
    const double level = medianOf(lumen), local = background ? background(chain[k]) : shell.median();
    // A voxel within half the local background's contrast of the level is on the level's side of the half-maximum
    // below whichever background is taken (the one farther from the level, below): no shell needed to pass it. Exact:
    // the values are the volume's and the blocks' float samples and upper medians of them, their differences and
    // half-way points exact in double.
    if (2 * std::abs(value[k] - level) <= std::abs(local - level)) continue;
    // Of the two, the one farther from the level (either can read a bright neighbour: the shell a wide vessel's
    // dim part round a thin ridge of it, the blocks an enhancing organ): the fall is not overstated.
    const double sh = shell.median(), bg = std::abs(local - level) > std::abs(sh - level) ? local : sh;
    if (std::isnan(bg)) continue;
    for (double& x : lumen) x = std::abs(x - level);
    if (!(std::abs(level - bg) > 3 * medianOf(std::move(lumen)))) continue;
    const double half = bg + 0.5 * (level - bg), sign = level > bg ? 1.0 : -1.0;
    if (sign * (value[k] - half) >= 0) continue;
    const double med = medianOf(std::vector<double>(value.begin(), value.begin() + static_cast<std::ptrdiff_t>(k + 1)));
    if (!(sign * (med - half) < 0)) continue;
    // The fall alone does not tell tissue past a vessel's end from a thin vessel's dim continuation (a masked CTA's
    // partial volume falls as far, session 39 end71): the stretch must also turn back (session 40 hook) - its end
    // behind the fall (the step from k to the end more than 90 degrees, the walks' turn back, off the feeding tube's
    // direction over its 5 mm to k) and come back towards k from the stretch's farthest reach by at least a run's
    // length (the same run as above). A true dim continuation keeps going: its end is its farthest reach.
    const Vec3 in = mmStep(g, chain[j - 1], chain[k]), net = mmStep(g, chain[k], chain[0]);
    double reach = 0;
    for (size_t i = 0; i <= k; ++i) reach = std::max(reach, mmStep(g, chain[k], chain[i]).norm());
    FadedStretch out;
    out.shellsRead = shell.reads();
    if (in.dot(net) < 0 && reach - net.norm() >= runMm)
      out.found = true, out.first = k, out.level = level, out.background = bg, out.medianValue = med,
      out.lengthMm = arc[k];
    return out;  // not found: the first fall keeps going - a dim continuation, not judged again further out
  }
  FadedStretch out;
  out.shellsRead = shell.reads();
  return out;
}

}  // namespace vs
