// The ray caster's per-frame work (internal to the render module): one cast function per
// display mode (planes, MIP, composited volume) sharing one front-to-back compositing and one
// label blend (blendLabel), run over 16x16 pixel tiles that parallelFor workers pull from a
// shared counter. Thread safety: the frame is read-only while the workers cast; every worker
// writes only its own tiles' pixels.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "render/renderer_impl.h"

namespace vs {

// Per-frame constants shared by every ray.
struct CastFrame {
  CastFrame(const Renderer::Impl& impl, const CameraFrame& camera, const OverlayBuffer* overlays);

  const Renderer::Impl& I;
  const RenderOptions& o;
  const CameraFrame& cf;
  const OverlayBuffer* ob;  // null: no overlays
  double dt;                // sample distance, mm
  WindowLevel wl;
  bool shade, haveLabels;
  float lop;  // label opacity
  double volLo[3], volHi[3], boxLo[3], boxHi[3];
  std::vector<std::pair<int, double>> planes;  // Triplanar / Monoplanar: (axis, index)
  int maxC[3];                                 // last trilinear cell per axis
  Mat3 Dt;                                     // direction transposed (world -> index axes)
  float bg[3];
  // MIP: the largest value that still maps to black (window low end, or where the TF's opacity
  // starts); blocks whose maximum is at or below it (or the ray's running maximum) are skipped.
  float mipFloor;
  std::vector<uint8_t> mipOn;
};

// Casts every pixel's ray into res.image and res.depth (sized by the caller); returns the number
// of volume samples taken. Throws Cancelled (checked once per tile).
int64_t castImage(const CastFrame& frame, RenderResult& res, Progress& progress);

}  // namespace vs
