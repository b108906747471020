// util/bucket_distances.h: the same distances, bit for bit, as a Dijkstra with a binary heap.
#include "util/bucket_distances.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <queue>
#include <random>

namespace vs {
namespace {

struct Graph {
  std::vector<std::vector<std::pair<int32_t, double>>> adj;
  double minStep = 0, maxStep = 0;
};

std::vector<double> heapDijkstra(const Graph& gr, const std::vector<std::pair<int32_t, double>>& sources) {
  std::vector<double> dist(gr.adj.size(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> h;
  for (const auto& [s, d0] : sources)
    if (d0 < dist[static_cast<size_t>(s)]) dist[static_cast<size_t>(s)] = d0, h.push({d0, s});
  std::vector<uint8_t> done(gr.adj.size(), 0);
  while (!h.empty()) {
    const auto [d, u] = h.top();
    h.pop();
    if (done[static_cast<size_t>(u)]) continue;
    done[static_cast<size_t>(u)] = 1;
    for (const auto& [v, mm] : gr.adj[static_cast<size_t>(u)])
      if (const double nd = d + mm; nd < dist[static_cast<size_t>(v)])
        dist[static_cast<size_t>(v)] = nd, h.push({nd, v});
  }
  return dist;
}

std::vector<double> buckets(const Graph& gr, const std::vector<std::pair<int32_t, double>>& sources, size_t* pushes) {
  size_t n = 0;
  auto d = bucketDistances(
      gr.adj.size(), sources, gr.minStep, gr.maxStep,
      [&](int32_t u, auto&& relax) {
        for (const auto& [v, mm] : gr.adj[static_cast<size_t>(u)]) relax(v, mm);
      },
      [&](int32_t) { ++n; });
  if (pushes) *pushes = n;
  return d;
}

void expectBitIdentical(const std::vector<double>& a, const std::vector<double>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size());
  size_t differ = 0, reached = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    differ += std::memcmp(&a[i], &b[i], sizeof(double)) != 0;
    reached += std::isfinite(a[i]);
  }
  EXPECT_EQ(differ, 0u) << what;
  EXPECT_GT(reached, a.size() / 4) << what;
}

// A voxel grid (26 neighbours, anisotropic spacing) restricted to a random blobby mask: the terminal scan's
// geodesic distances, full of exact ties (sums of a few step lengths in different orders).
Graph grid(uint32_t seed, int nx, int ny, int nz, double sx, double sy, double sz, double fill) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  std::vector<uint8_t> in(static_cast<size_t>(nx) * ny * nz);
  for (auto& v : in) v = u01(rng) < fill;
  auto at = [&](int x, int y, int z) { return (static_cast<size_t>(z) * ny + y) * nx + x; };
  Graph gr;
  gr.adj.resize(in.size());
  gr.minStep = std::min({sx, sy, sz});
  gr.maxStep = std::sqrt(sx * sx + sy * sy + sz * sz);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        if (!in[at(x, y, z)]) continue;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int X = x + dx, Y = y + dy, Z = z + dz;
              if ((dx | dy | dz) == 0 || X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz || !in[at(X, Y, Z)])
                continue;
              const double mm = std::sqrt(dx * dx * sx * sx + dy * dy * sy * sy + dz * dz * sz * sz);
              gr.adj[at(x, y, z)].push_back({static_cast<int32_t>(at(X, Y, Z)), mm});
            }
      }
  return gr;
}

TEST(BucketDistances, EqualAHeapDijkstraBitForBitOnAnisotropicGrids) {
  const double spacings[][3] = {{0.55, 0.55, 1.0}, {1.5, 1.5, 1.5}, {0.7, 0.9, 2.6}, {1.0 / 3.0, 0.5, 0.45}};
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    const double* sp = spacings[seed - 1];
    const Graph gr = grid(seed, 24, 20, 14, sp[0], sp[1], sp[2], 0.8);
    std::mt19937 rng(seed * 17);
    // One source at 0 (the fronts' root), many at one start > 0 (the depth's boundary at half a spacing).
    std::vector<std::pair<int32_t, double>> one{{static_cast<int32_t>(rng() % gr.adj.size()), 0.0}};
    std::vector<std::pair<int32_t, double>> many;
    for (int i = 0; i < 300; ++i) many.push_back({static_cast<int32_t>(rng() % gr.adj.size()), 0.5 * sp[0]});
    size_t pushes = 0;
    expectBitIdentical(buckets(gr, one, &pushes), heapDijkstra(gr, one), "one source");
    EXPECT_GT(pushes, gr.adj.size() / 4);
    expectBitIdentical(buckets(gr, many, nullptr), heapDijkstra(gr, many), "many sources");
  }
}

TEST(BucketDistances, EqualAHeapDijkstraWithRandomLengthsAndStartsFarApart) {
  // Random graph, edge lengths anywhere in [0.3, 2.9]; sources with different starts, some far beyond the
  // ring of buckets (entering later), one listed twice, the second time lower.
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> len(0.3, 2.9);
  Graph gr;
  gr.adj.resize(3000);
  gr.minStep = 0.3, gr.maxStep = 2.9;
  for (int32_t u = 0; u < 3000; ++u)
    for (int k = 0; k < 4; ++k) {
      const auto v = static_cast<int32_t>(rng() % 3000);
      const double mm = len(rng);
      gr.adj[static_cast<size_t>(u)].push_back({v, mm});
      gr.adj[static_cast<size_t>(v)].push_back({u, mm});
    }
  const std::vector<std::pair<int32_t, double>> sources{{5, 0.0},    {17, 3.25},    {900, 40.0},
                                                        {901, 41.5}, {2500, 120.0}, {17, 1.0}};
  expectBitIdentical(buckets(gr, sources, nullptr), heapDijkstra(gr, sources), "random graph");
  // A node no edge reaches stays at infinity.
  gr.adj.push_back({});
  const auto d = buckets(gr, {{5, 0.0}}, nullptr);
  EXPECT_TRUE(std::isinf(d.back()));
  EXPECT_EQ(d[5], 0.0);
}

}  // namespace
}  // namespace vs
