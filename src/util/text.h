// Numbers as text, the one home of the small formatters messages and reports use and of the
// number parser the front ends read their arguments with (issue 23: number formatting was
// re-written in most files, number parsing in the CLI and again in the viewer's script).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vs {

// 6 significant digits, as printf's %g and an ostream's default ("0.5", "1e+300", "-3").
std::string numberText(double v);

// A voxel index (vs::Index3) for messages: "(x,y,z)".
std::string indexText(const std::array<int64_t, 3>& v);

// Fixed decimals ("1.50" for (1.5, 2)).
std::string fixedText(double v, int decimals);

// `text` cut at every `separator` (n separators: n + 1 parts, empty ones kept).
std::vector<std::string> splitText(const std::string& text, char separator);

// Without leading and trailing blanks (spaces, tabs).
std::string trimmedText(const std::string& text);

// The whole of `text` (blanks around it allowed, a leading '+' too) as one finite number /
// one integer: false on empty text, trailing garbage, NaN, inf or (integers) out of range.
bool parseNumber(const std::string& text, double& out);
bool parseInteger(const std::string& text, int64_t& out);

}  // namespace vs
