// Region-of-interest crops of volumes (an inclusive voxel box) and the way back: a result
// computed on the crop is pasted into a volume of the full geometry. The crop keeps spacing and
// direction; its origin is the world position of the box's first voxel, so world coordinates
// of every voxel are unchanged.
#pragma once

#include <string>

#include "volume/volume.h"

namespace vs {

struct VoxelBox {
  Index3 lo{0, 0, 0}, hi{-1, -1, -1};  // inclusive corners (0-based voxel index)

  bool empty() const { return hi[0] < lo[0] || hi[1] < lo[1] || hi[2] < lo[2]; }
  bool contains(const Index3& v) const {
    for (int a = 0; a < 3; ++a)
      if (v[a] < lo[a] || v[a] > hi[a]) return false;
    return true;
  }
  Index3 dims() const { return {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1}; }
  // Full-volume index <-> index in the crop.
  Index3 toLocal(const Index3& v) const { return {v[0] - lo[0], v[1] - lo[1], v[2] - lo[2]}; }
  Index3 toGlobal(const Index3& v) const { return {v[0] + lo[0], v[1] + lo[1], v[2] + lo[2]}; }
  Vec3 toGlobal(const Vec3& v) const {
    return v + Vec3(static_cast<double>(lo[0]), static_cast<double>(lo[1]), static_cast<double>(lo[2]));
  }
  std::string describe() const;  // "x 3..40, y 0..63, z 10..20"
};

// The whole volume as a box.
VoxelBox wholeBox(const Geometry& g);
// A continuous box (x0,y0,z0,x1,y1,z1 in voxel index) intersected with the volume: lower corners
// rounded up, upper ones down. InvalidArgument naming the box when nothing of it is inside.
VoxelBox clampBox(const Geometry& g, const Vec3& lo, const Vec3& hi);
// Geometry of the crop (dims of the box, origin at its first voxel).
Geometry cropGeometry(const Geometry& g, const VoxelBox& box);

// The voxels of `volume` inside `box` (InvalidArgument if the box is empty or not inside).
template <class T>
Volume<T> cropVolume(const Volume<T>& volume, const VoxelBox& box);
// Copies `part` (a crop of box) into `whole` at the box's position (sizes checked).
template <class T>
void pasteVolume(const Volume<T>& part, const VoxelBox& box, Volume<T>& whole);

}  // namespace vs
