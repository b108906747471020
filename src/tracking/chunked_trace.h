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
//
// Refinement: each path's voxels are centred and given radii by the core's refineCentreline
// (tracking/centreline.h), on windows of the path: `refineWindow` points refined together with
// `refineOverlap` more on each side (whose results are dropped), in the region around them
// (bounding box + the rays' reach + the smoothing's support) read through the chunk cache and
// smoothed like the in-memory tracer's intensities (refinementIntensity). With a window holding
// the whole path this is the in-memory refinement of that path, and so it is with any window when
// the overlap exceeds the refinement's rounds + 1 (a point feels its neighbours only through one
// smoothing step per round: tested); memory is one window's region, never the path's box.
#pragma once

#include <vector>

#include "cost/cost3d.h"
#include "graph/block_search.h"
#include "graph/path.h"
#include "tracking/centreline.h"
#include "volume/chunked_volume.h"

namespace vs {

struct ChunkedTraceOptions {
  Cost3DOptions cost;        // kind Intensity or Given; windowLo/Hi NaN = estimated (see above)
  int blockShift = 4;        // search blocks of 2^shift voxels per side
  bool goalDirected = true;  // A* with the cost floor as bound (exact either way)
  bool refine = true;        // sub-voxel centrelines and radii (see above)
  CentrelineOptions centreline;
  double refineSmoothMm = 1.0;  // Gaussian sigma of the refinement's intensities (trace's intensity default)
  int refineWindow = 128;       // path points refined together
  int refineOverlap = 32;       // context points on each side of a window (dropped)
};

struct ChunkedTraceResult {
  std::vector<Path> paths;                   // one per target, empty when unreachable
  std::vector<std::vector<Vec3>> points;     // per path, per voxel: refined centreline (index); empty: not refined
  std::vector<std::vector<double>> radiiMm;  // per path, per voxel (refined); empty: not refined
  int64_t refineRegionVoxels = 0;            // largest region read for one refinement window
  double refineSeconds = 0;
  double windowLo = 0, windowHi = 0;  // Intensity: the window used
  std::string costDescription;
  BlockSearchStats search;
  ChunkCacheStats cache;
};

// The refinement alone (as traceChunked runs it) of one root-first voxel path: per voxel, the
// refined point (continuous index) and radius. `costsGiven`: the voxels are costs (centred in
// their valleys). Returns the largest region read in voxels through `regionVoxels`.
RefinedCentreline refineChunked(ChunkCache& volume, const std::vector<std::array<int64_t, 3>>& voxels, bool costsGiven,
                                const ChunkedTraceOptions& options, int64_t* regionVoxels = nullptr,
                                Progress& progress = Progress::none());

ChunkedTraceResult traceChunked(ChunkCache& volume, const Index3& root, const std::vector<Index3>& targets,
                                const ChunkedTraceOptions& options = {}, Progress& progress = Progress::none());

}  // namespace vs
