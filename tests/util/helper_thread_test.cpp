// HelperThread: jobs run on one kept thread, join waits for the job, the guard joins on a throw.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "orbis/util/helper_thread.hpp"

namespace orbis {
namespace {

TEST(HelperThread, RunsEachJobOnOneKeptThreadAndJoinWaitsForIt) {
  HelperThread helper;
  std::thread::id first;
  for (int i = 0; i < 50; ++i) {
    std::atomic<bool> ran{false};
    std::thread::id where;
    helper.run([&] {
      std::this_thread::sleep_for(std::chrono::microseconds(i % 3 == 0 ? 200 : 0));
      where = std::this_thread::get_id();
      ran = true;
    });
    helper.join();
    ASSERT_TRUE(ran) << "join returned before job " << i << " finished";
    EXPECT_NE(where, std::this_thread::get_id());
    if (i == 0) first = where;
    EXPECT_EQ(where, first) << "a new thread for job " << i;
  }
}

TEST(HelperThread, JoinGuardJoinsWhenTheOwnersShareThrows) {
  HelperThread helper;
  std::atomic<bool> finished{false};
  EXPECT_THROW(
      {
        helper.run([&] {
          std::this_thread::sleep_for(std::chrono::milliseconds(5));
          finished = true;
        });
        HelperThread::JoinGuard guard(helper);
        throw std::runtime_error("owner's share failed");
      },
      std::runtime_error);
  EXPECT_TRUE(finished);
}

TEST(HelperThread, DestroyedWithoutAJobOrAfterOne) {
  { HelperThread unused; }
  HelperThread helper;
  int value = 0;
  helper.run([&] { value = 7; });
  helper.join();
  EXPECT_EQ(value, 7);
}

}  // namespace
}  // namespace orbis
