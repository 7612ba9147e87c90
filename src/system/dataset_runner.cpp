#include "orbis/system/dataset_runner.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <thread>

#include "orbis/eval/metrics.hpp"
#include "orbis/io/dense_cloud.hpp"
#include "orbis/io/overview.hpp"
#include "orbis/io/ply.hpp"
#include "orbis/io/settings.hpp"
#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"
#include "orbis/util/progress.hpp"
#include "orbis/util/warnings.hpp"

#ifndef ORBIS_INSTALL_DATADIR
#define ORBIS_INSTALL_DATADIR ""
#endif
#ifndef ORBIS_SOURCE_DIR_FOR_DATA
#define ORBIS_SOURCE_DIR_FOR_DATA ""
#endif

namespace orbis {

namespace fs = std::filesystem;

fs::path defaultVocabularyPath() {
  const char* name = "vocabulary/orbis_orb_k10_L5.bin";
  if (const char* env = std::getenv("ORBIS_VOCABULARY"); env && *env) return env;
  for (const fs::path& base : {fs::path(ORBIS_SOURCE_DIR_FOR_DATA), fs::path(ORBIS_INSTALL_DATADIR) / "orbis"}) {
    if (base.empty()) continue;
    if (fs::exists(base / name)) return base / name;
  }
  throw Error("vocabulary", "", std::string("no shipped vocabulary found (looked for ") + name +
                                    " in the source tree and the install prefix); pass --vocab FILE");
}

namespace {

struct Defaults {
  int features;
  double fps;
};

Defaults datasetDefaults(DatasetKind kind) {
  switch (kind) {
    case DatasetKind::TumRgbd: return {1000, 30};
    case DatasetKind::Euroc: return {1200, 20};
    case DatasetKind::Kitti:
    case DatasetKind::KittiRaw: return {2000, 10};
  }
  return {1000, 30};
}

// One JSON object per line: {"kind": ..., name: value, ...}.
void writeEvents(const fs::path& file, const std::vector<StageEvent>& events) {
  std::ofstream out(file);
  for (const StageEvent& e : events) {
    out << "{\"kind\":\"" << e.kind << '"';
    for (const auto& [name, value] : e.values) out << ",\"" << name << "\":" << value;
    out << "}\n";
  }
}

// The atlas (docs/guide/atlas.md): maps with their frames, merges with their transform.
void writeAtlas(JsonWriter& w, const RunReport& r) {
  std::map<std::uint32_t, std::size_t> framesPerMap;
  for (std::uint32_t m : r.frameMaps) ++framesPerMap[m];
  w.key("maps").beginArray();
  for (const AtlasMapInfo& m : r.maps) {
    w.beginObject().field("id", std::size_t{m.id}).field("start_frame", m.startFrame).field("frames_tracked", framesPerMap[m.id]);
    w.field("keyframes", m.keyFrames).field("map_points", m.mapPoints).field("active", m.active);
    w.key("merged_into");
    if (m.merged) w.value(std::size_t{m.mergedInto});
    else w.null();
    w.endObject();
  }
  w.endArray();
  w.key("merges").beginArray();
  for (const MapMergeEvent& e : r.merges) {
    w.beginObject().field("frame", e.frameIndex).field("other_frame", e.otherFrameIndex);
    w.field("current_keyframe", e.current).field("other_keyframe", e.other);
    w.field("active_map", std::size_t{e.activeMap}).field("other_map", std::size_t{e.otherMap}).field("moved_map", std::size_t{e.movedMap});
    w.field("kept_map", std::size_t{e.keptMap}).field("moved_keyframes", e.movedKeyFrames).field("moved_points", e.movedPoints);
    w.field("inliers", e.inliers).field("fused_points", e.fusedPoints).field("scale", e.scale);
    w.key("rotation_wxyz").beginArray();
    for (int k = 0; k < 4; ++k) w.value(e.rotation[k]);
    w.endArray().key("translation").beginArray();
    for (int k = 0; k < 3; ++k) w.value(e.translation[k]);
    w.endArray().field("ms", e.milliseconds).endObject();
  }
  w.endArray();
}

void writeReport(const fs::path& file, const RunReport& r) {
  JsonWriter w;
  w.beginObject();
  w.field("dataset", r.dataset).field("sensor", r.sensor);
  w.field("frames", r.stats.frames).field("frames_tracked", r.stats.tracked).field("frames_lost", r.stats.lost);
  w.field("keyframes", r.stats.keyFrames).field("map_points", r.stats.mapPoints);
  // When the map started and, before that, why each frame did not start it.
  w.key("initialisation").beginObject().key("frame");
  if (r.stats.initialisedAtFrame) w.value(*r.stats.initialisedAtFrame);
  else w.null();
  w.key("waits").beginObject();
  for (const auto& [reason, frames] : r.stats.initialisationWaits) w.field(reason, frames);
  w.endObject().endObject();
  w.field("seconds", r.seconds);
  w.field("keyframes_loaded", r.keyFramesLoaded);
  if (r.loadedMapMetricScale) w.field("loaded_map_scale", *r.loadedMapMetricScale ? "metric" : "arbitrary");
  w.field("dense_points", r.densePoints);
  w.field("relocalisation_attempts", r.relocalisationAttempts).field("relocalisations", r.relocalisations);
  w.key("ate");
  if (r.ateRmse) {
    w.beginObject().field("rmse", *r.ateRmse).field("matched", r.ateMatched).field("alignment", r.ateAlignment);
    w.field("path_length", r.pathLength);
    w.key("keyframes");
    if (r.ateKeyFramesRmse) w.beginObject().field("rmse", *r.ateKeyFramesRmse).field("matched", r.ateKeyFramesMatched).endObject();
    else w.null();
    w.endObject();
  } else {
    w.null();
  }
  w.key("timing_ms").beginObject();
  for (const StageStats& s : r.timing) {
    w.key(s.stage).beginObject().field("count", s.count).field("mean", s.meanMs).field("median", s.medianMs);
    w.field("p95", s.p95Ms).field("max", s.maxMs).endObject();
  }
  w.endObject();
  // "scale": the current keyframe's map scale over the loop keyframe's (1 for metric sensors).
  w.key("loops").beginArray();
  for (const LoopClosureEvent& e : r.loopClosures) {
    w.beginObject().field("current_keyframe", e.current).field("loop_keyframe", e.loop).field("frame", e.frameIndex);
    w.field("inliers", e.inliers).field("scale", e.scale).endObject();
  }
  w.endArray();
  writeAtlas(w, r);
  // Repeated warnings folded (a few of each kind, then a count), as the program prints them.
  const std::vector<WarningKind> kinds = foldWarnings(r.warnings);
  w.key("warnings").beginArray();
  for (const auto& m : readableWarnings(kinds)) w.value(m);
  w.endArray();
  w.key("warning_counts").beginArray();
  for (const WarningKind& k : kinds) w.beginObject().field("kind", k.pattern).field("count", k.count).endObject();
  w.endArray().endObject();
  std::ofstream out(file);
  if (!out) throw fileError(file.string(), "cannot open for writing");
  out << w.str() << "\n";
}

template <class Sensor>
typename Sensor::Input makeInput(const DatasetFrame& f);

template <>
StereoInput makeInput<Stereo>(const DatasetFrame& f) {
  return {f.timestamp, f.left, f.right};
}
template <>
RgbdInput makeInput<Rgbd>(const DatasetFrame& f) {
  return {f.timestamp, f.left, f.depth};
}
template <>
MonocularInput makeInput<Monocular>(const DatasetFrame& f) {
  return {f.timestamp, f.left};
}
template <>
MonocularInput makeInput<MonocularFisheye>(const DatasetFrame& f) {
  return {f.timestamp, f.left};
}

bool inputComplete(const StereoInput& in) { return !in.left.empty() && !in.right.empty(); }
bool inputComplete(const RgbdInput& in) { return !in.image.empty() && !in.depth.empty(); }
bool inputComplete(const MonocularInput& in) { return !in.image.empty(); }

// A monocular camera's images may still carry lens distortion; the stereo and RGB-D inputs the
// runner feeds are rectified or undistorted.
template <class Sensor, class Lens>
Slam<Sensor> makeSlam(const typename Sensor::Camera& camera, const OrbParams& orb, const Lens& lens,
                      std::shared_ptr<const OrbVocabulary> vocabulary, const SlamOptions& options) {
  if constexpr (Sensor::kKind == SensorKind::Monocular) return Slam<Sensor>(camera, orb, lens, std::move(vocabulary), options);
  else return Slam<Sensor>(camera, orb, std::move(vocabulary), options);
}

// RunOptions::realtime: holds each frame back until its timestamp, counted from the first frame's,
// is due on the steady clock; a frame already due (tracking is behind) goes at once.
class FramePacer {
 public:
  explicit FramePacer(bool enabled) : enabled_(enabled) {}
  void waitUntilDue(double timestamp) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!started_) {
      started_ = true;
      firstTimestamp_ = timestamp;
      firstFed_ = now;
      return;
    }
    const auto due = firstFed_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(timestamp - firstTimestamp_));
    if (due > now) std::this_thread::sleep_until(due);
  }

 private:
  bool enabled_;
  bool started_ = false;
  double firstTimestamp_ = 0;
  std::chrono::steady_clock::time_point firstFed_;
};

