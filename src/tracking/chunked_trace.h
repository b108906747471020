// Minimal paths on volumes larger than memory (issue 25): root -> targets on a chunked volume
// (volume/chunked_volume.h, e.g. an OME-Zarr folder) with graph/block_search: the node costs
// are computed block by block, by the core's one cost function (cost/cost3d: computeNodeCost3D
// on the block), only where the search goes; the search state is allocated per block it
// touches. Memory: the chunk cache (capped) + about 13 B per voxel of the blocks the search
// reaches + the queue, never the volume.
//
// Costs: Intensity (pointwise: needs no halo; the window lo/hi default to the 1st / 99.9th
// percentiles of the chunks holding the root and the targets, since a whole-volume percentile
// would read everything) or Given (the voxels are the costs). The 26-connected node-cost model
// of the in-memory search, so a path equals the in-memory Dijkstra's on any crop holding it
// (tests/tracking/chunked_trace_test.cpp). Other kinds (gradient, vesselness: filters with a
// halo) are refused with InvalidArgument.
#pragma once

#include <vector>

#include "cost/cost3d.h"
#include "graph/block_search.h"
#include "graph/path.h"
#include "volume/chunked_volume.h"

namespace vs {

struct ChunkedTraceOptions {
  Cost3DOptions cost;        // kind Intensity or Given; windowLo/Hi NaN = estimated (see above)
  int blockShift = 4;        // search blocks of 2^shift voxels per side
  bool goalDirected = true;  // A* with the cost floor as bound (exact either way)
};

struct ChunkedTraceResult {
  std::vector<Path> paths;            // one per target, empty when unreachable
  double windowLo = 0, windowHi = 0;  // Intensity: the window used
  std::string costDescription;
  BlockSearchStats search;
  ChunkCacheStats cache;
};

ChunkedTraceResult traceChunked(ChunkCache& volume, const Index3& root, const std::vector<Index3>& targets,
                                const ChunkedTraceOptions& options = {}, Progress& progress = Progress::none());

}  // namespace vs
