// An automatic terminal's route across background between two vessels (auto_terminals.cpp, issue 21). The lumen
// region is flooded on the node costs of a smoothed image, so two vessels that pass within a voxel or two of each
// other without touching are joined through the background between them (a vessel-only head CTA, where every voxel off
// the vessels is 0: the smoothing's halo bridges them). The medial tree may then run from one vessel into the other
// across that background, and the path's refined points there lie off both. Such a crossing is found on a route in the
// raw image and the region's background voxels round it are cut from the medial tree: the route goes the lumen's own
// way, or the vessel beyond is not reached.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "volume/volume.h"

namespace vs {

// Where a route crosses background: a voxel off the lumen (below kOffLumen of the contrast from its background to
// the route's level there, terminal_end.h) with voxels on the lumen before and after it on the route.
struct RouteGap {
  size_t index = 0;     // in the route's voxels
  double cut = 0;       // the intensity below (bright) / above (dark) which a voxel is off the lumen there
  double sign = 1;      // +1 bright lumen, -1 dark
  double radiusMm = 0;  // the lumen's radius beside it
};

// The gaps on route.voxels beyond `from` (a path's own part: beyond where it leaves the paths so far). Level: the
// median raw intensity over the route's voxels within 5 mm (along it); background: the median of a shell
// 2 r + 2 .. 2 r + 6 mm round the voxel (r = the widest radiusMm(v) over those voxels); none where that contrast is
// within 3 x the median absolute deviation of the level's voxels (no lumen contrast to tell background by). Only
// voxels below the level's own spread are looked at (the shell is the cost).
std::vector<RouteGap> routeGaps(const VolumeF32& vol, const std::vector<Index3>& route, size_t from,
                                const std::function<double(const Index3&)>& radiusMm);

// Cuts the crossing at `gap` (at voxel v) from the medial tree: every region voxel (slot[voxel] >= 0) within
// 2 (r + the largest spacing) of v whose raw intensity is off the lumen gets an infinite node weight (the tree's
// Dijkstra never relaxes into it). Returns how many were cut.
size_t cutGap(const VolumeF32& vol, const std::vector<int32_t>& slot, const Index3& v, const RouteGap& gap,
              std::vector<float>& weight);

}  // namespace vs
