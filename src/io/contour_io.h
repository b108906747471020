// The live-wire contour document (`volscissors livewire --out contour.json`): writer and
// reader of one schema, so the CLI, the viewer and the Python bindings agree. The document itself
// (vs::ContourDocument) is a plain type of the core (volume/contour_document.h), filled from a
// live-wire by vs::contourDocument (scissors/live_wire_document.h).
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

#include "volume/contour_document.h"

namespace vs {

std::string contourToJson(const ContourDocument& contour);
// `where` names the source in errors.
ContourDocument contourFromJson(const std::string& text, const std::string& where);
void writeContour(const ContourDocument& contour, const std::string& path);  // atomic
ContourDocument readContour(const std::string& path);

}  // namespace vs
