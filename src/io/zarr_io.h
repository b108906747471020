// OME-Zarr 0.4 volumes (issue 25): Zarr v2 arrays in a folder, read chunk by chunk through
// vs::ChunkCache (volume/chunked_volume.h) so volumes larger than memory can be searched and
// sliced, or whole (readVolume's dispatch for small ones).
//
// Reading: a folder with a `.zattrs` holding `multiscales` (OME-Zarr 0.4: axes z, y, x of type
// space, optionally preceded by t/c axes of size 1; `datasets` with `scale` and optional
// `translation` transformations) or a bare Zarr v2 array folder (`.zarray`, spacing 1 mm).
// Arrays: zarr_format 2, C order, no filters, dtype |u1 <i2 <u2 <f4 (and |i1 <i4 <u4 <f8,
// converted as other readers do: see ZarrInfo notes), compressor null / zlib / gzip / blosc,
// dimension_separator "." or "/". Units: millimeter (1), micrometer (1e-3), nanometer,
// centimeter, meter; none = mm. Direction: OME-Zarr 0.4 has no rotation; ZarrWriter keeps the
// volume's in a `volscissors.direction` key of .zattrs (read back here), else identity.
// Validation (IoError naming the folder and, for chunk problems, the chunk key): metadata
// types and sizes, chunk sizes, dtype, compressor, every level's shape against level 0 and its
// scale (one voxel of tolerance), and each chunk as it is read: missing, truncated, a
// compressed stream that does not decompress to exactly one chunk.
//
// Writing: OME-Zarr 0.4, dtype kept, zlib or blosc (lz4 + shuffle) or none, chunks of `chunk`^3
// voxels, a pyramid of 2x2x2 mean-downsampled levels (until the largest side fits one chunk,
// or `levels`), axes in millimeter, written into a temporary folder and renamed into place
// (an existing output folder is replaced only once the new one is complete).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "util/progress.h"
#include "volume/chunked_volume.h"
#include "volume/volume.h"

namespace vs {

struct ZarrLevelInfo {
  std::string path;  // dataset path inside the folder, e.g. "0"
  Index3 dims{};
  Vec3 spacing{1, 1, 1};  // mm
  Vec3 origin{0, 0, 0};   // mm
  Index3 chunk{};
};

struct ZarrInfo {
  std::vector<ZarrLevelInfo> levels;
  std::string dtype;       // as stored, e.g. "<u2"
  std::string compressor;  // "none", "zlib", "gzip", "blosc/lz4"
  std::vector<std::string> notes;
  bool hasDirection = false;  // the folder holds volscissors' direction key (written by ZarrWriter)
};

// True if `path` is a folder that holds `.zattrs` or `.zarray`, or its name ends in ".zarr".
bool isZarrPath(const std::string& path);
// Opens level `level` of an OME-Zarr folder (0 = full resolution) as a chunked volume; the
// metadata of every level is validated. IoError naming the folder on bad metadata; the chunk
// loader throws IoError naming the chunk.
ChunkedVolume openZarr(const std::string& path, int level = 0, ZarrInfo* info = nullptr);
// Reads a whole level into memory (refused with DataError above 3/4 of physical memory).
AnyVolume readZarr(const std::string& path, int level = 0, ZarrInfo* info = nullptr,
                   Progress& progress = Progress::none());

struct ZarrWriteOptions {
  int chunk = 64;                   // voxels per chunk side
  int levels = 0;                   // pyramid levels including the full resolution (0: automatic)
  std::string compressor = "zlib";  // "zlib", "blosc" or "none"
  int compressionLevel = 1;
};

// Writes an OME-Zarr folder chunk by chunk, without holding the volume: the caller supplies
// each level-0 chunk once (any order); finish() builds the pyramid from the written level 0,
// writes the metadata and moves the folder into place. Destroyed without finish(), it removes
// the temporary folder.
class ZarrWriter {
 public:
  ZarrWriter(const std::string& path, const Geometry& geometry, VoxelType type, const ZarrWriteOptions& options = {});
  ~ZarrWriter();
  ZarrWriter(const ZarrWriter&) = delete;
  ZarrWriter& operator=(const ZarrWriter&) = delete;
  Index3 chunkGrid() const;
  int chunkSize() const;
  // Voxels of chunk c (chunk^3 floats, x fastest; values outside the volume ignored), converted
  // to the volume's type (rounded and clamped for integer types). Thread-compatible: distinct
  // chunks may be written from distinct threads.
  void writeChunk(const Index3& c, const float* voxels) const;
  void finish(Progress& progress = Progress::none());

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

void writeZarr(const AnyVolume& volume, const std::string& path, const ZarrWriteOptions& options = {},
               Progress& progress = Progress::none());

}  // namespace vs
