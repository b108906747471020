#include "tracking/pruned_graph.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>

#include "tracking/voxel_line.h"
#include "util/parallel.h"

namespace vs {

namespace {

constexpr uint16_t kInf = 65535;

// Offsets of a 6/18/26 connectivity (all of {-1,0,1}^3 \ 0 with at most k non-zero components).
std::vector<std::array<int, 3>> offsetsFor(int connectivity) {
  const int maxNonZero = connectivity == 6 ? 1 : (connectivity == 18 ? 2 : 3);
  std::vector<std::array<int, 3>> out;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nz = (dx != 0) + (dy != 0) + (dz != 0);
        if (nz == 0 || nz > maxNonZero) continue;
        out.push_back({dx, dy, dz});
      }
  return out;
}

std::vector<float> thresholded(const VolumeF32& vol, const IsoRegionOptions& opt) {
  std::vector<float> w = vol.voxels();
  for (auto& v : w)
    if (static_cast<double>(v) < opt.threshold) v = 0.0f;
  return w;
}

// 1 where the 3x3x3 block around the voxel is inside the volume and uniform: same(c, w) for every
// voxel w of the block, c the centre (linear indices).
template <class Same>
std::vector<uint8_t> uniformBlocksBy(const Index3& dims, Same same, Progress& progress) {
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  std::vector<uint8_t> u(static_cast<size_t>(nx * ny * nz), 0);
  parallelFor(1, std::max<int64_t>(1, nz - 1), [&](int64_t z0, int64_t z1) {
    for (int64_t z = z0; z < z1; ++z) {
      progress.check();
      for (int64_t y = 1; y < ny - 1; ++y)
        for (int64_t x = 1; x < nx - 1; ++x) {
          const int64_t i = x + nx * (y + ny * z);
          bool uniform = true;
          for (int64_t dz = -1; dz <= 1 && uniform; ++dz)
            for (int64_t dy = -1; dy <= 1 && uniform; ++dy) {
              const int64_t row = x + nx * (y + dy + ny * (z + dz));
              for (int64_t dx = -1; dx <= 1; ++dx)
                if (!same(i, row + dx)) {
                  uniform = false;
                  break;
                }
            }
          u[static_cast<size_t>(i)] = uniform ? 1 : 0;
        }
    }
  });
  return u;
}

// Intensity field: absolute tolerance on the thresholded values.
std::vector<uint8_t> uniformBlocks(const std::vector<float>& w, const Index3& dims, double tol, Progress& progress) {
  return uniformBlocksBy(
      dims,
      [&](int64_t c, int64_t v) {
        return std::abs(static_cast<double>(w[static_cast<size_t>(v)]) -
                        static_cast<double>(w[static_cast<size_t>(c)])) <= tol;
      },
      progress);
}

// Cost field: equal sign bits (when the cost uses them) and equal costs or within rel * |c(centre)|
// (inf == inf is uniform; inf vs finite is not).
std::vector<uint8_t> uniformCostBlocks(const NodeCost3D& cost, double rel, Progress& progress) {
  const bool useSign = !cost.sign.empty() && cost.signWeight > 0;
  const float* c = cost.node.data();
  const uint8_t* sg = useSign ? cost.sign.data() : nullptr;
  auto same = [&](int64_t a, int64_t b) {
    const size_t i = static_cast<size_t>(a), j = static_cast<size_t>(b);
    if (sg && (sg[i] != 0) != (sg[j] != 0)) return false;
    if (c[i] == c[j]) return true;
    return rel > 0 &&
           std::abs(static_cast<double>(c[j]) - static_cast<double>(c[i])) <= rel * std::abs(static_cast<double>(c[i]));
  };
  if (rel == 0 && !sg)
    return uniformBlocksBy(
        cost.geometry.dims,
        [&](int64_t a, int64_t b) { return c[static_cast<size_t>(a)] == c[static_cast<size_t>(b)]; }, progress);
  return uniformBlocksBy(cost.geometry.dims, same, progress);
}

// I = chessboard distance to the non-uniform set (two raster passes, 13 causal neighbours).
std::vector<uint16_t> chessboardMap(const std::vector<uint8_t>& uni, const Index3& dims, Progress& progress) {
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  std::vector<uint16_t> d(uni.size());
  for (size_t i = 0; i < d.size(); ++i) d[i] = uni[i] ? kInf : 0;
  if (nx < 3 || ny < 3 || nz < 3) return d;  // every voxel touches the border: all 0
  // Causal half of the 26-neighbourhood (raster order), as linear offsets.
  std::vector<int64_t> causal;
  for (int dz = -1; dz <= 0; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
        causal.push_back(dx + nx * (dy + ny * dz));
      }
  // Forward pass. Voxels with uni = 1 are interior (border voxels are never uniform).
  for (int64_t z = 1; z < nz - 1; ++z) {
    progress.check();
    for (int64_t y = 1; y < ny - 1; ++y)
      for (int64_t x = 1; x < nx - 1; ++x) {
        const int64_t i = x + nx * (y + ny * z);
        uint16_t& v = d[static_cast<size_t>(i)];
        if (v == 0) continue;
        uint16_t m = v;
        for (int64_t o : causal)
          m = std::min<uint16_t>(m, static_cast<uint16_t>(std::min<int>(kInf, d[static_cast<size_t>(i + o)] + 1)));
        v = m;
      }
  }
  for (int64_t z = nz - 2; z >= 1; --z) {
    progress.check();
    for (int64_t y = ny - 2; y >= 1; --y)
      for (int64_t x = nx - 2; x >= 1; --x) {
        const int64_t i = x + nx * (y + ny * z);
        uint16_t& v = d[static_cast<size_t>(i)];
        if (v == 0) continue;
        uint16_t m = v;
        for (int64_t o : causal)
          m = std::min<uint16_t>(m, static_cast<uint16_t>(std::min<int>(kInf, d[static_cast<size_t>(i - o)] + 1)));
        v = m;
      }
  }
  return d;
}

// Appendix B: one sweep per d (I = d becomes d + 1 when every 26-neighbour has I >= d).
std::vector<uint16_t> thesisIteration(const std::vector<uint8_t>& uni, const Index3& dims) {
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  std::vector<uint16_t> I(uni.size());
  for (size_t i = 0; i < I.size(); ++i) I[i] = uni[i] ? 1 : 0;
  for (int d = 1;; ++d) {
    std::vector<uint16_t> next = I;
    bool changed = false;
    for (int64_t z = 1; z < nz - 1; ++z)
      for (int64_t y = 1; y < ny - 1; ++y)
        for (int64_t x = 1; x < nx - 1; ++x) {
          const int64_t i = x + nx * (y + ny * z);
          if (I[static_cast<size_t>(i)] != d) continue;
          bool all = true;
          for (int dz = -1; dz <= 1 && all; ++dz)
            for (int dy = -1; dy <= 1 && all; ++dy)
              for (int dx = -1; dx <= 1 && all; ++dx)
                if (I[static_cast<size_t>(i + dx + nx * (dy + ny * dz))] < d) all = false;
          if (all) {
            next[static_cast<size_t>(i)] = static_cast<uint16_t>(d + 1);
            changed = true;
          }
        }
    I.swap(next);
    if (!changed) break;
  }
  return I;
}

struct UnionFind {
  std::vector<int32_t> parent;
  explicit UnionFind(int64_t n) : parent(static_cast<size_t>(n)) { std::iota(parent.begin(), parent.end(), 0); }
  int32_t find(int32_t a) {
    while (parent[static_cast<size_t>(a)] != a) {
      parent[static_cast<size_t>(a)] = parent[static_cast<size_t>(parent[static_cast<size_t>(a)])];
      a = parent[static_cast<size_t>(a)];
    }
    return a;
  }
  bool unite(int32_t a, int32_t b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
    return true;
  }
};

}  // namespace

