// orbis/system/slam_core_impl.hpp — bodies of SlamCore<Sensor> (slam_core.hpp).
//
// Contract: included by slam_core.hpp only; see there.
#pragma once

#include <algorithm>
#include <chrono>

#include "orbis/io/map_file.hpp"
#include "orbis/system/slam_core.hpp"
#include "orbis/util/allocator.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

template <SensorConfiguration Sensor>
SlamCore<Sensor>::SlamCore(const Camera& camera, std::shared_ptr<const OrbVocabulary> vocabulary, SlamOptions options)
    : camera_(camera), vocabulary_(std::move(vocabulary)), intrinsics_(mapIntrinsicsOf(camera)), options_(options) {
  if (options_.retainFreedMemory) retainFreedMemory();
  LocalMapperOptions mapperOptions;
  mapperOptions.threaded = !options_.deterministic;
  mapperOptions.backgroundPriority = options_.backgroundPriority;
  mapper_ = std::make_unique<LocalMapper<Sensor>>(camera_, map_, mapperOptions, &timer_);
  if (options_.loopClosing && !options_.localisationOnly) {
    LoopCloserOptions loopOptions;
    loopOptions.threaded = !options_.deterministic;
    loopOptions.backgroundPriority = options_.backgroundPriority;
    loopOptions.seed = options_.seed;
    loopOptions.mergeMaps = options_.atlas;
    loopCloser_ = std::make_unique<LoopCloser<Sensor>>(camera_, map_, mapper_.get(), database_, loopOptions, &timer_);
  }
  // Processed keyframes feed the keyframe database: through the loop closer (which queries it
  // before adding each one) or directly.
  mapper_->setKeyFrameSink([this](KeyFrame* kf) {
    if (loopCloser_) loopCloser_->insertKeyFrame(kf);
    else database_.add(kf->id, kf->bowVector());
  });
  // A culled keyframe leaves the database at once (as ORB-SLAM's SetBadFlag does), whether or not
  // a loop closer runs: relocalisation candidates then count only live keyframes.
  mapper_->setCulledKeyFrameSink([this](KeyFrame* kf) { database_.erase(kf->id); });
  TrackerOptions trackerOptions;
  trackerOptions.maxFramesBetweenKeyFrames = std::max(1, static_cast<int>(options_.fps + 0.5));
  trackerOptions.localisationOnly = options_.localisationOnly;
  trackerOptions.atlas = options_.atlas;
  trackerOptions.newMapAfterLostFrames = options_.newMapAfterLostFrames;
  trackerOptions.newMapAfterLostSeconds = options_.newMapAfterLostSeconds;
  tracker_ = std::make_unique<Tracker<Sensor>>(map_, *vocabulary_, mapper_.get(), trackerOptions, &timer_);
  RelocaliserOptions relocaliserOptions;
  relocaliserOptions.seed = options_.seed;
  relocaliser_ = std::make_unique<Relocaliser<Sensor>>(map_, database_, relocaliserOptions);
  // Called by the tracker, map mutex held, when it is lost. The database spans the atlas: found
  // in another map, tracking goes on there (that map becomes the active one).
  tracker_->setRelocaliser([this](Frame<Camera>& frame) {
    if (!relocaliser_->relocalise(frame)) return false;
    if (const KeyFrame* kf = map_.keyFrame(relocaliser_->stats().lastKeyFrame)) map_.setActiveMap(kf->mapId());
    return true;
  });
}

template <SensorConfiguration Sensor>
SlamCore<Sensor>::~SlamCore() { shutdown(); }

template <SensorConfiguration Sensor>
void SlamCore<Sensor>::shutdown() {
  if (shutDown_) return;
  shutDown_ = true;
  if (mapper_) mapper_->waitUntilIdle();
  if (loopCloser_) {
    // A loop correction or full BA pauses mapping; mapping must run until they have finished.
    loopCloser_->waitUntilIdle();
    mapper_->waitUntilIdle();
    loopCloser_->shutdown();
  }
  if (mapper_) mapper_->shutdown();
}

