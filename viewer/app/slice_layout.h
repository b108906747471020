// How a slice view shows a slice so that it reads like every other viewer (radiological
// convention: patient left on the screen's right; anterior up in axial, superior up in coronal
// and sagittal, anterior on the left in sagittal), whatever the file's storage order: the slice's
// u/v axes are flipped where the direction matrix says so, and every edge is labelled with the
// anatomical direction (R/L/A/P/S/I) it really points to. LPS world: +x = L, +y = P, +z = S.
#pragma once
#include <array>
#include <optional>
#include <set>
#include <string>

#include "render/renderer.h"
#include "scissors/live_wire.h"
#include "util/image.h"
#include "volume/volume.h"

namespace vs::viewer {

// Built on the core's picture frame (volume/slice.h sliceFrame): the anatomical plane, which slice
// axis runs across the screen, the flips and the edge letters are the frame's, so the viewer shows
// a slice as `volscissors render` draws it. u, v stay the slice's own axes (volume/slice.h
// SliceView, the live-wire's pixels); `transposed` says u runs down the screen (a volume stored
// sagittally or coronally).
struct SliceLayout {
  int axis = 2;  // fixed axis: 0 x, 1 y, 2 z (SliceView's u/v order)
  int64_t index = 0;
  std::string plane = "axial";    // the anatomical plane the slice lies in (sagittal, coronal, axial)
  int64_t width = 0, height = 0;  // slice pixels along u, v
  double spacingU = 1, spacingV = 1;
  bool transposed = false;               // u down the screen, v across it
  bool flipU = false, flipV = false;     // u / v runs against the screen axis it is shown along
  std::string left, right, top, bottom;  // anatomical labels of the screen edges
  // Screen position in [0,1]^2 (x right, y down) of the centre of slice pixel (u, v), and back.
  void toScreen(double u, double v, double& sx, double& sy) const;
  PixelUV fromScreen(double sx, double sy) const;  // clamped to the slice
  // The texture coordinate (u / width, v / height) shown at screen position (sx, sy) in [0,1]^2.
  std::array<double, 2> textureAt(double sx, double sy) const;
  // The slice's extent in mm across (x) and down (y) the screen.
  double screenWidthMm() const { return transposed ? double(height) * spacingV : double(width) * spacingU; }
  double screenHeightMm() const { return transposed ? double(width) * spacingU : double(height) * spacingV; }
};

// Where a slice image lies in a view of viewW x viewH pixels (x right, y down): fitted at its
// physical aspect ratio and centred (zoom 1, pan 0), scaled by `zoom` about the view's centre and
// moved by `pan` (in units of the fitted image's width and height, so a resized window keeps it).
// Zoom and pan change only what is shown: pickAt maps a view position back to the slice pixel
// under it, so a click after zoom or pan picks the voxel the user sees.
struct SliceFit {
  SliceLayout layout;
  double fitW = 0, fitH = 0;            // image size at zoom 1 (view pixels)
  double x0 = 0, y0 = 0, w = 0, h = 0;  // the image's rectangle in the view
  double viewW = 0, viewH = 0, zoom = 1;
  std::array<double, 2> pan{0, 0};
  // View position of slice pixel (u, v)'s centre.
  std::array<double, 2> viewOf(double u, double v) const;
  // The slice pixel under a view position; nullopt outside the image.
  std::optional<PixelUV> pickAt(double px, double py) const;
  // The pan that keeps the image point under view position (px, py) in place at zoom `newZoom`
  // (wheel zoom about the mouse, as Slicer and ITK-SNAP do).
  std::array<double, 2> panForZoomAbout(double px, double py, double newZoom) const;
  // The pan after dragging the image by (dx, dy) view pixels.
  std::array<double, 2> panAfterDrag(double dx, double dy) const;
};
SliceFit fitSlice(const SliceLayout& layout, double viewW, double viewH, double zoom = 1,
                  std::array<double, 2> pan = {0, 0});

// How labels (a loaded label map or the cut's parts) and the tools' drawn results (contours,
// trees, meshes) are shown over the slice views and the 3D view.
struct OverlaySettings {
  double labelOpacity = 0.5;    // blend of the label colour (render/renderer.h labelColor) into the image
  double overlayOpacity = 1.0;  // contours, trees, meshes
  std::set<int> hiddenLabels;   // hidden in every view; in the 3D view their voxels are not drawn
  bool labelVisible(int label) const { return label > 0 && !hiddenLabels.count(label); }
};

SliceLayout sliceLayout(const Geometry& g, int axis, int64_t index);
// The slice in grey through the window, u to the right, v down (no flips: the view flips), with
// the visible labels blended in their palette colour at the overlay's label opacity.
RgbaImage sliceImage(const VolumeF32& volume, int axis, int64_t index, const WindowLevel& window,
                     const VolumeU16* labels = nullptr, const OverlaySettings& overlays = {});

}  // namespace vs::viewer
