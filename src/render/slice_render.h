// Plain 2D slice images (axial / coronal / sagittal) with window/level, at the correct
// aspect ratio from the voxel spacing (thesis ch. 5 shows slices inside the 3D scene; this
// is the flat counterpart for reports and quick looks).
//
// Orientation: anatomical, whatever the storage order (volume/slice.h): axial anterior up and
// patient right on the left, coronal and sagittal superior up. The output pixel is
// min(spacing_u, spacing_v) mm square unless fitWidth/fitHeight scale the image to fit, or
// pixelPerVoxel asks for one picture pixel per voxel (no resampling: coordinates read off the
// picture are voxel indices through the SliceFrame). Sampling is bilinear. Labels (same dims)
// are blended with their palette colour; overlays are drawn in their own colours.
#pragma once

#include <array>
#include <vector>

#include "mesh/tri_mesh.h"
#include "render/renderer.h"
#include "util/image.h"
#include "volume/slice.h"
#include "volume/volume.h"

namespace vs {

struct SliceImageOptions {
  WindowLevel window;  // window <= 0: automatic (1st..99.5th percentile of the volume)
  int fitWidth = 0;    // > 0 (with fitHeight): scale the image to fit this box, keeping aspect
  int fitHeight = 0;
  bool pixelPerVoxel = false;       // one picture pixel per voxel (ignores fit and the spacing's aspect)
  bool orientationLetters = false;  // anatomical letters (R/L, A/P, S/I) at the middle of each edge
  bool indexTicks = false;          // ticks on the top and left edges every 10 voxel indices (longer every 50)
  double labelOpacity = 0.5;
  std::array<float, 3> overlayColor{1.0f, 0.2f, 0.2f};
  std::vector<std::array<float, 3>> polylineColors;  // one per overlay polyline; empty: overlayColor
  double overlayBand = 1.0;                          // overlay segments within this many voxels of the slice are drawn
};

// Size of the picture of one slice and its mapping to voxel indices. A picture pixel centre
// (i, j) (0-based, i right, j down) shows the continuous voxel index
//   indexAtOrigin + i * indexPerColumn + j * indexPerRow.
struct SlicePicture {
  SliceFrame frame;
  int width = 0, height = 0;
  Vec3 indexAtOrigin, indexPerColumn, indexPerRow;

  Vec3 indexOf(double i, double j) const { return indexAtOrigin + i * indexPerColumn + j * indexPerRow; }
  // Picture position (continuous, pixel centres at integers) of a voxel index.
  std::array<double, 2> pixelOf(const Vec3& index) const;
};

// Throws InvalidArgument for axis not in 0..2, index outside the volume, or an output side
// outside 1..Renderer::kMaxImageSide.
SlicePicture slicePicture(const Geometry& g, int axis, int64_t index, const SliceImageOptions& options = {});

// Colour of overlay number i (0-based) in every display mode: red, green, cyan, yellow,
// magenta, then again; the legend of a picture lists them in this order.
std::array<float, 3> overlayPaletteColor(size_t i);

// 1st..99.5th percentile window of a volume (width, centre).
WindowLevel percentileWindow(const AnyVolume& volume);

// Throws InvalidArgument for axis not in 0..2, index outside the volume, label dims that
// differ, polylineColors not empty and not one per overlay polyline, or an output side
// outside 1..Renderer::kMaxImageSide.
RgbaImage renderSlice(const AnyVolume& volume, int axis, int64_t index, const SliceImageOptions& options = {},
                      const AnyVolume* labels = nullptr, const std::vector<Polyline>* overlays = nullptr);

}  // namespace vs
