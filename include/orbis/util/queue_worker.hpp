// orbis/util/queue_worker.hpp — a FIFO of work items and, optionally, the thread that serves it:
// the scaffolding local mapping and loop closing share.
//
// Contract: push() may be called from any thread. In threaded mode start(serve) launches a worker
// that waits for items (or a wake-up) and calls serve() with busy() set; serve() pops items itself
// (pop()) and returns when it wants to wait again. Without start() nothing runs on its own: the
// owner drains the queue on its thread (deterministic mode). waitUntilIdle(drainInline) blocks
// until the queue is empty and the worker idle, or, with no worker, drains it inline;
// waitUntilIdleFor(budget) waits the same way for at most budget (threaded);
// waitUntilFewerThanFor(count, budget) until fewer than count items are queued. stop() wakes and
// joins the worker; items still queued stay queued.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "orbis/util/thread_scheduling.hpp"

namespace orbis {

// A queue of items served by one worker thread (or inline, when never started): local mapping's and
// loop closing's queues.
template <class Item>
class QueueWorker {
 public:
  QueueWorker() = default;
  QueueWorker(const QueueWorker&) = delete;
  QueueWorker& operator=(const QueueWorker&) = delete;
  ~QueueWorker() { stop(); }

  // Starts the thread, which calls serve() whenever items are queued or it is woken; with
  // `background` at a lower priority than the caller's (util/thread_scheduling.hpp).
  void start(std::function<void()> serve, bool background = false, const char* name = "orbis-worker") {
    thread_ = std::thread([this, background, name, serve = std::move(serve)] {
      nameThisThread(name);
      if (background) lowerThisThreadPriority();
      while (!finishing()) {
        {
          std::unique_lock lock(mutex_);
          // A bounded wait: serve() may have returned with items left (mapping paused), and
          // flags it polls change without a notification.
          cv_.wait_for(lock, std::chrono::milliseconds(5), [this] { return finish_.load() || !queue_.empty(); });
        }
        if (finishing()) break;
        busy_ = true;
        serve();
        {
          // Under the mutex, so a waiter between its check and its wait cannot miss the change.
          std::lock_guard lock(mutex_);
          busy_ = false;
        }
        idleCv_.notify_all();
      }
    });
  }

  // Queues an item and wakes the worker.
  void push(Item item) {
    {
      std::lock_guard lock(mutex_);
      queue_.push_back(std::move(item));
    }
    cv_.notify_all();
  }
  // Takes the oldest item, if any.
  std::optional<Item> pop() {
    std::optional<Item> item;
    {
      std::lock_guard lock(mutex_);
      if (queue_.empty()) return std::nullopt;
      item = std::move(queue_.front());
      queue_.pop_front();
    }
    queueCv_.notify_all();  // waitUntilFewerThanFor
    return item;
  }
  // Items queued.
  std::size_t size() const {
    std::lock_guard lock(mutex_);
    return queue_.size();
  }
  // Wakes the worker to look at its flags again.
  void wake() { cv_.notify_all(); }

  // Whether the worker runs on its own thread.
  bool threaded() const { return thread_.joinable(); }
  // Whether serve() is running now.
  bool busy() const { return busy_.load(); }
  // Nothing queued and nothing being served.
  bool idle() const { return size() == 0 && !busy(); }
  // Whether stop() was called.
  bool finishing() const { return finish_.load(); }

  // `alsoIdle` adds the owner's own condition (for instance no full BA running).
  void waitUntilIdle(const std::function<void()>& drainInline, const std::function<bool()>& alsoIdle = {}) {
    if (!threaded()) {
      if (!idle() || (alsoIdle && !alsoIdle())) drainInline();
      return;
    }
    waitIdleUntil(std::nullopt, alsoIdle);
  }

  // Threaded: as waitUntilIdle, but for at most `budget`; true when idle.
  bool waitUntilIdleFor(std::chrono::steady_clock::duration budget) {
    return waitIdleUntil(std::chrono::steady_clock::now() + budget, {});
  }

  // Blocks for at most `budget` until fewer than `count` items are queued; true when they are.
  bool waitUntilFewerThanFor(std::size_t count, std::chrono::steady_clock::duration budget) {
    std::unique_lock lock(mutex_);
    return queueCv_.wait_for(lock, budget, [&] { return queue_.size() < count; });
  }

  // Asks the thread to finish and joins it.
  void stop() {
    finish_ = true;
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  // Woken when the worker finishes serving, so a waiter returns as soon as it is idle. `alsoIdle`
  // flags change without a notification: only with one is the condition looked at again every few
  // milliseconds.
  bool waitIdleUntil(std::optional<std::chrono::steady_clock::time_point> deadline,
                     const std::function<bool()>& alsoIdle) {
    constexpr auto kRecheck = std::chrono::milliseconds(2);
    std::unique_lock lock(mutex_);
    while (!queue_.empty() || busy_.load() || (alsoIdle && !alsoIdle())) {
      const auto now = std::chrono::steady_clock::now();
      if (deadline && now >= *deadline) return false;
      std::optional<std::chrono::steady_clock::time_point> until = deadline;
      if (alsoIdle) until = std::min(deadline.value_or(now + kRecheck), now + kRecheck);
      if (until) idleCv_.wait_until(lock, *until);
      else idleCv_.wait(lock);  // only the worker's notification can make it idle
    }
    return true;
  }

  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::condition_variable idleCv_;   // the worker finished serving
  std::condition_variable queueCv_;  // an item was taken off the queue
  std::deque<Item> queue_;
  std::atomic<bool> busy_{false};
  std::atomic<bool> finish_{false};
  std::thread thread_;
};

}  // namespace orbis
