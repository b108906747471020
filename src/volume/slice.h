// Slices as a reader sees them: the one home of the slice-axis convention, the anatomical
// orientation of a slice picture, and the mapping between picture pixels and voxel indices.
//
// Slice pixels (u, v): a slice normal to index axis `axis` at `index` has in-plane index axes
// sliceInPlaneAxes(axis) = (u axis, v axis): x=K -> (y, z), y=K -> (x, z), z=K -> (x, y)
// (the SliceView and live-wire convention; u fastest in memory).
//
// Pictures are shown the way radiologists read them, whatever the storage order and the
// direction matrix (world is LPS: +x = patient left, +y = posterior, +z = superior):
//   axial    (slice normal along S-I): anterior up, patient right on the picture's left;
//   coronal  (normal along A-P):       superior up, patient right on the picture's left;
//   sagittal (normal along L-R):       superior up, anterior on the picture's left.
// Which anatomical plane a slice is follows from the world direction of its normal index
// axis, so "z=60" of a volume stored sagittally is a sagittal picture. Each index axis is
// paired with the world axis it runs closest to (jointly, so the three pairs differ).
//
// Picture coordinates (col, row) are 0-based pixel centres, col to the right, row down, at one
// picture pixel per voxel (resampled pictures scale this linearly, see render/slice_render.h).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "volume/geometry.h"
#include "volume/volume.h"

namespace vs {

// (u axis, v axis) of a slice normal to `axis`; InvalidArgument unless axis is 0, 1 or 2.
std::array<int, 2> sliceInPlaneAxes(int axis);
// Voxel index of slice pixel (u, v).
Index3 sliceToVolumeIndex(int axis, int64_t index, int64_t u, int64_t v);
// "x=3" / "y=10" / "z=40".
std::string sliceName(int axis, int64_t index);
// A label volume of geometry `g`: 1 where the pixel mask of slice `axis`=`index` (width x height
// slice pixels, u fastest, as fillContour returns it) is non-zero, 0 elsewhere: a slice
// contour's inside as a 3D mask. InvalidArgument when the sizes do not match the slice.
VolumeU8 sliceMaskVolume(const Geometry& g, int axis, int64_t index, const std::vector<uint8_t>& mask, int64_t width,
                         int64_t height);

// World (LPS) axis and sign each index axis runs along most closely.
struct AxisAlignment {
  std::array<int, 3> worldAxis{0, 1, 2};  // world axis of index axis i
  std::array<int, 3> sign{1, 1, 1};       // +1: index axis i points to + world axis
};
AxisAlignment alignAxes(const Geometry& g);

// The index axis that runs closest to superior-inferior: its slices are the axial ones.
int axialIndexAxis(const Geometry& g);

// Letter of the anatomical direction of +/- a world (LPS) axis: L R, P A, S I.
char anatomicalLetter(int worldAxis, int sign);
// Orientation code: for each index axis the direction it points to, e.g. "LPS" (identity
// direction, ITK/DICOM default), "RAS" (a NIfTI in the neurological convention), "LIP"...
std::string orientationCode(const Geometry& g);
// The direction matrix of an orientation code (orientationCode's inverse for axis-aligned
// directions): index axis i points to the code's letter i, e.g. "LPS" the identity, "RAS"
// diag(-1, -1, 1), "LAS" a y axis that runs to anterior. Case-insensitive. InvalidArgument for a
// code that is not one letter of each pair L/R, P/A, S/I.
Mat3 directionFromOrientationCode(const std::string& code);
// States the orientation of a volume whose header gives none (`--orientation CODE`): its direction
// becomes the code's; origin, spacing and voxels stay.
void setOrientation(Geometry& g, const std::string& code);
void setOrientation(AnyVolume& v, const std::string& code);

enum class AnatomicalPlane { Sagittal, Coronal, Axial };
std::string anatomicalPlaneName(AnatomicalPlane plane);  // "sagittal", "coronal", "axial"

// How one slice is shown at one picture pixel per voxel.
struct SliceFrame {
  int axis = 2;       // index axis normal to the slice
  int64_t index = 0;  // its position along that axis
  AnatomicalPlane plane = AnatomicalPlane::Axial;
  int colAxis = 0, rowAxis = 1;           // index axes along picture columns (right) and rows (down)
  bool colFlipped = false;                // true: the index along colAxis decreases to the right
  bool rowFlipped = false;                // true: the index along rowAxis decreases downwards
  int64_t width = 0, height = 0;          // voxels along colAxis and rowAxis
  double colSpacing = 1, rowSpacing = 1;  // mm per picture pixel along columns and rows
  std::array<char, 4> edgeLetters{};      // anatomical direction at the left, right, top, bottom edge

  // Continuous voxel index of picture position (col, row) (pixel centres at integers).
  Vec3 indexOf(double col, double row) const;
  // Picture position (col, row) of a continuous voxel index (the normal component is ignored).
  std::array<double, 2> pictureOf(const Vec3& index) const;
};

// Throws InvalidArgument for axis not in 0..2 or index outside the volume.
SliceFrame sliceFrame(const Geometry& g, int axis, int64_t index);

}  // namespace vs
