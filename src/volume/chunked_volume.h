// A volume made of chunks fetched on demand (issue 25): larger-than-memory data (OME-Zarr,
// io/zarr_io.h) are read a chunk at a time through a cache whose size is capped, so a search or
// a slice touches only the chunks it needs. The core knows nothing of files: a reader supplies
// `load`, which returns one chunk's voxels (converted to float32) or throws IoError naming it.
//
// Chunks are chunk[0] x chunk[1] x chunk[2] voxels (x fastest); edge chunks are full-sized,
// their voxels outside the volume are ignored. The cache evicts the least recently used chunk
// when the cap would be exceeded (at least one chunk is always held).
#pragma once

#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <unordered_map>
#include <vector>

#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct ChunkedVolume {
  Geometry geometry;
  VoxelType type = VoxelType::Float32;  // the stored voxel type (values are served as float)
  Index3 chunk{64, 64, 64};             // voxels per chunk along x, y, z
  // Loads chunk (cx, cy, cz): chunk[0]*chunk[1]*chunk[2] floats, x fastest. Throws on bad data.
  std::function<std::vector<float>(const Index3&)> load;

  Index3 chunkGrid() const {
    return {(geometry.dims[0] + chunk[0] - 1) / chunk[0], (geometry.dims[1] + chunk[1] - 1) / chunk[1],
            (geometry.dims[2] + chunk[2] - 1) / chunk[2]};
  }
};

struct ChunkCacheStats {
  int64_t loads = 0;      // chunks loaded (a chunk evicted and loaded again counts twice)
  int64_t hits = 0;       // chunk requests served from the cache
  int64_t peakBytes = 0;  // most bytes held at once
};

class ChunkCache {
 public:
  // capBytes: most bytes of chunk data held (>= one chunk is always allowed).
  ChunkCache(ChunkedVolume volume, int64_t capBytes);

  const ChunkedVolume& volume() const { return vol_; }
  // The chunk's voxels (valid until the next call). InvalidArgument outside the chunk grid.
  const float* chunk(const Index3& c);
  float at(int64_t x, int64_t y, int64_t z);
  // Copies the box [origin, origin + size) into out (x fastest); voxels outside the volume get
  // `outside`.
  void readRegion(const Index3& origin, const Index3& size, float* out, float outside = 0);
  // The whole volume in its stored voxel type (only for volumes that fit in memory).
  AnyVolume readAll(Progress& progress = Progress::none());
  // The box [origin, origin + size) in the stored voxel type, its geometry placing it where it
  // lies in the volume (origin moved to its first voxel; spacing and direction kept): e.g. one
  // slice (size 1 along an axis) reading only the chunks that hold it. InvalidArgument if the
  // box is empty or leaves the volume.
  AnyVolume readBox(const Index3& origin, const Index3& size);
  const ChunkCacheStats& stats() const { return stats_; }

 private:
  ChunkedVolume vol_;
  int64_t cap_;
  int64_t bytes_ = 0;
  Index3 grid_{};
  std::list<int64_t> lru_;  // front = most recent
  struct Slot {
    std::vector<float> data;
    std::list<int64_t>::iterator pos;
  };
  std::unordered_map<int64_t, Slot> slots_;
  ChunkCacheStats stats_;
};

}  // namespace vs
