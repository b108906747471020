// Where a ray crosses an iso-value of a volume's trilinear image: the one ray walk shared by the
// environment-map mesh (cutting/envmap.h: refuses objects that rays leave and meet again) and the
// fold check of surface extraction (surface/fold_check.h: an octant whose surface folds back).
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "volume/volume.h"

namespace vs {

struct IsoCrossing {
  double t = 0;         // mm from the origin, linear between the two samples around the crossing
  bool rising = false;  // from below the iso-value to >= it
};

struct RayIsoCrossings {
  bool startsAbove = false;  // the value at the origin is >= the iso-value
  std::vector<IsoCrossing> crossings;
  double end = 0;  // mm where the walk stopped: the first sample outside the volume or at maxLength,
                   // or the sample after the last crossing wanted
};

// Samples the ray origin + t * direction (world mm, `direction` a unit vector) every `step` mm from
// t = step until the sample lies more than half a voxel outside the volume or t >= maxLength; a
// crossing lies between two consecutive samples on different sides of `iso` (>= iso vs < iso).
// Stops once `maxCrossings` crossings are found.
RayIsoCrossings rayIsoCrossings(const VolumeF32& volume, double iso, const Vec3& origin, const Vec3& direction,
                                double step, double maxLength,
                                size_t maxCrossings = std::numeric_limits<size_t>::max());

}  // namespace vs
