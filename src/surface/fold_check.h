// Fold check of one octant's patch (issue 15: "an octant where the surface folds back over itself
// along a ray is detected and reported, never silently folded").
//
// The subdivision describes each octant's surface as a height field over the rays from the
// centre O (the planes' common point): one surface point per ray. An ear or an overhang breaks
// that: a ray from O leaves the object, crosses outside air, and meets the object again further
// out. Such an octant is either folded by the 3D paths (the mesh turns back) or, more often, the
// overhang is skipped (the paths span its base and the mesh misses it); the check sees both,
// because it asks the image, not the mesh's orientation, whether the object comes back beyond the
// surface the mesh describes. Rays cover the octant's solid angle on a triangular grid (direction
// proportional to (sx*i, sy*j, sz*k) in index space, i + j + k = grid, all >= 1). Along each ray
// that meets the patch, the patch's surface reaches as far as the farthest vertex of the first
// triangle the ray meets (vertices lie on the iso-surface; a coarse triangle's chord lies inside a
// convex object). The ray is folded when, beyond that reach plus one voxel, the image shows the
// object again after leaving it: a gap of at least one voxel (of the finest spacing) that is part
// of the outside (background connected to the volume's border within the octant, so cavities and
// inner layers such as a skull under the scalp do not count), then at least one voxel of object
// connected (6-neighbours, within the octant) to the object voxels under the patch's vertices: the
// same object folding back, not a separate one such as a head holder (counted apart).
// Slivers (nearly collinear vertices whose triangles flip) turn the mesh without any second
// crossing in the image, so they raise no alarm; the mesh's back-facing area is reported apart.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "surface/surface.h"
#include "volume/volume.h"

namespace vs {

// An octant is folded when more than this fraction of its rays is folded (a speck of noise
// outside the surface reaches a ray or two; an ear or overhang covers many).
constexpr double kFoldRayFraction = 0.01;

struct FoldCheck {
  int64_t rays = 0;        // rays from O through the octant that meet the patch
  int64_t foldedRays = 0;  // rays along which the patch's object comes back beyond the patch
  // Rays that meet, beyond the patch and across outside air, only objects not connected to the
  // patch's object within the octant (a head holder, a table): not folds, reported apart.
  int64_t otherObjectRays = 0;
  std::optional<Vec3> firstFold;  // continuous index where the first folded ray meets the object again
  double fraction() const { return rays > 0 ? double(foldedRays) / double(rays) : 0; }
  bool folded() const { return fraction() > kFoldRayFraction; }
};

// `vertices` in world mm, `triangles` the octant's patch; the object is the side of `iso` that
// holds `center` when `brightInside` says so (values >= iso), else values < iso. `rayGrid`: rays
// per side of the triangular grid ((rayGrid-1)(rayGrid-2)/2 rays, >= 3).
FoldCheck checkFold(const VolumeF32& volume, double iso, bool brightInside, const Index3& center,
                    const OctantSigns& octant, const std::vector<Vec3>& vertices,
                    const std::vector<std::array<int32_t, 3>>& triangles, int rayGrid = 48);

}  // namespace vs
