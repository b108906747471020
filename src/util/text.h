// Numbers as text, the one home of the small formatters messages and reports use (issue 23:
// number formatting was re-written in most files).
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace vs {

// 6 significant digits, as printf's %g and an ostream's default ("0.5", "1e+300", "-3").
std::string numberText(double v);

// A voxel index (vs::Index3) for messages: "(x,y,z)".
std::string indexText(const std::array<int64_t, 3>& v);

// Fixed decimals ("1.50" for (1.5, 2)).
std::string fixedText(double v, int decimals);

}  // namespace vs