template <class Sensor, class Lens>
void runWith(const typename Sensor::Camera& camera, const Lens& lens, const OrbParams& orb,
             double fps, DatasetReader& dataset, const RunOptions& options, RunReport& report) {
  auto vocabulary = std::make_shared<const OrbVocabulary>(OrbVocabulary::load(options.vocabulary));
  SlamOptions slamOptions;
  slamOptions.deterministic = options.deterministic;
  slamOptions.localisationOnly = options.localisationOnly;
  slamOptions.loopClosing = options.loopClosing;
  slamOptions.fps = fps;
  slamOptions.liveCamera = options.realtime;
  slamOptions.atlas = options.atlas;
  slamOptions.newMapAfterLostFrames = options.newMapAfterLostFrames;
  slamOptions.newMapAfterLostSeconds = options.newMapAfterLostSeconds;
  Slam<Sensor> slam = makeSlam<Sensor>(camera, orb, lens, vocabulary, slamOptions);
  slam.core().timer().enableEvents(options.stats);
  if (options.loadMap) {
    report.loadedMapMetricScale = slam.core().loadMap(*options.loadMap).metricScale;
    report.keyFramesLoaded = slam.core().loadedKeyFrames();
  }
  if (options.observer) {
    slam.setFrameObserver([observer = options.observer](FrameSnapshot&& frame) { observer->onFrame(std::move(frame)); });
    options.observer->attach([&slam] { return slam.mapSnapshot(); });
  }

  for (const auto& w : dataset.warnings()) report.warnings.push_back(w);
  const std::size_t n = options.maxFrames ? std::min(options.maxFrames, dataset.size()) : dataset.size();
  ProgressBar bar("orbis run", n, options.progress);
  const auto start = std::chrono::steady_clock::now();
  double lastTimestamp = -std::numeric_limits<double>::infinity();
  // --dense: the images of every frame that became a keyframe, by timestamp (the reader loads
  // fresh ones each frame, so keeping a reference is enough); the cloud is built at the end,
  // from the keyframes that survived culling, at their final poses.
  std::map<double, std::pair<cv::Mat, cv::Mat>> keyFrameImages;
  if (options.denseCloud && !Sensor::kDepthFromSensor)
    report.warnings.push_back("--dense needs an RGB-D sequence: no dense cloud written");
  std::exception_ptr failure;
  FramePacer pacer(options.realtime);
  try {
    for (std::size_t i = 0; i < n; ++i) {
      DatasetFrame frame;
      try {
        frame = dataset.frame(i);
      } catch (const Error& e) {
        report.warnings.push_back(std::string("frame ") + std::to_string(i) + " skipped: " + e.what());
        continue;
      }
      if (!(frame.timestamp > lastTimestamp)) {
        report.warnings.push_back("frame " + std::to_string(i) + " skipped: timestamp " +
                                  std::to_string(frame.timestamp) + " does not increase");
        continue;
      }
      const auto input = makeInput<Sensor>(frame);
      if (!inputComplete(input)) {  // one warning per skipped frame: the reader's reason, if it gave one
        report.warnings.push_back("frame " + std::to_string(i) + " skipped: " +
                                  (frame.warnings.empty() ? "incomplete input" : frame.warnings.front()));
        continue;
      }
      for (const auto& w : frame.warnings) report.warnings.push_back("frame " + std::to_string(i) + ": " + w);
      lastTimestamp = frame.timestamp;
      pacer.waitUntilDue(frame.timestamp);  // after reading: loading the images is not the camera's delay
      const TrackResult r = slam.track(input);
      if constexpr (Sensor::kDepthFromSensor) {
        if (options.denseCloud && r.newKeyFrame) keyFrameImages[frame.timestamp] = {input.depth, input.image};
      }
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      char status[64];
      std::snprintf(status, sizeof status, "%s %.1f fps", toString(r.state), secs > 0 ? (i + 1) / secs : 0.0);
      bar.update(i + 1, status);
    }
  } catch (...) {
    failure = std::current_exception();  // outputs computed so far are still written below
  }
  bar.finish();
  slam.shutdown();
  if (options.observer) options.observer->detach(slam.mapSnapshot());
  // A map that cannot be saved (an unwritable folder) must not cost the run's other outputs:
  // they are written below, then the error is reported.
  if (options.saveMap && !failure) {
    try {
      slam.core().saveMap(*options.saveMap);
    } catch (const Error&) {
      failure = std::current_exception();
    }
  }
  const RelocalisationStats relocalisation = slam.core().relocalisationStats();
  report.relocalisationAttempts = relocalisation.attempts;
  report.relocalisations = relocalisation.successes;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.stats = slam.stats();
  report.timing = slam.timer().summary();
  if (const auto* closer = slam.core().loopCloser()) report.loopClosures = closer->closures();
  report.maps = slam.core().maps();
  report.merges = slam.core().merges();
  report.frameMaps = slam.core().trajectoryMaps();
  const std::vector<std::uint32_t> frameMapsNow = slam.core().trajectoryMaps(true);

  fs::create_directories(options.outDir);
  const Trajectory trajectory = slam.trajectory();
  const Trajectory keyFrames = slam.keyFrameTrajectory();
  writeTrajectory(options.outDir / "trajectory.txt", trajectory, TrajectoryFormat::Tum);
  writeTrajectory(options.outDir / "keyframes.txt", keyFrames, TrajectoryFormat::Tum);
  {
    std::ofstream maps(options.outDir / "trajectory_maps.txt");
    maps << "# timestamp map_tracked_in map_now\n";
    char line[96];
    for (std::size_t i = 0; i < trajectory.size() && i < report.frameMaps.size(); ++i) {
      std::snprintf(line, sizeof line, "%.6f %u %u\n", trajectory[i].t, report.frameMaps[i], frameMapsNow[i]);
      maps << line;
    }
  }
  auto cloud = slam.mapPointCloud();
  writePly(options.outDir / "map.ply", cloud);

  OverviewScene scene;
  scene.estimate = trajectory;
  scene.keyFrames = keyFrames;
  scene.mapPoints = cloud;
  const Trajectory& gt = dataset.groundTruth();
  if (!gt.empty() && !trajectory.empty()) {
    try {
      // A monocular map's scale is arbitrary: its trajectory is compared up to a similarity.
      const eval::Alignment alignment = Sensor::kMetricScale ? eval::Alignment::SE3 : eval::Alignment::Sim3;
      report.ateAlignment = Sensor::kMetricScale ? "se3" : "sim3";
      const eval::AteResult ate = eval::computeAte(gt, trajectory, {alignment, 0.02});
      if (!keyFrames.empty()) {
        try {
          const eval::AteResult kfAte = eval::computeAte(gt, keyFrames, {alignment, 0.02});
          report.ateKeyFramesRmse = kfAte.stats.rmse;
          report.ateKeyFramesMatched = kfAte.stats.count;
        } catch (const Error& e) {
          report.warnings.push_back(std::string("keyframe ATE not computed: ") + e.what());
        }
      }
      report.ateRmse = ate.stats.rmse;
      report.ateMatched = ate.stats.count;
      for (std::size_t k = 1; k < ate.pairs.size(); ++k)
        report.pathLength += (gt[ate.pairs[k].groundTruth].pose.translation() -
                              gt[ate.pairs[k - 1].groundTruth].pose.translation()).norm();
      // Draw everything in the ground truth's frame.
      const Sim3d S = ate.alignment;
      for (auto& s : scene.estimate) s.pose = eval::applySimilarity(S, s.pose);
      for (auto& s : scene.keyFrames) s.pose = eval::applySimilarity(S, s.pose);
      for (auto& p : scene.mapPoints) p = (S * p.cast<double>()).cast<float>();
      scene.groundTruth = posesCovering(gt, trajectory, 0.5);
    } catch (const Error& e) {
      report.warnings.push_back(std::string("ATE not computed: ") + e.what());
    }
  }
  char title[200];
  std::snprintf(title, sizeof title, "%s (%s): %zu/%zu frames tracked, %zu keyframes, %zu points%s", report.dataset.c_str(),
                report.sensor.c_str(), report.stats.tracked, report.stats.frames, report.stats.keyFrames,
                report.stats.mapPoints,
                report.ateRmse ? (", ATE " + std::to_string(*report.ateRmse * 1000).substr(0, 6) + " mm").c_str() : "");
  scene.title = title;
  writeOverview(options.outDir / "overview.png", scene);
  if constexpr (Sensor::kDepthFromSensor) {
    if (options.denseCloud) {
      DenseCloudBuilder dense(camera.pinhole, camera.depthScale);
      for (const StampedPose& kf : keyFrames)
        if (auto it = keyFrameImages.find(kf.t); it != keyFrameImages.end())
          dense.addView(kf.pose, it->second.first, it->second.second);
      if (options.denseCloud->has_parent_path()) fs::create_directories(options.denseCloud->parent_path());
      dense.writePly(*options.denseCloud);
      report.densePoints = dense.voxelCount();
    }
  }
  writeReport(options.outDir / "report.json", report);
  if (options.stats) writeEvents(options.outDir / "stats.jsonl", slam.timer().events());
  if (failure) std::rethrow_exception(failure);
}

}  // namespace

