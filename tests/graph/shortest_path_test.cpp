#include "graph/shortest_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "graph/priority_queues.h"
#include "util/error.h"

namespace vs {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------- an independent brute-force reference ----------

struct RefEdge {
  int64_t u, v;
  double w;
};

std::vector<double> bellmanFord(int64_t n, const std::vector<RefEdge>& edges, const std::vector<int64_t>& sources) {
  std::vector<double> d(size_t(n), kInf);
  for (int64_t s : sources) d[size_t(s)] = 0;
  for (int64_t it = 0; it < n; ++it) {
    bool changed = false;
    for (const auto& e : edges)
      if (d[size_t(e.u)] + e.w < d[size_t(e.v)]) {
        d[size_t(e.v)] = d[size_t(e.u)] + e.w;
        changed = true;
      }
    if (!changed) break;
  }
  return d;
}

enum class Model { Node, Sign, Edge };

struct GridCase {
  std::array<int64_t, 3> dims;
  std::array<double, 3> spacing;
  int conn;
  Model model;
  std::vector<float> node, edge;
  std::vector<uint8_t> sign;
  float wg = 0.7f, wz = 0.3f;

  GridCost cost() const {
    if (model == Model::Node) return GridCost::nodes(node);
    if (model == Model::Sign) return GridCost::scissors(node, sign, wg, wz);
    return GridCost::perEdge(edge);
  }
  int64_t n() const { return dims[0] * dims[1] * dims[2]; }
  bool allowed(int dx, int dy, int dz) const {
    const int nz = (dx != 0) + (dy != 0) + (dz != 0);
    if (nz == 0) return false;
    if (conn == 4 || conn == 8)
      if (dz != 0) return false;
    if (conn == 4 || conn == 6) return nz == 1;
    if (conn == 18) return nz <= 2;
    return true;
  }
  // Independent edge weight (formulas of grid_cost.h), -1 if not an edge.
  double weight(int64_t u, int64_t v, const GridGraph& g) const {
    const auto a = g.coords(u), b = g.coords(v);
    const int dx = int(b[0] - a[0]), dy = int(b[1] - a[1]), dz = int(b[2] - a[2]);
    if (std::abs(dx) > 1 || std::abs(dy) > 1 || std::abs(dz) > 1 || !allowed(dx, dy, dz)) return -1;
    const double len =
        std::sqrt(std::pow(dx * spacing[0], 2) + std::pow(dy * spacing[1], 2) + std::pow(dz * spacing[2], 2));
    if (model == Model::Node) return len * (double(node[size_t(u)]) + node[size_t(v)]) / 2;
    if (model == Model::Sign) {
      const double fz = ((sign[size_t(u)] != 0) != (sign[size_t(v)] != 0)) ? 0.0 : 1.0;
      return len * (double(wg) * (double(node[size_t(u)]) + node[size_t(v)]) / 2 + double(wz) * fz);
    }
    // per-edge: find k by the documented order: dz slowest, dy, dx fastest
    int k = 0;
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
          if (!allowed(x, y, z)) continue;
          if (x == dx && y == dy && z == dz) return edge[size_t(u) * size_t(conn) + size_t(k)];
          ++k;
        }
    return -1;
  }
  std::vector<RefEdge> edges(const GridGraph& g) const {
    std::vector<RefEdge> out;
    for (int64_t u = 0; u < n(); ++u) {
      const auto a = g.coords(u);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            if (!g.contains(a[0] + dx, a[1] + dy, a[2] + dz)) continue;
            const int64_t v = g.node(a[0] + dx, a[1] + dy, a[2] + dz);
            const double w = weight(u, v, g);
            if (w >= 0) out.push_back({u, v, w});
          }
    }
    return out;
  }
};

GridCase randomCase(std::mt19937& rng, int conn, Model model, std::array<double, 3> spacing = {1, 1, 1}) {
  GridCase c;
  const bool twoD = conn == 4 || conn == 8;
  std::uniform_int_distribution<int> dim(3, twoD ? 9 : 5);
  c.dims = {dim(rng), dim(rng), twoD ? 1 : dim(rng)};
  c.spacing = spacing;
  c.conn = conn;
  c.model = model;
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  const int64_t n = c.n();
  c.node.resize(size_t(n));
  c.sign.resize(size_t(n));
  for (int64_t i = 0; i < n; ++i) {
    const float r = u01(rng);
    c.node[size_t(i)] = r < 0.05f ? 0.f : u01(rng) * 2.f;  // some zero costs
    c.sign[size_t(i)] = u01(rng) < 0.5f ? 1 : 0;
  }
  c.edge.resize(size_t(n * conn));
  for (auto& e : c.edge) e = u01(rng) < 0.05f ? 0.f : u01(rng) * 3.f;
  return c;
}

