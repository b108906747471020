// The cost that keeps 3D scissors paths on one iso-surface (thesis 4.2 eq. 19-22 and 4.3.1, with
// the corrections of reading-notes.md and issue 15).
//
// Node cost, turned into an edge cost by the engine as w(u,v) = len_mm(u,v) * (c(u) + c(v)) / 2:
//   c(u) = floor + w_g * (1 - min(G(u), maxG) / maxG) + w_iso * min(d(u) / h, 1)
//   d(u) = |V(u) - iso| / max(G(u), tiny)   first-order distance (mm) from the voxel to the iso-surface
//   h    = the finest voxel spacing (mm)
// Why each term:
//  * floor > 0: every edge costs at least floor * length, so among paths of equal image cost the
//    shortest wins. Without it the thesis's gradient cost is exactly 0 on every voxel whose |G|
//    reaches the robust maximum, and a path across such a plateau may wander arbitrarily far.
//  * the iso term: the thesis's gradient cost is cheap on *every* strong edge, so a path between two
//    skin points may dive to the skull (also a strong edge). Voxels within a voxel of the chosen
//    iso-surface are cheap, every other voxel costs w_iso more per mm: the path stays on the surface.
//  * the gradient term (eq. 20 with the robust max and the corrected denominator) prefers the
//    sharpest part of the boundary band, as in the thesis.
// All costs are finite and in [floor, floor + w_g + w_iso]. O(N) time, parallel over slices.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "util/progress.h"
#include "volume/sample.h"
#include "volume/volume.h"

namespace vs {

struct SurfaceCostOptions {
  double floor = 0.05;                // > 0: the positive floor per mm on every edge
  double weightGradient = 0.3;        // w_g
  double weightIso = 1.0;             // w_iso
  double robustMaxPercentile = 99.5;  // maxG = this percentile of the non-zero |grad|
};

struct SurfaceCost {
  std::vector<float> node;  // c(u) per voxel, x fastest
  double iso = 0;
  double robustMaxGradient = 0;
  std::string description;
};

// Throws InvalidArgument for floor <= 0, negative or non-finite weights, a percentile outside
// (0, 100]; DataError for non-finite voxels. Cancellable.
SurfaceCost computeSurfaceCost(const VolumeF32& volume, double iso, const SurfaceCostOptions& options = {},
                               Progress& progress = Progress::none());

// Otsu's threshold of the volume's histogram (256 bins between the 0.1th and 99.9th percentiles):
// the default iso-value, which separates an object (head, organ) from its background.
double otsuThreshold(const VolumeF32& volume);

// Gradient of V (intensity per mm, index axes) at a continuous index by central differences of
// trilinear samples one voxel apart (clamped at the border), and the trilinear value itself.
Vec3 sampleGradient(const VolumeF32& volume, const Vec3& index);

}  // namespace vs
