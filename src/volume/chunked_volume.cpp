#include "volume/chunked_volume.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace vs {

ChunkCache::ChunkCache(ChunkedVolume volume, int64_t capBytes) : vol_(std::move(volume)), cap_(capBytes) {
  vol_.geometry.validate();
  for (int a = 0; a < 3; ++a)
    if (vol_.chunk[a] < 1)
      throw InvalidArgument("chunked volume: chunk size " + std::to_string(vol_.chunk[a]) + " < 1");
  if (!vol_.load) throw InvalidArgument("chunked volume: no chunk loader");
  grid_ = vol_.chunkGrid();
}

const float* ChunkCache::chunk(const Index3& c) {
  for (int a = 0; a < 3; ++a)
    if (c[a] < 0 || c[a] >= grid_[a])
      throw InvalidArgument("chunk (" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," + std::to_string(c[2]) +
                            ") is outside the chunk grid");
  const int64_t key = c[0] + grid_[0] * (c[1] + grid_[1] * c[2]);
  if (auto it = slots_.find(key); it != slots_.end()) {
    ++stats_.hits;
    lru_.splice(lru_.begin(), lru_, it->second.pos);
    return it->second.data.data();
  }
  const size_t n = size_t(vol_.chunk[0] * vol_.chunk[1] * vol_.chunk[2]);
  std::vector<float> data = vol_.load(c);
  if (data.size() != n)
    throw DataError("chunk (" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," + std::to_string(c[2]) +
                    ") has " + std::to_string(data.size()) + " voxels, expected " + std::to_string(n));
  const int64_t bytes = int64_t(n * sizeof(float));
  while (!lru_.empty() && bytes_ + bytes > cap_) {
    const int64_t victim = lru_.back();
    lru_.pop_back();
    slots_.erase(victim);
    bytes_ -= bytes;
  }
  ++stats_.loads;
  lru_.push_front(key);
  Slot& s = slots_[key];
  s.data = std::move(data);
  s.pos = lru_.begin();
  bytes_ += bytes;
  stats_.peakBytes = std::max(stats_.peakBytes, bytes_);
  return s.data.data();
}

float ChunkCache::at(int64_t x, int64_t y, int64_t z) {
  const Index3& k = vol_.chunk;
  const float* d = chunk({x / k[0], y / k[1], z / k[2]});
  return d[size_t((x % k[0]) + k[0] * ((y % k[1]) + k[1] * (z % k[2])))];
}

void ChunkCache::readRegion(const Index3& origin, const Index3& size, float* out, float outside) {
  const Index3& d = vol_.geometry.dims;
  const Index3& k = vol_.chunk;
  std::fill(out, out + size[0] * size[1] * size[2], outside);
  Index3 lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::max<int64_t>(origin[a], 0);
    hi[a] = std::min<int64_t>(origin[a] + size[a], d[a]);
    if (lo[a] >= hi[a]) return;
  }
  for (int64_t cz = lo[2] / k[2]; cz <= (hi[2] - 1) / k[2]; ++cz)
    for (int64_t cy = lo[1] / k[1]; cy <= (hi[1] - 1) / k[1]; ++cy)
      for (int64_t cx = lo[0] / k[0]; cx <= (hi[0] - 1) / k[0]; ++cx) {
        const float* c = chunk({cx, cy, cz});
        const int64_t x0 = std::max(lo[0], cx * k[0]), x1 = std::min(hi[0], (cx + 1) * k[0]);
        const int64_t y0 = std::max(lo[1], cy * k[1]), y1 = std::min(hi[1], (cy + 1) * k[1]);
        const int64_t z0 = std::max(lo[2], cz * k[2]), z1 = std::min(hi[2], (cz + 1) * k[2]);
        for (int64_t z = z0; z < z1; ++z)
          for (int64_t y = y0; y < y1; ++y) {
            const float* src = c + ((x0 - cx * k[0]) + k[0] * ((y - cy * k[1]) + k[1] * (z - cz * k[2])));
            float* dst = out + ((x0 - origin[0]) + size[0] * ((y - origin[1]) + size[1] * (z - origin[2])));
            std::copy(src, src + (x1 - x0), dst);
          }
      }
}

namespace {
template <class T>
T clampTo(float v) {
  if constexpr (std::is_same_v<T, float>) {
    return v;
  } else {
    return T(v);  // the loader produced the stored integer values exactly
  }
}

template <class F>
AnyVolume ofStoredType(VoxelType type, const Geometry& g, F&& fill) {
  switch (type) {
    case VoxelType::UInt8: {
      VolumeU8 v(g);
      fill(v);
      return v;
    }
    case VoxelType::Int16: {
      VolumeI16 v(g);
      fill(v);
      return v;
    }
    case VoxelType::UInt16: {
      VolumeU16 v(g);
      fill(v);
      return v;
    }
    default: {
      VolumeF32 v(g);
      fill(v);
      return v;
    }
  }
}
}  // namespace

AnyVolume ChunkCache::readBox(const Index3& origin, const Index3& size) {
  const Geometry& G = vol_.geometry;
  for (int a = 0; a < 3; ++a)
    if (size[a] < 1 || origin[a] < 0 || origin[a] + size[a] > G.dims[a])
      throw InvalidArgument("readBox: box outside the volume " + G.describe());
  Geometry g = G;
  g.dims = size;
  g.origin = G.indexToWorld(Vec3(double(origin[0]), double(origin[1]), double(origin[2])));
  std::vector<float> buf(size_t(size[0] * size[1] * size[2]));
  readRegion(origin, size, buf.data());
  return ofStoredType(vol_.type, g, [&](auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    for (size_t i = 0; i < buf.size(); ++i) v.data()[i] = clampTo<T>(buf[i]);
  });
}

AnyVolume ChunkCache::readAll(Progress& progress) {
  const Geometry& g = vol_.geometry;
  auto fill = [&](auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const Index3& k = vol_.chunk;
    std::vector<float> slab(size_t(g.dims[0] * g.dims[1] * std::min(k[2], g.dims[2])));
    for (int64_t z0 = 0; z0 < g.dims[2]; z0 += k[2]) {
      progress.report(double(z0) / double(g.dims[2]), "read");
      const int64_t nz = std::min(k[2], g.dims[2] - z0);
      readRegion({0, 0, z0}, {g.dims[0], g.dims[1], nz}, slab.data());
      T* dst = v.data() + g.dims[0] * g.dims[1] * z0;
      for (int64_t i = 0; i < g.dims[0] * g.dims[1] * nz; ++i) dst[i] = clampTo<T>(slab[size_t(i)]);
    }
  };
  return ofStoredType(vol_.type, g, fill);
}

}  // namespace vs
