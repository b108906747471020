#include "tracking/chunked_trace.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <string>

#include "features/features3d.h"
#include "util/error.h"

namespace vs {

RefinedCentreline refineChunked(ChunkCache& volume, const std::vector<std::array<int64_t, 3>>& voxels, bool costsGiven,
                                const ChunkedTraceOptions& options, int64_t* regionVoxels, Progress& progress) {
  if (options.refineWindow < 1 || options.refineOverlap < 0)
    throw InvalidArgument("chunked refinement: window must be >= 1 point and overlap >= 0");
  const Geometry& G = volume.volume().geometry;
  const CentrelineOptions& co = options.centreline;
  const int64_t n = int64_t(voxels.size());
  RefinedCentreline out;
  out.points.resize(size_t(n));
  out.radiiMm.resize(size_t(n));
  // Margin per axis: the rays' reach, the points' moves, the smoothing kernel's support.
  const double reachMm = co.maxRadiusMm + co.maxStepMm * (co.iterations + 1) + 4.0 * options.refineSmoothMm;
  Index3 margin;
  for (int i = 0; i < 3; ++i) margin[i] = int64_t(std::ceil(reachMm / G.spacing[i])) + 2;
  for (int64_t s = 0; s < n; s += options.refineWindow) {
    progress.report(double(s) / double(n), "refine");
    const int64_t a = std::max<int64_t>(0, s - options.refineOverlap);
    const int64_t e = std::min(n, s + options.refineWindow + options.refineOverlap);
    Index3 lo = voxels[size_t(a)], hi = voxels[size_t(a)];
    for (int64_t k = a; k < e; ++k)
      for (int i = 0; i < 3; ++i) {
        lo[i] = std::min(lo[i], voxels[size_t(k)][size_t(i)]);
        hi[i] = std::max(hi[i], voxels[size_t(k)][size_t(i)]);
      }
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::max<int64_t>(0, lo[i] - margin[i]);
      hi[i] = std::min<int64_t>(G.dims[i] - 1, hi[i] + margin[i]);
    }
    Geometry g;
    g.dims = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
    g.spacing = G.spacing;
    if (regionVoxels) *regionVoxels = std::max(*regionVoxels, g.voxelCount());
    VolumeF32 region(g);
    volume.readRegion(lo, g.dims, region.data());
    const VolumeF32 lumen = refinementIntensity(region, options.refineSmoothMm, costsGiven);
    CentrelineTree tree;  // the window as a chain; its first point (the root, or context) stays
    for (int64_t k = a; k < e; ++k) {
      const auto& v = voxels[size_t(k)];
      tree.points.emplace_back(double(v[0] - lo[0]), double(v[1] - lo[1]), double(v[2] - lo[2]));
      tree.parent.push_back(int32_t(k - a) - 1);
    }
    const RefinedCentreline w = refineCentreline(lumen, tree, co);
    const Vec3 shift{double(lo[0]), double(lo[1]), double(lo[2])};
    for (int64_t k = s; k < std::min(n, s + options.refineWindow); ++k) {
      out.points[size_t(k)] = w.points[size_t(k - a)] + shift;
      out.radiiMm[size_t(k)] = w.radiiMm[size_t(k - a)];
    }
  }
  return out;
}

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
  if (options.refine) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const Path& p : out.paths) {
      RefinedCentreline rc;
      if (!p.empty())
        rc = refineChunked(volume, p.voxels, co.kind == CostKind3D::Given, options, &out.refineRegionVoxels, progress);
      out.points.push_back(std::move(rc.points));
      out.radiiMm.push_back(std::move(rc.radiiMm));
    }
    out.refineSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  out.cache = volume.stats();
  return out;
}

}  // namespace vs
