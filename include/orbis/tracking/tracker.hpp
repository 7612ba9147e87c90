// orbis/tracking/tracker.hpp — the tracking thread of the paper (§III, Fig. 2a), templated on the
// sensor configuration.
//
// Contract: track(frame) estimates the frame's camera pose against the map and decides whether
// it becomes a keyframe. On the first frame with enough depth it bootstraps the map (§III-B);
// a sensor without metric scale (monocular) initialises from two views instead
// (monocular_initialisation_impl.hpp): a reference frame, windowed matches in later frames, the
// two-view initialiser (geometry/two_view.hpp), two keyframes, BA, median depth scaled to 1; a
// refused attempt says why (initialisationRefusal()) and is retried with the next frame.
// Then: constant-velocity prediction with search by projection, falling back to bag-of-words
// matching against the reference keyframe; local-map tracking; motion-only BA with outlier
// rejection; the ORB-SLAM2 keyframe rule including the close-point rule (τt, τc). It holds
// Map::mutex() while it reads or changes the map. Every tracked frame's pose is kept relative
// to its reference keyframe, so trajectory() reflects later map corrections (loops, BA).
// What differs by sensor is asked of the trait at compile time: the search windows (RGB-D's
// depth from a sensor), the stereo checks, and which keypoints may be lifted from depth.
// Bodies: tracker_impl.hpp; Tracker<Stereo>, Tracker<Rgbd> and Tracker<Monocular> are compiled
// in src/tracking/.
// Monocular differs in its keyframe rule (no close points; a keyframe when tracking keeps under
// 90% of the reference keyframe's points, never while mapping is busy) and has no depth to lift
// points from: its map grows by the local mapper's triangulation.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <optional>
#include <random>
#include <vector>

#include "orbis/bow/vocabulary.hpp"
#include "orbis/geometry/two_view.hpp"
#include "orbis/map/frame.hpp"
#include "orbis/map/local_mapping_control.hpp"
#include "orbis/map/map.hpp"
#include "orbis/map/slam_events.hpp"
#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/sensor/sensor.hpp"
#include "orbis/util/timing.hpp"

namespace orbis {



// Tracking's thresholds (ORB-SLAM2's unless noted).
struct TrackerOptions {
  int closeTrackedThreshold = 100;   // τt: fewer tracked close points than this …
  int closeCreatableThreshold = 70;  // τc: … and at least this many creatable ones → keyframe
  int maxFramesBetweenKeyFrames = 30;  // the camera's fps, as ORB-SLAM2
  // Frames a new keyframe must wait after the last (0: none).
  int minFramesBetweenKeyFrames = 0;
  int minBootstrapFeatures = 500;      // keypoints needed to start the map (ORB-SLAM2)
  int bowLevelsUp = 4;                 // vocabulary level of the FeatureVector grouping
  bool localisationOnly = false;       // no keyframes, visual-odometry points from depth
  // Monocular two-view initialisation (ORB-SLAM's MonocularInitialization).
  int minInitialisationKeypoints = 100;  // a reference frame needs more keypoints than this
  int minInitialisationMatches = 100;    // windowed matches below this drop the reference
  float initialisationWindow = 100;      // px around the previous match (ORB-SLAM's)
  unsigned initialisationSeed = 5489;    // the two-view RANSAC's generator (deterministic runs)
  // @{
  // The atlas (issue 32): when relocalisation has failed on at least newMapAfterLostFrames frames
  // that could start a map, spanning at least newMapAfterLostSeconds, a new map is opened (the
  // old ones stay): at once for metric sensors, by two-view initialisation for monocular. Off:
  // ORB-SLAM2's single map, lost until relocalised.
  bool atlas = true;
  int newMapAfterLostFrames = 10;
  double newMapAfterLostSeconds = 0.3;
  // @}
};

// What tracking made of a frame.
struct TrackResult {
  // Ok, Lost or NotInitialised.
  TrackingState state = TrackingState::NotInitialised;
  SE3d Tcw;              // valid when state == Ok
  int inliers = 0;       // matches to map points after motion-only BA
  // Whether the frame became a keyframe.
  bool newKeyFrame = false;
  bool newMap = false;   // the frame opened a new map of the atlas (after a loss)
  std::uint32_t mapId = 0;  // the map of the atlas it was tracked in
};


// A tracked frame, stored relative to its reference keyframe.
struct TrackedFrame {
  // @{
  // Frame index, seconds and the reference keyframe.
  std::uint64_t index;
  double timestamp;
  KeyFrame* reference;
  // @}
  SE3d Tcr;  // camera-from-reference-keyframe
  std::uint32_t mapId = 0;  // the map of the atlas it was tracked in (its reference's map moves on merges)
};

// Camera-from-world of a tracked frame through its (possibly since culled) reference keyframe.
SE3d worldPoseOf(const TrackedFrame& f);

// Tracking (§III-B/§V): motion model or reference keyframe, then the local map; decides keyframes
// and relocalises when lost.
template <SensorConfiguration Sensor>
class Tracker {
 public:
  // @{
  // The sensor's camera model and frame type.
  using Camera = typename Sensor::Camera;
  using FrameT = Frame<Camera>;
  // @}

