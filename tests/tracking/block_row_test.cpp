// Session 47 speed3: LocalBackground::row clamps each scale's interpolated row by the own block and folds the scales
// in one pass per scale (rowWithSpread: with the first scale's spread) - every value must be the one the code before
// gave (the passes below: row(), the own block's clamp, the fold over the scales; the spread's row()), bit for bit,
// both polarities, ties and both zeros included.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {
namespace {

std::vector<double> backgroundRowBefore(const LocalBackground& bg, int64_t y, int64_t z, size_t nx) {
  const bool bright = bg.polarity == TubePolarity::Bright;
  std::vector<double> out(nx), r(nx);
  for (size_t k = 0; k < bg.scales.size(); ++k) {
    const BlockGrid& s = bg.scales[k];
    s.row(s.value, y, z, r);
    for (size_t x = 0; x < nx; ++x) {
      const double b = s.own(s.value, static_cast<int64_t>(x), y, z);
      r[x] = bright ? std::max(r[x], b) : std::min(r[x], b);
    }
    for (size_t x = 0; x < nx; ++x) out[x] = k == 0 ? r[x] : bright ? std::min(out[x], r[x]) : std::max(out[x], r[x]);
  }
  return out;
}

TEST(BlockRows, BackgroundRowEqualsTheCodeBefore) {
  std::mt19937_64 rng(4731);
  const int64_t dims[][3] = {{1, 1, 1}, {17, 9, 5}, {40, 3, 22}, {7, 31, 13}};
  int64_t voxels = 0;
  for (int round = 0; round < 6; ++round)
    for (const auto& d : dims)
      for (const bool bright : {true, false})
        for (const bool prepared : {true, false}) {
          Geometry g;
          g.dims = {d[0], d[1], d[2]};
          g.spacing = {0.7 + 0.1 * round, 0.9, 1.3};
          LocalBackground bg;
          bg.polarity = bright ? TubePolarity::Bright : TubePolarity::Dark;
          const bool coarse = round % 2 == 0;  // few distinct values: ties, and -0 against +0
          for (const double mm : {6.0, 3.0, 1.5}) {
            BlockGrid s = blockGrid(g, mm);
            s.value.resize(static_cast<size_t>(s.blocks[0] * s.blocks[1] * s.blocks[2]));
            s.spread.resize(s.value.size());
            for (size_t i = 0; i < s.value.size(); ++i) {
              s.spread[i] = static_cast<float>(std::uniform_real_distribution<double>(0, 40)(rng));
              const double u = std::uniform_real_distribution<double>(-1, 1)(rng);
              s.value[i] = coarse ? static_cast<float>(std::lround(2 * u)) : static_cast<float>(500 * u);
              if (coarse && std::lround(4 * u) == 0) s.value[i] = (i % 2) ? -0.0f : 0.0f;
            }
            if (prepared) s.prepareRows(g.dims[0]);
            bg.scales.push_back(std::move(s));
          }
          const size_t nx = static_cast<size_t>(g.dims[0]);
          std::vector<double> got(nx), withSpread(nx), spread(nx), spreadBefore(nx);
          for (int64_t z = 0; z < g.dims[2]; ++z)
            for (int64_t y = 0; y < g.dims[1]; ++y) {
              bg.row(y, z, got);
              const std::vector<double> want = backgroundRowBefore(bg, y, z, nx);
              bg.rowWithSpread(y, z, withSpread, spread);
              bg.scales.front().row(bg.scales.front().spread, y, z, spreadBefore);
              for (size_t x = 0; x < nx; ++x) {
                ASSERT_EQ(std::bit_cast<uint64_t>(withSpread[x]), std::bit_cast<uint64_t>(want[x])) << x;
                ASSERT_EQ(std::bit_cast<uint64_t>(spread[x]), std::bit_cast<uint64_t>(spreadBefore[x])) << x;
              }
              for (size_t x = 0; x < nx; ++x)
                ASSERT_EQ(std::bit_cast<uint64_t>(got[x]), std::bit_cast<uint64_t>(want[x]))
                    << x << " " << y << " " << z;
              voxels += static_cast<int64_t>(nx);
            }
        }
  EXPECT_GT(voxels, 50000);
}

}  // namespace
}  // namespace vs