// Checks a path against the independent edge weights.
void checkPath(const Path& p, const GridCase& c, const GridGraph& g, const std::vector<int64_t>& sources,
               int64_t target, double expectedCost) {
  ASSERT_FALSE(p.empty());
  EXPECT_EQ(p.nodes.back(), target);
  EXPECT_NE(std::find(sources.begin(), sources.end(), p.nodes.front()), sources.end());
  ASSERT_EQ(p.voxels.size(), p.nodes.size());
  double sum = 0, len = 0;
  for (size_t i = 0; i < p.nodes.size(); ++i) {
    EXPECT_EQ(p.voxels[i], g.coords(p.nodes[i]));
    if (i == 0) continue;
    const double w = c.weight(p.nodes[i - 1], p.nodes[i], g);
    ASSERT_GE(w, 0) << "consecutive path nodes are not neighbours";
    sum += w;
    const auto a = g.coords(p.nodes[i - 1]), b = g.coords(p.nodes[i]);
    len += std::sqrt(std::pow((b[0] - a[0]) * c.spacing[0], 2) + std::pow((b[1] - a[1]) * c.spacing[1], 2) +
                     std::pow((b[2] - a[2]) * c.spacing[2], 2));
  }
  EXPECT_NEAR(sum, p.cost, 1e-9 * (1 + sum));
  EXPECT_NEAR(p.cost, expectedCost, 1e-9 * (1 + expectedCost));
  EXPECT_NEAR(p.lengthMm, len, 1e-9 * (1 + len));
}

const int kConns[] = {4, 8, 6, 18, 26};
const Model kModels[] = {Model::Node, Model::Sign, Model::Edge};
const QueueKind kQueues[] = {QueueKind::Radix, QueueKind::BinaryHeap, QueueKind::Bucket};

TEST(ShortestPath, MatchesBellmanFordOnEveryGridAndCostModel) {
  std::mt19937 rng(7);
  for (int conn : kConns)
    for (Model model : kModels)
      for (int rep = 0; rep < 3; ++rep) {
        const std::array<double, 3> spacing =
            rep == 2 ? std::array<double, 3>{0.7, 1.3, 2.1} : std::array<double, 3>{1, 1, 1};
        GridCase c = randomCase(rng, conn, model, spacing);
        GridGraph g(c.dims, c.spacing, conn);
        std::vector<int64_t> sources{int64_t(rng() % uint32_t(c.n()))};
        if (rep == 1) sources.push_back(int64_t(rng() % uint32_t(c.n())));  // multiple sources
        const auto ref = bellmanFord(c.n(), c.edges(g), sources);
        for (QueueKind q : kQueues) {
          SCOPED_TRACE("conn " + std::to_string(conn) + " model " + std::to_string(int(model)) + " queue " +
                       std::to_string(int(q)) + " rep " + std::to_string(rep));
          SearchOptions opt;
          opt.queue = q;
          ShortestPathSearch s(g, c.cost(), sources, opt);
          s.runToCompletion();
          EXPECT_TRUE(s.finished());
          EXPECT_EQ(s.settledCount(), c.n());
          for (int64_t v = 0; v < c.n(); ++v) {
            ASSERT_TRUE(s.isSettled(v));
            EXPECT_NEAR(s.totalCost(v), ref[size_t(v)], 1e-9 * (1 + ref[size_t(v)]));
            const Path p = s.settledPath(v);
            checkPath(p, c, g, sources, v, ref[size_t(v)]);
            const int64_t pr = s.predecessor(v);
            if (pr >= 0) {
              EXPECT_EQ(g.neighbor(v, s.backDirection(v)), pr);
            }
          }
        }
      }
}

TEST(ShortestPath, CsrMatchesBellmanFord) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  for (int rep = 0; rep < 6; ++rep) {
    const int64_t n = 30 + rep * 7;
    std::vector<CsrGraph::Edge> edges;
    std::vector<RefEdge> ref;
    for (int i = 0; i < n * 3; ++i) {
      const int64_t a = rng() % n, b = rng() % n;
      const float w = u01(rng) < 0.1f ? 0.f : u01(rng) * 5;
      edges.push_back({a, b, w});
      ref.push_back({a, b, w});
      if (rep % 2 == 0) ref.push_back({b, a, w});
    }
    const bool undirected = rep % 2 == 0;
    CsrGraph g = CsrGraph::fromEdges(n, edges, undirected);
    EXPECT_EQ(g.edgeCount(), int64_t(ref.size()));
    const std::vector<int64_t> src{int64_t(rng() % n)};
    const auto d = bellmanFord(n, ref, src);
    for (QueueKind q : kQueues) {
      SearchOptions opt;
      opt.queue = q;
      ShortestPathSearch s(g, src, opt);
      s.runToCompletion();
      for (int64_t v = 0; v < n; ++v) {
        if (d[size_t(v)] == kInf)
          EXPECT_EQ(s.totalCost(v), kInf);
        else
          EXPECT_NEAR(s.totalCost(v), d[size_t(v)], 1e-9 * (1 + d[size_t(v)]));
        const Path p = s.pathTo(v);
        if (d[size_t(v)] == kInf) {
          EXPECT_TRUE(p.empty());
          EXPECT_FALSE(s.isSettled(v));
          continue;
        }
        ASSERT_FALSE(p.empty());
        EXPECT_EQ(p.nodes.front(), src[0]);
        EXPECT_EQ(p.nodes.back(), v);
        EXPECT_TRUE(p.voxels.empty());
        double sum = 0;
        for (size_t i = 1; i < p.nodes.size(); ++i) {
          double best = kInf;  // the cheapest parallel edge is the one used
          for (const auto& e : ref)
            if (e.u == p.nodes[i - 1] && e.v == p.nodes[i]) best = std::min(best, e.w);
          ASSERT_LT(best, kInf) << "path uses a missing edge";
          sum += best;
        }
        EXPECT_NEAR(sum, p.cost, 1e-9 * (1 + sum));
      }
    }
  }
}

