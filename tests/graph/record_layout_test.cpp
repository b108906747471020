// The bricked record layout of 3-D grid searches (graph/record_layout.h): the node -> record
// map is one to one, matches the brick formula, and the per-axis steps reach every neighbour's
// record, on dims that are and are not multiples of the brick edge.
#include "graph/record_layout.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>
#include <set>

#include "graph/grid_graph.h"

namespace vs::engine {
namespace {

TEST(RecordLayout, FastDivIsExact) {
  std::mt19937 rng(7);
  const uint64_t divisors[] = {1,    2,     3,     7,     8,        100,      255,        256,
                               4097, 65535, 65536, 65537, 16777216, 1u << 31, 0xffffffffu};
  for (uint64_t d : divisors) {
    const FastDiv f(d);
    const uint32_t edge[] = {0, uint32_t(d - 1), uint32_t(d), uint32_t(d + 1), 0x7fffffffu, 0xfffffffeu, 0xffffffffu};
    for (uint32_t v : edge) EXPECT_EQ(f.div(v), uint32_t(v / d)) << v << " / " << d;
    for (int i = 0; i < 20000; ++i) {
      const uint32_t v = uint32_t(rng());
      ASSERT_EQ(f.div(v), uint32_t(v / d)) << v << " / " << d;
    }
  }
}

TEST(RecordLayout, BricksMapEveryNodeOnceAndStepsReachTheNeighbours) {
  const std::array<int64_t, 3> dims[] = {{9, 5, 11}, {1, 1, 20}, {16, 8, 8}, {3, 17, 2}, {8, 9, 17}};
  for (const auto& d : dims) {
    const BrickLayout L(d[0], d[1], d[2]);
    std::set<int64_t> seen;
    for (int64_t z = 0; z < d[2]; ++z)
      for (int64_t y = 0; y < d[1]; ++y)
        for (int64_t x = 0; x < d[0]; ++x) {
          const int64_t r = L.at(x, y, z);
          const uint32_t v = uint32_t(x + d[0] * (y + d[1] * z));
          ASSERT_EQ(L.of(v), r);
          ASSERT_EQ(L.zOf(v), uint32_t(z));
          ASSERT_GE(r, 0);
          ASSERT_LT(r, L.recordCount());
          ASSERT_TRUE(seen.insert(r).second);
          const BrickLayout::Steps s = L.steps(r);
          for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                const int64_t X = x + dx, Y = y + dy, Z = z + dz;
                if (X < 0 || Y < 0 || Z < 0 || X >= d[0] || Y >= d[1] || Z >= d[2]) continue;
                ASSERT_EQ(r + s.x[dx + 1] + s.y[dy + 1] + s.z[dz + 1], L.at(X, Y, Z));
              }
        }
  }
}

template <int K>
void expectGridOrder(std::array<int64_t, 3> dims) {
  const GridGraph g(dims, {1, 1, 1}, K);
  constexpr Directions<K> d{};
  ASSERT_EQ(g.directionCount(), K);
  for (int k = 0; k < K; ++k) {
    EXPECT_EQ(d.d[k].x, g.offset(k)[0]) << K << " " << k;
    EXPECT_EQ(d.d[k].y, g.offset(k)[1]) << K << " " << k;
    EXPECT_EQ(d.d[k].z, g.offset(k)[2]) << K << " " << k;
  }
}

TEST(RecordLayout, DirectionsFollowTheGridOrder) {
  expectGridOrder<4>({4, 4, 1});
  expectGridOrder<8>({4, 4, 1});
  expectGridOrder<6>({4, 4, 4});
  expectGridOrder<18>({4, 4, 4});
  expectGridOrder<26>({4, 4, 4});
}

}  // namespace
}  // namespace vs::engine
