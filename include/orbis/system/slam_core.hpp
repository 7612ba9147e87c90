// orbis/system/slam_core.hpp — SlamCore<Sensor>: the SLAM system after feature extraction.
//
// Contract: owns the map, the keyframe database and the three stages of the paper for one
// sensor configuration: Tracker<Sensor> on the caller's thread, LocalMapper<Sensor> and
// LoopCloser<Sensor> on their own threads (threaded mode) or run inline in a fixed order after
// each new keyframe (deterministic mode: bit-identical results), Relocaliser<Sensor> for lost
// tracking. The camera model is held here once; every stage keeps a reference to it. Bodies:
// slam_core_impl.hpp; the built-in sensors are compiled in src/system/slam_core.cpp.
#pragma once

#include <atomic>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "orbis/bow/keyframe_database.hpp"
#include "orbis/io/map_file.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/loop/loop_closer.hpp"
#include "orbis/map/map.hpp"
#include "orbis/mapping/local_mapper.hpp"
#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/sensor/sensor.hpp"
#include "orbis/viewer/slam_observer.hpp"
#include "orbis/tracking/relocaliser.hpp"
#include "orbis/tracking/tracker.hpp"
#include "orbis/util/timing.hpp"

namespace orbis {

// How the system runs.
struct SlamOptions {
  bool deterministic = false;     // inline stages in a fixed order (the tests use it)
  bool localisationOnly = false;  // tracking only, against the existing map (§III-F)
  // Whether loops are closed.
  bool loopClosing = true;
  double fps = 30;                // frame rate: the keyframe rule's "max frames" (ORB-SLAM2)
  // Frames come from a live camera at fps (orbis run --realtime): threaded monocular tracking
  // then waits for mapping after a keyframe only for what is left of the frame period, so it
  // keeps the camera's rate; otherwise (frames fed as fast as tracking takes them) it waits
  // until mapping is idle, which costs wall time but no frames.
  bool liveCamera = false;
  // With a live camera, monocular tracking waits after a keyframe only until mapping has made the
  // keyframe's new points, and only before it tracks the next frame (false, the default), or
  // until mapping is idle, local BA included, at most the rest of the frame period (true, as
  // before issue 35). Why: docs/notes/2026-11-26-speed.md, "Monocular mapping at a live pace".
  bool liveWaitForLocalBA = false;
  std::uint32_t seed = 0;         // seeds every random choice (RANSAC)
  // Keep memory freed by bundle adjustment in the process for reuse (util/allocator.hpp): its
  // buffers are then not faulted in again page by page. Process-wide, so it stays set after the
  // system is gone; false leaves malloc's settings alone.
  bool retainFreedMemory = true;
  // Threaded mode: local mapping, loop closing and full BA run at a lower priority than tracking
  // (util/thread_scheduling.hpp), so on a busy machine a frame's tracking gets the cores first
  // and mapping the rest; results do not change. Why: docs/notes/2026-11-27-speed-scheduling.md.
  bool backgroundPriority = true;
  // @{
  // The atlas (issue 32; docs/guide/atlas.md): a new map when relocalisation has failed on
  // newMapAfterLostFrames frames that could start one, over newMapAfterLostSeconds; maps merged
  // when loop closing recognises a place of another. Off: ORB-SLAM2's single map.
  bool atlas = true;
  int newMapAfterLostFrames = 10;
  double newMapAfterLostSeconds = 0.3;
  // @}
};

// What a run has done so far.
struct SlamStats {
  // @{
  // Frames seen, tracked and lost; keyframes and map points in the map.
  std::size_t frames = 0, tracked = 0, lost = 0, keyFrames = 0, mapPoints = 0;
  // @}
  // Loops closed.
  std::size_t loopClosures = 0;
  // @{
  // The frame the map started on (monocular: the second view of the accepted pair), and why the
  // frames before it did not start it (Tracker::initialisationWaits: reason -> frames).
  std::optional<std::uint64_t> initialisedAtFrame;
  std::map<std::string, std::size_t> initialisationWaits;
  // @}
  // @{
  // Maps ever opened in the atlas, and merges done.
  std::size_t maps = 1, mapMerges = 0;  // maps ever opened in the atlas, merges done
  // @}
};

// Everything after feature extraction: tracking, local mapping, loop closing and relocalisation
// over one Map, all on Sensor's camera model, kernel and trait.
template <SensorConfiguration Sensor>
class SlamCore {
 public:
  // The sensor's camera model.
  using Camera = typename Sensor::Camera;

  // A core for camera with the vocabulary; starts the threads unless deterministic.
  SlamCore(const Camera& camera, std::shared_ptr<const OrbVocabulary> vocabulary, SlamOptions options);
  ~SlamCore();
  SlamCore(const SlamCore&) = delete;
  SlamCore& operator=(const SlamCore&) = delete;

  // extractionMs and image (the frame's input image, shared, never read here): passed on to the
  // frame observer, if one is set.
  TrackResult track(std::shared_ptr<const FrameFeatures> features, double timestamp, double extractionMs = 0,
                    const cv::Mat& image = cv::Mat());
  // Finishes queued work and joins the threads; the results stay readable.
  void shutdown();

