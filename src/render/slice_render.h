// Plain 2D slice images (axial / coronal / sagittal) with window/level, at the correct
// aspect ratio from the voxel spacing (thesis ch. 5 shows slices inside the 3D scene; this
// is the flat counterpart for reports and quick looks).
//
// Orientation (documented choice): axial (axis 2): x to the right, y down (row 0 = y 0);
// coronal (axis 1): x to the right, z up; sagittal (axis 0): y to the right, z up.
// The output pixel is min(spacing_u, spacing_v) mm square unless fitSize scales the image to
// fit; sampling is bilinear. Labels (same dims) are blended with their palette colour.
#pragma once

#include <vector>

#include "mesh/tri_mesh.h"
#include "render/renderer.h"
#include "util/image.h"
#include "volume/volume.h"

namespace vs {

struct SliceImageOptions {
  WindowLevel window;         // window <= 0: automatic (1st..99.5th percentile of the volume)
  int fitWidth = 0;           // > 0 (with fitHeight): scale the image to fit this box, keeping aspect
  int fitHeight = 0;
  double labelOpacity = 0.5;
  std::array<float, 3> overlayColor{1.0f, 0.2f, 0.2f};
  double overlayBand = 1.0;   // overlay segments within this many voxels of the slice are drawn
};

// 1st..99.5th percentile window of a volume (width, centre).
WindowLevel percentileWindow(const AnyVolume& volume);

// Throws InvalidArgument for axis not in 0..2, index outside the volume, label dims that
// differ, or an output side outside 1..Renderer::kMaxImageSide.
RgbaImage renderSlice(const AnyVolume& volume, int axis, int64_t index, const SliceImageOptions& options = {},
                      const AnyVolume* labels = nullptr, const std::vector<Polyline>* overlays = nullptr);

}  // namespace vs