std::string isoRegionFieldName(IsoRegionField f) { return f == IsoRegionField::Cost ? "cost" : "intensity"; }

IsoRegionField isoRegionFieldFromName(const std::string& s) {
  if (s == "cost") return IsoRegionField::Cost;
  if (s == "intensity") return IsoRegionField::Intensity;
  throw InvalidArgument("unknown IsoRegion field '" + s + "' (choose cost or intensity)");
}

std::vector<uint16_t> isoRegionMap(const VolumeF32& vol, const IsoRegionOptions& opt, Progress& progress) {
  VS_REQUIRE(!vol.empty(), "isoRegionMap: empty volume");
  VS_REQUIRE(opt.tolerance >= 0 && !std::isnan(opt.tolerance), "IsoRegion tolerance must be >= 0");
  const std::vector<float> w = thresholded(vol, opt);
  return chessboardMap(uniformBlocks(w, vol.dims(), opt.tolerance, progress), vol.dims(), progress);
}

std::vector<uint16_t> costIsoRegionMap(const NodeCost3D& cost, double rel, Progress& progress) {
  VS_REQUIRE(!cost.node.empty() && cost.node.size() == static_cast<size_t>(cost.geometry.voxelCount()),
             "costIsoRegionMap: empty cost or cost size differs from its geometry");
  VS_REQUIRE(rel >= 0 && std::isfinite(rel), "IsoRegion cost tolerance must be finite and >= 0 (relative)");
  return chessboardMap(uniformCostBlocks(cost, rel, progress), cost.geometry.dims, progress);
}

