// The live-wire contour document (`volscissors livewire --out contour.json`): writer and
// reader of one schema, so the CLI, the viewer and the Python bindings agree.
//   file, plane ("axial"|"coronal"|"sagittal"),
//   slice {axis "x"|"y"|"z", index, width, height, spacing_mm [su, sv]},
//   cost_kind "mb"|"gradient", weights {zero_crossing, gradient, direction} (mb only),
//   gradient_quantile, connectivity 4|8, smooth_mm, snap_px, closed,
//   points [[u,v]..] (slice pixels, volume/slice.h), points_index [[x,y,z]..],
//   points_world [[x,y,z]..] (LPS mm), points_picture [[col,row]..] (the slice picture at one
//   pixel per voxel, anatomical orientation), clicks, clicks_input [[u,v]..], length_mm, cost,
//   segments [{from, to, pixels, cost, length_mm}..], area_pixels, area_mm2 (closed only), mask.
// Errors: IoError naming the file and the field.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "volume/geometry.h"

namespace vs {

struct ContourDocument {
  using UV = std::array<int64_t, 2>;
  struct Segment {
    UV from{}, to{};
    int64_t pixels = 0;
    double cost = 0, lengthMm = 0;
  };
  std::string file;
  std::string plane;  // anatomical plane of the slice
  int axis = 2;
  int64_t index = 0, width = 0, height = 0;
  double spacingU = 1, spacingV = 1;
  std::string costKind = "mb";
  std::optional<std::array<double, 3>> weights;  // zero crossing, gradient, direction (mb)
  double gradientQuantile = 1;
  int connectivity = 8;
  double smoothMm = 0, snapPx = 0;
  bool closed = false;
  std::vector<UV> points, clicks, clicksInput;
  std::vector<Index3> pointsIndex;
  std::vector<Vec3> pointsWorld;
  std::vector<std::array<double, 2>> pointsPicture;
  double lengthMm = 0, cost = 0;
  std::vector<Segment> segments;
  std::optional<int64_t> areaPixels;
  std::optional<double> areaMm2;
  std::string mask;
};

std::string contourToJson(const ContourDocument& contour);
// `where` names the source in errors.
ContourDocument contourFromJson(const std::string& text, const std::string& where);
void writeContour(const ContourDocument& contour, const std::string& path);  // atomic
ContourDocument readContour(const std::string& path);

}  // namespace vs
