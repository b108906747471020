#pragma once
// Continuous sampling of a volume at a (fractional) index position.

#include "volume/volume.h"

namespace vs {

// Trilinear interpolation at a continuous index (x, y, z), clamped to the volume: the one sampler
// shared by the centreline refinement and the surface cost.
double sampleTrilinear(const VolumeF32& volume, const Vec3& index);

}  // namespace vs