TEST(ShortestPath, RadixQueueEqualsBinaryHeapOnLargerImagesAndVolumes) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  const std::pair<std::array<int64_t, 3>, int> shapes[] = {{{96, 80, 1}, 8}, {{24, 20, 18}, 26}, {{24, 20, 18}, 6}};
  for (const auto& [dims, conn] : shapes) {
    GridGraph g(dims, {1.0, 0.8, 1.5}, conn);
    std::vector<float> c(size_t(g.nodeCount()));
    // Smooth-ish image with a wide dynamic range (like vessel costs: 1e-3 .. 1).
    for (int64_t v = 0; v < g.nodeCount(); ++v) {
      const auto p = g.coords(v);
      const double s = std::sin(0.3 * double(p[0])) * std::cos(0.2 * double(p[1]) + 0.1 * double(p[2]));
      c[size_t(v)] = float(1e-3 + std::pow(0.5 + 0.5 * s, 4) + 0.05 * u01(rng));
    }
    SearchOptions a, b;
    a.queue = QueueKind::Radix;
    b.queue = QueueKind::BinaryHeap;
    ShortestPathSearch sa(g, GridCost::nodes(c), {g.nodeCount() / 3}, a);
    ShortestPathSearch sb(g, GridCost::nodes(c), {g.nodeCount() / 3}, b);
    sa.runToCompletion();
    sb.runToCompletion();
    for (int64_t v = 0; v < g.nodeCount(); ++v)
      ASSERT_NEAR(sa.totalCost(v), sb.totalCost(v), 1e-12 * (1 + sb.totalCost(v))) << "node " << v;
    // A coarse key resolution changes nothing but speed.
    SearchOptions coarse;
    coarse.keyResolution = 0.5;
    ShortestPathSearch sc(g, GridCost::nodes(c), {g.nodeCount() / 3}, coarse);
    sc.runToCompletion();
    for (int64_t v = 0; v < g.nodeCount(); ++v)
      ASSERT_NEAR(sc.totalCost(v), sb.totalCost(v), 1e-12 * (1 + sb.totalCost(v))) << "node " << v;
  }
}

TEST(ShortestPath, ResumedSearchEqualsFreshSearch) {
  std::mt19937 rng(5);
  for (QueueKind q : kQueues)
    for (double res : {0.0, 0.3}) {  // res 0.3: many nodes share a key, exercises re-queueing
      GridCase c = randomCase(rng, 26, Model::Node);
      c.dims = {12, 11, 10};
      c.node.assign(size_t(c.n()), 0.f);
      std::uniform_real_distribution<float> u01(0.f, 1.f);
      for (auto& x : c.node) x = u01(rng);
      GridGraph g(c.dims, {1, 1, 2}, 26);
      SearchOptions opt;
      opt.queue = q;
      opt.keyResolution = res;
      ShortestPathSearch resumed(g, c.cost(), {0}, opt);
      const int64_t targets[] = {g.node(5, 5, 5), g.node(1, 1, 0), g.node(11, 10, 9), g.node(3, 9, 2)};
      std::vector<double> got;
      for (int64_t t : targets) {
        const Path p = resumed.pathTo(t);
        ShortestPathSearch fresh(g, c.cost(), {0}, opt);
        const Path f = fresh.pathTo(t);
        EXPECT_NEAR(p.cost, f.cost, 1e-12 * (1 + f.cost));
        // Every node settled so far is final: compare with a full run.
        ShortestPathSearch full(g, c.cost(), {0}, opt);
        full.runToCompletion();
        for (int64_t v = 0; v < g.nodeCount(); ++v)
          if (resumed.isSettled(v)) {
            ASSERT_NEAR(resumed.totalCost(v), full.totalCost(v), 1e-12 * (1 + full.totalCost(v)));
          }
        EXPECT_NEAR(p.cost, full.totalCost(t), 1e-12 * (1 + p.cost));
      }
      EXPECT_LT(resumed.settledCount(), g.nodeCount() + 1);
      // settleUntilAll and costTo resume too.
      ShortestPathSearch again(g, c.cost(), {0}, opt);
      EXPECT_EQ(again.settleUntilAll(targets), 4);
      for (int64_t t : targets) EXPECT_TRUE(again.isSettled(t));
      // restart() with another source equals a fresh search from it.
      again.restart({g.node(11, 10, 9)});
      ShortestPathSearch fresh(g, c.cost(), {g.node(11, 10, 9)}, opt);
      EXPECT_NEAR(again.costTo(0), fresh.costTo(0), 1e-12);
      EXPECT_EQ(again.totalCost(g.node(11, 10, 9)), 0.0);
    }
}

