// Session 46 speed: the local background's tail cap searches its quartile and tail beside the block's percentile
// (already in place) instead of over the whole block - every capped value must be the one the code before gave, bit
// for bit (the reference copy below is that code as it was).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {
namespace {

float percentileBefore(std::vector<float>& vals, size_t sampled, double p) {
  if (vals.empty() || vals.size() < std::min<size_t>(8, (sampled + 1) / 2))
    return std::numeric_limits<float>::quiet_NaN();
  const auto k = static_cast<std::ptrdiff_t>(std::lround(p / 100.0 * static_cast<double>(vals.size() - 1)));
  std::nth_element(vals.begin(), vals.begin() + k, vals.end());
  return vals[static_cast<size_t>(k)];
}

void capBefore(std::vector<float>& vals, size_t sampled, double p, double percentile, bool bright, double floorWidth,
               double k, float& r) {
  if (std::isnan(r) || vals.size() < 8) return;
  const float q = percentileBefore(vals, sampled, 100.0 - p);
  const float tail = percentileBefore(vals, sampled, bright ? percentile / 5 : 100.0 - percentile / 5);
  if (std::isnan(q) || std::isnan(tail)) return;
  const double width = std::max(k * std::abs(double(q) - double(tail)), floorWidth);
  const float cap = static_cast<float>(bright ? q + width : q - width);
  if (bright ? r > cap : r < cap) r = cap;
}

// A block of n values: a Gaussian background (100 +- 10), a random share of them a lumen's tail `shift` beyond it on
// the lumen's side, quantised to steps of 7 (ties) where asked.
std::vector<float> randomBlock(std::mt19937_64& rng, size_t n, bool bright, bool quantised, double shift) {
  const double lumenShare = std::uniform_real_distribution<double>(0, 0.6)(rng);
  std::normal_distribution<double> noise(100, 10);
  std::vector<float> vals(n);
  for (float& v : vals) {
    double x = noise(rng);
    if (std::uniform_real_distribution<double>(0, 1)(rng) < lumenShare) x += bright ? shift : -shift;
    v = static_cast<float>(quantised ? std::round(x / 7) * 7 : x);
  }
  return vals;
}

// blockPercentile and the tail cap on `vals` against the code before's on `before` (rBefore: its percentile, already
// taken; capped in place), bit for bit. Returns the new code's raw (uncapped) and capped values.
std::pair<float, float> capSameAsBefore(std::vector<float>& vals, std::vector<float>& before, size_t sampled, double p,
                                        double percentile, bool bright, double floorWidth, double k, float& rBefore,
                                        int trial) {
  float r = blockPercentile(vals, sampled, p);
  EXPECT_EQ(std::bit_cast<uint32_t>(r), std::bit_cast<uint32_t>(rBefore)) << "trial " << trial;
  const float raw = r;
  capBefore(before, sampled, p, percentile, bright, floorWidth, k, rBefore);
  capAtBackgroundTail(vals, p, percentile, bright, floorWidth, k, r);
  EXPECT_EQ(std::bit_cast<uint32_t>(r), std::bit_cast<uint32_t>(rBefore)) << "trial " << trial;
  return {raw, r};
}

TEST(BlockPercentile, TailCapEqualsTheCodeBefore) {
  std::mt19937_64 rng(46);
  int capped = 0, cases = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    // Blocks of 0..600 values: Gaussian background, some with a lumen's tail, some quantised (ties), both polarities.
    const size_t n = std::uniform_int_distribution<size_t>(0, 600)(rng);
    const size_t sampled = n + std::uniform_int_distribution<size_t>(0, 40)(rng);
    const bool bright = trial % 2 == 0, quantised = trial % 3 == 0;
    std::vector<float> vals = randomBlock(rng, n, bright, quantised, 80);
    const double percentile = std::uniform_int_distribution<int>(0, 100)(rng);
    const double p = bright ? 100.0 - percentile : percentile;
    const double floorWidth = std::uniform_real_distribution<double>(0, 20)(rng);
    const double k = std::uniform_real_distribution<double>(0, 6)(rng);
    std::vector<float> before = vals;
    float rBefore = percentileBefore(before, sampled, p);
    const auto [raw, r] = capSameAsBefore(vals, before, sampled, p, percentile, bright, floorWidth, k, rBefore, trial);
    if (::testing::Test::HasFailure()) return;
    cases += !std::isnan(raw);
    capped += !std::isnan(raw) && r != raw;
  }
  EXPECT_GT(cases, 15000);
  EXPECT_GT(capped, 500);  // the cap itself exercised, not only the uncapped path
}

// Session 48 speed4: the cap skips q's and the tail's selections where r lies within floorWidth of the background
// side's extreme value (or of q). The floor drawn at and around those distances (a float's step either side, exactly
// on them) puts r on both sides of the skip's bound: the capped value must still be the code before's, bit for bit.
TEST(BlockPercentile, TailCapSkipAtItsBoundEqualsTheCodeBefore) {
  std::mt19937_64 rng(48);
  int capped = 0, cases = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const size_t n = std::uniform_int_distribution<size_t>(8, 300)(rng);
    const bool bright = trial % 2 == 0, quantised = trial % 3 == 0;
    std::vector<float> vals = randomBlock(rng, n, bright, quantised, 40);
    const double percentile = std::uniform_int_distribution<int>(1, 60)(rng);
    const double p = bright ? 100.0 - percentile : percentile;
    const double k = std::uniform_real_distribution<double>(0, 6)(rng);
    std::vector<float> before = vals;
    float rBefore = percentileBefore(before, n, p);
    // The distances the skip reads: to the extreme on the background's side and to q.
    std::vector<float> sorted = vals;
    std::sort(sorted.begin(), sorted.end());
    const float extreme = bright ? sorted.front() : sorted.back();
    const float q = sorted[static_cast<size_t>(std::lround((100.0 - p) / 100.0 * static_cast<double>(n - 1)))];
    const double to = std::abs(double(rBefore) - double(trial % 4 < 2 ? extreme : q));
    const double nudge[5] = {0, 1e-7, -1e-7, 1e-4, -1e-4};
    const double floorWidth = std::max(0.0, to * (1 + nudge[trial % 5]));
    const auto [raw, r] = capSameAsBefore(vals, before, n, p, percentile, bright, floorWidth, k, rBefore, trial);
    if (::testing::Test::HasFailure()) return;
    ++cases;
    capped += r != raw;
  }
  EXPECT_EQ(cases, 20000);
  EXPECT_GT(capped, 500);  // both sides of the bound: capped blocks too
}

}  // namespace
}  // namespace vs
