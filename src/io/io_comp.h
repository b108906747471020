// Voxel component types met on disk (internal to src/io; no Eigen, no ITK here so that
// the ITK bridge can include it: ITK 5.2 bundles its own Eigen, which clashes with ours
// inside one translation unit).
#pragma once

#include <cstddef>
#include <string>

namespace vs::io_detail {

enum class Comp { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };
size_t compSize(Comp c);
std::string compName(Comp c);

}  // namespace vs::io_detail

namespace vs::io_detail {
// Concatenates strings by appending (avoids GCC 12's false -Wrestrict on "lit" + string&&).
template <class... A>
std::string cat(const A&... parts) {
  std::string s;
  (s.append(parts), ...);
  return s;
}
}  // namespace vs::io_detail
