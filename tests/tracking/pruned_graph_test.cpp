// IsoRegion map and pruned graph (thesis 4.1, Appendix B): linear-time map == the thesis's
// iteration; the pruned graph never disconnects nodes the full grid connects; pruned paths
// cost at least the full-grid optimum (measured excess reported).
#include "tracking/pruned_graph.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <queue>
#include <random>

#include "cost/cost3d.h"
#include "graph/shortest_path.h"

namespace vs {
namespace {

// Piecewise-constant boxes on a flat background, a few noisy voxels, optional spacing.
VolumeF32 blocky(uint64_t seed, Index3 dims, Vec3 spacing = Vec3(1, 1, 1), int boxes = 6) {
  Geometry g;
  g.dims = dims;
  g.spacing = spacing;
  VolumeF32 v(g, 0.0f);
  std::mt19937_64 rng(seed);
  auto ri = [&](int64_t lo, int64_t hi) {
    return lo + static_cast<int64_t>(rng() % static_cast<uint64_t>(hi - lo + 1));
  };
  for (int b = 0; b < boxes; ++b) {
    const int64_t x0 = ri(0, dims[0] - 2), y0 = ri(0, dims[1] - 2), z0 = ri(0, dims[2] - 2);
    const int64_t x1 = ri(x0 + 1, dims[0] - 1), y1 = ri(y0 + 1, dims[1] - 1), z1 = ri(z0 + 1, dims[2] - 1);
    const float val = static_cast<float>(ri(1, 4) * 50);
    for (int64_t z = z0; z <= z1; ++z)
      for (int64_t y = y0; y <= y1; ++y)
        for (int64_t x = x0; x <= x1; ++x) v(x, y, z) = val;
  }
  for (int k = 0; k < 5; ++k)
    v(ri(0, dims[0] - 1), ri(0, dims[1] - 1), ri(0, dims[2] - 1)) = static_cast<float>(ri(1, 255));
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
  IsoRegionOptions bad;
  bad.tolerance = -1.0;
  EXPECT_THROW(isoRegionMap(v, bad), InvalidArgument);
}

// Direct definition for exact equality: the largest d such that the (2d+1)^3 cube lies inside the
// volume and every voxel has the centre's cost and sign bit.
std::vector<uint16_t> costMapByDefinition(const NodeCost3D& c) {
  const Index3 n = c.geometry.dims;
  std::vector<uint16_t> I(c.node.size(), 0);
  const bool useSign = !c.sign.empty() && c.signWeight > 0;
  for (int64_t z = 0; z < n[2]; ++z)
    for (int64_t y = 0; y < n[1]; ++y)
      for (int64_t x = 0; x < n[0]; ++x) {
        const size_t i = static_cast<size_t>(c.geometry.linear(x, y, z));
        for (int64_t d = 1;; ++d) {
          if (x - d < 0 || y - d < 0 || z - d < 0 || x + d >= n[0] || y + d >= n[1] || z + d >= n[2]) break;
          bool same = true;
          for (int64_t k = z - d; k <= z + d && same; ++k)
            for (int64_t j = y - d; j <= y + d && same; ++j)
              for (int64_t h = x - d; h <= x + d && same; ++h) {
                const size_t w = static_cast<size_t>(c.geometry.linear(h, j, k));
                same = c.node[w] == c.node[i] && (!useSign || c.sign[w] == c.sign[i]);
              }
          if (!same) break;
          I[i] = static_cast<uint16_t>(d);
        }
      }
  return I;
}

TEST(IsoRegion, CostFieldMapEqualsTheThesisIterationAndTheDefinition) {
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const VolumeF32 v = blocky(seed, {23, 19, 17});
    // Gradient cost with sign bits (seed odd: w_z > 0) and a windowed intensity cost.
    Cost3DOptions grad;
    grad.wz = seed % 2 ? 0.3 : 0.0;
    Cost3DOptions win;
    win.kind = CostKind3D::Intensity, win.windowLo = 60, win.windowHi = 160, win.smoothMm = 0;
    for (const NodeCost3D& c : {computeNodeCost3D(v, grad), computeNodeCost3D(v, win)}) {
      const auto I = costIsoRegionMap(c);
      EXPECT_EQ(I, costIsoRegionMapBruteForce(c)) << "seed " << seed << " " << c.description;
      EXPECT_EQ(I, costMapByDefinition(c)) << "seed " << seed << " " << c.description;
      for (double rel : {0.01, 0.3})
        EXPECT_EQ(costIsoRegionMap(c, rel), costIsoRegionMapBruteForce(c, rel)) << "seed " << seed << " rel " << rel;
    }
  }
  // Relative tolerance: costs 1.00 and 1.04 are one region at 5 %, two at 1 %.
  NodeCost3D c;
  c.geometry.dims = {9, 9, 9};
  c.node.assign(729, 1.0f);
  for (size_t i = 0; i < c.node.size(); i += 2) c.node[i] = 1.04f;
  EXPECT_EQ(costIsoRegionMap(c, 0.05)[static_cast<size_t>(c.geometry.linear(4, 4, 4))], 4);
  EXPECT_EQ(costIsoRegionMap(c, 0.01)[static_cast<size_t>(c.geometry.linear(4, 4, 4))], 0);
  // Sign bits split a region of equal costs.
  c.node.assign(729, 1.0f);
  c.sign.assign(729, 0);
  c.signWeight = 0.3f;
  c.sign[static_cast<size_t>(c.geometry.linear(6, 4, 4))] = 1;
  EXPECT_EQ(costIsoRegionMap(c)[static_cast<size_t>(c.geometry.linear(4, 4, 4))], 1);
  c.signWeight = 0;  // sign not used by the cost: ignored
  EXPECT_EQ(costIsoRegionMap(c)[static_cast<size_t>(c.geometry.linear(4, 4, 4))], 4);
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
  for (const IsoRegionField field : {IsoRegionField::Intensity, IsoRegionField::Cost}) {
    int64_t repairs = 0, nodes = 0, voxels = 0;
    for (uint64_t seed = 1; seed <= 12; ++seed)
      for (int conn : {6, 18, 26}) {
        const VolumeF32 v =
            blocky(seed, {26, 22, 20}, Vec3(1, 1, seed % 3 ? 1.0 : 2.0), 4 + static_cast<int>(seed % 5));
        Cost3DOptions co;
        if (seed % 2 == 0) co.kind = CostKind3D::Intensity, co.windowLo = 60, co.windowHi = 160;  // a windowed cost too
        const NodeCost3D cost = computeNodeCost3D(v, co);
        IsoRegionOptions io;
        io.field = field;
        if (field == IsoRegionField::Cost && seed % 3 == 0) io.costTolerance = 0.05;
        const PrunedGraph pg = buildPrunedGraph(v, cost, conn, io);
        EXPECT_LT(pg.nodes, pg.voxels);
        // The full grid of a box is connected, so the pruned graph must be one component.
        EXPECT_EQ(componentCount(pg.graph), 1)
            << "seed " << seed << " connectivity " << conn << " field " << isoRegionFieldName(field);
        repairs += pg.repairEdges, nodes += pg.nodes, voxels += pg.voxels;
      }
    std::printf(
        "[pruned connectivity, %s field] 36 graphs connected; %lld repair edges in total; %lld of %lld voxels are "
        "nodes\n",
        isoRegionFieldName(field).c_str(), static_cast<long long>(repairs), static_cast<long long>(nodes),
        static_cast<long long>(voxels));
  }
}

TEST(PrunedGraph, IsolatedShellInsideAFlatRegionStaysConnected) {
  // A small blob inside a big flat region: its I=0 shell touches no other I=0 voxel.
  Geometry g;
  g.dims = {31, 31, 31};
  VolumeF32 v(g, 10.0f);
  v(15, 15, 15) = 200.0f;
  v(16, 15, 15) = 200.0f;
  const NodeCost3D cost = computeNodeCost3D(v, Cost3DOptions{});
  IsoRegionOptions intensity;
  intensity.field = IsoRegionField::Intensity;
  EXPECT_EQ(componentCount(buildPrunedGraph(v, cost, 26, intensity).graph), 1);
  const PrunedGraph pg = buildPrunedGraph(v, cost, 26);  // cost field (default)
  EXPECT_EQ(pg.field, IsoRegionField::Cost);
  EXPECT_EQ(componentCount(pg.graph), 1);
  // Snapping: a pruned voxel snaps to a node.
  ASSERT_FALSE(pg.isNode(g.linear(8, 8, 8)));
  const int64_t n = pg.nearestNode({8, 8, 8});
  ASSERT_GE(n, 0);
  EXPECT_TRUE(pg.isNode(pg.nodeVoxel[static_cast<size_t>(n)]));
}

// Pruned path cost / full-grid optimum and length ratio over random node pairs; asserts the
// pruned graph never undercuts the full grid. Returns {mean cost ratio, max, mean length ratio}.
struct Excess {
  double meanCost = 0, maxCost = 0, meanLength = 0;
  int paths = 0;
};

Excess comparePaths(const VolumeF32& v, const NodeCost3D& cost, const IsoRegionOptions& io, uint64_t seed, int pairs) {
  const PrunedGraph pg = buildPrunedGraph(v, cost, 26, io);
  const GridGraph grid(v.dims(), {v.geometry().spacing[0], v.geometry().spacing[1], v.geometry().spacing[2]}, 26);
  const GridCost gc = cost.gridCost();
  std::mt19937_64 rng(seed);
  const int64_t src = pg.nodeVoxel[rng() % pg.nodeVoxel.size()];
  ShortestPathSearch full(grid, gc, {src});
  ShortestPathSearch pr(pg.graph, {pg.voxelNode[static_cast<size_t>(src)]});
  Excess e;
  for (int k = 0; k < pairs; ++k) {
    const int64_t node = static_cast<int64_t>(rng() % pg.nodeVoxel.size());
    const int64_t vox = pg.nodeVoxel[static_cast<size_t>(node)];
    const Path pf = full.pathTo(vox), pp = pr.pathTo(node);
    EXPECT_FALSE(pf.empty());
    EXPECT_FALSE(pp.empty());
    if (pf.empty() || pp.empty() || pf.cost <= 0) continue;
    EXPECT_GE(pp.cost, pf.cost * (1 - 1e-5)) << "seed " << seed;
    const double r = pp.cost / pf.cost;
    e.meanCost += r, e.maxCost = std::max(e.maxCost, r), e.meanLength += pp.lengthMm / std::max(1e-9, pf.lengthMm),
                     ++e.paths;
  }
  return e;
}

// Noisy intensities (uniform noise, no two neighbours alike) with bright boxes/rods; a windowed
// intensity cost (window 100..150, no smoothing) is then exactly 1 + eps in the background and
// eps inside the objects: flat in cost, never flat in intensity.
VolumeF32 noisyObjects(uint64_t seed, Index3 dims) {
  Geometry g;
  g.dims = dims;
  VolumeF32 v(g);
  std::mt19937_64 rng(seed);
  for (auto& x : v.voxels()) x = static_cast<float>(rng() % 60);
  auto ri = [&](int64_t lo, int64_t hi) {
    return lo + static_cast<int64_t>(rng() % static_cast<uint64_t>(hi - lo + 1));
  };
  for (int b = 0; b < 4; ++b) {  // rods along x, y or z with a 3x3 section, plus a box
    const int axis = b % 3;
    Index3 lo{ri(2, dims[0] - 5), ri(2, dims[1] - 5), ri(2, dims[2] - 5)}, hi{lo[0] + 2, lo[1] + 2, lo[2] + 2};
    if (b < 3)
      lo[static_cast<size_t>(axis)] = 1, hi[static_cast<size_t>(axis)] = dims[static_cast<size_t>(axis)] - 2;
    else
      hi = {std::min(lo[0] + 6, dims[0] - 2), std::min(lo[1] + 6, dims[1] - 2), std::min(lo[2] + 6, dims[2] - 2)};
    for (int64_t z = lo[2]; z <= hi[2]; ++z)
      for (int64_t y = lo[1]; y <= hi[1]; ++y)
        for (int64_t x = lo[0]; x <= hi[0]; ++x) v(x, y, z) = static_cast<float>(180 + rng() % 60);
  }
  return v;
}

Cost3DOptions windowedCost() {
  Cost3DOptions co;
  co.kind = CostKind3D::Intensity;
  co.windowLo = 100, co.windowHi = 150, co.smoothMm = 0;
  return co;
}

TEST(PrunedGraph, CostFieldPathsNeverUndercutTheFullGridAndStayClose) {
  for (const IsoRegionField field : {IsoRegionField::Intensity, IsoRegionField::Cost})
    for (int kind = 0; kind < 2; ++kind) {
      Excess sum;
      for (uint64_t seed = 1; seed <= 6; ++seed) {
        IsoRegionOptions io;
        io.field = field;
        // Gradient cost on blocky volumes (as in the thesis) and a windowed intensity cost on noisy ones.
        const VolumeF32 v = kind == 0 ? blocky(seed, {28, 24, 20}) : noisyObjects(seed, {28, 24, 20});
        const Excess e =
            comparePaths(v, computeNodeCost3D(v, kind == 0 ? Cost3DOptions{} : windowedCost()), io, seed, 10);
        sum.meanCost += e.meanCost, sum.maxCost = std::max(sum.maxCost, e.maxCost), sum.meanLength += e.meanLength;
        sum.paths += e.paths;
      }
      const double n = std::max(1, sum.paths);
      std::printf("[pruned vs full, %s field, %s] %d paths: cost ratio mean %.4f max %.4f, length ratio mean %.4f\n",
                  isoRegionFieldName(field).c_str(), kind == 0 ? "blocky/gradient" : "noisy/windowed intensity",
                  sum.paths, sum.meanCost / n, sum.maxCost, sum.meanLength / n);
      EXPECT_GE(sum.paths, 50);
      EXPECT_LT(sum.meanCost / n, 1.10);  // measured excess: a few percent (docs/notes/tracking.md)
    }
}

TEST(PrunedGraph, CostFieldPrunesAWindowedCostOnNoisyIntensities) {
  const VolumeF32 v = noisyObjects(7, {48, 40, 36});
  const NodeCost3D cost = computeNodeCost3D(v, windowedCost());
  IsoRegionOptions onIntensity;
  onIntensity.field = IsoRegionField::Intensity;
  const PrunedGraph pi = buildPrunedGraph(v, cost, 26, onIntensity);
  const PrunedGraph pc = buildPrunedGraph(v, cost, 26);
  std::printf(
      "[noisy intensities, windowed cost] %lld voxels: intensity field %lld nodes / %lld edges, cost field %lld nodes "
      "/ "
      "%lld edges (%lld repair), max I %d\n",
      static_cast<long long>(pc.voxels), static_cast<long long>(pi.nodes), static_cast<long long>(pi.edges),
      static_cast<long long>(pc.nodes), static_cast<long long>(pc.edges), static_cast<long long>(pc.repairEdges),
      pc.maxIsoRegion);
  EXPECT_EQ(pi.nodes, pi.voxels);      // noise: no uniform 3x3x3 intensity block at all
  EXPECT_LT(pc.nodes * 4, pc.voxels);  // the flat cost background is pruned: < 25 % of the voxels stay
  EXPECT_LT(pc.edges * 4, pi.edges);
  EXPECT_EQ(componentCount(pc.graph), 1);
  // The map equals the thesis's iteration on the same field.
  EXPECT_EQ(costIsoRegionMap(cost), costIsoRegionMapBruteForce(cost));
}

TEST(PrunedGraph, PathsCostAtLeastTheFullGridOptimum) {
  double sumRatio = 0, maxRatio = 0, sumLen = 0;
  int n = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const VolumeF32 v = blocky(seed, {28, 24, 20});
    const NodeCost3D cost = computeNodeCost3D(v, Cost3DOptions{});
    IsoRegionOptions io;
    io.field = IsoRegionField::Intensity;  // the thesis's rule (cost field: test above)
    const PrunedGraph pg = buildPrunedGraph(v, cost, 26, io);
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
  std::printf("[pruned vs full] %d paths: cost ratio mean %.4f max %.4f, length ratio mean %.4f\n", n, sumRatio / n,
              maxRatio, sumLen / n);
}

TEST(PrunedGraph, RejectsBadConnectivityAndOptionsOfTheOtherField) {
  const VolumeF32 v = blocky(1, {8, 8, 8});
  const NodeCost3D cost = computeNodeCost3D(v, Cost3DOptions{});
  EXPECT_THROW(buildPrunedGraph(v, cost, 8), InvalidArgument);
  IsoRegionOptions o;
  o.threshold = 30;  // intensity option with the (default) cost field
  EXPECT_THROW(buildPrunedGraph(v, cost, 26, o), InvalidArgument);
  o = {};
  o.field = IsoRegionField::Intensity;
  o.costTolerance = 0.1;
  EXPECT_THROW(buildPrunedGraph(v, cost, 26, o), InvalidArgument);
  EXPECT_THROW(costIsoRegionMap(cost, -0.1), InvalidArgument);
  EXPECT_THROW(costIsoRegionMap(cost, std::nan("")), InvalidArgument);
  EXPECT_THROW(isoRegionFieldFromName("voxels"), InvalidArgument);
  EXPECT_EQ(isoRegionFieldFromName(isoRegionFieldName(IsoRegionField::Cost)), IsoRegionField::Cost);
}

}  // namespace
}  // namespace vs
