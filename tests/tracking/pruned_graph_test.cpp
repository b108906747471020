// IsoRegion map and pruned graph (thesis 4.1, Appendix B): linear-time map == the thesis's
// iteration; the pruned graph never disconnects nodes the full grid connects; pruned paths
// cost at least the full-grid optimum (measured excess reported).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <queue>
#include <random>

#include "features/cost3d.h"
#include "graph/shortest_path.h"
#include "tracking/pruned_graph.h"

namespace vs {
namespace {

// Piecewise-constant boxes on a flat background, a few noisy voxels, optional spacing.
VolumeF32 blocky(uint64_t seed, Index3 dims, Vec3 spacing = Vec3(1, 1, 1), int boxes = 6) {
  Geometry g;
  g.dims = dims;
  g.spacing = spacing;
  VolumeF32 v(g, 0.0f);
  std::mt19937_64 rng(seed);
  auto ri = [&](int64_t lo, int64_t hi) { return lo + static_cast<int64_t>(rng() % static_cast<uint64_t>(hi - lo + 1)); };
  for (int b = 0; b < boxes; ++b) {
    const int64_t x0 = ri(0, dims[0] - 2), y0 = ri(0, dims[1] - 2), z0 = ri(0, dims[2] - 2);
    const int64_t x1 = ri(x0 + 1, dims[0] - 1), y1 = ri(y0 + 1, dims[1] - 1), z1 = ri(z0 + 1, dims[2] - 1);
    const float val = static_cast<float>(ri(1, 4) * 50);
    for (int64_t z = z0; z <= z1; ++z)
      for (int64_t y = y0; y <= y1; ++y)
        for (int64_t x = x0; x <= x1; ++x) v(x, y, z) = val;
  }
  for (int k = 0; k < 5; ++k) v(ri(0, dims[0] - 1), ri(0, dims[1] - 1), ri(0, dims[2] - 1)) = static_cast<float>(ri(1, 255));
  return v;
}

TEST(IsoRegion, UniformCubeHasChessboardCentre) {
  Geometry g;
  g.dims = {9, 9, 9};
  const VolumeF32 v(g, 7.0f);
  const auto I = isoRegionMap(v);
  EXPECT_EQ(I[static_cast<size_t>(g.linear(4, 4, 4))], 4);  // (2*4+1)^3 = the whole volume
  EXPECT_EQ(I[static_cast<size_t>(g.linear(0, 4, 4))], 0);  // border: block leaves the volume
  EXPECT_EQ(I[static_cast<size_t>(g.linear(2, 4, 5))], 2);
}

TEST(IsoRegion, LinearPassesEqualTheThesisIteration) {
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const VolumeF32 v = blocky(seed, {23, 19, 17});
    for (double tol : {0.0, 60.0}) {
      IsoRegionOptions o;
      o.tolerance = tol;
      o.threshold = seed % 2 ? 120.0 : -INFINITY;
      EXPECT_EQ(isoRegionMap(v, o), isoRegionMapBruteForce(v, o)) << "seed " << seed << " tol " << tol;
    }
  }
}

TEST(IsoRegion, ThresholdFlattensNoise) {
  Geometry g;
  g.dims = {20, 20, 20};
  VolumeF32 v(g);
  std::mt19937 rng(3);
  for (auto& x : v.voxels()) x = static_cast<float>(rng() % 30);  // noise below 30
  const auto raw = isoRegionMap(v);
  IsoRegionOptions o;
  o.threshold = 30;  // thesis: values below 30 set to 0
  const auto thr = isoRegionMap(v, o);
  EXPECT_EQ(*std::max_element(raw.begin(), raw.end()), 0);
  EXPECT_EQ(*std::max_element(thr.begin(), thr.end()), 9);
  EXPECT_THROW(isoRegionMap(v, IsoRegionOptions{-1.0, 0.0}), InvalidArgument);
}

// Connected components of a CSR graph (BFS), for the connectivity test.
int64_t componentCount(const CsrGraph& g) {
  std::vector<int8_t> seen(static_cast<size_t>(g.nodeCount()), 0);
  int64_t comps = 0;
  for (int64_t s = 0; s < g.nodeCount(); ++s) {
    if (seen[static_cast<size_t>(s)]) continue;
    ++comps;
    std::queue<int64_t> q;
    q.push(s);
    seen[static_cast<size_t>(s)] = 1;
    while (!q.empty()) {
      const int64_t u = q.front();
      q.pop();
      for (int64_t e = g.rowStart()[static_cast<size_t>(u)]; e < g.rowStart()[static_cast<size_t>(u) + 1]; ++e) {
        const int64_t v = g.targets()[static_cast<size_t>(e)];
        if (!seen[static_cast<size_t>(v)]) seen[static_cast<size_t>(v)] = 1, q.push(v);
      }
    }
  }
  return comps;
}

TEST(PrunedGraph, NeverDisconnectsWhatTheFullGridConnects) {
  int64_t repairs = 0;
  for (uint64_t seed = 1; seed <= 12; ++seed)
    for (int conn : {6, 18, 26}) {
      const VolumeF32 v = blocky(seed, {26, 22, 20}, Vec3(1, 1, seed % 3 ? 1.0 : 2.0), 4 + static_cast<int>(seed % 5));
      Cost3DOptions co;
      const NodeCost3D cost = computeNodeCost3D(v, co);
      const PrunedGraph pg = buildPrunedGraph(v, cost, conn);
      EXPECT_LT(pg.nodes, pg.voxels);
      // The full grid of a box is connected, so the pruned graph must be one component.
      EXPECT_EQ(componentCount(pg.graph), 1) << "seed " << seed << " connectivity " << conn;
      repairs += pg.repairEdges;
    }
  std::printf("[pruned connectivity] 36 graphs connected; %lld repair edges in total\n", static_cast<long long>(repairs));
}

TEST(PrunedGraph, IsolatedShellInsideAFlatRegionStaysConnected) {
  // A small blob inside a big flat region: its I=0 shell touches no other I=0 voxel.
  Geometry g;
  g.dims = {31, 31, 31};
  VolumeF32 v(g, 10.0f);
  v(15, 15, 15) = 200.0f;
  v(16, 15, 15) = 200.0f;
  const NodeCost3D cost = computeNodeCost3D(v, Cost3DOptions{});
  const PrunedGraph pg = buildPrunedGraph(v, cost, 26);
  EXPECT_EQ(componentCount(pg.graph), 1);
  // Snapping: a pruned voxel snaps to a node.
  ASSERT_FALSE(pg.isNode(g.linear(8, 8, 8)));
  const int64_t n = pg.nearestNode({8, 8, 8});
  ASSERT_GE(n, 0);
  EXPECT_TRUE(pg.isNode(pg.nodeVoxel[static_cast<size_t>(n)]));
}

TEST(PrunedGraph, PathsCostAtLeastTheFullGridOptimum) {
  double sumRatio = 0, maxRatio = 0, sumLen = 0;
  int n = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const VolumeF32 v = blocky(seed, {28, 24, 20});
    const NodeCost3D cost = computeNodeCost3D(v, Cost3DOptions{});
    const PrunedGraph pg = buildPrunedGraph(v, cost, 26);
    const GridGraph grid(v.dims(), {1, 1, 1}, 26);
    const GridCost gc = cost.gridCost();
    std::mt19937_64 rng(seed);
    const int64_t src = pg.nodeVoxel[rng() % pg.nodeVoxel.size()];
    ShortestPathSearch full(grid, gc, {src});
    ShortestPathSearch pr(pg.graph, {pg.voxelNode[static_cast<size_t>(src)]});
    for (int k = 0; k < 10; ++k) {
      const int64_t node = static_cast<int64_t>(rng() % pg.nodeVoxel.size());
      const int64_t vox = pg.nodeVoxel[static_cast<size_t>(node)];
      const Path pf = full.pathTo(vox), pp = pr.pathTo(node);
      ASSERT_FALSE(pf.empty());
      ASSERT_FALSE(pp.empty());
      if (pf.cost <= 0) continue;
      EXPECT_GE(pp.cost, pf.cost * (1 - 1e-5));
      const double r = pp.cost / pf.cost;
      sumRatio += r, maxRatio = std::max(maxRatio, r), sumLen += pp.lengthMm / std::max(1e-9, pf.lengthMm), ++n;
    }
  }
  std::printf("[pruned vs full] %d paths: cost ratio mean %.4f max %.4f, length ratio mean %.4f\n", n, sumRatio / n, maxRatio,
              sumLen / n);
}

TEST(PrunedGraph, RejectsBadConnectivity) {
  const VolumeF32 v = blocky(1, {8, 8, 8});
  const NodeCost3D cost = computeNodeCost3D(v, Cost3DOptions{});
  EXPECT_THROW(buildPrunedGraph(v, cost, 8), InvalidArgument);
}

}  // namespace
}  // namespace vs
