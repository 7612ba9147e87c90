// ORB extraction and stereo matching on real frames, each beside cv::ORB with the same
// feature budget in the same run. After the Google Benchmark table, prints the time ratio
// ours / cv::ORB and the coverage (share of 32x32 px cells holding >= 1 keypoint) per dataset.
// One thread each (CPU time), and orbis as the SLAM sensors run it (two threads, wall time, the
// TUM frames in colour) against cv::ORB's one thread; the same again while background threads
// keep the cores busy (the ...Loaded rows: threaded SLAM's mapping competes with extraction for
// the two cores, and how the work is split decides how much a held-back thread delays a frame).
// Data: ORBIS_DATA or ../shared/datasets; a dataset that is absent is skipped.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "orbis/camera/euroc_calibration.hpp"
#include "orbis/camera/rectification.hpp"
#include "orbis/features/frame_features.hpp"
#include "orbis/features/orb_extractor.hpp"
#include "orbis/util/thread_scheduling.hpp"


namespace fs = std::filesystem;

namespace {

constexpr int kFrames = 6;  // frames cycled through per dataset, so one image's luck does not decide

fs::path dataRoot() {
  if (const char* env = std::getenv("ORBIS_DATA"); env && *env) return env;
  return ORBIS_DEFAULT_DATA_DIR;
}

struct Dataset {
  std::string name;
  int features;
  std::vector<cv::Mat> left, right;  // right empty for monocular sources
  std::vector<cv::Mat> rectifiedLeft = {}, rectifiedRight = {};  // stereo sources only
  std::vector<cv::Mat> colour = {};  // the left frames as read in colour, where the source is colour (TUM)
  std::optional<orbis::RectifiedStereoCamera<double>> camera = {};  // the rectified pair's, stereo sources only
};

float bfOf(const Dataset& d) { return static_cast<float>(d.camera->bf()); }
float baselineOf(const Dataset& d) { return static_cast<float>(d.camera->baseline); }

std::vector<fs::path> sortedPngs(const fs::path& dir, int count) {
  std::vector<fs::path> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".png") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (static_cast<int>(files.size()) > count) files.resize(static_cast<std::size_t>(count));
  return files;
}

std::vector<cv::Mat> loadGray(const fs::path& dir, int count) {
  std::vector<cv::Mat> images;
  for (const auto& f : sortedPngs(dir, count)) images.push_back(cv::imread(f.string(), cv::IMREAD_GRAYSCALE));
  return images;
}

std::vector<cv::Mat> loadColour(const fs::path& dir, int count) {
  std::vector<cv::Mat> images;
  for (const auto& f : sortedPngs(dir, count)) images.push_back(cv::imread(f.string(), cv::IMREAD_COLOR));
  return images;
}

std::vector<Dataset>& datasets() {
  static std::vector<Dataset> sets = [] {
    std::vector<Dataset> out;
    const fs::path root = dataRoot();
    Dataset tum{"TUM_640x480", 1000, loadGray(root / "tum_fr3_teddy_200/rgb", kFrames), {}, {}, {},
                loadColour(root / "tum_fr3_teddy_200/rgb", kFrames)};
    Dataset euroc{"EuRoC_752x480", 1200, loadGray(root / "euroc_V1_01_easy_95/mav0/cam0/data", kFrames),
                  loadGray(root / "euroc_V1_01_easy_95/mav0/cam1/data", kFrames)};
    Dataset kitti{"KITTI_1226x370", 2000, loadGray(root / "kitti_06_first51/sequences/06/image_0", kFrames),
                  loadGray(root / "kitti_06_first51/sequences/06/image_1", kFrames)};
    if (!euroc.left.empty() && euroc.left.size() == euroc.right.size()) {
      // EuRoC is not rectified: rectify the pairs once, outside the timed loops.
      const fs::path cams = root / "euroc_V1_01_easy_95/mav0";
      const auto rect = orbis::rectifyStereo(orbis::readEurocCalibration(cams / "cam0/sensor.yaml"),
                                             orbis::readEurocCalibration(cams / "cam1/sensor.yaml"));
      euroc.rectifiedLeft.clear();
      for (std::size_t i = 0; i < euroc.left.size(); ++i) {
        auto pair = rect.rectify(euroc.left[i], euroc.right[i]);
        euroc.rectifiedLeft.push_back(pair.left);
        euroc.rectifiedRight.push_back(pair.right);
      }
      euroc.camera = rect.camera;
    }
    kitti.rectifiedLeft = kitti.left;
    kitti.rectifiedRight = kitti.right;
    kitti.camera = orbis::RectifiedStereoCamera<double>(
        orbis::PinholeCamera<double>{707.0912, 707.0912, 601.8873, 183.1104, 1226, 370}, 379.8145 / 707.0912);
    for (auto* d : {&tum, &euroc, &kitti})
      if (!d->left.empty()) out.push_back(std::move(*d));
    return out;
  }();
  return sets;
}