  // Tracks against map, handing keyframes to mapper.
  Tracker(Map& map, const OrbVocabulary& vocabulary, LocalMappingControl* mapper, TrackerOptions options,
          StageTimer* timer = nullptr);

  // Tracks one frame. A keyframe it makes is handed to local mapping by handOverNewKeyFrame()
  // (or, failing that, at the start of the next track()).
  TrackResult track(FrameT frame);
  // Queues the keyframe the last track() made for local mapping; call it after track() returns,
  // without the map's mutex. Why not inside track(): the queued keyframe wakes the mapping thread,
  // which the scheduler may run on the tracking thread's core for the keyframe's bag of words
  // while the pose is still being finished (docs/notes/2026-11-27-speed-mapping-cpu.md).
  void handOverNewKeyFrame();

  // The state after the last frame.
  TrackingState state() const { return state_; }
  // Why the last monocular initialisation attempt was refused (None before any attempt).
  TwoViewRefusal initialisationRefusal() const { return initialisationRefusal_; }
  // Why each frame before the map existed did not start it (monocular): reason -> frames. The
  // reasons: "too few keypoints" (no reference frame: a textureless or blank view), "new
  // reference frame", or a TwoViewRefusal's name ("too few matches", "low parallax", ...).
  const std::map<std::string, std::size_t>& initialisationWaits() const { return initialisationWaits_; }
  // @{
  // Localisation-only mode (no keyframes).
  void setLocalisationOnly(bool on) { options_.localisationOnly = on; }
  bool localisationOnly() const { return options_.localisationOnly; }
  // @}
  // Every tracked frame, by index. Read with the map mutex held (poses move with the map).
  const std::vector<TrackedFrame>& trackedFrames() const { return tracked_; }
  // World pose of a tracked frame.
  static SE3d worldPose(const TrackedFrame& f) { return worldPoseOf(f); }
  // Relocalisation hook (loop module): given the frame, returns true and sets its pose/matches
  // when it found itself in the map again.
  void setRelocaliser(std::function<bool(FrameT&)> relocalise) { relocalise_ = std::move(relocalise); }
  // A map was loaded: the first frames must relocalise in it rather than start a new map.
  void startLost() { state_ = TrackingState::Lost; }
  // Off by default: when on, track() records each keypoint's KeypointState (for observers).
  void setRecordKeypointStates(bool on) { recordKeypointStates_ = on; }
  // The last frame's keypoint states (empty unless recording) and its local map. Tracking thread.
  const std::vector<KeypointState>& keypointStates() const { return keypointStates_; }
  // The last frame's local map.
  const std::vector<MapPoint*>& localMapPoints() const { return localPoints_; }
  // The motion model: current-from-last of the last two tracked frames (none after a loss).
  const std::optional<SE3d>& motionModel() const { return velocity_; }

