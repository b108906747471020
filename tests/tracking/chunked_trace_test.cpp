// traceChunked (issue 25): block-wise costs and a block-sparse search on a chunked volume give
// the in-memory Dijkstra's costs, also across chunk and block faces, and the OME-Zarr phantom
// written chunk by chunk traces the same as its in-memory reading.
#include "tracking/chunked_trace.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "graph/grid_graph.h"
#include "graph/shortest_path.h"
#include "io/zarr_io.h"
#include "phantom/phantom.h"

namespace vs {
namespace {

ChunkedVolume overMemory(const VolumeF32& v, Index3 chunk) {
  ChunkedVolume cv;
  cv.geometry = v.geometry();
  cv.chunk = chunk;
  cv.load = [&v, chunk](const Index3& c) {
    std::vector<float> out(size_t(chunk[0] * chunk[1] * chunk[2]), 0.0f);
    for (int64_t z = 0; z < chunk[2]; ++z)
      for (int64_t y = 0; y < chunk[1]; ++y)
        for (int64_t x = 0; x < chunk[0]; ++x) {
          const int64_t gx = c[0] * chunk[0] + x, gy = c[1] * chunk[1] + y, gz = c[2] * chunk[2] + z;
          if (v.geometry().contains(gx, gy, gz)) out[size_t(x + chunk[0] * (y + chunk[1] * z))] = v(gx, gy, gz);
        }
    return out;
  };
  return cv;
}

// In-memory reference: the same cost options on the whole volume, full Dijkstra.
std::vector<double> reference(const VolumeF32& v, const Cost3DOptions& co, const Index3& root,
                              const std::vector<Index3>& targets) {
  const NodeCost3D nc = computeNodeCost3D(v, co);
  const GridGraph g(v.dims(), {v.geometry().spacing[0], v.geometry().spacing[1], v.geometry().spacing[2]}, 26);
  ShortestPathSearch s(g, GridCost::nodes(nc.node), {g.node(root[0], root[1], root[2])});
  std::vector<double> out;
  for (const Index3& t : targets) out.push_back(s.costTo(g.node(t[0], t[1], t[2])));
  return out;
}

TEST(ChunkedTrace, EqualsInMemoryDijkstraAcrossChunkFaces) {
  VesselPhantomOptions po;
  po.seed = 7;  // fixed in advance (docs/notes/large.md)
  po.dims = {70, 60, 52};
  po.spacing = {0.8, 0.8, 1.1};
  const VesselPhantom ph = makeVesselPhantom(po);
  const VolumeF32 vol = toFloat(AnyVolume(ph.volume));
  for (const Index3 chunk : {Index3{16, 16, 16}, Index3{7, 9, 11}}) {
    ChunkCache cache(overMemory(vol, chunk), 64 * 16 * 16 * 16 * 4);
    ChunkedTraceOptions o;
    o.cost.kind = CostKind3D::Intensity;
    o.cost.windowLo = 20;
    o.cost.windowHi = 220;
    for (const int shift : {2, 4}) {
      o.blockShift = shift;
      const ChunkedTraceResult r = traceChunked(cache, ph.truth.rootVoxel, ph.truth.terminalVoxels, o);
      const std::vector<double> ref = reference(vol, o.cost, ph.truth.rootVoxel, ph.truth.terminalVoxels);
      ASSERT_EQ(r.paths.size(), ref.size());
      for (size_t i = 0; i < ref.size(); ++i) {
        ASSERT_FALSE(r.paths[i].empty());
        EXPECT_NEAR(r.paths[i].cost, ref[i], 1e-12 * ref[i]) << "terminal " << i;
        EXPECT_EQ(r.paths[i].voxels.front(), ph.truth.rootVoxel);
        EXPECT_EQ(r.paths[i].voxels.back(), ph.truth.terminalVoxels[i]);
      }
      // Memory follows the explored region: far fewer blocks than the volume has.
      const int64_t B = int64_t(1) << shift;
      const int64_t allBlocks = ((70 + B - 1) / B) * ((60 + B - 1) / B) * ((52 + B - 1) / B);
      EXPECT_LT(r.search.blocksTouched, allBlocks);
    }
  }
  // Given costs: the voxels themselves (a cost volume, e.g. written by volscissors.pyramid).
  ChunkCache cache(overMemory(vol, {16, 16, 16}), 1 << 22);
  ChunkedTraceOptions o;
  o.cost.kind = CostKind3D::Given;
  const Index3 a{5, 5, 5}, b{60, 50, 40};
  const ChunkedTraceResult r = traceChunked(cache, a, {b}, o);
  EXPECT_NEAR(r.paths[0].cost, reference(vol, o.cost, a, {b})[0], 1e-9 * r.paths[0].cost);
  o.cost.kind = CostKind3D::Vesselness;
  EXPECT_THROW(traceChunked(cache, a, {b}, o), InvalidArgument);
}

// The refinement on windows read through the chunk cache: one window holding the whole path is
// the in-memory refinement of that path; short windows with enough context equal it; both lie on
// the phantom's centreline.
TEST(ChunkedTrace, RefinementEqualsInMemoryAndFollowsTheTruth) {
  VesselPhantomOptions po;
  po.seed = 7;  // fixed in advance (docs/notes/large.md)
  po.dims = {70, 60, 52};
  po.spacing = {0.8, 0.8, 1.1};
  const VesselPhantom ph = makeVesselPhantom(po);
  const VolumeF32 vol = toFloat(AnyVolume(ph.volume));
  ChunkCache cache(overMemory(vol, {16, 16, 16}), 64 * 16 * 16 * 16 * 4);
  ChunkedTraceOptions o;
  o.cost.kind = CostKind3D::Intensity;
  o.cost.windowLo = 20;
  o.cost.windowHi = 220;
  o.refineWindow = 1 << 20;
  const ChunkedTraceResult whole = traceChunked(cache, ph.truth.rootVoxel, ph.truth.terminalVoxels, o);
  o.refineWindow = 12;
  o.refineOverlap = 10;
  const ChunkedTraceResult windows = traceChunked(cache, ph.truth.rootVoxel, ph.truth.terminalVoxels, o);
  const VolumeF32 lumen = refinementIntensity(vol, o.refineSmoothMm, false);
  ASSERT_EQ(whole.points.size(), ph.truth.terminalVoxels.size());
  double sumWhole = 0, sumWin = 0, maxGap = 0;
  int64_t count = 0;
  for (size_t i = 0; i < whole.paths.size(); ++i) {
    const Path& p = whole.paths[i];
    ASSERT_EQ(whole.points[i].size(), p.voxels.size());
    ASSERT_EQ(windows.points[i].size(), p.voxels.size());
    CentrelineTree chain;
    for (size_t k = 0; k < p.voxels.size(); ++k) {
      chain.points.emplace_back(double(p.voxels[k][0]), double(p.voxels[k][1]), double(p.voxels[k][2]));
      chain.parent.push_back(int32_t(k) - 1);
    }
    const RefinedCentreline mem = refineCentreline(lumen, chain, o.centreline);
    for (size_t k = 0; k < p.voxels.size(); ++k) {
      EXPECT_LT((whole.points[i][k] - mem.points[k]).norm(), 1e-9) << "path " << i << " point " << k;
      EXPECT_NEAR(whole.radiiMm[i][k], mem.radiiMm[k], 1e-9);
      maxGap = std::max(maxGap, (windows.points[i][k] - mem.points[k]).norm());
      sumWhole += distanceToCenterline(ph.truth, whole.points[i][k]).distanceMm;
      sumWin += distanceToCenterline(ph.truth, windows.points[i][k]).distanceMm;
      ++count;
    }
  }
  // Windows of 12 points with 10 of context on each side: a point feels its neighbours only
  // through the rounds' smoothing (one neighbour per round, 4 rounds + the final centring), so
  // the kept points equal the whole path's refinement (with 2 of context they moved 0.48 voxel).
  EXPECT_LT(maxGap, 1e-5);  // (float rounding of the region-relative coordinates)
  // Mean distance to the truth: under half a voxel (0.8 mm spacing in-plane).
  EXPECT_LT(sumWhole / double(count), 0.4);
  EXPECT_LT(sumWin / double(count), 0.4);
  EXPECT_GT(whole.refineRegionVoxels, 0);
  EXPECT_LE(windows.refineRegionVoxels, whole.refineRegionVoxels);  // (the margin spans most of this volume)
  std::printf(
      "refined: mean distance to the truth %.3f mm (one window), %.3f mm (windows); windows vs one: max %.4f "
      "voxel\n",
      sumWhole / double(count), sumWin / double(count), maxGap);
  // Not refined on request.
  o.refine = false;
  EXPECT_TRUE(traceChunked(cache, ph.truth.rootVoxel, ph.truth.terminalVoxels, o).points.empty());
}

TEST(ChunkedTrace, ZarrPhantomWrittenChunkByChunk) {
  const auto dir = std::filesystem::temp_directory_path() / ("vs_chunked_trace_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.zarr").string();
  VesselPhantomOptions po;
  po.seed = 11;  // fixed in advance (docs/notes/large.md)
  po.dims = {80, 72, 64};
  Geometry g;
  g.dims = po.dims;
  ZarrWriteOptions zo;
  zo.chunk = 32;
  ZarrWriter w(path, g, VoxelType::UInt8, zo);
  const VesselTruth truth =
      makeVesselPhantomChunked(po, 32, [&w](const Index3& c, const float* v) { w.writeChunk(c, v); });
  w.finish();
  // Same tree as the in-memory generator.
  const VesselPhantom mem = makeVesselPhantom(po);
  ASSERT_EQ(truth.terminalVoxels, mem.truth.terminalVoxels);
  ASSERT_EQ(truth.rootVoxel, mem.truth.rootVoxel);
  ChunkCache cache(openZarr(path), int64_t(8) << 20);
  ChunkedTraceOptions o;
  o.cost.kind = CostKind3D::Intensity;
  const ChunkedTraceResult r = traceChunked(cache, truth.rootVoxel, truth.terminalVoxels, o);
  Cost3DOptions co = o.cost;
  co.windowLo = r.windowLo;
  co.windowHi = r.windowHi;
  const VolumeF32 whole = toFloat(readZarr(path));
  const std::vector<double> ref = reference(whole, co, truth.rootVoxel, truth.terminalVoxels);
  for (size_t i = 0; i < ref.size(); ++i) EXPECT_NEAR(r.paths[i].cost, ref[i], 1e-12 * ref[i]);
  // The path follows the tube: every voxel within the tube radius + 1 voxel of the centreline.
  for (size_t i = 0; i < r.paths.size(); ++i)
    for (const Index3& v : r.paths[i].voxels) {
      const CenterlineDistance d = distanceToCenterline(truth, Vec3(double(v[0]), double(v[1]), double(v[2])));
      ASSERT_LT(d.distanceMm, d.radiusMm + 1.5) << "terminal " << i;
    }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

}  // namespace
}  // namespace vs