std::vector<uint16_t> isoRegionMapBruteForce(const VolumeF32& vol, const IsoRegionOptions& opt) {
  const std::vector<float> w = thresholded(vol, opt);
  return thesisIteration(uniformBlocks(w, vol.dims(), opt.tolerance, Progress::none()), vol.dims());
}

std::vector<uint16_t> costIsoRegionMapBruteForce(const NodeCost3D& cost, double rel) {
  return thesisIteration(uniformCostBlocks(cost, rel, Progress::none()), cost.geometry.dims);
}

int64_t PrunedGraph::nearestNode(const Index3& v) const {
  if (nodes == 0) return -1;
  const int64_t self = geometry.linear(v[0], v[1], v[2]);
  if (voxelNode[static_cast<size_t>(self)] >= 0) return voxelNode[static_cast<size_t>(self)];
  const Index3& dims = geometry.dims;
  const int64_t maxR = std::max({dims[0], dims[1], dims[2]});
  const double ratio = geometry.spacing.maxCoeff() / geometry.spacing.minCoeff();
  int64_t best = -1;
  double bestD = std::numeric_limits<double>::infinity();
  int64_t stopR = maxR;
  for (int64_t r = 1; r <= std::min(maxR, stopR); ++r) {
    for (int64_t dz = -r; dz <= r; ++dz)
      for (int64_t dy = -r; dy <= r; ++dy)
        for (int64_t dx = -r; dx <= r; ++dx) {
          if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
          const int64_t x = v[0] + dx, y = v[1] + dy, z = v[2] + dz;
          if (!geometry.contains(x, y, z)) continue;
          const int32_t n = voxelNode[static_cast<size_t>(geometry.linear(x, y, z))];
          if (n < 0) continue;
          const double d =
              geometry.stepLength(Vec3(static_cast<double>(dx), static_cast<double>(dy), static_cast<double>(dz)));
          if (d < bestD) bestD = d, best = n;
        }
    if (best >= 0 && stopR == maxR)
      stopR = static_cast<int64_t>(std::ceil(static_cast<double>(r) * std::sqrt(3.0) * ratio));
  }
  return best;
}

