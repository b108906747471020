// Voxel component types met on disk (internal to src/io; no Eigen, no ITK here so that
// the ITK bridge can include it: ITK 5.2 bundles its own Eigen, which clashes with ours
// inside one translation unit).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace vs::io_detail {

enum class Comp { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };
size_t compSize(Comp c);
std::string compName(Comp c);

// Checked arithmetic for every size computed from a file: throws IoError "<what>: <field>
// overflows" instead of wrapping (a wrapped size is how a small file overflows a buffer).
uint64_t checkedMul(uint64_t a, uint64_t b, const std::string& what, const char* field);
uint64_t checkedAdd(uint64_t a, uint64_t b, const std::string& what, const char* field);

// Refuses, before allocating, a header that promises more voxel bytes than the file can
// hold: `available` bytes of stored data, `expansion` the most one stored byte can decode to
// (1 raw, 1032 zlib/deflate, 1/2 ASCII digits and separators). Throws IoError naming the file.
void checkDataCanHold(uint64_t need, uint64_t available, double expansion, const std::string& what);
// Throws DataError if a scratch buffer of `bytes` exceeds what volumes may use (maxVolumeBytes).
void checkScratchBytes(uint64_t bytes, const std::string& what);
// The largest decoded/stored byte ratio deflate can reach (zlib's documented bound is ~1032:1).
constexpr double kDeflateExpansion = 1040.0;

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
