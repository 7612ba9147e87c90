// QueueWorker::waitUntilIdleFor (util/queue_worker.hpp): gives up after its budget while the
// worker is serving, and returns true once the queue is empty and the worker idle.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>

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

}  // namespace
}  // namespace orbis
