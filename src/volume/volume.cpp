#include "volume/volume.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vs {

std::string voxelTypeName(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8:
      return "uint8";
    case VoxelType::Int16:
      return "int16";
    case VoxelType::UInt16:
      return "uint16";
    case VoxelType::Float32:
      return "float32";
  }
  return "unknown";
}

VoxelType voxelTypeFromName(const std::string& n) {
  if (n == "uint8" || n == "u8") return VoxelType::UInt8;
  if (n == "int16" || n == "i16") return VoxelType::Int16;
  if (n == "uint16" || n == "u16") return VoxelType::UInt16;
  if (n == "float32" || n == "float" || n == "f32") return VoxelType::Float32;
  throw InvalidArgument("unknown voxel type '" + n + "' (expected uint8, int16, uint16 or float32)");
}

size_t voxelTypeSize(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8:
      return 1;
    case VoxelType::Int16:
    case VoxelType::UInt16:
      return 2;
    case VoxelType::Float32:
      return 4;
  }
  return 0;
}

uint64_t maxVolumeBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long pageSize = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return uint64_t{8} << 30;
  return static_cast<uint64_t>(pages) * static_cast<uint64_t>(pageSize) / 4 * 3;
}

void checkAllocation(const Index3& dims, size_t bytesPerVoxel, const std::string& what) {
  uint64_t total = bytesPerVoxel;
  for (int64_t d : dims) {
    if (d < 1) throw DataError(what + ": dimension " + std::to_string(d) + " is not positive");
    if (total > std::numeric_limits<uint64_t>::max() / static_cast<uint64_t>(d))
      throw DataError(what + ": dimensions overflow 64-bit size");
    total *= static_cast<uint64_t>(d);
  }
  if (total > maxVolumeBytes())
    throw DataError(what + ": " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                    std::to_string(dims[2]) + " voxels need " + std::to_string(total >> 20) + " MiB, more than the " +
                    std::to_string(maxVolumeBytes() >> 20) + " MiB allowed on this machine");
}

VoxelType voxelType(const AnyVolume& v) {
  return std::visit(
      [](const auto& vol) { return VoxelTypeOf<typename std::decay_t<decltype(vol)>::value_type>::value; }, v);
}

const Geometry& geometryOf(const AnyVolume& v) {
  return std::visit([](const auto& vol) -> const Geometry& { return vol.geometry(); }, v);
}

uint64_t byteSize(const AnyVolume& v) {
  return std::visit(
      [](const auto& vol) {
        return static_cast<uint64_t>(vol.size()) * sizeof(typename std::decay_t<decltype(vol)>::value_type);
      },
      v);
}

ValueRange valueRange(const AnyVolume& v) {
  return std::visit(
      [](const auto& vol) {
        ValueRange r;
        bool first = true;
        for (auto x : vol.voxels()) {
          const double d = static_cast<double>(x);
          if (!std::isfinite(d)) {
            ++r.nonFinite;
            continue;
          }
          if (first) {
            r.min = r.max = d;
            first = false;
          } else {
            r.min = std::min(r.min, d);
            r.max = std::max(r.max, d);
          }
        }
        return r;
      },
      v);
}

VolumeF32 toFloat(const AnyVolume& v) {
  return std::visit(
      [](const auto& vol) {
        VolumeF32 out(vol.geometry());
        std::transform(vol.voxels().begin(), vol.voxels().end(), out.voxels().begin(),
                       [](auto x) { return static_cast<float>(x); });
        return out;
      },
      v);
}

void requireFinite(const AnyVolume& v, const std::string& what) {
  if (voxelType(v) != VoxelType::Float32) return;
  const auto r = valueRange(v);
  if (r.nonFinite > 0) throw DataError(what + ": " + std::to_string(r.nonFinite) + " voxel(s) are NaN or infinite");
}

template <class T>
Index3 SliceView<T>::voxelOf(int64_t u, int64_t v) const {
  switch (axis) {
    case 0:
      return {index, u, v};
    case 1:
      return {u, index, v};
    default:
      return {u, v, index};
  }
}

template <class T>
SliceView<T> sliceView(const Volume<T>& vol, int axis, int64_t index) {
  const auto& g = vol.geometry();
  if (axis < 0 || axis > 2) throw InvalidArgument("slice axis must be 0 (x), 1 (y) or 2 (z)");
  if (index < 0 || index >= g.dims[axis])
    throw InvalidArgument("slice index " + std::to_string(index) + " is outside 0.." +
                          std::to_string(g.dims[axis] - 1) + " along " + "xyz"[axis]);
  const int64_t sx = 1, sy = g.dims[0], sz = g.dims[0] * g.dims[1];
  SliceView<T> s;
  s.axis = axis;
  s.index = index;
  switch (axis) {
    case 0:
      s = {vol.data() + index * sx, g.dims[1], g.dims[2], sy, sz, g.spacing[1], g.spacing[2], 0, index};
      break;
    case 1:
      s = {vol.data() + index * sy, g.dims[0], g.dims[2], sx, sz, g.spacing[0], g.spacing[2], 1, index};
      break;
    default:
      s = {vol.data() + index * sz, g.dims[0], g.dims[1], sx, sy, g.spacing[0], g.spacing[1], 2, index};
  }
  return s;
}

template <class T>
Volume<T> extractSlice(const Volume<T>& vol, int axis, int64_t index) {
  const SliceView<T> s = sliceView(vol, axis, index);
  const auto& g = vol.geometry();
  const int u = axis == 0 ? 1 : 0;
  const int v = axis == 2 ? 1 : 2;
  Geometry out;
  out.dims = {s.width, s.height, 1};
  out.spacing = {s.spacingU, s.spacingV, g.spacing[axis]};
  Vec3 start(0, 0, 0);
  start[axis] = static_cast<double>(index);
  out.origin = g.indexToWorld(start);
  out.direction.col(0) = g.direction.col(u);
  out.direction.col(1) = g.direction.col(v);
  out.direction.col(2) = g.direction.col(axis);
  Volume<T> img(out);
  for (int64_t y = 0; y < s.height; ++y)
    for (int64_t x = 0; x < s.width; ++x) img(x, y, 0) = s(x, y);
  return img;
}

std::pair<int, int64_t> parseSliceSpec(const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos) throw InvalidArgument("slice '" + spec + "': expected AXIS=INDEX, e.g. z=40");
  const std::string axisName = spec.substr(0, eq);
  int axis = -1;
  if (axisName == "x" || axisName == "sagittal")
    axis = 0;
  else if (axisName == "y" || axisName == "coronal")
    axis = 1;
  else if (axisName == "z" || axisName == "axial")
    axis = 2;
  else
    throw InvalidArgument("slice '" + spec + "': axis must be x, y, z (or sagittal, coronal, axial)");
  size_t used = 0;
  long long idx = 0;
  try {
    idx = std::stoll(spec.substr(eq + 1), &used);
  } catch (...) {
    used = 0;
  }
  if (used == 0 || used != spec.size() - eq - 1) throw InvalidArgument("slice '" + spec + "': index is not an integer");
  return {axis, idx};
}

#define VS_INSTANTIATE(T)                                          \
  template struct SliceView<T>;                                    \
  template SliceView<T> sliceView(const Volume<T>&, int, int64_t); \
  template Volume<T> extractSlice(const Volume<T>&, int, int64_t);
VS_INSTANTIATE(uint8_t)
VS_INSTANTIATE(int16_t)
VS_INSTANTIATE(uint16_t)
VS_INSTANTIATE(float)
#undef VS_INSTANTIATE

}  // namespace vs
