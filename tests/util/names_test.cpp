// util/names.h: an enum's name table looked up both ways.
#include "util/names.h"

#include <gtest/gtest.h>

namespace vs {
namespace {

enum class Fruit { Apple, Pear, Plum };
constexpr std::pair<Fruit, const char*> kFruits[] = {{Fruit::Apple, "apple"}, {Fruit::Pear, "pear"}};

TEST(Names, NameOfAndValueOfAreInverse) {
  EXPECT_EQ(nameOf(kFruits, Fruit::Apple), "apple");
  EXPECT_EQ(nameOf(kFruits, Fruit::Pear), "pear");
  EXPECT_EQ(valueOf(kFruits, "pear"), Fruit::Pear);
  EXPECT_EQ(valueOf(kFruits, "apple"), Fruit::Apple);
}

TEST(Names, UnlistedValuesAndNames) {
  EXPECT_EQ(nameOf(kFruits, Fruit::Plum), "?");
  EXPECT_EQ(nameOf(kFruits, Fruit::Plum, "none"), "none");
  EXPECT_FALSE(valueOf(kFruits, "plum").has_value());
  EXPECT_FALSE(valueOf(kFruits, "Apple").has_value());  // names are exact
}

TEST(Names, NamesTextListsTheTableInOrder) {
  EXPECT_EQ(namesText(kFruits), "apple, pear");
  EXPECT_EQ(namesText(kFruits, " | "), "apple | pear");
}

}  // namespace
}  // namespace vs
