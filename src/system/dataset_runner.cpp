#include "orbis/system/dataset_runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <thread>

#include "frame_preparation.hpp"
#include "orbis/camera/rectification.hpp"
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
  w.field("interrupted", r.interrupted);
  // Where the frames came from, what the source lost and how late the poses were.
  w.key("source").beginObject().field("name", r.dataset).field("live", r.live).field("dropped_frames", r.droppedFrames);
  w.key("end_reason");
  if (r.endReason.empty()) w.null();
  else w.value(r.endReason);
  w.key("input_size").beginArray().value(r.inputWidth).value(r.inputHeight).endArray();
  w.key("resized_to");
  if (r.resizedWidth) w.beginArray().value(r.resizedWidth).value(r.resizedHeight).endArray();
  else w.null();
  w.endObject();
  w.key("latency_ms").beginObject().field("count", r.latency.count).field("median", r.latency.medianMs);
  w.field("p95", r.latency.p95Ms).field("max", r.latency.maxMs).endObject();
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
typename Sensor::Input makeInput(const SourceFrame& f);

template <>
StereoInput makeInput<Stereo>(const SourceFrame& f) {
  return {f.timestamp, f.image, f.right};
}
template <>
RgbdInput makeInput<Rgbd>(const SourceFrame& f) {
  return {f.timestamp, f.image, f.depth};
}
template <>
MonocularInput makeInput<Monocular>(const SourceFrame& f) {
  return {f.timestamp, f.image};
}
template <>
MonocularInput makeInput<MonocularFisheye>(const SourceFrame& f) {
  return {f.timestamp, f.image};
}

LatencyStats latencyStats(std::vector<double> ms) {
  LatencyStats s;
  s.count = ms.size();
  if (ms.empty()) return s;
  std::sort(ms.begin(), ms.end());
  const auto at = [&](double q) { return ms[static_cast<std::size_t>(std::min<double>(ms.size() - 1, std::floor(q * (ms.size() - 1) + 0.5)))]; };
  s.medianMs = at(0.5);
  s.p95Ms = at(0.95);
  s.maxMs = ms.back();
  return s;
}

// The status line of a run: frames, state, fps, dropped frames, keyframes, map points.
std::string statusText(TrackingState state, double fps, std::size_t dropped, const SlamStats& stats) {
  char text[160];
  std::snprintf(text, sizeof text, "%s %.1f fps, %zu dropped, %zu keyframes, %zu points", toString(state), fps, dropped,
                stats.keyFrames, stats.mapPoints);
  return text;
}

bool inputComplete(const StereoInput& in) { return !in.left.empty() && !in.right.empty(); }
bool inputComplete(const RgbdInput& in) { return !in.image.empty() && !in.depth.empty(); }
bool inputComplete(const MonocularInput& in) { return !in.image.empty(); }

// A monocular camera's images may still carry lens distortion; the stereo and RGB-D inputs the
// runner feeds are rectified or undistorted.
template <class Sensor, class Lens>
Slam<Sensor> makeSlam(const typename Sensor::Camera& camera, const OrbParams& orb, const Lens& lens,
                      std::shared_ptr<const OrbVocabulary> vocabulary, const SlamOptions& options) {
  if constexpr (std::constructible_from<typename Sensor::FeatureBuilder, const typename Sensor::Camera&, const OrbParams&,
                                        const Lens&>)
    return Slam<Sensor>(camera, orb, lens, std::move(vocabulary), options);
  else return Slam<Sensor>(camera, orb, std::move(vocabulary), options);
}

