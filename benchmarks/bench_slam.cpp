// End-to-end SLAM timing: per-frame tracking time (ORB extraction + tracking, what the caller of
// track() waits for) over whole real sequences, in threaded (real-time) and deterministic mode.
// Frames are decoded before the clock starts. The in-process reference is cv::ORB's
// detectAndCompute with the same feature budget on the same frames (the bare cost of getting
// features with OpenCV), so the ratio says how many "OpenCV extractions" one tracked frame costs.
// The table after the benchmarks also gives the ratio to ORB-SLAM2's median tracking time on
// TUM teddy measured on this machine class (30.5 ms, issue 7) — a fixed external figure.
// Data: ORBIS_DATA or ../shared/datasets; an absent sequence is skipped.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <opencv2/features2d.hpp>

#include "orbis/adapters/dataset.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/system/slam.hpp"

namespace fs = std::filesystem;
using namespace orbis;

namespace {

constexpr double kOrbSlam2TeddyMedianMs = 30.5;

fs::path dataRoot() {
  if (const char* env = std::getenv("ORBIS_DATA"); env && *env) return env;
  return ORBIS_DEFAULT_DATA_DIR;
}

struct Loaded {
  std::unique_ptr<DatasetReader> reader;
  std::vector<DatasetFrame> frames;
};

Loaded& load(DatasetKind kind, const char* folder) {
  static std::map<std::string, Loaded> cache;
  auto [it, inserted] = cache.try_emplace(folder);
  if (inserted && fs::exists(dataRoot() / folder)) {
    it->second.reader = openDataset(kind, dataRoot() / folder);
    for (std::size_t i = 0; i < it->second.reader->size(); ++i) {
      DatasetFrame f = it->second.reader->frame(i);
      const bool complete = !f.left.empty() && (kind == DatasetKind::TumRgbd ? !f.depth.empty() : !f.right.empty());
      if (complete) it->second.frames.push_back(std::move(f));
    }
  }
  return it->second;
}

struct Summary {
  double medianMs = 0, meanMs = 0, p95Ms = 0;
};
std::map<std::string, Summary> gSlam, gCvOrb;

Summary summarise(std::vector<double> ms) {
  Summary s;
  if (ms.empty()) return s;
  std::sort(ms.begin(), ms.end());
  s.medianMs = ms[ms.size() / 2];
  s.p95Ms = ms[std::min(ms.size() - 1, ms.size() * 95 / 100)];
  for (double v : ms) s.meanMs += v / static_cast<double>(ms.size());
  return s;
}

std::shared_ptr<const OrbVocabulary> vocabulary() {
  static auto voc = std::make_shared<const OrbVocabulary>(OrbVocabulary::load(defaultVocabularyPath()));
  return voc;
}

template <class Sensor>
void runSequence(benchmark::State& state, DatasetKind kind, const char* folder, int features, double fps,
                 bool deterministic) {
  Loaded& data = load(kind, folder);
  if (data.frames.empty()) {
    state.SkipWithError((std::string(folder) + " not found under ORBIS_DATA").c_str());
    return;
  }
  // Monocular runs on the colour/left camera's pinhole of the same sequence.
  const typename Sensor::Camera camera = [&]() -> typename Sensor::Camera {
    if constexpr (Sensor::kKind == SensorKind::Monocular)
      return std::visit([](const auto& c) { return pinholeOf(c); }, data.reader->camera());
    else return std::get<typename Sensor::Camera>(data.reader->camera());
  }();
  OrbParams orb;
  orb.features = features;
  std::vector<double> perFrameMs;
  for (auto _ : state) {
    SlamOptions options;
    options.deterministic = deterministic;
    options.fps = fps;
    Slam<Sensor> slam(camera, orb, vocabulary(), options);
    perFrameMs.clear();
    for (const DatasetFrame& f : data.frames) {
      typename Sensor::Input input;
      if constexpr (std::is_same_v<Sensor, Rgbd>) input = {f.timestamp, f.left, f.depth};
      else if constexpr (std::is_same_v<Sensor, Monocular>) input = {f.timestamp, f.left};
      else input = {f.timestamp, f.left, f.right};
      const auto t0 = std::chrono::steady_clock::now();
      slam.track(input);
      perFrameMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    slam.shutdown();
  }
  const Summary s = summarise(perFrameMs);
  const std::string key = std::string(folder) + (Sensor::kKind == SensorKind::Monocular ? " mono" : "") +
                          (deterministic ? " deterministic" : " threaded");
  gSlam[key] = s;
  state.counters["median_ms"] = s.medianMs;
  state.counters["p95_ms"] = s.p95Ms;
  state.counters["frames"] = static_cast<double>(perFrameMs.size());
}

void runCvOrb(benchmark::State& state, DatasetKind kind, const char* folder, int features) {
  Loaded& data = load(kind, folder);
  if (data.frames.empty()) {
    state.SkipWithError((std::string(folder) + " not found under ORBIS_DATA").c_str());
    return;
  }
  auto orb = cv::ORB::create(features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, 20);
  std::vector<double> perFrameMs;
  for (auto _ : state) {
    perFrameMs.clear();
    for (const DatasetFrame& f : data.frames) {
      cv::Mat grey = f.left;
      std::vector<cv::KeyPoint> keypoints;
      cv::Mat descriptors;
      const auto t0 = std::chrono::steady_clock::now();
      if (grey.channels() == 3) cv::cvtColor(grey, grey, cv::COLOR_BGR2GRAY);
      orb->detectAndCompute(grey, cv::noArray(), keypoints, descriptors);
      perFrameMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      benchmark::DoNotOptimize(descriptors.data);
    }
  }
  gCvOrb[folder] = summarise(perFrameMs);
  state.counters["median_ms"] = gCvOrb[folder].medianMs;
}

constexpr const char* kTeddy = "tum_fr3_teddy_200";
constexpr const char* kEuroc = "euroc_V1_01_easy_95";
constexpr const char* kKitti = "kitti_06_first51";

void BM_TeddyRgbdThreaded(benchmark::State& s) { runSequence<Rgbd>(s, DatasetKind::TumRgbd, kTeddy, 1000, 30, false); }
void BM_TeddyRgbdDeterministic(benchmark::State& s) { runSequence<Rgbd>(s, DatasetKind::TumRgbd, kTeddy, 1000, 30, true); }
void BM_TeddyMonoThreaded(benchmark::State& s) { runSequence<Monocular>(s, DatasetKind::TumRgbd, kTeddy, 1000, 30, false); }
void BM_TeddyCvOrb(benchmark::State& s) { runCvOrb(s, DatasetKind::TumRgbd, kTeddy, 1000); }
void BM_EurocStereoThreaded(benchmark::State& s) { runSequence<Stereo>(s, DatasetKind::Euroc, kEuroc, 1200, 20, false); }
void BM_EurocCvOrb(benchmark::State& s) { runCvOrb(s, DatasetKind::Euroc, kEuroc, 1200); }
void BM_KittiStereoThreaded(benchmark::State& s) { runSequence<Stereo>(s, DatasetKind::Kitti, kKitti, 2000, 10, false); }
void BM_KittiCvOrb(benchmark::State& s) { runCvOrb(s, DatasetKind::Kitti, kKitti, 2000); }

BENCHMARK(BM_TeddyCvOrb)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_TeddyRgbdThreaded)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_TeddyRgbdDeterministic)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_TeddyMonoThreaded)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_EurocCvOrb)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_EurocStereoThreaded)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_KittiCvOrb)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_KittiStereoThreaded)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::printf("\nper-frame tracking time (ORB extraction + tracking), last iteration, ms\n");
  std::printf("%-36s %8s %8s %8s %14s %14s\n", "run", "median", "mean", "p95", "/ cv::ORB med", "/ ORB-SLAM2");
  for (const auto& [key, s] : gSlam) {
    const std::string folder = key.substr(0, key.find(' '));
    const auto ref = gCvOrb.find(folder);
    const double cvRatio = ref != gCvOrb.end() && ref->second.medianMs > 0 ? s.medianMs / ref->second.medianMs : 0;
    char external[32] = "-";
    if (folder == kTeddy) std::snprintf(external, sizeof external, "%.2f", s.medianMs / kOrbSlam2TeddyMedianMs);
    std::printf("%-36s %8.2f %8.2f %8.2f %14.2f %14s\n", key.c_str(), s.medianMs, s.meanMs, s.p95Ms, cvRatio, external);
  }
  for (const auto& [folder, s] : gCvOrb)
    std::printf("cv::ORB detectAndCompute %-20s median %.2f ms\n", folder.c_str(), s.medianMs);
  return 0;
}