 private:
  void computeBow(FrameT& f) const;
  // A keyframe of frame f in the active map: with f's words when it has them, else with their
  // computation left to whichever thread needs them first (the mapping thread, normally).
  KeyFrame* createKeyFrameFrom(const FrameT& f);
  bool bootstrap(FrameT& f)
    requires(Sensor::kMetricScale);
  // Monocular (monocular_initialisation_impl.hpp); constrained so that the explicit
  // instantiations for metric sensors do not compile them.
  bool initialiseFromTwoViews(FrameT& f)
    requires(!Sensor::kMetricScale);
  bool createInitialMap(FrameT& f, const std::vector<std::pair<std::size_t, std::size_t>>& pairs,
                        const TwoViewResult& twoView)
    requires(!Sensor::kMetricScale);
  void startMap(KeyFrame* first, KeyFrame* second, FrameT& f)
    requires(!Sensor::kMetricScale);
  // The atlas: counts a lost frame that could start a map; true when a new map is due.
  bool newMapDue();
  // Opens a new map after a loss and starts it from `f` where the sensor can (metric: at once).
  bool startNewMapAfterLoss(FrameT& f);
  // Scales what is kept relative to keyframes (frame poses, the motion model) by the scale of
  // the merges since the last frame that moved their map (monocular; metric merges have none).
  void followMergeScales();
  bool trackReferenceKeyFrame();
  // Projects the last frame's matches through `motion` (current from last) and optimises.
  bool trackWithMotionModel(const SE3d& motion);
  // Frames a relocalisation must track the local map for (the relocalised one included) before
  // a keyframe may be made from its pose; see needNewKeyFrame.
  static constexpr std::uint64_t kFramesToConfirmRelocalisation = 3;
  // The current frame is fewer than n frames after the last relocalisation (if any).
  bool withinFramesOfRelocalisation(std::uint64_t n) const {
    return lastRelocalisedFrame_ && current_.index < *lastRelocalisedFrame_ + n;
  }
  bool trackLocalMap();
  void updateLastFrame();
  void replaceRetiredPoints(FrameT& f);
  void updateLocalMap();
  int searchLocalPoints();
  bool needNewKeyFrame() const;
  void createNewKeyFrame();
  // Runs motion-only BA on current_, then drops outliers; returns matches to map points kept.
  int optimiseAndDropOutliers();
  void recordKeypointStates();
  // Diagnosis (`orbis run --stats`): a named counter of the current frame, logged with the frame.
  void note(const char* name, double value) const {
    if (timer_ && timer_->eventsEnabled()) diagnostics_.emplace_back(name, value);
  }

  Map& map_;
  const OrbVocabulary& vocabulary_;
  LocalMappingControl* mapper_;
  TrackerOptions options_;
  StageTimer* timer_;
  std::function<bool(FrameT&)> relocalise_;

  TrackingState state_ = TrackingState::NotInitialised;
  FrameT current_, last_;
  std::optional<SE3d> velocity_;  // Tcw(current) * Twc(last) of the last tracked pair
  KeyFrame* reference_ = nullptr;
  KeyFrame* pendingKeyFrame_ = nullptr;  // made by the last track(), not yet queued for mapping
  std::uint64_t lastKeyFrameFrame_ = 0;
  std::optional<std::uint64_t> lastRelocalisedFrame_;
  int matchesInliers_ = 0;
  std::vector<KeyFrame*> localKeyFrames_;
  std::vector<MapPoint*> localPoints_;
  std::vector<MapPoint*> pointSlots_;  // updateLocalMap's scratch, only grows
  bool recordKeypointStates_ = false;
  std::vector<KeypointState> keypointStates_;
  std::vector<std::unique_ptr<MapPoint>> temporaryStorage_;
  std::vector<TrackedFrame> tracked_;
  int lostFramesWithView_ = 0;  // lost frames since the last tracked one that could start a map
  double lostSince_ = 0;        // timestamp of the first of them
  std::uint64_t mergesSeen_ = 0;  // Map::mergeCount() when the last frame was tracked
  mutable std::vector<std::pair<std::string, double>> diagnostics_;

  // Monocular initialisation: the reference frame, where its keypoints were last matched.
  std::optional<FrameT> initialReference_;
  std::vector<Eigen::Vector2f> initialPredicted_;
  std::mt19937 initialisationRng_{options_.initialisationSeed};
  TwoViewRefusal initialisationRefusal_ = TwoViewRefusal::None;
  std::map<std::string, std::size_t> initialisationWaits_;
};

}  // namespace orbis

#include "orbis/tracking/tracker_impl.hpp"
#include "orbis/tracking/monocular_initialisation_impl.hpp"

namespace orbis {
extern template class Tracker<Stereo>;
extern template class Tracker<Rgbd>;
extern template class Tracker<Monocular>;
extern template class Tracker<MonocularFisheye>;
}  // namespace orbis
