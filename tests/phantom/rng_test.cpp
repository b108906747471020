#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "phantom/phantom.h"

using namespace vs;

TEST(PhantomRng, EngineIsTheStandardMt19937_64) {
  // The standard fixes the 10000th output of a default-seeded mt19937_64 (seed 5489).
  PhantomRng rng(5489);
  uint64_t v = 0;
  for (int i = 0; i < 10000; ++i) v = rng.next();
  EXPECT_EQ(v, 9981545732273789042ull);
}

TEST(PhantomRng, SameSeedSameSequenceDifferentSeedDifferent) {
  PhantomRng a(7), b(7), c(8);
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const double x = a.normal(), y = b.normal(), z = c.normal();
    EXPECT_EQ(x, y);
    differs |= x != z;
  }
  EXPECT_TRUE(differs);
}

TEST(PhantomRng, UniformFromTopBitsInUnitInterval) {
  PhantomRng rng(3);
  std::mt19937_64 ref(3);
  for (int i = 0; i < 1000; ++i) {
    const double u = rng.uniform();
    EXPECT_EQ(u, static_cast<double>(ref() >> 11) * 0x1.0p-53);
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
}

TEST(PhantomRng, BoxMullerMatchesFormulaAndMoments) {
  // The first pair is exactly the Box-Muller transform of the first two uniforms.
  PhantomRng rng(11);
  std::mt19937_64 ref(11);
  const double u1 = 1.0 - static_cast<double>(ref() >> 11) * 0x1.0p-53;
  const double u2 = static_cast<double>(ref() >> 11) * 0x1.0p-53;
  const double r = std::sqrt(-2 * std::log(u1));
  EXPECT_DOUBLE_EQ(rng.normal(), r * std::cos(2 * M_PI * u2));
  EXPECT_DOUBLE_EQ(rng.normal(), r * std::sin(2 * M_PI * u2));
  // Moments over 200k samples: mean 0 +- 0.01, variance 1 +- 0.02 (> 5 standard errors).
  const int n = 200000;
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = rng.normal();
    s += x;
    s2 += x * x;
  }
  EXPECT_NEAR(s / n, 0.0, 0.01);
  EXPECT_NEAR(s2 / n, 1.0, 0.02);
}

TEST(PhantomRng, IntegerCoversInclusiveRange) {
  PhantomRng rng(5);
  std::set<int64_t> seen;
  for (int i = 0; i < 2000; ++i) {
    const int64_t v = rng.integer(-2, 3);
    EXPECT_GE(v, -2);
    EXPECT_LE(v, 3);
    seen.insert(v);
  }
  EXPECT_EQ(seen.size(), 6u);
  EXPECT_THROW(rng.integer(3, 2), InvalidArgument);
  EXPECT_NE(PhantomRng::derive(1, 1), PhantomRng::derive(1, 2));
  EXPECT_NE(PhantomRng::derive(1, 1), PhantomRng::derive(2, 1));
}
