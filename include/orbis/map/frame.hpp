// orbis/map/frame.hpp — the frame being tracked: features, pose and map-point matches.
//
// Contract: a Frame<Camera> is built once per input by the sensor's feature builder and then
// only its pose, its matches and their outlier flags change. Features are shared, immutable,
// with the keyframe it may become. The camera is the sensor's compile-time model (owned by the
// SLAM system, outliving the frame); `intrinsics` records the undistorted image bounds
// keypoints fall in and the numbers a keyframe's map-file record keeps. uRight < 0 marks a
// keypoint without a stereo/depth coordinate.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "orbis/bow/bow_vector.hpp"
#include "orbis/camera/camera_model.hpp"
#include "orbis/map/key_frame.hpp"

namespace orbis {

// A tracked frame: its features, pose and map-point matches, on the sensor's camera model.
template <CameraModel Camera>
struct Frame {
  // Index in the input sequence.
  std::uint64_t index = 0;
  // Seconds.
  double timestamp = 0;
  // The frame's features (shared, immutable).
  std::shared_ptr<const FrameFeatures> features;
  // The camera model (not owned).
  const Camera* camera = nullptr;
  // The camera as the map file records it, and the image bounds.
  MapIntrinsics intrinsics;

  // @{
  // Bag of words and node-grouped features, computed on demand (relocalisation, keyframes).
  bow::BowVector bow;
  bow::FeatureVector featureVector;
  bool hasBow = false;
  // @}

  // Camera from world.
  SE3d Tcw;
  std::vector<MapPoint*> points;  // one slot per keypoint; null when unmatched
  std::vector<char> outlier;      // set by motion-only BA

  // Keypoints (match slots).
  std::size_t size() const { return points.size(); }
  // The camera centre in the world.
  Eigen::Vector3d cameraCenter() const { return Tcw.inverse().translation(); }
  // Clears every match.
  void resetMatches() {
    points.assign(features ? features->size() : 0, nullptr);
    outlier.assign(points.size(), 0);
  }
  // Number of matched, non-outlier points.
  int inliers() const {
    int n = 0;
    for (std::size_t i = 0; i < points.size(); ++i) n += (points[i] && !outlier[i]) ? 1 : 0;
    return n;
  }
  // Whether keypoint i has a right coordinate or depth.
  bool isStereo(std::size_t i) const { return features->uRight[i] >= 0; }
  // Close points (paper §III-A) are trusted from one frame; a monocular camera has none.
  bool isClose(std::size_t i) const {
    const float d = features->depth[i];
    return d > 0 && d < camera->closeDepthThreshold();
  }
  // World point of keypoint i from its depth (stereo or RGB-D), using the current pose.
  bool pointFromDepth(std::size_t i, Eigen::Vector3d& world) const {
    return orbis::pointFromDepth(*camera, *features, i, Tcw, world);
  }
};

}  // namespace orbis
