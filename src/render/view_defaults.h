// What every front end shows for a volume given no options: one policy for the CLI, the
// viewer and the Python bindings, chosen so that each display mode shows something on any
// volume (tests/cli/default_views_test.cpp measures that on every shared data set).
//   view:        OrbitView (render/camera.h), from anterior-left-above: no plane edge-on;
//   cutbox:      the central half of the volume along every axis;
//   monoplanar:  the central slice of the axial index axis (volume/slice.h axialIndexAxis);
//   triplanar:   the three central planes;
//   MIP window:  1st percentile .. 99.99th percentile of the voxels, so the brightest
//                structure along most rays (bone in a head CT) is not all white.
#pragma once

#include "render/renderer.h"
#include "volume/volume.h"

namespace vs {

// The central half of the volume: index box x0,y0,z0,x1,y1,z1 (inclusive, rounded).
std::array<double, 6> defaultCutBox(const Geometry& g);

// RenderOptions{} with the mode and the defaults above filled in (box, plane axis, MIP window).
RenderOptions defaultRenderOptions(const AnyVolume& volume, RenderMode mode);

// Window spanning the lo..hi quantiles of the finite voxels (width, centre).
WindowLevel quantileWindow(const AnyVolume& volume, double lo, double hi);

}  // namespace vs
