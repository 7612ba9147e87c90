// Enum name tables: several names per value with the first written back, exact or
// case-ignoring lookup, and the error listing every name in table order.
#include <string>

#include <gtest/gtest.h>

#include "orbis/util/enum_names.hpp"

namespace orbis {
namespace {

enum class Fruit { Apple, Pear, Quince };
constexpr EnumName<Fruit> kFruitNames[] = {
    {Fruit::Apple, "apple"}, {Fruit::Pear, "pear"}, {Fruit::Pear, "poire"}};

TEST(EnumNames, FindsEveryNameAndWritesTheFirst) {
  static_assert(findEnumName(kFruitNames, "poire") == Fruit::Pear);  // usable at compile time
  EXPECT_EQ(findEnumName(kFruitNames, "apple"), Fruit::Apple);
  EXPECT_EQ(findEnumName(kFruitNames, "pear"), Fruit::Pear);
  EXPECT_EQ(enumName(kFruitNames, Fruit::Pear), "pear");
  EXPECT_EQ(enumName(kFruitNames, Fruit::Quince), "?");  // a value the table lacks
}

TEST(EnumNames, LetterCaseIsIgnoredOnlyWhenAsked) {
  EXPECT_FALSE(findEnumName(kFruitNames, "Apple").has_value());
  EXPECT_EQ(findEnumName(kFruitNames, "APPLE", LetterCase::Ignored), Fruit::Apple);
  EXPECT_FALSE(findEnumName(kFruitNames, "appl", LetterCase::Ignored).has_value());
  EXPECT_FALSE(findEnumName(kFruitNames, "apples", LetterCase::Ignored).has_value());
}

TEST(EnumNames, ParseErrorNamesOriginAndEveryName) {
  EXPECT_EQ(parseEnumName(kFruitNames, "poire", "fruit", "argument --fruit"), Fruit::Pear);
  try {
    parseEnumName(kFruitNames, "kiwi", "fruit", "basket.yaml", "key Fruit");
    ADD_FAILURE() << "kiwi parsed";
  } catch (const Error& e) {
    EXPECT_EQ(e.source(), "basket.yaml");
    EXPECT_EQ(e.where(), "key Fruit");
    EXPECT_EQ(std::string(e.what()),
              "basket.yaml, key Fruit: unknown fruit \"kiwi\" (expected apple, pear or poire)");
  }
}

}  // namespace
}  // namespace orbis
