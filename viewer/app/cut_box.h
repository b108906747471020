// The cut-box mode's box moved with 3D handles (thesis 5.1: the box is placed in the 3D view): one
// handle at the centre of each face; dragging a face's handle moves that face along its axis by
// the mouse's motion along the axis' direction on the screen. GL-free; the window draws the
// handles and feeds the drags (window/cut_box_view.cpp), the script sets the box (`cut-box`).
#pragma once
#include <array>

#include "volume/volume.h"

namespace vs::viewer {

using CutBox = std::array<double, 6>;  // x0 y0 z0 x1 y1 z1, continuous index, inclusive

// Face f (0..5: x0 y0 z0 x1 y1 z1) lies across axis f % 3 at box[f]; its handle is its centre.
Vec3 cutBoxHandle(const CutBox& box, int face);

// The box with face `face` at `value`, clamped into the volume and at least one voxel from the
// opposite face.
CutBox movedCutBoxFace(const CutBox& box, int face, double value, const Index3& dims);

// A face dragged on the screen: `handlePx`/`axisPx` are the handle's screen position and that of
// the handle moved one voxel along the face's axis; `mouseDelta` the mouse's motion since the grab
// (pixels). Returns the voxels the face moves: the motion's component along the axis' screen
// direction, in voxels (0 when the axis points at the viewer, under half a pixel a voxel).
double cutBoxFaceShift(const std::array<double, 2>& handlePx, const std::array<double, 2>& axisPx,
                       const std::array<double, 2>& mouseDelta);

}  // namespace vs::viewer
