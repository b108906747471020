// The 3D view's stereo pair, one home for the eyes' cameras: the ray caster draws each eye with
// these matrices, the window projects the tools' results and the stylus sphere through them, and
// the stylus picks with the camera of the eye under the mouse (side-by-side), so what a user
// clicks in an eye's picture is what that eye shows there.
#pragma once
#include <vector>

#include "app/viewer_app.h"

namespace vs::viewer {

struct StereoEye {
  int eye = 0;  // -1 left, 0 mono, +1 right
  int x0 = 0;   // the eye's viewport within the view: columns x0 .. x0 + width
  int width = 0, height = 0;
  EyeView view;  // its camera (eyeView with the app's separation and convergence)
};

// The eyes of `mode` for a 3D view of width x height pixels: Off -> the mono camera; anaglyph and
// quad -> two eyes over the whole view; side-by-side -> the left eye in the left half, the right
// eye in the right half.
std::vector<StereoEye> stereoEyes(const ViewerApp& app, StereoMode mode, int width, int height);

// A world point in an eye's viewport: continuous pixel (x from the viewport's left, y down) and
// view depth (mm in front of the eye). False behind the eye.
bool projectToEye(const StereoEye& eye, const Vec3& world, double& px, double& py, double& depth);
// The ray through continuous pixel (px, py) of an eye's viewport: origin and unit direction, world mm.
void eyeRay(const StereoEye& eye, double px, double py, Vec3& origin, Vec3& dir);

// The eye whose viewport holds view column px (side-by-side: the half under the mouse; other
// modes: the first).
const StereoEye& eyeAt(const std::vector<StereoEye>& eyes, double px);

}  // namespace vs::viewer
