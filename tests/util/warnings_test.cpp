// Repeated warnings folded into a few examples and a count per kind.
#include "orbis/util/warnings.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

TEST(Warnings, AlikeWarningsAreFoldedAfterAFewAndCounted) {
  std::vector<std::string> warnings;
  for (int i = 0; i < 1226; ++i)
    warnings.push_back("frame " + std::to_string(i) + " skipped: rgb.txt, line " + std::to_string(i + 4) +
                       ": no depth map within 0.020000 s of 13050311" + std::to_string(i) + ".png");
  warnings.insert(warnings.begin() + 2, "ATE not computed: no pose pairs");
  const std::vector<orbis::WarningKind> kinds = orbis::foldWarnings(warnings, 3);
  ASSERT_EQ(kinds.size(), 2u);
  EXPECT_EQ(kinds[0].count, 1226u);
  EXPECT_EQ(kinds[0].pattern, "frame # skipped: rgb.txt, line #: no depth map within #.# s of #.png");
  EXPECT_EQ(kinds[1].count, 1u);

  const std::vector<std::string> lines = orbis::readableWarnings(kinds);
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0], warnings[0]);
  EXPECT_EQ(lines[3], "... (1223 more like this)");
  EXPECT_EQ(lines[4], "ATE not computed: no pose pairs");
  EXPECT_TRUE(orbis::readableWarnings(orbis::foldWarnings({})).empty());
}

}  // namespace
