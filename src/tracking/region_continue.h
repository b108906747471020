// The terminal scan's lumen region continued along dim branches (issue 21, session 18).
//
// The region is the voxels at or below the cost's lumen level connected to the root. A branch that
// dims along its length (partial volume, wash-out, a portal branch 25-40 HU over the liver) drops below
// that level and the region ends there, though the branch goes on: the terminal scan then stops short
// and finds fewer branch ends than the image holds. A lower per-voxel level would let noise and tissue
// in. Instead, hysteresis along the branch's continuity:
//  - candidates: voxels outside the region at or below a lower level (continueFactor x the lumen level:
//    about the noise floor of the auto cost's local contrast), not left out by the region's fronts (region_fronts.h);
//  - their geodesic distance dR (mm, 26-neighbour steps through candidates) from the region;
//  - the candidates farther than the wall (wallSpacings x the largest spacing) from the region, in
//    26-connected pieces. The region's own partial-volume wall is a thin shell within the wall distance and
//    never a piece; noise beside the tree is a blob a few voxels across; a branch continuing beyond the
//    region's end (or leaving its side dimly) is a tube whose distance from the region grows along it;
//  - a piece is a continuation when it is a resolved tube (its cross-section per shell on average
//  minCrossSectionSquares
//    squares of the largest spacing: a thinner tube is partial volume - on 2 mm slices a small bronchus at -770 HU -
//    or a noise streak) that reaches reachSpacings largest spacings beyond
//    the wall and minReachMm (the terminal scan passes its minimum branch length: a dim stretch shorter than a branch
//    the scan would take only moves a branch's end into its partial-volume tail - the README airway's ends to -850 HU),
//    cut at the first shell (one largest spacing of dR) wider than widenRatio x its first shells (a tube keeps its
//    cross-section; a sheet or blob of tissue it opens into widens): those voxels, and the candidates on their shortest
//    way back to the region, are admitted.
// The region is then flooded again with the admitted voxels as lumen (bright parts beyond a dim stretch
// join through them), and continued again (a few rounds, each reaching at most maxReachMm).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cost/cost3d.h"
#include "volume/volume.h"

namespace vs {

struct RegionContinueOptions {
  // The candidates' level: this x the lumen level. The default lumen level is 0.2 x the background's (90th
  // percentile) cost, so 4 x it is 80 % of the background's cost: with the lumen model's power 4 a lumen-ness of
  // ~0.05 against the level's ~0.33, about the auto cost's noise floor. The continuity tests below, not the level,
  // keep noise and tissue out. Measured (docs/notes/tracking.md, session 18 region3): sqrt(5) x (half the level's
  // lumen-ness) admitted a band of contrast so narrow that a branch fading past it was lost; 4.8 x (96 %: any
  // contrast) let a vesselness cost's halo beyond the tree's tips in (PhantomAuto: no terminal within 4 voxels).
  double continueFactor = 4.0;
  double wallSpacings = 1.5;   // the region's wall: candidates within this x the largest spacing of it
  double reachSpacings = 3.0;  // a continuation reaches this x the largest spacing beyond the wall,
  double minReachMm = 0;       // and at least this far from the region (the terminal scan's branch length)
  double widenRatio = 3.0;     // a shell wider than this x the piece's first shells: it opened into tissue
  // A continuation's mean cross-section, in squares of the largest spacing: a resolved tube, not a chain.
  double minCrossSectionSquares = 2.0;
  double minCompactness = 0.2;  // a shell's area against its bounding box's longest side squared (a disc: pi / 4)
  double maxReachMm = 40.0;     // the candidates' search reaches this far from the region per round
};

struct RegionContinuation {
  std::vector<int64_t> admitted;  // linear voxel indices outside the region, admitted as lumen
  int pieces = 0;                 // candidates' pieces beyond the wall
  int continued = 0;              // of them, continuations
  size_t candidates = 0;          // candidate voxels reached from the region
  int open = 0;                   // continuations that reach the search's limit (maxReachMm): go on next round
};

// regionVoxels/slot: the region (linear indices; per volume voxel its slot, -1 outside); excluded: per volume
// voxel, 1 where the region's fronts left it out (empty: none); level: the lumen level (on nodeWeight x node).
RegionContinuation continueRegion(const Geometry& g, const NodeCost3D& cost, double level,
                                  const std::vector<int64_t>& regionVoxels, const std::vector<int32_t>& slot,
                                  const std::vector<uint8_t>& excluded, const RegionContinueOptions& o = {});

}  // namespace vs
