// orbis/util/parallel_for.hpp — fork-join over a small number of tasks, for the solver's loops.
//
// Contract: parallelFor(threads, tasks, f) calls f(task) exactly once for every task in
// [0, tasks) and returns when all have returned. The caller's thread takes tasks too; up to
// threads - 1 helpers of a process-wide pool (started on first use, one fewer than the
// hardware's cores, at least one) take the others; callers at background priority
// (util/thread_scheduling.hpp) have a pool of their own, whose helpers run at that priority too.
// Which thread runs a task is unspecified, so a caller that wants the same result at any thread
// count makes each task's output depend on the task alone. threads <= 1 or tasks <= 1 runs
// inline; so does a call made while the helpers serve another caller (local BA and a loop's full
// BA never wait for each other's helpers). f must not throw. Waking a helper costs a few
// microseconds: worth it for work of tens of microseconds.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "orbis/util/thread_scheduling.hpp"

namespace orbis {

namespace parallel_detail {

class HelperPool {
 public:
  // The pool for callers at background priority (util/thread_scheduling.hpp) or for the others.
  static HelperPool& instance(bool background) {
    if (background) {
      static HelperPool pool;
      return pool;
    }
    static HelperPool pool;
    return pool;
  }
  int helpers() const { return static_cast<int>(threads_.size()); }

  // Runs f over [0, tasks) with up to `helpers` helpers; false (nothing run) when the pool is busy.
  bool tryRun(int helpers, int tasks, const std::function<void(int)>& f) {
    std::unique_lock busy(busy_, std::try_to_lock);
    if (!busy.owns_lock()) return false;
    helpers = std::min(helpers, this->helpers());
    next_.store(0, std::memory_order_relaxed);
    {
      std::lock_guard lock(mutex_);
      job_ = &f;
      tasks_ = tasks;
      wanted_ = helpers;
      active_ = helpers;
      ++generation_;
    }
    wake_.notify_all();
    takeTasks(f, tasks);
    std::unique_lock lock(mutex_);
    done_.wait(lock, [&] { return active_ == 0; });
    job_ = nullptr;
    return true;
  }

  ~HelperPool() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

 private:
  // Helpers inherit their creator's priority: the background pool is made by its first caller,
  // which is a background thread.
  HelperPool() {
    const int n = std::max(1, static_cast<int>(std::thread::hardware_concurrency()) - 1);
    for (int i = 0; i < n; ++i) threads_.emplace_back([this, i] { serve(i); });
  }

  void takeTasks(const std::function<void(int)>& f, int tasks) {
    for (int t = next_.fetch_add(1, std::memory_order_relaxed); t < tasks;
         t = next_.fetch_add(1, std::memory_order_relaxed))
      f(t);
  }

  void serve(int index) {
    nameThisThread("orbis-pool");
    unsigned long seen = 0;
    for (;;) {
      const std::function<void(int)>* job;
      int tasks;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || (generation_ != seen && index < wanted_); });
        if (stop_) return;
        seen = generation_;
        job = job_;
        tasks = tasks_;
      }
      takeTasks(*job, tasks);
      {
        std::lock_guard lock(mutex_);
        if (--active_ == 0) done_.notify_one();
      }
    }
  }

  std::mutex busy_;  // held by the caller whose tasks the helpers serve
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(int)>* job_ = nullptr;
  int tasks_ = 0, wanted_ = 0, active_ = 0;
  unsigned long generation_ = 0;
  bool stop_ = false;
  std::atomic<int> next_{0};
  std::vector<std::thread> threads_;
};

}  // namespace parallel_detail
// Runs f(task) for task in [0, tasks) on up to `threads` threads of the shared pool; returns when all ran.
template <class F>
void parallelFor(int threads, int tasks, F&& f) {
  if (threads > 1 && tasks > 1) {
    const std::function<void(int)> job = [&f](int task) { f(task); };
    auto& pool = parallel_detail::HelperPool::instance(isThisThreadBackground());
    if (pool.tryRun(std::min(threads, tasks) - 1, tasks, job)) return;
  }
  for (int t = 0; t < tasks; ++t) f(t);
}

}  // namespace orbis