namespace {

// Nodes: I = 0 or a local maximum of I over the 26-neighbourhood (I > 0 => not on the border).
std::vector<uint8_t> isoRegionNodes(const std::vector<uint16_t>& I, const std::vector<int64_t>& lin26, int64_t N) {
  std::vector<uint8_t> isNode(static_cast<size_t>(N), 0);
  parallelFor(
      0, N,
      [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
          const uint16_t d = I[static_cast<size_t>(i)];
          bool node = d == 0;
          if (!node) {
            node = true;
            for (int64_t o : lin26)
              if (I[static_cast<size_t>(i + o)] > d) {
                node = false;
                break;
              }
          }
          isNode[static_cast<size_t>(i)] = node;
        }
      },
      1 << 16);
  return isNode;
}

// Weight of a (possibly long) edge: the cost of the straight voxel chain it stands for (the
// same rasterisation as the tracker's path output), so a pruned path never costs less than
// the full-grid path through the same voxels.
double chainCost(const Geometry& g, const NodeCost3D& cost, int64_t a, int64_t b) {
  const Index3 pa = g.unlinear(a), pb = g.unlinear(b);
  double w = 0;
  Index3 prev = pa;
  forEachVoxelAfter(pa, pb, [&](const Index3& q) {
    const double l = g.stepLength(Vec3(static_cast<double>(q[0] - prev[0]), static_cast<double>(q[1] - prev[1]),
                                       static_cast<double>(q[2] - prev[2])));
    w += cost.edgeCost(g.linear(prev[0], prev[1], prev[2]), g.linear(q[0], q[1], q[2]), l);
    prev = q;
  });
  return w;
}

// Each voxel's representative node: a node itself, a pruned voxel its steepest-ascent
// neighbour's (pruned voxels taken by decreasing I, counting-sorted).
std::vector<int32_t> ascentRepresentatives(const PrunedGraph& pg, const std::vector<uint16_t>& I,
                                           const std::vector<uint8_t>& isNode, const std::vector<int64_t>& lin26) {
  const int64_t N = pg.voxels;
  std::vector<int32_t> rep(pg.voxelNode);
  // Counting sort of pruned voxels by decreasing I.
  const size_t maxD = static_cast<size_t>(pg.maxIsoRegion) + 1;
  std::vector<int64_t> count(maxD + 2, 0);
  for (int64_t i = 0; i < N; ++i)
    if (!isNode[static_cast<size_t>(i)]) ++count[std::min<size_t>(I[static_cast<size_t>(i)], maxD)];
  std::vector<int64_t> pos(maxD + 2, 0);
  for (size_t d = maxD; d-- > 0;) pos[d] = pos[d + 1] + count[d + 1];
  std::vector<int64_t> order(static_cast<size_t>(pos[0] + count[0]));
  for (int64_t i = 0; i < N; ++i)
    if (!isNode[static_cast<size_t>(i)])
      order[static_cast<size_t>(pos[std::min<size_t>(I[static_cast<size_t>(i)], maxD)]++)] = i;
  for (int64_t i : order) {  // decreasing I; every pruned voxel has a neighbour with larger I
    const uint16_t d = I[static_cast<size_t>(i)];
    int64_t bestV = -1;
    uint16_t bestI = d;
    for (int64_t o : lin26) {
      const uint16_t di = I[static_cast<size_t>(i + o)];
      if (di > bestI) bestI = di, bestV = i + o;
    }
    rep[static_cast<size_t>(i)] = rep[static_cast<size_t>(bestV)];
  }
  return rep;
}

}  // namespace

