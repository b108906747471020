// CPU ray caster for direct volume rendering (thesis 1.1, eq. 1-6; display modes of ch. 5).
// Works without GPU or display; multi-threaded over 16x16 pixel tiles (parallelFor workers
// pulling tiles from a shared counter).
//
// Per ray (world space, honouring spacing/origin/direction): samples every dt =
// sampleStep * min(spacing) mm along the ray inside the volume box (voxel centres 0..dims-1),
// trilinear interpolation (eq. 6), transfer-function lookup (TfTable, opacity corrected for
// dt), optional Blinn-Phong shading with a headlight from central-difference gradients
// divided by the spacing (eq. 1-3, reading notes), front-to-back compositing
//   C += (1 - A) a c,  A += (1 - A) a            (same image as the back-to-front eq. 4-5)
// with early ray termination at A >= earlyTermination. Empty-space skipping: per transfer
// function one 64-bit word per 4^3 block of trilinear cells, bit set = the cell's corner values
// can map to non-zero opacity; rays walk the 4^3 blocks with a 3D DDA (fixed-point crossing
// times), jump over blocks whose word is 0 and skip samples whose cell bit is 0 before
// interpolating. Sample positions are t0 + k dt in 32.32 fixed point (index space), the same
// whichever way sample k is reached, so the image is the same as without skipping.
// Shading (RenderOptions::ambient etc.): colour (ka + kd |n.l|) + ks |n.l|^p with a white
// headlight (ambient light white too; VTK's CPU ray caster with its default light has ka = 0).
// MIP keeps the maximum sample and shows it in grey through the window (or, with
// mipTransferFunction, as TF colour x opacity like VTK); blocks whose maximum cannot beat the
// ray's running maximum or would map to black anyway are skipped.
//
// Modes: Full (whole volume), CutBox (only the index box `box`; its entry faces show the
// data in grey through the window, with opacity faceOpacity, the inside is ray cast behind),
// Triplanar (the three index planes `planes` as textured planes, opaque where they show data
// and nearly clear where their grey is black, so that they do not hide each other behind empty
// space), Monoplanar (one opaque plane), Mip. Overlays (meshes and polylines, e.g. a tree's
// branches) are rasterised first into a view-depth buffer and treated as opaque geometry: each
// ray composites the volume only up to the overlay's depth, then the overlay colour, so depth is
// correct both ways (MIP draws them on top).
//
// Also returned: a per-pixel view depth (mm along the camera's forward axis) where the
// accumulated opacity first reaches depthThreshold (or where a plane/face/overlay was hit);
// +inf where the ray never got there.
//
// Cost: construction O(voxels) (compact copy, automatic window, block min/max); prepare() O(voxels)
// (TF cell words; gradient table 6 bytes/voxel when shading); a frame is O(pixels * samples per
// ray). Memory: 1 (uint8) or 2 bytes per voxel for the values, + 6 bytes per voxel for gradients
// when shading, + ~0.15 for the block grids (min/max floats and cell words per 4^3 block).
// Sources: renderer.cpp (API, preparation), ray_cast.cpp (per-mode casts, compositing),
// block_walk.h (block DDA), overlay_raster.cpp, window_level.h (shared with slice_render).
//
// Thread safety: a Renderer is not safe for concurrent use (render() prepares lazily and the
// setters change its state); render() itself uses parallelFor workers internally. Distinct
// Renderer objects are independent.
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <vector>

#include "mesh/tri_mesh.h"
#include "render/camera.h"
#include "render/transfer_function.h"
#include "render/window_level.h"
#include "util/image.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

enum class RenderMode { Full, CutBox, Triplanar, Monoplanar, Mip };

// "full", "cutbox", "triplanar", "monoplanar", "mip"; throws InvalidArgument otherwise.
RenderMode renderModeFromName(const std::string& name);
std::string renderModeName(RenderMode m);

