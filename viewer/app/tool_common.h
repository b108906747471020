// What every tool of the viewer shares (without any core algorithm header, so the tools' own
// headers can include it whatever else they see).
#pragma once
#include <cstddef>
#include <string>

namespace vs::viewer {

constexpr size_t kUndoDepth = 100;  // per tool; the issue asks for >= 20

// A file name the volume writers take (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd).
bool isVolumePath(const std::string& path);

}  // namespace vs::viewer
