#include "volume/slice.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>

#include "util/error.h"

namespace vs {

std::array<int, 2> sliceInPlaneAxes(int axis) {
  VS_REQUIRE(axis >= 0 && axis <= 2, "slice axis must be 0 (x, sagittal), 1 (y, coronal) or 2 (z, axial)");
  return {axis == 0 ? 1 : 0, axis == 2 ? 1 : 2};
}

Index3 sliceToVolumeIndex(int axis, int64_t index, int64_t u, int64_t v) {
  const auto [ua, va] = sliceInPlaneAxes(axis);
  Index3 i{};
  i[static_cast<size_t>(axis)] = index;
  i[static_cast<size_t>(ua)] = u;
  i[static_cast<size_t>(va)] = v;
  return i;
}

VolumeU8 sliceMaskVolume(const Geometry& g, int axis, int64_t index, const std::vector<uint8_t>& mask, int64_t width,
                         int64_t height) {
  const auto [ua, va] = sliceInPlaneAxes(axis);
  if (index < 0 || index >= g.dims[static_cast<size_t>(axis)] || width != g.dims[static_cast<size_t>(ua)] ||
      height != g.dims[static_cast<size_t>(va)] || mask.size() != static_cast<size_t>(width * height))
    throw InvalidArgument("sliceMaskVolume: the mask does not match slice " + sliceName(axis, index) + " of " +
                          g.describe());
  VolumeU8 label(g, 0);
  for (int64_t v = 0; v < height; ++v)
    for (int64_t u = 0; u < width; ++u)
      if (mask[static_cast<size_t>(u + width * v)]) {
        const Index3 i = sliceToVolumeIndex(axis, index, u, v);
        label(i[0], i[1], i[2]) = 1;
      }
  return label;
}

std::string sliceName(int axis, int64_t index) {
  VS_REQUIRE(axis >= 0 && axis <= 2, "slice axis must be 0, 1 or 2");
  return std::string(1, "xyz"[axis]) + "=" + std::to_string(index);
}

AxisAlignment alignAxes(const Geometry& g) {
  // The permutation index axis -> world axis with the largest total |direction| wins; on ties
  // (45 degree obliques) the first in lexicographic order, so the choice is deterministic.
  std::array<int, 3> perm{0, 1, 2}, best = perm;
  double bestScore = -1;
  do {
    double score = 0;
    for (int i = 0; i < 3; ++i) score += std::abs(g.direction(perm[static_cast<size_t>(i)], i));
    if (score > bestScore + 1e-9) bestScore = score, best = perm;
  } while (std::next_permutation(perm.begin(), perm.end()));
  AxisAlignment a;
  a.worldAxis = best;
  for (int i = 0; i < 3; ++i)
    a.sign[static_cast<size_t>(i)] = g.direction(best[static_cast<size_t>(i)], i) < 0 ? -1 : 1;
  return a;
}

int axialIndexAxis(const Geometry& g) {
  const AxisAlignment a = alignAxes(g);
  for (int i = 0; i < 3; ++i)
    if (a.worldAxis[static_cast<size_t>(i)] == 2) return i;
  return 2;  // unreachable: the alignment is a permutation
}

char anatomicalLetter(int worldAxis, int sign) {
  static const char plus[] = {'L', 'P', 'S'}, minus[] = {'R', 'A', 'I'};
  VS_REQUIRE(worldAxis >= 0 && worldAxis <= 2, "world axis must be 0, 1 or 2");
  return sign < 0 ? minus[worldAxis] : plus[worldAxis];
}

std::string orientationCode(const Geometry& g) {
  const AxisAlignment a = alignAxes(g);
  std::string code;
  for (size_t i = 0; i < 3; ++i) code += anatomicalLetter(a.worldAxis[i], a.sign[i]);
  return code;
}

Mat3 directionFromOrientationCode(const std::string& code) {
  VS_REQUIRE(code.size() == 3, "orientation code '" + code + "' must have three letters (e.g. LPS, RAS, LAS)");
  Mat3 d = Mat3::Zero();
  std::array<bool, 3> used{false, false, false};
  for (size_t i = 0; i < 3; ++i) {
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(code[i])));
    const std::string letters = "LPSRAI";
    const auto k = letters.find(c);
    VS_REQUIRE(k != std::string::npos,
               "orientation code '" + code + "': '" + std::string(1, code[i]) + "' is not one of L R P A S I");
    const int world = static_cast<int>(k % 3);
    VS_REQUIRE(!used[size_t(world)], "orientation code '" + code + "' names the " +
                                         std::string(world == 0   ? "L-R"
                                                     : world == 1 ? "P-A"
                                                                  : "S-I") +
                                         " axis twice (give one letter of each pair L/R, P/A, S/I)");
    used[size_t(world)] = true;
    d(world, static_cast<Eigen::Index>(i)) = k < 3 ? 1.0 : -1.0;
  }
  return d;
}

