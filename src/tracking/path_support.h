// Nothing silent about a path through tissue (issue 21): a traced path is the cheapest way from the root to its
// target, and where the image offers none along a lumen it still finds one, straight through whatever lies between
// (session 18: the abdominal CT's perigastric paths crossed the stomach's wall and content, down to -293 HU). The
// auto cost already says per voxel how much it is lumen (its membership s, the node cost c = eps + (1 - s)^power)
// and what its contrast is against its own local background (localContrastAt); a path voxel is unsupported where
// both say no: s = 0 (the cost at its ceiling) and the smoothed value not beyond the local background by one noise
// spread (the larger of the root's and the local one, the unit the cost's own floor t0 counts in). A contiguous run
// of unsupported voxels at least minLengthMm long along the path is reported in the trace's notes with its ends,
// length and the contrast found there. The paths themselves are not changed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "cost/cost3d.h"
#include "tracking/auto_cost.h"
#include "tracking/tracker.h"

namespace vs {

struct PathSupportOptions {
  // A stretch shorter than this is not reported: a thin vessel's partial-volume dip, a voxel path cutting a bend
  // (the family's tuning seeds' longest on paths along their tubes: 3.1 mm; docs/notes/tracking.md session 19 tissue1).
  double minLengthMm = 5;
  double minSpacings = 2;   // ... nor shorter than this many of the largest spacing (thick slices: one slice's dip)
  double noiseSpreads = 1;  // a contrast up to this many noise spreads is none
};

// Per path voxel: the auto cost's membership and contrast there.
struct VoxelSupport {
  double membership = 0;  // s, from the node cost
  double intensity = 0;   // smoothed
  double contrast = 0;    // towards the lumen, against the local background
  double noise = 0;       // the larger of the root's and the local spread
  bool supported = true;
};

struct UnsupportedStretch {
  size_t first = 0, last = 0;  // indices into the path's voxels (inclusive)
  double lengthMm = 0;         // along the path, from its first voxel to its last
  double minIntensity = 0, maxIntensity = 0;
  double medianContrast = 0, maxContrast = 0;  // towards the lumen (maxContrast: the most lumen-like)
  double meanContrast = 0;                     // towards the lumen, over the stretch's voxels
  double noise = 0;                            // the largest noise spread along it
};

// The support of every voxel of `voxels` under the auto cost (`cost` its node cost with `options`' eps and power,
// `smoothed` and `background` what it saw, `estimate` the root's).
std::vector<VoxelSupport> pathSupport(const std::vector<Index3>& voxels, const NodeCost3D& cost,
                                      const AutoCostOptions& costOptions, const VolumeF32& smoothed,
                                      const LocalBackground& background, const LumenEstimate& estimate,
                                      const PathSupportOptions& options = {});

// The contiguous runs of unsupported voxels at least max(minLengthMm, minSpacings x the largest spacing) long (from
// the first voxel's centre to the last one's).
std::vector<UnsupportedStretch> unsupportedStretches(const Geometry& g, const std::vector<Index3>& voxels,
                                                     const std::vector<VoxelSupport>& support,
                                                     const PathSupportOptions& options = {});

// The notes for every path's stretches (a stretch wholly inside the part a path shares with an earlier one is left to
// that one). Voxels are written with `messageOffset` added (a crop's origin in the whole volume).
std::vector<std::string> pathSupportNotes(const std::vector<TracedPath>& paths, size_t givenTargets,
                                          const NodeCost3D& cost, const AutoCostOptions& costOptions,
                                          const VolumeF32& smoothed, const LocalBackground& background,
                                          const LumenEstimate& estimate, const Index3& messageOffset,
                                          const PathSupportOptions& options = {});

}  // namespace vs
