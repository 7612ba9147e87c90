// parallelFor (util/parallel_for.hpp): every task runs exactly once at any thread count, a call
// made from inside a task (the helpers busy) runs inline rather than waiting, and calls from two
// threads at once both complete.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "orbis/util/parallel_for.hpp"

namespace orbis {
namespace {

TEST(ParallelFor, RunsEveryTaskOnceAtAnyThreadCount) {
  for (int threads : {0, 1, 2, 5}) {
    for (int tasks : {0, 1, 2, 7, 100}) {
      std::vector<std::atomic<int>> runs(static_cast<std::size_t>(tasks));
      for (int repeat = 0; repeat < 20; ++repeat) parallelFor(threads, tasks, [&](int t) { ++runs[static_cast<std::size_t>(t)]; });
      for (int t = 0; t < tasks; ++t) EXPECT_EQ(runs[static_cast<std::size_t>(t)], 20) << threads << " threads, task " << t;
    }
  }
}

TEST(ParallelFor, NestedCallRunsInline) {
  std::atomic<int> inner{0};
  parallelFor(2, 4, [&](int) { parallelFor(2, 3, [&](int) { ++inner; }); });
  EXPECT_EQ(inner, 12);
}

TEST(ParallelFor, ConcurrentCallersBothComplete) {
  std::atomic<long> sum{0};
  auto work = [&] {
    for (int repeat = 0; repeat < 200; ++repeat) parallelFor(2, 8, [&](int t) { sum += t; });
  };
  std::thread other(work);
  work();
  other.join();
  EXPECT_EQ(sum, 2L * 200 * 28);
}

}  // namespace
}  // namespace orbis
