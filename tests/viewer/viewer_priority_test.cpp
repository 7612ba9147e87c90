// The viewer's threads yield the cores to SLAM (live_viewer.hpp): on Linux its publisher and
// server threads run at nice 19, and the threads that create it keep their own priority.
#include <gtest/gtest.h>

#ifdef __linux__
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "orbis/util/error.hpp"
#include "orbis/viewer/live_viewer.hpp"

namespace {

// The nice value of each of this process's threads, from /proc/self/task/TID/stat (field 19).
std::vector<int> threadNiceValues() {
  std::vector<int> values;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream in(task.path() / "stat");
    std::string stat((std::istreambuf_iterator<char>(in)), {});
    std::istringstream fields(stat.substr(stat.rfind(')') + 2));  // after "(comm) ": field 3 on
    std::string field;
    for (int i = 3; i <= 19 && fields >> field; ++i) {
      if (i == 19) values.push_back(std::stoi(field));
    }
  }
  return values;
}

TEST(ViewerPriority, ItsThreadsRunAtNiceNineteenAndTheCallersKeepTheirs) {
  const int callerNice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
  const auto nicedThreads = [] {
    int n = 0;
    for (int nice : threadNiceValues()) n += nice == 19;
    return n;
  };
  const int nicedBefore = nicedThreads();  // a test run at nice 19 has some already
  std::unique_ptr<orbis::LiveViewer> viewer;
  for (int port = 18931; port < 18941 && !viewer; ++port) {  // the first free one
    try {
      viewer = std::make_unique<orbis::LiveViewer>(orbis::ViewerOptions{.port = port});
    } catch (const orbis::Error&) {
    }
  }
  ASSERT_TRUE(viewer) << "no free port in 18931-18940";
  // The threads lower their own priority as they start.
  int niced = 0;
  for (int attempt = 0; attempt < 100 && niced < 2; ++attempt) {
    niced = nicedThreads() - nicedBefore;
    if (niced < 2) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_GE(niced, 2) << "the publisher and the server thread";
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())), callerNice);
}

}  // namespace
#endif