TEST(ShortestPath, EarlyStopSettlesOnlyWhatIsNeeded) {
  GridGraph g({64, 64, 1}, {1, 1, 1}, 8);
  std::vector<float> c(size_t(g.nodeCount()), 1.f);
  for (double res : {0.0, 0.7, 3.0}) {  // coarse keys: many nodes per radix bucket
    SearchOptions opt;
    opt.keyResolution = res;
    ShortestPathSearch s(g, GridCost::nodes(c), {g.node(32, 32, 0)}, opt);
    EXPECT_NEAR(s.costTo(g.node(34, 32, 0)), 2.0, 1e-12);
    EXPECT_LT(s.settledCount(), res > 1 ? 400 : 100);
    EXPECT_FALSE(s.finished());
    s.settleUntilCost(10.0);
    for (int64_t v = 0; v < g.nodeCount(); ++v) {
      const double t = s.totalCost(v);
      if (t <= 10.0) {
        EXPECT_TRUE(s.isSettled(v));
      }
      if (t > 10.0 + 1.5) {
        EXPECT_FALSE(s.isSettled(v));
      }
    }
    // Resuming after a cost limit completes the same map.
    s.runToCompletion();
    ShortestPathSearch full(g, GridCost::nodes(c), {g.node(32, 32, 0)});
    full.runToCompletion();
    for (int64_t v = 0; v < g.nodeCount(); ++v) ASSERT_NEAR(s.totalCost(v), full.totalCost(v), 1e-12);
  }
}

TEST(ShortestPath, AnisotropicSpacingChoosesTheShorterPhysicalDetour) {
  // Two disjoint 4-connected corridors from (0,0) to (4,4) in a 7x7 image:
  // A = 6 steps in x + 4 in y, B = 4 in x + 6 in y. Uniform cost 1 => cost = length in mm.
  GridGraph base({7, 7, 1}, {1, 1, 1}, 4);
  std::vector<uint8_t> mask(49, 0);
  auto allow = [&](int x, int y) { mask[size_t(base.node(x, y, 0))] = 1; };
  for (int x = 0; x <= 5; ++x) allow(x, 0);
  for (int y = 1; y <= 4; ++y) allow(5, y);
  for (int y = 0; y <= 5; ++y) allow(0, y);
  for (int x = 1; x <= 4; ++x) allow(x, 5);
  allow(4, 4);
  std::vector<float> c(49, 1.f);
  SearchOptions opt;
  opt.mask = mask;
  for (const auto& [sx, sy, viaA] : {std::tuple{1.0, 2.0, true}, std::tuple{2.0, 1.0, false}}) {
    GridGraph g({7, 7, 1}, {sx, sy, 1}, 4);
    ShortestPathSearch s(g, GridCost::nodes(c), {0}, opt);
    const Path p = s.pathTo(g.node(4, 4, 0));
    ASSERT_FALSE(p.empty());
    const int64_t corner = viaA ? g.node(5, 0, 0) : g.node(0, 5, 0);
    EXPECT_NE(std::find(p.nodes.begin(), p.nodes.end(), corner), p.nodes.end());
    EXPECT_NEAR(p.cost, 4 * (sx + sy) + 2 * std::min(sx, sy), 1e-12);
    EXPECT_NEAR(p.lengthMm, p.cost, 1e-12);
    // Masked nodes are unreachable and report +inf.
    EXPECT_TRUE(s.pathTo(g.node(2, 2, 0)).empty());
    EXPECT_EQ(s.costTo(g.node(2, 2, 0)), kInf);
  }
  // 3D: a z step costs the z spacing.
  GridGraph g3({3, 3, 3}, {1, 1, 3}, 6);
  std::vector<float> c3(27, 1.f);
  ShortestPathSearch s3(g3, GridCost::nodes(c3), {0});
  EXPECT_NEAR(s3.costTo(g3.node(0, 0, 2)), 6.0, 1e-12);
  EXPECT_NEAR(s3.costTo(g3.node(2, 0, 0)), 2.0, 1e-12);
}

