// Typed 3D volumes: Geometry plus one contiguous voxel vector, x fastest
// (so NumPy sees [z, y, x] without a copy). 2D images are volumes with dims.z == 1.
// Supported voxel types: uint8, int16, uint16, float32; readers convert anything
// else (with a note) and apply intensity scaling (NIfTI slope, DICOM rescale).
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "util/error.h"
#include "volume/geometry.h"

namespace vs {

enum class VoxelType { UInt8, Int16, UInt16, Float32 };

std::string voxelTypeName(VoxelType t);                // "uint8", "int16", "uint16", "float32"
VoxelType voxelTypeFromName(const std::string& name);  // throws InvalidArgument
size_t voxelTypeSize(VoxelType t);

template <class T>
struct VoxelTypeOf;
template <>
struct VoxelTypeOf<uint8_t> {
  static constexpr VoxelType value = VoxelType::UInt8;
};
template <>
struct VoxelTypeOf<int16_t> {
  static constexpr VoxelType value = VoxelType::Int16;
};
template <>
struct VoxelTypeOf<uint16_t> {
  static constexpr VoxelType value = VoxelType::UInt16;
};
template <>
struct VoxelTypeOf<float> {
  static constexpr VoxelType value = VoxelType::Float32;
};

// Largest volume we agree to allocate, in bytes (default: 3/4 of physical memory).
// Readers check a header against it *before* allocating.
uint64_t maxVolumeBytes();
// Throws DataError naming `what` if dims * bytesPerVoxel overflow or exceed maxVolumeBytes().
void checkAllocation(const Index3& dims, size_t bytesPerVoxel, const std::string& what);

template <class T>
class Volume {
 public:
  using value_type = T;

  Volume() = default;
  // Allocates dims voxels set to `fill`; validates the geometry and the size first.
  explicit Volume(const Geometry& g, T fill = T{}) : geom_(g) {
    geom_.validate();
    checkAllocation(g.dims, sizeof(T), "volume");
    data_.assign(static_cast<size_t>(g.voxelCount()), fill);
  }

  const Geometry& geometry() const { return geom_; }
  Geometry& geometry() { return geom_; }  // to change spacing/origin/direction, not dims
  const Index3& dims() const { return geom_.dims; }
  int64_t size() const { return static_cast<int64_t>(data_.size()); }
  bool empty() const { return data_.empty(); }

  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  std::vector<T>& voxels() { return data_; }
  const std::vector<T>& voxels() const { return data_; }

  // Unchecked access (callers validate coordinates at their boundary).
  T& operator()(int64_t x, int64_t y, int64_t z) { return data_[static_cast<size_t>(geom_.linear(x, y, z))]; }
  const T& operator()(int64_t x, int64_t y, int64_t z) const {
    return data_[static_cast<size_t>(geom_.linear(x, y, z))];
  }
  // Checked access: throws InvalidArgument for coordinates outside the volume.
  const T& at(int64_t x, int64_t y, int64_t z) const {
    if (!geom_.contains(x, y, z))
      throw InvalidArgument("voxel (" + std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z) +
                            ") is outside the volume " + geom_.describe());
    return (*this)(x, y, z);
  }

 private:
  Geometry geom_;
  std::vector<T> data_;
};

using VolumeU8 = Volume<uint8_t>;
using VolumeI16 = Volume<int16_t>;
using VolumeU16 = Volume<uint16_t>;
using VolumeF32 = Volume<float>;

// A volume of any supported voxel type, as readers return it.
using AnyVolume = std::variant<VolumeU8, VolumeI16, VolumeU16, VolumeF32>;

VoxelType voxelType(const AnyVolume& v);
const Geometry& geometryOf(const AnyVolume& v);
uint64_t byteSize(const AnyVolume& v);

struct ValueRange {
  double min = 0, max = 0;
  int64_t nonFinite = 0;  // NaN or inf voxels (float volumes only)
};
ValueRange valueRange(const AnyVolume& v);

// Converts to float32 (the type features and costs work in), keeping geometry.
VolumeF32 toFloat(const AnyVolume& v);

// Throws DataError naming `what` if a float volume holds NaN or inf voxels.
void requireFinite(const AnyVolume& v, const std::string& what);

// A cheap, non-owning 2D view of one axis-aligned slice of a volume.
// axis: 0 = sagittal (x fixed, view u = y, v = z), 1 = coronal (y fixed, u = x, v = z),
// 2 = axial (z fixed, u = x, v = y). Pixel (u, v) maps to voxel pointer base + u*strideU + v*strideV.
template <class T>
struct SliceView {
  const T* base = nullptr;
  int64_t width = 0, height = 0;      // along u and v
  int64_t strideU = 0, strideV = 0;   // in elements
  double spacingU = 1, spacingV = 1;  // mm
  int axis = 2;
  int64_t index = 0;  // slice position along the fixed axis

  const T& operator()(int64_t u, int64_t v) const { return base[u * strideU + v * strideV]; }
  // Voxel index (x,y,z) of slice pixel (u,v).
  Index3 voxelOf(int64_t u, int64_t v) const;
};

// Throws InvalidArgument if axis not in 0..2 or index out of range.
template <class T>
SliceView<T> sliceView(const Volume<T>& vol, int axis, int64_t index);

// Copies a slice into a new 1-slice volume (dims = width x height x 1) with the slice's
// spacing; origin/direction are set so pixel (u,v) maps to the same world point as the voxel.
template <class T>
Volume<T> extractSlice(const Volume<T>& vol, int axis, int64_t index);

// Parses "z=40", "y=10", "x=3" (also "axial=40", "coronal=..", "sagittal=..");
// returns {axis, index}. Throws InvalidArgument on bad syntax.
std::pair<int, int64_t> parseSliceSpec(const std::string& spec);

}  // namespace vs
