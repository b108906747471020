#include "tracking/chunked_trace.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "features/features3d.h"
#include "util/error.h"

namespace vs {

ChunkedTraceResult traceChunked(ChunkCache& volume, const Index3& root, const std::vector<Index3>& targets,
                                const ChunkedTraceOptions& options, Progress& progress) {
  const ChunkedVolume& cv = volume.volume();
  const Geometry& G = cv.geometry;
  Cost3DOptions co = options.cost;
  if (co.kind != CostKind3D::Intensity && co.kind != CostKind3D::Given)
    throw InvalidArgument("chunked trace: cost '" + costKindName(co.kind) +
                          "' needs filters over the whole volume; use intensity or given for chunked volumes");
  if (co.kind == CostKind3D::Intensity && co.smoothMm > 0)
    throw InvalidArgument("chunked trace: the intensity cost's smoothing is not available on chunked volumes");
  if (!G.contains(root)) throw InvalidArgument("chunked trace: root outside the volume " + G.describe());
  for (const Index3& t : targets)
    if (!G.contains(t)) throw InvalidArgument("chunked trace: target outside the volume " + G.describe());
  ChunkedTraceResult out;
  if (co.kind == CostKind3D::Intensity && (std::isnan(co.windowLo) || std::isnan(co.windowHi))) {
    // Percentiles of the chunks holding the root and the targets.
    std::set<Index3> chunks;
    auto add = [&](const Index3& v) { chunks.insert({v[0] / cv.chunk[0], v[1] / cv.chunk[1], v[2] / cv.chunk[2]}); };
    add(root);
    for (const Index3& t : targets) add(t);
    std::vector<float> sample;
    for (const Index3& c : chunks) {
      const Index3 o{c[0] * cv.chunk[0], c[1] * cv.chunk[1], c[2] * cv.chunk[2]};
      const Index3 n{std::min(cv.chunk[0], G.dims[0] - o[0]), std::min(cv.chunk[1], G.dims[1] - o[1]),
                     std::min(cv.chunk[2], G.dims[2] - o[2])};
      std::vector<float> box(size_t(n[0] * n[1] * n[2]));
      volume.readRegion(o, n, box.data());
      sample.insert(sample.end(), box.begin(), box.end());
    }
    if (std::isnan(co.windowLo)) co.windowLo = percentileOf(sample, 1.0);
    if (std::isnan(co.windowHi)) co.windowHi = percentileOf(sample, 99.9);
    if (!(co.windowHi > co.windowLo))
      throw DataError("chunked trace: no contrast around the root and targets (intensity window " +
                      std::to_string(co.windowLo) + ".." + std::to_string(co.windowHi) + "); give --window lo,hi");
  }
  out.windowLo = co.windowLo;
  out.windowHi = co.windowHi;

  BlockCostSource src;
  src.dims = G.dims;
  src.spacing = {G.spacing[0], G.spacing[1], G.spacing[2]};
  src.blockShift = options.blockShift;
  // The cost floor bounds every node cost from below (intensity: eps; given: 0, no bound known).
  src.minCost = options.goalDirected && co.kind == CostKind3D::Intensity ? co.epsilon : 0.0;
  const int64_t B = int64_t(1) << options.blockShift;
  src.fill = [&volume, &co, &G, B, &out](const std::array<int64_t, 3>& b, std::span<float> dst) {
    const Index3 o{b[0] * B, b[1] * B, b[2] * B};
    const Index3 n{std::min(B, G.dims[0] - o[0]), std::min(B, G.dims[1] - o[1]), std::min(B, G.dims[2] - o[2])};
    Geometry g;
    g.dims = n;
    g.spacing = G.spacing;
    VolumeF32 block(g);
    volume.readRegion(o, n, block.data());
    NodeCost3D nc;
    try {
      nc = computeNodeCost3D(block, co);
    } catch (const DataError& e) {  // voxel named in block coordinates: say where the block is
      throw DataError(std::string(e.what()) + " (in the block at voxel (" + std::to_string(o[0]) + "," +
                      std::to_string(o[1]) + "," + std::to_string(o[2]) + "))");
    }
    if (out.costDescription.empty()) out.costDescription = nc.description;
    std::fill(dst.begin(), dst.end(), 0.0f);
    for (int64_t z = 0; z < n[2]; ++z)
      for (int64_t y = 0; y < n[1]; ++y)
        std::copy_n(nc.node.data() + size_t(n[0] * (y + n[1] * z)), size_t(n[0]), dst.data() + size_t(B * (y + B * z)));
  };
  BlockSearch search(src);
  std::vector<std::array<int64_t, 3>> t;
  for (const Index3& v : targets) t.push_back({v[0], v[1], v[2]});
  out.paths = search.findPaths({root[0], root[1], root[2]}, t, progress);
  out.search = search.stats();
  out.cache = volume.stats();
  return out;
}

}  // namespace vs
