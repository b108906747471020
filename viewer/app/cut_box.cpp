#include "app/cut_box.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "app/viewer_app.h"
#include "util/error.h"

namespace vs::viewer {

Vec3 cutBoxHandle(const CutBox& b, int face) {
  VS_REQUIRE(face >= 0 && face < 6, "cut box: face must be 0..5");
  Vec3 c((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2);
  c[face % 3] = b[size_t(face)];
  return c;
}

CutBox movedCutBoxFace(const CutBox& box, int face, double value, const Index3& dims) {
  VS_REQUIRE(face >= 0 && face < 6, "cut box: face must be 0..5");
  const int a = face % 3;
  const double hi = double(dims[size_t(a)] - 1);
  CutBox b = box;
  if (face < 3)
    b[size_t(face)] = std::clamp(value, 0.0, std::max(0.0, b[size_t(a + 3)] - 1));
  else
    b[size_t(face)] = std::clamp(value, std::min(hi, b[size_t(a)] + 1), hi);
  return b;
}

double cutBoxFaceShift(const std::array<double, 2>& h, const std::array<double, 2>& ax,
                       const std::array<double, 2>& d) {
  const double sx = ax[0] - h[0], sy = ax[1] - h[1], s2 = sx * sx + sy * sy;
  if (s2 < 0.25) return 0;
  return (d[0] * sx + d[1] * sy) / s2;
}

void ViewerApp::setCutBox(const std::optional<std::array<double, 6>>& box) {
  VS_REQUIRE(hasVolume(), "no volume loaded");
  if (box) {
    const Index3& d = geometry().dims;
    for (int a = 0; a < 3; ++a) {
      const double lo = (*box)[size_t(a)], hi = (*box)[size_t(a + 3)];
      VS_REQUIRE(std::isfinite(lo) && std::isfinite(hi) && lo >= 0 && hi <= double(d[size_t(a)] - 1) && lo < hi,
                 std::string("cut box: ") + "xyz"[a] + " must run from 0 to " + std::to_string(d[size_t(a)] - 1) +
                     " with the first face before the second");
    }
  }
  view_.cutBox = box;
}

}  // namespace vs::viewer