void setOrientation(Geometry& g, const std::string& code) { g.direction = directionFromOrientationCode(code); }

void setOrientation(AnyVolume& v, const std::string& code) {
  const Mat3 d = directionFromOrientationCode(code);
  std::visit([&](auto& vol) { vol.geometry().direction = d; }, v);
}

std::string anatomicalPlaneName(AnatomicalPlane plane) {
  switch (plane) {
    case AnatomicalPlane::Sagittal:
      return "sagittal";
    case AnatomicalPlane::Coronal:
      return "coronal";
    case AnatomicalPlane::Axial:
      return "axial";
  }
  return "axial";
}

SliceFrame sliceFrame(const Geometry& g, int axis, int64_t index) {
  VS_REQUIRE(axis >= 0 && axis <= 2, "slice axis must be 0 (x), 1 (y) or 2 (z)");
  VS_REQUIRE(index >= 0 && index < g.dims[static_cast<size_t>(axis)],
             "slice " + sliceName(axis, index) + " is outside the volume (0.." +
                 std::to_string(g.dims[static_cast<size_t>(axis)] - 1) + ")");
  const AxisAlignment a = alignAxes(g);
  SliceFrame f;
  f.axis = axis;
  f.index = index;
  const int normalWorld = a.worldAxis[static_cast<size_t>(axis)];
  f.plane = normalWorld == 0   ? AnatomicalPlane::Sagittal
            : normalWorld == 1 ? AnatomicalPlane::Coronal
                               : AnatomicalPlane::Axial;
  // Screen right and screen down as (world axis, sign) for each plane (see the header).
  int rightWorld = 0, rightSign = 1, downWorld = 1, downSign = 1;
  if (f.plane == AnatomicalPlane::Coronal) downWorld = 2, downSign = -1;
  if (f.plane == AnatomicalPlane::Sagittal) rightWorld = 1, downWorld = 2, downSign = -1;
  for (int i : sliceInPlaneAxes(axis)) {
    const size_t s = static_cast<size_t>(i);
    if (a.worldAxis[s] == rightWorld) {
      f.colAxis = i;
      f.colFlipped = a.sign[s] != rightSign;
    } else {
      f.rowAxis = i;
      f.rowFlipped = a.sign[s] != downSign;
    }
  }
  f.width = g.dims[static_cast<size_t>(f.colAxis)];
  f.height = g.dims[static_cast<size_t>(f.rowAxis)];
  f.colSpacing = g.spacing[f.colAxis];
  f.rowSpacing = g.spacing[f.rowAxis];
  f.edgeLetters = {anatomicalLetter(rightWorld, -rightSign), anatomicalLetter(rightWorld, rightSign),
                   anatomicalLetter(downWorld, -downSign), anatomicalLetter(downWorld, downSign)};
  return f;
}

Vec3 SliceFrame::indexOf(double col, double row) const {
  Vec3 i;
  i[axis] = static_cast<double>(index);
  i[colAxis] = colFlipped ? static_cast<double>(width - 1) - col : col;
  i[rowAxis] = rowFlipped ? static_cast<double>(height - 1) - row : row;
  return i;
}

std::array<double, 2> SliceFrame::pictureOf(const Vec3& i) const {
  const double c = i[colAxis], r = i[rowAxis];
  return {colFlipped ? static_cast<double>(width - 1) - c : c, rowFlipped ? static_cast<double>(height - 1) - r : r};
}

}  // namespace vs