orbis::OrbParams paramsFor(const Dataset& d) {
  orbis::OrbParams p;
  p.features = d.features;
  return p;
}

cv::Ptr<cv::ORB> cvOrbFor(const Dataset& d) {
  const orbis::OrbParams p = paramsFor(d);
  return cv::ORB::create(p.features, p.scaleFactor, p.levels, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31,
                         p.iniThFast);
}

void BM_OrbisExtract(benchmark::State& state, std::size_t which, bool openCvFast) {
  const Dataset& d = datasets()[which];
  orbis::OrbExtractor extractor(paramsFor(d));
  if (openCvFast) extractor.setOpenCvFast(true);
  std::vector<orbis::Keypoint> kps;
  std::vector<orbis::OrbDescriptor> desc;
  std::size_t frame = 0, total = 0;
  for (auto _ : state) {
    extractor.extract(d.left[frame++ % d.left.size()], kps, desc);
    total += kps.size();
    benchmark::DoNotOptimize(desc.data());
  }
  state.counters["keypoints"] = static_cast<double>(total) / static_cast<double>(state.iterations());
}

void BM_CvOrbExtract(benchmark::State& state, std::size_t which) {
  const Dataset& d = datasets()[which];
  auto orb = cvOrbFor(d);
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  std::size_t frame = 0, total = 0;
  for (auto _ : state) {
    orb->detectAndCompute(d.left[frame++ % d.left.size()], cv::noArray(), kps, desc);
    total += kps.size();
    benchmark::DoNotOptimize(desc.data);
  }
  state.counters["keypoints"] = static_cast<double>(total) / static_cast<double>(state.iterations());
}

// How the cores are kept busy beside a row: not at all, by threads at the caller's priority, or by
// threads at the priority orbis gives its background threads (util/thread_scheduling.hpp).
enum class Load { kNone, kBusy, kBusyBackground };

