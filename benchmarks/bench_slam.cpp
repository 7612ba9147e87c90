// benchmarks/bench_slam — end-to-end SLAM timing per mode and per stage, as ratios to cv::ORB.
//
// For each shared slice and mode (RGB-D, stereo, monocular) the program alternates, --runs times:
// cv::ORB's detectAndCompute over the sequence's (left/colour) frames on one OpenCV thread, with
// the mode's feature budget (the in-process yardstick: what getting features costs with OpenCV on
// this machine at this moment), then a threaded `orbis run` of the same sequence (runDataset,
// the dataset's default budget and rate). It prints, per mode, the medians over the runs of each
// stage's per-frame median and p95 (StageTimer, as report.json), the per-frame time as the issue
// 35 table defines it (ORB extraction + tracking medians) and its ratio to cv::ORB's median.
// The last column divides by ORB-SLAM2's median tracking time measured in an earlier session on
// this machine (issue 35): a fixed external figure, not re-measured here, so it moves with the
// machine's load while the cv::ORB ratio does not.
// --realtime adds runs of every case paced at the frames' timestamps (RunOptions::realtime), as
// ORB-SLAM2's example programs feed them (they sleep until the next timestamp), and prints the
// per-frame time as those programs measure it: the whole tracking call (Slam::track, from the
// frame fed to its pose), median and p95. For the monocular cases it adds the live-camera
// figures (SlamOptions::liveCamera): the wait for mapping after a keyframe (median, p95),
// keyframes, local BA time, and the Sim(3)-aligned ATE and scale (estimate to ground truth).
// Data: --data DIR, else ORBIS_DATA, else ../shared/datasets; an absent slice is skipped.
// Usage and options: docs/guide/speed.md.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "orbis/adapters/dataset.hpp"
#include "orbis/eval/metrics.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/util/allocator.hpp"
#include "orbis/util/error.hpp"

namespace fs = std::filesystem;
using namespace orbis;

namespace {

struct Case {
  std::string label;
  DatasetKind kind;
  fs::path path;
  std::optional<SensorKind> sensor;  // empty: the dataset's own
  int features;                      // the dataset's default budget (dataset_runner.cpp)
  double orbSlam2Ms;                 // issue 35's ORB-SLAM2 median, 0 when not measured
  std::optional<fs::path> settings;  // ORB-SLAM2 settings YAML, as `orbis run --settings`
};

struct Options {
  fs::path data;
  int runs = 3;
  bool realtime = false;
  bool realtimeOnly = false;
  std::vector<std::string> only;
  std::vector<Case> extra;
  fs::path work = fs::temp_directory_path() / "orbis_bench_slam";
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double percentile95(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(v.size())))];
}

int defaultFeatures(DatasetKind kind) {
  switch (kind) {
    case DatasetKind::TumRgbd: return 1000;
    case DatasetKind::Euroc: return 1200;
    case DatasetKind::Kitti:
    case DatasetKind::KittiRaw: return 2000;
  }
  return 1000;
}

std::vector<Case> sharedSlices(const fs::path& data) {
  const auto mono = std::optional<SensorKind>(SensorKind::Monocular);
  return {
      {"teddy rgbd", DatasetKind::TumRgbd, data / "tum_fr3_teddy_200", std::nullopt, 1000, 15.0},
      {"euroc stereo", DatasetKind::Euroc, data / "euroc_V1_01_easy_95", std::nullopt, 1200, 26.8},
      {"kitti06 stereo", DatasetKind::Kitti, data / "kitti_06_first51", std::nullopt, 2000, 53.1},
      {"kitti0102 stereo", DatasetKind::Kitti, data / "kitti_0102_first51", std::nullopt, 2000, 50.6},
      {"teddy mono", DatasetKind::TumRgbd, data / "tum_fr3_teddy_200", mono, 1000, 12.7},
      {"kitti06 mono", DatasetKind::Kitti, data / "kitti_06_first51", mono, 2000, 18.7},
  };
}