template <SensorConfiguration Sensor>
TrackResult SlamCore<Sensor>::track(std::shared_ptr<const FrameFeatures> features, double timestamp,
                                    double extractionMs, const cv::Mat& image) {
  using Clock = std::chrono::steady_clock;
  // Read only by the frame observer and a wait bounded by the frame period: no clock call on the
  // stereo/RGB-D path without a viewer.
  const bool timed = frameObserver_ || waitBoundedByFramePeriod();
  const Clock::time_point start = timed ? Clock::now() : Clock::time_point{};
  std::shared_ptr<const FrameFeatures> observed = frameObserver_ ? features : nullptr;
  Frame<Camera> frame;
  frame.index = frames_++;
  frame.timestamp = timestamp;
  frame.camera = &camera_;
  frame.intrinsics = intrinsics_;
  // The image bounds keypoints can fall in come from the features (undistorted bounds).
  frame.intrinsics.minX = features->grid.minX();
  frame.intrinsics.maxX = features->grid.maxX();
  frame.intrinsics.minY = features->grid.minY();
  frame.intrinsics.maxY = features->grid.maxY();
  frame.features = std::move(features);
  TrackResult result;
  if constexpr (!Sensor::kMetricScale) waitForTriangulationOfLastKeyFrame();
  else waitForRoomInMappingQueue();
  {
    ScopedStage stage(&timer_, "tracking: total");
    result = tracker_->track(std::move(frame));
  }
  tracker_->handOverNewKeyFrame();
  if (result.state == TrackingState::Lost) ++lost_;
  if (result.state != TrackingState::NotInitialised && !initialisedAtFrame_) initialisedAtFrame_ = frames_ - 1;
  // Deterministic mode: local mapping runs to quiescence after every frame, in order.
  if (options_.deterministic && result.newKeyFrame) {
    mapper_->runUntilIdle();
    if (loopCloser_) loopCloser_->runUntilIdle();
  }
  if constexpr (!Sensor::kMetricScale) {
    if (!options_.deterministic && result.newKeyFrame) waitForMappingAfterKeyFrame(start, extractionMs);
  }
  if (frameObserver_) {
    ScopedStage stage(&timer_, "tracking: observer");  // what watching costs the tracking thread
    FrameSnapshot snapshot;
    snapshot.index = frames_ - 1;
    snapshot.timestamp = timestamp;
    snapshot.state = result.state;
    snapshot.Tcw = result.Tcw;
    snapshot.inliers = result.inliers;
    snapshot.newKeyFrame = result.newKeyFrame;
    snapshot.image = image;  // a reference: the viewer's own thread scales and encodes it, if at all
    snapshot.imageWidth = image.empty() ? intrinsics_.maxX : image.cols;
    snapshot.imageHeight = image.empty() ? intrinsics_.maxY : image.rows;
    snapshot.features = std::move(observed);
    snapshot.keypointStates = tracker_->keypointStates();
    snapshot.localMapPoints.reserve(tracker_->localMapPoints().size());
    for (const MapPoint* p : tracker_->localMapPoints()) snapshot.localMapPoints.push_back(p->id);
    snapshot.extractionMs = extractionMs;
    snapshot.trackingMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    frameObserver_(std::move(snapshot));
  }
  return result;
}

template <SensorConfiguration Sensor>
void SlamCore<Sensor>::setFrameObserver(FrameObserver observer) {
  std::lock_guard lock(map_.mutex());
  frameObserver_ = std::move(observer);
  tracker_->setRecordKeypointStates(static_cast<bool>(frameObserver_));
}

template <SensorConfiguration Sensor>
MapSnapshot SlamCore<Sensor>::mapSnapshot() const {
  MapSnapshot snapshot;
  {
    std::lock_guard lock(map_.mutex());
    snapshot = snapshotOfMap(map_);
    snapshot.trajectory.reserve(tracker_->trackedFrames().size());
    for (const TrackedFrame& f : tracker_->trackedFrames())
      snapshot.trajectory.push_back(worldPoseOf(f).inverse().translation().cast<float>());
    snapshot.frames = frames_;
  }
  if (loopCloser_) {
    snapshot.loopClosures = loopCloser_->closures();
    snapshot.merges = loopCloser_->merges();
  }
  return snapshot;
}

template <SensorConfiguration Sensor>
void SlamCore<Sensor>::setLocalisationOnly(bool on) {
  std::lock_guard lock(map_.mutex());
  tracker_->setLocalisationOnly(on);
}

template <SensorConfiguration Sensor>
RelocalisationStats SlamCore<Sensor>::relocalisationStats() const {
  std::lock_guard lock(map_.mutex());
  return relocaliser_->stats();
}

