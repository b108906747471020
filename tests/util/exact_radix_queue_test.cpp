// util/exact_radix_queue.h: the same pop order as a binary heap of (distance, id) pairs.
#include "util/exact_radix_queue.h"

#include <gtest/gtest.h>

#include <functional>
#include <queue>
#include <random>

namespace vs {
namespace {

using Item = std::pair<double, int32_t>;
using Heap = std::priority_queue<Item, std::vector<Item>, std::greater<>>;

// Dijkstra-like use: every push lies at or beyond the last pop; many exact ties (sums of a few step
// lengths, the same distance pushed for several ids and twice for one id).
void compareOnRandomRun(uint32_t seed, int sources, double sourceDistance) {
  std::mt19937 rng(seed);
  const double stepsMm[] = {0.5, 0.5 * std::sqrt(2.0), 1.0, 0.75, 1.0 / 3.0};
  ExactRadixQueue q;
  Heap h;
  std::uniform_int_distribution<int32_t> id(0, 999);
  for (int i = 0; i < sources; ++i) {
    const int32_t s = id(rng);
    q.push(sourceDistance, s);
    h.push({sourceDistance, s});
  }
  size_t popped = 0;
  while (!h.empty()) {
    ASSERT_FALSE(q.empty());
    ASSERT_EQ(q.size(), h.size());
    const Item a = q.pop(), b = h.top();
    h.pop();
    ASSERT_EQ(a, b) << "pop " << popped << " of seed " << seed;
    ++popped;
    if (popped > 20000) continue;  // then drain
    const int n = static_cast<int>(rng() % 4);
    for (int k = 0; k < n; ++k) {
      double d = a.first + stepsMm[rng() % 5];
      if (rng() % 4 == 0) d = a.first + stepsMm[0] + stepsMm[1];  // the same sum in the other order below
      if (rng() % 4 == 0) d = a.first + stepsMm[1] + stepsMm[0];
      const int32_t v = rng() % 8 == 0 ? a.second : id(rng);
      q.push(d, v);
      h.push({d, v});
      if (rng() % 5 == 0) q.push(d, v), h.push({d, v});  // a duplicate entry
    }
  }
  EXPECT_TRUE(q.empty());
  EXPECT_GT(popped, 1000u);
}

TEST(ExactRadixQueue, PopsInTheOrderOfABinaryHeapOfThePairs) {
  for (uint32_t seed = 1; seed <= 6; ++seed) compareOnRandomRun(seed, 1 + static_cast<int>(seed) * 7, 0.0);
  compareOnRandomRun(7, 50, 0.25);  // every source at one distance > 0 (the depth's boundary)
  compareOnRandomRun(8, 50, -0.0);  // -0 is 0
}

TEST(ExactRadixQueue, EqualDistancesComeOutByIdAndClearEmpties) {
  ExactRadixQueue q;
  for (int32_t i : {5, 3, 9, 1}) q.push(2.0, i);
  q.push(1.5, 7);
  EXPECT_EQ(q.pop(), Item(1.5, 7));
  q.push(2.0, 0);  // a push at a distance already queued, after a pop
  q.push(3.0, 2);
  for (int32_t i : {0, 1, 3, 5, 9}) EXPECT_EQ(q.pop(), Item(2.0, i));
  EXPECT_EQ(q.pop(), Item(3.0, 2));
  EXPECT_TRUE(q.empty());
  q.push(4.0, 1);
  q.clear();
  EXPECT_TRUE(q.empty());
  q.push(0.5, 4);  // below the distances of before the clear
  EXPECT_EQ(q.pop(), Item(0.5, 4));
}

}  // namespace
}  // namespace vs
