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

// The one number parser of the CLI's arguments and the viewer's script.
TEST(Text, ParseNumberTakesTheWholeTextOrNothing) {
  double d = 0;
  EXPECT_TRUE(parseNumber(" +1.5 ", d));
  EXPECT_EQ(d, 1.5);
  EXPECT_TRUE(parseNumber("-2e3", d));
  EXPECT_EQ(d, -2000);
  for (const char* bad : {"", " ", "1.5x", "nan", "inf", "-inf", "1,2", "1e999"})
    EXPECT_FALSE(parseNumber(bad, d)) << bad;
  int64_t i = 0;
  EXPECT_TRUE(parseInteger("42", i));
  EXPECT_EQ(i, 42);
  EXPECT_TRUE(parseInteger("-7", i));
  EXPECT_EQ(i, -7);
  for (const char* bad : {"", "4.2", "9999999999999999999999", "3 4", "x"}) EXPECT_FALSE(parseInteger(bad, i)) << bad;
  EXPECT_EQ(splitText("a,,b,", ','), (std::vector<std::string>{"a", "", "b", ""}));
  EXPECT_EQ(splitText("", ','), (std::vector<std::string>{""}));
  EXPECT_EQ(trimmedText("\t a b  "), "a b");
}

}  // namespace
}  // namespace vs
