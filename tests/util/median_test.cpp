// util/median.h: the tracking levels' upper median.
#include "util/median.h"

#include <gtest/gtest.h>

#include <vector>

namespace vs {

TEST(Median, OddCountIsTheMiddleValue) {
  std::vector<double> v{5, 1, 4, 2, 3};
  EXPECT_DOUBLE_EQ(medianInPlace(v), 3);
  EXPECT_EQ(v.size(), 5u);
}

TEST(Median, EvenCountIsTheUpperOfTheTwoMiddleValuesNotTheirMean) {
  // A level is a value the image holds: 3, not 2.5.
  EXPECT_DOUBLE_EQ(medianOf({4, 1, 3, 2}), 3);
}

TEST(Median, EmptyIsZeroAndOneValueIsItself) {
  EXPECT_DOUBLE_EQ(medianOf({}), 0);
  EXPECT_DOUBLE_EQ(medianOf({-7.5}), -7.5);
}

TEST(Median, MedianOfLeavesTheCallersVectorUntouched) {
  const std::vector<double> v{9, 8, 7};
  EXPECT_DOUBLE_EQ(medianOf(v), 8);
  EXPECT_EQ(v, (std::vector<double>{9, 8, 7}));
}

}  // namespace vs
