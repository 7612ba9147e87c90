// orbis/system/slam.hpp — the SLAM system a user instantiates: orbis::Slam<Sensor>.
//
// Contract: Slam<Sensor> turns each input into features with the sensor's compile-time
// FeatureBuilder, then hands them to the sensor-agnostic core (SlamCore: tracking, local mapping,
// loop closing over one Map). track() returns the frame's pose and tracking state. Two modes:
// threaded (real time: local mapping and loop closing run on their own threads) and
// deterministic (the same stages run inline in a fixed order after each frame, so the same
// input gives a bit-identical trajectory on every run). shutdown() finishes queued work and
// joins the threads; the trajectory and map stay readable afterwards.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "orbis/bow/keyframe_database.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/map/map.hpp"
#include "orbis/system/sensor.hpp"
#include "orbis/tracking/relocaliser.hpp"
#include "orbis/tracking/tracker.hpp"
#include "orbis/util/timing.hpp"

namespace orbis {

class LocalMapper;
class LoopCloser;

struct SlamOptions {
  bool deterministic = false;     // inline stages in a fixed order (the tests use it)
  bool localisationOnly = false;  // tracking only, against the existing map (§III-F)
  bool loopClosing = true;
  double fps = 30;                // frame rate: the keyframe rule's "max frames" (ORB-SLAM2)
  std::uint32_t seed = 0;         // seeds every random choice (RANSAC)
};

struct SlamStats {
  std::size_t frames = 0, tracked = 0, lost = 0, keyFrames = 0, mapPoints = 0;
  std::size_t loopClosures = 0;
};

// The sensor-agnostic part of the system (non-template; src/system/slam_core.cpp).
class SlamCore {
 public:
  SlamCore(std::shared_ptr<const OrbVocabulary> vocabulary, const MapIntrinsics& intrinsics, bool rgbd,
           SlamOptions options);
  ~SlamCore();
  SlamCore(const SlamCore&) = delete;
  SlamCore& operator=(const SlamCore&) = delete;

  TrackResult track(std::shared_ptr<const FrameFeatures> features, double timestamp);
  void shutdown();

  Trajectory trajectory() const;          // every tracked frame, camera-to-world
  Trajectory keyFrameTrajectory() const;  // every good keyframe, camera-to-world
  std::vector<Eigen::Vector3f> mapPointCloud() const;
  SlamStats stats() const;
  TrackingState state() const { return tracker_->state(); }
  void setLocalisationOnly(bool on);

  // Map files (io/map_file.hpp). saveMap waits for local mapping to finish its queue. loadMap
  // needs a core that has not tracked yet; tracking then starts lost and relocalises in the map.
  void saveMap(const std::filesystem::path& file);
  void loadMap(const std::filesystem::path& file);
  SensorKind sensorKind() const { return rgbd_ ? SensorKind::Rgbd : SensorKind::Stereo; }
  // Relocalisation attempts and successes; keyframes loaded from a map file.
  RelocalisationStats relocalisationStats() const;
  std::size_t loadedKeyFrames() const { return loadedKeyFrames_; }

  Map& map() { return map_; }
  const Map& map() const { return map_; }
  StageTimer& timer() { return timer_; }
  const StageTimer& timer() const { return timer_; }
  const MapIntrinsics& intrinsics() const { return intrinsics_; }
  // Null when loop closing is off (SlamOptions::loopClosing, localisation-only mode).
  const LoopCloser* loopCloser() const { return loopCloser_.get(); }

 private:
  std::shared_ptr<const OrbVocabulary> vocabulary_;
  MapIntrinsics intrinsics_;
  bool rgbd_;
  SlamOptions options_;
  StageTimer timer_;
  Map map_;
  bow::KeyframeDatabase database_;  // relocalisation candidates; fed by local mapping's sink
  std::unique_ptr<Relocaliser> relocaliser_;
  std::size_t loadedKeyFrames_ = 0;
  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<LoopCloser> loopCloser_;  // declared after mapper_: destroyed before it
  std::unique_ptr<Tracker> tracker_;
  std::uint64_t frames_ = 0, lost_ = 0;
  bool shutDown_ = false;
};

MapIntrinsics makeMapIntrinsics(const PinholeCamera<double>& pinhole, double bf, double closeDepth, int width,
                                int height, double disparitySigma = 0.0);

// A depth sensor's disparity σ; 0 for cameras that measure no depth of their own.
template <class Camera>
double disparitySigmaOf(const Camera& camera) {
  if constexpr (requires { camera.disparitySigma; }) return static_cast<double>(camera.disparitySigma);
  else return 0.0;
}

template <SensorConfiguration Sensor>
class Slam {
 public:
  using Camera = typename Sensor::Camera;
  using Input = typename Sensor::Input;

  Slam(const Camera& camera, const OrbParams& orb, std::shared_ptr<const OrbVocabulary> vocabulary,
       SlamOptions options = {})
      : builder_(camera, orb),
        core_(std::move(vocabulary),
              makeMapIntrinsics(camera.pinhole, camera.bf(), camera.closeDepthThreshold(), camera.pinhole.width,
                                camera.pinhole.height, disparitySigmaOf(camera)),
              Sensor::kDepthFromSensor, options) {}

  TrackResult track(const Input& input) {
    std::shared_ptr<const FrameFeatures> features;
    {
      ScopedStage stage(&core_.timer(), "tracking: ORB extraction");
      features = std::make_shared<const FrameFeatures>(builder_.build(input));
    }
    return core_.track(std::move(features), input.timestamp);
  }

  void shutdown() { core_.shutdown(); }
  Trajectory trajectory() const { return core_.trajectory(); }
  Trajectory keyFrameTrajectory() const { return core_.keyFrameTrajectory(); }
  std::vector<Eigen::Vector3f> mapPointCloud() const { return core_.mapPointCloud(); }
  SlamStats stats() const { return core_.stats(); }
  TrackingState state() const { return core_.state(); }
  void setLocalisationOnly(bool on) { core_.setLocalisationOnly(on); }
  const StageTimer& timer() const { return core_.timer(); }
  SlamCore& core() { return core_; }

 private:
  typename Sensor::FeatureBuilder builder_;
  SlamCore core_;
};

}  // namespace orbis
