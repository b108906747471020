// sampleBlock (auto_cost_blocks.cpp: the local background's samples of one block, appended branch-free) against
// a plain one-push-per-sample reference on random volumes with NaNs: both polarities, with and without the upper
// edge's shell and the structure's mask, blocks cut by the volume's faces (the last voxel of the volume
// included), steps of 1 to 3.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include "phantom/phantom.h"
#include "tracking/auto_cost.h"

namespace vs {
namespace {

BlockSamples reference(const VolumeF32& vol, const int64_t lo[3], const int64_t bv[3], const int64_t step[3],
                       bool bright, float edge, const uint8_t* up, float hiUp, const uint8_t* bm) {
  const Geometry& g = vol.geometry();
  BlockSamples s;
  auto out = [&](float v) { return bright ? v < edge : v > edge; };
  for (int64_t z = lo[2]; z < std::min(g.dims[2], lo[2] + bv[2]); z += step[2])
    for (int64_t y = lo[1]; y < std::min(g.dims[1], lo[1] + bv[1]); y += step[1])
      for (int64_t x = lo[0]; x < std::min(g.dims[0], lo[0] + bv[0]); x += step[0]) {
        ++s.sampled;
        const int64_t i = g.linear(x, y, z);
        const uint8_t m = bm ? bm[i] : 0;
        s.inStructure += m >= 2;
        if (m == 3) s.deepVals.push_back(vol.data()[i]);
        const float v = vol.data()[i];
        if (!out(v) || (up && (up[i] || (bright ? v > hiUp : v < hiUp)))) continue;
        s.vals.push_back(v);
        if (bm) s.valIn.push_back(m != 0);
        if (x + 1 < g.dims[0] && out(vol.data()[i + 1])) {
          s.diffs.push_back(std::abs(vol.data()[i + 1] - v));
          if (bm) s.diffIn.push_back(m != 0 || bm[i + 1] != 0);
        }
      }
  return s;
}

template <class T>
void expectSame(const std::vector<T>& got, const std::vector<T>& want, const char* what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (size_t k = 0; k < got.size(); ++k) {
    if constexpr (std::is_floating_point_v<T>) {
      if (std::isnan(want[k])) {
        ASSERT_TRUE(std::isnan(got[k])) << what << " #" << k;
        continue;
      }
    }
    ASSERT_EQ(got[k], want[k]) << what << " #" << k;
  }
}

TEST(BlockSamples, EqualAOnePushPerSampleReference) {
  Geometry g;
  g.dims = {13, 9, 7};
  const int64_t n = g.voxelCount();
  PhantomRng rng(21);
  VolumeF32 vol(g);
  std::vector<uint8_t> mask(static_cast<size_t>(n)), shell(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) {
    const double u = rng.uniform(0, 1);
    vol.data()[i] = u < 0.05 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(rng.uniform(0, 300));
    shell[static_cast<size_t>(i)] = rng.uniform(0, 1) < 0.2;
    mask[static_cast<size_t>(i)] = static_cast<uint8_t>(rng.uniform(0, 4));
  }
  BlockSamples got;  // reused across blocks, as blockBackground does
  size_t kept = 0, pairs = 0, deep = 0;
  for (const bool bright : {true, false})
    for (const bool withUp : {false, true})
      for (const bool withMask : {false, true})
        for (int64_t st = 1; st <= 3; ++st) {
          const int64_t bv[3] = {5, 4, 3}, step[3] = {st, st, 1};
          for (int64_t z0 = 0; z0 < g.dims[2]; z0 += bv[2])
            for (int64_t y0 = 0; y0 < g.dims[1]; y0 += bv[1])
              for (int64_t x0 = 0; x0 < g.dims[0]; x0 += bv[0]) {
                const int64_t lo[3] = {x0, y0, z0};
                const uint8_t* up = withUp ? shell.data() : nullptr;
                const uint8_t* bm = withMask ? mask.data() : nullptr;
                sampleBlock(vol, lo, bv, step, bright, 150.0f, up, 200.0f, bm, got);
                const BlockSamples want = reference(vol, lo, bv, step, bright, 150.0f, up, 200.0f, bm);
                EXPECT_EQ(got.sampled, want.sampled);
                EXPECT_EQ(got.inStructure, want.inStructure);
                expectSame(got.vals, want.vals, "vals");
                expectSame(got.diffs, want.diffs, "diffs");
                expectSame(got.valIn, want.valIn, "valIn");
                expectSame(got.diffIn, want.diffIn, "diffIn");
                expectSame(got.deepVals, want.deepVals, "deepVals");
                kept += want.vals.size();
                pairs += want.diffs.size();
                deep += want.deepVals.size();
              }
        }
  EXPECT_GT(kept, 0u);  // every rule was exercised
  EXPECT_GT(pairs, 0u);
  EXPECT_GT(deep, 0u);
}

}  // namespace
}  // namespace vs
