// The quantification outputs (`volscissors measure`, `trace --measure`, Python): the per-cross-
// section CSV and the JSON summary (quantify/quantify.h), as text and JSON values that the front
// ends write atomically. One schema, one writer (here, not in src/io: io may not depend on tools).
//   CSV, one row per cross-section of each root->tip path (a trunk's sections repeat in every
//   path through it): path, segment, arc_mm (from the root), segment_arc_mm, x_mm, y_mm, z_mm
//   (world), area_mm2, eq_diameter_mm, min_diameter_mm, max_diameter_mm, min_dir_x..z,
//   max_dir_x..z (world unit vectors), lumen, wall (intensity levels), flags (empty: measured;
//   else leaves_volume|meets_branch|no_boundary, with empty numbers), branch_point (the index in
//   "branch_points" of the branch point whose neighbour section this is; empty for the others).
//   JSON {"polarity", "step_mm", "sections": {"total", "measured", "leaves_volume",
//   "meets_branch", "no_boundary"}, "segments": [...], "paths": [...], "branch_points": [...]} (a branch point's
//   "parent_section" and "child_sections": its neighbour sections, distance from it along the segment, area, diameter)
//   (fields as in quantify.h, mm and degrees; NaN -> null).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "quantify/quantify.h"

namespace vs {

nlohmann::json measurementToJson(const TreeMeasurement& m, const QuantifyOptions& options);
std::string measurementCsv(const TreeMeasurement& m);

}  // namespace vs
