// Session 50 speed7: the local background's block selections by a branchless quickselect instead of std::nth_element -
// the k-th value must be nth_element's float bit for bit, the range left partitioned around k (the tail cap's later
// selections search between those pivots), the values only moved, and samples holding a NaN or a -0 must be told
// apart (there the callers keep nth_element).
#include "tracking/block_select.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {
namespace {

// Noise around a background, with ties (quantised), few distinct values, or one repeated value, by `kind`.
std::vector<float> samples(std::mt19937_64& rng, size_t n, int kind) {
  std::normal_distribution<double> noise(-800, 40);
  std::vector<float> v(n);
  for (float& x : v) {
    const double y = noise(rng);
    x = static_cast<float>(kind == 0 ? y : kind == 1 ? std::round(y / 7) * 7 : kind == 2 ? std::round(y / 60) : 5.0);
  }
  if (kind == 4)  // sorted and reversed runs: the pivot's worst orders
    std::sort(v.begin(), v.end(), [&](float a, float b) { return n % 2 ? a < b : b < a; });
  return v;
}

TEST(BlockSelect, KthEqualsNthElementBitForBitAndPartitionsAroundIt) {
  std::mt19937_64 rng(50);
  for (int trial = 0; trial < 20000; ++trial) {
    const size_t n = std::uniform_int_distribution<size_t>(1, trial % 10 == 0 ? 3000 : 300)(rng);
    std::vector<float> v = samples(rng, n, trial % 5);
    // A sub-range as the tail cap's later selections use (between earlier pivots), or the whole.
    size_t lo = 0, hi = n;
    if (trial % 3 == 0) {
      lo = std::uniform_int_distribution<size_t>(0, n - 1)(rng);
      hi = std::uniform_int_distribution<size_t>(lo + 1, n)(rng);
    }
    const size_t k = std::uniform_int_distribution<size_t>(lo, hi - 1)(rng);
    std::vector<float> ref = v;
    std::nth_element(ref.begin() + static_cast<std::ptrdiff_t>(lo), ref.begin() + static_cast<std::ptrdiff_t>(k),
                     ref.begin() + static_cast<std::ptrdiff_t>(hi));
    std::vector<float> before = v;
    ASSERT_FALSE(orderNeedsNthElement(v.data(), n));
    selectKth(v.data(), lo, k, hi);
    ASSERT_EQ(std::bit_cast<uint32_t>(v[k]), std::bit_cast<uint32_t>(ref[k])) << "trial " << trial;
    for (size_t i = lo; i < hi; ++i) {
      ASSERT_FALSE(i < k && v[k] < v[i]) << "trial " << trial << " i " << i;
      ASSERT_FALSE(i > k && v[i] < v[k]) << "trial " << trial << " i " << i;
    }
    for (size_t i = 0; i < n; ++i) {
      if (i < lo || i >= hi) {
        ASSERT_EQ(std::bit_cast<uint32_t>(v[i]), std::bit_cast<uint32_t>(before[i]));
      }
    }
    std::sort(v.begin(), v.end());
    std::sort(before.begin(), before.end());
    ASSERT_EQ(v, before) << "trial " << trial;
  }
}

TEST(BlockSelect, NanAndNegativeZeroKeepNthElement) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::vector<float> v = {3, 1, 0.0f, 2, inf, -inf, 7};
  EXPECT_FALSE(orderNeedsNthElement(v.data(), v.size()));  // +0 and the infinities have one place in the order
  v.push_back(-0.0f);
  EXPECT_TRUE(orderNeedsNthElement(v.data(), v.size()));
  v.back() = nan;
  EXPECT_TRUE(orderNeedsNthElement(v.data(), v.size()));
  v.back() = -nan;
  EXPECT_TRUE(orderNeedsNthElement(v.data(), v.size()));
  v.back() = std::numeric_limits<float>::denorm_min();
  EXPECT_FALSE(orderNeedsNthElement(v.data(), v.size()));
  EXPECT_FALSE(orderNeedsNthElement(nullptr, 0));
}

// blockSpread (the median neighbour difference) on either path against nth_element over the same differences.
TEST(BlockSelect, BlockSpreadEqualsTheCodeBefore) {
  std::mt19937_64 rng(51);
  for (int trial = 0; trial < 5000; ++trial) {
    const size_t n = std::uniform_int_distribution<size_t>(1, 400)(rng);
    std::vector<float> d = samples(rng, n, trial % 5);
    for (float& x : d) x = std::abs(x + 800);
    if (trial % 7 == 0) d[std::uniform_int_distribution<size_t>(0, n - 1)(rng)] = -0.0f;  // nth_element's path
    std::vector<float> ref = d;
    std::nth_element(ref.begin(), ref.begin() + static_cast<std::ptrdiff_t>(n / 2), ref.end());
    const float want = 1.4826f * ref[n / 2] / std::sqrt(2.0f);
    const float got = blockSpread(d, 0.0f, n);
    ASSERT_EQ(std::bit_cast<uint32_t>(got), std::bit_cast<uint32_t>(want)) << "trial " << trial;
  }
}

}  // namespace
}  // namespace vs
