// orbis/util/helper_thread.hpp — one persistent thread that runs one job at a time: fork-join
// work on every frame, where starting a thread each time would cost more than waking one.
// Not parallelFor's pool (util/parallel_for.hpp): that pool is shared with bundle adjustment and
// runs a caller inline while BA holds it, which in threaded mode is much of the time; a frame's
// extraction owns its helper.
//
// Contract: run(job) hands `job` to the thread and returns at once; join() returns when it has
// returned. One owner calls run() and join() (not thread-safe); every run() is followed by a
// join() before the next run() and before anything the job refers to goes away (JoinGuard does
// it on every path out of a scope). The thread starts on the first run() and is joined by the
// destructor. The job must not throw. Everything the job did happens-before join()'s return.
// run() wakes the thread on a core other than the caller's (WakeSteering), so that after a
// camera's frame period of idling the job does not wait for the caller's core; the thread undoes
// that steering after the job, so between jobs it has every core it had. join() spins briefly
// before it blocks.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

#include "orbis/util/thread_scheduling.hpp"

namespace orbis {

// A thread kept between jobs, for fork-join work per frame.
class HelperThread {
 public:
  HelperThread() = default;
  HelperThread(const HelperThread&) = delete;
  HelperThread& operator=(const HelperThread&) = delete;
  ~HelperThread() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    if (thread_.joinable()) thread_.join();
  }

  // Starts `job` on the helper thread.
  void run(std::function<void()> job) {
    // Steered before the job is visible: a thread that is still awake from the last job may take
    // it at once, and the steering must be there for the settle that follows the job.
    const bool started = thread_.joinable();
    if (started) steering_.steerAwayFromCaller();
    {
      std::lock_guard lock(mutex_);
      job_ = std::move(job);
      pending_ = true;
    }
    if (!started) thread_ = std::thread([this] { serve(); });
    wake_.notify_one();
  }

  // Waits until the job run() started has returned: spinning a little first, for a job that is
  // about to end, since a thread blocked here is woken tens of microseconds after the notify on
  // the 2-core VM (docs/notes/2026-11-29-speed-tracking-on-two-cores.md).
  void join() {
    for (int i = 0; i < kJoinSpins; ++i) {
      if (!pending_.load(std::memory_order_acquire)) return;
      pause();
    }
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return !pending_.load(std::memory_order_acquire); });
  }

  // Joins the helper when the scope ends, also when the owner's share of the work throws.
  class JoinGuard {
   public:
    // Joins `helper` when destroyed.
    explicit JoinGuard(HelperThread& helper) : helper_(helper) {}
    JoinGuard(const JoinGuard&) = delete;
    JoinGuard& operator=(const JoinGuard&) = delete;
    ~JoinGuard() { helper_.join(); }

   private:
    HelperThread& helper_;
  };

 private:
  void serve() {
    nameThisThread("orbis-helper");
    steering_.adoptThisThread();
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stop_ || (pending_.load() && job_); });
      if (stop_ && !pending_.load()) return;
      std::function<void()> job = std::move(job_);
      job_ = nullptr;
      lock.unlock();
      job();
      job = nullptr;  // before join() can return: what the job holds goes while the owner waits
      lock.lock();
      pending_.store(false, std::memory_order_release);
      done_.notify_one();
      // Undone after the job, not before it: the system call delayed the job's start
      // (docs/notes/2026-11-29-speed-tracking-on-two-cores.md).
      lock.unlock();
      steering_.settle();
      lock.lock();
    }
  }

  static constexpr int kJoinSpins = 2000;  // about 35 us on the 2-core VM (Zen 5)

  static void pause() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    asm volatile("yield");
#endif
  }

  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::function<void()> job_;
  // A job was handed over and has not returned yet; written under mutex_, read without it by
  // join()'s spin.
  std::atomic<bool> pending_{false};
  bool stop_ = false;
  WakeSteering steering_;
  std::thread thread_;
};

}  // namespace orbis
