// The ray caster's block walk (render/block_walk.h) against brute force: random rays through a
// block grid, every span in ray order, spans partition [tA, tB] exactly, every fine sample of
// the ray lies in the block of the span that covers it, and skipped blocks are exactly the
// ones whose on[] byte is 0.
#include "render/block_walk.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace vs {
namespace {

struct Span {
  size_t bi;
  int b[3];
  double tIn, tOut;
};

struct TestRay {
  double o[3], d[3], inv[3];
  double tA, tB;
};

const BlockGridShape kGrid{2, 5, 4, 3};  // 4-cell blocks, 20 x 16 x 12 cells

std::vector<Span> walk(const TestRay& r, const std::vector<uint8_t>& on) {
  std::vector<Span> out;
  walkBlocks(kGrid, r.o, r.d, r.inv, r.tA, r.tB, on.data(), [&](size_t bi, int bx, int by, int bz, double a, double b) {
    out.push_back({bi, {bx, by, bz}, a, b});
    return true;
  });
  return out;
}

// Random rays from outside the grid through a random inside point, some along the axes;
// clipped to the grid as the ray caster clips to the volume.
std::vector<TestRay> randomRays(int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  const double ext[3] = {20, 16, 12};
  std::vector<TestRay> rays;
  while (int(rays.size()) < count) {
    TestRay r{};
    double target[3], len = 0;
    for (int a = 0; a < 3; ++a) {
      target[a] = u(rng) * ext[a];
      r.o[a] = -10 + u(rng) * (ext[a] + 20);
      r.d[a] = target[a] - r.o[a];
    }
    if (rays.size() % 5 == 0) r.d[rays.size() % 3] = 0, r.o[rays.size() % 3] = target[rays.size() % 3];
    for (double x : r.d) len += x * x;
    for (double& x : r.d) x /= std::sqrt(len);
    for (int a = 0; a < 3; ++a) r.inv[a] = std::abs(r.d[a]) > 1e-15 ? 1.0 / r.d[a] : 0.0;
    const double lo[3] = {0, 0, 0}, hi[3] = {ext[0] - 1e-3, ext[1] - 1e-3, ext[2] - 1e-3};
    if (!intersectBox(r.o, r.d, lo, hi, r.tA, r.tB) || r.tB - r.tA < 1e-3) continue;
    rays.push_back(r);
  }
  return rays;
}

TEST(BlockWalk, SpansPartitionTheRayAndContainItsSamples) {
  const std::vector<uint8_t> all(size_t(kGrid.bx) * kGrid.by * kGrid.bz, 1);
  for (const TestRay& r : randomRays(300)) {
    const std::vector<Span> spans = walk(r, all);
    ASSERT_FALSE(spans.empty());
    EXPECT_EQ(spans.front().tIn, r.tA);
    EXPECT_EQ(spans.back().tOut, r.tB);
    for (size_t i = 0; i < spans.size(); ++i) {
      const Span& s = spans[i];
      EXPECT_LE(s.tIn, s.tOut);
      if (i > 0) {
        EXPECT_EQ(s.tIn, spans[i - 1].tOut);
      }
      EXPECT_EQ(s.bi, size_t(s.b[0] + kGrid.bx * (s.b[1] + kGrid.by * s.b[2])));
      const int nb[3] = {kGrid.bx, kGrid.by, kGrid.bz};
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(s.b[a], 0);
        EXPECT_LT(s.b[a], nb[a]);
      }
    }
    // Brute force: fine samples away from block faces lie in the block of their span.
    const int n = 2000;
    size_t j = 0;
    for (int k = 0; k <= n; ++k) {
      const double t = r.tA + (r.tB - r.tA) * k / n;
      while (j + 1 < spans.size() && spans[j].tOut < t) ++j;
      bool nearFace = false;
      int b[3];
      for (int a = 0; a < 3; ++a) {
        const double p = (r.o[a] + r.d[a] * t) / 4;
        nearFace = nearFace || std::abs(p - std::round(p)) < 1e-6;
        b[a] = int(std::floor(p));
      }
      if (nearFace) continue;
      ASSERT_LE(spans[j].tIn, t + 1e-9);
      EXPECT_EQ(spans[j].b[0], b[0]);
      EXPECT_EQ(spans[j].b[1], b[1]);
      EXPECT_EQ(spans[j].b[2], b[2]);
    }
  }
}

TEST(BlockWalk, SkipsExactlyTheBlocksThatAreOff) {
  std::mt19937 rng(11);
  const size_t nb = size_t(kGrid.bx) * kGrid.by * kGrid.bz;
  const std::vector<uint8_t> all(nb, 1);
  std::vector<uint8_t> some(nb);
  for (auto& x : some) x = uint8_t(rng() % 3 == 0);
  for (const TestRay& r : randomRays(200)) {
    std::vector<Span> want;
    for (const Span& s : walk(r, all))
      if (some[s.bi] && s.tOut > s.tIn) want.push_back(s);
    std::vector<Span> got;
    for (const Span& s : walk(r, some))
      if (s.tOut > s.tIn) got.push_back(s);
    ASSERT_EQ(got.size(), want.size());
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].bi, want[i].bi);
      EXPECT_EQ(got[i].tIn, want[i].tIn);
      EXPECT_EQ(got[i].tOut, want[i].tOut);
    }
  }
}

TEST(BlockWalk, StopsWhenVisitReturnsFalse) {
  const std::vector<uint8_t> all(size_t(kGrid.bx) * kGrid.by * kGrid.bz, 1);
  TestRay r{{-5, 1.5, 1.5}, {1, 0, 0}, {1, 0, 0}, 0, 0};
  const double lo[3] = {0, 0, 0}, hi[3] = {19.999, 15.999, 11.999};
  ASSERT_TRUE(intersectBox(r.o, r.d, lo, hi, r.tA, r.tB));
  EXPECT_EQ(walk(r, all).size(), 5u);  // along x through the 5 blocks of the first row
  int visited = 0;
  walkBlocks(kGrid, r.o, r.d, r.inv, r.tA, r.tB, all.data(),
             [&](size_t, int, int, int, double, double) { return ++visited < 2; });
  EXPECT_EQ(visited, 2);
}

TEST(BlockWalk, IntersectBoxMissesAndHits) {
  const double lo[3] = {0, 0, 0}, hi[3] = {10, 10, 10};
  double t0, t1;
  const double o[3] = {-5, 5, 5}, d[3] = {1, 0, 0};
  ASSERT_TRUE(intersectBox(o, d, lo, hi, t0, t1));
  EXPECT_DOUBLE_EQ(t0, 5);
  EXPECT_DOUBLE_EQ(t1, 15);
  const double above[3] = {-5, 11, 5};
  EXPECT_FALSE(intersectBox(above, d, lo, hi, t0, t1));
}

}  // namespace
}  // namespace vs
