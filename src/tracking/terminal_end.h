// An automatic terminal's end on its vessel's lumen (auto_terminals.cpp, issue 21). The lumen region is flooded on
// the node costs of a smoothed image, so beside a vessel's end in a vessel-only (masked) volume, where every voxel
// off the vessels is 0, it takes in a voxel or two of that background: the branch's farthest voxel can be one of them
// (the head CTA's terminals on zero voxels just past a vessel's end), and the path's refined end lies off the vessel.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "util/median.h"
#include "volume/volume.h"

namespace vs {

// An end voxel's share of the contrast from its background to its lumen level below which it is off the lumen.
constexpr double kOffLumen = 0.25;

// The index in `chain` (the far end's medial chain, the end first, back towards the paths so far) of the end on the
// lumen. Level: the chain's median intensity over its first 5 mm; background: the median of a shell 2 r + 2 .. 2 r + 6
// mm round the end (outside the vessel whatever its width; r = radiusMm); either polarity. When a voxel within
// 2 r + 2 x the largest spacing of the end is off the lumen (below kOffLumen of the contrast), the end moves back to
// the first voxel on the lumen beyond the last such; 0 (the end kept) when none is off, none beyond is on, or the
// end has no contrast to its background.
size_t endOnLumen(const VolumeF32& vol, const std::vector<Index3>& chain, double radiusMm);

// A terminal's last stretch judged against the tube that feeds it (session 39 end71: the aorta MRA's renal path ran
// ~30 mm on past the artery's end through a thread of dimmer tissue - endOnLumen judges an end by its own first 5 mm).
struct FadedStretch {
  bool found = false;
  size_t first = 0;  // the stretch is chain[0 .. first] (first: where the chain fell, nearest the paths)
  double level = 0, background = 0, medianValue = 0, lengthMm = 0;
  size_t shellsRead = 0;  // background shells measured (session 41 cpu144: only where the fall's test needs one)
};

// `chain`: the far end first, back to its source; its first `free` voxels are not on the paths so far. From the
// paths outward, the first free voxel k that reads beyond the half-maximum from its tube's level to its local
// background on the background's side, where the chain's stretch from k to its end is a run (PathSupportOptions'
// run length: max(5 mm, 2 largest spacings)) whose median lies there too. Level: the median over the 5 mm of free
// chain before k (the tube's own, as endOnLumen's; none without 5 mm of it); background at k: of endOnLumen's shell
// (2 r + 2 .. 2 r + 6 mm, r = radiusMm there) and `background` (the auto cost's local background, where given) the
// one farther from the level; no contrast (endOnLumen's 3 x median absolute deviation): none. Found only where that
// stretch also turns back (session 40 hook): its end behind k (more than 90 degrees off the tube's direction over
// its 5 mm to k) and nearer k than the stretch's farthest reach by at least the run length; the first fall that
// does not turn back ends the scan (a thin vessel's dim continuation keeps going). The shell is placed where k lies
// more than r from where it was last placed (or where that one holds no voxel) and measured only where a voxel is not
// within half the local background's contrast of the level (the result is the same as measuring every one placed).
FadedStretch fadedStretch(const VolumeF32& vol, const std::vector<Index3>& chain, size_t free,
                          const std::function<double(const Index3&)>& radiusMm,
                          const std::function<double(const Index3&)>& background = {});

// The step (mm) from voxel a to voxel b.
inline Vec3 mmStep(const Geometry& g, const Index3& a, const Index3& b) {
  return Vec3(static_cast<double>(b[0] - a[0]) * g.spacing[0], static_cast<double>(b[1] - a[1]) * g.spacing[1],
              static_cast<double>(b[2] - a[2]) * g.spacing[2]);
}

// The distance (mm) between two voxels.
inline double mmBetween(const Geometry& g, const Index3& a, const Index3& b) {
  return g.stepLength(
      Vec3(static_cast<double>(a[0] - b[0]), static_cast<double>(a[1] - b[1]), static_cast<double>(a[2] - b[2])));
}

// The median (util/median.h) of the voxels whose centres lie rIn .. rOut mm from e or from the continuous point p
// (NaN when the shell is empty): a vessel's level and its background, at an end, along a route
// (terminal_gaps.h) and round a refined point (dim_points.h; a shell round the point's nearest voxel instead is up to
// 0.87 voxel off, enough to leave a point just below the half-maximum).
double shellMedian(const VolumeF32& vol, const Vec3& p, double rIn, double rOut);
double shellMedian(const VolumeF32& vol, const Index3& e, double rIn, double rOut);

// A branch's end on its medial ridge (auto_terminals.cpp's lumen region r: its voxels, depth, medial tree pred). The
// far end of the longest branch is a voxel on the region's wall (the geodesically farthest one): in a wide lumen the
// medial chain runs along the ridge, then veers to a corner of the end face. The end is moved back along the chain to
// the last voxel whose inscribed ball (1.5 x its depth) still reaches the far end.
template <class Region>
int32_t ridgeEnd(const Geometry& g, const Region& r, const std::vector<uint8_t>& suppressed, int32_t far) {
  const Index3 F = g.unlinear(r.voxel[static_cast<size_t>(far)]);
  int32_t end = far;
  float deepest = 0;
  for (int32_t w = far; w >= 0 && !suppressed[static_cast<size_t>(w)]; w = r.pred[static_cast<size_t>(w)]) {
    const double d = r.depth[static_cast<size_t>(w)];
    const double dist = mmBetween(g, F, g.unlinear(r.voxel[static_cast<size_t>(w)]));
    deepest = std::max(deepest, static_cast<float>(d));
    if (dist > 3.0 * deepest + g.spacing.maxCoeff()) break;  // well past the end's neighbourhood
    if (dist <= 1.5 * d) end = w;
  }
  return end;
}

// The end on its vessel's lumen, not on background the smoothed cost took in (terminal_end.h): moved back along its
// chain (at most 64 voxels, not into the paths' suppression zones).
template <class Region, class Radius>
int32_t endOnItsLumen(const VolumeF32& vol, const Region& r, const std::vector<uint8_t>& suppressed, int32_t end,
                      Radius&& lumenRadius) {
  std::vector<int32_t> back;
  std::vector<Index3> backAt;
  for (int32_t w = end; w >= 0 && !suppressed[static_cast<size_t>(w)] && back.size() < 64;
       w = r.pred[static_cast<size_t>(w)])
    back.push_back(w), backAt.push_back(r.index(w));
  return back.empty() ? end : back[endOnLumen(vol, backAt, lumenRadius(r.index(end)))];
}

}  // namespace vs