PrunedGraph buildPrunedGraph(const VolumeF32& vol, const NodeCost3D& cost, int connectivity,
                             const IsoRegionOptions& opt, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  VS_REQUIRE(connectivity == 6 || connectivity == 18 || connectivity == 26,
             "pruned graph connectivity must be 6, 18 or 26, got " + std::to_string(connectivity));
  VS_REQUIRE(cost.node.size() == static_cast<size_t>(vol.size()), "buildPrunedGraph: cost and volume sizes differ");
  const Geometry& g = vol.geometry();
  const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  const int64_t N = g.voxelCount();
  VS_REQUIRE(N < (int64_t{1} << 31), "buildPrunedGraph: volume too large (>= 2^31 voxels)");
  const bool onCost = opt.field == IsoRegionField::Cost;
  VS_REQUIRE(!onCost || (opt.tolerance == 0 && opt.threshold == -std::numeric_limits<double>::infinity()),
             "IsoRegion threshold/tolerance apply to the intensity field; use the cost tolerance with the cost field");
  VS_REQUIRE(onCost || opt.costTolerance == 0, "IsoRegion cost tolerance applies to the cost field only");
  VS_REQUIRE(cost.geometry.dims == g.dims, "buildPrunedGraph: cost geometry differs from the volume's");
  progress.report(0.0, "isoregion");
  const std::vector<uint16_t> I =
      onCost ? costIsoRegionMap(cost, opt.costTolerance, progress) : isoRegionMap(vol, opt, progress);
  const auto offs = offsetsFor(connectivity);
  std::vector<int64_t> lin;
  for (auto& o : offs) lin.push_back(o[0] + nx * (o[1] + ny * o[2]));
  auto off26 = offsetsFor(26);
  std::vector<int64_t> lin26;
  for (auto& o : off26) lin26.push_back(o[0] + nx * (o[1] + ny * o[2]));

  PrunedGraph pg;
  pg.geometry = g;
  pg.connectivity = connectivity;
  pg.field = opt.field;
  pg.voxels = N;
  pg.voxelNode.assign(static_cast<size_t>(N), -1);
  const std::vector<uint8_t> isNode = isoRegionNodes(I, lin26, N);
  std::vector<std::array<float, 3>> positions;
  for (int64_t i = 0; i < N; ++i) {
    if (!isNode[static_cast<size_t>(i)]) continue;
    pg.voxelNode[static_cast<size_t>(i)] = static_cast<int32_t>(pg.nodeVoxel.size());
    pg.nodeVoxel.push_back(i);
    const Index3 p = g.unlinear(i);
    positions.push_back({static_cast<float>(static_cast<double>(p[0]) * g.spacing[0]),
                         static_cast<float>(static_cast<double>(p[1]) * g.spacing[1]),
                         static_cast<float>(static_cast<double>(p[2]) * g.spacing[2])});
    pg.maxIsoRegion = std::max<int>(pg.maxIsoRegion, I[static_cast<size_t>(i)]);
  }
  pg.nodes = static_cast<int64_t>(pg.nodeVoxel.size());
  progress.report(0.3, "graph");

  auto len = [&](int64_t a, int64_t b) { return chainCost(g, cost, a, b); };
  // Every undirected edge once, in a deterministic order: fn(uVoxel, vVoxel).
  auto forEachEdge = [&](auto&& fn) {
    for (int64_t z = 0; z < nz; ++z) {
      progress.check();
      for (int64_t y = 0; y < ny; ++y)
        for (int64_t x = 0; x < nx; ++x) {
          const int64_t u = x + nx * (y + ny * z);
          if (!isNode[static_cast<size_t>(u)]) continue;
          const int d = I[static_cast<size_t>(u)];
          for (size_t k = 0; k < offs.size(); ++k) {
            if (d == 0) {
              if (!g.contains(x + offs[k][0], y + offs[k][1], z + offs[k][2])) continue;
              const int64_t v = u + lin[k];
              if (v <= u || !isNode[static_cast<size_t>(v)] || I[static_cast<size_t>(v)] != 0) continue;
              fn(u, v);
            } else {
              const int64_t X = x + d * offs[k][0], Y = y + d * offs[k][1], Z = z + d * offs[k][2];
              if (!g.contains(X, Y, Z)) continue;  // cannot happen (the cube is inside), kept for safety
              const int64_t v = g.linear(X, Y, Z);
              if (!isNode[static_cast<size_t>(v)]) continue;
              if (I[static_cast<size_t>(v)] == d && v < u) continue;  // the other centre adds it
              fn(u, v);
            }
          }
        }
    }
  };
  // Pass 1: degrees and components (no weights yet). The CSR is built directly (8 bytes per
  // directed edge) instead of through an edge list.
  std::vector<int64_t> rowStart(static_cast<size_t>(pg.nodes) + 1, 0);
  UnionFind uf(pg.nodes);
  int64_t undirected = 0;
  forEachEdge([&](int64_t u, int64_t v) {
    const int32_t a = pg.voxelNode[static_cast<size_t>(u)], b = pg.voxelNode[static_cast<size_t>(v)];
    ++rowStart[static_cast<size_t>(a) + 1], ++rowStart[static_cast<size_t>(b) + 1];
    uf.unite(a, b);
    ++undirected;
  });
  progress.report(0.5, "graph");

  // Connectivity repair: representatives of pruned voxels by steepest ascent of I.
  std::vector<std::pair<int32_t, int32_t>> repairs;
  {
    const std::vector<int32_t> rep = ascentRepresentatives(pg, I, isNode, lin26);
    for (int64_t z = 0; z < nz; ++z) {
      progress.check();
      for (int64_t y = 0; y < ny; ++y)
        for (int64_t x = 0; x < nx; ++x) {
          const int64_t a = x + nx * (y + ny * z);
          for (size_t k = offs.size() / 2; k < offs.size(); ++k) {  // forward half of the directions
            const int64_t X = x + offs[k][0], Y = y + offs[k][1], Z = z + offs[k][2];
            if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
            const int64_t b = a + lin[k];
            if (I[static_cast<size_t>(a)] == 0 && I[static_cast<size_t>(b)] == 0) continue;  // already an edge
            const int32_t ra = rep[static_cast<size_t>(a)], rb = rep[static_cast<size_t>(b)];
            if (ra == rb || !uf.unite(ra, rb)) continue;
            repairs.push_back({ra, rb});
            ++rowStart[static_cast<size_t>(ra) + 1], ++rowStart[static_cast<size_t>(rb) + 1];
          }
        }
    }
  }
  pg.repairEdges = static_cast<int64_t>(repairs.size());
  pg.edges = undirected + pg.repairEdges;
  progress.report(0.7, "graph");

  // Pass 2: fill targets and weights (both directions), in the same deterministic order.
  for (size_t i = 1; i < rowStart.size(); ++i) rowStart[i] += rowStart[i - 1];
  std::vector<int64_t> cursor(rowStart.begin(), rowStart.end() - 1);
  std::vector<uint32_t> targets(static_cast<size_t>(rowStart.back()));
  std::vector<float> weights(static_cast<size_t>(rowStart.back()));
  auto put = [&](int32_t a, int32_t b, float w) {
    const size_t i = static_cast<size_t>(cursor[static_cast<size_t>(a)]++);
    targets[i] = static_cast<uint32_t>(b);
    weights[i] = w;
  };
  forEachEdge([&](int64_t u, int64_t v) {
    const int32_t a = pg.voxelNode[static_cast<size_t>(u)], b = pg.voxelNode[static_cast<size_t>(v)];
    const float w = static_cast<float>(len(u, v));
    put(a, b, w), put(b, a, w);
  });
  for (const auto& [ra, rb] : repairs) {
    const float w =
        static_cast<float>(len(pg.nodeVoxel[static_cast<size_t>(ra)], pg.nodeVoxel[static_cast<size_t>(rb)]));
    put(ra, rb, w), put(rb, ra, w);
  }
  progress.report(0.9, "graph");
  pg.graph = CsrGraph(std::move(rowStart), std::move(targets), std::move(weights), std::move(positions));
  pg.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress.report(1.0, "graph");
  return pg;
}

}  // namespace vs
