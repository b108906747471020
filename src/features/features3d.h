// 3D image features for 3D Intelligent Scissors and tracking (thesis 1.1 eq. 1-3, 4.2 eq. 21-24,
// corrections in reading-notes.md).
//
// Layout: every per-voxel array is a flat std::vector indexed by Geometry::linear(x,y,z)
// (x fastest), the same layout as the source volume. Units: gradient in intensity units per
// mm (central differences divided by the voxel spacing, anisotropy honoured); the Laplacian of
// eq. 24 is dimensionless-scaled intensity (V minus the mean of its 26 neighbours).
// Border voxels use replicated (clamped) neighbours, i.e. one-sided differences for the gradient.
// Complexity: O(N) time, parallel over z slices (vs::parallelFor), 2 floats per voxel of memory.
// Compute once and reuse: a Features3D object is immutable and serves every later trace/query.
#pragma once

#include <cstdint>
#include <vector>

#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct Features3DOptions {
  bool laplacian = true;  // also compute the eq. 24 Laplacian (zero-crossing term)
  // "max G" of eq. 20 is this percentile of the non-zero |grad| values (100 = the true max), so
  // one bright outlier (metal, a calcification) does not flatten every other edge's cost.
  double robustMaxPercentile = 99.5;
};

struct Features3D {
  Geometry geometry;                     // of the source volume
  std::vector<float> gradientMagnitude;  // G(u), eq. 21, intensity / mm
  std::vector<float> laplacian;          // eq. 24: V(u) - mean of its 26 neighbours (empty if not asked)
  float maxGradient = 0;                 // largest G over the volume
  float robustMaxGradient = 0;           // the options' percentile of G (>= a tiny epsilon; <= maxGradient)

  bool hasLaplacian() const { return !laplacian.empty(); }
  // True where the Laplacian is strictly positive (the per-node sign bit of eq. 22; see cost3d.h).
  bool laplacianPositive(int64_t i) const { return laplacian[static_cast<size_t>(i)] > 0.0f; }
};

// Central-difference gradient at one voxel (eq. 1-3 with the corrected division by spacing),
// one-sided at the border. Index (x,y,z) must be inside; unchecked.
Vec3 centralGradient(const VolumeF32& volume, int64_t x, int64_t y, int64_t z);

// The voxel of largest centralGradient magnitude within `radius` voxels (a ball in index units,
// clipped to the volume) of p; ties go to the nearest. p itself when radius <= 0. p must be
// inside (InvalidArgument otherwise). The viewer's point snap (a click onto the nearby edge).
Index3 strongestGradientVoxel(const VolumeF32& volume, const Index3& p, double radius);

// Computes G and the Laplacian for every voxel. Throws DataError on non-finite voxels,
// InvalidArgument on an empty volume or a percentile outside (0,100]. Cancellable via progress.
Features3D computeFeatures3D(const VolumeF32& volume, const Features3DOptions& options = {},
                             Progress& progress = Progress::none());

// The p-th percentile (0 < p <= 100) of a float array by nth_element on a copy (O(N); arrays
// over 4M values are subsampled with a fixed stride). positiveOnly: ignore values <= 0 (so a
// mostly flat volume does not get a zero "max"). Used for robust maxima. Empty input -> 0.
float percentileOf(const std::vector<float>& values, double p, bool positiveOnly = false);
// The subsampling stride percentileOf uses for n values (1 up to 8M values): a block-wise caller
// that gathers the values at linear indices k * stride of the whole array, then calls percentileOf
// on them, gets the whole array's percentile exactly (the Dask pyramid's vesselness, issue 25).
size_t percentileSampleStride(size_t n);

}  // namespace vs
