// The valley term of the auto cost (issue 21, kissing vessels): a voxel that is less lumen-like
// than BOTH of its samples along some line through it - the dip (bright polarity) or ridge (dark)
// between two lumens that touch or nearly touch - is not lumen, however lumen-like its own value.
// After partial volume and the cost's smoothing two tubes under a voxel apart are one bright
// region whose neck still lies below both tubes' interiors along the line joining them; without
// this term a path jumps through that neck when its own tube is the longer way round.
//
// Depth at voxel v: over the 13 opposite pairs (a, b) of the 26 neighbour directions, at each
// radius of `scales` (ringScalesFor: valleyVoxels x 2^k smallest spacings, 1 and 2 by default),
// the largest
//   bright: min(a, b) - v        dark: v - max(a, b)
// i.e. how far the voxel lies below (above) the dimmer (brighter) of its two sides on the line
// where that is most. Inside a tube the line across it has darker sides and the line along it
// flat ones (noise only); at a tube's wall one side is background: no depth there. The auto cost
// takes it twice: on the unsmoothed intensities, ramped from valleyNoiseFloor (2) noise spreads
// of those intensities (the cost's smoothing fills a neck under a voxel wide), and on the smoothed
// ones, ramped from the local contrast's t0 (one noisy voxel of the neck is no way through); each
// over the local contrast's span, capping the voxel's lumen score s by 1 - the ramp
// (docs/notes/tracking.md, session 13 kiss3).
#pragma once

#include <cstdint>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {

// The valley depth of voxel (x, y, z) (above); stops early once it exceeds `enough`. Samples
// outside the volume take the nearest face voxel.
double valleyDepth(const VolumeF32& smoothed, const std::vector<RingScale>& scales, int64_t x, int64_t y, int64_t z,
                   bool bright, double enough);

// The lumen score s capped by the valley at (x, y, z): min(s, 1 - clip((depth - lo) / span, 0, 1)).
// Only computed where s > 0 (a valley makes nothing cheaper).
double capByValley(const VolumeF32& smoothed, const std::vector<RingScale>& scales, int64_t x, int64_t y, int64_t z,
                   bool bright, double s, double lo, double span);

}  // namespace vs