// cv::ORB with ORB-SLAM's pyramid (8 levels, 1.2) and the case's budget, on one thread, per frame.
std::vector<double> cvOrbMs(DatasetReader& reader, int features) {
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  auto orb = cv::ORB::create(features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, 20);
  std::vector<double> ms;
  for (std::size_t i = 0; i < reader.size(); ++i) {
    const DatasetFrame f = reader.frame(i);
    if (f.left.empty()) continue;
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors, grey;
    const auto t0 = std::chrono::steady_clock::now();
    if (f.left.channels() == 3) cv::cvtColor(f.left, grey, cv::COLOR_BGR2GRAY);
    else grey = f.left;
    orb->detectAndCompute(grey, cv::noArray(), keypoints, descriptors);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  cv::setNumThreads(threads);
  return ms;
}

// One stage's per-run medians and p95s (over the runs of a case).
struct StageRuns {
  std::vector<double> median, p95;
  std::size_t count = 0;
};

struct CaseResult {
  std::vector<double> cvOrbMedian;
  std::vector<std::string> stageOrder;
  std::map<std::string, StageRuns> stages;
  std::vector<double> keyFrames, ateMm, scale, seconds;
  std::vector<double> callMedian, callP95;  // the whole tracking call (paced runs only)
  std::size_t frames = 0;
};

void addReport(CaseResult& result, const RunReport& report, const fs::path& out, DatasetReader& reader) {
  for (const StageStats& s : report.timing) {
    auto [it, inserted] = result.stages.try_emplace(s.stage);
    if (inserted) result.stageOrder.push_back(s.stage);
    it->second.median.push_back(s.medianMs);
    it->second.p95.push_back(s.p95Ms);
    it->second.count = s.count;
  }
  result.keyFrames.push_back(static_cast<double>(report.stats.keyFrames));
  result.seconds.push_back(report.seconds);
  result.callMedian.push_back(report.latency.medianMs);
  result.callP95.push_back(report.latency.p95Ms);
  result.frames = report.stats.frames;
  if (report.ateRmse) result.ateMm.push_back(*report.ateRmse * 1000);
  // The similarity that aligns the estimate to the ground truth: its scale is the map's unit in
  // metres (monocular), 1 for a metric sensor up to the alignment's own error.
  if (report.ateAlignment == "sim3" && !reader.groundTruth().empty()) {
    try {
      const Trajectory estimate = readTrajectory(out / "trajectory.txt", TrajectoryFormat::Tum);
      const eval::AteResult ate = eval::computeAte(reader.groundTruth(), estimate, {eval::Alignment::Sim3, 0.02});
      result.scale.push_back(ate.alignment.scale());
    } catch (const Error&) {
    }
  }
}

double stageMedian(const CaseResult& r, const std::string& stage) {
  const auto it = r.stages.find(stage);
  return it == r.stages.end() ? 0 : median(it->second.median);
}
double stageP95(const CaseResult& r, const std::string& stage) {
  const auto it = r.stages.find(stage);
  return it == r.stages.end() ? 0 : median(it->second.p95);
}

void printStages(const Case& c, const CaseResult& r, bool realtime) {
  std::printf("\n%s%s: %zu frames, %d runs, keyframes %.0f, cv::ORB median %.2f ms\n", c.label.c_str(),
              realtime ? " (realtime)" : "", r.frames, static_cast<int>(r.keyFrames.size()), median(r.keyFrames),
              median(r.cvOrbMedian));
  std::printf("  %-34s %6s %9s %9s %10s\n", "stage", "count", "median", "p95", "med/cvORB");
  const double ref = median(r.cvOrbMedian);
  for (const std::string& name : r.stageOrder) {
    const double m = stageMedian(r, name);
    std::printf("  %-34s %6zu %9.3f %9.3f %10.3f\n", name.c_str(), r.stages.at(name).count, m, stageP95(r, name),
                ref > 0 ? m / ref : 0);
  }
}

std::string loadNow() {
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) < 0) return "?";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2f %.2f %.2f", load[0], load[1], load[2]);
  return buf;
}

CaseResult runCase(const Case& c, const Options& options, bool realtime) {
  DatasetOptions datasetOptions;
  datasetOptions.sensor = c.sensor;
  datasetOptions.tolerateBadFrames = true;
  CaseResult result;
  for (int run = 0; run < options.runs; ++run) {
    auto reader = openDataset(c.kind, c.path, datasetOptions);
    result.cvOrbMedian.push_back(median(cvOrbMs(*reader, c.features)));
    RunOptions run_options;
    run_options.vocabulary = defaultVocabularyPath();
    run_options.outDir = options.work / (c.label + (realtime ? " realtime " : " ") + std::to_string(run));
    run_options.progress = false;
    run_options.realtime = realtime;
    run_options.settings = c.settings;
    const RunReport report = runDataset(*reader, run_options);
    addReport(result, report, run_options.outDir, *reader);
    std::fprintf(stderr, "bench_slam: %s%s run %d: %.1f s, load %s\n", c.label.c_str(), realtime ? " realtime" : "",
                 run + 1, report.seconds, loadNow().c_str());
  }
  return result;
}