TEST(ShortestPath, AStarEqualsDijkstra) {
  std::mt19937 rng(9);
  for (int conn : kConns)
    for (Model model : kModels)
      for (QueueKind q : kQueues) {
        GridCase c = randomCase(rng, conn, model, {1.0, 1.4, 0.6});
        for (auto& x : c.node) x += 0.2f;  // a positive bound makes A* do something
        GridGraph g(c.dims, c.spacing, conn);
        SearchOptions opt;
        opt.queue = q;
        for (int rep = 0; rep < 4; ++rep) {
          const int64_t s = rng() % c.n(), t = rng() % c.n();
          ShortestPathSearch d(g, c.cost(), {s}, opt);
          const double want = d.costTo(t);
          SearchOptions dijkstra = opt;
          dijkstra.useAStar = false;
          const Path a = findPath(g, c.cost(), s, t, opt);
          const Path b = findPath(g, c.cost(), s, t, dijkstra);
          EXPECT_NEAR(a.cost, want, 1e-9 * (1 + want));
          EXPECT_NEAR(b.cost, want, 1e-9 * (1 + want));
          checkPath(a, c, g, {s}, t, want);
        }
      }
  // A* on a uniform image settles far fewer nodes than needed for the whole disc; check the path is straight.
  GridGraph g({200, 200, 1}, {1, 1, 1}, 8);
  std::vector<float> c(size_t(g.nodeCount()), 1.f);
  const Path p = findPath(g, GridCost::nodes(c), g.node(10, 100, 0), g.node(190, 100, 0));
  EXPECT_NEAR(p.cost, 180.0, 1e-9);
  EXPECT_EQ(p.size(), 181u);
  // CSR with positions: a ring of points; A* equals Dijkstra.
  const int n = 40;
  std::vector<std::array<float, 3>> pos;
  std::vector<CsrGraph::Edge> e;
  for (int i = 0; i < n; ++i) {
    pos.push_back({float(std::cos(i * 2 * M_PI / n)) * 10, float(std::sin(i * 2 * M_PI / n)) * 10, 0});
    e.push_back({i, (i + 1) % n, 1.0f + float(i % 3)});
    if (i % 5 == 0) e.push_back({i, (i + n / 2) % n, 30.f});
  }
  CsrGraph cg = CsrGraph::fromEdges(n, e, true, pos);
  EXPECT_GT(cg.minWeightPerMm(), 0);
  for (int t = 0; t < n; ++t) {
    ShortestPathSearch d(cg, {3});
    const Path a = findPath(cg, 3, t);
    EXPECT_NEAR(a.cost, d.costTo(t), 1e-9);
    EXPECT_GT(a.lengthMm + (t == 3 ? 1 : 0), 0);
  }
}

TEST(ShortestPath, CancelThrowsAndTheSearchCanResume) {
  GridGraph g({40, 40, 40}, {1, 1, 1}, 26);
  std::vector<float> c(size_t(g.nodeCount()));
  std::mt19937 rng(2);
  for (auto& x : c) x = float(rng() % 1000) / 1000.f;
  SearchOptions opt;
  opt.progressChunk = 1000;
  ShortestPathSearch s(g, GridCost::nodes(c), {0}, opt);
  int reports = 0;
  Progress cancelling([&](double f, const std::string& stage) {
    EXPECT_EQ(stage, "search");
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
    ++reports;
  });
  cancelling.cancel();
  EXPECT_THROW(s.runToCompletion(cancelling), Cancelled);
  EXPECT_LT(s.settledCount(), g.nodeCount());
  // Resume with a working progress: same result as an uninterrupted search.
  double last = -1;
  Progress ok([&](double f, const std::string&) {
    EXPECT_GE(f, last);
    last = f;
  });
  s.runToCompletion(ok);
  EXPECT_GT(last, 0.9);
  ShortestPathSearch full(g, GridCost::nodes(c), {0}, opt);
  full.runToCompletion();
  for (int64_t v = 0; v < g.nodeCount(); v += 7) ASSERT_DOUBLE_EQ(s.totalCost(v), full.totalCost(v));
}

