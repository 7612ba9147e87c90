// Scheduler hints: background priority lowers this thread only and reaches parallelFor's helpers;
// WakeSteering keeps a woken helper off its waker's core until it settles, then gives it back
// every core it had.
#include <gtest/gtest.h>
#include <pthread.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "orbis/util/helper_thread.hpp"
#include "orbis/util/parallel_for.hpp"
#include "orbis/util/thread_scheduling.hpp"

#if defined(__linux__)
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace orbis {
namespace {

#if defined(__linux__)

int niceOfThisThread() { return ::getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid))); }

TEST(ThreadScheduling, LowersOnlyTheCallingThread) {
  const int before = niceOfThisThread();
  if (before + kBackgroundNice > 19) GTEST_SKIP() << "nice " << before << " leaves no room to lower";
  int inside = 0, after = 0;
  bool lowered = false, flagged = false;
  std::thread([&] {
    lowered = lowerThisThreadPriority();
    inside = niceOfThisThread();
    flagged = isThisThreadBackground();
  }).join();
  after = niceOfThisThread();
  EXPECT_TRUE(lowered);
  EXPECT_EQ(inside, before + kBackgroundNice);
  // Once: a background thread lowering itself again, or a thread it started, stays where it is.
  int again = 0, child = 0;
  std::thread([&] {
    lowerThisThreadPriority();
    lowerThisThreadPriority();
    again = niceOfThisThread();
    std::thread([&] {
      lowerThisThreadPriority();
      child = niceOfThisThread();
    }).join();
  }).join();
  EXPECT_EQ(again, before + kBackgroundNice);
  EXPECT_EQ(child, before + kBackgroundNice);
  EXPECT_TRUE(flagged);
  EXPECT_EQ(after, before);
  EXPECT_FALSE(isThisThreadBackground());
}

TEST(ThreadScheduling, BackgroundCallersGetBackgroundHelpers) {
  const int base = niceOfThisThread();
  if (base + kBackgroundNice > 19) GTEST_SKIP() << "nice " << base << " leaves no room to lower";
  std::mutex mutex;
  std::vector<int> nices;
  std::thread([&] {
    ASSERT_TRUE(lowerThisThreadPriority());
    // Tasks long enough that a helper takes some of them.
    parallelFor(2, 8, [&](int) {
      std::this_thread::sleep_for(std::chrono::milliseconds(3));
      std::lock_guard lock(mutex);
      nices.push_back(niceOfThisThread());
    });
  }).join();
  ASSERT_EQ(nices.size(), 8u);
  for (int n : nices) EXPECT_EQ(n, base + kBackgroundNice);
  // And a foreground caller's helpers stay at its priority.
  nices.clear();
  parallelFor(2, 8, [&](int) {
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
    std::lock_guard lock(mutex);
    nices.push_back(niceOfThisThread());
  });
  ASSERT_EQ(nices.size(), 8u);
  for (int n : nices) EXPECT_EQ(n, base);
}

// The name a thread gave itself, read back as tools read it.
std::string nameOfThisThread() {
  char name[64] = {};
  EXPECT_EQ(::pthread_getname_np(::pthread_self(), name, sizeof(name)), 0);
  return name;
}

TEST(ThreadScheduling, NamesThreadsAsToolsShowThem) {
  std::string shortName, longName;
  std::thread([&] {
    nameThisThread("orbis-mapping");
    shortName = nameOfThisThread();
    nameThisThread("orbis-a-name-longer-than-fifteen");
    longName = nameOfThisThread();
  }).join();
  EXPECT_EQ(shortName, "orbis-mapping");
  EXPECT_EQ(longName, "orbis-a-name-lo");  // Linux keeps 15 characters
}

// Every thread orbis starts is named, so a profile can be split by thread.
TEST(ThreadScheduling, HelperThreadIsNamed) {
  HelperThread helper;
  std::string name;
  helper.run([&] { name = nameOfThisThread(); });
  helper.join();
  EXPECT_EQ(name, "orbis-helper");
}

cpu_set_t affinityOf(pid_t tid) {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(::sched_getaffinity(tid, sizeof(set), &set), 0) << "thread " << tid;
  return set;
}

TEST(ThreadScheduling, SteeringExcludesTheWakersCoreUntilSettled) {
  cpu_set_t mine = affinityOf(0);
  if (CPU_COUNT(&mine) < 2) GTEST_SKIP() << "one core: nothing to steer to";
  WakeSteering steering;
  std::atomic<pid_t> helper{0};
  std::atomic<int> stage{0};
  std::thread t([&] {
    steering.adoptThisThread();
    helper = static_cast<pid_t>(::syscall(SYS_gettid));
    stage = 1;
    while (stage.load() != 2) std::this_thread::yield();
    steering.settle();
    stage = 3;
    while (stage.load() != 4) std::this_thread::yield();  // alive until its cores are read
  });
  while (stage.load() != 1) std::this_thread::yield();
  // Pinned to one core, so the core the steering excludes is known.
  const int core = ::sched_getcpu();
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(core, &one);
  // No ASSERT until the thread is joined: it waits for the stages below.
  const bool pinned = ::sched_setaffinity(0, sizeof(one), &one) == 0;
  EXPECT_TRUE(pinned);
  const bool steered = pinned && steering.steerAwayFromCaller();
  EXPECT_TRUE(steered);
  if (steered) {
    const cpu_set_t narrowed = affinityOf(helper);
    EXPECT_FALSE(CPU_ISSET(core, &narrowed));
    EXPECT_EQ(CPU_COUNT(&narrowed), CPU_COUNT(&mine) - 1);
  }
  stage = 2;
  while (stage.load() != 3) std::this_thread::yield();
  const cpu_set_t settled = affinityOf(helper);
  stage = 4;
  t.join();
  EXPECT_TRUE(CPU_EQUAL(&settled, &mine));
  ::sched_setaffinity(0, sizeof(mine), &mine);
}

// A job may run on the cores its wake was steered to (undoing the steering is a system call
// made after the job, so that the job starts at once), never on more than the thread had, and
// between jobs the thread has every core it had.
TEST(ThreadScheduling, HelperThreadKeepsItsCoresBetweenJobs) {
  cpu_set_t mine = affinityOf(0);
  HelperThread helper;
  for (int i = 0; i < 20; ++i) {
    cpu_set_t during;
    pid_t tid = 0;
    helper.run([&] {
      during = affinityOf(0);
      tid = static_cast<pid_t>(::syscall(SYS_gettid));
    });
    helper.join();
    cpu_set_t within;
    CPU_AND(&within, &during, &mine);
    EXPECT_TRUE(CPU_EQUAL(&within, &during)) << "job " << i << " ran on a core the thread did not have";
    // The thread settles right after the job; give it a moment.
    cpu_set_t between = affinityOf(tid);
    for (int wait = 0; wait < 1000 && !CPU_EQUAL(&between, &mine); ++wait) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      between = affinityOf(tid);
    }
    EXPECT_TRUE(CPU_EQUAL(&between, &mine)) << "after job " << i << " its cores stayed narrowed";
  }
}

#else

TEST(ThreadScheduling, DoesNothingOffLinux) {
  EXPECT_FALSE(lowerThisThreadPriority());
  EXPECT_FALSE(isThisThreadBackground());
}

#endif

}  // namespace
}  // namespace orbis