struct RenderOptions {
  RenderMode mode = RenderMode::Full;
  double sampleStep = 0.5;  // ray sample distance in units of the smallest spacing
  bool shading = true;      // Blinn-Phong from gradients (Full, CutBox)
  // Blinn-Phong, coefficients in [0, 1], power in [0, 128]. VTK's benchmark sets the same numbers,
  // but its CPU ray caster multiplies ambient by the light's ambient colour (black by default).
  double ambient = 0.3, diffuse = 0.8, specular = 0.2, specularPower = 10.0;
  bool emptySpaceSkipping = true;
  double earlyTermination = 0.99;                  // stop a ray once its opacity reaches this
  double depthThreshold = 0.5;                     // opacity at which the depth image is taken
  std::array<double, 6> box{0, 0, 0, -1, -1, -1};  // CutBox: x0,y0,z0,x1,y1,z1 index (inclusive); x1<x0: whole volume
  double faceOpacity = 1.0;                        // CutBox: opacity of the data shown on the box faces
  Vec3 planes{-1, -1, -1};                         // Triplanar: index of the x, y and z planes; < 0: the centre
  int planeAxis = 2;                               // Monoplanar: 0 = x (sagittal), 1 = y (coronal), 2 = z (axial)
  double planeIndex = -1;                          // Monoplanar: index along planeAxis; < 0: the centre
  WindowLevel window;                              // grey mapping of planes, faces and MIP
  bool mipTransferFunction = false;  // MIP pixel = TF colour x TF opacity of the maximum (as VTK), not grey
  double labelOpacity = 0.5;         // blend of label colours into samples and planes
  std::array<float, 3> background{0, 0, 0};
};

struct RenderResult {
  RgbaImage image;           // opaque (alpha 255), background where nothing was hit
  std::vector<float> depth;  // width*height view depths (mm), +inf where none
  int64_t samples = 0;       // volume samples taken (for statistics)
};

// Colour of label l (1..) in the default palette; label 0 is "none".
std::array<float, 3> labelColor(int label);

// Blends label l's palette colour into the colour c with the given opacity (label <= 0: none).
template <class T>
inline void blendLabel(T c[3], int label, T opacity) {
  if (label <= 0) return;
  const auto lc = labelColor(label);
  for (size_t k = 0; k < 3; ++k) c[k] = (1 - opacity) * c[k] + opacity * static_cast<T>(lc[k]);
}

class Renderer {
 public:
  // Keeps a compact copy of the voxels (uint8 as is, other types as uint16 with an offset and a
  // scale, exact for integer data spanning < 65536 values). Throws DataError for non-finite voxels.
  explicit Renderer(const AnyVolume& volume, Progress& progress = Progress::none());
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const Geometry& geometry() const;
  ValueRange range() const;
  // The automatic window (1st..99.5th percentile of the voxel values).
  WindowLevel autoWindow() const;

  void setTransferFunction(const TransferFunction& tf);
  const TransferFunction& transferFunction() const;
  // Throws InvalidArgument for out-of-range box/plane/step values (checked against the volume).
  void setOptions(const RenderOptions& options);
  const RenderOptions& options() const;
  // A label volume with the same dims (values > 0 are labels). Throws InvalidArgument if dims differ.
  void setLabels(const AnyVolume& labels);
  void clearLabels();

  // Overlays in world mm. radiusMm <= 0: use the polyline's radii, else 1.5 pixels.
  void addMesh(const TriMesh& mesh, const std::array<float, 3>& color);
  void addPolylines(const std::vector<Polyline>& lines, const std::array<float, 3>& color, double radiusMm = 0);
  void clearOverlays();
  // Fraction of overlay points outside the volume's world bounding box (0 if none).
  double overlayFractionOutside() const;

  // Builds what the options/TF need (TF table, block flags, gradients). Called by render()
  // when stale; call it yourself to time it separately.
  void prepare(Progress& progress = Progress::none());
  // Renders one frame (calls prepare() first when the TF or options changed). Throws
  // InvalidArgument for an image side outside 1..kMaxImageSide or a degenerate camera.
  RenderResult render(const Camera& camera, int width, int height, Progress& progress = Progress::none());

  static constexpr int kMaxImageSide = 8192;

  struct Impl;  // internal (render/renderer_impl.h), named here for the module's own files

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace vs
