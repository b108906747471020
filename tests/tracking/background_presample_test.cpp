// BackgroundPresample (auto_cost_blocks.cpp: the local background's blocks away from the root's structure, sampled
// while the connect flood runs): the local background found with it equals the one found without it, block for block
// (values, spreads, the former background, the wide lumen's levels, the differs flags), on random volumes of both
// polarities with and without the upper edge's shell and a structure with a deep part; a presample whose window the
// flood cut does not match and is not used; an exception from the flood's side is passed on with the helper joined.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "phantom/phantom.h"
#include "tracking/auto_cost.h"
#include "util/parallel.h"

namespace vs {
namespace {

void expectSameFloats(const std::vector<float>& got, const std::vector<float>& want, const char* what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (size_t i = 0; i < got.size(); ++i) {
    if (std::isnan(want[i])) {
      EXPECT_TRUE(std::isnan(got[i])) << what << " #" << i;
      continue;
    }
    EXPECT_EQ(got[i], want[i]) << what << " #" << i;
  }
}

void expectSameGrids(const std::vector<BlockGrid>& got, const std::vector<BlockGrid>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t k = 0; k < got.size(); ++k) {
    expectSameFloats(got[k].value, want[k].value, "value");
    expectSameFloats(got[k].spread, want[k].spread, "spread");
    expectSameFloats(got[k].lumenLevel, want[k].lumenLevel, "lumen level");
    EXPECT_EQ(got[k].differs, want[k].differs);
  }
}

TEST(BackgroundPresample, GivesTheBackgroundFoundWithoutIt) {
  Geometry g;
  g.dims = {41, 29, 23};
  g.spacing = Vec3(0.7, 0.8, 1.1);
  const int64_t n = g.voxelCount();
  int checked = 0;
  for (const bool bright : {true, false})
    for (const bool withUpper : {false, true})
      for (const bool withStructure : {false, true}) {
        PhantomRng rng(31 + static_cast<uint64_t>(checked));
        VolumeF32 v(g);
        for (int64_t i = 0; i < n; ++i) {
          const double u = rng.uniform(0, 1);
          const double val = u < 0.6 ? rng.uniform(0, 120) : u < 0.9 ? rng.uniform(150, 300) : rng.uniform(400, 900);
          v.data()[i] = static_cast<float>(bright ? val : 1000 - val);
        }
        LumenEstimate e;
        e.polarity = bright ? TubePolarity::Bright : TubePolarity::Dark;
        e.lumen = bright ? 200 : 800;
        e.windowLo = bright ? 140 : 700;
        e.windowHi = bright ? 300 : 860;
        e.upperFraction = withUpper ? 1 : 0;
        e.upperLo = bright ? 330 : 670;
        e.upperHi = bright ? 380 : 620;
        const std::vector<uint8_t> shell = withUpper ? upperShell(v, e) : std::vector<uint8_t>();
        const std::vector<uint8_t>* up = withUpper ? &shell : nullptr;
        // A structure: a slab with its wall (1), inside (2) and a deep core (3), and a wide-lumen zone around it.
        RootStructure s;
        if (withStructure) {
          s.mask.assign(static_cast<size_t>(n), 0);
          s.wideZone.assign(static_cast<size_t>(n), 0);
          for (int64_t z = 0; z < g.dims[2]; ++z)
            for (int64_t y = 0; y < g.dims[1]; ++y)
              for (int64_t x = 0; x < g.dims[0]; ++x) {
                const int64_t i = g.linear(x, y, z), d = std::abs(x - 12);
                const uint8_t m = d <= 2 ? 3 : d <= 5 ? 2 : d == 6 ? 1 : 0;
                s.mask[static_cast<size_t>(i)] = m;
                if (m == 3) s.deep.push_back(i);
                s.wideZone[static_cast<size_t>(i)] = d <= 6 ? 2 : d <= 9 ? 1 : 0;
              }
        }
        auto background = [&](const BackgroundPresample* pre) {
          RootStructure copy = s;
          return estimateLocalBackground(v, e, 4.0, 25, 2, withStructure ? &copy : nullptr, up, pre);
        };
        BackgroundPresample pre(v, e, 4.0, 25, 2, up);
        const int ran = pre.whileRunning([] { return 7; });
        EXPECT_EQ(ran, 7);
        pre.finish();
        ASSERT_TRUE(pre.matches(e, 4.0, 25, 2, up));
        const LocalBackground with = background(&pre), without = background(nullptr);
        expectSameGrids(with.scales, without.scales);
        expectSameGrids(with.structureScales, without.structureScales);
        EXPECT_EQ(with.structure, without.structure);
        EXPECT_EQ(withStructure, !without.structureScales.empty());
        // The flood cut the window: the blocks sampled with the old one do not match, and are not used.
        LumenEstimate cut = e;
        (bright ? cut.windowLo : cut.windowHi) = bright ? 170 : 830;
        EXPECT_FALSE(pre.matches(cut, 4.0, 25, 2, up));
        EXPECT_FALSE(pre.matches(e, 4.0, 25, 3, up));
        RootStructure c1 = s, c2 = s;
        const LocalBackground a = estimateLocalBackground(v, cut, 4.0, 25, 2, withStructure ? &c1 : nullptr, up, &pre);
        const LocalBackground b = estimateLocalBackground(v, cut, 4.0, 25, 2, withStructure ? &c2 : nullptr, up);
        expectSameGrids(a.scales, b.scales);
        ++checked;
      }
  EXPECT_EQ(checked, 8);
}

TEST(BackgroundPresample, PassesOnTheFloodsExceptionAndIsNotUsedUnfinished) {
  Geometry g;
  g.dims = {20, 20, 20};
  VolumeF32 v(g);
  LumenEstimate e;
  e.lumen = 200;
  e.windowLo = 140;
  e.windowHi = 200;
  BackgroundPresample pre(v, e, 4.0, 25, 1, nullptr);
  EXPECT_FALSE(pre.matches(e, 4.0, 25, 1, nullptr));  // nothing sampled yet
  EXPECT_THROW(pre.whileRunning([]() -> int { throw std::runtime_error("flood"); }), std::runtime_error);
}

// Session 48 speed5: every worker but the flood's samples blocks (before: one helper). The blocks are the same bit for
// bit whatever the number of threads claiming them: one (no helper), two (the code before's one helper) and eight.
TEST(BackgroundPresample, AnyNumberOfHelpersGivesTheSameBlocks) {
  Geometry g;
  g.dims = {37, 31, 19};
  g.spacing = Vec3(0.6, 0.7, 1.3);
  VolumeF32 v(g);
  PhantomRng rng(4807);
  for (int64_t i = 0; i < g.voxelCount(); ++i) {
    const double u = rng.uniform(0, 1);
    v.data()[i] = static_cast<float>(u < 0.7 ? rng.uniform(0, 120) : rng.uniform(150, 400));
  }
  LumenEstimate e;
  e.lumen = 200;
  e.windowLo = 140;
  e.windowHi = 300;
  e.localTailCap = 5;
  e.spread = 6;
  const char* before = std::getenv("VS_THREADS");
  const std::string saved = before ? before : "";
  std::vector<std::vector<std::vector<PlainBlock>>> runs;
  for (const char* threads : {"1", "2", "8"}) {
    setenv("VS_THREADS", threads, 1);
    ASSERT_EQ(workerCount(), std::atoi(threads));
    BackgroundPresample pre(v, e, 3.0, 25, 2, nullptr);
    EXPECT_EQ(pre.whileRunning([] { return 3; }), 3);
    pre.finish();
    EXPECT_TRUE(pre.matches(e, 3.0, 25, 2, nullptr));
    runs.push_back(pre.blocks);
  }
  if (before)
    setenv("VS_THREADS", saved.c_str(), 1);
  else
    unsetenv("VS_THREADS");
  const auto bits = [](float f) { return std::bit_cast<uint32_t>(f); };
  size_t blocks = 0;
  for (size_t r = 1; r < runs.size(); ++r) {
    ASSERT_EQ(runs[r].size(), runs[0].size());
    for (size_t k = 0; k < runs[0].size(); ++k) {
      ASSERT_EQ(runs[r][k].size(), runs[0][k].size());
      for (size_t b = 0; b < runs[0][k].size(); ++b, ++blocks) {
        const PlainBlock &got = runs[r][k][b], &want = runs[0][k][b];
        ASSERT_EQ(bits(got.raw), bits(want.raw)) << r << " " << k << " " << b;
        ASSERT_EQ(bits(got.uncapped), bits(want.uncapped)) << r << " " << k << " " << b;
        ASSERT_EQ(bits(got.spread), bits(want.spread)) << r << " " << k << " " << b;
      }
    }
  }
  EXPECT_GT(blocks, 1000u);
}

}  // namespace
}  // namespace vs