// A monocular keyframe makes map only once mapping has triangulated it and local BA has refined
// it. A tracker that went on against the keyframe's neighbourhood while mapping still worked on
// it drifted in scale whenever it outran mapping: frames fed faster than the camera's rate (orbis
// run feeds them as fast as tracking goes) or a slow machine (under ThreadSanitizer the rendered
// loop closed with a Sim(3) scale of 0.014, keyframe ATE 482 mm). Waiting out only the rest of
// the frame period is not enough there: nothing of it is left; waiting for triangulation alone
// was not either (one of four runs collapsed). So tracking waits until mapping is idle. That costs
// wall time (teddy monocular: 11 s for 6.7 s of frames on two cores, 7 s without), so with a live
// camera (SlamOptions::liveCamera) tracking keeps the camera's rate instead: mapping gets what is
// left of the frame period (1/fps after extraction and tracking), and tracking runs on if it has
// not finished. The metric sensors need no wait: each frame measures its own depth. Measurements:
// docs/notes/2026-11-24-monocular-threaded-wait.md. With a live camera (unless
// SlamOptions::liveWaitForLocalBA) tracking does not wait here at all: the next frame, before it
// is tracked, waits until this keyframe's new points exist, and local BA runs while the camera
// delivers frames, as in ORB-SLAM2 (docs/notes/2026-11-26-speed.md).
template <SensorConfiguration Sensor>
void SlamCore<Sensor>::waitForMappingAfterKeyFrame(std::chrono::steady_clock::time_point trackingStart,
                                                   double extractionMs) {
  using Clock = std::chrono::steady_clock;
  if (!waitBoundedByFramePeriod()) {
    ScopedStage stage(&timer_, "tracking: wait for mapping");
    mapper_->waitUntilIdle();
    return;
  }
  if (!options_.liveWaitForLocalBA) {
    triangulationPending_ = true;  // waited for before the next frame is tracked
    return;
  }
  ScopedStage stage(&timer_, "tracking: wait for mapping");
  const auto period = std::chrono::duration<double>(1.0 / std::max(1.0, options_.fps));
  const auto spent = Clock::now() - trackingStart + std::chrono::duration<double, std::milli>(extractionMs);
  if (spent < period) mapper_->waitUntilIdleFor(std::chrono::duration_cast<Clock::duration>(period - spent));
}

template <SensorConfiguration Sensor>
void SlamCore<Sensor>::waitForTriangulationOfLastKeyFrame() {
  if (!triangulationPending_) return;
  triangulationPending_ = false;
  ScopedStage stage(&timer_, "tracking: wait for mapping");
  const auto period = std::chrono::duration<double>(1.0 / std::max(1.0, options_.fps));
  mapper_->waitUntilTriangulatedFor(std::chrono::duration_cast<std::chrono::steady_clock::duration>(period));
}

// Stereo/RGB-D, threaded, fed faster than a camera: the keyframe rule (ORB-SLAM2's) refuses a
// keyframe while mapping has three queued, which with a live camera means mapping cannot keep up
// and a keyframe must be skipped. Fed flat out, tracking only outran mapping: on the rendered room
// it refused the keyframes while matches fell 126 -> 21 and was lost (docs/notes/
// 2026-11-29-mapping-queue-wait.md). So a frame waits here, outside the map's lock, until the queue
// has room; bounded so that mapping paused by loop closing cannot hold tracking for long.
template <SensorConfiguration Sensor>
void SlamCore<Sensor>::waitForRoomInMappingQueue() {
  if (options_.deterministic || options_.liveCamera) return;  // inline mapping; a camera's pace
  if (mapper_->queuedKeyFrames() < kMaxQueuedKeyFrames) return;
  ScopedStage stage(&timer_, "tracking: wait for mapping");
  mapper_->waitUntilQueuedBelowFor(kMaxQueuedKeyFrames, std::chrono::seconds(2));
}

template <SensorConfiguration Sensor>
void SlamCore<Sensor>::saveMap(const std::filesystem::path& file) {
  // Queued keyframes would be saved half-processed: let mapping (and loop closing) settle first.
  if (options_.deterministic) {
    mapper_->runUntilIdle();
    if (loopCloser_) loopCloser_->runUntilIdle();
  } else if (!shutDown_) {
    mapper_->waitUntilIdle();
    if (loopCloser_) loopCloser_->waitUntilIdle();
    mapper_->waitUntilIdle();
  }
  std::lock_guard lock(map_.mutex());
  writeMapFile(file, map_,
               {sensorKind(), intrinsics_, vocabularyChecksum(*vocabulary_), 0, 0, 0, 0, Sensor::kMetricScale});
}