// RunOptions::realtime: holds each frame back until its timestamp, counted from the first frame's,
// is due on the steady clock; a frame already due (tracking is behind) goes at once.
class FramePacer {
 public:
  explicit FramePacer(bool enabled) : enabled_(enabled) {}
  bool enabled() const { return enabled_; }
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

// What runWith needs of the run besides the camera: the source, the frame already read to
// size the camera, and the scaling decided from it.
struct RunInput {
  FrameSource& source;
  std::optional<SourceFrame> first;
  run_detail::FrameScaling scaling;
  const Trajectory* groundTruth = nullptr;
  std::size_t pulled = 0;  // frames taken from the source before the run (unreadable ones)
  std::shared_ptr<const OrbVocabulary> vocabulary;
};

template <class Sensor, class Lens>
void runWith(const typename Sensor::Camera& camera, const Lens& lens, const OrbParams& orb,
             double fps, RunInput& in, const RunOptions& options, RunReport& report) {
  FrameSource& source = in.source;
  SlamOptions slamOptions;
  slamOptions.deterministic = options.deterministic;
  slamOptions.localisationOnly = options.localisationOnly;
  slamOptions.loopClosing = options.loopClosing;
  slamOptions.fps = fps;
  slamOptions.liveCamera = options.realtime || source.live();
  slamOptions.atlas = options.atlas;
  slamOptions.newMapAfterLostFrames = options.newMapAfterLostFrames;
  slamOptions.newMapAfterLostSeconds = options.newMapAfterLostSeconds;
  Slam<Sensor> slam = makeSlam<Sensor>(camera, orb, lens, in.vocabulary, slamOptions);
  slam.core().timer().enableEvents(options.stats);
  if (options.loadMap) {
    report.loadedMapMetricScale = slam.core().loadMap(*options.loadMap).metricScale;
    report.keyFramesLoaded = slam.core().loadedKeyFrames();
  }
  if (options.observer) {
    slam.setFrameObserver([observer = options.observer](FrameSnapshot&& frame) { observer->onFrame(std::move(frame)); });
    options.observer->attach([&slam] { return slam.mapSnapshot(); });
  }

  const std::optional<std::size_t> expected = source.expectedFrames();
  const std::size_t n = options.maxFrames ? (expected ? std::min(options.maxFrames, *expected) : options.maxFrames)
                                          : expected.value_or(0);
  ProgressBar bar("orbis run", n, options.progress);  // without a total: a status line
  const auto start = std::chrono::steady_clock::now();
  double lastTimestamp = -std::numeric_limits<double>::infinity();
  // --dense: the images of every frame that became a keyframe, by timestamp (the reader loads
  // fresh ones each frame, so keeping a reference is enough); the cloud is built at the end,
  // from the keyframes that survived culling, at their final poses.
  std::map<double, std::pair<cv::Mat, cv::Mat>> keyFrameImages;
  if (options.denseCloud && !Sensor::kDepthFromSensor)
    report.warnings.push_back("--dense needs an RGB-D sequence: no dense cloud written");
  std::exception_ptr failure;
  FramePacer pacer(options.realtime && !source.live());  // a live source keeps its own time
  std::vector<double> latencyMs;
  std::string status;
  auto lastStatus = start - std::chrono::seconds(1);
  std::size_t pulled = in.pulled, processed = 0;
  try {
    while (!options.maxFrames || pulled < options.maxFrames) {
      if (options.stopRequested && options.stopRequested()) {
        report.interrupted = true;
        break;
      }
      std::optional<SourceFrame> frame;
      if (in.first) {
        frame = std::move(in.first);
        in.first.reset();
      } else {
        try {
          frame = source.next();
        } catch (const Error& e) {
          report.warnings.push_back(std::string("frame ") + std::to_string(pulled++) + " skipped: " + e.what());
          continue;
        }
      }
      if (!frame) {
        if (options.stopRequested && options.stopRequested()) report.interrupted = true;
        break;
      }
      ++pulled;
      const std::size_t i = frame->index;
      if (!(frame->timestamp > lastTimestamp)) {
        report.warnings.push_back("frame " + std::to_string(i) + " skipped: timestamp " +
                                  std::to_string(frame->timestamp) + " does not increase");
        continue;
      }
      if (!run_detail::applyScaling(*frame, in.scaling)) {
        report.warnings.push_back("frame " + std::to_string(i) + " skipped: " + std::to_string(frame->image.cols) + "x" +
                                  std::to_string(frame->image.rows) + " is not the first frame's size");
        continue;
      }
      const auto input = makeInput<Sensor>(*frame);
      if (!inputComplete(input)) {  // one warning per skipped frame: the reader's reason, if it gave one
        report.warnings.push_back("frame " + std::to_string(i) + " skipped: " +
                                  (frame->warnings.empty() ? "incomplete input" : frame->warnings.front()));
        continue;
      }
      for (const auto& w : frame->warnings) report.warnings.push_back("frame " + std::to_string(i) + ": " + w);
      lastTimestamp = frame->timestamp;
      pacer.waitUntilDue(frame->timestamp);  // after reading: loading the images is not the camera's delay
      const auto fed = pacer.enabled() ? std::chrono::steady_clock::now() : frame->captured;
      const TrackResult r = slam.track(input);
      const auto now = std::chrono::steady_clock::now();
      ++processed;
      if (r.state == TrackingState::Ok) latencyMs.push_back(std::chrono::duration<double, std::milli>(now - fed).count());
      if constexpr (Sensor::kDepthFromSensor) {
        if (options.denseCloud && r.newKeyFrame) keyFrameImages[frame->timestamp] = {input.depth, input.image};
      }
      if (bar.enabled() && now - lastStatus > std::chrono::milliseconds(250)) {
        lastStatus = now;
        const double secs = std::chrono::duration<double>(now - start).count();
        status = statusText(r.state, secs > 0 ? processed / secs : 0.0, source.dropped(), slam.stats());
      }
      bar.update(pulled, status);
    }
  } catch (...) {
    failure = std::current_exception();  // outputs computed so far are still written below
  }
  report.droppedFrames = source.dropped();
  report.endReason = source.endReason();
  report.latency = latencyStats(std::move(latencyMs));
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
  const Trajectory& gt = *in.groundTruth;
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

namespace {

// The calibration of a source without a settings file: its own, or an error saying how to get one.
DatasetCamera sourceCamera(const FrameSource& source) {
  if (source.hasCalibration())
    if (auto camera = source.camera()) return *camera;
  throw Error(source.name(), "",
              "has no calibration: pass --settings FILE, an ORB-SLAM2 settings YAML with Camera.fx/fy/cx/cy "
              "and k1/k2/p1/p2 (examples/settings/ holds some), or measure your camera with "
              "`orbis calibrate` (docs/guide/own-camera.md)");
}

// Raw stereo frames rectified on load by the settings' LEFT./RIGHT. blocks (as ORB-SLAM2's
// stereo examples do): for sources without a calibration of their own; a dataset rectifies itself.
class RectifyingSource final : public FrameSource {
 public:
  RectifyingSource(FrameSource& raw, StereoRectification rectification, std::string settings)
      : raw_(raw), rectification_(std::move(rectification)), settings_(std::move(settings)) {
    warnings_ = raw_.warnings();
  }
  std::optional<SourceFrame> next() override {
    std::optional<SourceFrame> frame = raw_.next();
    if (!frame || frame->right.empty()) return frame;
    const RectificationBlock& block = rectification_.left;
    if (frame->image.cols != block.width || frame->image.rows != block.height || frame->right.size() != frame->image.size())
      throw Error(settings_, "key LEFT.width",
                  "rectifies " + std::to_string(block.width) + "x" + std::to_string(block.height) + " images but " +
                      raw_.name() + " delivers " + std::to_string(frame->image.cols) + "x" +
                      std::to_string(frame->image.rows) + " (right " + std::to_string(frame->right.cols) + "x" +
                      std::to_string(frame->right.rows) + "): calibrate the rig at the size the frames come in");
    StereoRectification::Images rectified = rectification_.rectify(frame->image, frame->right);
    frame->image = std::move(rectified.left);
    frame->right = std::move(rectified.right);
    return frame;
  }
  std::string name() const override { return raw_.name(); }
  SensorKind sensor() const override { return raw_.sensor(); }
  bool live() const override { return raw_.live(); }
  std::optional<std::size_t> expectedFrames() const override { return raw_.expectedFrames(); }
  const Trajectory& groundTruth() const override { return raw_.groundTruth(); }
  std::size_t dropped() const override { return raw_.dropped(); }
  std::string endReason() const override { return raw_.endReason(); }
  void setCancelCheck(std::function<bool()> cancel) override { raw_.setCancelCheck(std::move(cancel)); }

 private:
  FrameSource& raw_;
  StereoRectification rectification_;
  std::string settings_;
};

RunReport runFrames(FrameSource& rawSource, const RunOptions& options, const Defaults& defaults) {
  std::unique_ptr<FrameSource> rectifying;
  if (options.settings && rawSource.sensor() == SensorKind::Stereo && !rawSource.hasCalibration()) {
    const Settings s = Settings::load(*options.settings, SensorKind::Stereo);
    if (s.rectification)
      rectifying = std::make_unique<RectifyingSource>(rawSource, s.stereoRectification(), options.settings->string());
  }
  FrameSource& source = rectifying ? *rectifying : rawSource;
  RunReport report;
  report.dataset = source.name();
  report.live = source.live();
  OrbParams orb;
  orb.features = defaults.features;
  double fps = defaults.fps;
  DatasetCamera camera;
  RadTanDistortion<double> lens;
  std::optional<KannalaBrandtCamera<double>> fisheye;  // settings with Camera.type KannalaBrandt8
  int resizeWidth = options.resizeWidth;
  std::string calibrationSource = source.name();
  if (options.settings) {
    const Settings s = Settings::load(*options.settings, source.sensor());
    orb = s.orb;
    fps = s.fps;
    if (const auto* kb = std::get_if<KannalaBrandtCamera<double>>(&s.camera)) fisheye = *kb;
    camera = std::visit(
        [](const auto& c) -> DatasetCamera {
          if constexpr (std::is_same_v<std::decay_t<decltype(c)>, KannalaBrandtCamera<double>>) return c.centralPinhole();
          else return c;
        },
        s.camera);
    lens = s.distortion;
    if (resizeWidth <= 0) resizeWidth = s.newWidth;
    calibrationSource = options.settings->string();
  } else {
    camera = sourceCamera(source);
    lens = source.distortion();
  }
  if (options.stopRequested) source.setCancelCheck(options.stopRequested);
  report.sensor = std::string(toString(source.sensor()));
  for (const auto& w : source.warnings()) report.warnings.push_back(w);
  Trajectory groundTruth = source.groundTruth();
  if (options.groundTruth) groundTruth = readTrajectory(*options.groundTruth, detectTrajectoryFormat(*options.groundTruth));

  // The first frame that reads sizes the camera (a bad one is skipped as any other would be).
  // The vocabulary loads first: a live source starts capturing with that read, and the first
  // frame should not wait for the load.
  RunInput in{source, std::nullopt, {}, &groundTruth, 0, nullptr};
  in.vocabulary = std::make_shared<const OrbVocabulary>(OrbVocabulary::load(options.vocabulary));
  while (!in.first && !(options.stopRequested && options.stopRequested())) {
    try {
      in.first = source.next();
      if (!in.first) break;
    } catch (const Error& e) {
      report.warnings.push_back(std::string("frame ") + std::to_string(in.pulled++) + " skipped: " + e.what());
    }
  }
  if (in.first) {
    in.scaling = run_detail::planScaling(camera, in.first->image.cols, in.first->image.rows, resizeWidth,
                                         calibrationSource, !source.hasCalibration(), report.warnings);
    report.inputWidth = in.scaling.inputWidth;
    report.inputHeight = in.scaling.inputHeight;
    if (in.scaling.imageScale != 1.0) {
      report.resizedWidth = in.scaling.width;
      report.resizedHeight = in.scaling.height;
    }
  }
  if (fisheye) {
    // Settings pick the instantiation once: a monocular Kannala-Brandt lens (settings.hpp). Its
    // intrinsics are not rescaled, so the frames must come at the calibrated size.
    if (in.scaling.imageScale != 1.0)
      throw Error(calibrationSource, "key Camera.type",
                  "a KannalaBrandt8 camera runs at its calibrated image size: drop --resize / Camera.newWidth, or "
                  "calibrate the camera at the size the frames come in");
    report.sensor += " (fisheye)";
    runWith<MonocularFisheye>(MonocularFisheye::cameraOf(*fisheye), *fisheye, orb, fps, in, options, report);
    return report;
  }
  std::visit(
      [&](const auto& cam) {
        using C = std::decay_t<decltype(cam)>;
        if constexpr (std::is_same_v<C, RectifiedStereoCamera<double>>) {
          runWith<Stereo>(cam, lens, orb, fps, in, options, report);
        } else if constexpr (std::is_same_v<C, RgbdCamera<double>>) {
          runWith<Rgbd>(cam, lens, orb, fps, in, options, report);
        } else {
          static_assert(std::is_same_v<C, PinholeCamera<double>>);
          runWith<Monocular>(cam, lens, orb, fps, in, options, report);
        }
      },
      camera);
  return report;
}

}  // namespace

RunReport runSource(FrameSource& source, const RunOptions& options) { return runFrames(source, options, {1000, 30}); }

RunReport runDataset(DatasetReader& dataset, const RunOptions& options) {
  const auto source = makeDatasetSource(dataset);
  RunReport report = runFrames(*source, options, datasetDefaults(dataset.kind()));
  return report;
}

}  // namespace orbis
