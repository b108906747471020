// The split (thesis 3.1, 3.3): the cutting surface is voxelised thick enough that no 26-connected
// path crosses it, then region growing from both of its sides over the object (voxels >= iso)
// labels the two parts. Labels: 0 background, 1 kept, 2 cut away.
#pragma once

#include <cstdint>
#include <optional>

#include "cutting/cutting_surface.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct SplitOptions {
  // Voxel (index) whose side is kept; empty = cut away the smaller side.
  std::optional<Index3> keepSeed;
};

struct SplitResult {
  VolumeU8 labels;  // same geometry as the volume
  int64_t keptVoxels = 0, cutVoxels = 0;
  int64_t surfaceVoxels = 0;  // voxels the cutting surface blocked (each given to one side)
};

// Throws DataError when the two sides of the surface are joined (the contour does not enclose
// a part: "separates nothing"), when one side holds no object, or for a seed outside the object,
// on the cutting surface or on neither side. Cancellable.
SplitResult splitVolume(const VolumeF32& volume, double iso, const CuttingSurface& surface,
                        const SplitOptions& options = {}, Progress& progress = Progress::none());

// One part of a split as a volume of its own: `volume` with every voxel whose label is not
// `label` set to the volume's minimum (so a viewer shows the part alone). InvalidArgument when
// the dimensions differ.
template <class T>
Volume<T> splitPart(const Volume<T>& volume, const VolumeU8& labels, uint8_t label);

}  // namespace vs
