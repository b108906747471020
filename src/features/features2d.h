// Per-pixel image features of one 2D slice for the live-wire cost (thesis 2.3, eq. 7-12;
// Mortensen & Barrett 1995): optional Gaussian pre-smoothing, gradient by central
// differences divided by the pixel spacing (reading-notes, eq. 1-3), gradient magnitude,
// Laplacian and its zero crossings.
//
// Layout: every per-pixel array has width * height entries, u (x) fastest:
//   index = u + width * v.
// Units: gradients in intensity / mm, the Laplacian in intensity / mm^2, spacing in mm.
// Anisotropic pixel spacing is honoured everywhere (differences divide by the spacing of
// their axis; the smoothing sigma is given in mm and converted per axis).
//
// Failure behaviour:
//  - a non-finite pixel (NaN, inf) throws DataError naming the slice ("slice z=40") and the
//    first offending pixel: the live-wire cost of a NaN is undefined and silently treating it
//    as 0 would draw contours along holes in the data;
//  - a flat image (all pixels equal) is fine: gradient 0, no zero crossing, maxMagnitude 0;
//    the cost functions then give uniform costs (see cost/live_wire_cost.h).
// Complexity: O(N) for the features, O(N * sigma/spacing) for the smoothing (separable, both
// passes row-wise). Rows are processed in parallel (parallelFor) and the inner loops are
// vectorised (SSE2 where available) with the same arithmetic as the per-pixel definitions:
// interior gradients/Laplacians multiply by precomputed reciprocals of the spacing terms (exact
// for power-of-two spacings, otherwise within one double rounding before the float result).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "volume/volume.h"

namespace vs {

struct Features2DOptions {
  double smoothSigmaMm = 0.0;  // Gaussian pre-smoothing sigma in mm (0 = none); per-axis sigma
                               // in pixels = sigma / spacing, kernel radius ceil(3 sigma px),
                               // replicated borders
};

struct Features2D {
  int64_t width = 0, height = 0;      // pixels along u and v
  double spacingU = 1, spacingV = 1;  // mm
  std::vector<float> smoothed;        // the (optionally smoothed) image the features were taken from
  std::vector<float> gradU, gradV;    // dI/du, dI/dv in intensity / mm (central differences,
                                      // one-sided at the border)
  std::vector<float> magnitude;       // sqrt(gradU^2 + gradV^2), eq. 8
  std::vector<float> laplacian;       // d2I/du2 + d2I/dv2 (3-point stencils, replicated border)
  std::vector<uint8_t> zeroCrossing;  // 1 where the Laplacian changes sign to a 4-neighbour and
                                      // this pixel is the one closer to zero (ties: both), else 0
  float maxMagnitude = 0;             // largest gradient magnitude (0 for a flat image)

  int64_t pixelCount() const { return width * height; }
  int64_t index(int64_t u, int64_t v) const { return u + width * v; }
  bool contains(int64_t u, int64_t v) const { return u >= 0 && v >= 0 && u < width && v < height; }
  // The q-th quantile (0..1) of the gradient magnitude (nearest rank); 0 for a flat image.
  float magnitudeQuantile(double q) const;
};

// Computes the features of a slice. `what` names the slice in error messages; when empty
// it is derived from the view ("slice z=40"). Throws DataError for non-finite pixels,
// InvalidArgument for an empty view or a negative/non-finite sigma.
template <class T>
Features2D computeFeatures2D(const SliceView<T>& slice, const Features2DOptions& options = {},
                             const std::string& what = {});

// Convenience: a 2D image stored as a volume with dims.z == 1 (InvalidArgument otherwise).
Features2D computeFeatures2D(const AnyVolume& image2d, const Features2DOptions& options = {});

// "slice z=40" / "slice y=3" / "slice x=7" for a view.
std::string describeSlice(int axis, int64_t index);

}  // namespace vs