TEST(ShortestPath, BadInputIsRejectedClearly) {
  GridGraph g({4, 4, 1}, {1, 1, 1}, 8);
  std::vector<float> c(16, 1.f);
  EXPECT_THROW(ShortestPathSearch(g, GridCost::nodes(c), {16}), InvalidArgument);
  EXPECT_THROW(ShortestPathSearch(g, GridCost::nodes(c), {-1}), InvalidArgument);
  EXPECT_THROW(ShortestPathSearch(g, GridCost::nodes(c), {}), InvalidArgument);
  ShortestPathSearch s(g, GridCost::nodes(c), {5});
  EXPECT_THROW(s.pathTo(16), InvalidArgument);
  EXPECT_THROW(s.costTo(-3), InvalidArgument);
  // Seed equal to target: a 1-node path of cost 0.
  const Path self = s.pathTo(5);
  ASSERT_EQ(self.size(), 1u);
  EXPECT_EQ(self.nodes[0], 5);
  EXPECT_EQ(self.cost, 0.0);
  EXPECT_EQ(self.lengthMm, 0.0);
  EXPECT_EQ(findPath(g, GridCost::nodes(c), 5, 5).size(), 1u);
  // NaN / negative costs name the voxel.
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), -0.5f}) {
    std::vector<float> b = c;
    b[6] = bad;
    try {
      ShortestPathSearch x(g, GridCost::nodes(b), {0});
      FAIL() << "expected DataError";
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find("(2,1,0)"), std::string::npos) << e.what();
    }
    std::vector<float> edges(16 * 8, 1.f);
    edges[6 * 8 + 4] = bad;  // an in-grid edge
    EXPECT_THROW(ShortestPathSearch(g, GridCost::perEdge(edges), {0}), DataError);
    std::vector<CsrGraph::Edge> ce{{0, 1, bad}};
    EXPECT_THROW(CsrGraph::fromEdges(2, ce), DataError);
  }
  // Out-of-grid per-edge entries are ignored; wrong array sizes are rejected.
  std::vector<float> edges(16 * 8, 1.f);
  edges[0 * 8 + 0] = std::numeric_limits<float>::quiet_NaN();  // (0,0) towards (-1,-1): not an edge
  EXPECT_NO_THROW(ShortestPathSearch(g, GridCost::perEdge(edges), {0}));
  EXPECT_THROW(ShortestPathSearch(g, GridCost::nodes(std::vector<float>(15, 1.f)), {0}), InvalidArgument);
  EXPECT_THROW(ShortestPathSearch(g, GridCost::perEdge(std::vector<float>(16 * 4, 1.f)), {0}), InvalidArgument);
  std::vector<uint8_t> shortSign(3, 0);
  EXPECT_THROW(ShortestPathSearch(g, GridCost::scissors(c, shortSign), {0}), InvalidArgument);
  EXPECT_THROW(ShortestPathSearch(g, GridCost::scissors(c, std::vector<uint8_t>(16, 0), -1.f, 0.3f), {0}),
               InvalidArgument);
  // Masked-out source, wrong mask size.
  std::vector<uint8_t> mask(16, 1);
  mask[0] = 0;
  SearchOptions opt;
  opt.mask = mask;
  EXPECT_THROW(ShortestPathSearch(g, GridCost::nodes(c), {0}, opt), InvalidArgument);
  std::vector<uint8_t> shortMask(5, 1);
  opt.mask = shortMask;
  EXPECT_THROW(ShortestPathSearch(g, GridCost::nodes(c), {1}, opt), InvalidArgument);
  // +inf costs are impassable: a wall of inf makes the far side unreachable (empty path, +inf cost).
  std::vector<float> wall(16, 1.f);
  for (int y = 0; y < 4; ++y) wall[size_t(g.node(2, y, 0))] = std::numeric_limits<float>::infinity();
  ShortestPathSearch w(g, GridCost::nodes(wall), {0});
  EXPECT_TRUE(w.pathTo(g.node(3, 3, 0)).empty());
  EXPECT_EQ(w.costTo(g.node(3, 3, 0)), kInf);
  EXPECT_FALSE(w.isSettled(g.node(3, 3, 0)));
  EXPECT_TRUE(w.finished());
  EXPECT_TRUE(findPath(g, GridCost::nodes(wall), 0, g.node(3, 3, 0)).empty());
  // CSR structure errors.
  EXPECT_THROW(CsrGraph({0, 1}, {5}, {1.f}), InvalidArgument);
  EXPECT_THROW(CsrGraph({0, 2}, {0}, {1.f}), InvalidArgument);
  EXPECT_THROW(CsrGraph::fromEdges(2, {{0, 2, 1.f}}), InvalidArgument);
}

TEST(ShortestPath, TotalsAndBackPointerArraysAreExposed) {
  GridGraph g({5, 5, 1}, {1, 1, 1}, 8);
  std::vector<float> c(25, 1.f);
  ShortestPathSearch s(g, GridCost::nodes(c), {0, 24});  // two sources
  s.runToCompletion();
  ASSERT_EQ(s.totalCosts().size(), 25u);
  ASSERT_EQ(s.nodeState().size(), 25u);
  EXPECT_TRUE(s.predecessors().empty());
  EXPECT_EQ(s.backDirection(0), kNoDirection);
  EXPECT_EQ(s.predecessor(24), -1);
  for (int64_t v = 0; v < 25; ++v) {
    const auto p = g.coords(v);
    const double d0 = std::max(p[0], p[1]) + (std::sqrt(2.0) - 1) * std::min(p[0], p[1]);
    const double d1 = std::max(4 - p[0], 4 - p[1]) + (std::sqrt(2.0) - 1) * std::min(4 - p[0], 4 - p[1]);
    EXPECT_NEAR(s.totalCosts()[size_t(v)], std::min(d0, d1), 1e-12);
    EXPECT_TRUE(s.nodeState()[size_t(v)] & ShortestPathSearch::kSettledBit);
    const int dir = s.nodeState()[size_t(v)] & ShortestPathSearch::kDirectionMask;
    if (v != 0 && v != 24) {
      ASSERT_LT(dir, 8);
      EXPECT_EQ(v + g.linearOffset(dir), s.predecessor(v));
    }
  }
}
}  // namespace
}  // namespace vs