bool selected(const Case& c, const Options& options) {
  if (options.only.empty()) return true;
  return std::any_of(options.only.begin(), options.only.end(),
                     [&](const std::string& s) { return c.label.find(s) != std::string::npos; });
}

// --sequence KIND:PATH[:SENSOR], labelled by the folder's name.
Case parseSequence(const std::string& spec) {
  const auto first = spec.find(':');
  if (first == std::string::npos) throw Error("argument --sequence", "", "expects KIND:PATH[:SENSOR], got '" + spec + "'");
  const auto last = spec.rfind(':');
  const DatasetKind kind = parseDatasetKind(spec.substr(0, first), "argument --sequence");
  std::optional<SensorKind> sensor;
  std::string path = spec.substr(first + 1);
  if (last != first) {
    const std::string tail = spec.substr(last + 1);
    if (tail == "mono" || tail == "stereo" || tail == "rgbd") {
      sensor = parseSensorKind(tail, "argument --sequence");
      path = spec.substr(first + 1, last - first - 1);
    }
  }
  if (!fs::exists(path)) throw fileError(path, "no such sequence folder (argument --sequence)");
  std::string label = fs::path(path).filename().string();
  if (label.empty()) label = fs::path(path).parent_path().filename().string();
  label += sensor == SensorKind::Monocular ? " mono" : "";
  // A folder written by `orbis synth` carries its calibration: settings.yaml, settings_mono.yaml.
  std::optional<fs::path> settings;
  const fs::path yaml = fs::path(path) / (sensor == SensorKind::Monocular ? "settings_mono.yaml" : "settings.yaml");
  if (fs::exists(yaml)) settings = yaml;
  return {label, kind, path, sensor, defaultFeatures(kind), 0, settings};
}

void usage() {
  std::printf(
      "bench_slam [--runs N] [--only LABEL]... [--sequence KIND:PATH[:SENSOR]]... [--realtime] [--realtime-only]\n"
      "           [--data DIR] [--work DIR]\n"
      "Per-mode, per-stage medians and p95 of threaded orbis runs over the shared slices, with the ratio to\n"
      "cv::ORB's extraction measured alternately in the same process (docs/guide/speed.md).\n"
      "  --runs N            runs per case, alternating cv::ORB and orbis (default 3)\n"
      "  --only LABEL        only cases whose label contains LABEL (repeatable), e.g. mono, kitti06\n"
      "  --sequence SPEC     add a sequence: KIND (tum, euroc, kitti) : PATH [: mono|stereo|rgbd]; its\n"
      "                      settings.yaml (settings_mono.yaml for mono) is used when present\n"
      "  --realtime          also run every case paced at its timestamps (as ORB-SLAM2's examples): per-frame\n"
      "                      time of the whole tracking call; for monocular also wait for mapping, local BA, ATE, scale\n"
      "  --realtime-only     only the paced runs\n"
      "  --data DIR          the shared datasets (default $ORBIS_DATA, else ../shared/datasets)\n"
      "  --work DIR          scratch folder for the runs' outputs (default: the temp folder)\n");
}

