// How a slice view shows a slice so that it reads like every other viewer (radiological
// convention: patient left on the screen's right; anterior up in axial, superior up in coronal
// and sagittal, anterior on the left in sagittal), whatever the file's storage order: the slice's
// u/v axes are flipped where the direction matrix says so, and every edge is labelled with the
// anatomical direction (R/L/A/P/S/I) it really points to. LPS world: +x = L, +y = P, +z = S.
#pragma once
#include <string>

#include "render/renderer.h"
#include "scissors/live_wire.h"
#include "util/image.h"
#include "volume/volume.h"

namespace vs::viewer {

struct SliceLayout {
  int axis = 2;  // fixed axis: 0 sagittal, 1 coronal, 2 axial (SliceView's u/v order)
  int64_t index = 0;
  int64_t width = 0, height = 0;  // slice pixels along u, v
  double spacingU = 1, spacingV = 1;
  bool flipU = false, flipV = false;     // display u right-to-left / v bottom-to-top
  std::string left, right, top, bottom;  // anatomical labels of the screen edges
  // Screen position in [0,1]^2 (x right, y down) of the centre of slice pixel (u, v), and back.
  void toScreen(double u, double v, double& sx, double& sy) const;
  PixelUV fromScreen(double sx, double sy) const;  // clamped to the slice
};

// The letter of a world direction's dominant component: "L"/"R", "P"/"A", "S"/"I".
std::string anatomicalLabel(const Vec3& worldDirection);
SliceLayout sliceLayout(const Geometry& g, int axis, int64_t index);
// The slice in grey through the window, u to the right, v down (no flips: the view flips).
RgbaImage sliceImage(const VolumeF32& volume, int axis, int64_t index, const WindowLevel& window);

}  // namespace vs::viewer
