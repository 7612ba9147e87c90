#include "orbis/util/thread_scheduling.hpp"

#if defined(__linux__)
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <pthread.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#endif

namespace orbis {

namespace {
thread_local bool background = false;
}  // namespace

#if defined(__linux__)

namespace {
pid_t thisThreadId() { return static_cast<pid_t>(::syscall(SYS_gettid)); }

// The main thread's nice value at the first call: background threads sit kBackgroundNice above
// it, also those started by a background thread (which inherit its nice value already).
int baselineNice() {
  static const int baseline = [] {
    errno = 0;
    const int nice = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::getpid()));
    return nice == -1 && errno != 0 ? 0 : nice;
  }();
  return baseline;
}
}  // namespace

bool lowerThisThreadPriority() {
  const auto tid = static_cast<id_t>(thisThreadId());
  errno = 0;
  const int current = ::getpriority(PRIO_PROCESS, tid);
  if (current == -1 && errno != 0) return false;
  const int target = std::min(baselineNice() + kBackgroundNice, 19);
  if (current < target && ::setpriority(PRIO_PROCESS, tid, target) != 0) return false;
  background = true;
  return true;
}

struct WakeSteering::State {
  std::atomic<pid_t> helper{0};  // 0 until adoptThisThread()
  cpu_set_t allowed{};           // the helper's cores at adoptThisThread()
};

void WakeSteering::adoptThisThread() {
  if (::sched_getaffinity(0, sizeof(state_->allowed), &state_->allowed) != 0) return;
  if (CPU_COUNT(&state_->allowed) < 2) return;
  state_->helper.store(thisThreadId(), std::memory_order_release);
}

bool WakeSteering::steerAwayFromCaller() {
  const pid_t helper = state_->helper.load(std::memory_order_acquire);
  if (helper == 0) return false;
  const int callerCore = ::sched_getcpu();
  if (callerCore < 0 || callerCore >= CPU_SETSIZE || !CPU_ISSET(callerCore, &state_->allowed)) return false;
  cpu_set_t others = state_->allowed;
  CPU_CLR(callerCore, &others);
  if (::sched_setaffinity(helper, sizeof(others), &others) != 0) return false;
  steered_.store(true, std::memory_order_release);
  return true;
}

void WakeSteering::settle() {
  if (!steered_.exchange(false, std::memory_order_acq_rel)) return;
  ::sched_setaffinity(0, sizeof(state_->allowed), &state_->allowed);
}

#else

bool lowerThisThreadPriority() { return false; }

struct WakeSteering::State {};
void WakeSteering::adoptThisThread() {}
bool WakeSteering::steerAwayFromCaller() { return false; }
void WakeSteering::settle() {}

#endif

bool isThisThreadBackground() { return background; }

void nameThisThread([[maybe_unused]] const char* name) {
#if defined(__linux__)
  char truncated[16] = {};
  std::strncpy(truncated, name, sizeof(truncated) - 1);
  ::pthread_setname_np(::pthread_self(), truncated);
#endif
}

WakeSteering::WakeSteering() : state_(std::make_unique<State>()) {}
WakeSteering::~WakeSteering() = default;

}  // namespace orbis
