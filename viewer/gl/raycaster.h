// GPU ray caster (layer 2 of viewer/): the CPU renderer's model (render/renderer.h) in a
// fragment shader, for interactive frame rates. The volume is one 3D float texture sampled with
// the hardware's trilinear filter; per pixel a ray from explicit view/projection matrices (one
// pair per eye, app/viewer_app.h EyeView) is intersected with the volume box (voxel centres
// 0..dims-1, spacing, origin and direction honoured), sampled every sampleStep x min(spacing)
// mm, mapped through the transfer function's table (the CPU renderer's TfTable: same opacity
// correction for the step), shaded Blinn-Phong with a headlight from central-difference
// gradients, and composited front to back with early termination. Jittered ray starts (a
// per-pixel hash times one step) remove wood-grain artefacts; off for the comparison tests.
// Modes as the CPU renderer: full, cut box (entry faces in grey through the window, opaque),
// triplanar / monoplanar (opaque grey planes), MIP (grey through the window).
// Needs a current OpenGL 3.3 core context (a window's or EglContext's).
#pragma once
#include <array>
#include <memory>

#include "app/viewer_app.h"
#include "render/renderer.h"
#include "render/transfer_function.h"
#include "util/image.h"
#include "volume/volume.h"

namespace vs::viewer {

struct RayCastSettings {
  RenderMode mode = RenderMode::Full;
  std::array<double, 6> box{0, 0, 0, -1, -1, -1};  // cut box, index, inclusive; x1 < x0: whole volume
  Vec3 planes{-1, -1, -1};                         // triplanar plane indices; < 0: the centre
  int planeAxis = 2;                               // monoplanar
  double planeIndex = -1;                          // monoplanar; < 0: the centre
  WindowLevel window{1, 0};                        // planes, faces, MIP (must be > 0)
  bool shading = true;
  bool jitter = true;
  double sampleStep = 0.5;
  double earlyTermination = 0.99;
  double ambient = 0.3, diffuse = 0.8, specular = 0.2, specularPower = 10.0;
  std::array<float, 3> background{0, 0, 0};
  double labelOpacity = 0.5;  // blend of the label colour into samples, planes and faces (as the CPU renderer)
};

class GpuRayCaster {
 public:
  // Compiles the shaders; throws vs::Error with the compiler's log if that fails.
  GpuRayCaster();
  ~GpuRayCaster();
  GpuRayCaster(const GpuRayCaster&) = delete;
  GpuRayCaster& operator=(const GpuRayCaster&) = delete;

  // Uploads the volume (float 3D texture; 4 bytes per voxel of GPU memory).
  void setVolume(const AnyVolume& volume);
  void setTransferFunction(const TransferFunction& tf);
  // Labels over the volume (same dims; null: none), blended as the CPU renderer does; a label the
  // palette hides is not drawn at all (a cut part shown or hidden). Labels above the palette's
  // size take the colour and visibility of (label - 1) % 12 + 1.
  void setLabels(const VolumeU16* labels);
  static constexpr int kLabelPaletteSize = 1024;
  void setLabelPalette(const OverlaySettings& overlays);
  // Draws into the current framebuffer's viewport (x, y, w, h in GL window coordinates, origin
  // bottom-left). Colour writes obey the caller's glColorMask (anaglyph).
  void draw(const EyeView& eye, int x, int y, int w, int h, const RayCastSettings& settings);
  // Renders into an offscreen framebuffer and reads it back (top row first, as RgbaImage).
  RgbaImage renderImage(const EyeView& eye, int w, int h, const RayCastSettings& settings);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// RgbaImage of the current framebuffer's rectangle (GL window coordinates), rows flipped so the
// top row comes first.
RgbaImage readFramebuffer(int x, int y, int w, int h);

}  // namespace vs::viewer
