#pragma once
// The tracking levels' median: the upper median (the element at size / 2 once ordered), so a level or a spread is
// always a value that was sampled. quantify_detail::median is the measurement's two-sided median, reported to users.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace vs {

// Reorders v; 0 for an empty v.
inline double medianInPlace(std::vector<double>& v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

inline double medianOf(std::vector<double> v) { return medianInPlace(v); }

}  // namespace vs
