#include <gtest/gtest.h>

#include "orbis/util/timing.hpp"

TEST(StageTimer, SummarisesSamplesPerStageInFirstSeenOrder) {
  orbis::StageTimer t;
  for (int i = 1; i <= 20; ++i) t.record("extract", i);
  t.record("track", 5.0);
  const auto s = t.summary();
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].stage, "extract");
  EXPECT_EQ(s[0].count, 20u);
  EXPECT_DOUBLE_EQ(s[0].meanMs, 10.5);
  EXPECT_DOUBLE_EQ(s[0].medianMs, 10.5);
  EXPECT_DOUBLE_EQ(s[0].p95Ms, 19.0);
  EXPECT_DOUBLE_EQ(s[0].maxMs, 20.0);
  EXPECT_EQ(s[1].stage, "track");
  EXPECT_DOUBLE_EQ(s[1].medianMs, 5.0);
}