  Trajectory trajectory() const;          // every tracked frame, camera-to-world
  // Per frame of trajectory(): the map it was tracked in, and the map holding it now (they
  // differ once its map was merged into another; then its pose is in that map's frame).
  std::vector<std::uint32_t> trajectoryMaps(bool current = false) const;
  // @{
  // The atlas: every map ever opened (merged ones flagged), the active one, the merges so far.
  std::vector<AtlasMapInfo> maps() const;
  std::uint32_t activeMapId() const;
  std::vector<MapMergeEvent> merges() const;
  // @}
  Trajectory keyFrameTrajectory() const;  // every good keyframe, camera-to-world
  // @{
  // The map's points, the counters, the tracking state, and localisation-only mode.
  std::vector<Eigen::Vector3f> mapPointCloud() const;
  SlamStats stats() const;
  TrackingState state() const { return tracker_->state(); }
  void setLocalisationOnly(bool on);
  // @}
  // Called after every frame on the tracking thread (slam_observer.hpp); set before tracking
  // starts, empty to remove. Without one, track() does no extra work.
  void setFrameObserver(FrameObserver observer);
  // Whether a frame observer is set.
  bool observesFrames() const { return static_cast<bool>(frameObserver_); }
  // The map, loop closures and trajectory copied under the map mutex; callable from any thread.
  MapSnapshot mapSnapshot() const;

  // Map files (io/map_file.hpp). saveMap waits for local mapping to finish its queue. loadMap
  // needs a core that has not tracked yet; tracking then starts lost and relocalises in the map.
  // The file records whether the map's scale is metric (Sensor::kMetricScale); loadMap returns
  // the file's header.
  void saveMap(const std::filesystem::path& file);
  // Loads a map file into a core that has not tracked yet; returns the file's header.
  MapFileInfo loadMap(const std::filesystem::path& file);
  // The sensor's kind.
  static constexpr SensorKind sensorKind() { return Sensor::kKind; }
  // Relocalisation attempts and successes; keyframes loaded from a map file.
  RelocalisationStats relocalisationStats() const;
  // Keyframes loaded from a map file.
  std::size_t loadedKeyFrames() const { return loadedKeyFrames_; }

  // @{
  // The map, the timer and the camera.
  Map& map() { return map_; }
  const Map& map() const { return map_; }
  StageTimer& timer() { return timer_; }
  const StageTimer& timer() const { return timer_; }
  const Camera& camera() const { return camera_; }
  // @}
  // What the map file records of the camera.
  const MapIntrinsics& intrinsics() const { return intrinsics_; }
  // Null when loop closing is off (SlamOptions::loopClosing, localisation-only mode).
  const LoopCloser<Sensor>* loopCloser() const { return loopCloser_.get(); }

 private:
  // Threaded monocular after a new keyframe: waits for local mapping (see the definition).
  void waitForMappingAfterKeyFrame(std::chrono::steady_clock::time_point trackingStart, double extractionMs);
  // Live monocular: before tracking a frame, wait (at most a frame period) until the keyframe the
  // frame before made has its new points.
  void waitForTriangulationOfLastKeyFrame();
  // Threaded stereo/RGB-D fed faster than a camera: before tracking a frame, wait until local
  // mapping's queue is below the keyframe rule's limit.
  void waitForRoomInMappingQueue();
  // Threaded monocular with a live camera: that wait is bounded by the frame period, which
  // track() then times from its start.
  bool waitBoundedByFramePeriod() const {
    return !Sensor::kMetricScale && options_.liveCamera && !options_.deterministic;
  }

  const Camera camera_;  // every stage below holds a reference to it
  std::shared_ptr<const OrbVocabulary> vocabulary_;
  MapIntrinsics intrinsics_;
  SlamOptions options_;
  StageTimer timer_;
  Map map_;
  bow::KeyframeDatabase database_;  // relocalisation candidates; fed by local mapping's sink
  std::unique_ptr<Relocaliser<Sensor>> relocaliser_;
  std::size_t loadedKeyFrames_ = 0;
  std::unique_ptr<LocalMapper<Sensor>> mapper_;
  std::unique_ptr<LoopCloser<Sensor>> loopCloser_;  // declared after mapper_: destroyed before it
  std::unique_ptr<Tracker<Sensor>> tracker_;
  std::atomic<std::uint64_t> frames_{0};  // atomic: mapSnapshot() reads it from an observer's thread
  std::uint64_t lost_ = 0;
  std::optional<std::uint64_t> initialisedAtFrame_;
  FrameObserver frameObserver_;
  bool shutDown_ = false;
  bool triangulationPending_ = false;  // waitForTriangulationOfLastKeyFrame has a keyframe to wait for
};

// The map file's record of a camera model: its pinhole, bf (0 without stereo), close-depth
// threshold, image size and, for a depth sensor, its disparity σ.
template <CameraModel Camera>
MapIntrinsics mapIntrinsicsOf(const Camera& camera) {
  const PinholeCamera<double>& pinhole = pinholeOf(camera);
  MapIntrinsics k;
  k.fx = pinhole.fx;
  k.fy = pinhole.fy;
  k.cx = pinhole.cx;
  k.cy = pinhole.cy;
  if constexpr (StereoCameraModel<Camera>) k.bf = camera.bf();
  k.closeDepth = camera.closeDepthThreshold();
  if constexpr (requires { camera.disparitySigma; }) k.disparitySigma = static_cast<double>(camera.disparitySigma);
  k.maxX = pinhole.width;
  k.maxY = pinhole.height;
  return k;
}

}  // namespace orbis

#include "orbis/system/slam_core_impl.hpp"

namespace orbis {
extern template class SlamCore<Stereo>;
extern template class SlamCore<Rgbd>;
extern template class SlamCore<Monocular>;
extern template class SlamCore<MonocularFisheye>;

}  // namespace orbis
