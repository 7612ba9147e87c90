// orbis/util/thread_scheduling.hpp — hints to the operating system's scheduler, so that a frame's
// latency-bound work gets the cores first. Results never depend on them.
//
// Contract (Linux; elsewhere every call does nothing and returns false):
// - lowerThisThreadPriority() sets the calling thread's nice value to kBackgroundNice above the
//   main thread's (any user may lower a priority; a thread already there, such as one a background
//   thread started, keeps its value) and returns whether it took. Threads it starts afterwards
//   inherit the lower priority.
//   Local mapping, loop closing and full BA call it in threaded mode (SlamOptions::
//   backgroundPriority); parallelFor gives such a caller helpers at the same priority.
// - nameThisThread() names the calling thread (orbis' threads are named "orbis-…").
// - WakeSteering places a woken helper thread on a core other than its waker's. Linux tends to
//   wake a thread on the waker's core when the other cores have been idle a while (on virtual
//   machines an idle virtual CPU does not count as free), and the helper then waits there until
//   the waker blocks or the load balancer moves it: about 1 ms after a 33 ms camera period on the
//   2-core VM of docs/notes/2026-11-27-speed-scheduling.md, a third of a frame's extraction. The
//   helper calls adoptThisThread() once when it starts and settle() after each job it was woken
//   for (HelperThread: after, so that the system call does not delay the job); the waker
//   calls steerAwayFromCaller() before waking it. The steering lasts until settle(), which gives
//   the helper back every core it was allowed at adoptThisThread(), so a user's taskset or cpuset
//   is kept. With one allowed core it does nothing.
#pragma once

#include <atomic>
#include <memory>

namespace orbis {

// Nice increment of background threads: a contended core's time then goes about 10:1 to the
// foreground thread (CFS weights 1024 against 110).
inline constexpr int kBackgroundNice = 10;

// Lowers the calling thread's priority (see the contract); true when it took.
bool lowerThisThreadPriority();
// Whether lowerThisThreadPriority() took on the calling thread.
bool isThisThreadBackground();

// Names the calling thread for tools that list threads (top -H, perf report --comm, gdb); Linux
// keeps the first 15 characters. Does nothing elsewhere.
void nameThisThread(const char* name);

// Steers a helper thread's wake-ups away from its waker's core (see the contract).
class WakeSteering {
 public:
  WakeSteering();
  ~WakeSteering();
  WakeSteering(const WakeSteering&) = delete;
  WakeSteering& operator=(const WakeSteering&) = delete;

  // On the helper thread, once, before it first waits.
  void adoptThisThread();
  // On the waking thread, before it wakes the helper; true when the helper was steered.
  bool steerAwayFromCaller();
  // On the helper thread, after the job it was woken for: undoes the steering, if any.
  void settle();

 private:
  struct State;
  std::unique_ptr<State> state_;
  std::atomic<bool> steered_{false};
};

}  // namespace orbis
