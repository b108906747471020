// The terminal scan's region described for the report's note: its size and depth, a leak warning, and what its
// continuation along dim branches and its fronts' spills changed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "volume/volume.h"

namespace vs {

// The share of the volume from which the terminal scan's region is reported as leaked.
inline constexpr double kLeakedRegionShare = 0.2;

std::string describeRegion(const Geometry& g, size_t regionVoxels, const std::vector<float>& depth);

struct RegionChanges {
  size_t continuedVoxels = 0;  // admitted along dim branches (region_continue.h)
  int continuedPieces = 0;
  size_t spilledVoxels = 0;        // left out where fronts spilled (region_fronts.h)
  Index3 spillAt{0, 0, 0};         // the first spill's onset
  double spillMm = 0;              // its distance from the root
  bool continuationAsked = false;  // AutoTerminalOptions::continueDimBranches was on
};
std::string describeRegionChanges(const Geometry& g, const RegionChanges& c);

}  // namespace vs
