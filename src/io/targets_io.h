// Target lists for tracking (`volscissors trace --targets-file`): one schema, one reader.
//   text: one target per line, "x y z" or "x,y,z" (numbers; '#' starts a comment; blank lines
//         are skipped);
//   JSON: [[x,y,z], ...] or {"terminals" | "targets": [[x,y,z] | {"voxel": [x,y,z]}, ...],
//         "root" | "root_voxel": [x,y,z]} (the phantom truth and the peers' sidecars both work).
// The file decides its kind by its first non-blank character ('{' or '[': JSON).
// Coordinates are returned as written (voxel index or world mm: the caller knows which).
// Errors: IoError naming the file and what is wrong (cannot open, invalid JSON, a line or an
// entry that is not three finite numbers, no target at all), with the line number for text.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "volume/geometry.h"

namespace vs {

struct TargetList {
  std::vector<Vec3> targets;  // at least one
  std::optional<Vec3> root;   // JSON "root" / "root_voxel" when present
};

TargetList readTargetList(const std::string& path);
// The same from text already in memory; `path` names the source in errors.
TargetList parseTargetList(const std::string& text, const std::string& path);

}  // namespace vs
