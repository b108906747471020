// util/text.h: the shared number and index formatters.
#include "util/text.h"

#include <gtest/gtest.h>

namespace vs {
namespace {

TEST(Text, NumberTextIsSixSignificantDigits) {
  EXPECT_EQ(numberText(0.5), "0.5");
  EXPECT_EQ(numberText(-3), "-3");
  EXPECT_EQ(numberText(1e300), "1e+300");
  EXPECT_EQ(numberText(1.0 / 3.0), "0.333333");
}

TEST(Text, FixedTextAndIndexText) {
  EXPECT_EQ(fixedText(1.5, 2), "1.50");
  EXPECT_EQ(fixedText(2.0, 0), "2");
  EXPECT_EQ(fixedText(-0.125, 1), "-0.1");
  EXPECT_EQ(indexText({1, -2, 30}), "(1,-2,30)");
}

}  // namespace
}  // namespace vs
