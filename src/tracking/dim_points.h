// Refined points on a partial-volume dip of a thin vessel (issue 21, session 27 net10). On a vessel about a voxel
// across, the search's route steps diagonally through voxels the vessel only grazes (a 3DRA artery's route reads
// 120, 70, 24, 112, 128), and the refinement, centring in the smoothed intensities, leaves its point on such a voxel
// or a fraction of a voxel off the ridge: the point reads below half-way from its background to its vessel's level
// in the image itself, i.e. outside the vessel by the half-maximum the criterion uses.
#pragma once

#include <cstddef>

#include "tracking/centreline.h"
#include "volume/volume.h"

namespace vs {

// Moves every refined point (the root and points on a wide trunk's axis, RefinedCentreline::wideTrunk, excepted) that
// reads, in `vol` (trilinear), nearer its background than half the way to its vessel's level onto the most lumen-like
// position within half a voxel of it (index space: the voxel cell the point stands for). Level: the median of the
// refined points within 5 mm along the tree; background: the median of a shell 2 r + 2 .. 2 r + 6 mm round the point
// (outside the vessel whatever its width; r its radius), as terminal_end.h's; a point whose level lies within one
// median absolute deviation (of the values within 5 mm) of that background has no contrast and is left. `polarity`
// > 0: the lumen is bright, < 0 dark, 0: nothing moves. Repeated (at most 3 passes, half a voxel each) while a pass
// moves a point, since the levels follow the moved points. Returns the number of moves.
size_t ridgeDimPoints(const VolumeF32& vol, RefinedCentreline& refined, int polarity);

}  // namespace vs
