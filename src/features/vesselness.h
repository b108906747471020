// Hessian-based multi-scale vesselness (Frangi et al., MICCAI 1998) for tracking tubular
// structures (thesis 4.3.2; the gradient cost of eq. 19-21 follows vessel *walls*, a
// vesselness cost follows *centerlines*). Written here without ITK (ITK stays in src/io).
//
// Per scale sigma (mm): Gaussian smoothing (separable, sigma/spacing voxels per axis, kernel
// radius ceil(3 sigma), clamped borders), Hessian by central differences divided by the
// spacing, scale-normalised by sigma^2; eigenvalues |l1| <= |l2| <= |l3| (closed form);
//   V = (1 - exp(-Ra^2 / 2a^2)) exp(-Rb^2 / 2b^2) (1 - exp(-S^2 / 2c^2)),
//   Ra = |l2|/|l3|, Rb = |l1|/sqrt|l2 l3|, S = sqrt(l1^2+l2^2+l3^2), c = half the max S,
// and V = 0 unless l2, l3 have the polarity's sign (bright tubes: both < 0, e.g. contrast CTA,
// MRA; dark tubes: both > 0, e.g. airways in CT). The result is the maximum over scales.
// Layout: flat vector, x fastest (Geometry::linear). Values in [0, 1].
// Complexity: O(N * (sum of kernel sizes + const)) per scale, parallel over slices;
// memory 3 floats per voxel. Cancellable through progress.
#pragma once

#include <vector>

#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

enum class TubePolarity { Bright, Dark };

struct VesselnessOptions {
  std::vector<double> scalesMm;  // Gaussian sigmas in mm; empty: {1, 2, 3} x smallest spacing
  TubePolarity polarity = TubePolarity::Bright;
  double alpha = 0.5;  // plate vs line sensitivity (Ra)
  double beta = 0.5;   // blob vs line sensitivity (Rb)
  double c = 0;        // structureness scale; 0: half the max S at each scale
  // c per scale, given (e.g. the whole volume's, when a block is computed alone); empty: `c` above.
  std::vector<double> cPerScale;
};

// The scales used (opt.scalesMm, or {1, 2, 3} x the smallest spacing). Throws InvalidArgument.
std::vector<double> vesselnessScales(const Geometry& g, const VesselnessOptions& opt);

// Voxels of context a block needs on each side so that its vesselness equals the whole volume's:
// the largest Gaussian kernel radius over scales and axes, plus 1 for the Hessian's differences.
// A block cut out with this margin (none beyond the volume's faces) gives, inside the margin, the
// same floats as computeVesselness on the whole volume (the Dask pyramid relies on it, issue 25).
int vesselnessHaloVoxels(const Geometry& g, const VesselnessOptions& opt);

// Frangi's c per scale, half the largest Hessian (Frobenius) norm, over the voxels of the box
// [lo, hi) of `volume` (the whole volume when hi is {0,0,0}). The maximum over blocks (each with
// the halo above, its own voxels as the box) is the whole volume's c, which computeVesselness
// takes through cPerScale. 0 for a flat scale.
std::vector<double> vesselnessStructureScale(const VolumeF32& volume, const VesselnessOptions& opt,
                                             const Index3& lo = {0, 0, 0}, const Index3& hi = {0, 0, 0});

// Throws InvalidArgument on an empty volume or a non-positive scale, DataError on NaN voxels.
std::vector<float> computeVesselness(const VolumeF32& volume, const VesselnessOptions& options = {},
                                     Progress& progress = Progress::none());

// Separable Gaussian smoothing with sigma in mm per axis (sigma/spacing voxels), clamped borders.
// sigma 0 on an axis leaves it unsmoothed. Exposed for tests and other features.
VolumeF32 gaussianSmooth3D(const VolumeF32& volume, double sigmaMm, Progress& progress = Progress::none());

// Eigenvalues of the symmetric matrix [[a,d,e],[d,b,f],[e,f,c]] sorted by absolute value
// ascending (|l[0]| <= |l[1]| <= |l[2]|). Closed form, double precision.
void symmetricEigenvalues3(double a, double b, double c, double d, double e, double f, double l[3]);

}  // namespace vs
