// The thesis's environment-map mesh (3.1; reading notes on 5.1): rays from a centre inside the
// object towards the vertices of a latitude-longitude grid on the unit sphere; each ray's vertex is
// where it leaves the object (the iso crossing, linear between samples). It describes only objects
// that are star-shaped from the centre: a ray that leaves the object and meets it again shows a
// part hidden behind another, and the mesh is refused (use the iso-surface mesh instead).
#pragma once

#include <optional>

#include "mesh/tri_mesh.h"
#include "volume/volume.h"

namespace vs {

struct EnvMapOptions {
  double iso = 0;                // the object is the voxels >= iso
  std::optional<Vec3> centerMm;  // ray origin, world mm; default: the centroid of the object's voxels
  int latitudes = 90;            // rows of the grid from pole to pole (>= 4)
  int longitudes = 180;          // columns around the axis (>= 8)
};

// Vertices in world mm, triangles wound outwards. Throws DataError when the volume holds no object
// voxel, the centre lies outside the object, or the object is not star-shaped from the centre
// (saying how many rays meet it again, and where the first does); InvalidArgument on bad options.
TriMesh envMapMesh(const VolumeF32& volume, const EnvMapOptions& options);

}  // namespace vs
