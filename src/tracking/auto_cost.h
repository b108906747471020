// trace's default cost: the intensity cost of cost/cost3d.h with its polarity and window
// estimated from the root's neighbourhood against its surroundings, so one default follows
// contrast-filled vessels (CTA, MRA: bright) and air-filled airways (CT: dark) without tuning.
//
// Estimate (on the smoothed intensities the cost sees):
//   lumen    L = median over a ball of lumenRadiusMm around the root (at least its 26 neighbours);
//   spread   s = robust noise: the smaller of 1.4826 * MAD over that ball and 1.4826 * median
//            |v(x+1) - v(x)| / sqrt(2) within shellOuterMm (edges inflate the first, texture the second);
//   surround B: among the shell voxels (shellInnerMm..shellOuterMm from the root) that differ
//            from L by more than max(3 s, 5% of |median(shell) - L|) in the direction of
//            median(shell), the surroundPercentile-th one counted from the lumen's side: the most
//            lumen-like material that is not lumen (lung parenchyma around airways, soft tissue
//            around vessels), so the window does not let paths wander into it;
//   polarity bright if L > median(shell), else dark;
//   window   from L to L + windowFraction * (B - L): the lumen is cheap, everything at or beyond
//            that point (half-way to the surroundings by default) costs the most.
// No contrast (|B - L| <= minContrastToNoise * max(s, tiny) or no surround voxel): DataError that
// names --cost intensity --polarity --window as the way out.
#pragma once

#include <string>

#include "cost/cost3d.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct AutoCostOptions {
  double smoothMm = 0.5;      // Gaussian pre-smoothing sigma of the intensities (mm; 0: none);
                              // more merges thin vessels into the background
  double lumenRadiusMm = 0;   // the root's neighbourhood (0: its 26 neighbours)
  double shellInnerMm = 4.0;  // the surroundings: a shell around the root
  double shellOuterMm = 15.0;
  double surroundPercentile = 5;    // of the non-lumen shell voxels, counted from the lumen's side
  double windowFraction = 0.5;      // the window ends this fraction of the way from L to B
  double minContrastToNoise = 4.0;  // |B - L| must exceed this many noise spreads
  double power = 4;                 // cost exponent (as the intensity cost)
  double epsilon = 1e-3;            // cost floor (as the intensity cost)
};

struct LumenEstimate {
  TubePolarity polarity = TubePolarity::Bright;
  double lumen = 0;                   // L
  double spread = 0;                  // s (noise)
  double surround = 0;                // B
  double windowLo = 0, windowHi = 0;  // the intensity window given to the intensity cost
  std::string describe() const;       // "bright, lumen 312 (spread 9.5), surroundings 48, window 180..312"
};

// Estimates polarity and window at `root` (0-based voxel inside `smoothed`). Throws
// InvalidArgument for a root outside the volume, DataError when there is no contrast.
LumenEstimate estimateLumen(const VolumeF32& smoothed, const Index3& root, const AutoCostOptions& options = {});

struct AutoCost {
  NodeCost3D cost;  // description starts with "auto"
  LumenEstimate estimate;
  VolumeF32 smoothed;  // the intensities the cost and the estimate saw
};

// Smooths, estimates at `root` and returns the intensity node cost with the estimated polarity
// and window.
AutoCost computeAutoCost(const VolumeF32& volume, const Index3& root, const AutoCostOptions& options = {},
                         Progress& progress = Progress::none());

}  // namespace vs
