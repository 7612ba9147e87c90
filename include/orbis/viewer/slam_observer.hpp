// orbis/viewer/slam_observer.hpp — the seam a live display watches SLAM through: owned by the viewer,
// filled by the system (SlamCore includes it; the viewer never includes the system).
//
// Contract: a FrameObserver set on SlamCore is called on the tracking thread right after each
// frame with a FrameSnapshot: copied data only (the frame's features are shared, immutable), so
// the observer may keep it; it must return at once (copy into a slot, never wait). Its image is
// the input image itself, shared (a cv::Mat header, not a copy of the pixels): whoever feeds
// Slam::track a frame must not write into that frame's pixels afterwards while an observer is
// set (hand each frame its own buffer, as the dataset readers do, or pass a clone). Without an
// observer the tracker records nothing extra. A MapSnapshot is a copy of the map's keyframes,
// points, graphs, loop closures and trajectory, taken by SlamCore::mapSnapshot() under the map
// mutex; an observer takes one at its own (low) rate from its own thread. SlamObserver bundles
// both for runDataset: attach() before the first frame, onFrame() per frame, detach() with the
// final map after shutdown, before the system is destroyed.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/features/frame_features.hpp"
#include "orbis/geometry/se3.hpp"
#include "orbis/map/map.hpp"
#include "orbis/map/slam_events.hpp"

namespace orbis {

// One tracked frame, as the tracking thread hands it to an observer.
struct FrameSnapshot {
  // @{
  // Frame index, seconds, tracking state, inliers and whether it became a keyframe.
  std::uint64_t index = 0;
  double timestamp = 0;
  TrackingState state = TrackingState::NotInitialised;
  SE3d Tcw;  // valid when state == Ok
  int inliers = 0;
  bool newKeyFrame = false;
  // @}
  std::shared_ptr<const FrameFeatures> features;  // keypoints (shared with the map, immutable)
  std::vector<KeypointState> keypointStates;      // one per keypoint
  std::vector<MapPointId> localMapPoints;         // the tracker's local map after this frame
  cv::Mat image;  // the input image (left of a stereo pair; grey or BGR), shared; may be empty
  // @{
  // Sizes and times.
  double imageWidth = 0, imageHeight = 0;         // the image's size (undistorted bounds without one)
  double extractionMs = 0, trackingMs = 0;        // tracking includes inline mapping (deterministic)
  // @}
};

// A keyframe, copied for the viewer.
struct KeyFrameSnapshot {
  // @{
  // Its id, the frame it was made from, and its pose (world from camera).
  KeyFrameId id = 0;
  std::uint64_t frameIndex = 0;
  SE3d Twc;
  // @}
  std::int64_t parent = -1;  // spanning tree; -1 at the root
  std::uint32_t mapId = 0;   // its map of the atlas (the viewer colours each map)
  // @{
  // Graph edges.
  std::vector<KeyFrameId> covisibles, loopEdges;  // covisibles: weight >= kStrongCovisibility
  // @}
};

// A map point, copied for the viewer.
struct MapPointSnapshot {
  // @{
  // Its id, position and the keyframe that created it.
  MapPointId id = 0;
  Eigen::Vector3f position;
  KeyFrameId firstKeyFrame = 0;
  // @}
};

// The map, copied under its mutex: keyframes, points, loops and trajectory.
struct MapSnapshot {
  static constexpr int kStrongCovisibility = 100;  // the edges ORB-SLAM2's viewer draws
  // @{
  // Keyframes, points and loop closures.
  std::vector<KeyFrameSnapshot> keyFrames;
  std::vector<MapPointSnapshot> points;
  std::vector<LoopClosureEvent> loopClosures;
  // @}
  std::vector<MapMergeEvent> merges;  // maps of the atlas merged, in order
  std::vector<Eigen::Vector3f> trajectory;  // camera centres of the tracked frames
  // Frames tracked.
  std::size_t frames = 0;
};

// Called after every frame on the tracking thread.
using FrameObserver = std::function<void(FrameSnapshot&&)>;
// Gives a copy of the map on request (any thread).
using MapSnapshotSource = std::function<MapSnapshot()>;

// Copies the good keyframes and points of `map`; the caller holds map.mutex().
MapSnapshot snapshotOfMap(const Map& map);

// What watches a run: the viewer, or a user's own observer.
class SlamObserver {
 public:
  virtual ~SlamObserver() = default;
  virtual void attach(MapSnapshotSource source) = 0;  // the source is valid until detach()
  virtual void onFrame(FrameSnapshot&& frame) = 0;    // tracking thread: must not block
  // The run ended with this map.
  virtual void detach(MapSnapshot finalMap) = 0;
};

}  // namespace orbis
