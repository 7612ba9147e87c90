// orbis/system/slam.hpp — the SLAM system a user instantiates: orbis::Slam<Sensor>.
//
// Contract: Slam<Sensor> turns each input into features with the sensor's compile-time
// FeatureBuilder, then hands them to SlamCore<Sensor> (tracking, local mapping, loop closing over
// one Map, every stage templated on the same sensor). track() returns the frame's pose and
// tracking state. Two modes: threaded (real time: local mapping and loop closing run on their
// own threads) and
// deterministic (the same stages run inline in a fixed order after each frame, so the same
// input gives a bit-identical trajectory on every run). shutdown() finishes queued work and
// joins the threads; the trajectory and map stay readable afterwards.
#pragma once

#include <chrono>
#include <concepts>
#include <memory>
#include <vector>

#include "orbis/features/feature_storage.hpp"
#include "orbis/sensor/sensor.hpp"
#include "orbis/system/slam_core.hpp"
#include "orbis/util/timing.hpp"

namespace orbis {

// The SLAM system on a sensor: features by Sensor::FeatureBuilder, then SlamCore (tracking, local
// mapping, loop closing).
template <SensorConfiguration Sensor>
class Slam {
 public:
  // @{
  // The sensor's camera model and input.
  using Camera = typename Sensor::Camera;
  using Input = typename Sensor::Input;
  // @}

  // A system for camera, with the extractor's parameters and the vocabulary.
  Slam(const Camera& camera, const OrbParams& orb, std::shared_ptr<const OrbVocabulary> vocabulary,
       SlamOptions options = {})
      : builder_(camera, orb), core_(camera, std::move(vocabulary), options) {}
  // A monocular camera whose images still carry radial-tangential distortion (the builder
  // undistorts keypoints; a fisheye's lens is part of MonocularFisheye's camera).
  template <class Lens>
  Slam(const Camera& camera, const OrbParams& orb, const Lens& lens, std::shared_ptr<const OrbVocabulary> vocabulary,
       SlamOptions options = {})
    requires std::constructible_from<typename Sensor::FeatureBuilder, const Camera&, const OrbParams&, const Lens&>
      : builder_(camera, orb, lens), core_(camera, std::move(vocabulary), options) {}

  // Extracts the input's features and tracks them; returns the state and, when tracked, the pose.
  TrackResult track(const Input& input) {
    std::shared_ptr<const FrameFeatures> features;
    double extractionMs = 0;
    {
      using Clock = std::chrono::steady_clock;
      const Clock::time_point start = core_.observesFrames() ? Clock::now() : Clock::time_point{};
      ScopedStage stage(&core_.timer(), "tracking: ORB extraction");
      features = std::make_shared<const FrameFeatures>(storage_.keep(builder_.build(input)));
      if (core_.observesFrames()) extractionMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    }
    const TrackResult result = core_.track(std::move(features), input.timestamp, extractionMs, observedImage(input));
    // A builder with an initialisation budget (monocular) uses it until the map exists, and again
    // after a reset (sensor.hpp).
    if constexpr (requires { builder_.setInitialising(true); })
      builder_.setInitialising(result.state == TrackingState::NotInitialised);
    return result;
  }

  // Finishes queued mapping and loop-closing work and joins the threads; the results stay readable.
  void shutdown() { core_.shutdown(); }
  // Every tracked frame's pose (camera to world).
  Trajectory trajectory() const { return core_.trajectory(); }
  // Every good keyframe's pose (camera to world).
  Trajectory keyFrameTrajectory() const { return core_.keyFrameTrajectory(); }
  // The map's points.
  std::vector<Eigen::Vector3f> mapPointCloud() const { return core_.mapPointCloud(); }
  // Frames, tracked, lost, keyframes, points, loops and initialisation.
  SlamStats stats() const { return core_.stats(); }
  // The state after the last frame.
  TrackingState state() const { return core_.state(); }
  // Switches localisation-only mode on or off.
  void setLocalisationOnly(bool on) { core_.setLocalisationOnly(on); }
  // See SlamCore::setFrameObserver and mapSnapshot (slam_observer.hpp).
  void setFrameObserver(FrameObserver observer) { core_.setFrameObserver(std::move(observer)); }
  // A copy of the map, loops and trajectory (any thread).
  MapSnapshot mapSnapshot() const { return core_.mapSnapshot(); }
  // Per-stage timing.
  const StageTimer& timer() const { return core_.timer(); }
  // @{
  // The core, for what Slam does not forward (map files, the map itself).
  using Core = SlamCore<Sensor>;
  Core& core() { return core_; }
  const Core& core() const { return core_; }
  // @}

 private:
  // The image a frame observer is shown: the left one of a stereo pair.
  static const cv::Mat& observedImage(const Input& input) {
    if constexpr (requires { input.left; }) return input.left;
    else return input.image;
  }

  typename Sensor::FeatureBuilder builder_;
  // What a keyframe keeps of the features, in memory faulted in off the frame's call, for every
  // sensor's builder alike (features/feature_storage.hpp).
  FeatureStorageReserve storage_;
  SlamCore<Sensor> core_;
};

}  // namespace orbis
