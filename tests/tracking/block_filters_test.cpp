// Session 47 speed2: neighbourFilter runs on threads over the block layers and reads its 27 neighbours into a fixed
// array - every block's value and spread must be the one the code before gave, bit for bit (the reference copy below
// is that code as it was), ties and both zeros included.
#include "tracking/block_filters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

namespace vs {
namespace {

void neighbourFilterBefore(BlockGrid& bg, const std::vector<float>& raw, const std::vector<float>* rawSpread,
                           bool bright) {
  bg.value.resize(raw.size());
  bg.spread.assign(raw.size(), 0);
  std::vector<float> near, nearSpread;
  for (int64_t k = 0; k < bg.blocks[2]; ++k)
    for (int64_t j = 0; j < bg.blocks[1]; ++j)
      for (int64_t i = 0; i < bg.blocks[0]; ++i) {
        near.clear();
        nearSpread.clear();
        for (int64_t c = std::max<int64_t>(0, k - 1); c <= std::min(bg.blocks[2] - 1, k + 1); ++c)
          for (int64_t b = std::max<int64_t>(0, j - 1); b <= std::min(bg.blocks[1] - 1, j + 1); ++b)
            for (int64_t a = std::max<int64_t>(0, i - 1); a <= std::min(bg.blocks[0] - 1, i + 1); ++a) {
              const size_t n = static_cast<size_t>((c * bg.blocks[1] + b) * bg.blocks[0] + a);
              near.push_back(raw[n]);
              if (rawSpread && (*rawSpread)[n] >= 0) nearSpread.push_back((*rawSpread)[n]);
            }
        const size_t at = static_cast<size_t>((k * bg.blocks[1] + j) * bg.blocks[0] + i);
        bg.value[at] =
            bright ? *std::max_element(near.begin(), near.end()) : *std::min_element(near.begin(), near.end());
        if (!nearSpread.empty()) {
          const auto m = nearSpread.begin() + static_cast<std::ptrdiff_t>(nearSpread.size() / 2);
          std::nth_element(nearSpread.begin(), m, nearSpread.end());
          bg.spread[at] = *m;
        }
      }
}

TEST(BlockFilters, NeighbourFilterEqualsTheCodeBefore) {
  std::mt19937_64 rng(4721);
  const int64_t sizes[][3] = {{1, 1, 1}, {5, 4, 3}, {1, 7, 9}, {13, 11, 17}, {2, 2, 40}, {30, 1, 2}};
  int64_t blocks = 0;
  for (int round = 0; round < 40; ++round)
    for (const auto& n : sizes)
      for (const bool bright : {true, false}) {
        BlockGrid grid;
        for (int a = 0; a < 3; ++a) grid.blocks[a] = n[a];
        const size_t count = static_cast<size_t>(n[0] * n[1] * n[2]);
        std::vector<float> raw(count), spread(count);
        const bool coarse = round % 3 == 0;  // few distinct values: ties, and -0 against +0
        for (size_t i = 0; i < count; ++i) {
          const double u = std::uniform_real_distribution<double>(-1, 1)(rng);
          raw[i] = coarse ? static_cast<float>(std::lround(2 * u)) : static_cast<float>(500 * u);
          if (coarse && std::lround(4 * u) == 0) raw[i] = (i % 2) ? -0.0f : 0.0f;
          const double w = std::uniform_real_distribution<double>(0, 1)(rng);
          spread[i] = w < 0.2 ? -1.0f : coarse ? static_cast<float>(std::lround(3 * w)) : static_cast<float>(40 * w);
        }
        for (const bool withSpread : {true, false}) {
          BlockGrid got = grid, want = grid;
          neighbourFilter(got, raw, withSpread ? &spread : nullptr, bright);
          neighbourFilterBefore(want, raw, withSpread ? &spread : nullptr, bright);
          ASSERT_EQ(got.value.size(), count);
          for (size_t i = 0; i < count; ++i) {
            ASSERT_EQ(std::bit_cast<uint32_t>(got.value[i]), std::bit_cast<uint32_t>(want.value[i])) << i;
            ASSERT_EQ(std::bit_cast<uint32_t>(got.spread[i]), std::bit_cast<uint32_t>(want.spread[i])) << i;
          }
          blocks += static_cast<int64_t>(count);
        }
      }
  EXPECT_GT(blocks, 100000);
}

}  // namespace
}  // namespace vs