// Threads that keep cores busy while they live (arithmetic only), like local mapping's threads
// during a threaded run.
class BackgroundLoad {
 public:
  explicit BackgroundLoad(Load load) {
    const int threads = load == Load::kNone ? 0 : 2;
    const bool lowered = load == Load::kBusyBackground;
    for (int t = 0; t < threads; ++t)
      threads_.emplace_back([this, lowered] {
        if (lowered) orbis::lowerThisThreadPriority();
        double x = 1.0;
        while (!stop_.load(std::memory_order_relaxed))
          for (int i = 0; i < 1000; ++i) x = x * 1.0000001 + 1e-9;
        benchmark::DoNotOptimize(x);
      });
  }
  ~BackgroundLoad() {
    stop_ = true;
    for (std::thread& t : threads_) t.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

// A camera's frame period: the paced rows sleep this long between frames, untimed, as a live
// camera or ORB-SLAM2's example programs do; caches and idle cores are then as a real run has them.
constexpr auto kFramePeriod = std::chrono::milliseconds(33);

// One image a frame period apart (wall time of the extraction alone): orbis on one thread or as
// the monocular and RGB-D sensors run it (two threads, colour input), or cv::ORB on one.
template <class Extract>
void timePaced(benchmark::State& state, std::size_t frames, Extract&& extract) {
  std::size_t frame = 0;
  for (auto _ : state) {
    std::this_thread::sleep_for(kFramePeriod);
    const auto start = std::chrono::steady_clock::now();
    extract(frame++ % frames);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
}

void BM_OrbisExtractPaced(benchmark::State& state, std::size_t which, bool twoThreads) {
  const Dataset& d = datasets()[which];
  const std::vector<cv::Mat>& frames = twoThreads && !d.colour.empty() ? d.colour : d.left;
  orbis::OrbExtractor extractor(paramsFor(d));
  extractor.setParallelLevels(twoThreads);
  std::vector<orbis::Keypoint> kps;
  std::vector<orbis::OrbDescriptor> desc;
  timePaced(state, frames.size(), [&](std::size_t i) {
    extractor.extract(frames[i], kps, desc);
    benchmark::DoNotOptimize(desc.data());
  });
}

void BM_CvOrbExtractPaced(benchmark::State& state, std::size_t which) {
  const Dataset& d = datasets()[which];
  auto orb = cvOrbFor(d);
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  timePaced(state, d.left.size(), [&](std::size_t i) {
    orb->detectAndCompute(d.left[i], cv::noArray(), kps, desc);
    benchmark::DoNotOptimize(desc.data);
  });
}

// One image as the monocular and RGB-D sensors extract it: the levels on two threads, a colour
// image (where the source has one) converted inside. Wall time.
void BM_OrbisExtractTwoThreads(benchmark::State& state, std::size_t which, Load busy) {
  const Dataset& d = datasets()[which];
  BackgroundLoad load(busy);
  const std::vector<cv::Mat>& frames = d.colour.empty() ? d.left : d.colour;
  orbis::OrbExtractor extractor(paramsFor(d));
  extractor.setParallelLevels(true);
  std::vector<orbis::Keypoint> kps;
  std::vector<orbis::OrbDescriptor> desc;
  std::size_t frame = 0;
  for (auto _ : state) {
    extractor.extract(frames[frame++ % frames.size()], kps, desc);
    benchmark::DoNotOptimize(desc.data());
  }
}

// Matching on two threads, where the matcher offers it (builds of before it did not).
template <class Matcher>
void matchOnTwoThreadsWhereOffered(Matcher& matcher) {
  if constexpr (requires { matcher.setParallel(true); }) matcher.setParallel(true);
}

// A rectified pair as the stereo sensor extracts it: orbis::extractStereo (the right image on a
// second thread, then the matching, on two threads where the matcher offers it). Wall time.
void BM_OrbisStereoTwoThreads(benchmark::State& state, std::size_t which, Load busy) {
  const Dataset& d = datasets()[which];
  BackgroundLoad load(busy);
  orbis::OrbExtractor left(paramsFor(d)), right(paramsFor(d));
  orbis::StereoMatcher matcher;
  matchOnTwoThreadsWhereOffered(matcher);
  std::size_t frame = 0;
  for (auto _ : state) {
    const std::size_t i = frame++ % d.rectifiedLeft.size();
    const orbis::FrameFeatures f =
        orbis::extractStereo(left, right, d.rectifiedLeft[i], d.rectifiedRight[i], *d.camera, matcher);
    benchmark::DoNotOptimize(f.uRight.data());
  }
}

// Both images of a rectified pair: extraction and stereo matching (paper Sec. III-A).
void BM_OrbisStereo(benchmark::State& state, std::size_t which) {
  const Dataset& d = datasets()[which];
  orbis::OrbExtractor left(paramsFor(d)), right(paramsFor(d));
  std::vector<orbis::Keypoint> kl, kr;
  std::vector<orbis::OrbDescriptor> dl, dr;
  std::vector<float> uRight, depth;
  orbis::StereoMatcher matcher;
  std::size_t frame = 0;
  double matched = 0, total = 0;
  for (auto _ : state) {
    const std::size_t i = frame++ % d.rectifiedLeft.size();
    left.extract(d.rectifiedLeft[i], kl, dl);
    right.extract(d.rectifiedRight[i], kr, dr);
    matcher.match({kl, dl, left.pyramid()}, {kr, dr, right.pyramid()}, left.scaleLevels(), bfOf(d), baselineOf(d), uRight, depth);
    matched += static_cast<double>(std::count_if(uRight.begin(), uRight.end(), [](float u) { return u >= 0; }));
    total += static_cast<double>(kl.size());
  }
  state.counters["matched%"] = 100 * matched / total;
}

// The matching step alone, on features extracted once (what stereo adds to two extractions).
// With twoThreads, on the two threads the stereo sensor gives it (wall time).
void BM_OrbisStereoMatchOnly(benchmark::State& state, std::size_t which, bool twoThreads) {
  const Dataset& d = datasets()[which];
  orbis::OrbExtractor left(paramsFor(d)), right(paramsFor(d));
  std::vector<orbis::Keypoint> kl, kr;
  std::vector<orbis::OrbDescriptor> dl, dr;
  left.extract(d.rectifiedLeft[0], kl, dl);
  right.extract(d.rectifiedRight[0], kr, dr);
  std::vector<float> uRight, depth;
  orbis::StereoMatcher matcher;
  if (twoThreads) matchOnTwoThreadsWhereOffered(matcher);
  for (auto _ : state) {
    matcher.match({kl, dl, left.pyramid()}, {kr, dr, right.pyramid()}, left.scaleLevels(), bfOf(d), baselineOf(d), uRight, depth);
    benchmark::DoNotOptimize(uRight.data());
  }
}

// The same with cv::ORB on both images and OpenCV's brute-force cross-checked matcher, kept
// when the rows agree within 2 px and the disparity is positive: a plain OpenCV pipeline.
void BM_CvOrbStereo(benchmark::State& state, std::size_t which) {
  const Dataset& d = datasets()[which];
  auto orb = cvOrbFor(d);
  cv::BFMatcher bf(cv::NORM_HAMMING, true);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  std::vector<cv::DMatch> matches;
  std::size_t frame = 0;
  double matched = 0, total = 0;
  for (auto _ : state) {
    const std::size_t i = frame++ % d.rectifiedLeft.size();
    orb->detectAndCompute(d.rectifiedLeft[i], cv::noArray(), kl, dl);
    orb->detectAndCompute(d.rectifiedRight[i], cv::noArray(), kr, dr);
    bf.match(dl, dr, matches);
    for (const cv::DMatch& m : matches) {
      const cv::Point2f a = kl[static_cast<std::size_t>(m.queryIdx)].pt, b = kr[static_cast<std::size_t>(m.trainIdx)].pt;
      matched += std::abs(a.y - b.y) < 2.f && a.x >= b.x;
    }
    total += static_cast<double>(kl.size());
  }
  state.counters["matched%"] = 100 * matched / total;
}

// Share of 32x32 cells of the image holding at least one keypoint.
template <class Points>
double coverage(const Points& points, cv::Size size) {
  const int cols = (size.width + 31) / 32, rows = (size.height + 31) / 32;
  std::vector<char> hit(static_cast<std::size_t>(cols * rows), 0);
  for (const auto& p : points) {
    const int cx = std::clamp(static_cast<int>(p.x) / 32, 0, cols - 1);
    const int cy = std::clamp(static_cast<int>(p.y) / 32, 0, rows - 1);
    hit[static_cast<std::size_t>(cy * cols + cx)] = 1;
  }
  return static_cast<double>(std::count(hit.begin(), hit.end(), 1)) / static_cast<double>(hit.size());
}

struct Xy {
  float x, y;
};

void printCoverage() {
  std::printf("\nCoverage: share of 32x32 px cells with >= 1 keypoint (mean over %d frames)\n", kFrames);
  std::printf("%-16s %8s %10s %10s %10s %10s\n", "dataset", "budget", "orbis kps", "cv kps", "orbis cov", "cv cov");
  for (const Dataset& d : datasets()) {
    orbis::OrbExtractor extractor(paramsFor(d));
    auto orb = cvOrbFor(d);
    double ours = 0, theirs = 0, oursN = 0, theirsN = 0;
    for (const cv::Mat& img : d.left) {
      std::vector<orbis::Keypoint> kps;
      std::vector<orbis::OrbDescriptor> desc;
      extractor.extract(img, kps, desc);
      std::vector<Xy> pts;
      for (const auto& k : kps) pts.push_back({k.u, k.v});
      ours += coverage(pts, img.size());
      oursN += static_cast<double>(kps.size());
      std::vector<cv::KeyPoint> cvKps;
      cv::Mat cvDesc;
      orb->detectAndCompute(img, cv::noArray(), cvKps, cvDesc);
      std::vector<Xy> cvPts;
      for (const auto& k : cvKps) cvPts.push_back({k.pt.x, k.pt.y});
      theirs += coverage(cvPts, img.size());
      theirsN += static_cast<double>(cvKps.size());
    }
    const double n = static_cast<double>(d.left.size());
    std::printf("%-16s %8d %10.0f %10.0f %9.1f%% %9.1f%%\n", d.name.c_str(), d.features, oursN / n,
                theirsN / n, 100 * ours / n, 100 * theirs / n);
  }
}

// Collects per-benchmark CPU and wall time, keyed by the registered name (without the
// /real_time or /manual_time suffix), so the ratios can be printed after the normal table.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    // With --benchmark_repetitions the median of the repetitions (aggregates are reported after
    // the repetitions, so it overwrites them); otherwise the single run.
    for (const Run& r : runs)
      if ((r.run_type == Run::RT_Iteration && r.iterations > 0) ||
          (r.run_type == Run::RT_Aggregate && r.aggregate_name == "median"))
      {
        times[r.run_name.function_name] = r.GetAdjustedCPUTime();
        wallTimes[r.run_name.function_name] = r.GetAdjustedRealTime();
      }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> times, wallTimes;
};

}  // namespace

// Registration helpers: one thread's CPU time, several threads' wall time, or the paced rows'
// manually timed extraction (60 frames, a frame period apart).
template <class... Args>
void cpuRow(const std::string& name, Args&&... args) {
  benchmark::RegisterBenchmark(name.c_str(), std::forward<Args>(args)...)->Unit(benchmark::kMillisecond);
}
template <class... Args>
void wallRow(const std::string& name, Args&&... args) {
  benchmark::RegisterBenchmark(name.c_str(), std::forward<Args>(args)...)->Unit(benchmark::kMillisecond)->UseRealTime();
}
template <class... Args>
void pacedRow(const std::string& name, Args&&... args) {
  benchmark::RegisterBenchmark(name.c_str(), std::forward<Args>(args)...)
      ->Unit(benchmark::kMillisecond)
      ->UseManualTime()
      ->Iterations(60);
}

int main(int argc, char** argv) {
  cv::setNumThreads(1);  // both sides single-threaded, so the ratio compares algorithms
  for (std::size_t i = 0; i < datasets().size(); ++i) {
    const std::string& n = datasets()[i].name;
    cpuRow("Extract/orbis/" + n, BM_OrbisExtract, i, false);
    cpuRow("ExtractCvFast/orbis/" + n, BM_OrbisExtract, i, true);
    cpuRow("Extract/cvORB/" + n, BM_CvOrbExtract, i);
    wallRow("ExtractTwoThreads/orbis/" + n, BM_OrbisExtractTwoThreads, i, Load::kNone);
    wallRow("ExtractTwoThreadsLoaded/orbis/" + n, BM_OrbisExtractTwoThreads, i, Load::kBusy);
    wallRow("ExtractTwoThreadsLoadedBackground/orbis/" + n, BM_OrbisExtractTwoThreads, i, Load::kBusyBackground);
    pacedRow("ExtractPaced/orbis/" + n, BM_OrbisExtractPaced, i, false);
    pacedRow("ExtractTwoThreadsPaced/orbis/" + n, BM_OrbisExtractPaced, i, true);
    pacedRow("ExtractPaced/cvORB/" + n, BM_CvOrbExtractPaced, i);
  }
  for (std::size_t i = 0; i < datasets().size(); ++i) {
    if (datasets()[i].rectifiedLeft.empty()) continue;
    const std::string& n = datasets()[i].name;
    cpuRow("Stereo/orbis/" + n, BM_OrbisStereo, i);
    cpuRow("Stereo/cvORB/" + n, BM_CvOrbStereo, i);
    cpuRow("StereoMatchOnly/orbis/" + n, BM_OrbisStereoMatchOnly, i, false);
    wallRow("StereoMatchOnlyTwoThreads/orbis/" + n, BM_OrbisStereoMatchOnly, i, true);
    wallRow("StereoTwoThreads/orbis/" + n, BM_OrbisStereoTwoThreads, i, Load::kNone);
    wallRow("StereoTwoThreadsLoaded/orbis/" + n, BM_OrbisStereoTwoThreads, i, Load::kBusy);
    wallRow("StereoTwoThreadsLoadedBackground/orbis/" + n, BM_OrbisStereoTwoThreads, i, Load::kBusyBackground);
  }
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\nTime ratio orbis / cv::ORB (same budget, same run; <= 1.00 is the goal)\n");
  // One line "dataset what ratio" when both rows ran (a filter may have left either out).
  auto ratio = [](const std::map<std::string, double>& times, const std::string& dataset, const std::string& what,
                  const std::string& numerator, const std::string& denominator) {
    const auto a = times.find(numerator + dataset), b = times.find(denominator + dataset);
    if (a != times.end() && b != times.end())
      std::printf("%-16s %s %.3f\n", dataset.c_str(), what.c_str(), a->second / b->second);
  };
  for (const Dataset& d : datasets()) {
    const auto& cpu = reporter.times;
    const auto& wall = reporter.wallTimes;
    const std::string& n = d.name;
    const std::string asSlam = "extraction as SLAM runs it";
    ratio(cpu, n, "extraction", "Extract/orbis/", "Extract/cvORB/");
    ratio(cpu, n, "extraction with cv::FAST instead of our score map", "ExtractCvFast/orbis/", "Extract/cvORB/");
    ratio(cpu, n, "stereo pair (2 extractions + matching)", "Stereo/orbis/", "Stereo/cvORB/");
    ratio(wall, n, asSlam + (d.colour.empty() ? " (two threads, wall)" : " (two threads, colour input, wall)"),
          "ExtractTwoThreads/orbis/", "Extract/cvORB/");
    ratio(wall, n, "stereo pair as SLAM runs it (two threads, wall)", "StereoTwoThreads/orbis/", "Extract/cvORB/");
    // Under load: the wall time against the same rows without it (how much a busy machine costs).
    ratio(wall, n, asSlam + ", two busy threads beside / idle (wall)", "ExtractTwoThreadsLoaded/orbis/",
          "ExtractTwoThreads/orbis/");
    ratio(wall, n, asSlam + ", two busy background threads beside / idle (wall)",
          "ExtractTwoThreadsLoadedBackground/orbis/", "ExtractTwoThreads/orbis/");
    // Paced: a frame period between images, against the same extraction back to back.
    ratio(wall, n, asSlam + ", paced / back to back (wall)", "ExtractTwoThreadsPaced/orbis/", "ExtractTwoThreads/orbis/");
    ratio(wall, n, "extraction on one thread, paced / back to back (wall)", "ExtractPaced/orbis/", "Extract/orbis/");
    ratio(wall, n, "cv::ORB paced / back to back (wall)", "ExtractPaced/cvORB/", "Extract/cvORB/");
    ratio(wall, n, "stereo pair as SLAM runs it, two busy threads beside / idle (wall)", "StereoTwoThreadsLoaded/orbis/",
          "StereoTwoThreads/orbis/");
    ratio(wall, n, "stereo pair as SLAM runs it, two busy background threads beside / idle (wall)",
          "StereoTwoThreadsLoadedBackground/orbis/", "StereoTwoThreads/orbis/");
  }
  printCoverage();
  benchmark::Shutdown();
  return 0;
}