Options parseArgs(int argc, char** argv) {
  Options o;
  if (const char* env = std::getenv("ORBIS_DATA"); env && *env) o.data = env;
  else o.data = ORBIS_DEFAULT_DATA_DIR;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw Error("argument " + a, "", "expects a value");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage();
      std::exit(0);
    } else if (a == "--runs") {
      o.runs = std::atoi(value().c_str());
      if (o.runs < 1) throw Error("argument --runs", "", "expects a positive count");
    } else if (a == "--only") {
      o.only.push_back(value());
    } else if (a == "--sequence") {
      o.extra.push_back(parseSequence(value()));
    } else if (a == "--realtime") {
      o.realtime = true;
    } else if (a == "--realtime-only") {
      o.realtime = o.realtimeOnly = true;
    } else if (a == "--data") {
      o.data = value();
    } else if (a == "--work") {
      o.work = value();
    } else {
      throw Error("argument " + a, "", "unknown option (see --help)");
    }
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) try {
  // Every SLAM run sets these allocator settings (SlamCore); set before the first cv::ORB pass too,
  // or that pass alone re-faults its buffers on every frame and the first case's yardstick comes
  // out about 2.7 times slower (docs/notes/2026-11-29-speed-slot-bits.md).
  retainFreedMemory();
  const Options options = parseArgs(argc, argv);
  fs::create_directories(options.work);
  std::vector<Case> cases;
  for (const Case& c : sharedSlices(options.data))
    if (fs::exists(c.path)) cases.push_back(c);
    else std::fprintf(stderr, "bench_slam: %s skipped (%s not found)\n", c.label.c_str(), c.path.c_str());
  cases.insert(cases.end(), options.extra.begin(), options.extra.end());
  std::erase_if(cases, [&](const Case& c) { return !selected(c, options); });
  std::printf("bench_slam: %d runs per case, load at start %s\n", options.runs, loadNow().c_str());

  struct Row {
    Case c;
    CaseResult r;
  };
  std::vector<Row> rows, live;
  if (!options.realtimeOnly)
    for (const Case& c : cases) {
      rows.push_back({c, runCase(c, options, false)});
      printStages(c, rows.back().r, false);
    }
  if (options.realtime)
    for (const Case& c : cases) {
      live.push_back({c, runCase(c, options, true)});
      printStages(c, live.back().r, true);
    }

  if (!rows.empty()) {
    std::printf("\nper-frame time, threaded (ORB extraction + tracking medians, as issue 35), median over %d runs\n",
                options.runs);
    std::printf("%-18s %8s %9s %9s %9s %9s %10s %12s\n", "case", "cv::ORB", "extract", "track", "frame", "frame p95",
                "/ cv::ORB", "/ ORB-SLAM2*");
    for (const auto& [c, r] : rows) {
      const double cv = median(r.cvOrbMedian);
      const double extract = stageMedian(r, "tracking: ORB extraction"), track = stageMedian(r, "tracking: total");
      const double frame = extract + track;
      const double frameP95 = stageP95(r, "tracking: ORB extraction") + stageP95(r, "tracking: total");
      char external[16] = "-";
      if (c.orbSlam2Ms > 0) std::snprintf(external, sizeof external, "%.2f", frame / c.orbSlam2Ms);
      std::printf("%-18s %8.2f %9.2f %9.2f %9.2f %9.2f %10.3f %12s\n", c.label.c_str(), cv, extract, track, frame,
                  frameP95, cv > 0 ? frame / cv : 0, external);
    }
    std::printf("* ORB-SLAM2's medians from issue 35 (an earlier session, same machine class), not re-measured.\n");
  }
  if (!live.empty()) {
    std::printf("\nper-frame time, paced at the timestamps (--realtime, as ORB-SLAM2's example programs run): the\n"
                "whole tracking call (frame fed to pose: extraction, tracking, any wait), median over %d runs\n",
                options.runs);
    std::printf("%-18s %8s %9s %9s %9s %9s %10s %12s\n", "case", "cv::ORB", "extract", "track", "call", "call p95",
                "/ cv::ORB", "/ ORB-SLAM2*");
    for (const auto& [c, r] : live) {
      const double cv = median(r.cvOrbMedian), call = median(r.callMedian);
      char external[16] = "-";
      if (c.orbSlam2Ms > 0) std::snprintf(external, sizeof external, "%.2f", call / c.orbSlam2Ms);
      std::printf("%-18s %8.2f %9.2f %9.2f %9.2f %9.2f %10.3f %12s\n", c.label.c_str(), cv,
                  stageMedian(r, "tracking: ORB extraction"), stageMedian(r, "tracking: total"), call,
                  median(r.callP95), cv > 0 ? call / cv : 0, external);
    }
    std::printf("* ORB-SLAM2's medians from issue 35 (an earlier session, same machine class), not re-measured.\n");
    std::printf("\nlive camera (--realtime), monocular, median over %d runs\n", options.runs);
    std::printf("%-18s %5s %11s %9s %9s %11s %9s %8s\n", "case", "KFs", "wait med", "wait p95", "local BA",
                "local BA p95", "ATE mm", "scale");
    for (const auto& [c, r] : live) {
      if (c.sensor != SensorKind::Monocular) continue;
      std::printf("%-18s %5.0f %11.2f %9.2f %9.2f %11.2f %9.1f %8.4f\n", c.label.c_str(), median(r.keyFrames),
                  stageMedian(r, "tracking: wait for mapping"), stageP95(r, "tracking: wait for mapping"),
                  stageMedian(r, "mapping: local BA"), stageP95(r, "mapping: local BA"), median(r.ateMm),
                  median(r.scale));
    }
  }
  std::printf("load at end %s\n", loadNow().c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_slam: %s\n", e.what());
  return 1;
}
