// Internal helpers shared by the phantom generators (not part of the public API).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "phantom/phantom.h"
#include "util/error.h"

namespace vs::phantom_detail {

// Extent (mm) of a voxel box with edge lengths `spacing` along unit direction n: the
// width over which a surface crossing the voxel sweeps from "all in" to "all out".
inline double voxelExtentAlong(const Vec3& n, const Vec3& spacing) {
  return std::abs(n[0]) * spacing[0] + std::abs(n[1]) * spacing[1] + std::abs(n[2]) * spacing[2];
}

// Fraction of a voxel inside a surface, from the signed distance sd (mm, < 0 inside)
// of its centre and its extent along the normal: a linear partial-volume ramp.
inline double coverage(double sd, double extent) { return std::clamp(0.5 - sd / extent, 0.0, 1.0); }

inline void requireFiniteIn(double v, double lo, double hi, const std::string& what) {
  if (!std::isfinite(v) || v < lo || v > hi)
    throw InvalidArgument(what + " = " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " +
                          std::to_string(hi) + "]");
}

// 1e-4 mm (0.1 micron) to 1000 mm: below, squared and cubed lengths underflow (1e-300 gave
// NaN extents and minutes of looping over a NaN-bounded box).
inline constexpr double kMinSpacingMm = 1e-4, kMaxSpacingMm = 1000;
inline void requireSpacing(const Vec3& s, const std::string& who) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(s[i]) || s[i] < kMinSpacingMm || s[i] > kMaxSpacingMm)
      throw InvalidArgument(who + ": spacing must be within [0.0001, 1000] mm on every axis");
}

inline void requireDims(const Index3& d, int64_t minXY, int64_t minZ, const std::string& who) {
  for (int i = 0; i < 3; ++i) {
    const int64_t m = i < 2 ? minXY : minZ;
    if (d[i] < m)
      throw InvalidArgument(who + ": size along " + std::string(1, "xyz"[i]) + " is " + std::to_string(d[i]) +
                            ", need at least " + std::to_string(m));
  }
}

// The truth's root voxel, terminals (ends of childless branches) and branch points (ends of the
// others), from its branches: one home for every generator that builds a VesselTruth.
inline void addRootTerminalsAndBranchPoints(VesselTruth& T) {
  T.rootVoxel = roundIndex(T.branches.front().points.front());
  for (size_t i = 0; i < T.branches.size(); ++i) {
    const VesselBranch& b = T.branches[i];
    if (b.children.empty()) {
      T.terminalVoxels.push_back(roundIndex(b.points.back()));
      T.terminalBranches.push_back(static_cast<int>(i));
    } else {
      VesselBranchPoint bp;
      bp.position = b.points.back();
      bp.voxel = roundIndex(bp.position);
      bp.parent = static_cast<int>(i);
      bp.children = b.children;
      T.branchPoints.push_back(bp);
    }
  }
}

// The family's bone blocks (vessel_family_bone.cpp; phantom.h: makeVesselFamilyBoneCase) drawn from `rng`,
// added to the rendered, noise-free c.volume and listed in c.bones.
void addBoneBlocks(PhantomRng& rng, VesselFamilyCase& c);
VesselFamilyCase makeVesselFamilyCase(uint64_t seed, VesselFamilyVariant variant, const Index3& dims, bool bone);

}  // namespace vs::phantom_detail