namespace vs {
namespace {

// Large enough that the O(N) record init and the cost validation run on several threads.
TEST(ShortestPath, LargeGridParallelInitAndValidation) {
  GridGraph g({300, 300, 13}, {1, 1, 1}, 26);
  std::vector<float> c(size_t(g.nodeCount()), 1.f);
  std::vector<uint8_t> mask(size_t(g.nodeCount()), 1);
  for (int64_t z = 0; z < 13; ++z)
    for (int64_t y = 0; y < 300; ++y) mask[size_t(g.node(200, y, z))] = 0;  // a wall at x = 200
  SearchOptions opt;
  opt.mask = mask;
  const int64_t src = g.node(150, 150, 6);
  ShortestPathSearch s(g, GridCost::nodes(c), {src}, opt);
  s.settleUntilCost(6.0);
  for (int64_t z = 0; z < 13; ++z)
    for (int64_t y = 140; y < 160; ++y)
      for (int64_t x = 140; x < 160; ++x) {
        std::array<int64_t, 3> d{std::abs(x - 150), std::abs(y - 150), std::abs(z - 6)};
        std::sort(d.begin(), d.end());  // d[0] <= d[1] <= d[2]
        const double want = std::sqrt(3.0) * double(d[0]) + std::sqrt(2.0) * double(d[1] - d[0]) + double(d[2] - d[1]);
        const int64_t v = g.node(x, y, z);
        if (want <= 6.0) {
          ASSERT_TRUE(s.isSettled(v));
          ASSERT_NEAR(s.totalCost(v), want, 1e-9);
        }
      }
  EXPECT_EQ(s.costTo(g.node(250, 150, 6)), kInf);  // behind the wall
  EXPECT_NEAR(s.costTo(g.node(199, 150, 6)), 49.0, 1e-9);
  c[size_t(g.nodeCount() - 5)] = -1.f;  // found by the parallel validation, named by voxel
  try {
    ShortestPathSearch bad(g, GridCost::nodes(c), {src});
    FAIL() << "expected DataError";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("(295,299,12)"), std::string::npos) << e.what();
  }
}

// The bucket queue against a sorted reference: monotone pushes (each at most maxStep above the
// last extracted key) over many wraps of its circular window pop in key order.
TEST(ShortestPath, BucketQueuePopsInKeyOrderAcrossWraps) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double scale = 10, maxStep = 20;  // keys advance by at most 200 per push: 256-bucket window
  ASSERT_EQ(detail::BucketQueue::bucketsFor(scale, maxStep), 256u);
  EXPECT_EQ(detail::BucketQueue::bucketsFor(1, 1e6), UINT64_MAX);  // too wide: the engine uses Radix
  detail::BucketQueue q(scale, maxStep);
  std::vector<double> prio(5000, 0.0);
  std::multimap<uint64_t, uint32_t> ref;
  double last = 0;
  uint32_t next = 0;
  for (int i = 0; i < 3; ++i, ++next) {
    q.push(0.0, next);
    ref.emplace(0, next);
  }
  while (!q.empty()) {
    ASSERT_FALSE(ref.empty());
    const uint32_t v = q.pop();
    const uint64_t want = ref.begin()->first;
    EXPECT_EQ(q.keyOf(prio[v]), want) << "node " << v;
    for (auto it = ref.begin(); it != ref.end(); ++it)
      if (it->second == v) {
        ref.erase(it);
        break;
      }
    last = prio[v];
    for (int k = 0; k < (next % 10 == 0 ? 2 : 1) && next < prio.size(); ++k, ++next) {
      prio[next] = last + (u01(rng) < 0.2 ? 0.0 : u01(rng) * maxStep * 0.999);
      q.push(prio[next], next);
      ref.emplace(q.keyOf(prio[next]), next);
    }
  }
  EXPECT_TRUE(ref.empty());
  EXPECT_GT(q.lastKey(), 10 * 256u);  // the window wrapped more than 10 times
}

