// QueueWorker::waitUntilIdleFor (util/queue_worker.hpp): gives up after its budget while the
// worker is serving, and returns true once the queue is empty and the worker idle;
// waitUntilFewerThanFor: gives up while the queue is that long, and returns once an item is taken.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "orbis/util/queue_worker.hpp"

namespace orbis {
namespace {

using namespace std::chrono_literals;

TEST(QueueWorker, WaitUntilIdleForGivesUpWhileServingAndSucceedsOnceIdle) {
  QueueWorker<int> worker;
  std::atomic<bool> release{false};
  std::atomic<int> served{0};
  worker.start([&] {
    while (worker.pop()) {
      while (!release) std::this_thread::sleep_for(1ms);  // held until the test lets it go
      ++served;
    }
  });
  EXPECT_TRUE(worker.waitUntilIdleFor(1s));  // nothing queued yet
  worker.push(1);
  EXPECT_FALSE(worker.waitUntilIdleFor(20ms));  // queued or being served, and held there
  EXPECT_FALSE(worker.idle());
  release = true;
  EXPECT_TRUE(worker.waitUntilIdleFor(60s));  // returns as soon as the item is done
  EXPECT_EQ(served.load(), 1);
  worker.stop();
}

TEST(QueueWorker, WaitUntilFewerThanForEndsWhenAnItemIsTaken) {
  QueueWorker<int> worker;  // not started: the test takes the items
  for (int i = 0; i < 3; ++i) worker.push(i);
  EXPECT_TRUE(worker.waitUntilFewerThanFor(4, 0ms));
  EXPECT_FALSE(worker.waitUntilFewerThanFor(3, 20ms));
  std::thread taker([&] {
    std::this_thread::sleep_for(20ms);
    worker.pop();
  });
  // At the budget the wait reports its condition anyway, so only the time shows a missed wake.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(worker.waitUntilFewerThanFor(3, 30s));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 15s) << "woken by the budget, not by pop()";
  EXPECT_EQ(worker.size(), 2u);
  taker.join();
}

}  // namespace
}  // namespace orbis
