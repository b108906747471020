// The two-thread full map (SearchOptions::threads, runToCompletion on large grids): the totals
// must be the sequential search's bit for bit, every reachable node settled, back pointers
// consistent (and the sequential ones where edge weights are positive, equal totals included), and a cancel must leave
// a search that either loop can resume.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "graph/shortest_path.h"
#include "util/error.h"

namespace vs {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

SearchOptions withThreads(int threads, std::span<const uint8_t> mask = {}) {
  SearchOptions o;
  o.threads = threads;
  o.parallelMinNodes = 0;  // small test grids take the parallel path too
  o.progressChunk = 997;   // progress and stop checks often
  o.mask = mask;
  return o;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Totals bit-identical to `ref`, settled state equal, and each back pointer leads to a settled
// neighbour whose total plus the edge weight gives the node's total.
// With sameTree, the back pointers are ref's too (positive edge weights: equal totals are broken
// by direction, not by arrival order; zero-cost plateaus keep the first offer, so not there).
void expectSameMap(const ShortestPathSearch& s, const ShortestPathSearch& ref, const GridGraph& g,
                   const std::vector<float>& c, bool sameTree = false) {
  ASSERT_EQ(s.settledCount(), ref.settledCount());
  EXPECT_TRUE(s.finished());
  for (int64_t v = 0; v < g.nodeCount(); ++v) {
    ASSERT_TRUE(sameBits(s.totalCost(v), ref.totalCost(v)))
        << "node " << v << ": " << s.totalCost(v) << " vs " << ref.totalCost(v);
    ASSERT_EQ(s.isSettled(v), ref.isSettled(v)) << "node " << v;
    const int64_t p = s.predecessor(v);
    if (sameTree) {
      ASSERT_EQ(p, ref.predecessor(v)) << "node " << v << ": the tree differs";
    }
    if (p < 0) continue;
    ASSERT_TRUE(s.isSettled(p));
    const auto a = g.coords(p), b = g.coords(v);
    const auto& sp = g.spacing();
    const double len = std::sqrt(std::pow(double(b[0] - a[0]) * sp[0], 2) + std::pow(double(b[1] - a[1]) * sp[1], 2) +
                                 std::pow(double(b[2] - a[2]) * sp[2], 2));
    const double w = len * (double(c[size_t(p)]) + double(c[size_t(v)])) / 2;
    ASSERT_NEAR(s.totalCost(p) + w, s.totalCost(v), 1e-12 * (1 + s.totalCost(v))) << "node " << v;
  }
}

std::vector<float> randomCosts(const GridGraph& g, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  std::vector<float> c(size_t(g.nodeCount()));
  for (auto& x : c) {
    const float r = u01(rng);
    x = r < 0.03f ? 0.f : r < 0.05f ? std::numeric_limits<float>::infinity() : 1e-3f + u01(rng) * u01(rng);
  }
  return c;
}

TEST(ParallelSearch, TwoThreadMapEqualsSequentialBitForBit) {
  struct Case {
    std::array<int64_t, 3> dims;
    std::array<double, 3> spacing;
    int conn;
  };
  const Case cases[] = {{{23, 19, 21}, {1, 1, 1}, 26},   {{20, 17, 24}, {0.7, 0.9, 2.5}, 26},
                        {{25, 18, 16}, {1, 1, 1.5}, 18}, {{19, 22, 20}, {1, 1, 1}, 6},
                        {{90, 70, 1}, {1, 1, 1}, 8},     {{60, 85, 1}, {0.5, 1.2, 1}, 4}};
  uint32_t seed = 1;
  for (const Case& k : cases) {
    SCOPED_TRACE("grid " + std::to_string(k.dims[0]) + "x" + std::to_string(k.dims[1]) + "x" +
                 std::to_string(k.dims[2]) + ", " + std::to_string(k.conn) + "-connected");
    GridGraph g(k.dims, k.spacing, k.conn);
    const std::vector<float> c = randomCosts(g, seed++);
    // Sources in both halves of the split, one of them on the split layer itself.
    const int64_t n = g.nodeCount();
    const std::vector<int64_t> sources{n / 7, n / 2, n - n / 5};
    ShortestPathSearch ref(g, GridCost::nodes(c), sources, withThreads(1));
    ref.runToCompletion();
    for (int rep = 0; rep < 3; ++rep) {  // thread timing differs from run to run
      ShortestPathSearch par(g, GridCost::nodes(c), sources, withThreads(2));
      par.runToCompletion();
      expectSameMap(par, ref, g, c);
    }
  }
}

TEST(ParallelSearch, HonoursMasksAndUnreachableRegions) {
  GridGraph g({30, 26, 24}, {1, 1, 1}, 26);
  std::vector<float> c = randomCosts(g, 11);
  std::vector<uint8_t> mask(size_t(g.nodeCount()), 1);
  for (int64_t y = 0; y < 26; ++y)
    for (int64_t x = 0; x < 30; ++x) mask[size_t(g.node(x, y, 5))] = 0;  // a closed wall at z = 5
  const std::vector<int64_t> sources{g.node(3, 3, 20)};
  ShortestPathSearch ref(g, GridCost::nodes(c), sources, withThreads(1, mask));
  ref.runToCompletion();
  ShortestPathSearch par(g, GridCost::nodes(c), sources, withThreads(2, mask));
  par.runToCompletion();
  expectSameMap(par, ref, g, c);
  EXPECT_EQ(par.totalCost(g.node(3, 3, 2)), kInf);  // behind the wall
  EXPECT_FALSE(par.isSettled(g.node(3, 3, 2)));
}

// A search stopped part way (settleUntil) and then completed on two threads.
TEST(ParallelSearch, CompletesAResumedSearch) {
  GridGraph g({28, 24, 26}, {1, 1.2, 0.8}, 26);
  const std::vector<float> c = randomCosts(g, 5);
  const std::vector<int64_t> sources{g.node(14, 12, 2)};
  ShortestPathSearch ref(g, GridCost::nodes(c), sources, withThreads(1));
  ref.runToCompletion();
  ShortestPathSearch s(g, GridCost::nodes(c), sources, withThreads(2));
  const int64_t t = g.node(20, 20, 10);
  ASSERT_TRUE(s.settleUntil(t));
  EXPECT_TRUE(sameBits(s.totalCost(t), ref.totalCost(t)));
  s.runToCompletion();
  expectSameMap(s, ref, g, c);
}

// Cancelled part way on two threads: every node still marked settled has its final total, the
// settled count is right, and resuming (either loop) gives the reference map.
TEST(ParallelSearch, CancelLeavesAResumableSearch) {
  GridGraph g({40, 36, 44}, {1, 1, 1}, 26);
  const std::vector<float> c = randomCosts(g, 9);
  const std::vector<int64_t> sources{g.node(5, 5, 5), g.node(30, 30, 40)};
  ShortestPathSearch ref(g, GridCost::nodes(c), sources, withThreads(1));
  ref.runToCompletion();
  for (int resumeThreads : {1, 2}) {
    for (int cancelAfter : {1, 4, 12}) {
      SCOPED_TRACE("resume on " + std::to_string(resumeThreads) + " thread(s), cancel after " +
                   std::to_string(cancelAfter) + " reports");
      ShortestPathSearch s(g, GridCost::nodes(c), sources, withThreads(2));
      int reports = 0;
      Progress* self = nullptr;
      Progress cancelling([&](double f, const std::string& stage) {
        EXPECT_EQ(stage, "search");
        EXPECT_GE(f, 0.0);
        EXPECT_LE(f, 1.0);
        if (++reports >= cancelAfter) self->cancel();  // the next report() throws
      });
      self = &cancelling;
      EXPECT_THROW(s.runToCompletion(cancelling), Cancelled);
      EXPECT_LT(s.settledCount(), g.nodeCount());
      int64_t settled = 0;
      for (int64_t v = 0; v < g.nodeCount(); ++v) {
        if (!s.isSettled(v)) continue;
        ++settled;
        ASSERT_TRUE(sameBits(s.totalCost(v), ref.totalCost(v))) << "settled node " << v << " is not final";
      }
      EXPECT_EQ(settled, s.settledCount());
      if (resumeThreads == 1) {
        // The sequential loop after a parallel cancel: early stops stay exact.
        const int64_t far = g.node(39, 0, 43);
        EXPECT_TRUE(sameBits(s.costTo(far), ref.totalCost(far)));
      }
      if (resumeThreads == 1)
        s.settleUntilCost(kInf);  // the sequential loop to the end
      else
        s.runToCompletion();  // the two-thread loop again
      expectSameMap(s, ref, g, c);
    }
  }
}

// Costs of a few dyadic values: totals are exact sums, so many nodes have several predecessors
// giving exactly the same total. The tree must still be the sequential one, every run.
TEST(ParallelSearch, EqualTotalsGiveTheSequentialTree) {
  for (const int conn : {26, 6, 8}) {
    SCOPED_TRACE(std::to_string(conn) + "-connected");
    GridGraph g(conn == 8 ? std::array<int64_t, 3>{80, 90, 1} : std::array<int64_t, 3>{22, 20, 24}, {1, 1, 1}, conn);
    std::mt19937 rng(7);
    std::vector<float> c(size_t(g.nodeCount()));
    for (auto& x : c) x = std::array<float, 3>{0.25f, 0.5f, 1.f}[rng() % 3];
    std::vector<float> flat(c.size(), 1.f);
    for (const auto* costs : {&c, &flat}) {
      const std::vector<int64_t> sources{g.nodeCount() / 3};
      ShortestPathSearch ref(g, GridCost::nodes(*costs), sources, withThreads(1));
      ref.runToCompletion();
      for (int rep = 0; rep < 5; ++rep) {
        ShortestPathSearch par(g, GridCost::nodes(*costs), sources, withThreads(2));
        par.runToCompletion();
        expectSameMap(par, ref, g, *costs, true);
      }
    }
  }
}

// Automatic mode: small grids and A* stay sequential, and the result never depends on it.
TEST(ParallelSearch, AutomaticModeGivesTheSameMap) {
  GridGraph g({64, 64, 64}, {1, 1, 1}, 26);
  const std::vector<float> c = randomCosts(g, 13);
  SearchOptions automatic;  // threads = 0, parallelMinNodes = 2^20 > 262144: sequential
  SearchOptions forced = withThreads(2);
  forced.parallelMinNodes = 1 << 18;
  ShortestPathSearch a(g, GridCost::nodes(c), {g.node(32, 32, 1)}, automatic);
  ShortestPathSearch b(g, GridCost::nodes(c), {g.node(32, 32, 1)}, forced);
  a.runToCompletion();
  b.runToCompletion();
  expectSameMap(b, a, g, c);
}

}  // namespace
}  // namespace vs