// A key resolution so fine that one edge spans > 2^16 keys falls back to the radix heap; the
// result is the same whatever the queue.
TEST(ShortestPath, BucketQueueFallbackGivesTheSameMap) {
  GridGraph g({40, 30, 1}, {1, 1, 1}, 8);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  std::vector<float> c(size_t(g.nodeCount()));
  for (auto& x : c) x = 1e-3f + u01(rng);
  SearchOptions heap, fine, coarse;
  heap.queue = QueueKind::BinaryHeap;
  fine.keyResolution = 1e-7;   // 2^16 buckets would not cover one edge
  coarse.keyResolution = 0.9;  // label-correcting inside a bucket
  ShortestPathSearch a(g, GridCost::nodes(c), {7}, heap), b(g, GridCost::nodes(c), {7}, fine),
      d(g, GridCost::nodes(c), {7}, coarse);
  a.runToCompletion();
  b.runToCompletion();
  d.runToCompletion();
  for (int64_t v = 0; v < g.nodeCount(); ++v) {
    ASSERT_NEAR(b.totalCost(v), a.totalCost(v), 1e-12 * (1 + a.totalCost(v)));
    ASSERT_NEAR(d.totalCost(v), a.totalCost(v), 1e-12 * (1 + a.totalCost(v)));
  }
}

// Records are filled lazily in chunks of consecutive node ids: an early stop near one corner of
// a grid of many chunks leaves far chunks untouched; reads of untouched nodes (T, settled, back
// pointer, nodeState with the interior flag, masked -inf) must still be right, and resuming,
// materialising and restarting must give the reference map.
TEST(ShortestPath, LazyChunkInitIsInvisible) {
  GridGraph g({70, 60, 50}, {1, 1, 1.5}, 26);  // 210000 nodes, reach 4271 -> 13 chunks of 2^14
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  std::vector<float> c(size_t(g.nodeCount()));
  for (auto& x : c) x = 0.05f + u01(rng);
  std::vector<uint8_t> mask(size_t(g.nodeCount()), 1);
  const int64_t maskedFar = g.node(60, 50, 45), maskedNear = g.node(3, 3, 3);
  mask[size_t(maskedFar)] = 0;
  mask[size_t(maskedNear)] = 0;
  for (QueueKind q : kQueues) {
    SearchOptions opt, ref;
    opt.queue = q;
    opt.mask = mask;
    ref.queue = QueueKind::BinaryHeap;
    ref.mask = mask;
    ShortestPathSearch full(g, GridCost::nodes(c), {g.node(1, 1, 1)}, ref);
    full.runToCompletion();
    ShortestPathSearch s(g, GridCost::nodes(c), {g.node(1, 1, 1)}, opt);
    const int64_t near = g.node(4, 2, 1), far = g.node(65, 55, 48), edge = g.node(69, 30, 49);
    EXPECT_NEAR(s.costTo(near), full.totalCost(near), 1e-12);
    EXPECT_LT(s.settledCount(), 2000);
    for (int64_t v : {far, edge, maskedFar}) {
      EXPECT_FALSE(s.isSettled(v));
      EXPECT_EQ(s.totalCost(v), kInf);
      EXPECT_EQ(s.predecessor(v), -1);
      EXPECT_EQ(s.backDirection(v), kNoDirection);
    }
    EXPECT_FALSE(s.settleUntil(maskedNear));
    EXPECT_TRUE(s.pathTo(maskedFar).empty());
    // Snapshot after the early stop: every chunk filled, interior flag from the coordinates.
    const auto st = s.nodeState();
    const auto T = s.totalCosts();
    for (int64_t v = 0; v < g.nodeCount(); ++v) {
      const auto p = g.coords(v);
      const bool interior = p[0] >= 1 && p[0] <= 68 && p[1] >= 1 && p[1] <= 58 && p[2] >= 1 && p[2] <= 48;
      ASSERT_EQ((st[size_t(v)] & 0x20) != 0, interior) << "node " << v;
      ASSERT_EQ((st[size_t(v)] & ShortestPathSearch::kSettledBit) != 0, s.isSettled(v));
      if (mask[size_t(v)] == 0) {
        ASSERT_EQ(T[size_t(v)], -kInf);
      }
    }
    // Resumed to the far corner and to completion: the reference map.
    EXPECT_NEAR(s.costTo(far), full.totalCost(far), 1e-12 * (1 + full.totalCost(far)));
    s.runToCompletion();
    for (int64_t v = 0; v < g.nodeCount(); ++v) {
      if (mask[size_t(v)] == 0) {
        ASSERT_EQ(s.totalCost(v), kInf);
        continue;
      }
      ASSERT_NEAR(s.totalCost(v), full.totalCost(v), 1e-12 * (1 + full.totalCost(v))) << "node " << v;
    }
    // restart() forgets the old records although they stay in memory.
    s.restart({far});
    EXPECT_EQ(s.settledCount(), 0);
    EXPECT_FALSE(s.isSettled(near));
    EXPECT_EQ(s.totalCost(near), kInf);
    ShortestPathSearch fresh(g, GridCost::nodes(c), {far}, ref);
    EXPECT_NEAR(s.costTo(edge), fresh.costTo(edge), 1e-12 * (1 + fresh.costTo(edge)));
    const Path p = s.pathTo(edge);
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.nodes.front(), far);
  }
}

}  // namespace
}  // namespace vs
