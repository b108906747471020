// The terminal scan's lumen region grown by depth-ordered fronts (issue 21): where a front widens
// beyond what a tree's lumens do, the region has spilled into tissue of the lumen's values.
//
// The region's voxels are ordered by their geodesic distance from the root through the region and
// cut into shells one largest spacing thick; a shell's connected pieces are the fronts. In a tube
// a front is the lumen's cross-section; at the root, the root's lumen on both sides. Going along a
// tree a front stays a branch's cross-section (distally narrower; proximally each parent ~1.6 x
// its child's area, Murray). A front that enters a sheet of the lumen's values (non-contrast CT's
// body wall and mediastinum, a layer of tissue a vessel touches) widens along the sheet as a ring,
// one that enters a blob (a heart chamber) as a growing sphere's cap: many times the root's
// cross-section within a few of the blob's or sheet's own sizes. Such a front, every front beyond
// it (reached only through spilled ones) and the widened fronts before it are the spill.
//
// Measured (docs/notes/tracking.md, session 17 leak2): the depth of a front (pi x depth^2 against
// its area) was tried first and fails: the region is porous in a wide lumen near the lumen level
// (stent struts, noise), its depth there is a third of the lumen's radius.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "volume/volume.h"

namespace vs {

struct RegionFrontOptions {
  // The root's front: the widest front within refRadii x the root's radius (+ 2 shells) of it.
  double refRadii = 4.0;
  // A front wider than this times the root's front has left the root's tree: the root's front is its
  // lumen's cross-section on both sides (2 x), and going up a tree each generation's parent is
  // 2^(2/3) ~ 1.6 x as wide as its child (Murray), so 8 x allows ~3 generations above the root.
  double maxAreaRatio = 8.0;
  // A spilled front's parents wider than this times the root's front are left out as well.
  double backOffRatio = 3.0;
};

struct RegionFronts {
  std::vector<uint8_t> spilled;  // per slot: 1 where the region has spilled
  size_t spilledVoxels = 0;
  double rootArea = 0;         // the root's front (mm^2)
  int onsets = 0;              // fronts where a spill starts (not all their parents spilled)
  Index3 firstOnset{0, 0, 0};  // a voxel of the first (nearest the root)
  double firstOnsetMm = 0;     // its geodesic distance from the root
  double firstOnsetArea = 0;
};

// The region's adjacency when it is built (auto_terminals.cpp): per slot a record of `stride` entries, the
// neighbour count, then the neighbours' slots packed as slot << 5 | step. records null: the slot array is read.
struct RegionAdjacency {
  const uint32_t* records = nullptr;
  size_t stride = 0;
};

// voxel/at: the region's voxels (linear index, index) per slot; slot: per volume voxel, -1 outside;
// dist: per slot, the geodesic distance (mm) from the root; rootRadiusMm: its lumen's radius.
RegionFronts regionFronts(const Geometry& g, int connectivity, const std::vector<int64_t>& voxel,
                          const std::vector<std::array<int32_t, 3>>& at, const std::vector<int32_t>& slot,
                          const std::vector<double>& dist, double rootRadiusMm, const RegionFrontOptions& o = {},
                          const RegionAdjacency& adjacency = {});

}  // namespace vs