template <SensorConfiguration Sensor>
MapFileInfo SlamCore<Sensor>::loadMap(const std::filesystem::path& file) {
  std::lock_guard lock(map_.mutex());
  if (frames_ != 0) throw fileError(file.string(), "a map can only be loaded before the first frame is tracked");
  const MapFileInfo info = readMapFile(file, map_, {sensorKind(), intrinsics_, vocabularyChecksum(*vocabulary_), 0, 0,
                                                    vocabulary_->wordCount(), vocabulary_->nodeCount(),
                                                    Sensor::kMetricScale});
  for (KeyFrame* kf : map_.keyFrames()) database_.add(kf->id, kf->bowVector());
  loadedKeyFrames_ = info.keyFrames;
  // There is a map already: find the camera in it instead of starting a new one.
  if (loadedKeyFrames_ > 0) tracker_->startLost();
  return info;
}

template <SensorConfiguration Sensor>
Trajectory SlamCore<Sensor>::trajectory() const {
  std::lock_guard lock(map_.mutex());
  Trajectory out;
  out.reserve(tracker_->trackedFrames().size());
  for (const TrackedFrame& f : tracker_->trackedFrames()) out.push_back({f.timestamp, worldPoseOf(f).inverse()});
  return out;
}

template <SensorConfiguration Sensor>
std::vector<std::uint32_t> SlamCore<Sensor>::trajectoryMaps(bool current) const {
  std::lock_guard lock(map_.mutex());
  std::vector<std::uint32_t> out;
  out.reserve(tracker_->trackedFrames().size());
  for (const TrackedFrame& f : tracker_->trackedFrames()) out.push_back(current ? f.reference->mapId() : f.mapId);
  return out;
}

template <SensorConfiguration Sensor>
std::vector<AtlasMapInfo> SlamCore<Sensor>::maps() const {
  std::lock_guard lock(map_.mutex());
  std::vector<AtlasMapInfo> out;
  for (const AtlasMapRecord& r : map_.mapRecords()) {
    AtlasMapInfo info;
    info.id = r.id;
    info.startFrame = r.startFrame;
    info.active = r.id == map_.activeMapId();
    info.merged = r.mergedInto.has_value();
    info.mergedInto = r.mergedInto.value_or(r.id);
    if (!info.merged) {
      info.keyFrames = map_.keyFrameCount(r.id);
      info.mapPoints = map_.mapPointCount(r.id);
    }
    out.push_back(info);
  }
  return out;
}

template <SensorConfiguration Sensor>
std::uint32_t SlamCore<Sensor>::activeMapId() const {
  std::lock_guard lock(map_.mutex());
  return map_.activeMapId();
}

template <SensorConfiguration Sensor>
std::vector<MapMergeEvent> SlamCore<Sensor>::merges() const {
  return loopCloser_ ? loopCloser_->merges() : std::vector<MapMergeEvent>{};
}

template <SensorConfiguration Sensor>
Trajectory SlamCore<Sensor>::keyFrameTrajectory() const {
  std::lock_guard lock(map_.mutex());
  Trajectory out;
  for (KeyFrame* kf : map_.keyFrames()) out.push_back({kf->timestamp, kf->Twc()});
  return out;
}

template <SensorConfiguration Sensor>
std::vector<Eigen::Vector3f> SlamCore<Sensor>::mapPointCloud() const {
  std::lock_guard lock(map_.mutex());
  std::vector<Eigen::Vector3f> out;
  for (MapPoint* p : map_.mapPoints()) out.push_back(p->position().cast<float>());
  return out;
}

template <SensorConfiguration Sensor>
SlamStats SlamCore<Sensor>::stats() const {
  std::lock_guard lock(map_.mutex());
  SlamStats s;
  s.frames = frames_;
  s.tracked = tracker_->trackedFrames().size();
  s.lost = lost_;
  s.keyFrames = map_.keyFrameCount();
  s.mapPoints = map_.mapPointCount();
  s.loopClosures = loopCloser_ ? loopCloser_->closures().size() : 0;
  s.initialisedAtFrame = initialisedAtFrame_;
  s.initialisationWaits = tracker_->initialisationWaits();
  s.maps = map_.mapRecords().size();
  s.mapMerges = loopCloser_ ? loopCloser_->merges().size() : 0;
  return s;
}

}  // namespace orbis