RunReport runDataset(DatasetReader& dataset, const RunOptions& options) {
  RunReport report;
  report.dataset = std::string(toString(dataset.kind())) + ":" + dataset.root().filename().string();
  const Defaults defaults = datasetDefaults(dataset.kind());
  OrbParams orb;
  orb.features = defaults.features;
  double fps = defaults.fps;
  DatasetCamera camera;
  RadTanDistortion<double> lens;
  if (options.settings) {
    const Settings s = Settings::load(*options.settings, dataset.sensor());
    orb = s.orb;
    fps = s.fps;
    if (const auto* fisheye = std::get_if<KannalaBrandtCamera<double>>(&s.camera)) {
      // Settings pick the instantiation once: a monocular Kannala-Brandt lens (settings.hpp).
      report.sensor = std::string(toString(dataset.sensor())) + " (fisheye)";
      runWith<MonocularFisheye>(MonocularFisheye::planeOf(*fisheye), *fisheye, orb, fps, dataset, options, report);
      return report;
    }
    camera = std::visit(
        [](const auto& c) -> DatasetCamera {
          if constexpr (std::is_same_v<std::decay_t<decltype(c)>, KannalaBrandtCamera<double>>) return c.centralPinhole();
          else return c;
        },
        s.camera);
    lens = s.distortion;
  } else {
    camera = dataset.camera();
    lens = dataset.distortion();
  }
  report.sensor = std::string(toString(dataset.sensor()));
  std::visit(
      [&](const auto& cam) {
        using C = std::decay_t<decltype(cam)>;
        if constexpr (std::is_same_v<C, RectifiedStereoCamera<double>>) {
          runWith<Stereo>(cam, lens, orb, fps, dataset, options, report);
        } else if constexpr (std::is_same_v<C, RgbdCamera<double>>) {
          runWith<Rgbd>(cam, lens, orb, fps, dataset, options, report);
        } else {
          static_assert(std::is_same_v<C, PinholeCamera<double>>);
          runWith<Monocular>(cam, lens, orb, fps, dataset, options, report);
        }
      },
      camera);
  return report;
}

}  // namespace orbis
